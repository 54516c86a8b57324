"""Names are data: text from file names and models made safe for every place it is written.

A file name may hold any byte but ``/`` and NUL: control characters (ESC, BEL),
bytes that are not UTF-8 (Python keeps them as lone surrogates,
``os.fsdecode``), dollar signs.  :func:`printable` makes such text safe for a
terminal, a DXF text, an XML/SVG document and a JSON file alike: every control
character and every undecodable byte becomes a visible escape (``\\x1b``,
``\\xff``), everything else is kept.  Pictures (matplotlib) are drawn with
``parse_math=False`` besides, so that ``$x$`` stays the text it is.
"""

from __future__ import annotations

import os
import re

__all__ = ["counted", "escape", "printable", "spreadsheet_cell"]

_UNSAFE = re.compile(r"[\x00-\x1f\x7f-\x9f\ud800-\udfff]")


def escape(match: re.Match) -> str:
    """The visible escape of one matched character (``\\x1b``, ``\\xff`` for an undecodable byte, ``\\u2028``)."""
    ch = match.group(0)
    code = ord(ch)
    if 0xDC80 <= code <= 0xDCFF:  # an undecodable byte, as os.fsdecode keeps it
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def printable(text) -> str:
    """``text`` (a str, bytes or path) with control characters and undecodable bytes as visible escapes.

    Examples
    --------
    >>> printable("part\\x1b[31m.stl")
    'part\\\\x1b[31m.stl'
    >>> printable(b"caf\\xe9.step")
    'caf\\\\xe9.step'
    """
    if not isinstance(text, str):
        text = os.fsdecode(text)
    return _UNSAFE.sub(escape, text)


_FORMULA = ("=", "+", "-", "@", "\t", "\r", "\uff1d", "\uff0b", "\uff0d", "\uff20")
"""What a spreadsheet may take a cell's text for the start of a formula by (OWASP's CSV injection list, with the
full-width forms some spreadsheets read as the same)."""


def spreadsheet_cell(text: str) -> str:
    """``text`` safe as a CSV cell a spreadsheet opens: made :func:`printable`, and a text that starts as a formula
    could (``=``, ``+``, ``-``, ``@``, a tab or carriage return) gets a leading ``'`` (OWASP's rule: the cell
    then shows the text, it never runs it).  Numbers are written as numbers, not through this.

    Examples
    --------
    >>> spreadsheet_cell("=cmd|' -C calc'!A0"), spreadsheet_cell("bracket"), spreadsheet_cell("-2 mm")
    ("'=cmd|' -C calc'!A0", 'bracket', "'-2 mm")
    """
    text = printable(text)
    return "'" + text if text.startswith(_FORMULA) else text


_IRREGULAR = {"vertex": "vertices", "copy": "copies", "process": "processes", "patch": "patches"}


def counted(n: int, noun: str) -> str:
    """``n`` and ``noun``, plural unless ``n`` is 1: ``"1 panel"``, ``"2 panels"``, ``"1 vertex"``.

    Examples
    --------
    >>> counted(1, "dart"), counted(14, "dart"), counted(0, "finding"), counted(3, "vertex")
    ('1 dart', '14 darts', '0 findings', '3 vertices')
    """
    if n == 1:
        return f"{n} {noun}"
    return f"{n} {_IRREGULAR.get(noun, noun + 'es' if noun.endswith(('s', 'x', 'ch', 'sh')) else noun + 's')}"
