"""patterns inside FreeCAD: the pattern and the blank back in the CAD document, parametric.

Importable in FreeCAD (``FreeCAD`` and ``Part`` must import), in the GUI and
in ``freecadcmd``, for scripts and for the workbench (``freecad/patterns_wb``)::

    import patterns.freecad as pf
    pattern = pf.make_pattern(doc.Cut, seam_allowance=10)       # a Part::FeaturePython, recomputed with Cut
    blank = pf.make_blank(doc.Bracket, k_factor=0.44)           # a bent part's blank and bend lines
    pf.export(pattern, "cut.dxf")                               # the project's writers: DXF, SVG, JSON
    print(pf.report_of(pattern))                                # the check, as in the Report view

See docs/freecad.md.
"""

from __future__ import annotations

from ..audit import Report
from ..errors import InputError
from ..export import write
from .features import (
    BLANK_RECORDS,
    PATTERN_RECORDS,
    ROLES,
    BlankFeature,
    MarksFeature,
    PatternFeature,
    make_blank,
    make_pattern,
)

__all__ = ["BLANK_RECORDS", "PATTERN_RECORDS", "ROLES", "BlankFeature", "MarksFeature", "PatternFeature", "export",
           "make_blank", "make_pattern", "report_of"]


def _proxy(obj):
    proxy = getattr(obj, "Proxy", None)
    if not isinstance(proxy, (PatternFeature, BlankFeature)):
        raise InputError(f"{getattr(obj, 'Label', obj)}: not a patterns Pattern or Blank object")
    if proxy.drawing is None:
        obj.touch()
        obj.Document.recompute()
    if proxy.drawing is None:
        raise InputError(f"{obj.Label}: its recompute failed: {obj.getStatusString()}")
    return proxy


def export(obj, path, **options) -> None:
    """Write a Pattern or Blank object's pieces with the project's writers (never FreeCAD's DXF exporter).

    ``path``'s suffix chooses the profile as :func:`patterns.write` does: ``.dxf`` (``profile="machine"`` or
    ``"astm"``), ``.svg``, ``.json`` (the report, in the drawing's frame); ``options`` are
    :class:`patterns.WriteOptions` fields (``layer_map``, ``version``, ``units``, ``bend_lines``).  The
    pieces are the object's, with its own options: the same file ``patterns flatten`` (or ``unfold``) writes
    for the same part and options.
    """
    proxy = _proxy(obj)
    write(proxy.checked if str(path).lower().endswith(".json") else proxy.drawing, path, **options)


def report_of(obj) -> Report:
    """The check report of a Pattern or Blank object's last recompute."""
    return _proxy(obj).report
