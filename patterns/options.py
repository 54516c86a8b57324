"""Options: declared once, validated once, for the API and the command line alike.

* :func:`check_number`: every numeric option of the API (and so of the command
  line) is checked here, the same way: a real number (Python or numpy, never a
  ``bool``), finite unless said otherwise, within its bounds; an
  :class:`~patterns.errors.InputError` naming the option and what it takes
  otherwise.
* :class:`Options`: the frozen option records (``LoadOptions``,
  ``FlattenOptions``, ``CheckOptions``, ``DxfOptions``), each field declared
  once with :func:`option`; the API makes them from its keywords
  (:meth:`Options.of`), the command line makes its flags from the same fields
  (:func:`add_arguments`) and the records from the parsed flags
  (:func:`from_arguments`).
"""

from __future__ import annotations

import contextlib
import contextvars
import difflib
import math
import numbers
from collections.abc import Callable
from dataclasses import dataclass, field, fields, is_dataclass, replace
from enum import Enum
from typing import Any

import numpy as np

from .errors import InputError
from .units import LARGEST_LENGTH

__all__ = ["Options", "Spec", "add_arguments", "check_number", "check_ratio", "cli_flags", "from_arguments", "from_text",
           "given_flags", "is_number", "label", "naming", "option", "parse_text", "suggest"]

_LABELS: contextvars.ContextVar = contextvars.ContextVar("patterns_option_labels", default=None)
"""``{option name: what to call it}`` while a record is made from the command line's flags (the flags)."""


@contextlib.contextmanager
def naming(names: dict):
    """Within it, the records' messages call each option as ``names`` says (``{field name: name}``): the
    command line's flags, or a bundle's names (``dart_strain`` for ``FlattenOptions.max_strain``)."""
    token = _LABELS.set(names)
    try:
        yield
    finally:
        _LABELS.reset(token)


def label(name: str) -> str:
    """What a message calls option ``name``: its CLI flag while the command line makes a record, else ``name``.

    A record's own cross-checks (``__post_init__``) name their options through it, so that the command line's
    errors name the flag the user typed (``--nest-gap``) and the API's the keyword (``gap``).
    """
    return (_LABELS.get() or {}).get(name, name)


def suggest(word: str, choices) -> str:
    """``"; did you mean X?"`` for the closest of ``choices`` to ``word`` (a mistyped option), or ``""``."""
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f"; did you mean {close[0]}?" if close else ""


def is_number(value, *, integer: bool = False) -> bool:
    """True for a real number (``int``, ``float``, numpy's), not a ``bool``; integers only if ``integer``."""
    if isinstance(value, (bool, np.bool_)):
        return False
    kind = numbers.Integral if integer else numbers.Real
    return isinstance(value, kind)


def check_number(value, option: str, *, low=None, high=None, low_open: bool = False, high_open: bool = False,
                 integer: bool = False, finite: bool = True, name: str | None = None):
    """``value`` as a Python ``float`` (``int`` if ``integer``), or InputError naming ``option``.

    Parameters
    ----------
    value
        What the caller gave.
    option : str
        The option's name, for the message (``"max_strain"``).
    low, high : float, optional
        Bounds, inclusive unless ``low_open`` / ``high_open``.
    integer : bool
        Only integers.
    finite : bool
        Refuse NaN and infinities (default).
    name : str, optional
        What the option belongs to (a file or model name), put first in the message.
    """
    try:  # a Python int past 64 bits is a number np.isfinite cannot take (TypeError): finite all the same
        ok = is_number(value, integer=integer) and not (finite and not np.isfinite(value))
    except (TypeError, OverflowError):
        ok = isinstance(value, int) and not isinstance(value, bool)
    if ok and low is not None:
        ok = value > low if low_open else value >= low
    if ok and high is not None:
        ok = value < high if high_open else value <= high
    if not ok:
        prefix = f"{name}: " if name else ""
        raise InputError(f"{prefix}{option} must be {_describe(low, high, low_open, high_open, integer)}, "
                         f"got {value!r}")
    return int(value) if integer else float(value)


