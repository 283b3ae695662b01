"""Tests of grammarc.model (a package, so that its test modules may share names with those of tests/io)."""
