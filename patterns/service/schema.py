"""The options of a host's objects: one property per option of the records, declared once, checked once.

A host (FreeCAD, Blender) shows the options of a pattern or a blank as properties of its own objects and
sends their values back as they are; the worker makes the option records from them with
:func:`patterns.options.from_text` -- the records' own validator, the one the API and the command line use.
The schema a host builds its properties from (:func:`schema`) is sent by the worker (``hello``), so the host
side declares no option of its own.

Naming: a property is named as its option, except where two records of one object share a name; then a
record whose option has its own command-line flag takes the flag's name (``FlattenOptions.max_strain`` is
``dart_strain`` beside ``CheckOptions.max_strain``, the nester's ``gap`` is ``nest_gap`` beside the pieces'
``gap``), as on the command line.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..audit import CheckOptions
from ..errors import InputError
from ..flattening import FlattenOptions
from ..nesting import NestOptions
from ..options import flag_of, from_text, is_number
from ..pieces import PieceOptions
from ..pieces.options import PATTERN_ONLY
from ..sheetmetal import UnfoldOptions
from ..tessellate import MeshingOptions

__all__ = ["KINDS", "Kind", "Property", "records_of", "schema"]


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


def _kind(f, spec) -> str:
    if isinstance(f.default, bool):
        return "bool"
    if spec.choices is not None:
        return "choice"
    if f.default is not None and spec.integer:
        return "int"
    if f.default is not None and not spec.repeat and is_number(f.default) and (spec.check is None or spec.parse is float):
        return "float"
    return "text"


def _default(kind: str, default):
    if kind == "text":
        return "" if default is None else str(default)
    if kind == "choice":
        return str(getattr(default, "value", default))
    return default


@dataclass(frozen=True)
class Kind:
    """An object kind of the hosts (``pattern``, ``blank``): its records, their groups, the options it has not."""

    name: str
    records: tuple
    groups: tuple
    skip: frozenset = frozenset()

    def properties(self) -> tuple:
        """Every option as a :class:`Property`, record by record."""
        options = [(record, group, f) for record, group in zip(self.records, self.groups) for f in fields(record)
                   if "spec" in f.metadata and (record, f.name) not in self.skip]
        shared = {f.name for _, _, f in options if sum(g.name == f.name for _, _, g in options) > 1}
        out, taken = [], set()
        for record, group, f in options:
            spec = f.metadata["spec"]
            name = f.name
            if name in shared and spec.flag and not spec.flag.startswith("--no-"):
                name = flag_of(f.name, spec).lstrip("-").replace("-", "_")
            if name in taken:
                raise TypeError(f"{self.name}: two options are both named {name!r}: give one a flag of its own")
            taken.add(name)
            kind = _kind(f, spec)
            out.append(Property(name, record.__name__, f.name, group, kind, _default(kind, f.default), spec.help,
                                tuple(spec.choices or ()), spec.low, spec.high))
        return tuple(out)


KINDS = {
    "pattern": Kind("pattern", (MeshingOptions, FlattenOptions, PieceOptions, NestOptions, CheckOptions),
                    ("Meshing", "Flattening", "Pieces", "Nesting", "Check")),
    "blank": Kind("blank", (UnfoldOptions, PieceOptions, NestOptions, CheckOptions),
                  ("Unfolding", "Pieces", "Nesting", "Check"), frozenset((PieceOptions, n) for n in PATTERN_ONLY)),
}
"""The kinds of object a host makes, by name."""


def schema() -> dict:
    """``{kind: [property as a dict, ...]}``: what a host builds its objects' properties from."""
    return {name: [p.to_dict() for p in kind.properties()] for name, kind in KINDS.items()}


def _text(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return "" if value is None else str(value)


def records_of(kind: str, values: dict, *, name: str) -> dict:
    """``{record class: record}`` of one object from its properties' ``values`` (``{property name: value}``,
    those left out at their defaults), each checked by its record.

    Raises
    ------
    InputError
        An unknown kind or property (naming the known ones), or a bad value (the record's own message,
        after ``name``).
    """
    if kind not in KINDS:
        raise InputError(f"{name}: unknown kind {kind!r}; the kinds are {', '.join(KINDS)}")
    if not isinstance(values, dict):
        raise InputError(f"{name}: the options must be an object of property names and values")
    properties = KINDS[kind].properties()
    known = {p.name for p in properties}
    unknown = sorted(set(values) - known)
    if unknown:
        raise InputError(f"{name}: unknown option {unknown[0]!r}; the options are {', '.join(sorted(known))}")
    texts: dict = {}
    for p in properties:
        if p.name in values:
            texts.setdefault(p.record, {})[p.option] = _text(values[p.name])
    return {record: from_text(record, texts.get(record.__name__, {}), name=name) for record in KINDS[kind].records}
