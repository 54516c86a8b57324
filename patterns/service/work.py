"""What the worker does for a host: make a pattern or a blank of a shape, export it, say what it found.

Each object is computed as ``patterns flatten`` (or ``unfold``) computes it -- load through the library's
one reading path, flatten or unfold, pieces, nest when asked, check -- and answered as BREP text and plain
numbers (:func:`make`).  The last results are kept by the request's key (:class:`Results`), so an export
right after a recompute writes the pieces the host shows without computing them again.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import time
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ..audit import Report, checked_drawing
from ..blank import Blank
from ..bundle import HOST_KINDS, Bundle
from ..errors import InputError
from ..export import WriteOptions, write
from ..export.layers import PRESETS
from ..flattening import flatten
from ..measure import triangle_strains
from ..nesting import layout
from ..pattern import Pattern
from ..pieces import Drawing, drawing_of, piece_labels
from ..reading import mesh_model
from ..sheetmetal import unfold
from ..tessellate import mesh_shape
from . import brep

__all__ = ["Made", "Results", "bundle_of", "export", "figures", "key_of", "make", "validate"]


_FLAGS = re.compile(r"(?m)^[01]{7}$")
"""A BREP shape's flags line (free, modified, checked, orientable, closed, infinite, convex): left out of keys."""


def _stamp(path: str) -> list:
    """A file's size and modification time: an edited table file is a new request."""
    status = os.stat(path)
    return [status.st_size, status.st_mtime_ns]


def key_of(kind: str, shape: str, options: dict, name: str) -> str:
    """The key of a request's result: SHA-256 of its kind, name, options and shape (what a host hashes too;
    the name is in the pieces' names and labels)."""
    files = {v: _stamp(v) for v in options.values() if isinstance(v, str) and os.path.isfile(v)}  # a bend table
    text = json.dumps([kind, name, options, files], sort_keys=True, separators=(",", ":"))
    geometry = _FLAGS.sub("", shape)  # a shape's state flags change when it is only displayed (tessellated)
    return hashlib.sha256(text.encode() + b"\0" + geometry.encode()).hexdigest()


@dataclass(frozen=True)
class Made:
    """One computed object: its request's key, the subject (a Pattern or a Blank), its drawing, the checked
    drawing, the report."""

    key: str
    subject: Pattern | Blank
    drawing: Drawing
    checked: Drawing
    report: Report


class Results:
    """The last ``size`` results, by key (oldest dropped first); ``computed`` counts the computations."""

    def __init__(self, size: int = 8):
        self.size, self.computed = size, 0
        self._items: OrderedDict = OrderedDict()

    def get(self, kind: str, shape: str, options: dict, name: str) -> Made:
        key = key_of(kind, shape, options, name)
        if key in self._items:
            self._items.move_to_end(key)
            return self._items[key]
        made = _compute(kind, shape, options, name, key)
        self.computed += 1
        self._items[key] = made
        while len(self._items) > self.size:
            self._items.popitem(last=False)
        return made


def bundle_of(kind: str, options: dict, *, name: str) -> Bundle:
    """The bundle of a host's object (kind ``pattern`` or ``blank``) from its request's options, each checked by
    its record (InputError naming ``name``)."""
    if kind not in HOST_KINDS:
        raise InputError(f"{name}: unknown kind {kind!r}; the kinds are {', '.join(HOST_KINDS)}")
    return Bundle.from_json(kind, options, name=name)


def _compute(kind: str, shape: str, options: dict, name: str, key: str = "") -> Made:
    bundle = bundle_of(kind, options, name=name)  # every option checked before the shape is read
    if shape.startswith("{"):  # a mesh (its arrays as JSON: see _fields), never BREP text
        if kind != "pattern":
            raise InputError(f"{name}: a blank is unfolded from a CAD shape (BREP), not a mesh")
        mesh = json.loads(shape)
        model = mesh_model(np.asarray(mesh["vertices"], dtype=np.float64), np.asarray(mesh["faces"]), name=name,
                           seams=mesh.get("seams"))
        subject = flatten(model, bundle.flatten)
    elif kind == "pattern":
        model = mesh_shape(brep.from_brep(shape, name), bundle.load, name=name)
        subject = flatten(model, bundle.flatten)
    else:
        subject = unfold(brep.from_brep(shape, name), bundle.unfold, name=name)
    nesting = bundle.nest
    if nesting.active:
        drawing = layout(subject, nesting, pieces=bundle.pieces).drawing()
    else:
        drawing = drawing_of(subject, bundle.pieces)
    report, checked = checked_drawing(subject, drawing, bundle.check)
    return Made(key, subject, drawing, checked, report)


def _face_strain(made: Made, n_faces: int) -> list:
    """The largest principal strain of the panel of each of the source's ``n_faces`` faces (0 for a blank)."""
    strain = [0.0] * n_faces
    if isinstance(made.subject, Pattern):
        for flat, numbers in zip(made.subject.panels, made.report.panels):
            for face in flat.panel.cad_faces:
                if 0 <= face < n_faces:
                    strain[face] = float(numbers.strain_max)
    return strain


def figures(report: Report) -> dict:
    """The check's figures a host shows: the worst strain and where (panel, point in the drawing, mm), the
    share of the 3D area above the limit, the largest seam mismatch and where, the findings by severity."""
    worst = max(report.panels, key=lambda p: p.strain_max, default=None)
    area = sum(p.area_3d for p in report.panels)
    above = [p for p in report.panels if p.share_above_limit is not None]
    seam = max(report.seams, key=lambda s: abs(s.mismatch), default=None)
    counts: dict = {}
    for f in report.findings:
        counts[f.severity.value] = counts.get(f.severity.value, 0) + 1
    return {
        "ok": report.ok,
        "max_strain": report.max_strain,
        "strain_max": None if worst is None else worst.strain_max,
        "strain_max_panel": None if worst is None else worst.name,
        "strain_max_at": None if worst is None else [float(c) for c in worst.strain_max_at],
        "share_above_limit": (sum(p.share_above_limit * p.area_3d for p in above) / area) if above and area else None,
        "seam_mismatch": None if seam is None else abs(seam.mismatch),
        "seam_mismatch_at": None if seam is None else f"seam {seam.id} ({' | '.join(seam.panels)})",
        "panels": len(report.panels), "seams": len(report.seams), "blanks": len(report.blanks),
        "findings": counts,
    }


