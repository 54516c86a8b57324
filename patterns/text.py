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

__all__ = ["printable"]

_UNSAFE = re.compile(r"[\x00-\x1f\x7f-\x9f\ud800-\udfff]")


def _escape(match: re.Match) -> str:
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
    return _UNSAFE.sub(_escape, text)
