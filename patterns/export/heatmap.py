"""Strain heat maps of a pattern: PNG or SVG, with matplotlib.

Each panel is drawn flat, every triangle coloured by its dominant strain (the
principal strain of larger magnitude: blue where the flat pattern is shorter
than the surface, red where it is longer), with its outline, its seams and its
name.  People look at this before cutting.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import atomic_output
from ..options import check_number
from ..pieces.drawing import row_offsets
from ..text import printable

__all__ = ["HEAT_MAP_FORMATS", "display_offsets", "heat_map"]

HEAT_MAP_FORMATS = (".png", ".svg")
"""File suffixes :func:`heat_map` writes."""


def display_offsets(pattern, *, gap: float | None = None) -> np.ndarray:
    """Where to put each panel of a pattern that is not laid out, for a picture: rows of bounding boxes
    (:func:`patterns.pieces.drawing.row_offsets`), ``(k, 2)`` mm; all zero once the pattern is laid out."""
    if pattern.laid_out:
        return np.zeros((len(pattern.panels), 2))
    return row_offsets([np.r_[p.uv.min(axis=0), p.uv.max(axis=0)] for p in pattern.panels], gap=gap)


def heat_map(pattern, path, *, max_strain: float | None = None, title: str | None = None, dpi: int = 150) -> None:
    """Draw the strain heat map of a pattern to a PNG or SVG file.

    Parameters
    ----------
    pattern : patterns.Pattern
    path : str or Path
        ``.png`` or ``.svg``; written atomically (a failed write leaves no file).
    max_strain : float, optional
        Colour scale limit (0.03 = 3 %): strains beyond it are drawn at full
        colour.  Default: the largest strain in the pattern.
    title : str, optional
        Default: the pattern's name with its RMS and largest strain.
    dpi : float
        PNG resolution, 10 to 1200 (the figure is 10 x 7 inches).

    Raises
    ------
    InputError
        An unknown suffix or a bad limit.
    ExportError
        The file cannot be written.
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.figure import Figure

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in HEAT_MAP_FORMATS:
        raise InputError(f"{path}: heat maps are written as {' or '.join(HEAT_MAP_FORMATS)}, not {suffix or '(none)'!r}")
    if max_strain is not None:
        max_strain = check_number(max_strain, "max_strain", low=0, low_open=True, name=str(path))
    dpi = check_number(dpi, "dpi", low=10, high=1200, name=str(path))  # a 10 x 7 inch figure: 100 MP at most
    offsets = display_offsets(pattern)
    strains = [p.strains for p in pattern.panels]
    worst = max(float(np.max(np.abs(s.dominant))) for s in strains)
    limit = float(max_strain) if max_strain is not None else max(worst, 1e-6)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=-100.0 * limit, vmax=100.0 * limit)
    fig = Figure(figsize=(10, 7), layout="constrained")
    ax = fig.add_subplot()
    mappable = None
    total_w = sum(float(s.area_3d.sum()) for s in strains)
    rms = np.sqrt(sum(0.5 * float(np.sum(s.area_3d * (s.strain**2).sum(axis=1))) for s in strains) / total_w)
    for flat, s, off in zip(pattern.panels, strains, offsets):
        uv = flat.uv + off
        mappable = ax.tripcolor(uv[:, 0], uv[:, 1], flat.faces, facecolors=100.0 * s.dominant, cmap="RdBu_r",
                                norm=norm, edgecolors="none", rasterized=suffix == ".svg")
        for loop in flat.loops:
            ring = uv[np.r_[loop, loop[:1]]]
            ax.plot(ring[:, 0], ring[:, 1], color="black", linewidth=0.8)
        centre = uv[flat.loops[0]].mean(axis=0)
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
    ax.set_aspect("equal")
    ax.set_xlabel("mm")
    ax.set_ylabel("mm")
    ax.set_title(printable(title) if title is not None else
                 f"{printable(pattern.name)}: strain RMS {rms:.2%}, largest {worst:.2%} (dashed: seams)",
                 parse_math=False)  # names are data: "$x$" stays the text it is
    bar = fig.colorbar(mappable, ax=ax, shrink=0.8, extend="both" if worst > limit else "neither")
    bar.set_label("strain, %  (blue: flat shorter than the surface, red: longer)")
    with atomic_output(path, what="heat map") as tmp:
        fig.savefig(tmp, format=suffix[1:], dpi=dpi)