def make(results: Results, request: dict) -> dict:
    """The reply to ``make``: the pieces (BREP), their marks, labels, the report and its figures."""
    started = time.perf_counter()
    kind, shape, options, name = _fields(request)
    made = results.get(kind, shape, options, name)
    labels = [label for p in made.drawing.pieces for label in piece_labels(p)]
    marks = brep.marks(made.drawing.pieces, labels)
    n_faces = request.get("faces", 0)
    if not isinstance(n_faces, int) or n_faces < 0:
        raise InputError(f"{name}: faces must be a count, got {n_faces!r}")
    return {
        "key": made.key,  # hashed once, by Results.get
        "shape": brep.pieces_brep(made.drawing.pieces, bends=kind == "blank"),
        "marks": marks,
        "colours": {role: layer.color for role, layer in PRESETS["patterns"].items()},
        "labels": [lb.text for lb in labels],
        "pieces": len(made.drawing.pieces),
        "ok": made.report.ok,
        "report": str(made.report),
        "figures": figures(made.report),
        "face_strain": _face_strain(made, n_faces),
        **(_flat(made, shape) if shape.startswith("{") else {}),
        "seconds": time.perf_counter() - started,
    }


def _flat(made: Made, shape: str) -> dict:
    """For a mesh: ``flat``, each piece as a flat mesh where the drawing lays it (``vertices`` (n, 2) mm,
    ``faces``, ``strain`` per face: the dominant principal strain), its cut ``outline`` (mm) and its panel's name;
    and ``triangle_strain``, the strain of each of the request's triangles (0 where none was flattened)."""
    from scipy.spatial import cKDTree

    pattern = made.subject
    strains = [triangle_strains(flat.vertices, flat.faces, flat.flattening.uv).dominant for flat in pattern.panels]
    pieces = []
    for piece in made.drawing.pieces:  # a copy shares its panel's strains
        flat = pattern.panels[piece.source.index]
        pieces.append({"name": piece.name, "panel": flat.name,
                       "vertices": np.round(piece.placement(flat.uv), 6).tolist(),
                       "faces": np.asarray(flat.faces).tolist(),
                       "strain": np.round(strains[piece.source.index], 8).tolist(),
                       "outline": np.round(piece.outline.points(0.05), 6).tolist()})
    mesh = json.loads(shape)
    v, f = np.asarray(mesh["vertices"], dtype=np.float64), np.asarray(mesh["faces"], dtype=np.int64)
    out = np.zeros(len(f))
    if len(f) and pattern.panels:  # every flattened triangle (a dart's split ones too), where it lies in 3D
        centres = np.concatenate([flat.vertices[flat.faces].mean(axis=1) for flat in pattern.panels])
        _, nearest = cKDTree(centres).query(v[f].mean(axis=1))
        out = np.concatenate(strains)[nearest]  # each triangle: the flattened triangle at its centre
    return {"flat": pieces, "triangle_strain": np.round(out, 8).tolist()}


def validate(request: dict) -> dict:
    """The reply to ``validate``: the options checked by their records, nothing computed (InputError if bad)."""
    name = request.get("name") or "shape"
    bundle_of(request.get("kind"), request.get("options") or {}, name=str(name))
    return {}


def export(results: Results, request: dict) -> dict:
    """The reply to ``export``: the object's pieces written to ``path`` by :func:`patterns.write` (the
    suffix chooses: ``.dxf``, ``.svg``, ``.json``), with ``write`` options (:class:`patterns.WriteOptions`)."""
    kind, shape, options, name = _fields(request)
    path = request.get("path")
    if not isinstance(path, str) or not path:
        raise InputError(f"{name}: export needs a path")
    extra = request.get("write") or {}
    if not isinstance(extra, dict):
        raise InputError(f"{name}: write options must be an object of WriteOptions fields")
    WriteOptions.of(None, extra, name=name)  # checked before any work
    made = results.get(kind, shape, options, name)
    write(made.checked if path.lower().endswith(".json") else made.drawing, path, **extra)
    return {"path": path}


def _fields(request: dict) -> tuple:
    name = request.get("name") or "shape"
    if not isinstance(name, str):
        raise InputError("name must be text")
    kind, shape, options = request.get("kind"), request.get("shape"), request.get("options") or {}
    if not isinstance(kind, str):
        raise InputError(f"{name}: kind must be 'pattern' or 'blank'")
    mesh = request.get("mesh")
    if mesh is not None:  # a mesh: {"vertices": (n, 3) mm, "faces": (m, 3) indices, "seams": (k, 2) edges}
        if not isinstance(mesh, dict) or not {"vertices", "faces"} <= set(mesh):
            raise InputError(f"{name}: mesh must be an object with vertices (n x 3, mm) and faces (m x 3)")
        shape = json.dumps({"vertices": mesh["vertices"], "faces": mesh["faces"], "seams": mesh.get("seams") or []},
                           separators=(",", ":"))
    if not isinstance(shape, str) or shape.startswith("{") and mesh is None:
        raise InputError(f"{name}: shape must be BREP text (or give a mesh)")
    return kind, shape, options, name
