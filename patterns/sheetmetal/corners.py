"""Corners where bends meet, drawn as a shop's CAD draws them (part of stage 5 of an unfold).

Where two bends meet at a closed corner (a tray, a box), the model's bend
zones end in curved edges against the corner's closing faces (a mitre cut
through a cylinder is an ellipse, and an ellipse rolled out is a wave).
Developed as they are, those edges leave a curved tongue of a few mm at
the corner, which a laser would cut as a spike.  SolidWorks draws no such
tongue: the side edges of the two flanges run on, straight, until they meet.

:func:`treat_corners` finds every such run on a cut loop -- pieces that are
ends of bend faces and not straight (a straight end is a ruling of the bend,
already what every CAD draws), between two straight edges -- and replaces it
by the corner its option names:

``"none"`` (the default, SolidWorks' closed corner)
    The two straight edges on either side, extended to where they meet.
``"rectangular"``
    The rectangle where the two bend zones cross is cut out: the edges run
    to the zones' inside tangent lines and meet at the inside corner of the
    flat face between the bends (a square relief "tangent to the bends").
    Given a size, a square of that side centred on the bend lines' crossing
    (a parallelogram with sides along the bend lines where they are not
    square), as SolidWorks' rectangular relief "centred on bend lines".
``"round"``
    A circle about the crossing of the two bend lines through that inside
    corner (so it clears both bend zones), the edges cut back to it; given a
    size, a circle of that diameter about the crossing.

A relief of a given size that does not reach a flange's edge (smaller than
the flange's edge is far from the crossing) cannot be cut as asked: that
corner is drawn closed and said (``relief-not-drawn``).
``"tear"``
    No material taken out: a straight rip from each flange's edge to the
    inside corner (a V-shaped slit).
``"as-modelled"``
    The corner developed as the model has it, tongue and all (what FreeCAD's
    SheetMetal unfolder draws); the blank then has ``outline-cusp`` notes.

A run that is not the ends of two bends, between two straight edges that
meet within :data:`REACH` of it, is left as the model has it (one bend's end
cut on the slant is developed as it is: SolidWorks does the same).
"""

from __future__ import annotations

import numpy as np

from ..curves import Arc, Line, Polyline

__all__ = ["CORNER_RELIEFS", "REACH", "SIZED_RELIEFS", "treat_corners"]

CORNER_RELIEFS = ("none", "rectangular", "round", "tear", "as-modelled")
"""The corner treatments :func:`treat_corners` knows (``UnfoldOptions.corner_relief``)."""
SIZED_RELIEFS = ("rectangular", "round")
"""The corner reliefs that take a size (``UnfoldOptions.corner_relief_size`` or ``corner_relief_ratio``): the
square's side or the circle's diameter, centred on the crossing of the two bend lines."""

REACH = 3.0
"""Two edges meet "at" a corner when their crossing lies within this many thicknesses of the run they replace."""


SHORT = 0.1
"""A cut piece shorter than this many thicknesses between two bend ends is part of the corner they make."""


def _ends(piece) -> tuple:
    if isinstance(piece, Arc):
        return piece.start_point, piece.end_point
    pts = piece.points()
    return pts[0], pts[-1]


def _cross(p, d, q, e):
    """The crossing of the lines ``p + s d`` and ``q + t e``: ``(point, s, t)``, or None when parallel."""
    m = np.column_stack([d, -e])
    if abs(np.linalg.det(m)) < 1e-9 * np.linalg.norm(d) * np.linalg.norm(e):
        return None
    s, t = np.linalg.solve(m, q - p)
    return p + s * d, float(s), float(t)


def _runs(items: list, short: float) -> list:
    """Index runs (start, length) of consecutive bend-end items, cyclically; never the whole loop.  A piece
    shorter than ``short`` between two bend ends (a slit that nicks the flat face beside them) joins the run."""
    n = len(items)
    flags = [it[2] for it in items]
    for i in range(n):
        piece = items[i][0]
        if not flags[i] and flags[i - 1] and flags[(i + 1) % n] and np.linalg.norm(np.subtract(*_ends(piece))) < short:
            flags[i] = True
    if all(flags) or not any(flags):
        return []
    first = next(k for k in range(n) if not flags[k])  # start scanning at a piece that is no bend end
    runs, k = [], 1
    while k <= n:
        i = (first + k) % n
        if flags[i]:
            j = k
            while flags[(first + j) % n]:
                j += 1
            runs.append(((first + k) % n, j - k))
            k = j
        else:
            k += 1
    return runs


