"""The options of :func:`patterns.flatten`, declared once: :class:`FlattenOptions`.

The command line makes its flattening flags from these fields; the mesh engine
(:func:`patterns.flatten_mesh`) checks its own relaxation keywords with the same
declarations (:meth:`FlattenOptions.checked`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..options import Options, label, option
from .energy import ENERGIES
from .seams import Ease, SeamLengths

__all__ = ["METHODS", "REFERENCES", "FlattenOptions", "parse_direction", "parse_ease"]

METHODS = ("relaxed", "isometric", "conformal")
"""The flattening methods :func:`patterns.flatten_mesh` accepts."""

REFERENCES = ("inside", "outside", "mid")
"""Which skin of the sheet the CAD model shows."""


def parse_direction(text: str):
    """``"X,Y,Z"`` (command line) as a tuple of three floats."""
    try:
        values = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"expected X,Y,Z numbers, got {text!r}") from None
    if len(values) != 3:
        raise ValueError(f"expected three numbers X,Y,Z, got {text!r}")
    return values


def parse_ease(text: str) -> Ease:
    """``"SEAM:PANEL:AMOUNT"`` (command line; mm, or a percentage with ``%``) as an :class:`Ease`."""
    try:
        seam, panel, amount = text.split(":")
        if amount.endswith("%"):
            return Ease(int(seam), panel, ratio=float(amount[:-1]) / 100.0)
        return Ease(int(seam), panel, mm=float(amount))
    except ValueError:
        raise ValueError(f"expected SEAM:PANEL:MM or SEAM:PANEL:PERCENT%, got {text!r}") from None


def ease_text(ease: Ease) -> str:
    """An :class:`Ease` as the command line writes it (the inverse of :func:`parse_ease`); ValueError for one
    with both ``mm`` and ``ratio``, which that text cannot say."""
    if ease.mm and ease.ratio:
        raise ValueError(f"seam {ease.seam} of {ease.panel}: an ease of both mm and ratio has no text form")
    amount = f"{ease.ratio * 100!r}%" if ease.ratio else repr(float(ease.mm))
    return f"{ease.seam}:{ease.panel}:{amount}"


def _grain(value, option):
    """A 3D direction, or a mapping of panel names to 3D directions (names checked against the model later)."""
    if isinstance(value, Mapping):
        return {str(name): _direction(d, f"{option}[{name!r}]") for name, d in value.items()}
    return _direction(value, option)


def _direction(value, option):
    try:
        d = np.asarray(value, dtype=np.float64).reshape(3)
    except (TypeError, ValueError):
        raise InputError(f"{option} must be a 3D direction (x, y, z), got {value!r}") from None
    if not np.all(np.isfinite(d)) or not np.any(d):
        raise InputError(f"{option} must be a non-zero 3D direction, got {value!r}")
    d = d / np.abs(d).max()  # a direction: its length does not matter (1e308, 1e308, 0 is (1, 1, 0))
    return tuple(float(x) for x in d / math.hypot(*d))  # no BLAS: the same bits on every CPU


def _ease(value, option):
    items = [value] if isinstance(value, Ease) else value
    try:
        items = tuple(items)
    except TypeError:
        raise InputError(f"{option} must be a patterns.Ease or a sequence of them, got {type(value).__name__}") from None
    for item in items:
        if not isinstance(item, Ease):
            raise InputError(f"{option} must be a patterns.Ease or a sequence of them, got a {type(item).__name__}")
    return items


@dataclass(frozen=True, repr=False)
class FlattenOptions(Options):
    """How :func:`patterns.flatten` lays a model's panels flat (``patterns flatten``, ``check``, ``batch``)."""

    method: str = option("relaxed", "the mesh engine for freeform panels: relaxed (the greedy start relaxed to "
                                    "the least strain, always one-to-one: for patterns), isometric (the greedy "
                                    "grower alone) or conformal (the paper as written)", choices=METHODS)
    exact: bool = option(True, "unroll planar, cylindrical and conical CAD faces analytically (exact, strain 0); "
                               "the command line's --no-exact sends them through the mesh engine too",
                               off="send planar, cylindrical and conical CAD faces through the mesh engine too, "
                                   "instead of unrolling them analytically")
    thickness: float = option(0.0, "sheet thickness, mm: develop the neutral surface, k_factor x thickness from "
                                   "the inside skin", low=0, unit="mm")
    k_factor: float = option(0.5, "position of the neutral surface from the inside skin, 0..1", low=0, high=1,
                             metavar="K")
    reference: str = option("mid", "which skin of the sheet the model shows", choices=REFERENCES)
    grain: tuple | dict | None = option(None, "a 3D direction to point along +Y on every panel (fabric grain, rolling "
                                 "direction), or (API) a mapping of panel names to directions",
                           check=_grain, parse=parse_direction, metavar="X,Y,Z")
    seams: str = option("true", "relaxed: hold every seam edge at its 3D length (true), each seam side's total "
                                "length (total), or nothing (free)", choices=tuple(m.value for m in SeamLengths))
    ease: tuple | None = option(None, "deliberate extra length on one side of a seam (patterns.Ease; on the command "
                                "line SEAM:PANEL:MM or SEAM:PANEL:PERCENT%, repeatable)",
                          check=_ease, parse=parse_ease, repeat=True, metavar="SEAM:PANEL:AMOUNT", text=ease_text)
    max_strain: float | None = option(None, "cut darts into a freeform panel whose worst triangle strain is "
                                            "above this ratio (0.03 = 3 %): the fewest evenly spaced darts, as short "
                                            "as the limit allows",
                                      optional=True, unit="ratio", flag="--dart-strain")
    max_darts: int = option(12, "at most this many darts per panel (or slashes, on a saddle-shaped one), 0..100",
                            low=0, high=100, integer=True, metavar="N")
    gores: bool = option(False, "with a strain limit: split a panel above it into gores along the dart lines, "
                                "run on to the crown, each cut a seam held at its 3D length, instead of darts "
                                "that stop short")
    max_gores: int = option(24, "at most this many pieces (cuts from its outline) a panel above the strain limit "
                                "is split into: gores, or, with darts, pieces with darts where max_darts darts "
                                "alone fall short (0: darts only, never split), 0..100",
                            low=0, high=100, integer=True, metavar="N")
    max_iterations: int = option(500, "relaxed: at most this many relaxation iterations (up to 100000)", low=0,
                                 low_open=True, high=100_000, integer=True, metavar="N")
    energy_tolerance: float = option(1e-6, "relaxed: stop when the energy falls by less than this fraction per "
                                           "iteration", low=0, metavar="R")
    min_stretch: float | None = option(None, "relaxed: keep every triangle at least this fraction of its size in "
                                             "every direction, 0..1", low=0, high=1, low_open=True,
                                       high_open=True, optional=True, metavar="R")
    energy: str = option("auto", "relaxed: the distortion minimised (auto: ARAP, the squared principal strains, "
                                 "or the hybrid where ARAP would press triangles flat)", choices=ENERGIES)

    def __post_init__(self):
        super().__post_init__()
        if self.method != "relaxed":
            for name in ("ease", "min_stretch"):
                if getattr(self, name) is not None:
                    raise InputError(f"{label(name)} applies to {label('method')} relaxed only")
            if self.energy != "auto":
                raise InputError(f"{label('energy')} applies to {label('method')} relaxed only")
        if self.gores and self.max_strain is None:  # gores are cut at a strain limit: without one, nothing to do
            raise InputError(f"{label('gores')} cuts a panel into gores where its strain is above "
                             f"{label('max_strain')}: give that limit too (e.g. {label('max_strain')} 0.03)")
        if self.gores and self.max_gores < 1:
            raise InputError(f"{label('gores')} needs {label('max_gores')} 1 or more")
        if self.ease and self.seams == "free":
            raise InputError(f"{label('ease')} needs {label('seams')} true or total")
