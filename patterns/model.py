"""The loaded model: panels (pieces to cut) joined by seams.

:func:`patterns.load` returns a :class:`Model`; :func:`patterns.flatten` turns it
into a :class:`patterns.Pattern`.  Everything is in millimetres.  All arrays are
read-only; nothing here changes after it is made.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from .mesh import face_areas, longest_first, polyline_length, validate_mesh
from .text import counted

__all__ = ["Bookkeeping", "panel_from_mesh", "Model", "Panel", "Seam", "Surface", "SurfaceKind"]


def _own(array, dtype=None) -> np.ndarray:
    """A read-only array the record owns: the caller's array itself only if it is already read-only.

    A constructor never freezes (nor keeps a writeable reference to) an array it was given.
    """
    a = np.asarray(array, dtype=dtype)
    base = a.base if isinstance(a.base, np.ndarray) else None
    if a.flags.writeable or (base is not None and base.flags.writeable):
        a = a.copy()  # a view of a writeable array could still change under the record
    a.setflags(write=False)
    return a


class SurfaceKind(str, Enum):
    """The analytic surfaces a panel can be unrolled from exactly."""

    PLANE = "plane"
    CYLINDER = "cylinder"
    CONE = "cone"
    GENERAL_CONE = "general cone"
    """Straight lines from one point (the apex, ``origin``) to a curve (the
    ``directrix``): an oblique cone, such as the corners of a square-to-round."""


@dataclass(frozen=True, eq=False)
class Surface:
    """A CAD face's analytic surface (OpenCascade's parametrisation), in mm.

    Attributes
    ----------
    kind : SurfaceKind
    origin, x_dir, y_dir, axis : (3,) float64
        The surface's frame (``gp_Ax3``): location, X and Y directions, main axis.
    radius : float
        Cylinder: its radius; cone: the radius in the plane through ``origin``.
    semi_angle : float
        Cone: half the opening angle, radians (signed as in OpenCascade).

    A cylinder is ``origin + radius (cos u x_dir + sin u y_dir) + v axis``; a
    cone ``origin + (radius + v sin a)(cos u x_dir + sin u y_dir) + v cos a axis``.
    """

    kind: SurfaceKind
    origin: np.ndarray
    x_dir: np.ndarray
    y_dir: np.ndarray
    axis: np.ndarray
    radius: float = 0.0
    semi_angle: float = 0.0
    directrix: np.ndarray | None = None
    """General cone: (k, 3) points along the curve the lines from the apex end on, in order."""


@dataclass(frozen=True, eq=False)
class Panel:
    """One piece to be cut: a triangle mesh that is a disk (or a disk with holes).

    Attributes
    ----------
    name : str
        ``"face3"`` for CAD face 3, the group's name for a group of CAD faces,
        ``"piece0"`` for a piece of a mesh file.
    vertices : (n, 3) float64, mm
    faces : (m, 3) int64
        Counter-clockwise seen from the outside (the CAD face's orientation).
    loops : tuple of (k,) int64
        Boundary loops, the panel to their left; the longest (in 3D) first.
    cad_faces : tuple of int
        The CAD faces (indices into the shape's faces, in build123d's
        ``shape.faces()`` order) meshed into this panel; empty for a mesh file.
    surface : Surface or None
        For a panel that is one planar, cylindrical or conical CAD face: its
        surface, which :func:`patterns.flatten` unrolls exactly.
    param : (n, 2) float64 or None
        With ``surface``: each vertex's surface parameters (u, v), to tell the
        two copies of a point on a seam line apart (approximate on the boundary).
    insert_into : str or None
        For an insert (:mod:`patterns.flattening.inserts`: a wedge cut from a
        saddle-shaped panel to relieve it, sewn back into the slash it leaves):
        the name of the panel it fills.
    gore_of : str or None
        For a gore (:mod:`patterns.flattening.gores`: a piece of a panel split
        along cuts from its outline to its crown, each cut a seam): the name of
        the panel it was cut from.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    loops: tuple
    cad_faces: tuple = ()
    surface: Surface | None = None
    param: np.ndarray | None = None
    insert_into: str | None = None
    gore_of: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "vertices", _own(self.vertices))
        object.__setattr__(self, "faces", _own(self.faces))
        object.__setattr__(self, "loops", tuple(_own(loop) for loop in self.loops))
        if self.param is not None:
            object.__setattr__(self, "param", _own(self.param, np.float64))

    @property
    def area(self) -> float:
        """Area of the triangles, mm^2."""
        return float(face_areas(self.vertices, self.faces).sum())


