"""One bundle of option records per run: what the command line, ``batch``, the worker and every host read.

A run of the pipeline takes several option records (:class:`~patterns.LoadOptions`,
:class:`~patterns.FlattenOptions`, :class:`~patterns.CheckOptions`, ...).  A :class:`Bundle` holds them, frozen,
for one :data:`KINDS` of run, and is made by one door per front end -- all of them down to the records' own
validator (:meth:`patterns.options.Options.of`):

* :meth:`Bundle.of` -- Python values by name (``batch(dart_strain=0.03, max_strain=0.05)``);
* :meth:`Bundle.from_arguments` -- the command line's parsed flags;
* :meth:`Bundle.from_json` -- a worker request or a host's properties (JSON values, or text as the command line
  takes it); :meth:`Bundle.to_json` writes that form back.

One name per meaning, everywhere: an option is named as its field, except where two records of one kind have a
field of the same name; then the one with a command-line flag of its own takes the flag's name
(``FlattenOptions.max_strain`` is ``dart_strain``, the check's ``max_strain`` stays; the nester's ``gap`` is
``nest_gap`` beside the pieces' ``gap``), as the command line has them.  Two records that share one flag
(``--units``) share one name: the value goes to both.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, fields
from enum import Enum
from typing import Any

from .audit import CheckOptions
from .errors import InputError
from .export import WriteOptions
from .flattening import FlattenOptions
from .nesting import NestOptions
from .options import Spec, cli_flags, flag_of, from_arguments, given_flags, is_number, naming, parse_text, suggest
from .pieces import PieceOptions
from .pieces.options import PATTERN_ONLY
from .reading import LoadOptions
from .sheetmetal import UnfoldOptions
from .tessellate import MeshingOptions

__all__ = ["KINDS", "Bundle", "Kind", "Name", "Slot"]


@dataclass(frozen=True)
class Slot:
    """One record of a kind of run.

    Attributes
    ----------
    name : {"load", "flatten", "unfold", "pieces", "nest", "check", "write"}
        The bundle's field that holds it.
    record : type
        The :class:`~patterns.options.Options` class.
    group : str
        Its title in a host's task panel (and the command line's help).
    skip : tuple of str
        Fields this kind has not (a blank's pieces have no seam allowance).
    """

    name: str
    record: type
    group: str
    skip: tuple = ()


@dataclass(frozen=True)
class Name:
    """One option as the bundle names it.

    Attributes
    ----------
    name : str
        The name (see the module).
    targets : tuple of (str, str)
        ``(slot, field)`` of every record it sets: one, or two for a shared flag (``units``).
    spec : Spec
        The declaration (of the first target).
    default : Any
        The field's default.
    group : str
        The first target's group.
    """

    name: str
    targets: tuple
    spec: Spec
    default: Any
    group: str


@dataclass(frozen=True)
class Kind:
    """A kind of run: its records, in order."""

    name: str
    slots: tuple

    def names(self) -> tuple:
        """Every option of the kind as a :class:`Name`, record by record (see the module for the rule)."""
        options = [(slot, f) for slot in self.slots for f in fields(slot.record)
                   if "spec" in f.metadata and f.name not in slot.skip]
        count = Counter(f.name for _, f in options)
        by_flag: dict = {}
        for slot, f in options:
            by_flag.setdefault(cli_flags(slot.record)[f.name], []).append((slot, f))
        out: dict = {}
        for shared in by_flag.values():
            slot, f = shared[0]
            spec = f.metadata["spec"]
            name = f.name
            if len(shared) == 1 and count[f.name] > 1 and spec.flag and not spec.flag.startswith("--no-"):
                name = flag_of(f.name, spec).lstrip("-").replace("-", "_")
            if name in out:
                raise TypeError(f"{self.name}: two options are both named {name!r}: give one a flag of its own")
            out[name] = Name(name, tuple((s.name, g.name) for s, g in shared), spec, f.default, slot.group)
        order = {(s.name, f.name): i for i, (s, f) in enumerate(options)}
        return tuple(sorted(out.values(), key=lambda n: order[n.targets[0]]))

    def labels(self, slot: str) -> dict:
        """``{field name: option name}`` of one record of the kind: what its messages call its options."""
        return {field: n.name for n in self.names() for s, field in n.targets if s == slot}


def _kind(*slots: Slot, name: str) -> Kind:
    return Kind(name, slots)


_LOAD = Slot("load", LoadOptions, "Loading")
_FLATTEN = Slot("flatten", FlattenOptions, "Flattening")
_UNFOLD = Slot("unfold", UnfoldOptions, "Unfolding")
_PIECES = Slot("pieces", PieceOptions, "Pieces")
_BLANK_PIECES = Slot("pieces", PieceOptions, "Pieces", PATTERN_ONLY)
_NEST = Slot("nest", NestOptions, "Nesting")
_CHECK = Slot("check", CheckOptions, "Check")
_WRITE = Slot("write", WriteOptions, "Output")

KINDS = {
    "load": _kind(_LOAD, name="load"),
    "flatten": _kind(_LOAD, _FLATTEN, _CHECK, _PIECES, _WRITE, _NEST, name="flatten"),
    "unfold": _kind(_UNFOLD, _CHECK, _BLANK_PIECES, _WRITE, _NEST, name="unfold"),
    "pattern": _kind(Slot("load", MeshingOptions, "Meshing"), _FLATTEN, _PIECES, _NEST, _CHECK, name="pattern"),
    "blank": _kind(_UNFOLD, _BLANK_PIECES, _NEST, _CHECK, name="blank"),
}
"""The kinds of run: ``load`` (``patterns info``), ``flatten`` and ``unfold`` (the command line, ``batch``),
``pattern`` and ``blank`` (a host's objects, through the worker: a shape is meshed, not read from a file)."""

HOST_KINDS = ("pattern", "blank")
"""The kinds a host's objects are."""


def _kind_of(kind: str, name: str | None) -> Kind:
    if kind not in KINDS:
        prefix = f"{name}: " if name else ""
        raise InputError(f"{prefix}unknown kind {kind!r}; the kinds are {', '.join(KINDS)}")
    return KINDS[kind]


@dataclass(frozen=True, repr=False)
class Bundle:
    """The option records of one run, frozen (see the module).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    load : LoadOptions or MeshingOptions or None
        How the part is read (``flatten``, ``load``) or meshed (``pattern``).
    flatten : FlattenOptions or None
    unfold : UnfoldOptions or None
    pieces : PieceOptions or None
    nest : NestOptions or None
    check : CheckOptions or None
    write : WriteOptions or None
        The records; None where the kind has not the record.
    """

    kind: str
    load: MeshingOptions | None = None
    flatten: FlattenOptions | None = None
    unfold: UnfoldOptions | None = None
    pieces: PieceOptions | None = None
    nest: NestOptions | None = None
    check: CheckOptions | None = None
    write: WriteOptions | None = None

    def __post_init__(self):
        slots = {s.name: s for s in _kind_of(self.kind, None).slots}
        for f in fields(self)[1:]:
            value = getattr(self, f.name)
            if f.name not in slots:
                if value is not None:
                    raise InputError(f"a {self.kind} bundle has no {f.name} options")
            elif value is None:
                object.__setattr__(self, f.name, slots[f.name].record())
            elif not isinstance(value, slots[f.name].record):
                raise InputError(f"{f.name} must be a patterns {slots[f.name].record.__name__}, got "
                                 f"{type(value).__name__}")
            else:
                default = slots[f.name].record()
                off = [n for n in slots[f.name].skip if not _same(getattr(value, n), getattr(default, n))]
                if off:
                    raise InputError(f"{off[0]} is a flattened pattern's option: a {self.kind} has none")

    @staticmethod
    def names(kind: str) -> tuple:
        """Every option of ``kind`` as a :class:`Name`: what ``of``, ``from_json`` and ``to_json`` take."""
        return _kind_of(kind, None).names()

    @classmethod
    def of(cls, kind: str, values: dict | None = None, *, name: str | None = None) -> Bundle:
        """The bundle of ``kind`` from ``{option name: value}`` (Python values; those left out at their defaults).

        Raises
        ------
        InputError
            An unknown kind or option (with the closest name), or a bad value (the record's own message, after
            ``name`` when given).
        """
        return cls._made(kind, values or {}, name=name, text=False)

    @classmethod
    def from_json(cls, kind: str, values: dict, *, name: str | None = None) -> Bundle:
        """The bundle of ``kind`` from its JSON form: ``{option name: value}``, a value JSON's own (number,
        bool, list, object) or text as the command line takes it (``"2500x1250"``, ``"0.03"``, ``"true"``;
        a repeatable option's items separated by ``;``); an empty text is the default.  Raises as :meth:`of`."""
        if not isinstance(values, dict):
            raise InputError(f"{name + ': ' if name else ''}the options must be an object of option names and "
                             f"values")
        return cls._made(kind, values, name=name, text=True)

    @classmethod
    def from_arguments(cls, kind: str, args, *, name: str | None = None) -> Bundle:
        """The bundle of ``kind`` from the command line's parsed ``args`` (its flags made by
        :func:`patterns.options.add_arguments` from the same records); messages name the flags.

        A flag the kind has not (``--seam-allowance`` to unfold) is refused when it is given.
        """
        made = {}
        typed = given_flags(args)
        for slot in _kind_of(kind, name).slots:
            flags = cli_flags(slot.record)
            for skipped in slot.skip:
                dest = flags[skipped].lstrip("-").replace("-", "_")
                given = getattr(args, dest, None)
                default = next(f.default for f in fields(slot.record) if f.name == skipped)
                if (flags[skipped] in typed) if typed is not None else given not in (None, default, False, []):
                    raise InputError(f"{flags[skipped]} is a flattened pattern's option: a {kind} has none")
            made[slot.name] = from_arguments(slot.record, args, name=name,
                                             **{f: getattr(slot.record(), f) for f in slot.skip})
        return cls(kind, **made)

    @classmethod
    def _made(cls, kind: str, values: dict, *, name: str | None, text: bool) -> Bundle:
        prefix = f"{name}: " if name else ""
        spec = _kind_of(kind, name)
        known = {n.name: n for n in spec.names()}
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise InputError(f"{prefix}unknown option {unknown[0]!r} for a {kind}{suggest(unknown[0], known)}; the "
                             f"options are {', '.join(sorted(known))}")
        per_slot: dict = {}
        for option, value in values.items():
            entry = known[option]
            if text:
                value = _from_json(entry, value, prefix)
                if value is _DEFAULT:
                    continue
            for slot, field in entry.targets:
                per_slot.setdefault(slot, {})[field] = value
        made = {}
        for slot in spec.slots:
            with naming(spec.labels(slot.name)):  # the record's messages name the bundle's names
                made[slot.name] = slot.record.of(None, per_slot.get(slot.name, {}), name=name)
        return cls(kind, **made)

    def records(self) -> dict:
        """``{slot name: record}`` of the kind's records, in order."""
        return {s.name: getattr(self, s.name) for s in KINDS[self.kind].slots}

    def to_json(self) -> dict:
        """``{option name: value}`` of every option off its default, as :meth:`from_json` reads it back (JSON's
        own values; text where JSON has no type: a table's path, a layer map, an ease)."""
        out = {}
        for entry in self.names(self.kind):
            slot, field = entry.targets[0]
            value = getattr(getattr(self, slot), field)
            if _same(value, entry.default):
                continue
            out[entry.name] = _to_json(entry.spec, value)
        return out

    def __repr__(self) -> str:
        return f"Bundle({self.kind!r}, {self.to_json()!r})"


_DEFAULT = object()
"""An empty text: the option at its default."""


def _same(value, default) -> bool:
    try:
        return bool(value == default)
    except (TypeError, ValueError):
        return False


def _to_json(spec: Spec, value):
    if spec.repeat and isinstance(value, (list, tuple)) and spec.text is not None:
        return [spec.text(item) for item in value]
    if spec.text is not None and value is not None:
        return spec.text(value)
    return _plain(value)


def _plain(value):
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if is_number(value) and not isinstance(value, (int, float)):
        return value.item()  # a numpy number
    return value


def _from_json(entry: Name, value, prefix: str):
    """A JSON value of ``entry``: text parsed as the command line parses it, anything else as it is."""
    spec = entry.spec
    if isinstance(value, str) and not value.strip():
        return _DEFAULT
    try:
        if spec.repeat and isinstance(value, str):
            return [parse_text(spec, entry.default, item.strip()) for item in value.split(";") if item.strip()]
        if spec.repeat and isinstance(value, list):
            return [parse_text(spec, entry.default, item) if isinstance(item, str) else item for item in value]
        if isinstance(value, str) and isinstance(entry.default, bool):
            word = value.strip().lower()
            if word not in ("1", "0", "true", "false", "yes", "no", "on", "off"):
                raise ValueError(f"expected true or false, got {value!r}")
            return word in ("1", "true", "yes", "on")
        if isinstance(value, str) and spec.choices is None:
            return parse_text(spec, entry.default, value.strip())
    except ValueError as exc:
        raise InputError(f"{prefix}{entry.name}: {exc}") from None
    return value
