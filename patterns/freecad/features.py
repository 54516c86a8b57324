"""The pattern and the blank as parametric objects of a FreeCAD document.

A ``Pattern`` (:func:`make_pattern`) and a ``Blank`` (:func:`make_blank`) are
``Part::FeaturePython`` objects linked to their source (a body, a Part
feature, or some of its faces).  When the source changes, FreeCAD recomputes
them: the source's shape goes through the API's own pipeline
(:func:`patterns.load` and :func:`patterns.flatten`, or
:func:`patterns.unfold`), its pieces are made (:func:`patterns.pieces_of`),
laid out side by side or nested (:func:`patterns.layout`), checked
(:func:`patterns.check`), and the object's ``Shape`` becomes the pieces'
cut faces at 1:1 in the XY plane (a blank's bend lines as edges beside its
face).  Every option is a property (:mod:`~patterns.freecad.properties`).  Each
kind of mark -- sew lines, notches, grain, drill holes, bend lines up and down,
rulings, labels -- is a child object (``Marks``) in the object's group, as
FreeCAD SheetMetal keeps a sketch per layer.  The check report goes to the
Report view; the strain of each source face to ``FaceStrain`` (and, in the GUI,
to the source's face colours).
"""

from __future__ import annotations

import os

import FreeCAD
import numpy as np
import Part

from ..audit import CheckOptions, Report, checked_drawing
from ..blank import Blank
from ..errors import InputError, PatternsError
from ..export.layers import PRESETS
from ..flattening import FlattenOptions, flatten
from ..nesting import NestOptions, layout
from ..pattern import Pattern
from ..pieces import Drawing, PieceOptions, drawing_of, piece_labels
from ..pieces.options import PATTERN_ONLY
from ..sheetmetal import UnfoldOptions, unfold
from ..tessellate import MeshingOptions, mesh_shape
from .properties import add_properties, property_names, read_record
from .shapes import cut_face, library_shape, mark_shapes

__all__ = ["BLANK_GROUPS", "BLANK_RECORDS", "BLANK_SKIP", "PATTERN_GROUPS", "PATTERN_RECORDS", "ROLES", "BlankFeature",
           "MarksFeature", "PatternFeature", "make_blank", "make_pattern"]

PATTERN_RECORDS = (MeshingOptions, FlattenOptions, PieceOptions, NestOptions, CheckOptions)
"""The option records of a pattern object, in the order their property groups come."""
PATTERN_GROUPS = ("Meshing", "Flattening", "Pieces", "Nesting", "Check")
"""Their property groups (and the task panel's pages)."""

BLANK_RECORDS = (UnfoldOptions, PieceOptions, NestOptions, CheckOptions)
"""The option records of a blank object."""
BLANK_GROUPS = ("Unfolding", "Pieces", "Nesting", "Check")
"""Their property groups."""
BLANK_SKIP = frozenset((PieceOptions, name) for name in PATTERN_ONLY)
"""The piece options a blank has not (seams, rulings, fitted arcs, strain)."""

ROLES = ("sew", "notch", "grain", "drill", "bend_up", "bend_down", "bend", "label")
"""The kinds of mark a ``Marks`` child holds, one each."""


def _source_shape(obj) -> Part.Shape:
    """The shape of the object's source: the whole object's, or the faces linked."""
    if obj.Source is None:
        raise InputError(f"{obj.Label}: no source (link it to a body, a Part feature or some of its faces)")
    source, subs = obj.Source
    if not subs:
        return source.Shape
    return Part.makeCompound([source.Shape.getElement(s) for s in subs])


