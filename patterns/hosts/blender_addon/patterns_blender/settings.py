"""The options as the scene's properties (``scene.patterns``), made from the engine's schema: declared once.

``patterns blender install`` writes the engine's option schema (``schema.json``, what the worker's ``hello``
sends); each option of a pattern becomes a property named as the engine names it (``dart_strain`` the darts'
limit, ``max_strain`` the check's), with its help, default and bounds.  Only values off their defaults are
sent; the engine checks them with the records the API and the command line use.
"""

import bpy

from .engine import schema

KINDS = {"bool": bpy.props.BoolProperty, "int": bpy.props.IntProperty, "float": bpy.props.FloatProperty,
         "text": bpy.props.StringProperty}

MAIN = ("dart_strain", "max_strain", "gores", "seam_allowance", "notch_spacing", "grain", "width", "sheet", "copies")
"""The options the sidebar shows first; the others are under "All options"."""


def properties():
    """The pattern's options, as the install recorded them (a list of dicts; empty without a schema)."""
    return schema().get("pattern", [])


def _property(p):
    label = p["name"].replace("_", " ").capitalize()
    text = p["help"][:500]
    if p["kind"] == "choice":
        items = [(c, c, "") for c in p["choices"]]
        return bpy.props.EnumProperty(name=label, description=text, items=items, default=p["default"])
    keywords = {"name": label, "description": text, "default": p["default"]}
    if p["kind"] in ("int", "float"):
        big = 2**31 - 1 if p["kind"] == "int" else 3.4e38  # Blender keeps ints in 32 bits, floats in single precision
        if p["low"] is not None:
            keywords["min"] = max(p["low"], -big)
        if p["high"] is not None:
            keywords["max"] = min(p["high"], big)
        if p["kind"] == "int":
            keywords = {k: int(v) if k in ("min", "max") else v for k, v in keywords.items()}
    if p["kind"] == "float":
        keywords["precision"] = 4
    return KINDS[p["kind"]](**keywords)


def settings_class():
    """A PropertyGroup with one property per option."""
    annotations = {p["name"]: _property(p) for p in properties()}
    return type("PatternsSettings", (bpy.types.PropertyGroup,), {"__annotations__": annotations})


def values(settings) -> dict:
    """``{option: value}`` of the options off their defaults (floats to seven digits: Blender keeps them in
    single precision, so 0.03 is sent as 0.03)."""
    out = {}
    for p in properties():
        value = getattr(settings, p["name"])
        if p["kind"] == "float":
            value = float(f"{value:.7g}")
            if abs(value - p["default"]) <= 1e-7 * max(1.0, abs(p["default"])):
                continue
        elif value == p["default"]:
            continue
        out[p["name"]] = value
    return out


def limit(settings) -> float:
    """The strain a colour map's red stands for: the check's limit, else the darts', else 5 %."""
    for name in ("max_strain", "dart_strain"):
        text = str(getattr(settings, name, "") or "").strip()
        try:
            if text and float(text) > 0:
                return float(text)
        except ValueError:
            pass
    return 0.05
