"""The pattern and the blank as parametric objects of a FreeCAD document, computed by the engine beside it.

A ``Pattern`` (:func:`make_pattern`) and a ``Blank`` (:func:`make_blank`) are ``Part::FeaturePython``
objects linked to their source (a body, a Part feature, or some of its faces).  When the source or an
option changes, the object sends the source's shape (BREP text) and its options to the engine
(:mod:`.engine`), which flattens or unfolds it as ``patterns flatten`` (``unfold``) would, and gets back
the pieces' cut faces at 1:1 in the XY plane (a blank's bend lines as edges beside them), the marks, the
report and its figures.  The request's key is kept (``Key``): a recompute that would send the same
request -- the pattern moved (Placement), the document reopened -- reuses the shape it has and never
calls the engine.  Each kind of mark is a child object (``Marks``) in the object's group.
"""

import json
import os

import FreeCAD
import Part

from . import properties
from .engine import EngineError, engine, key_of
from .properties import PatternsError, check_options
from .proxies import Stateless, marks_of

ROLES = ("sew", "notch", "grain", "drill", "bend_up", "bend_down", "bend", "label")
"""The kinds of mark a ``Marks`` child holds, one each."""
ROLES_OF = {"pattern": ("sew", "notch", "grain", "drill", "bend", "label"),
            "blank": ("bend_up", "bend_down", "bend", "label")}
"""The Marks children each kind of object has (empty while it has none of that mark: a seam allowance set
later fills its ``sew``)."""


def _shape(text):
    shape = Part.Shape()
    shape.importBrepFromString(text)
    return shape


def _source(obj):
    """``(shape, faces)``: the shape of the object's source (the whole object's, or the faces linked) and its
    face count."""
    if obj.Source is None:
        raise PatternsError(f"{obj.Label}: no source (link it to a body, a Part feature or some of its faces)")
    source, subs = obj.Source
    shape = source.Shape if not subs else Part.makeCompound([source.Shape.getElement(s) for s in subs])
    return shape, len(shape.Faces)


def _fixed_face(subs):
    """A blank's selected face (``["Face21"]``) as its fixed face, or None."""
    faces = [s for s in subs if s.startswith("Face")]
    return faces[0] if len(faces) == 1 else None


class _Feature(Stateless):
    """What a pattern and a blank share: the source link, the option properties, the result properties, the
    pieces' marks of the last engine call."""

    KIND = ""

    def __init__(self, obj):
        obj.Proxy = self
        obj.addProperty("App::PropertyLinkSub", "Source", self.KIND.title(), "The object (or its faces) laid flat")
        obj.addProperty("App::PropertyStringList", "Marks", "Result",
                        "The names of its Marks objects (shown under it in the tree)")
        properties.add(obj, engine().options[self.KIND])
        obj.addProperty("App::PropertyBool", "Ok", "Result", "The check found no error and no exceeded limit")
        obj.addProperty("App::PropertyString", "Report", "Result", "The check report, as the Report view shows it")
        obj.addProperty("App::PropertyString", "Figures", "Result",
                        "The check's figures (JSON): worst strain and where, share above the limit, seam mismatch")
        obj.addProperty("App::PropertyInteger", "Pieces", "Result", "How many pieces (copies included)")
        obj.addProperty("App::PropertyString", "Key", "Result", "The last request's key: unchanged, not recomputed")
        for name in ("Ok", "Report", "Figures", "Pieces", "Marks", "Key"):
            obj.setEditorMode(name, 1)  # read-only: the recompute sets them
        obj.setEditorMode("Key", 2)
        self.marks, self.labels, self.colours = None, [], {}

    def request(self, obj):
        """``(key, request fields)`` of the object as it is now (from the object alone: no engine)."""
        shape, faces = _source(obj)
        options, name = properties.changed(obj), obj.Source[0].Label
        options = {k: os.path.abspath(v) if isinstance(v, str) and os.path.isfile(v) else v  # a table: FreeCAD's
                   for k, v in options.items()}                                                # folder, not the engine's
        text = shape.exportBrepToString()
        return key_of(self.KIND, text, options, name), {"kind": self.KIND, "shape": text, "options": options,
                                                        "name": name, "faces": faces}

    def execute(self, obj):
        try:
            key, fields = self.request(obj)
            if key == obj.Key and not obj.Shape.isNull():
                obj.Shape = _placed(obj.Shape, obj.Placement)  # moved or reopened: the same pieces, no engine
                return
            properties.add(obj, engine().options[self.KIND])  # an engine upgraded since: its new options
            result = engine().request("make", **fields)
            self.apply(obj, key, result)
        except Exception as exc:  # noqa: BLE001 - the engine's word, or a shape FreeCAD cannot read: the recompute fails
            FreeCAD.Console.PrintError(f"patterns: {exc}\n")
            obj.Ok, obj.Report = False, f"recompute failed: {exc}"  # not the last good one's verdict
            raise PatternsError(str(exc)) from None

    def apply(self, obj, key, result):
        """The engine's result on the object: shape, marks, report."""
        obj.Shape = _placed(_shape(result["shape"]), obj.Placement)
        self.marks = {role: _shape(text) for role, text in result["marks"].items()}
        self.labels, self.colours = list(result["labels"]), dict(result["colours"])
        obj.Ok, obj.Report, obj.Pieces = result["ok"], result["report"], result["pieces"]
        obj.Figures = json.dumps(result["figures"])
        obj.Key = key
        say = FreeCAD.Console.PrintMessage if result["ok"] else FreeCAD.Console.PrintWarning
        say(f"patterns: {result['report']}\n")

    def mark(self, role):
        """``(shape, texts)`` of one kind of mark of the last engine call, or None when it was not made in this
        session (the object's shape was reused: its marks keep theirs)."""
        if self.marks is None:
            return None
        return self.marks.get(role, Part.Shape()), (self.labels if role == "label" else [])

    def onDocumentRestored(self, obj):
        self.restored()

    def restored(self):
        self.marks, self.labels, self.colours = None, [], {}


