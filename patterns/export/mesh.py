"""Flat meshes as Wavefront OBJ (z = 0), for viewers and texture tools."""

from __future__ import annotations

import numpy as np

from ..files import atomic_output

__all__ = ["write_flat_obj"]


def write_flat_obj(path, uv: np.ndarray, faces: np.ndarray) -> None:
    """Write the flat mesh ``(uv, faces)`` as an OBJ with z = 0.

    Parameters
    ----------
    path : str or Path
        Replaced atomically.
    uv : (n, 2) float64
        Flat positions, written with 17 significant digits (lossless).
    faces : (m, 3) int64
        Zero-based; written one-based as OBJ wants.
    """
    with atomic_output(path, what="OBJ file") as tmp, open(tmp, "w", encoding="ascii") as out:
        out.write("# flat pattern written by patterns; z = 0, true scale\n")
        np.savetxt(out, np.column_stack([uv, np.zeros(len(uv))]), fmt="v %.17g %.17g %.17g")
        np.savetxt(out, faces + 1, fmt="f %d %d %d")