def treat_corners(items: list, *, relief: str, thickness: float, bend_lines: dict, size: float | None = None,
                  missed: list | None = None) -> list:
    """One cut loop with the corners where bends meet treated as ``relief`` says.

    Parameters
    ----------
    items : list of (piece, face, bend_end)
        The loop's pieces in order (each ending where the next starts), the skin
        face each came from, and whether it is a curved end of a bend face.
    relief : str
        One of :data:`CORNER_RELIEFS`.
    thickness : float
        The sheet's thickness, mm (how far an edge may be extended: :data:`REACH`).
    bend_lines : dict
        ``{face: ((2, 2) float64, float)}``: the centre line of the bend each bend face belongs to and half
        its developed width, mm.
    size : float, optional
        A rectangular or round relief's size, mm (the square's side, the circle's diameter), centred on the
        bend lines' crossing; default: just clear both bend zones.
    missed : list, optional
        Gets the ``(2,) float64`` crossing of the bend lines, mm, of each corner where a relief of ``size``
        does not reach a flange's edge (that corner is drawn closed).

    Returns
    -------
    list of (piece, face)
        The loop's pieces; the input is not changed.
    """
    runs = [] if relief == "as-modelled" else _runs(items, SHORT * thickness)
    if not runs:
        return [(p, f) for p, f, _ in items]
    n = len(items)
    out = {k: (p, f) for k, (p, f, _) in enumerate(items)}
    for start, length in runs:
        idx = [(start + j) % n for j in range(length)]
        before, after = (start - 1) % n, (start + length) % n
        a, b = items[before][0], items[after][0]
        if not (isinstance(a, Line) and isinstance(b, Line)) or before == after:
            continue
        bends = {id(bend_lines[items[k][1]][0]) if items[k][1] in bend_lines else items[k][1] for k in idx
                 if items[k][2]}
        if len(bends) < 2:
            continue  # one bend's end cut on the slant: developed as it is, as every CAD does
        da, db = a.end - a.start, b.end - b.start
        hit = _cross(a.end, da, b.start, db)
        if hit is None:
            continue
        corner, s, t = hit
        run_pts = np.vstack([items[k][0].points(0.01) for k in idx])
        if s < -1e-9 or t > 1e-9 or np.min(np.linalg.norm(run_pts - corner, axis=1)) > REACH * thickness:
            continue  # the edges do not run on to meet beside this run
        ends = [k for k in idx if items[k][2]]  # the bend ends themselves (not a short nick between them)
        faces = [items[k][1] for k in ends]
        change = [j for j in range(1, len(ends)) if faces[j] != faces[j - 1]]
        inner = None
        if len(change) == 1:  # the ends of two bends, meeting at the inside corner of the face between them
            j = change[0]
            inner = 0.5 * (_ends(items[ends[j - 1]][0])[1] + _ends(items[ends[j]][0])[0])
        lines = [bend_lines.get(faces[0]), bend_lines.get(faces[-1])]
        new = _corner(relief, a, b, corner, inner, lines, size)
        if isinstance(new, np.ndarray):  # the relief asked for does not reach a flange's edge: closed, and said
            if missed is not None:
                missed.append(new)
            new = None
        if new is None:
            new_a, middle, new_b = Line(a.start, corner), [], Line(corner, b.end)
        else:
            new_a, middle, new_b = new
        out[before] = (new_a, items[before][1])
        out[after] = (new_b, items[after][1])
        for j, k in enumerate(idx):
            out[k] = None
        face = items[idx[0]][1]
        out[idx[0]] = [(piece, face) for piece in middle] or None
    loop = []
    for k in range(n):
        v = out[k]
        if v is None:
            continue
        loop.extend(v if isinstance(v, list) else [v])
    return [(p, f) for p, f in loop if not (isinstance(p, Line) and p.length < 1e-9)]


def _inside_corner(near, lines):
    """The corner of the square where two bend zones cross nearest ``near``: where the lines ``half`` off
    each bend line meet (``lines``: two ``((2, 2) line, half width)``); None when either is unknown."""
    if any(z is None for z in lines):
        return None
    best = None
    (p, q), h1 = lines[0]
    (r, w), h2 = lines[1]
    n1 = np.array([-(q - p)[1], (q - p)[0]]) / np.linalg.norm(q - p)
    n2 = np.array([-(w - r)[1], (w - r)[0]]) / np.linalg.norm(w - r)
    for s1 in (-1, 1):
        for s2 in (-1, 1):
            hit = _cross(p + s1 * h1 * n1, q - p, r + s2 * h2 * n2, w - r)
            if hit is not None and (best is None or np.linalg.norm(hit[0] - near) < np.linalg.norm(best - near)):
                best = hit[0]
    return best


