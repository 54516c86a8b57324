"""The DXF ASTM D6673 (AAMA) profile: for garment CAD (Gerber AccuMark, Lectra, Optitex, CLO).

R12, in mm, laid out as ezdxf's ``gerber_D6673`` add-on writes it (no
``$MODEL_SPACE``/``$PAPER_SPACE`` blocks, no handles: Gerber's reader rejects
them), with a header declaring only the units and a TABLES section declaring
every layer used.  One BLOCK per piece, inserted once on layer 1: the cut line
(1), turn and curve points (2, 3), notches (4: a POINT, z = depth, group 50 =
the angle into the piece), grain (7), internal lines (8: bend lines and
rulings), cut-outs (11), drill holes (13), the sew line (14), annotations
(15).  The style's own text stands in model space above the pieces.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..files import atomic_output
from ..pieces import Drawing, Piece, piece_labels
from ..pieces.allowance import straight_runs
from ..text import printable
from ..units import Unit
from .dxfdoc import add_text, new_doc
from .options import WriteOptions

__all__ = ["ASTM_LAYERS", "ASTM_VERSION", "SAMPLE_SIZE", "write"]

ASTM_LAYERS = {1: "cut line, piece text", 2: "turn points", 3: "curve points", 4: "notches", 7: "grain line",
               8: "internal lines", 11: "internal cut-outs", 13: "drill holes", 14: "sew line", 15: "annotation"}
"""Layers of the ASTM D6673 profile."""

ASTM_VERSION = "ASTM/D6673/10"
"""The standard's version line, first of the style text."""

SAMPLE_SIZE = "BASE"
"""The one size a flattened pattern is (no grading): the piece text's ``Size:`` and the style's sample size."""

_CUT_SAMPLE = 0.01
"""Chord error of an arc of a blank's contour drawn as ASTM polyline points, mm (ASTM has no arcs)."""


def _creation_date() -> str:
    """Today (UTC) as MM-DD-YYYY, or the day of ``SOURCE_DATE_EPOCH`` when set (reproducible builds)."""
    import datetime
    import os

    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    when = (datetime.datetime.fromtimestamp(int(epoch), tz=datetime.timezone.utc) if epoch and epoch.isdigit()
            else datetime.datetime.now(tz=datetime.timezone.utc))
    return when.strftime("%m-%d-%Y")


def _block_name(name: str, used: set) -> str:
    base = re.sub(r"[^A-Za-z0-9_\-]", "_", name)[:31] or "PIECE"
    out, k = base, 1
    while out.upper() in used:
        k += 1
        out = f"{base[:28]}_{k}"
    used.add(out.upper())
    return out


def _turning(loop: np.ndarray) -> np.ndarray:
    """Turning angle at every vertex of a closed polyline, radians (0 = straight on)."""
    a = loop - np.roll(loop, 1, axis=0)
    b = np.roll(loop, -1, axis=0) - loop
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    dot = (a * b).sum(axis=1)
    return np.abs(np.arctan2(cross, dot))