def _placed(shape, placement):
    shape = shape.copy()
    shape.Placement = placement
    return shape


class PatternFeature(_Feature):
    """The proxy of a pattern: the source flattened into pieces (see the module)."""

    KIND = "pattern"

    def __init__(self, obj):
        super().__init__(obj)
        obj.addProperty("App::PropertyFloatList", "FaceStrain", "Result",
                        "The largest principal strain of each face of the source's shape (ratio), as the report says")
        obj.addProperty("App::PropertyBool", "ShowStrain", "View",
                        "Colour the source's faces by their strain (white none, red at the limit); off: its own colours")
        obj.addProperty("App::PropertyString", "SourceColours", "View", "The source's own face colours, kept while "
                        "the strain is shown")
        obj.setEditorMode("FaceStrain", 1)
        obj.setEditorMode("SourceColours", 2)

    def apply(self, obj, key, result):
        super().apply(obj, key, result)
        obj.FaceStrain = result["face_strain"]

    def onChanged(self, obj, prop):
        if prop in ("ShowStrain", "FaceStrain") and "SourceColours" in obj.PropertiesList \
            and "Restore" not in obj.State:  # while a document is read, its colours are the saved ones
            from .views import show_strain

            show_strain(obj)


class BlankFeature(_Feature):
    """The proxy of a blank: a bent sheet-metal source unfolded (see the module)."""

    KIND = "blank"


class MarksFeature(Stateless):
    """One kind of mark of a pattern or blank (``Role``): its lines (or label points, with ``Texts``)."""

    def __init__(self, obj, base, role):
        obj.Proxy = self
        obj.addProperty("App::PropertyLink", "Base", "Marks", "The pattern or blank marked")
        obj.addProperty("App::PropertyEnumeration", "Role", "Marks", "What is marked")
        obj.addProperty("App::PropertyStringList", "Texts", "Marks", "The labels, at the points of the shape")
        obj.Role = list(ROLES)
        obj.Base, obj.Role = base, role
        obj.setEditorMode("Texts", 1)
        obj.setExpression("Placement", f"{base.Name}.Placement")  # the marks lie on the pieces, wherever they go

    def execute(self, obj):
        made = obj.Base.Proxy.mark(obj.Role)
        if made is None:  # the base reused its shape (reopened, moved): so do its marks
            if not obj.Shape.isNull():
                obj.Shape = _placed(obj.Shape, obj.Placement)
            return
        shape, texts = made
        obj.Shape = shape if shape.isNull() else _placed(shape, obj.Placement)
        obj.Texts = texts


def _beside(obj, source):
    """A new pattern or blank laid beside its source, to its +X side (not under it), its lowest piece level
    with the source's lowest point."""
    part, pieces = source.Shape.BoundBox, obj.Shape.BoundBox
    if part.isValid() and pieces.isValid():
        gap = 0.1 * max(part.XLength, part.YLength, 10.0)
        obj.Placement.Base = FreeCAD.Vector(part.XMax + gap - pieces.XMin, part.YMin - pieces.YMin, 0)
        obj.Document.recompute()


def _add_marks(doc, obj):
    for role in ROLES_OF[obj.Proxy.KIND]:
        child = doc.addObject("Part::FeaturePython", f"{obj.Name}_{role}")
        MarksFeature(child, obj, role)
        child.Label = f"{obj.Label} {role.replace('_', ' ')}"
        obj.Marks = list(obj.Marks) + [child.Name]
        from .views import view_marks

        view_marks(child, obj.Proxy.colours.get(role, 7))