class _Feature:
    """What a pattern and a blank share: the source link, the option properties, the result properties, the
    pieces of the last recompute, and the marks."""

    RECORDS: tuple = ()
    GROUPS: tuple = ()
    SKIP: frozenset = frozenset()
    KIND = ""

    def __init__(self, obj):
        obj.Proxy = self
        obj.addProperty("App::PropertyLinkSub", "Source", self.KIND, "The object (or its faces) laid flat")
        obj.addProperty("App::PropertyStringList", "Marks", "Result",
                        "The names of its Marks objects (shown under it in the tree)")
        add_properties(obj, self.RECORDS, self.GROUPS, self.SKIP)
        obj.addProperty("App::PropertyBool", "Ok", "Result", "The check found no error and no exceeded limit")
        obj.addProperty("App::PropertyString", "Report", "Result", "The check report, as the Report view shows it")
        obj.addProperty("App::PropertyInteger", "Pieces", "Result", "How many pieces (copies included)")
        for name in ("Ok", "Report", "Pieces", "Marks"):
            obj.setEditorMode(name, 1)  # read-only: the recompute sets them
        self.drawing: Drawing | None = None
        self.checked: Drawing | None = None
        self.report: Report | None = None

    def record(self, obj, record):
        """One option record, from the object's properties (checked by the record)."""
        return read_record(obj, record, self.RECORDS, name=obj.Label, skip=self.SKIP)

    def records(self, obj) -> dict:
        return {r: self.record(obj, r) for r in self.RECORDS}

    def _result(self, obj, subject, records) -> None:
        """Pieces, nest, check, shape and report of a flattened pattern or unfolded blank."""
        nesting = records[NestOptions]
        if nesting.active:
            drawing = layout(subject, nesting, pieces=records[PieceOptions]).drawing()
        else:
            drawing = drawing_of(subject, records[PieceOptions])
        report, checked = checked_drawing(subject, drawing, records[CheckOptions])
        self.drawing, self.checked, self.report = drawing, checked, report
        shape = self.shape(drawing)
        shape.Placement = obj.Placement  # the object keeps where the user put it
        obj.Shape = shape
        obj.Ok, obj.Report, obj.Pieces = report.ok, str(report), len(drawing.pieces)
        say = FreeCAD.Console.PrintMessage if report.ok else FreeCAD.Console.PrintWarning
        say(f"patterns: {report}\n")

    def shape(self, drawing: Drawing) -> Part.Shape:
        return Part.makeCompound([cut_face(p) for p in drawing.pieces])

    def marks(self, role: str) -> tuple:
        """``(shape, texts)`` of one kind of mark of the last recompute (texts for labels only)."""
        if self.drawing is None:
            raise InputError("recompute the pattern first: its pieces are made when it is recomputed")
        if role == "label":
            labels = [label for p in self.drawing.pieces for label in piece_labels(p)]
            points = [Part.Vertex(FreeCAD.Vector(float(lb.at[0]), float(lb.at[1]), 0.0)) for lb in labels]
            return (Part.makeCompound(points) if points else Part.Shape()), [lb.text for lb in labels]
        return mark_shapes(self.drawing.pieces).get(role, Part.Shape()), []

    def onDocumentRestored(self, obj):
        self.drawing = self.checked = self.report = None

    def dumps(self):
        return None

    def loads(self, state):
        self.drawing = self.checked = self.report = None

    __getstate__ = dumps

    def __setstate__(self, state):
        self.loads(state)


class PatternFeature(_Feature):
    """The proxy of a pattern: the source flattened into pieces (see the module)."""

    RECORDS, GROUPS, KIND = PATTERN_RECORDS, PATTERN_GROUPS, "Pattern"

    def __init__(self, obj):
        super().__init__(obj)
        obj.addProperty("App::PropertyFloatList", "FaceStrain", "Result",
                        "The largest principal strain of each face of the source's shape (ratio), as the report says")
        obj.setEditorMode("FaceStrain", 1)
        self.pattern: Pattern | None = None

    def execute(self, obj):
        records = self.records(obj)
        shape = _source_shape(obj)
        source = obj.Source[0]
        try:
            model = mesh_shape(library_shape(shape, source.Label), records[MeshingOptions], name=source.Label)
            pattern = flatten(model, records[FlattenOptions])
            self._result(obj, pattern, records)
        except PatternsError as exc:
            FreeCAD.Console.PrintError(f"patterns: {exc}\n")
            raise
        self.pattern = pattern
        obj.FaceStrain = self.face_strain(len(shape.Faces))
        _colour_faces(obj, source)

    def face_strain(self, n_faces: int) -> list:
        """The largest principal strain of the panel of each of the source's ``n_faces`` faces."""
        strain = [0.0] * n_faces
        for panel, numbers in zip(self.pattern.panels, self.report.panels):
            for face in panel.panel.cad_faces:
                if 0 <= face < n_faces:
                    strain[face] = float(numbers.strain_max)
        return strain


