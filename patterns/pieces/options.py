"""What goes onto a piece: seam allowance, notches, rulings, arcs, labels -- declared once.

:class:`PieceOptions` is the one declaration of these options for the API
(:func:`patterns.pieces.pieces_of`, :func:`patterns.write`,
:func:`patterns.layout`), the command line (its flags are made from it) and
batches.  :func:`check_marks` refuses, before any drawing, a spacing that would
draw more marks than a file should hold.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..options import Options, check_number, is_number, option

__all__ = ["MAX_MARKS", "MAX_SEAM_ALLOWANCE", "NOTCH_STYLES", "PATTERN_ONLY", "SEAM_CORNERS", "SMALLEST_PANEL",
           "PieceOptions", "check_marks"]

NOTCH_STYLES = ("slit", "v")
"""Notch shapes: a slit across the seam allowance, or a V."""

SEAM_CORNERS = ("mitre", "bevel", "square")
"""Corners of the seam allowance."""

MAX_SEAM_ALLOWANCE = 1000.0
"""The largest seam allowance, mm: a metre of cloth or sheet outside the seam line is not an allowance."""

MAX_MARKS = 100_000
"""The most notches, and the most bend lines, one file gets: a spacing that would draw more
(a notch every 0.1 mm) is refused before anything is drawn."""

SMALLEST_PANEL = 0.01
"""The smallest panel drawn, mm across: ten times the 0.001 mm to which straight runs are drawn."""


def _seam_allowance(value, option):
    """A number (mm, 0..1000) or a mapping ``{seam id or None: mm}``, checked (seam ids against the pattern later)."""
    if isinstance(value, Mapping):
        return {key: check_number(mm, f"{option}[{key!r}] (mm)", low=0, high=MAX_SEAM_ALLOWANCE)
                for key, mm in value.items()}
    if is_number(value):
        return check_number(value, f"{option} (mm)", low=0, high=MAX_SEAM_ALLOWANCE)
    raise InputError(f"{option} must be a number (mm) or a mapping of seam ids to mm, got {type(value).__name__}")


@dataclass(frozen=True, repr=False)
class PieceOptions(Options):
    """What is cut and marked on each piece (:func:`patterns.pieces.pieces_of`, :func:`patterns.write`,
    ``patterns flatten -o``)."""

    seam_allowance: float | dict = option(0.0, "seam allowance added outside the seam line, mm, on every edge (API: also "
                                               "a mapping of seam ids to mm, the key None for every other edge); the "
                                               "seam line then goes on SEW (ASTM layer 14)",
                                          check=_seam_allowance, parse=float, unit="mm")
    seam_corners: str = option("mitre", "corners of the seam allowance: offset lines meeting at a point (mitre), "
                                        "cut straight across at the allowance (bevel), or each side's allowance "
                                        "run straight on past the corner (square)",
                               choices=SEAM_CORNERS)
    mitre_limit: float = option(2.0, "a mitred corner reaching further than this many allowances from its seam "
                                     "line is bevelled there (garment CAD's corner limit; 2 keeps a square "
                                     "corner's mitre, 1.41, and bevels the tip of a gore)",
                                low=1.0, high=10.0, metavar="K")
    notch_spacing: float | None = option(None, "matching notches along every seam every this many mm of 3D "
                                               "length, on both panels (default: at the seam ends only)",
                                         low=0, low_open=True, optional=True, unit="mm")
    notch_style: str = option("slit", "notch shape: a slit across the seam allowance, or a V", choices=NOTCH_STYLES)
    bend_spacing: float | None = option(None, "draw the rulings of exactly developed cylinders and cones about "
                                              "this far apart (mm) with their bend angles (a blank's bends are "
                                              "always drawn)", low=0, low_open=True, optional=True, unit="mm")
    arcs: bool = option(False, "cut contours of flattened panels as arcs and lines fitted within arc_tolerance (a "
                               "blank's are exact lines and arcs already)")
    arc_tolerance: float = option(0.01, "largest distance of the fitted arcs from the contour, mm",
                                  low=0, low_open=True, unit="mm")
    text_height: float | None = option(None, "label height, mm (default 3 % of each piece's size, 2-12 mm); no label "
                                             "is drawn below 2 mm (or below a smaller height given here): one that "
                                             "does not fit is left out, with a label-left-out note",
                                       low=0, low_open=True, optional=True, unit="mm")
    gap: float | None = option(None, "space between pieces when they are not nested, mm (default 8 % of the largest)",
                               low=0, optional=True, unit="mm")
    strain_layer: bool = option(False, "the strain heat map as filled triangles on layer STRAIN (DXF machine "
                                       "profile; true colour from R2004)")

    @property
    def largest_allowance(self) -> float:
        """Deprecated (goes in 0.3.0; nothing reads it): the widest seam allowance asked for, mm."""
        import warnings

        warnings.warn("PieceOptions.largest_allowance is deprecated and goes in 0.3.0: use patterns.PieceOptions's "
                      "seam_allowance (max of its values, for a mapping)", DeprecationWarning, stacklevel=2)
        a = self.seam_allowance
        return max(a.values(), default=0.0) if isinstance(a, Mapping) else float(a)


PATTERN_ONLY = ("seam_allowance", "seam_corners", "mitre_limit", "notch_spacing", "notch_style", "bend_spacing", "arcs",
                "arc_tolerance", "strain_layer")
"""The options only a flattened pattern's pieces have (seams, rulings, fitted arcs, strain): a blank takes the others."""


def check_marks(name: str, seam_lengths, panel_sizes, options: PieceOptions) -> None:
    """InputError when a panel is too small to draw (:data:`SMALLEST_PANEL`), or when ``notch_spacing`` or
    ``bend_spacing`` would draw more than :data:`MAX_MARKS` marks.

    Parameters
    ----------
    name : str
        The part, for the message.
    seam_lengths : sequence of float
        Every seam's 3D length, mm (a notch every ``notch_spacing`` on each side).
    panel_sizes : sequence of float
        Every panel's largest extent, mm (a bend line every ``bend_spacing`` across it, at most).
    options : PieceOptions
    """
    small = [size for size in panel_sizes if not size >= SMALLEST_PANEL]
    if small:
        raise InputError(f"{name}: a panel {small[0]:.3g} mm across, under the {SMALLEST_PANEL:g} mm a DXF draws "
                         f"a panel at (parts are read in mm: check the file's unit)")
    total = float(np.sum(seam_lengths)) if len(seam_lengths) else 0.0
    if options.notch_spacing:
        notches = 2 * (total / options.notch_spacing + len(seam_lengths))
        if notches > MAX_MARKS:
            raise InputError(f"{name}: notch_spacing {options.notch_spacing:g} mm would draw about {notches:.3g} "
                             f"notches along {total:.0f} mm of seams; at most {MAX_MARKS} are drawn: give a larger "
                             f"spacing")
    if options.bend_spacing:
        lines = float(np.sum(panel_sizes)) / options.bend_spacing if len(panel_sizes) else 0.0
        if lines > MAX_MARKS:
            raise InputError(f"{name}: bend_spacing {options.bend_spacing:g} mm would draw up to {lines:.3g} bend "
                             f"lines across {len(panel_sizes)} panels; at most {MAX_MARKS} are drawn: give a "
                             f"larger spacing")