def _make(kind, source, name, marks, options):
    source, subs = source if isinstance(source, tuple) else (source, [])
    if not isinstance(getattr(source, "Shape", None), Part.Shape):
        raise PatternsError(f"{kind.__name__}: the source must be a FreeCAD object with a shape, got "
                            f"{type(source).__name__}")
    if kind is BlankFeature and _fixed_face(subs):  # SheetMetal's habit: the selected face stays put
        options, subs = {"fixed_face": _fixed_face(subs), **options}, []
    check_options(kind.KIND, {k: v for k, v in options.items()}, getattr(source, "Label", name))
    doc = source.Document
    doc.openTransaction(f"patterns: {kind.KIND}")
    obj = None
    try:
        obj = doc.addObject("Part::FeaturePython", name)
        kind(obj)
        obj.Source = (source, list(subs))
        properties.set_values(obj, engine().options[kind.KIND], options, obj.Label)
        obj.Proxy.execute(obj)  # the one engine call: the document's recompute below reuses its key
        doc.recompute()
        if not obj.isValid():
            raise PatternsError(f"{obj.Label}: {obj.getStatusString()}")
        _beside(obj, source)
        if marks:
            _add_marks(doc, obj)
            doc.recompute()
    except Exception as exc:  # noqa: BLE001 - whatever failed, the document is left as it was
        if obj is not None:
            for child in marks_of(obj):
                doc.removeObject(child.Name)
            doc.removeObject(obj.Name)
        doc.abortTransaction()
        raise exc if isinstance(exc, PatternsError) else PatternsError(f"{name}: {exc}") from None
    doc.commitTransaction()
    from .views import view_pieces

    view_pieces(obj)
    return obj


def make_pattern(source, *, name="Pattern", marks=True, **options):
    """A parametric pattern of ``source`` in its document: its pieces, flat at 1:1, recomputed with it.

    ``source``: an object with a shape, or ``(object, ["Face1", ...])`` for some of its faces.  ``options``:
    any option of the engine's ``MeshingOptions``, ``FlattenOptions``, ``PieceOptions``, ``NestOptions`` and
    ``CheckOptions`` by its property name -- the API's name, or where two share one the command line's
    (``dart_strain`` for the darts' limit, ``max_strain`` for the check's, ``nest_gap``).  Each is a property
    of the object.  A bad option raises :class:`PatternsError` with the engine's message before anything
    is added; a failed first recompute leaves nothing in the document.
    """
    return _make(PatternFeature, source, name, marks, options)


def make_blank(source, *, name="Blank", marks=True, **options):
    """A parametric blank of a bent sheet-metal ``source``: the blank's face and its bend lines as edges.

    A source given with one selected face, ``(solid, ["Face21"])``, is the whole solid with that face fixed
    (``fixed_face="Face21"``, as FreeCAD SheetMetal takes it).  Options: those of ``UnfoldOptions``
    (``k_factor``, ``bend_table``, ``fixed_face``: an index or FreeCAD's ``FaceN``), the piece options a
    blank has, the nesting and the check options; otherwise as :func:`make_pattern`.
    """
    return _make(BlankFeature, source, name, marks, options)


def _proxy(obj):
    proxy = getattr(obj, "Proxy", None)
    if not isinstance(proxy, (PatternFeature, BlankFeature)):
        raise PatternsError(f"{getattr(obj, 'Label', obj)}: not a patterns Pattern or Blank object")
    return proxy


def export(obj, path, **options):
    """Write a Pattern or Blank object's pieces with the engine's writers (never FreeCAD's DXF exporter): the
    suffix chooses (``.dxf``, ``.svg``, ``.json`` the report); ``options``: ``WriteOptions`` fields
    (``profile``, ``layer_map``, ``version``, ``units``, ``bend_lines``)."""
    proxy = _proxy(obj)
    try:
        _, fields = proxy.request(obj)
        engine().request("export", path=os.path.abspath(str(path)), write=options, **fields)  # FreeCAD's folder
    except EngineError as exc:
        raise PatternsError(str(exc)) from None


class Report:
    """The check of a Pattern or Blank object's last recompute: ``ok``, the report's ``text``, its
    ``figures`` (worst strain and where, share above the limit, seams' mismatch)."""

    def __init__(self, obj):
        self.ok, self.text = bool(obj.Ok), obj.Report
        self.figures = json.loads(obj.Figures) if obj.Figures else {}

    def __str__(self):
        return self.text


def report_of(obj):
    """The :class:`Report` of a Pattern or Blank object's last recompute."""
    _proxy(obj)
    return Report(obj)
