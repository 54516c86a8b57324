"""The grain: turn each flat panel so that a 3D direction points along +Y."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from ..errors import InputError
from ..measure import flat_direction
from ..mesh import _readonly
from ..pattern import Flattening

__all__ = ["grain_table", "turn_to_grain"]


def grain_table(grain, model) -> dict:
    """``{panel name: unit (3,) direction}`` from ``flatten(grain=...)``."""
    if grain is None:
        return {}
    names = [p.name for p in model.panels]
    items = grain.items() if isinstance(grain, Mapping) else [(n, grain) for n in names]
    out = {}
    for name, direction in items:
        if name not in names:
            raise InputError(f"{model.name}: grain names panel {name!r}, which the model does not have")
        try:
            d = np.asarray(direction, dtype=np.float64).reshape(3)
        except (TypeError, ValueError):
            raise InputError(f"{model.name}: a grain is a 3D direction (x, y, z), got {direction!r}") from None
        if not np.all(np.isfinite(d)) or not np.any(d):
            raise InputError(f"{model.name}: a grain is a non-zero 3D direction, got {direction!r}")
        out[name] = d / math.hypot(*d)  # no BLAS: the same bits on every CPU
    return out


def turn_to_grain(result: Flattening, direction) -> Flattening:
    """The flattening turned about its centre so that ``direction`` points along +Y (a rotation)."""
    d = flat_direction(result.vertices, result.faces, result.uv, direction)
    angle = np.pi / 2 - np.arctan2(d[1], d[0])
    c, s = np.cos(angle), np.sin(angle)
    centre = result.uv.mean(axis=0)
    x, y = result.uv[:, 0] - centre[0], result.uv[:, 1] - centre[1]  # written out: a BLAS product's bits vary by CPU
    uv = np.column_stack([x * c - y * s + centre[0], x * s + y * c + centre[1]])
    return replace(result, uv=_readonly(uv))
