"""A sheet-metal blank as DXF for a laser, plasma or punch: cut contours, bend lines, a label.

Layers: ``CUT`` (the outline as one closed LWPOLYLINE, straight pieces as
vertices and arcs as bulges; every round hole a CIRCLE; other holes closed
LWPOLYLINEs), ``BEND`` (each bend's centre line, CENTER linetype, with its
direction, angle and inside radius written beside it) and ``LABEL`` (the
part's name, thickness, K-factor or bend table, size).  Millimetres
(``$INSUNITS`` 4, ``$MEASUREMENT`` 1); the drawing starts 5 mm from the origin
in the first quadrant, where a machine's work area does.
"""

from __future__ import annotations

import numpy as np

from ..errors import ExportError, InputError
from ..files import atomic_output
from ..text import printable
from .dxf import _new_doc, _readable_angle, _save

__all__ = ["write_blank_dxf"]

_MARGIN = 5.0
"""Distance of the drawing from the X and Y axes, mm."""


def _vertices(loop, shift) -> list:
    """``[(x, y, bulge)]`` of a closed loop: each piece's start, arcs as bulges."""
    out = []
    for piece in loop.pieces:
        if hasattr(piece, "sweep"):  # an Arc
            a = piece.center + piece.radius * np.array([np.cos(piece.start), np.sin(piece.start)]) + shift
            out.append((float(a[0]), float(a[1]), float(np.tan(piece.sweep / 4))))
        else:
            for p in piece.points(0.001)[:-1] + shift:
                out.append((float(p[0]), float(p[1]), 0.0))
    return out


def write_blank_dxf(blank, path, *, text_height: float = 3.0, version: str = "R2000") -> None:
    """Write a blank as a DXF for a cutter (atomically: a refused or failed write leaves nothing).

    Parameters
    ----------
    blank : patterns.Blank
    path : str or Path
    text_height : float
        Height of the bend labels and the part label, mm.
    version : {"R2000", "R2004", "R2007", "R2010", "R2013", "R2018"}

    Raises
    ------
    ExportError
        The blank cannot be cut as it is (a finding such as flanges that overlap;
        nothing is written), or the file cannot be written.
    """
    import ezdxf

    if not all(hasattr(blank, a) for a in ("outline", "holes", "bends", "findings")):
        raise InputError(f"{path}: write_blank_dxf takes a patterns.Blank, got {type(blank).__name__}")
    if not np.isfinite(text_height) or text_height <= 0:
        raise InputError(f"{path}: text_height must be a positive number of mm, got {text_height!r}")
    if version not in ("R2000", "R2004", "R2007", "R2010", "R2013", "R2018"):
        raise InputError(f"{path}: version must be R2000 .. R2018 (bulged polylines), got {version!r}")
    errors = [f.message for f in blank.findings if f.error]
    if errors:
        raise ExportError(f"{path}: not written: {errors[0]}")
    x0, y0, _, _ = blank.polygon.bounds
    shift = np.array([_MARGIN - x0, _MARGIN - y0])
    doc = _new_doc(ezdxf, version, 4)
    doc.header["$MEASUREMENT"] = 1
    doc.linetypes.add("CENTER", pattern=[1.25, 0.75, -0.125, 0.25, -0.125], description="Center ____ _ ____ _")
    for name, color, linetype in (("CUT", 7, "CONTINUOUS"), ("BEND", 3, "CENTER"), ("LABEL", 2, "CONTINUOUS")):
        doc.layers.add(name, color=color, linetype=linetype)
    msp = doc.modelspace()
    msp.add_lwpolyline(_vertices(blank.outline, shift), format="xyb", close=True, dxfattribs={"layer": "CUT"})
    for hole in blank.holes:
        if hole.is_circle:
            arc = hole.pieces[0]
            msp.add_circle(tuple(arc.center + shift), arc.radius, dxfattribs={"layer": "CUT"})
        else:
            msp.add_lwpolyline(_vertices(hole, shift), format="xyb", close=True, dxfattribs={"layer": "CUT"})
    centre = ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER
    for bend in blank.bends:
        a, b = bend.line + shift
        msp.add_line(tuple(a), tuple(b), dxfattribs={"layer": "BEND", "linetype": "CENTER"})
        direction = (b - a) / max(np.linalg.norm(b - a), 1e-12)
        side = np.array([-direction[1], direction[0]])
        at = 0.5 * (a + b) + side * 0.8 * text_height
        label = f"{bend.direction.upper()} {bend.angle:.1f} DEG R{bend.inside_radius:g}"
        msp.add_text(label, height=text_height, rotation=_readable_angle(direction),
                     dxfattribs={"layer": "BEND"}).set_placement(tuple(at), align=centre)
    w, h = blank.size
    how = f"K {blank.k_factor:g}" if blank.k_factor is not None else "BEND TABLE"
    label = f"{printable(blank.name)}  T {blank.thickness:g} MM  {how}  {w:.1f} x {h:.1f} MM"
    msp.add_text(label, height=text_height, dxfattribs={"layer": "LABEL"}).set_placement(
        (_MARGIN, _MARGIN + h + 1.5 * text_height), align=ezdxf.enums.TextEntityAlignment.BOTTOM_LEFT)
    with atomic_output(path, what="DXF file") as tmp:
        _save(doc, tmp)
