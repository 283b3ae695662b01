"""Reading grammar text from disk: UTF-8 with or without a byte-order mark, else Windows-1252.

CityEngine writes rule files in UTF-8, but many public ones were saved by editors in a Windows code page
(accented comments in Latin-1 or Windows-1252). Rather than refuse them, their bytes are decoded as
Windows-1252, which maps nearly every byte to a character, and the reader is warned so that the file can be saved as UTF-8.
The text keeps its lines, so an error position stays ``file:line:col``. A BOM is dropped: it is no
character of the grammar.
"""

from __future__ import annotations

import codecs
from pathlib import Path

#: What a file not in UTF-8 is decoded as.
FALLBACK_ENCODING = "cp1252"


def decode_grammar(data: bytes) -> tuple[str, str | None]:
    """The text of a grammar file's bytes, and the encoding it fell back to (None for UTF-8).

    Parameters
    ----------
    data : bytes
        The file's contents.

    Returns
    -------
    text : str
        Without a leading byte-order mark.
    fallback : str or None
        ``"cp1252"`` when the bytes are not UTF-8, else None.
    """
    data = data.removeprefix(codecs.BOM_UTF8)
    try:
        return data.decode("utf-8"), None
    except UnicodeDecodeError:
        # the five bytes cp1252 leaves unassigned (0x81, 0x8d, 0x8f, 0x90, 0x9d) become U+FFFD, so that no
        # file is refused for one stray byte in a comment
        return data.decode(FALLBACK_ENCODING, errors="replace"), FALLBACK_ENCODING


def encoding_warning(name: str) -> str:
    """The warning for a grammar decoded as Windows-1252, naming the file as diagnostics name it."""
    return f"`{name}` is not UTF-8: read as Windows-1252 (save it as UTF-8 to silence this)"


def read_grammar_text(path: str | Path) -> tuple[str, str | None]:
    """Read a grammar file: its text and the encoding it fell back to (None for UTF-8).

    Raises ``OSError`` as ``Path.read_bytes`` does.
    """
    return decode_grammar(Path(path).read_bytes())
