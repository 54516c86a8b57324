"""One layer and colour convention for every DXF a machine cuts from, and the layer maps shops ask for.

Every line of a piece has a *role*: ``cut`` (the outline), ``hole`` (a
cut-out), ``sew``, ``notch``, ``grain``, ``drill``, ``bend_up`` and
``bend_down`` (a blank's bends, by the way the flange turns), ``bend`` (a
ruling of a rolled panel, bumped either way), ``label``, ``strain``,
``stock`` and ``countersink`` (the rim of a countersunk or counterbored hole:
marked, not cut; the hole itself is a ``hole`` at its through diameter).  A :class:`LayerMap` gives each role a layer (name, AutoCAD colour
index, linetype).  Flattened patterns and unfolded blanks use the same map;
the presets:

* ``patterns`` (default): ``CUT`` 1 red, ``SEW`` 5, ``NOTCH`` 6, ``GRAIN`` 3,
  ``BEND`` 2 dashed (every bend), ``DRILL`` 4, ``LABEL`` 7, ``STRAIN`` 8,
  ``STOCK`` 9, ``COUNTERSINK`` 4;
* ``updown``: as ``patterns``, with ``BEND_UP`` and ``BEND_DOWN`` by direction
  (FreeCAD SheetMetal issue 551);
* ``solidworks``: outline, holes and countersinks' rims on ``0`` (colour 7),
  as SolidWorks writes its flat patterns, bend lines on ``BEND`` in
  SolidWorks' ``CENTERX2`` linetype;
* ``inventor``: Autodesk Inventor's flat-pattern layers (``IV_OUTER_PROFILE``,
  ``IV_INTERIOR_PROFILES``, ``IV_BEND``, ``IV_BEND_DOWN``, ``IV_ROLL``).

Bend lines are dashed in every preset.  A map is a preset, then ``role=LAYER``
overrides (``"updown,bend_up=UP"``); ``role=`` leaves a role out of the file.
Two roles a machine treats differently (the outline and a bend line) never
share a layer, in any case (``cut=bend`` is refused: ``bend`` is ``BEND`` to
every reader), unless the preset itself draws them so (``solidworks``' rims
on ``0``, as SolidWorks does).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ..errors import InputError
from ..text import printable

__all__ = ["LINETYPES", "PRESETS", "ROLES", "Layer", "LayerMap", "layer_map"]

ROLES = ("cut", "hole", "sew", "notch", "grain", "drill", "bend", "bend_up", "bend_down", "label", "strain", "stock",
         "countersink")
"""What a line on a piece is, in the order layers are declared."""

LINETYPES = {
    "DASHED": ([5.0, 3.0, -2.0], "Dashed __ __ __ __"),
    "CENTERX2": ([20.32, 12.7, -2.54, 2.54, -2.54], "Center (2x) ________  __  ________  __"),  # as SolidWorks writes it
}
"""Linetypes the presets use: ``{name: (DXF pattern: total length, then dashes (+) and gaps (-), mm; description)}``."""


@dataclass(frozen=True)
class Layer:
    """A DXF layer: its name, AutoCAD colour index and linetype."""

    name: str
    color: int = 7
    linetype: str = "CONTINUOUS"


_BASE = {"cut": Layer("CUT", 1), "hole": Layer("CUT", 1), "sew": Layer("SEW", 5), "notch": Layer("NOTCH", 6),
         "grain": Layer("GRAIN", 3), "drill": Layer("DRILL", 4), "bend": Layer("BEND", 2, "DASHED"),
         "bend_up": Layer("BEND", 2, "DASHED"), "bend_down": Layer("BEND", 2, "DASHED"),
         "label": Layer("LABEL", 7), "strain": Layer("STRAIN", 8), "stock": Layer("STOCK", 9),
         "countersink": Layer("COUNTERSINK", 4)}

PRESETS = {
    "patterns": _BASE,
    "updown": {**_BASE, "bend_up": Layer("BEND_UP", 2, "DASHED"), "bend_down": Layer("BEND_DOWN", 30, "DASHED")},
    "solidworks": {**_BASE, "cut": Layer("0", 7), "hole": Layer("0", 7), "countersink": Layer("0", 7),
                   "bend": Layer("BEND", 7, "CENTERX2"),
                   "bend_up": Layer("BEND", 7, "CENTERX2"), "bend_down": Layer("BEND", 7, "CENTERX2")},
    "inventor": {**_BASE, "cut": Layer("IV_OUTER_PROFILE", 7), "hole": Layer("IV_INTERIOR_PROFILES", 7),
                 "bend": Layer("IV_ROLL", 2, "DASHED"), "bend_up": Layer("IV_BEND", 2, "DASHED"),
                 "bend_down": Layer("IV_BEND_DOWN", 30, "DASHED")},
}
"""The layer maps by name (``--layer-map NAME``)."""


@dataclass(frozen=True)
class LayerMap:
    """Each role's layer; a role mapped to None is left out of the file.

    Attributes
    ----------
    name : str
        What it was made from (``"updown"``, ``"patterns,bend=RULING"``).
    layers : tuple of (str, Layer or None)
        ``(role, layer)`` for every role of :data:`ROLES`, in that order.
    """

    name: str
    layers: tuple

    def __getitem__(self, role: str) -> Layer | None:
        return dict(self.layers)[role]

    def declared(self) -> list:
        """The distinct layers used, in the order of :data:`ROLES` (a layer two roles share once)."""
        seen = {}
        for _, layer in self.layers:
            if layer is not None and layer.name.casefold() not in seen:  # CUT and Cut: one layer to a reader
                seen[layer.name.casefold()] = layer
        return list(seen.values())

    def __str__(self) -> str:
        return self.name


_KINDS = {"cut": "cut", "hole": "cut", "bend": "bend", "bend_up": "bend", "bend_down": "bend"}
"""Roles a machine treats alike, which may share a layer (the outline and the holes are cut; every bend is
bent); every other role is a kind of its own."""


def _layer_name(name: str, option: str) -> str:
    """``name`` if a DXF layer may be called so (ezdxf's rule: none of ``<>/\\":;?*=`` and the back quote), with
    no control character and no ``|`` (AutoCAD's mark of a layer from an external reference); else InputError."""
    from ezdxf.lldxf.validator import is_valid_layer_name

    if not is_valid_layer_name(name) or "|" in name or any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise InputError(f"{option}: {printable(name)!r} is not a DXF layer name (none of < > / \\ \" : ; ? * = | ` "
                         f"or control characters)")
    return name


def _check_shared(layers: dict, preset: dict, option: str) -> None:
    """InputError where two roles of different kinds (:data:`_KINDS`) land on one layer (DXF layer names are
    the same in any case: ``bend`` is ``BEND``) and the preset did not put them there: a cutter would cut the
    bend lines."""
    by_name: dict = {}
    for role in ROLES:
        if layers[role] is not None:
            by_name.setdefault(layers[role].name.casefold(), []).append(role)
    for roles in by_name.values():
        kinds = {_KINDS.get(r, r) for r in roles}
        own = {preset[r].name.casefold() if preset[r] is not None else None for r in roles}
        if len(kinds) > 1 and len(own) > 1:
            name = layers[roles[0]].name
            raise InputError(f"{option}: roles {', '.join(roles)} would share layer {name!r} (layer names are the "
                             f"same in any case): a machine cuts, bends or marks a whole layer alike; give each "
                             f"its own layer")


def _item(role, value, option) -> Layer | None:
    if role not in ROLES:
        raise InputError(f"{option}: unknown role {role!r}; the roles are {', '.join(ROLES)}")
    if value is None or value == "":
        return None
    if isinstance(value, Layer):
        return value
    if isinstance(value, str):
        return Layer(_layer_name(value, f"{option}[{role!r}]"), _BASE[role].color, _BASE[role].linetype)
    raise InputError(f"{option}[{role!r}] must be a layer name or a patterns.export.layers.Layer, got "
                     f"{type(value).__name__}")


def layer_map(value, option: str = "layer_map") -> LayerMap:
    """A :class:`LayerMap` from a preset name, ``"preset,role=LAYER,..."``, a mapping ``{role: layer name or
    Layer or None}`` (over the ``patterns`` preset), or a LayerMap; InputError naming what is wrong."""
    if isinstance(value, LayerMap):
        return value
    if isinstance(value, Mapping):
        layers = dict(PRESETS["patterns"])
        for role, layer in value.items():
            layers[role] = _item(role, layer, option)
        name = "patterns," + ",".join(f"{k}={getattr(v, 'name', v) or ''}" for k, v in value.items())
        _check_shared(layers, PRESETS["patterns"], option)
        return LayerMap(name, tuple((r, layers[r]) for r in ROLES))
    if not isinstance(value, str):
        raise InputError(f"{option} must be a preset ({', '.join(PRESETS)}), 'preset,role=LAYER,...' or a mapping, "
                         f"got {type(value).__name__}")
    parts = [p.strip() for p in value.split(",") if p.strip()]
    preset = "patterns"
    if parts and "=" not in parts[0]:
        preset = parts.pop(0)
        if preset not in PRESETS:
            raise InputError(f"{option}: unknown preset {preset!r}; the presets are {', '.join(PRESETS)}")
    layers = dict(PRESETS[preset])
    for part in parts:
        role, sep, name = part.partition("=")
        if not sep:
            raise InputError(f"{option}: expected role=LAYER after the preset, got {part!r}")
        layers[role.strip()] = _item(role.strip(), name.strip(), option)
    _check_shared(layers, PRESETS[preset], option)
    return LayerMap(value, tuple((r, layers[r]) for r in ROLES))
