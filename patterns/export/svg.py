"""The SVG profile: for laser and vinyl cutters, and for the browser -- 1:1 in millimetres.

The page is as large as the drawing (``width``/``height`` in mm, one user
unit a millimetre), y up as in the DXF (the drawing is flipped into SVG's y-down
page, nothing scaled).  Strokes follow the colour convention the common laser
software and services read, by operation:

* **cut** -- red ``#FF0000``: every outline and hole, one closed path each,
  arcs as true SVG arcs (LightBurn layer 02, a Glowforge "cut" step);
* **score** -- blue ``#0000FF``: sew lines, notches, grain, drill marks,
  bend lines (dashed) and the rims of countersunk and counterbored holes (a
  mark where the machinist countersinks; the hole itself is cut at its through
  diameter) (LightBurn layer 01, a Glowforge "score" step);
* **engrave** -- black ``#000000`` filled text: names, strains, seam lengths,
  bend labels (LightBurn layer 00, a Glowforge "engrave" step).

Strokes are hairlines (0.1 mm).  Each operation is an Inkscape layer
(``inkscape:groupmode="layer"``), so that Inkscape, and cutters that import by
layer, see three.  A nest's stock is left out (it is not cut).
"""

from __future__ import annotations

from xml.sax.saxutils import escape

import numpy as np

from ..curves import Arc, Loop
from ..files import atomic_output
from ..pieces import MARGIN, Drawing, piece_labels
from ..pieces.allowance import straight_runs
from ..units import Unit
from .options import WriteOptions

__all__ = ["COLOURS", "write"]

COLOURS = {"cut": "#FF0000", "score": "#0000FF", "engrave": "#000000"}
"""Stroke (and text fill) colour of each operation."""

STROKE = 0.1
"""Stroke width, mm: a hairline for cutters."""

_CAP = 0.72
"""A font's cap height as a fraction of its size (the DXF's text height is the cap height)."""


class _Page:
    """SVG coordinates of drawing points: y flipped about the page's height (mm)."""

    def __init__(self, height: float):
        self.height = height

    def xy(self, p) -> str:
        return f"{p[0]:.4f} {self.height - p[1]:.4f}"

    def loop(self, loop: Loop) -> str:
        """One closed path: lines as L, arcs as SVG arcs (a full circle as two halves)."""
        out = []
        for piece in loop.pieces:
            if isinstance(piece, Arc):
                halves = 2 if piece.is_circle else 1
                for k in range(halves):
                    sweep = piece.sweep / halves
                    a = piece.start + k * sweep
                    start = piece.center + piece.radius * np.array([np.cos(a), np.sin(a)])
                    end = piece.center + piece.radius * np.array([np.cos(a + sweep), np.sin(a + sweep)])
                    if not out:
                        out.append(f"M {self.xy(start)}")
                    large = 1 if abs(sweep) > np.pi else 0
                    # SVG's sweep flag 1 turns the positive way of the page's y-down axes: clockwise as seen.  The
                    # page's y-flip keeps what is seen (an arc counter-clockwise with y up is still seen so): 0
                    flag = 0 if sweep > 0 else 1
                    out.append(f"A {piece.radius:.4f} {piece.radius:.4f} 0 {large} {flag} {self.xy(end)}")
            else:
                pts = piece.points()
                if not out:
                    out.append(f"M {self.xy(pts[0])}")
                out.extend(f"L {self.xy(p)}" for p in pts[1:])
        return " ".join(out) + " Z"

    def polyline(self, points, close: bool) -> str:
        pts = np.asarray(points)
        return "M " + " L ".join(self.xy(p) for p in pts) + (" Z" if close else "")


def _layer(name: str, colour: str, body: list, *, fill: bool = False) -> str:
    paint = f'fill="{colour}" stroke="none"' if fill else f'fill="none" stroke="{colour}" stroke-width="{STROKE}"'
    return (f'<g id="{name}" inkscape:groupmode="layer" inkscape:label="{name}" {paint}>\n' + "\n".join(body)
            + "\n</g>")


def write(drawing: Drawing, path, options: WriteOptions) -> None:
    """Write a drawing as SVG at 1:1 in mm (atomically)."""
    _, _, x1, y1 = drawing.bounds
    width, height = x1 + MARGIN, y1 + MARGIN  # the drawing starts MARGIN from the axes: as much room beyond it
    page = _Page(height)
    cut, score, engrave = [], [], []
    for piece in drawing.pieces:
        for loop in (piece.outline, *piece.holes):
            cut.append(f'<path d="{page.loop(loop)}"/>')
        if piece.allowance:
            score += [f'<path d="{page.polyline(straight_runs(s), True)}"/>' for s in piece.sew]
        for notch in piece.notches:
            ends = [(notch.at, notch.tip)] if notch.mouth is None else [(notch.tip, e) for e in notch.mouth]
            score += [f'<path d="{page.polyline([a, b], False)}"/>' for a, b in ends]
        score += [f'<path d="{page.loop(Loop((rim.circle,)))}"/>' for rim in piece.rims]  # marked, never cut
        for tip in piece.drills:  # a drill mark: a small cross
            d = 0.5 * piece.text_height
            score += [f'<path d="{page.polyline([tip - [d, 0], tip + [d, 0]], False)}"/>',
                      f'<path d="{page.polyline([tip - [0, d], tip + [0, d]], False)}"/>']
        if piece.grain is not None:
            score.append(f'<path d="{page.polyline(piece.grain, False)}"/>')
        if options.bend_lines:
            score += [f'<path d="{page.polyline(b.line, False)}" stroke-dasharray="3 2"/>' for b in piece.bends]
        for label in piece_labels(piece, Unit.MM):  # as the piece keeps them (placed anew only if not in mm)
            if label.kind == "bend" and not options.bend_lines:
                continue
            x, y = label.at[0], height - label.at[1]
            engrave.append(f'<text x="{x:.4f}" y="{y:.4f}" font-size="{label.height / _CAP:.4f}" '
                           f'font-family="sans-serif" text-anchor="middle" dominant-baseline="central" '
                           f'transform="rotate({-label.angle:.4f} {x:.4f} {y:.4f})">{escape(label.text)}</text>')
    text = (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<svg xmlns="http://www.w3.org/2000/svg" '
            f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
            f'width="{width:.4f}mm" height="{height:.4f}mm" viewBox="0 0 {width:.4f} {height:.4f}">\n'
            f'<title>{escape(drawing.name)}</title>\n<desc>patterns: 1:1, mm; red cut, blue score, black '
            f'engrave</desc>\n'
            + "\n".join([_layer("cut", COLOURS["cut"], cut), _layer("score", COLOURS["score"], score),
                         _layer("engrave", COLOURS["engrave"], engrave, fill=True)]) + "\n</svg>\n")
    with atomic_output(path, what="SVG file") as tmp:
        tmp.write_text(text, encoding="utf-8")
