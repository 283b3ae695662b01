"""Temporary: ``replacing`` moved to ``grammarc.atomic``; this name stays for the importers not yet moved."""

from grammarc.atomic import replacing

__all__ = ["replacing"]