def check_ratio(value, option: str, *, name: str | None = None) -> float:
    """A strain or tolerance given as a ratio, ``0 < value <= 1`` (``0.03`` is 3 %), or InputError.

    Every strain option takes this one rule: a ratio, never a percentage, so ``3`` (meant as 3 %) is
    refused with the way to write it instead of being taken as 300 %.
    """
    prefix = f"{name}: " if name else ""
    if not is_number(value) or not np.isfinite(value) or not 0 < value <= 1:
        hint = f"; {value:g} % is {value / 100:g}" if is_number(value) and np.isfinite(value) and 1 < value <= 100 \
            else ""
        raise InputError(f"{prefix}{option} must be a ratio > 0 and <= 1 (0.03 means 3 %), got {value!r}{hint}")
    return float(value)


class _Whole(int):
    """An integer bound, written whole in a message (4294967295, never 4.29497e+09)."""

    def __format__(self, spec):
        return str(int(self))


def _describe(low, high, low_open, high_open, integer) -> str:
    """``"a positive number"``, ``"an integer >= 0"``, ``"a number between 0 and 1"``, ..."""
    kind = "integer" if integer else "number"
    article = "an" if integer else "a"
    if low == 0 and low_open and high == LARGEST_LENGTH:
        return f"a positive {kind} {'<' if high_open else '<='} {high:g}"
    if integer:  # an open end of integers is the next integer in: "between 1 and 100000", never "between 0" for > 0
        low = None if low is None else _Whole(math.floor(low) + 1 if low_open else math.ceil(low))
        high = None if high is None else _Whole(math.ceil(high) - 1 if high_open else math.floor(high))
        low_open = high_open = False
    if low is not None and high is not None:
        if low_open or high_open:
            return f"{article} {kind} {'>' if low_open else '>='} {low:g} and {'<' if high_open else '<='} {high:g}"
        return f"{article} {kind} between {low:g} and {high:g}"
    if low == 0 and low_open:
        return f"a positive {kind}"
    if low is not None:
        return f"{article} {kind} {'>' if low_open else '>='} {low:g}"
    if high is not None:
        return f"{article} {kind} {'<' if high_open else '<='} {high:g}"
    return f"a finite {kind}"


# --------------------------------------------------------------------------- #
# Option records: one declaration per option, for the API and the CLI alike
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class Spec:
    """What one option takes, and its help: the declaration the API validates with and the CLI is made from.

    Attributes
    ----------
    help : str
        One or two sentences, shown by ``--help`` and in the record's docstring.
    low, high, low_open, high_open, integer
        A number's bounds (see :func:`check_number`); a number option has
        ``low`` or ``high`` or ``integer`` set, or a numeric default.
    choices : tuple of str, optional
        The values a choice takes.
    optional : bool
        None is accepted (and means "not set").
    flag : str, optional
        The CLI flag; default ``--`` and the name with dashes.  Two records
        may share a flag (``--units``): the one value goes to both.
    parse : callable, optional
        CLI text to value (for values other than numbers and choices).
    check : callable, optional
        ``check(value, option) -> value`` for values other than numbers,
        choices and booleans (raises :class:`~patterns.errors.InputError`).
    repeat : bool
        The CLI flag may be given several times; the values come as a list.
    metavar : str, optional
    unit : {"mm", "ratio"}, optional
        ``"mm"``: a length in millimetres, at most :data:`~patterns.units.LARGEST_LENGTH`
        (whatever ``high`` says), shown as ``MM`` on the command line.  ``"ratio"``:
        a strain or tolerance, ``0 < value <= 1`` (:func:`check_ratio`: ``0.03`` is 3 %).
    off : str, optional
        For an option that is on by default: the help of the command line's
        ``--no-...`` flag, saying what the flag does (required there).
    text : callable, optional
        A checked value (one item, for ``repeat``) back to the text ``parse``
        reads (a table's path, an ease's ``SEAM:PANEL:MM``): the JSON form of
        a value JSON has no type for (:meth:`patterns.bundle.Bundle.to_json`).
    """

    help: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    integer: bool = False
    choices: tuple | None = None
    optional: bool = False
    flag: str | None = None
    parse: Callable | None = None
    check: Callable | None = None
    repeat: bool = False
    metavar: str | None = None
    unit: str | None = None
    off: str | None = None
    text: Callable | None = None

    def __post_init__(self):
        if self.unit == "mm":
            object.__setattr__(self, "high", LARGEST_LENGTH if self.high is None else min(self.high, LARGEST_LENGTH))
            object.__setattr__(self, "metavar", self.metavar or "MM")
        elif self.unit == "ratio":
            object.__setattr__(self, "low", 0.0)
            object.__setattr__(self, "low_open", True)
            object.__setattr__(self, "high", 1.0)
            object.__setattr__(self, "metavar", self.metavar or "R")
        elif self.unit is not None:
            raise ValueError(f"unit must be 'mm' or 'ratio', got {self.unit!r}")

    def validate(self, value, option: str, default):
        """``value`` checked (numbers as Python numbers), or InputError naming ``option``."""
        if value is None and (self.optional or default is None):
            return None
        if self.check is not None:
            return self.check(value, option)
        if self.choices is not None:
            if isinstance(value, Enum):
                value = value.value
            if not isinstance(value, str) or value not in self.choices:
                raise InputError(f"{option} must be one of {', '.join(map(str, self.choices))}, got {value!r}")
            return value
        if isinstance(default, bool):
            if not isinstance(value, (bool, np.bool_)):
                raise InputError(f"{option} must be True or False, got {value!r}")
            return bool(value)
        if self.unit == "ratio":
            return check_ratio(value, option)
        if self.integer or self.low is not None or self.high is not None or is_number(default):
            return check_number(value, option, low=self.low, high=self.high, low_open=self.low_open,
                                high_open=self.high_open, integer=self.integer)
        return value


