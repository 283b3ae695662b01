"""The numbers of random-stream sites of a grammar's files, given out in source order.

A module of its own, not ``lowering``'s, which imports lark: a file whose statements the lowered cache
kept (``lowered_cache``) goes on numbering the sites of the files after it without being lowered.
"""

from __future__ import annotations


class Sites:
    """The numbers of random-stream sites, given out in source order across a grammar's files
    (``next(sites)``); ``next_site`` is the number the next one gets."""

    def __init__(self, next_site: int = 1):
        self.next_site = next_site

    def __next__(self) -> int:
        self.next_site += 1
        return self.next_site - 1