@dataclass(frozen=True, eq=False)
class Seam:
    """A line along which two panels (or two sides of one panel) are joined.

    Attributes
    ----------
    id : int
        Index in :attr:`Model.seams`.
    panels : (int, int)
        The panels on either side (indices into :attr:`Model.panels`); equal
        for a seam that closes one panel on itself (the seam line of a
        cylinder or cone face, or a cut made to open a tube).
    points : (k, 3) float64, mm
        The seam's points, in order, shared by both sides.
    vertices : ((k,) int64, (k,) int64)
        The same points as vertex indices into each side's panel.
    length : float, mm
        The seam's exact length: the CAD edge's curve length for a CAD seam,
        the polyline's length for a cut.
    cad_edge : int or None
        The CAD edge (index into ``shape.edges()``), or None for a cut that
        `patterns` made to open a closed surface or a tube.
    """

    id: int
    panels: tuple
    points: np.ndarray
    vertices: tuple
    length: float
    cad_edge: int | None = None

    def __post_init__(self):
        object.__setattr__(self, "points", _own(self.points))
        object.__setattr__(self, "vertices", tuple(_own(v) for v in self.vertices))

    @property
    def polyline_length(self) -> float:
        """Length of the polyline through :attr:`points`, mm (below :attr:`length` on a curve)."""
        return polyline_length(self.points)

    @property
    def closes_panel(self) -> bool:
        """True when both sides belong to the same panel."""
        return self.panels[0] == self.panels[1]


@dataclass(frozen=True)
class Bookkeeping:
    """What loading did to the input, so that nothing happens behind the user's back.

    Attributes
    ----------
    welded : int
        Vertices merged into another at exactly the same coordinates (mesh
        files: STL by default, see :func:`patterns.reading.read_mesh`).
    unused : int
        Vertices no face used, dropped.
    cuts : int
        Cuts made to open a tube-like piece into a disk (seams with no CAD
        edge; each is a seam of the model).
    split : int
        Closed pieces split into panels along their creases (mesh files).
    units : str
        The unit the file's coordinates were read in and converted from to mm
        (``"mm"``: nothing converted).
    """

    welded: int = 0
    unused: int = 0
    cuts: int = 0
    split: int = 0
    units: str = "mm"

    def __str__(self) -> str:
        parts = [f"{counted(self.welded, 'vertex')} welded" if self.welded else "",
                 f"{self.unused} unused vertices dropped" if self.unused else "",
                 f"{self.cuts} cut{'s' if self.cuts != 1 else ''} made to open tubes" if self.cuts else "",
                 f"{self.split} closed piece{'s' if self.split != 1 else ''} split into panels along creases"
                 if self.split else "",
                 f"coordinates read in {self.units} and converted to mm" if self.units != "mm" else ""]
        return "; ".join(p for p in parts if p) or "nothing welded, dropped or cut"


@dataclass(frozen=True, eq=False)
class Model:
    """Panels and seams of one part, in millimetres.

    Attributes
    ----------
    name : str
        The file name, or the build123d object's type.
    panels : tuple of Panel
    seams : tuple of Seam
    max_edge : float, mm
        The target edge length the panels were meshed to (for mesh files, the
        longest edge found).
    bookkeeping : Bookkeeping
        What loading did: vertices welded, unused vertices dropped, cuts made.
    """

    name: str
    panels: tuple
    seams: tuple
    max_edge: float
    bookkeeping: Bookkeeping = Bookkeeping()

    def seams_of(self, panel: int) -> tuple:
        """The seams with ``panel`` on either side."""
        return tuple(s for s in self.seams if panel in s.panels)

    def __repr__(self) -> str:
        return (f"Model({self.name!r}, {counted(len(self.panels), 'panel')}, {counted(len(self.seams), 'seam')}, "
                f"max_edge={self.max_edge:.4g} mm)")


def panel_from_mesh(label: str, vertices, faces, *, name: str, cad_faces: tuple = (), surface=None,
                    param=None, insert_into: str | None = None, gore_of: str | None = None) -> Panel:
    """A :class:`Panel` from a disk-like mesh: validated (``name`` in messages), its loops longest first.

    The one way loading builds a panel, from a mesh file's piece or from CAD faces.
    """
    v, f, conn = validate_mesh(vertices, faces, name=name)
    return Panel(label, v, f, longest_first(v, conn.loops), tuple(cad_faces), surface=surface, param=param,
                 insert_into=insert_into, gore_of=gore_of)