def _block(doc, piece: Piece, name: str, style: str) -> None:
    """One piece's block: its lines, points and texts on the ASTM layers."""
    block = doc.blocks.new(name=name)
    loops = [piece.outline.points(_CUT_SAMPLE)] + [h.points(_CUT_SAMPLE) for h in piece.holes]
    block.add_polyline2d(loops[0].tolist(), close=True, dxfattribs={"layer": "1"})
    for loop in loops[1:]:
        block.add_polyline2d(loop.tolist(), close=True, dxfattribs={"layer": "11"})
    for loop in loops:
        for p, t in zip(loop, _turning(loop)):
            block.add_point((float(p[0]), float(p[1])), dxfattribs={"layer": "2" if t > np.radians(20) else "3"})
    if piece.allowance:
        for loop in piece.sew:
            block.add_polyline2d(straight_runs(loop).tolist(), close=True, dxfattribs={"layer": "14"})
    for notch in piece.notches:
        # ASTM notch: a POINT on the cut line; z = depth, group 50 = angle (into the piece), group 39 = width
        # for a V notch.
        angle = float(np.degrees(np.arctan2(notch.inward[1], notch.inward[0])))
        attribs = {"layer": "4", "angle": angle}
        if notch.mouth is not None:
            attribs["thickness"] = float(notch.depth)
        block.add_point((float(notch.at[0]), float(notch.at[1]), float(notch.depth)), dxfattribs=attribs)
    for tip in piece.drills:
        block.add_point((float(tip[0]), float(tip[1])), dxfattribs={"layer": "13"})
    if piece.grain is not None:
        block.add_line(tuple(piece.grain[0]), tuple(piece.grain[1]), dxfattribs={"layer": "7"})
    for bend in piece.bends:  # internal lines: a blank's bends, the rulings of a rolled panel
        block.add_line(tuple(bend.line[0]), tuple(bend.line[1]), dxfattribs={"layer": "8"})
    lines = [f"Piece Name:{piece.name}", f"Size:{SAMPLE_SIZE}", "Quantity:1", "Material:", f"Style Name:{style}",
             "Units:METRIC"]
    block_lines = [(s, 2.0 - k, 0.6) for k, s in enumerate(lines)] + [(t, -5.0, 0.6) for t in piece.title[:1]]
    k = 0
    for label in piece_labels(piece, Unit.MM, block=block_lines):
        if label.kind == "bend":
            continue
        layer = "1" if label.kind == "title" and k < len(lines) else "15"
        k += label.kind == "title"
        add_text(block, label.text, label.at, label.height, angle=label.angle, layer=layer)
    doc.modelspace().add_blockref(name, (0.0, 0.0), dxfattribs={"layer": "1"})


def _export(doc, path) -> None:
    """Write an ASTM file as ezdxf's ``gerber_D6673`` add-on lays it out (no handles, only the piece
    blocks, which Gerber's reader needs), its empty header replaced by one declaring the units and
    followed by a TABLES section declaring every layer the pieces use."""
    import io

    from ezdxf.addons import gerber_D6673
    from ezdxf.lldxf.tagwriter import TagWriter

    stream = io.StringIO()
    gerber_D6673.export_stream(doc, stream)
    empty = "  0\nSECTION\n  2\nHEADER\n  0\nENDSEC\n"
    text = stream.getvalue()
    if not text.startswith(empty):  # pragma: no cover - the add-on's layout changed
        raise RuntimeError("ezdxf's gerber_D6673 add-on no longer writes an empty header first")
    tables = io.StringIO()
    writer = TagWriter(tables, write_handles=False, dxfversion=doc.dxfversion)
    tables.write("  0\nSECTION\n  2\nTABLES\n")
    doc.tables.linetypes.export_dxf(writer)
    doc.tables.layers.export_dxf(writer)
    tables.write("  0\nENDSEC\n")
    header = (f"  0\nSECTION\n  2\nHEADER\n  9\n$INSUNITS\n 70\n{Unit.MM.insunits}\n  9\n$MEASUREMENT\n 70\n"
              f"{Unit.MM.measurement}\n  0\nENDSEC\n")
    Path(path).write_text(header + tables.getvalue() + text[len(empty):], encoding="ascii", errors="dxfreplace")


def write(drawing: Drawing, path, options: WriteOptions) -> None:
    """Write a drawing as an ASTM D6673 DXF (atomically)."""
    doc = new_doc("R12", 0)
    for layer in ASTM_LAYERS:
        doc.layers.add(str(layer))
    style = printable(drawing.name)
    used = set()
    for piece in drawing.pieces:
        _block(doc, piece, _block_name(piece.name, used), style)
    # The style's own text, in model space above the pieces (ASTM D6673 / AAMA): which standard,
    # style, date, author, sample size, grade rule table (none: one size) and units.
    top = max(p.bounds[3] for p in drawing.pieces)
    left = min(p.bounds[0] for p in drawing.pieces)
    th = drawing.pieces[0].text_height
    lines = [ASTM_VERSION, f"Style Name:{style}", f"Creation Date:{_creation_date()}", "Author:patterns",
             f"Sample Size:{SAMPLE_SIZE}", "Grading Rule Table:", "Units:METRIC"]
    for k, line in enumerate(lines):  # the version line on top
        add_text(doc.modelspace(), line, (left, top + th * (len(lines) - k)), 0.6 * th, layer="1",
                 align="BOTTOM_LEFT")
    with atomic_output(path, what="DXF file") as tmp:
        _export(doc, tmp)
