"""The JSON profile: the report, and every piece as drawn, in the drawing's frame.

One document per drawing (schema :data:`REPORT_SCHEMA`): the check report of
what the pieces were made from (``patterns.Report.to_dict``: verdict, limits,
panels, seams, blanks, findings) and, under ``pieces``, each piece as the DXF
and SVG of the same drawing draw it -- outline and holes as ``[x, y, bulge]``
rows, the rims of countersunk holes, sew lines, notches, drill holes, grain, bend lines with direction,
angle, inside radius and K-factor, seam sides, the labels as the DXF places
them (in mm), strain, findings -- every coordinate in mm in the DXF's frame
(the drawing's first quadrant).
"""

from __future__ import annotations

import json

import numpy as np

from ..files import atomic_output
from ..pieces import MARGIN, Drawing, Piece, piece_labels
from .options import WriteOptions

__all__ = ["REPORT_SCHEMA", "piece_dict", "write"]

REPORT_SCHEMA = "patterns.report/5"
"""The ``schema`` value of the JSON report (see docs/report.md)."""

_DIGITS = 4
"""Coordinates are written to 0.1 µm."""


def _xy(points) -> list:
    return np.round(np.asarray(points, dtype=np.float64), _DIGITS).tolist()


def piece_dict(piece: Piece) -> dict:
    """One piece as the JSON report gives it (mm, the drawing's frame)."""
    m = piece.placement
    return {
        "name": piece.name,
        "source": {"kind": piece.source.kind, "part": piece.source.part, "index": piece.source.index,
                   "faces": list(piece.source.faces), "copy": piece.source.copy},
        "placement": {"angle_deg": round(float(np.degrees(m.angle)), 9), "dx": round(m.dx, _DIGITS),
                      "dy": round(m.dy, _DIGITS), "mirrored": m.mirrored},
        "area_mm2": round(piece.area, 3),
        "outline": _xy(piece.outline.vertices()),
        "holes": [_xy(h.vertices()) for h in piece.holes],
        "rims": [r.to_dict() for r in piece.rims],
        "sew": [_xy(s) for s in piece.sew] if piece.allowance else [],
        "notches": [{"at": _xy(n.at), "tip": _xy(n.tip), "mouth": None if n.mouth is None else _xy(n.mouth)}
                    for n in piece.notches],
        "drills": _xy(piece.drills),
        "grain": None if piece.grain is None else _xy(piece.grain),
        "bends": [{"line": _xy(b.line), "sequence": b.sequence or None,
                   "angle_deg": round(b.angle, 4), "direction": b.direction,
                   "inside_radius_mm": b.inside_radius, "k_factor": b.k_factor,
                   "allowance_mm": None if b.allowance is None else round(b.allowance, 4)} for b in piece.bends],
        "seams": [{"seam": s.seam, "side": s.side, "length_3d_mm": s.length_3d, "length_flat_mm": s.length_flat}
                  for s in piece.seams],
        "labels": [{"text": label.text, "at": _xy(label.at), "height": round(label.height, 4),
                    "angle_deg": round(label.angle, 4), "kind": label.kind} for label in piece_labels(piece)],
        "strain": None if piece.strain is None else {"rms": piece.strain.rms, "p95": piece.strain.p95,
                                                     "p99": piece.strain.p99, "max": piece.strain.max},
        "findings": [f.to_dict() for f in piece.findings],
    }


def write(drawing: Drawing, path, options: WriteOptions) -> None:
    """Write the drawing's report and pieces as JSON (atomically; never a NaN)."""
    document = {"schema": REPORT_SCHEMA, **(drawing.report or {"pattern": drawing.name})}
    document["frame"] = {"units": "mm", "origin": f"the DXF's and the SVG's: x right, y up, the drawing "
                                                  f"{MARGIN:g} mm from both axes"}
    document["pieces"] = [piece_dict(p) for p in drawing.pieces]
    document["stock"] = [list(s) for s in drawing.stock]
    document["sheets"] = [s.to_dict() for s in drawing.sheets()]  # what a shop quotes each sheet from
    document["note"] = drawing.note
    text = json.dumps(document, indent=2, allow_nan=False)
    with atomic_output(path, what="report") as tmp:
        tmp.write_text(text + "\n", encoding="utf-8")