class BlankFeature(_Feature):
    """The proxy of a blank: a bent sheet-metal source unfolded (see the module)."""

    RECORDS, GROUPS, SKIP, KIND = BLANK_RECORDS, BLANK_GROUPS, BLANK_SKIP, "Blank"

    def execute(self, obj):
        records = self.records(obj)
        source = obj.Source[0]
        try:
            blank = unfold(library_shape(_source_shape(obj), source.Label), records[UnfoldOptions],
                           name=source.Label)
            self._result(obj, blank, records)
        except PatternsError as exc:
            FreeCAD.Console.PrintError(f"patterns: {exc}\n")
            raise
        self.blank: Blank = blank

    def shape(self, drawing: Drawing) -> Part.Shape:
        """The blank's face and, beside it, its bend lines as edges."""
        edges = [Part.LineSegment(FreeCAD.Vector(*b.line[0], 0), FreeCAD.Vector(*b.line[1], 0)).toShape()
                 for p in drawing.pieces for b in p.bends]
        return Part.makeCompound([cut_face(p) for p in drawing.pieces] + edges)


class MarksFeature:
    """One kind of mark of a pattern or blank (``Role``): its lines (or label points, with ``Texts``)."""

    def __init__(self, obj, base, role: str):
        obj.Proxy = self
        obj.addProperty("App::PropertyLink", "Base", "Marks", "The pattern or blank marked")
        obj.addProperty("App::PropertyEnumeration", "Role", "Marks", "What is marked")
        obj.addProperty("App::PropertyStringList", "Texts", "Marks", "The labels, at the points of the shape")
        obj.Role = list(ROLES)
        obj.Base, obj.Role = base, role
        obj.setEditorMode("Texts", 1)
        obj.setExpression("Placement", f"{base.Name}.Placement")  # the marks lie on the pieces, wherever they go

    def execute(self, obj):
        shape, texts = obj.Base.Proxy.marks(obj.Role)
        if not shape.isNull():
            shape.Placement = obj.Placement
        obj.Shape, obj.Texts = shape, texts

    def dumps(self):
        return None

    def loads(self, state):
        return None

    __getstate__ = dumps

    def __setstate__(self, state):
        return None


class ViewPieces:
    """The GUI's view of a pattern or blank: its Marks objects under it in the tree, and its icon.  (A view,
    not a link: the marks depend on the pattern, so the pattern may not depend on them.)"""

    def __init__(self, view):
        view.Proxy = self

    def attach(self, view):
        self.Object = view.Object

    def claimChildren(self):
        doc = self.Object.Document
        return [doc.getObject(name) for name in self.Object.Marks if doc.getObject(name) is not None]

    def getIcon(self):
        return _icon("flatten" if isinstance(self.Object.Proxy, PatternFeature) else "unfold")

    def dumps(self):
        return None

    def loads(self, state):
        return None

    __getstate__ = dumps

    def __setstate__(self, state):
        return None


class ViewMarks(ViewPieces):
    """The GUI's view of a Marks object: lines in the colour of its role's layer, labels as points."""

    def attach(self, view):
        self.Object = view.Object
        layer = PRESETS["patterns"][view.Object.Role]
        view.LineColor = _ACI.get(layer.color, (0.0, 0.0, 0.0))
        view.PointColor = view.LineColor
        view.PointSize = 4.0

    def claimChildren(self):
        return []

    def getIcon(self):
        return _icon("patterns")


_ACI = {1: (1.0, 0.0, 0.0), 2: (0.8, 0.7, 0.0), 3: (0.0, 0.6, 0.0), 4: (0.0, 0.7, 0.7), 5: (0.0, 0.0, 1.0),
        6: (0.8, 0.0, 0.8), 7: (0.1, 0.1, 0.1)}
"""The AutoCAD colours of the layers, as FreeCAD's view shows them."""


def _icon(name: str) -> str:
    """An icon of the workbench (next to the package in a checkout or an addon folder), or none."""
    path = os.path.join(os.path.dirname(__file__), "..", "..", "freecad", "patterns_wb", "resources", "icons",
                        f"{name}.svg")
    return os.path.normpath(path) if os.path.exists(path) else ""


def _view(obj, kind) -> None:
    """Give an object its view proxy, in the GUI."""
    if FreeCAD.GuiUp and obj.ViewObject is not None:
        kind(obj.ViewObject)


