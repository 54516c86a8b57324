"""DXF output with ezdxf.

:func:`write_outline_dxf` writes the cut contours of a flat pattern: each
boundary loop one closed polyline on layer ``CUT``, z = 0, true scale, units
declared in the header.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from ._atomic import atomic_output

__all__ = ["UNITS", "write_outline_dxf"]

UNITS = {"mm": 4, "cm": 5, "m": 6, "in": 1}
"""Unit names accepted by the writers and their DXF ``$INSUNITS`` codes."""


def write_outline_dxf(path, loops: Sequence[np.ndarray], *, units: str = "mm", layer: str = "CUT") -> None:
    """Write closed flat loops as one closed polyline each.

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
    import ezdxf  # heavy; only when exporting

    if units not in UNITS:
        raise InputError(f"unknown unit {units!r}; choose one of {', '.join(UNITS)}")
    for i, loop in enumerate(loops):
        loop = np.asarray(loop)
        if loop.ndim != 2 or loop.shape[1] != 2 or len(loop) < 3 or not np.all(np.isfinite(loop)):
            raise InputError(f"{path}: loop {i} is not a finite (k >= 3, 2) array")
    doc = ezdxf.new("R2000", setup=False)
    doc.header["$INSUNITS"] = UNITS[units]
    doc.header["$MEASUREMENT"] = 0 if units == "in" else 1
    doc.layers.add(layer, color=1)
    msp = doc.modelspace()
    for loop in loops:
        msp.add_lwpolyline(np.asarray(loop, dtype=np.float64).tolist(), close=True, dxfattribs={"layer": layer})
    with atomic_output(path, what="DXF file") as tmp:
        doc.saveas(tmp)