def option(default, help: str, **spec) -> Any:
    """A field of an :class:`Options` record: its default and its :class:`Spec` (keywords as there)."""
    return field(default=default, metadata={"spec": Spec(help, **spec)})


class Options:
    """Base of the frozen option records (:class:`~patterns.export.dxf.DxfOptions`, ...).

    Each field is declared once, with :func:`option`; the record checks every
    value when it is made (``InputError`` naming the option), the API builds
    it from its keywords (:meth:`of`), and the command line makes its flags
    from the same fields (:func:`add_arguments`, :func:`from_arguments`), so
    that the two cannot drift.  Subclasses are frozen dataclasses.
    """

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        cls.__doc__ = (cls.__doc__ or "").rstrip() + "\n\n    Attributes\n    ----------\n" + "".join(
            f"    {name} : {_kind(spec, default)}\n        {spec.help}.\n"
            for name, spec, default in _specs_from_annotations(cls))

    def __post_init__(self):
        for f in fields(self):
            spec = f.metadata.get("spec")
            if spec is not None:
                object.__setattr__(self, f.name, spec.validate(getattr(self, f.name), label(f.name), f.default))

    @classmethod
    def of(cls, options=None, keywords=None, *, name: str | None = None):
        """The record from ``options`` (a record of this kind, or None) with ``keywords`` over it.

        Raises
        ------
        InputError
            ``options`` of another kind, an unknown keyword, or a bad value;
            the message starts with ``name`` when given.
        """
        prefix = f"{name}: " if name else ""
        if options is not None and not isinstance(options, cls):
            raise InputError(f"{prefix}options must be a patterns {cls.__name__}, got {type(options).__name__}")
        keywords = dict(keywords or {})
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(keywords) - set(known))
        if unknown:
            raise InputError(f"{prefix}unknown option {unknown[0]!r}{suggest(unknown[0], known)}; the options are "
                             f"{', '.join(known)}")
        try:
            return replace(options, **keywords) if options is not None else cls(**keywords)
        except InputError as exc:
            raise InputError(f"{prefix}{exc}") from None

    @classmethod
    def checked(cls, option: str, value, *, where: str | None = None):
        """One option's value checked by its declaration (for a function that takes it as a keyword), or InputError."""
        declared = next(f for f in fields(cls) if f.name == option)
        try:
            return declared.metadata["spec"].validate(value, option, declared.default)
        except InputError as exc:
            raise InputError(f"{where}: {exc}" if where else str(exc)) from None

    def __repr__(self) -> str:
        changed = [f"{f.name}={getattr(self, f.name)!r}" for f in fields(self)
                   if getattr(self, f.name) != f.default]
        return f"{type(self).__name__}({', '.join(changed)})"


