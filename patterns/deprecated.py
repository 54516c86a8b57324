"""Public names of 0.1.0 that 0.2.0 replaced, kept working for one minor version (they go in 0.3.0).

Each warns (``DeprecationWarning``, naming its replacement) and does what it did, through today's API.
They are set on their classes here, at the top of the house, because what they call (the writers, the
nester) lies above the classes themselves: ``Pattern`` must not import the writers.

* ``Pattern.to_dxf(path, **options)``: :func:`patterns.write` (a DXF; ``options`` its keywords).
* ``Pattern.layout(options=None, **keywords)``: :func:`patterns.layout`.
* ``Report.to_json(path)``: the report's :meth:`~patterns.Report.to_dict` as JSON, written atomically
  (``patterns.write(pattern, "x.json")`` writes it with the pieces, in the drawing's frame).
"""

from __future__ import annotations

import json
import warnings

from .audit import Report
from .errors import InputError
from .export import write
from .files import atomic_output
from .nesting import layout
from .pattern import Pattern

__all__ = ["GOES_IN"]

GOES_IN = "0.3.0"
"""The release that removes them (CHANGELOG.md)."""


def _warn(old: str, new: str) -> None:
    warnings.warn(f"{old} is deprecated and goes in {GOES_IN}: use {new}", DeprecationWarning, stacklevel=3)


def _to_dxf(self: Pattern, path, options=None, **keywords) -> None:
    """Deprecated: ``patterns.write(pattern, path, **options)``."""
    _warn("Pattern.to_dxf", "patterns.write(pattern, path, ...)")
    if options is not None:
        raise InputError("Pattern.to_dxf: the DxfOptions record is gone; give its fields as keywords "
                         "(patterns.write(pattern, path, seam_allowance=10, ...))")
    if not str(path).lower().endswith(".dxf"):
        raise InputError(f"{path}: Pattern.to_dxf writes a .dxf file")
    write(self, path, **keywords)


def _layout(self: Pattern, options=None, **keywords):
    """Deprecated: ``patterns.layout(pattern, ...)``."""
    _warn("Pattern.layout", "patterns.layout(pattern, ...)")
    return layout(self, options, **keywords)


def _to_json(self: Report, path) -> None:
    """Deprecated: ``patterns.write(pattern, "report.json")`` (the report with the pieces)."""
    _warn("Report.to_json", 'patterns.write(pattern, "report.json")')
    text = json.dumps(self.to_dict(), indent=2, allow_nan=False)
    with atomic_output(path, what="report") as tmp:
        tmp.write_text(text + "\n", encoding="utf-8")


Pattern.to_dxf = _to_dxf
Pattern.layout = _layout
Report.to_json = _to_json