def _colour_faces(obj, source) -> None:
    """In the GUI: the source's faces coloured by their strain (white none, red at the check's limit or 5 %)."""
    if not FreeCAD.GuiUp or source.ViewObject is None or obj.Source[1]:
        return
    limit = obj.Proxy.report.max_strain or 0.05
    colours = []
    for s in obj.FaceStrain:
        t = float(np.clip(s / limit, 0.0, 1.0))
        colours.append((1.0, 1.0 - t, 1.0 - t, 0.0))
    source.ViewObject.DiffuseColor = colours


def _options(obj, proxy, options: dict) -> None:
    """Set options given as the API's keywords (or the properties' names) on a new object; checked at once."""
    names = property_names(proxy.RECORDS, proxy.SKIP)
    by_api = {}
    for (record, option), prop in names.items():
        by_api.setdefault(option, prop)
    for key, value in options.items():
        prop = key if key in names.values() else by_api.get(key)
        if prop is None:
            raise InputError(f"{obj.Label}: unknown option {key!r}; the options are {', '.join(sorted(names.values()))}")
        kind = obj.getTypeIdOfProperty(prop)
        setattr(obj, prop, ("" if value is None else str(value)) if kind == "App::PropertyString" else value)
    proxy.records(obj)  # every value checked now, by its record


def _make(kind, source, name: str, marks: bool, options: dict):
    source, subs = source if isinstance(source, tuple) else (source, [])
    if not isinstance(getattr(source, "Shape", None), Part.Shape):
        raise InputError(f"{kind.__name__}: the source must be a FreeCAD object with a shape, got "
                         f"{type(source).__name__}")
    doc = source.Document
    obj = doc.addObject("Part::FeaturePython", name)
    proxy = kind(obj)
    obj.Source = (source, list(subs))
    try:
        _options(obj, proxy, options)
    except PatternsError:
        doc.removeObject(obj.Name)
        raise
    doc.recompute()
    if not obj.isValid():
        raise InputError(f"{obj.Label}: {obj.getStatusString()}")
    if marks:
        for role in ROLES:
            shape, texts = proxy.marks(role)
            if shape.isNull() and not texts:
                continue
            child = doc.addObject("Part::FeaturePython", f"{obj.Name}_{role}")
            MarksFeature(child, obj, role)
            child.Label = f"{obj.Label} {role.replace('_', ' ')}"
            obj.Marks = list(obj.Marks) + [child.Name]
            _view(child, ViewMarks)
        doc.recompute()
    _view(obj, ViewPieces)
    return obj


def make_pattern(source, *, name: str = "Pattern", marks: bool = True, **options):
    """A parametric pattern of ``source`` in its document: its pieces, flat at 1:1, recomputed with it.

    Parameters
    ----------
    source : FreeCAD object with a Shape, or ``(object, ["Face1", ...])``
        A body, a Part feature, or some of its faces.
    name : str
        The new object's name.
    marks : bool
        Add a ``Marks`` child for each kind of mark the pieces have (sew lines, notches, grain, drill holes,
        bend lines, labels).
    **options
        Any option of :class:`patterns.tessellate.MeshingOptions`, :class:`patterns.FlattenOptions`,
        :class:`patterns.PieceOptions`, :class:`patterns.NestOptions`, :class:`patterns.CheckOptions`,
        by its API name (``seam_allowance=10``, ``sheet=(1000, 500)``); where two records share a name,
        the command line's (``dart_strain``, ``nest_gap``).  Each is a property of the object.

    Returns
    -------
    FreeCAD ``Part::FeaturePython``
        Its ``Shape`` is a compound of the pieces' cut faces; ``Ok``, ``Report``, ``Pieces`` and
        ``FaceStrain`` say what the check found.

    Raises
    ------
    patterns.InputError
        A bad option (before the object is recomputed; nothing is added), a source with no shape, or a
        recompute that failed (the message says why).
    """
    return _make(PatternFeature, source, name, marks, options)


def make_blank(source, *, name: str = "Blank", marks: bool = True, **options):
    """A parametric blank of a bent sheet-metal ``source``: the blank's face and its bend lines as edges.

    Options: those of :class:`patterns.UnfoldOptions` (``k_factor``, ``bend_table``: a CSV's path,
    ``fixed_face``), the piece options a blank has (``text_height``, ``gap``), :class:`patterns.NestOptions`
    and :class:`patterns.CheckOptions`; otherwise as :func:`make_pattern`.
    """
    return _make(BlankFeature, source, name, marks, options)
