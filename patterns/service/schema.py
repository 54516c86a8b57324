"""The options of a host's objects: one property per option of the kind's :class:`~patterns.bundle.Bundle`.

A host (FreeCAD, Blender) shows the options of a pattern or a blank as properties of its own objects and
sends their values back as they are; the worker makes the bundle from them (:meth:`Bundle.from_json
<patterns.bundle.Bundle.from_json>`) -- the records' own validator, the one the API and the command line use.
The schema a host builds its properties from (:func:`schema`) is sent by the worker (``hello``), so the host
side declares no option of its own, and a property is named as the bundle names its option (``dart_strain``
for the darts' limit beside the check's ``max_strain``, ``nest_gap`` beside the pieces' ``gap``).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..bundle import HOST_KINDS, KINDS, Bundle, Name
from ..errors import InputError
from ..options import is_number

__all__ = ["Property", "properties", "records_of", "schema"]


@dataclass(frozen=True)
class Property:
    """One option as a host's property.

    Attributes
    ----------
    name : str
        The property's name (see the module).
    record, option : str
        The record's class name and the option's name in it.
    group : str
        The property group (the record's page in a task panel).
    kind : {"bool", "choice", "int", "float", "text"}
        A switch, one of ``choices``, a whole number, a number, or text (optional numbers, a grain
        direction, ``2500x1250``, ``NAME=N;NAME=N``): empty text is the default.
    default : bool, int, float or str
        The default, in the property's kind.
    help : str
        The option's help, one or two sentences.
    choices : tuple of str
        A choice's values; empty otherwise.
    low, high : float or None
        A number's bounds.
    """

    name: str
    record: str
    option: str
    group: str
    kind: str
    default: bool | int | float | str
    help: str
    choices: tuple = ()
    low: float | None = None
    high: float | None = None

    def to_dict(self) -> dict:
        return {"name": self.name, "record": self.record, "option": self.option, "group": self.group,
                "kind": self.kind, "default": self.default, "help": self.help, "choices": list(self.choices),
                "low": self.low, "high": self.high}


def _kind(entry: Name) -> str:
    spec, default = entry.spec, entry.default
    if isinstance(default, bool):
        return "bool"
    if spec.choices is not None:
        return "choice"
    if default is not None and spec.integer:
        return "int"
    if default is not None and not spec.repeat and is_number(default) and (spec.check is None or spec.parse is float):
        return "float"
    return "text"


def _default(kind: str, default):
    if kind == "text":
        return "" if default is None else str(default)
    if kind == "choice":
        return str(getattr(default, "value", default))
    return default


def properties(kind: str) -> tuple:
    """Every option of a host's ``kind`` (``pattern``, ``blank``) as a :class:`Property`, record by record."""
    if kind not in HOST_KINDS:
        raise InputError(f"unknown kind {kind!r}; the kinds are {', '.join(HOST_KINDS)}")
    slots = {slot.name: slot for slot in KINDS[kind].slots}
    out = []
    for entry in Bundle.names(kind):
        slot, option = entry.targets[0]
        kind_of = _kind(entry)
        spec = entry.spec
        out.append(Property(entry.name, slots[slot].record.__name__, option, entry.group, kind_of,
                            _default(kind_of, entry.default), spec.help, tuple(spec.choices or ()), spec.low,
                            spec.high))
    return tuple(out)


def schema() -> dict:
    """``{kind: [property as a dict, ...]}``: what a host builds its objects' properties from."""
    return {kind: [p.to_dict() for p in properties(kind)] for kind in HOST_KINDS}


def records_of(kind: str, values: dict, *, name: str) -> dict:
    """Deprecated (goes in 0.3.0): ``{record class: record}`` of a host's object; use
    :meth:`patterns.bundle.Bundle.from_json` and :meth:`~patterns.bundle.Bundle.records`."""
    import warnings

    warnings.warn("patterns.service.records_of goes in 0.3.0: use patterns.bundle.Bundle.from_json(kind, values)",
                  DeprecationWarning, stacklevel=2)
    bundle = Bundle.from_json(kind, values, name=name)
    return {type(record): record for record in bundle.records().values()}