def _corner(relief, a: Line, b: Line, corner, inner, lines, size=None):
    """``(a', [pieces between], b')`` for a relief, None for the plain corner (``"none"``, or no inside corner),
    or the bend lines' crossing ((2,) float64) where a relief of ``size`` does not reach a flange's edge."""
    if relief == "none" or inner is None:
        return None
    inner = _inside_corner(inner, lines)  # exact, even where the model's mitre nicks the face between the bends
    if inner is None:
        return None
    da, db = (a.end - a.start), (b.end - b.start)
    da, db = da / np.linalg.norm(da), db / np.linalg.norm(db)
    if relief == "tear":
        return a, [Line(a.end, inner), Line(inner, b.start)], b
    (p, q), (r, w) = lines[0][0], lines[1][0]
    hit = _cross(p, q - p, r, w - r)
    if hit is None:
        return None
    centre = hit[0]
    if relief == "rectangular" and size is not None:
        return _sized_square(a, b, da, db, inner, lines, size, centre)
    if relief == "rectangular":
        q1 = inner + ((a.end - inner) @ da) * da  # a's end, dropped onto the line through the inside corner along a
        q2 = inner + ((b.start - inner) @ db) * db
        return a, [Line(a.end, q1), Line(q1, inner), Line(inner, q2), Line(q2, b.start)], b
    # round: about the crossing of the two bend lines, through the inside corner (or of the diameter asked)
    radius = float(np.linalg.norm(inner - centre)) if size is None else size / 2
    ea, eb = _on_circle(a.start, da, centre, radius, first=True), _on_circle(b.start, db, centre, radius, first=False)
    if ea is None or eb is None:
        return None if size is None else centre
    if size is not None and ((ea - a.start) @ da <= 0 or (b.end - eb) @ db <= 0):
        return centre  # the circle takes a flange's whole edge
    start = float(np.arctan2(*(ea - centre)[::-1]))
    end = float(np.arctan2(*(eb - centre)[::-1]))
    via = float(np.arctan2(*(inner - centre)[::-1]))  # the arc goes round by the inside corner
    sweep = (end - start) % (2 * np.pi)
    if (via - start) % (2 * np.pi) > sweep:
        sweep -= 2 * np.pi
    return Line(a.start, ea), [Arc(centre, radius, start, sweep)], Line(eb, b.end)


def _sized_square(a: Line, b: Line, da, db, inner, lines, size: float, centre):
    """The rectangular relief of side ``size`` centred on the bend lines' crossing ``centre``: ``(a', [pieces],
    b')``, or ``centre`` when a flange's edge does not cross it.  ``a`` is the edge of the flange beyond the
    first bend (``lines[0]``), ``b`` of the one beyond the second; ``inner`` the inside corner of the face
    between the bends (it says on which side of each bend line that face lies)."""
    (p, q), _ = lines[0]
    (r, w), _ = lines[1]
    u, v = (q - p) / np.linalg.norm(q - p), (w - r) / np.linalg.norm(w - r)
    n1, n2 = np.array([-u[1], u[0]]), np.array([-v[1], v[0]])
    s1, s2 = np.sign((inner - centre) @ n1), np.sign((inner - centre) @ n2)  # the flat face's side of each line
    half = size / 2

    def at(k1, k2):  # the relief's corner k1 half sizes off the first bend line, k2 off the second
        return _cross(centre + k1 * half * n1, u, centre + k2 * half * n2, v)[0]

    near, q1, q2 = at(s1, s2), at(-s1, s2), at(s1, -s2)
    ea, eb = _cross(a.start, da, centre - s1 * half * n1, u), _cross(b.start, db, centre - s2 * half * n2, v)
    if ea is None or eb is None:
        return centre
    ea, eb = ea[0], eb[0]
    far = at(-s1, -s2)  # the corner across from the flat face: each flange's edge crosses a side that ends there
    on_side = all(np.dot(e - x, e - far) <= 1e-12 * size * size for e, x in ((ea, q1), (eb, q2)))
    if not on_side or (ea - a.start) @ da <= 0 or (b.end - eb) @ db <= 0:
        return centre  # a flange's edge passes by the relief, or the relief takes its whole edge
    return Line(a.start, ea), [Line(ea, q1), Line(q1, near), Line(near, q2), Line(q2, eb)], Line(eb, b.end)


def _on_circle(p, d, centre, radius, *, first: bool):
    """Where the line ``p + s d`` (``d`` a unit vector) crosses the circle: the first crossing, or the last."""
    f = p - centre
    bq = f @ d
    disc = bq * bq - (f @ f - radius * radius)
    if disc < 0:
        return None
    s = -bq - np.sqrt(disc) if first else -bq + np.sqrt(disc)
    return p + s * d


def is_bend_end(piece, kind: str) -> bool:
    """Whether a cut piece of a skin face of ``kind`` is a curved end of a bend (not a ruling)."""
    return kind in ("cylinder", "cone") and isinstance(piece, Polyline)
