"""The data model: the types every layer passes around, below all the others (readers and writers import it)."""
