"""The commands of ``grammarc``, a module for each kind: ``cli`` parses the command line and runs the one
asked for (``run_*``). Each imports what its command needs when it runs, so that a command pays only for
its own imports."""
