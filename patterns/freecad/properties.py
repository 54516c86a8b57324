"""The option records as properties of a FreeCAD object: the same names, defaults and validation.

Every option of a record (:class:`patterns.FlattenOptions`, ...) becomes one
property of the object, in a group named after the record: a switch
(``App::PropertyBool``), a choice (``App::PropertyEnumeration``), a number
with a default (``App::PropertyFloat``, ``App::PropertyInteger``), or text
for the rest (optional numbers, a grain direction, a sheet ``2500x1250``,
``NAME=N;NAME=N``): empty text is the option's default.  A property is named
as the option; where two records of one object share a name the command line's
flag tells them apart (``--dart-strain`` is ``dart_strain``, ``--nest-gap``
``nest_gap``).  The record is made back from the properties by
:func:`patterns.options.from_text`, so it is checked by the one validator:
a bad value fails the object's recompute with the record's own message.
"""

from __future__ import annotations

from dataclasses import fields

from ..options import flag_of, from_text, is_number

__all__ = ["add_properties", "property_names", "read_record"]


def _name(f, spec, taken: set) -> str:
    if f.name not in taken:
        return f.name
    return flag_of(f.name, spec).lstrip("-").replace("-", "_")


def property_names(records, skip=()) -> dict:
    """``{(record, option name): property name}`` for records given in order (a clash takes the flag's name);
    ``skip``: ``(record, option name)`` pairs the object does not have."""
    out, taken = {}, set()
    for record in records:
        for f in fields(record):
            spec = f.metadata.get("spec")
            if spec is None or (record, f.name) in skip:
                continue
            name = _name(f, spec, taken)
            taken.add(name)
            out[(record, f.name)] = name
    return out


def _kind(f, spec) -> str:
    if isinstance(f.default, bool):
        return "App::PropertyBool"
    if spec.choices is not None:
        return "App::PropertyEnumeration"
    if f.default is not None and spec.integer:
        return "App::PropertyInteger"
    if f.default is not None and not spec.repeat and is_number(f.default) and (spec.check is None or spec.parse is float):
        return "App::PropertyFloat"
    return "App::PropertyString"


def add_properties(obj, records, groups, skip=()) -> None:
    """Add a property for every option of ``records`` to ``obj``, each record's in its group of ``groups``
    (``skip``: ``(record, option name)`` pairs left out)."""
    names = property_names(records, skip)
    for record, group in zip(records, groups):
        for f in fields(record):
            spec = f.metadata.get("spec")
            if spec is None or (record, f.name) in skip:
                continue
            name, kind = names[(record, f.name)], _kind(f, spec)
            if name in obj.PropertiesList:
                continue
            obj.addProperty(kind, name, group, spec.help[0].upper() + spec.help[1:] + ".")
            if kind == "App::PropertyEnumeration":
                setattr(obj, name, list(spec.choices))
                setattr(obj, name, str(f.default))
            elif kind == "App::PropertyString":
                setattr(obj, name, "" if f.default is None else str(f.default))
            else:
                setattr(obj, name, f.default)


def read_record(obj, record, records, *, name: str, skip=()):
    """The ``record`` its properties on ``obj`` give (``records``, ``skip``: as :func:`add_properties` had them)."""
    names = property_names(records, skip)
    texts = {}
    for f in fields(record):
        prop = names.get((record, f.name))
        if prop is not None and prop in obj.PropertiesList:
            value = getattr(obj, prop)
            texts[f.name] = repr(value) if isinstance(value, float) else str(value)
    return from_text(record, texts, name=name)
