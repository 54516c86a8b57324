"""The engine's options as properties of a FreeCAD object, from the schema the engine sends.

Each option is one property in its record's group: a switch (``App::PropertyBool``), a choice
(``App::PropertyEnumeration``), a number (``App::PropertyInteger``, ``App::PropertyFloat``), or text for
the rest (empty is the default).  Nothing is declared or checked here: the engine's option records are the
one declaration and the one validator; the values go to the engine as they are
(:func:`check_options` asks it).
"""

import json

from .engine import EngineError, Refused, engine


class PatternsError(ValueError):
    """A request the engine refused (a bad option, a shape it cannot use), or an engine that cannot answer;
    the message says which and what to do."""


def check_options(kind, options, label):
    """Check options with the engine's records before anything is added (PatternsError saying what is wrong)."""
    try:  # the engine's records refuse an unknown name too, listing the known ones
        engine().request("validate", kind=kind, options=options, name=label)
    except (EngineError, Refused) as exc:
        raise PatternsError(str(exc)) from None


KINDS = {"bool": "App::PropertyBool", "choice": "App::PropertyEnumeration", "int": "App::PropertyInteger",
         "float": "App::PropertyFloat", "text": "App::PropertyString"}
"""FreeCAD's property type of each kind of option."""


def add(obj, properties):
    """Add a property for every option (``properties``: the engine's schema of the object's kind) that the
    object has not yet (an engine upgraded since: its new options), and keep every option's default on the
    object (``OptionDefaults``), so that :func:`changed` needs no engine."""
    if "OptionDefaults" not in obj.PropertiesList:
        obj.addProperty("App::PropertyString", "OptionDefaults", "Result", "Each option's default (JSON)")
        obj.setEditorMode("OptionDefaults", 2)
    defaults = json.loads(obj.OptionDefaults or "{}")
    for p in properties:
        defaults[p["name"]] = p["default"]
        if p["name"] in obj.PropertiesList:
            continue
        text = p["help"][:1].upper() + p["help"][1:] + "."
        obj.addProperty(KINDS[p["kind"]], p["name"], p["group"], text)
        if p["kind"] == "choice":
            setattr(obj, p["name"], list(p["choices"]))
        setattr(obj, p["name"], p["default"])
    obj.OptionDefaults = json.dumps(defaults, sort_keys=True)


def value(obj, p):
    """One option's value on ``obj``, in the kind the schema gives."""
    got = getattr(obj, p["name"])
    if p["kind"] == "float":
        return float(got)
    if p["kind"] == "int":
        return int(got)
    if p["kind"] == "bool":
        return bool(got)
    return str(got)


def changed(obj):
    """``{name: value}`` of the options set away from their defaults (what the engine is sent), from the
    object alone."""
    out = {}
    for name, default in sorted(json.loads(obj.OptionDefaults or "{}").items()):
        if name not in obj.PropertiesList:
            continue
        got = getattr(obj, name)
        got = got if isinstance(got, (bool, int, float)) else str(got)
        if got != default:
            out[name] = got
    return out


_KINDS = {"float": float, "int": int}


def set_values(obj, properties, values, label):
    """Set options given by property name, each as its kind (``"10"`` for a number is 10.0); PatternsError
    naming an unknown option or a value of the wrong kind."""
    known = {p["name"]: p for p in properties}
    for name, given in values.items():
        if name not in known:
            raise PatternsError(f"{label}: unknown option {name!r}; the options are {', '.join(sorted(known))}")
        kind = known[name]["kind"]
        try:
            if kind in ("text", "choice"):
                given = "" if given is None else str(given)
            elif kind == "bool":
                given = given if isinstance(given, bool) else str(given).strip().lower() in ("1", "true", "yes", "on")
            else:
                given = _KINDS[kind](given)
            setattr(obj, name, given)
        except (TypeError, ValueError) as exc:
            raise PatternsError(f"{label}: {name} must be {'a whole number' if kind == 'int' else 'a number'}, "
                                f"got {given!r} ({exc})") from None
