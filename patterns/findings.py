"""What a check finds: one finding type for patterns and blanks alike (an auditor collects them).

:func:`patterns.check` reports a pattern's overlaps, strain and seams as
:class:`Finding` s; :func:`patterns.unfold` reports a blank's faults (flanges
that land on one another, a bend with no flange, a face that had to be meshed)
as the same records, with the same severities and one vocabulary of codes.
Geometry never raises: it becomes a finding with its place.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from .curves import Motion

__all__ = ["Code", "Finding", "Severity"]


class Severity(str, Enum):
    """How bad a :class:`Finding` is."""

    ERROR = "error"
    """The piece cannot be cut as it is (folds, overlaps, flanges that collide)."""
    LIMIT = "limit"
    """A limit the user asked for is exceeded (``max_strain``, ``max_seam_mismatch``), or a length the
    pattern was asked to keep is not kept."""
    NOTE = "note"
    """Worth knowing, not a failure (the relaxation stopped before converging, a bend with no flange)."""


class Code(str, Enum):
    """What a :class:`Finding` is about (also its JSON ``code``)."""

    FOLDED_TRIANGLES = "folded-triangles"
    OUTLINE_CROSSES_ITSELF = "outline-crosses-itself"
    HOLE_CROSSES_OUTLINE = "hole-crosses-outline"
    HOLE_OUTSIDE_OUTLINE = "hole-outside-outline"
    INSIDE_OUT = "inside-out"
    PANELS_OVERLAP = "panels-overlap"
    STRAIN_ABOVE_LIMIT = "strain-above-limit"
    SEAM_MISMATCH_ABOVE_LIMIT = "seam-mismatch-above-limit"
    SEAM_LENGTH_NOT_KEPT = "seam-length-not-kept"
    AREA_NOT_KEPT = "area-not-kept"
    GROSSLY_DISTORTED = "grossly-distorted"
    NOT_CONVERGED = "not-converged"
    DARTS = "darts"
    INSERTS = "inserts"
    """A saddle-shaped panel slashed from its outline by ``flatten(max_strain=...)``, each slash's wedge cut out
    as an insert that is sewn back into it (:mod:`patterns.flattening.inserts`)."""
    GORES = "gores"
    """A panel split into gores by ``flatten(max_strain=..., gores=True)``, each cut a seam
    (:mod:`patterns.flattening.gores`)."""
    FLANGES_OVERLAP = "flanges-overlap"
    """Faces of a blank that land on one another once unfolded: it cannot be cut in one piece."""
    BEND_WITHOUT_FLANGE = "bend-without-flange"
    """A bend with no flat face on one side."""
    MESHED_FACE = "meshed-face"
    """A face of a sheet that is no plane, cylinder or cone: meshed and flattened, with strain."""
    LABEL_LEFT_OUT = "label-left-out"
    """A label (a piece's name, a seam's or a bend's) that fits nowhere on its piece at the least text height:
    left out of the drawing rather than drawn smaller or across a cut."""
    OUTLINE_CUSP = "outline-cusp"
    """A blank's cut contour turning back on itself (a spike of material, or a notch, sharper than
    ``patterns.sheetmetal.contour.CUSP_DEGREES``): a corner developed as the model has it
    (``corner_relief="as-modelled"``) or a face drawn to a point."""
    OUTLINE_TOUCHES_ITSELF = "outline-touches-itself"
    """A blank's cut contours touch or cross one another: the part would fall apart, or cannot be cut."""
    SLIVER = "sliver"
    """A strip of a blank narrower than half the sheet's thickness: it burns away or bends under the cut."""
    HOLE_NEAR_BEND = "hole-near-bend"
    """A hole of a blank closer to a bend's zone than half the V-die from its centre line (or 1.5 t): the
    press brake draws it out of shape (:mod:`patterns.sheetmetal.rules`)."""
    SHORT_FLANGE = "short-flange"
    """A flange of a blank too short to rest on the shoulder of a 6 t V-die through the bend."""
    RELIEF_NOT_DRAWN = "relief-not-drawn"
    """A corner where a relief of the size asked (``corner_relief_size``, ``corner_relief_ratio``) does not
    reach a flange's edge: that corner is drawn closed."""
    OBLIQUE_CUT = "oblique-cut"
    """A cut across a bend whose wall is not square to the sheet (a hole drilled after bending): drawn as the
    wall's trace on the neutral layer, which the two faces' traces are not; or, where that cannot be traced
    (a counterbore's step before the neutral layer, a spline wall), drawn as the fixed face's trace, saying
    why."""
    MISSING_RELIEF = "missing-relief"
    """A bend that ends against unbent material of its blank with no relief cut there: the corner tears."""
    TINY_PART = "tiny-part"
    """A pattern less than a millimetre across: most likely a mesh modelled in metres (or centimetres, inches)
    read as millimetres; the note names the unit that gives it a likely size and the option that says it."""
    SHEET_METAL = "sheet-metal"
    """A CAD part that is a bent sheet (two parallel planes a thickness apart, coaxial cylinders whose radii
    differ by it) given to ``flatten``: each face comes out a loose panel; ``unfold`` makes one blank."""
    OPEN_CONTOUR = "open-contour"
    """A cut contour of a blank that does not close: an error, a cutter must never get one."""


@dataclass(frozen=True, eq=False)
class Finding:
    """One thing a check found.

    Attributes
    ----------
    code : Code
    severity : Severity
    panels : tuple of str
        The panel (or the two panels, or the blank) concerned; empty for a seam-only finding.
    points : (k, 2) float64, mm
        Where, in the flat pattern or blank as placed (crossing points, centres
        of folded triangles, a point inside an overlap, the worst triangle's
        centre).
    faces : (j,) int64
        Triangles concerned (folded, or above the strain limit), indices into
        the panel's faces; empty when not about triangles.  ``points`` and
        ``faces`` are the finding's own copies, read-only.
    seam : int or None
        The seam concerned.
    message : str
        One line, starting with the panel, seam or blank.
    """

    code: Code
    severity: Severity
    panels: tuple
    points: np.ndarray
    faces: np.ndarray
    seam: int | None
    message: str

    def __post_init__(self):
        for name, dtype in (("points", np.float64), ("faces", np.int64)):  # the finding's own, read-only
            value = np.array(getattr(self, name), dtype=dtype)
            if name == "points":
                value = value.reshape(-1, 2)
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @property
    def error(self) -> bool:
        """True for an error: the piece cannot be cut as it is."""
        return self.severity is Severity.ERROR

    def moved(self, motion: Motion) -> Finding:
        """The same finding with its points moved by ``motion`` (a piece laid out or nested)."""
        return Finding(self.code, self.severity, self.panels, motion(self.points), self.faces, self.seam,
                       self.message)

    def to_dict(self) -> dict:
        return {
            "code": self.code.value,
            "severity": self.severity.value,
            "panels": list(self.panels),
            "seam": self.seam,
            "points": self.points.tolist(),
            "faces": self.faces.tolist(),
            "message": self.message,
        }