def _specs_from_annotations(cls):
    """``[(name, Spec, default)]`` of a record's options: its bases' (already dataclasses) and its own
    ``option(...)`` fields (the dataclass decorator has not run yet)."""
    out, seen = [], set()
    for base in reversed(cls.__mro__[1:]):
        if is_dataclass(base):
            for f in fields(base):
                if "spec" in f.metadata and f.name not in seen:
                    seen.add(f.name)
                    out.append((f.name, f.metadata["spec"], f.default))
    for name in cls.__dict__.get("__annotations__", {}):
        value = cls.__dict__.get(name)
        spec = getattr(value, "metadata", {}).get("spec") if value is not None else None
        if spec is not None and name not in seen:
            out.append((name, spec, value.default))
    return out


def _kind(spec: Spec, default) -> str:
    """The numpydoc type line of an option: ``{"mm", "in"}, default "mm"``, ``float, optional``, ..."""
    if spec.choices is not None:
        kind = "{" + ", ".join(repr(c) for c in spec.choices) + "}"
    elif isinstance(default, bool):
        kind = "bool"
    elif spec.integer:
        kind = "int"
    elif spec.low is not None or spec.high is not None or is_number(default):
        kind = "float"
    else:
        kind = "object"
    return f"{kind}, optional" if default is None else f"{kind}, default {default!r}"


def flag_of(name: str, spec: Spec) -> str:
    """The CLI flag of an option (``--max-edge`` for ``max_edge``, unless the spec names one)."""
    return spec.flag or "--" + name.replace("_", "-")


def _dest(flag: str) -> str:
    return flag.lstrip("-").replace("-", "_")


def add_arguments(parser, record: type, *, skip: tuple = ()) -> None:
    """Add a flag to an ``argparse`` parser for every option of ``record`` (an :class:`Options` class).

    A flag another record has already added (``--units``) is kept once.  The
    parser does only the text-to-value step; the values are checked when the
    record is made (:func:`from_arguments`), by the same code as the API's.
    """
    import argparse

    for f in fields(record):
        spec = f.metadata.get("spec")
        if spec is None or f.name in skip:
            continue
        flag = flag_of(f.name, spec)
        if any(flag in action.option_strings for action in parser._actions):
            continue
        text = spec.help.replace("%", "%%")
        if isinstance(f.default, bool):
            if f.default:  # the flag turns it off: its help says what the flag does, not what the default is
                if spec.off is None:
                    raise TypeError(f"{record.__name__}.{f.name}: an option on by default needs off= (its --no- help)")
                flag = spec.flag or "--no-" + f.name.replace("_", "-")
                text = spec.off.replace("%", "%%")
            parser.add_argument(flag, dest=_dest(flag), action=_actions()["flag"], help=text)
            continue
        kind = _typed(spec.parse) if spec.parse else (int if spec.integer else float if spec.choices is None and (
            spec.low is not None or spec.high is not None or is_number(f.default)) else str)
        if spec.optional or f.default is None:  # "none" (any case) is None, as the help offers
            kind = _or_none(kind)
        default = None if spec.repeat else f.default
        default = default.value if isinstance(default, Enum) else default
        parser.add_argument(flag, dest=_dest(flag), type=kind, default=default, choices=spec.choices,
                            action=_actions()["append" if spec.repeat else "store"], metavar=spec.metavar,
                            help=text + ("" if default in (None, "") else f" (default {default})"))
    del argparse


def given_flags(args) -> set | None:
    """The flags the user typed on the command line that made ``args`` (each as :func:`add_arguments` declared
    it, an abbreviation read as its whole flag), or None when ``args`` came from elsewhere (built by hand)."""
    given = vars(args).get("given")
    return None if given is None else set(given)


_ACTIONS: dict = {}


def _actions() -> dict:
    """``{"store", "append", "flag"}`` -> argparse actions that do what argparse's own do and note the flag in
    the namespace's ``given`` set: a value typed equal to the default is still the user's choice (``--material
    X --k-factor 0.5`` is refused, not read as "no K-factor given")."""
    if _ACTIONS:
        return _ACTIONS
    import argparse

    def note(namespace, action):
        given = vars(namespace).get("given")
        if given is None:
            given = set()
            namespace.given = given
        given.add(action.option_strings[0])

    class Store(argparse.Action):
        def __call__(self, parser, namespace, values, option_string=None):
            setattr(namespace, self.dest, values)
            note(namespace, self)

    class Append(argparse.Action):
        def __call__(self, parser, namespace, values, option_string=None):
            setattr(namespace, self.dest, [*(getattr(namespace, self.dest, None) or ()), values])
            note(namespace, self)

    class Flag(argparse.Action):
        def __init__(self, option_strings, dest, default=False, required=False, help=None):
            super().__init__(option_strings, dest, nargs=0, const=True, default=default, required=required,
                             help=help)

        def __call__(self, parser, namespace, values, option_string=None):
            setattr(namespace, self.dest, True)
            note(namespace, self)

    _ACTIONS.update(store=Store, append=Append, flag=Flag)
    return _ACTIONS


