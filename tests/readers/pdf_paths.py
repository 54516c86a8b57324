"""The stroked line segments of a PDF that LibreCAD's ``dxf2pdf`` or Inkscape printed, in millimetres on paper.

LibreCAD (Qt's PDF engine) writes each page as one content stream: a transformation
(``a b c d e f cm``), then runs of ``r g b SCN`` (the stroke colour), ``x y m`` /
``x y l`` (move, line) and ``S`` (stroke).  Arcs and text come as many short lines.
Inkscape (cairo) writes ``RG`` colours and draws arcs as cubic Béziers (``c``), each
sampled here as 32 segments, and closes paths with ``h``.
This reads exactly those operators, applies the current matrix (``q``/``Q`` save and
restore it) and returns every stroked segment with its colour, in mm (1 pt = 25.4/72 mm),
so a test can measure what LibreCAD drew: at ``--scale 1`` a 200 mm edge must come out
200 mm long on paper.
"""

from __future__ import annotations

import itertools
import re
import zlib
from collections import defaultdict

import numpy as np

PT = 25.4 / 72.0
"""One PDF point, mm."""


def _streams(data: bytes):
    for raw in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", data, re.DOTALL):
        try:
            yield zlib.decompress(raw)
        except zlib.error:
            yield raw


def segments(path) -> dict:
    """``{(r, g, b): (k, 2, 2) float64 array of segments, mm}`` of every stroked path in the PDF at ``path``."""
    out = defaultdict(list)
    for stream in _streams(open(path, "rb").read()):
        tokens = stream.split()
        stack, operands = [], []
        ctm = np.eye(3)
        colour = (0.0, 0.0, 0.0)
        path_segments, current, start = [], None, None
        for tok in tokens:
            try:
                operands.append(float(tok))
                continue
            except ValueError:
                pass
            op = tok.decode("latin-1")
            if op == "cm" and len(operands) >= 6:
                a, b, c, d, e, f = operands[-6:]
                ctm = np.array([[a, b, 0.0], [c, d, 0.0], [e, f, 1.0]]) @ ctm
            elif op == "q":
                stack.append(ctm.copy())
            elif op == "Q" and stack:
                ctm = stack.pop()
            elif op in ("SCN", "RG") and len(operands) >= 3:
                colour = tuple(operands[-3:])
            elif op == "m" and len(operands) >= 2:
                current = start = _apply(ctm, operands[-2:])
            elif op == "l" and len(operands) >= 2 and current is not None:
                point = _apply(ctm, operands[-2:])
                path_segments.append((current, point))
                current = point
            elif op == "c" and len(operands) >= 6 and current is not None:
                given = operands[-6:]
                controls = [current] + [_apply(ctm, given[2 * k:2 * k + 2]) for k in range(3)]
                t = np.linspace(0.0, 1.0, 33)[:, None]
                c0, c1, c2, c3 = (np.array(c) for c in controls)
                pts = (1 - t) ** 3 * c0 + 3 * (1 - t) ** 2 * t * c1 + 3 * (1 - t) * t**2 * c2 + t**3 * c3
                path_segments.extend((tuple(a), tuple(b)) for a, b in itertools.pairwise(pts))
                current = tuple(pts[-1])
            elif op == "h" and current is not None and start is not None:
                path_segments.append((current, start))
                current = start
            elif op in ("S", "s"):
                out[colour].extend(path_segments)
                path_segments, current = [], None
            elif op in ("n", "f", "F", "f*", "B", "B*", "b", "b*", "W", "W*"):
                if op not in ("W", "W*"):
                    path_segments, current = [], None
            operands = []
        # anything left unstroked is not drawn
    return {k: np.array(v, dtype=float) * PT for k, v in out.items() if v}


def _apply(ctm, xy):
    x, y = xy
    p = np.array([x, y, 1.0]) @ ctm
    return (p[0], p[1])
