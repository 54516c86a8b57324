"""What every DXF writer of ``patterns`` shares: new documents, exact contours, texts, saving.

A contour (:class:`~patterns.curves.Loop`) is written as ONE closed polyline:
straight pieces as vertices, arcs as bulges (``LWPOLYLINE``, or ``POLYLINE``
on R12); a full circle as a ``CIRCLE``.  Documents are saved with fixed
metadata, so that one drawing and one set of options always give the same
bytes.  :func:`write_outline_dxf` writes bare flat loops (an engine result)
without the piece model.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..curves import Arc, Loop
from ..errors import InputError
from ..files import atomic_output
from ..units import UNIT_NAMES, Unit
from .layers import LINETYPES

__all__ = ["add_loop", "add_text", "declare_linetypes", "new_doc", "r12_units", "save", "write_outline_dxf"]


def new_doc(version: str, insunits: int):
    """``ezdxf.new`` without its warning that R12 has no ``$INSUNITS`` (we know, and say it in a text)."""
    import ezdxf

    log = logging.getLogger("ezdxf")
    level = log.level
    log.setLevel(logging.ERROR)
    try:
        return ezdxf.new(version, setup=False, units=insunits)
    finally:
        log.setLevel(level)


def declare_linetypes(doc, names) -> None:
    """Declare the non-continuous linetypes among ``names`` (:data:`~patterns.export.layers.LINETYPES`)."""
    for name in dict.fromkeys(names):
        if name in LINETYPES and name not in doc.linetypes:
            pattern, description = LINETYPES[name]
            doc.linetypes.add(name, pattern=pattern, description=description)


def add_loop(layout, loop: Loop, layer: str, *, scale: float = 1.0, r12: bool = False, circles: bool = True) -> None:
    """One closed contour: a CIRCLE for a full circle (when ``circles``), else one closed polyline with bulges."""
    if circles and loop.is_circle:
        arc = loop.pieces[0]
        assert isinstance(arc, Arc)
        layout.add_circle(tuple(arc.center * scale), arc.radius * scale, dxfattribs={"layer": layer})
        return
    rows = loop.vertices()
    rows[:, :2] *= scale
    if r12:
        layout.add_polyline2d(rows[:, :2].tolist(), close=True, dxfattribs={"layer": layer})
        if np.any(rows[:, 2] != 0):
            for vertex, bulge in zip(layout[-1].vertices, rows[:, 2]):
                vertex.dxf.bulge = float(bulge)
    elif np.any(rows[:, 2] != 0):
        layout.add_lwpolyline(rows.tolist(), format="xyb", close=True, dxfattribs={"layer": layer})
    else:
        layout.add_lwpolyline(rows[:, :2].tolist(), close=True, dxfattribs={"layer": layer})


def add_polyline(layout, points, layer: str, *, scale: float = 1.0, r12: bool = False, close: bool = True) -> None:
    """A polyline through ``points`` ((k, 2) mm)."""
    pts = (np.asarray(points) * scale).tolist()
    if r12:
        layout.add_polyline2d(pts, close=close, dxfattribs={"layer": layer})
    else:
        layout.add_lwpolyline(pts, close=close, dxfattribs={"layer": layer})


def add_text(layout, text: str, at, height: float, *, angle: float = 0.0, layer: str, scale: float = 1.0,
             align: str = "MIDDLE_CENTER") -> None:
    """A TEXT at ``at`` (mm), ``height`` mm, turned ``angle`` degrees, aligned by ``align``."""
    import ezdxf

    layout.add_text(text, height=height * scale, rotation=angle, dxfattribs={"layer": layer}).set_placement(
        tuple(np.asarray(at, dtype=np.float64) * scale), align=getattr(ezdxf.enums.TextEntityAlignment, align))


def save(doc, path) -> None:
    """Save with fixed metadata (dates 2000-01-01, constant GUIDs): the same drawing and options always give a
    byte-identical file."""
    import ezdxf

    old = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        doc.saveas(path)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = old
    # ezdxf also stamps its own "created/written by" records with the time of day.
    path = Path(path)
    text = path.read_text(encoding=doc.output_encoding, errors="surrogateescape")
    fixed = re.sub(r"(\d+\.\d+\.\d+) @ \d{4}-\d\d-\d\dT[\d:.]+\+00:00", r"\1 @ 2000-01-01T00:00:00+00:00", text)
    if fixed != text:
        path.write_text(fixed, encoding=doc.output_encoding, errors="surrogateescape")


def r12_units(path, unit: Unit, encoding: str) -> None:
    """Write ``$INSUNITS`` and ``$MEASUREMENT`` into an R12 file's header as well.

    DXF R12 predates both variables (ezdxf leaves them out), but readers that scale
    by them -- Inkscape's "read from file" -- take a file without them for inches
    and draw a millimetre drawing 25.4 times too large; R12 readers that do not
    know them skip unknown header variables.  The unit is also in a text of every
    file (``UNITS: MM``, ASTM ``Units:METRIC``)."""
    path = Path(path)
    text = path.read_text(encoding=encoding, errors="surrogateescape")
    head = re.search(r"(?m)^\s*2\r?\nHEADER\r?\n", text)
    if head is None:  # pragma: no cover - every file ezdxf writes has a header section
        return
    found = [f"  9\n$INSUNITS\n 70\n{unit.insunits}\n", f"  9\n$MEASUREMENT\n 70\n{unit.measurement}\n"]
    path.write_text(text[:head.end()] + "".join(found) + text[head.end():], encoding=encoding,
                    errors="surrogateescape")


def write_outline_dxf(path, loops: Sequence[np.ndarray], *, units: str = "mm", layer: str = "CUT") -> None:
    """Write closed flat loops as one closed polyline each (an engine result, without the piece model).

    Parameters
    ----------
    path : str or Path
        The DXF file to write (replaced atomically).
    loops : sequence of (k, 2) float64
        Flat loops, in ``units``, not repeating the first point at the end.
    units : {"mm", "cm", "m", "in"}
        The unit the coordinates are in, declared in ``$INSUNITS``.
    layer : str
        Layer of the contours.

    Raises
    ------
    InputError
        Unknown unit, or a loop with fewer than 3 points or non-finite values.
    ExportError
        The file cannot be written.
    """
    import ezdxf

    if units not in UNIT_NAMES:
        raise InputError(f"{path}: unknown unit {units!r}; choose one of {', '.join(UNIT_NAMES)}")
    for i, loop in enumerate(loops):
        loop = np.asarray(loop)
        if loop.ndim != 2 or loop.shape[1] != 2 or len(loop) < 3 or not np.all(np.isfinite(loop)):
            raise InputError(f"{path}: loop {i} is not a finite (k >= 3, 2) array")
    doc = ezdxf.new("R2000", setup=False)
    doc.header["$INSUNITS"] = Unit(units).insunits
    doc.header["$MEASUREMENT"] = Unit(units).measurement
    doc.layers.add(layer, color=1)
    msp = doc.modelspace()
    for loop in loops:
        msp.add_lwpolyline(np.asarray(loop, dtype=np.float64).tolist(), close=True, dxfattribs={"layer": layer})
    with atomic_output(path, what="DXF file") as tmp:
        save(doc, tmp)