def _or_none(kind: Callable) -> Callable:
    """``kind``, with the text ``none`` (any case) read as None (an optional option left unset)."""

    def or_none(text):
        return None if text.strip().lower() == "none" else kind(text)

    or_none.__name__ = getattr(kind, "__name__", "value")
    return or_none


def _typed(parse: Callable) -> Callable:
    """A parse function whose ValueError argparse shows as it is (``expected X,Y,Z ...``), not as
    ``invalid parse_direction value``."""
    import argparse

    def typed(text):
        try:
            return parse(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    typed.__name__ = parse.__name__
    return typed


def from_arguments(record: type, args, *, name: str | None = None, **extra):
    """The ``record`` (an :class:`Options` class) from parsed ``args`` (see :func:`add_arguments`), plus ``extra``.

    When ``args`` notes the flags the user typed (:func:`given_flags`), only those are passed to the record,
    the rest left at the record's defaults, so that the record sees what was given, as :meth:`Options.of`
    sees the API's keywords."""
    values = {}
    given = given_flags(args)
    for f in fields(record):
        spec = f.metadata.get("spec")
        if spec is None or f.name in extra:
            continue
        negated = isinstance(f.default, bool) and f.default  # a flag that turns it off: --no-...
        dest = _dest(spec.flag or "--no-" + f.name.replace("_", "-")) if negated else _dest(flag_of(f.name, spec))
        if dest not in vars(args):
            continue  # a field the parser has no flag for (skipped by add_arguments): its default
        if given is not None and cli_flags(record)[f.name] not in given:
            continue  # not typed: the record's default
        if negated:
            values[f.name] = not getattr(args, dest)
        else:
            value = getattr(args, dest)
            if not (spec.repeat and value is None):
                values[f.name] = value
    values.update(extra)
    with naming(cli_flags(record)):  # the messages name the flags the user typed
        return record.of(None, values, name=name)


def cli_flags(record: type) -> dict:
    """``{option name: CLI flag}`` for every option of ``record`` (what :func:`add_arguments` adds)."""
    out = {}
    for f in fields(record):
        spec = f.metadata.get("spec")
        if spec is not None:
            negated = isinstance(f.default, bool) and f.default
            out[f.name] = (spec.flag or "--no-" + f.name.replace("_", "-")) if negated else flag_of(f.name, spec)
    return out


def parse_text(spec: Spec, default, text: str):
    """One value from its text, as the command line parses it (before the record checks it); ValueError if
    it cannot be read."""
    if spec.parse is not None:
        return spec.parse(text)
    if spec.integer:
        return int(text)
    if spec.choices is None and (spec.low is not None or spec.high is not None or is_number(default)):
        return float(text)
    return text


def from_text(record: type, texts: dict, *, name: str | None = None, separator: str = ";"):
    """The ``record`` from option values given as text (a CAD document's string properties, a form's fields).

    ``texts`` is ``{option name: text}``; an empty text leaves the option at its default; a repeatable
    option takes its items separated by ``separator``.  Each text is parsed as the command line parses
    its flag, then the record checks every value (:meth:`Options.of`): one declaration, one validator.
    """
    values = {}
    for f in fields(record):
        spec = f.metadata.get("spec")
        text = texts.get(f.name)
        if spec is None or text is None or not str(text).strip():
            continue
        try:
            if spec.repeat:
                values[f.name] = [parse_text(spec, f.default, item.strip()) for item in str(text).split(separator)
                                  if item.strip()]
            elif isinstance(f.default, bool):
                values[f.name] = str(text).strip().lower() in ("1", "true", "yes", "on")
            else:
                values[f.name] = parse_text(spec, f.default, str(text).strip())
        except ValueError as exc:
            prefix = f"{name}: " if name else ""
            raise InputError(f"{prefix}{f.name}: {exc}") from None
    return record.of(None, values, name=name)
