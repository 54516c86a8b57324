"""How a drawing is written: the profile, the unit, the DXF version, the layer map -- declared once.

:class:`WriteOptions` is the one declaration of the writers' options for the
API (:func:`patterns.write`), the command line (its flags are made from it)
and batches; what goes onto each piece is :class:`patterns.pieces.PieceOptions`.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..options import Options, option
from ..units import UNIT_NAMES
from . import registry
from .layers import PRESETS, LayerMap, layer_map

__all__ = ["DXF_VERSIONS", "WriteOptions"]

DXF_VERSIONS = ("R12", "R2000", "R2004", "R2007", "R2010", "R2013", "R2018")
"""The DXF versions the machine profile writes (ASTM D6673 is R12)."""


def _profile(value, option_name):
    if not isinstance(value, str) or value not in registry.names():
        raise InputError(f"{option_name} must be one of {', '.join(registry.names())}, got {value!r}")
    return value


@dataclass(frozen=True, repr=False)
class WriteOptions(Options):
    """How a drawing is written (:func:`patterns.write`, ``patterns flatten -o``, ``patterns unfold -o``)."""

    profile: str | None = option(None, "output profile: machine (DXF for lasers, plasma, waterjet, knife plotters) "
                                       "or astm (DXF, ASTM D6673 for garment CAD), svg, json (the report), bends (a blank's "
                                       "bend sheet, CSV); "
                                       "default from the file's suffix (.dxf: machine); see docs/dxf.md",
                                 check=_profile, optional=True, metavar="NAME")
    units: str = option("mm", "unit of the drawing (machine profile and a flat OBJ; ASTM, SVG and JSON are mm); a "
                              "mesh file's own unit is --input-units", choices=UNIT_NAMES)
    version: str | None = option(None, "machine profile: DXF version (default R2000; ASTM is R12)",
                                 choices=DXF_VERSIONS, flag="--dxf-version", optional=True)
    layer_map: LayerMap = option(layer_map("patterns"), "machine profile: the layers, a preset (" + ", ".join(PRESETS)
                                 + ") then role=LAYER overrides, e.g. updown or 'solidworks,label=TEXT' "
                                   "(role= leaves a role out); see docs/dxf.md", check=layer_map, parse=str,
                                 metavar="MAP", text=str)
    bend_lines: bool = option(True, "draw bend and ruling lines (--no-bend-lines leaves them and their labels out, "
                                    "for a cutter that would cut them)", flag="--no-bend-lines",
                                    off="leave bend and ruling lines and their labels out (for a cutter that would "
                                        "cut them)")

    sheet_files: bool = option(False, "with a nest on sheets, also write each sheet as a file of its own beside "
                                      "the pattern (NAME-1.dxf, NAME-2.dxf, ...): the sheet and its pieces alone, "
                                      "for the machine")

    def __post_init__(self):
        super().__post_init__()
        if self.profile == "astm":
            if self.version not in (None, "R12"):
                raise InputError(f"the ASTM profile is written as R12 only, not {self.version!r}")
            if self.units != "mm":
                raise InputError("the ASTM profile is written in mm (METRIC) only")
            if self.layer_map.name != "patterns":
                raise InputError("the ASTM profile's layers are the standard's numbers: no layer_map")
