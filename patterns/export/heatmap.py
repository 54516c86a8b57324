"""Strain heat maps of a pattern: PNG or SVG, with matplotlib.

Each panel is drawn flat, every triangle coloured by its dominant strain (the
principal strain of larger magnitude: blue where the flat pattern is shorter
than the surface, red where it is longer), with its outline, its seams and its
name (at the point of the panel farthest from its edges and holes, never in a
hole).  The colour bar's ticks are percentages, never a scientific multiplier;
a strain-free part's bar spans +-:data:`SMALLEST_SCALE` about a plain 0 %.
People look at this before cutting.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import atomic_output
from ..mesh import extent
from ..options import check_number, check_ratio
from ..pattern import Pattern
from ..pieces.drawing import row_offsets
from ..text import printable

__all__ = ["HEAT_MAP_FORMATS", "SMALLEST_SCALE", "display_offsets", "finding_marks", "heat_map", "heat_map_figure",
           "percent_tick"]

HEAT_MAP_FORMATS = (".png", ".svg")
"""File suffixes :func:`heat_map` writes."""

SMALLEST_SCALE = 0.001
"""The least half-range of the colour scale when no ``max_strain`` is given (0.001 = 0.1 %): a part with
no strain (all planar, or developed exactly) gets a bar from -0.1 % to 0.1 % about 0 %, not one of
+-1e-6 with a scientific multiplier."""


def display_offsets(pattern, *, gap: float | None = None) -> np.ndarray:
    """Where to put each panel of a pattern that is not laid out, for a picture: rows of bounding boxes
    (:func:`patterns.pieces.drawing.row_offsets`), ``(k, 2)`` mm; all zero once the pattern is laid out."""
    if pattern.laid_out:
        return np.zeros((len(pattern.panels), 2))
    return row_offsets([np.r_[p.uv.min(axis=0), p.uv.max(axis=0)] for p in pattern.panels], gap=gap)


def finding_marks(pattern, offsets) -> list:
    """``[(code, (k, 2) points mm)]``: each finding of :func:`patterns.check` that has points, moved by its panel's
    offset in the picture -- the same points the report gives, where the heat map draws that panel."""
    from ..audit import check

    names = {flat.name: k for k, flat in enumerate(pattern.panels)}
    out = []
    for f in check(pattern).findings:
        if len(f.points) and f.panels and f.panels[0] in names:
            out.append((f.code.value, np.asarray(f.points, dtype=np.float64) + offsets[names[f.panels[0]]]))
    return out


def percent_tick(scale: float):
    """A colour-bar tick formatter for strains in %, the bar spanning +-``scale`` %: ``"0.075%"``, ``"0%"``,
    ``"−15%"`` -- three significant digits of the scale, trailing zeros dropped, never an exponent."""
    decimals = max(0, 2 - int(np.floor(np.log10(scale)))) if scale > 0 else 0

    def tick(value, _position=None) -> str:
        text = f"{value:.{decimals}f}".rstrip("0").rstrip(".") if decimals else f"{value:.0f}"
        return "0%" if text in ("0", "-0") else text.replace("-", "\N{MINUS SIGN}") + "%"

    return tick


def heat_map(pattern, path, *, max_strain: float | None = None, title: str | None = None, dpi: int = 150) -> None:
    """Draw the strain heat map of a pattern to a PNG or SVG file.

    Parameters
    ----------
    pattern : patterns.Pattern
    path : str or Path
        ``.png`` or ``.svg``; written atomically (a failed write leaves no file).
    max_strain : float, optional
        Colour scale limit (0.03 = 3 %): strains beyond it are drawn at full
        colour.  Default: the largest strain in the pattern, and at least
        :data:`SMALLEST_SCALE` (0.1 %: a strain-free part's bar reads -0.1 % .. 0 % .. 0.1 %).
    title : str, optional
        Default: the pattern's name with its RMS and largest strain.

    Every finding of :func:`patterns.check` that has points is marked where it is (an ``x`` at each point,
    numbered, with its code), in the picture's frame: its panel moved as the picture lays it out.
    dpi : float
        PNG resolution, 10 to 1200 (the figure is 10 x 7 inches).

    Raises
    ------
    InputError
        An unknown suffix or a bad limit.
    ExportError
        The file cannot be written.
    """
    path = Path(path)
    if not isinstance(pattern, Pattern):
        kind = type(pattern).__name__
        why = ("a blank is unfolded exactly, its strain 0 everywhere: there is nothing to colour (draw it with "
               "patterns.write(blank, 'blank.svg') or patterns.preview_dxf)" if kind == "Blank" else
               "give the Pattern patterns.flatten returned")
        raise InputError(f"{path}: a heat map draws a flattened pattern's strain, not a {kind}; {why}")
    suffix = path.suffix.lower()
    if suffix not in HEAT_MAP_FORMATS:
        raise InputError(f"{path}: heat maps are written as {' or '.join(HEAT_MAP_FORMATS)}, not {suffix or '(none)'!r}")
    if max_strain is not None:
        max_strain = check_ratio(max_strain, "max_strain", name=str(path))
    dpi = check_number(dpi, "dpi", low=10, high=1200, name=str(path))  # a 10 x 7 inch figure: 100 MP at most
    fig = heat_map_figure(pattern, max_strain=max_strain, title=title, rasterized=suffix == ".svg")
    with atomic_output(path, what="heat map") as tmp:
        fig.savefig(tmp, format=suffix[1:], dpi=dpi)


def heat_map_figure(pattern, *, max_strain: float | None = None, title: str | None = None,
                    rasterized: bool = False):
    """The heat map of :func:`heat_map` as a matplotlib ``Figure`` (10 x 7 inches, not drawn yet): its
    first axes the panels, its second the colour bar (ticks in %).  ``max_strain`` is taken as checked
    (a fraction); ``rasterized`` draws the triangles as an image (for SVG)."""
    from matplotlib.collections import LineCollection
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter
    from shapely import Polygon
    from shapely.ops import polylabel

    offsets = display_offsets(pattern)
    strains = [p.strains for p in pattern.panels]
    worst = max(float(np.max(np.abs(s.dominant))) for s in strains)
    limit = float(max_strain) if max_strain is not None else max(worst, SMALLEST_SCALE)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=-100.0 * limit, vmax=100.0 * limit)
    fig = Figure(figsize=(10, 7), layout="constrained")
    ax = fig.add_subplot()
    mappable = None
    total_w = sum(float(s.area_3d.sum()) for s in strains)
    rms = np.sqrt(sum(0.5 * float(np.sum(s.area_3d * (s.strain**2).sum(axis=1))) for s in strains) / total_w)
    for flat, s, off in zip(pattern.panels, strains, offsets):
        uv = flat.uv + off
        mappable = ax.tripcolor(uv[:, 0], uv[:, 1], flat.faces, facecolors=100.0 * s.dominant, cmap="RdBu_r",
                                norm=norm, edgecolors="none", rasterized=rasterized)
        for loop in flat.loops:
            ring = uv[np.r_[loop, loop[:1]]]
            ax.plot(ring[:, 0], ring[:, 1], color="black", linewidth=0.8)
        panel = Polygon(uv[flat.loops[0]], [uv[loop] for loop in flat.loops[1:]])
        size = extent(uv[flat.loops[0]])
        centre = np.array(polylabel(panel, tolerance=max(size, 1e-9) / 1000).coords[0]) if panel.is_valid \
            else uv[flat.loops[0]].mean(axis=0)  # inside the panel, as far from its edges and holes as can be
        ax.annotate(printable(flat.name), centre, ha="center", va="center", fontsize=9, parse_math=False,
                    bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.7, "linewidth": 0})
    segments = []
    for fs in pattern.seams:
        seam = fs.seam
        for side, (p, idx) in enumerate(zip(seam.panels, seam.vertices)):
            pts = pattern.panels[p].uv[idx] + offsets[p]
            segments.append(pts)
            mid = pts[len(pts) // 2]
            ax.annotate(f"s{seam.id}", mid, fontsize=7, color="darkgreen", ha="center", va="center")
    if segments:
        ax.add_collection(LineCollection(segments, colors="darkgreen", linewidths=1.6, linestyles="dashed"))
    for k, (code, at) in enumerate(finding_marks(pattern, offsets), start=1):  # where each finding is, as drawn
        ax.plot(at[:, 0], at[:, 1], "x", color="black", markersize=6, markeredgewidth=1.5)
        ax.annotate(f"{k} {code}", at[0], xytext=(4, 4), textcoords="offset points", fontsize=7, parse_math=False,
                    bbox={"boxstyle": "round", "facecolor": "yellow", "alpha": 0.8, "linewidth": 0})
    ax.set_aspect("equal")
    ax.set_xlabel("mm")
    ax.set_ylabel("mm")
    ax.set_title(printable(title) if title is not None else
                 f"{printable(pattern.name)}: strain RMS {rms:.2%}, largest {worst:.2%} (dashed: seams)",
                 parse_math=False)  # names are data: "$x$" stays the text it is
    bar = fig.colorbar(mappable, ax=ax, shrink=0.8, extend="both" if worst > limit else "neither",
                       format=FuncFormatter(percent_tick(100.0 * limit)))  # no offset, no multiplier
    bar.set_label("strain  (blue: flat shorter than the surface, red: longer)")
    return fig
