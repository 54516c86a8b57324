"""The piece: what a cutter cuts and marks, in mm at 1:1, whatever file it goes into.

A :class:`Piece` is one piece of material: its cut outline and holes as
exact lines, true arcs and polylines (:class:`~patterns.curves.Loop`), the
marks drawn on it (sew lines, notches, drill holes, a grain line, bend lines
with their direction, angle, inside radius and K-factor), the seam sides its
labels name, and where it came from (a pattern's panel or a blank, its strain,
its findings).  A flattened panel and an unfolded blank both become pieces
(:func:`patterns.pieces.pieces_of`); the nester, every writer (DXF machine and
ASTM, SVG, the JSON report) and batch take pieces, and nothing else.

Pieces are immutable: :meth:`Piece.moved` returns the piece moved rigidly (or
mirrored: the opposite-hand piece), every mark with it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import shapely

from ..curves import Loop, Motion
from ..measure import StrainStats

__all__ = ["BendLine", "Label", "Labels", "Notch", "Piece", "SeamSide", "Source", "StrainMap"]


def _frozen(array, shape=None) -> np.ndarray:
    out = np.array(array, dtype=np.float64)
    if shape is not None:
        out = out.reshape(shape)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class Notch:
    """A notch: a mark cut into the piece's edge where its mate's notch must meet it when sewn.

    Attributes
    ----------
    at : (2,) float64, mm
        Its start on the cut line.
    inward : (2,) float64
        Unit direction into the piece.
    depth : float
        mm: to the seam line (with a seam allowance), or a snip.
    mouth : (2, 2) float64 or None, mm
        A V notch: the two ends of its mouth on the cut line (its tip is ``at + depth * inward``);
        None for a slit.
    """

    at: np.ndarray
    inward: np.ndarray
    depth: float
    mouth: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "at", _frozen(self.at, (2,)))
        object.__setattr__(self, "inward", _frozen(self.inward, (2,)))
        if self.mouth is not None:
            object.__setattr__(self, "mouth", _frozen(self.mouth, (2, 2)))

    @property
    def tip(self) -> np.ndarray:
        return self.at + self.depth * self.inward

    def moved(self, motion: Motion) -> Notch:
        return Notch(motion(self.at), motion.direction(self.inward), self.depth,
                     None if self.mouth is None else motion(self.mouth))


@dataclass(frozen=True, eq=False)
class BendLine:
    """A line the piece is bent (or rolled) along.

    Attributes
    ----------
    line : (2, 2) float64, mm
        End to end.
    angle : float
        Degrees the material turns there.
    direction : str
        ``"up"`` or ``"down"`` (a blank's bend: the way the flange turns, seen from the side drawn), or
        ``""`` (a ruling of a rolled panel, bumped or rolled either way).
    inside_radius : float or None
        mm (a blank's bend).
    k_factor : float or None
        The K-factor it was developed with (None: a bend table, or a ruling).
    allowance : float or None
        The developed width of the bend zone, mm (a blank's bend).
    sequence : int
        A blank's bend: its place in the press brake's order (1 first), as the blank numbered it; 0 for a
        ruling.
    of : int
        How many bends the blank has (a blank of one bend has no order to give: its label has no number).
    flange : float
        A blank's bend: its outer flange's depth, mm (the bend sheet's ``flange_mm``).
    """

    line: np.ndarray
    angle: float
    direction: str = ""
    inside_radius: float | None = None
    k_factor: float | None = None
    allowance: float | None = None
    sequence: int = 0
    of: int = 0
    flange: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "line", _frozen(self.line, (2, 2)))

    @property
    def label(self) -> str:
        """The text drawn beside it: ``1 UP 90.0 DEG R3`` for a blank's bend (its number in the bending order
        first, when the blank has two bends or more), ``BEND 11.61 DEG`` for a ruling."""
        if self.direction:
            number = f"{self.sequence} " if self.of > 1 else ""
            return f"{number}{self.direction.upper()} {self.angle:.1f} DEG R{self.inside_radius:g}"
        return f"BEND {self.angle:.2f} DEG"

    def moved(self, motion: Motion) -> BendLine:
        return replace(self, line=motion(self.line))


@dataclass(frozen=True, eq=False)
class SeamSide:
    """One side of a seam on a piece: what its label says, and the line it runs along.

    Attributes
    ----------
    seam : int
        The seam's id.
    side : int
        0 or 1.
    length_3d : float
        The seam's exact 3D length, mm.
    length_flat : float
        This side's flat length, mm.
    points : (k, 2) float64, mm
        The seam line on the piece, the piece to its left.
    """

    seam: int
    side: int
    length_3d: float
    length_flat: float
    points: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "points", _frozen(self.points, (-1, 2)))

    def moved(self, motion: Motion) -> SeamSide:
        pts = motion(self.points)
        return replace(self, points=pts[::-1] if motion.mirrored else pts)


@dataclass(frozen=True, eq=False)
class StrainMap:
    """Every triangle of a panel as drawn, with its dominant principal strain (the STRAIN layer).

    Attributes
    ----------
    triangles : (m, 3, 2) float64, mm
    strain : (m,) float64
        Dominant principal strain (0.01 = 1 %; negative where the flat is shorter than the surface).
    """

    triangles: np.ndarray
    strain: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "triangles", _frozen(self.triangles, (-1, 3, 2)))
        object.__setattr__(self, "strain", _frozen(self.strain, (-1,)))

    def moved(self, motion: Motion) -> StrainMap:
        return StrainMap(motion(self.triangles.reshape(-1, 2)).reshape(-1, 3, 2), self.strain)


@dataclass(frozen=True, eq=False)
class Label:
    """A placed label: its text, centre (2,) mm, cap height mm and angle (degrees), and what it says:
    ``"title"`` (the piece's name and what it is), ``"seam"`` (a seam side's lengths) or ``"bend"``.

    Its box (:func:`patterns.pieces.labels.text_box`) reaches from a descender a quarter height below the
    baseline to the cap height: a label turned upside down by a move is turned back to read left to right
    and shifted that quarter height, so that it covers the same place (:meth:`moved`)."""

    text: str
    at: np.ndarray
    height: float
    angle: float
    kind: str = "title"
    of: int = -1
    """A seam label's index in :attr:`Piece.seams`, a bend label's in :attr:`Piece.bends` (-1 for the title)."""

    def __post_init__(self):
        object.__setattr__(self, "at", _frozen(self.at, (2,)))

    def moved(self, motion: Motion) -> Label:
        a = np.radians(self.angle)
        along, up = motion.direction(np.array([np.cos(a), np.sin(a)])), motion.direction(np.array([-np.sin(a),
                                                                                                     np.cos(a)]))
        angle = float(np.degrees(np.arctan2(along[1], along[0])))
        if angle > 90 + 1e-6:  # read left to right, as readable_angle turns it (a vertical text stays at 90,
            angle -= 180      # whichever way round-off leans)
        elif angle <= -90 + 1e-6:
            angle += 180
        r = np.radians(angle)
        new_up = np.array([-np.sin(r), np.cos(r)])
        at = motion(self.at)
        if float(up @ new_up) < 0:  # upside down, turned back: the box's descender on the other side
            at = at + 0.25 * self.height * new_up
        return replace(self, at=at, angle=angle)


@dataclass(frozen=True, eq=False)
class Labels:
    """A piece's labels, placed once (:func:`patterns.pieces.labels.place_labels`) and moved with it.

    Attributes
    ----------
    placed : tuple of Label
        The title block, then the seam labels, then the bend labels.
    left_out : tuple of Label
        Those that fit nowhere on the piece at the least height, as they asked to be drawn (each a
        ``label-left-out`` note on the piece).
    least : float
        The least height any label was tried at, mm.
    unit : str
        The unit the seam labels say their lengths in (``"mm"``, ...; places are in mm).
    """

    placed: tuple
    left_out: tuple
    least: float
    unit: str = "mm"

    def moved(self, motion: Motion) -> Labels:
        return Labels(tuple(label.moved(motion) for label in self.placed),
                      tuple(label.moved(motion) for label in self.left_out), self.least, self.unit)


@dataclass(frozen=True)
class Source:
    """Where a piece came from.

    Attributes
    ----------
    kind : str
        ``"panel"`` (a flattened pattern's) or ``"blank"`` (an unfolded sheet-metal part's).
    part : str
        The pattern's or the blank's name.
    index : int
        The panel's index in its pattern (0 for a blank).
    faces : tuple of int
        The CAD faces it was made from (a panel's, or a blank's fixed face and bends).
    copy : int
        0 for the piece itself, ``k`` for its ``k``-th extra copy in a nest.
    """

    kind: str
    part: str
    index: int = 0
    faces: tuple = ()
    copy: int = 0


@dataclass(frozen=True, eq=False)
class Piece:
    """One piece of material, as cut and marked (mm, 1:1).

    Attributes
    ----------
    name : str
    outline : patterns.curves.Loop
        The cut line, counter-clockwise (with a seam allowance: the allowance's outline).
    holes : tuple of patterns.curves.Loop
        Cut-outs, clockwise; a drilled hole is one full-circle arc.
    sew : tuple of (k, 2) float64
        The finished piece's outline and holes (the seam line), mm; drawn as sew lines when
        ``allowance`` is set, else the same as the cut.
    allowance : bool
        A seam allowance lies between the sew line and the cut line.
    notches : tuple of Notch
    drills : (d, 2) float64, mm
        Drill holes (a dart's point).
    grain : (2, 2) float64 or None, mm
        The grain line, end to end.
    bends : tuple of BendLine
    seams : tuple of SeamSide
    title : tuple of str
        What the piece's label says under its name (its strain; a blank's thickness and K-factor).
    text_height : float
        The height its labels are drawn at, mm.
    label_at : (2,) float64, mm
        Where its name goes (inside it).
    source : Source
    strain : patterns.measure.StrainStats or None
        The panel's principal strains (None for an exact blank).
    findings : tuple of patterns.Finding
        What the check found on it, its points where the piece lies.
    strain_map : StrainMap or None
        Its triangles and strains, when asked for (``strain_layer``).
    placement : patterns.curves.Motion
        How the piece was moved from where its panel or blank lies (laid out, nested, mirrored).
    rims : tuple of patterns.blank.Rim
        A blank's countersinks' and counterbores' rims: circles marked, not cut (the hole is cut at its
        through diameter, one of ``holes``).
    labels : Labels or None
        Its labels, placed when the piece was made (:func:`patterns.pieces.pieces_of`) and moved with it;
        None for a piece made otherwise (the writers then place them: :func:`patterns.pieces.labels.labels_of`).
    """

    name: str
    outline: Loop
    holes: tuple
    sew: tuple
    allowance: bool
    notches: tuple
    drills: np.ndarray
    grain: np.ndarray | None
    bends: tuple
    seams: tuple
    title: tuple
    text_height: float
    label_at: np.ndarray
    source: Source
    strain: StrainStats | None = None
    findings: tuple = ()
    strain_map: StrainMap | None = None
    placement: Motion = field(default_factory=Motion)
    rims: tuple = ()
    labels: Labels | None = None

    def __post_init__(self):
        object.__setattr__(self, "sew", tuple(_frozen(s, (-1, 2)) for s in self.sew))
        object.__setattr__(self, "drills", _frozen(self.drills, (-1, 2)))
        if self.grain is not None:
            object.__setattr__(self, "grain", _frozen(self.grain, (2, 2)))
        object.__setattr__(self, "label_at", _frozen(self.label_at, (2,)))

    @cached_property
    def polygon(self) -> shapely.Polygon:
        """What is cut: the outline less the holes, sampled within 0.001 mm."""
        return shapely.Polygon(self.outline.points(), [h.points() for h in self.holes])

    @cached_property
    def finished(self) -> shapely.Polygon:
        """The finished piece (inside the sew line): where its labels go."""
        return shapely.Polygon(self.sew[0], list(self.sew[1:]))

    @property
    def area(self) -> float:
        """Cut area, mm²: the outline less the holes, exactly (arcs as arcs)."""
        return self.outline.area - sum(h.area for h in self.holes)

    @property
    def bounds(self) -> tuple:
        """``(x0, y0, x1, y1)`` of the cut outline, mm."""
        return tuple(float(v) for v in shapely.bounds(self.outline.polygon))

    def moved(self, motion: Motion) -> Piece:
        """The piece moved by ``motion`` (turned and shifted, or mirrored: the opposite-hand piece), every
        mark and finding with it; ``placement`` records the whole move from its source."""
        holes = tuple(h.moved(motion) for h in self.holes)
        sew = tuple(motion(s)[::-1] if motion.mirrored else motion(s) for s in self.sew)
        return replace(
            self, outline=self.outline.moved(motion), holes=holes, sew=sew,
            notches=tuple(n.moved(motion) for n in self.notches), drills=motion(self.drills),
            grain=None if self.grain is None else motion(self.grain), bends=tuple(b.moved(motion) for b in self.bends),
            seams=tuple(s.moved(motion) for s in self.seams), label_at=motion(self.label_at),
            findings=tuple(f.moved(motion) for f in self.findings),
            strain_map=None if self.strain_map is None else self.strain_map.moved(motion),
            placement=motion @ self.placement, rims=tuple(r.moved(motion) for r in self.rims),
            labels=None if self.labels is None else self.labels.moved(motion))

    def copy(self, name: str, number: int, *, mirrored: bool = False) -> Piece:
        """Another piece of the same, named ``name`` (its ``number``-th copy); ``mirrored``: its mirror image
        (across its own vertical line through ``label_at``).  Its title says another name: its labels are
        placed anew (``labels`` None until then)."""
        piece = replace(self, name=name, source=replace(self.source, copy=number), labels=None)
        if not mirrored:
            return piece
        x = float(self.label_at[0])
        return piece.moved(Motion(0.0, 2 * x, 0.0, mirrored=True))
