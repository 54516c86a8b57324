"""The DXF machine profile: for lasers, plasma and waterjet cutters and knife plotters.

Every cut contour is ONE closed polyline (an arc a bulge, a drilled hole a
CIRCLE) on the ``cut`` role's layer, never duplicated (a countersunk hole's
rim is a CIRCLE on the ``countersink`` role's layer); marks and texts go on
layers of their own (:mod:`~patterns.export.layers`: one convention for
patterns and blanks, or a shop's layer map), bend lines dashed.  z = 0, 1:1,
``$INSUNITS`` and ``$MEASUREMENT`` declared (R12 too, which predates them), the
drawing where :func:`patterns.pieces.drawing_of` put it.
"""

from __future__ import annotations

import numpy as np

from ..curves import Loop
from ..files import atomic_output
from ..pieces import Drawing, Piece, piece_labels
from ..pieces.allowance import straight_runs
from ..units import Unit
from .dxfdoc import add_loop, add_polyline, add_text, declare_linetypes, new_doc, r12_units, save
from .layers import LayerMap
from .options import WriteOptions

__all__ = ["write"]

_BEND_ROLE = {"up": "bend_up", "down": "bend_down", "": "bend"}


def _roles(drawing: Drawing, options: WriteOptions) -> list:
    """The roles this drawing draws (strain and stock only when it has them; bends unless left out)."""
    out = [r for r in ("cut", "hole", "sew", "notch", "grain", "drill", "bend", "bend_up", "bend_down", "label")
           if options.bend_lines or not r.startswith("bend")]
    if any(p.strain_map is not None for p in drawing.pieces):
        out.append("strain")
    if drawing.stock:
        out.append("stock")
    if any(p.rims for p in drawing.pieces):
        out.append("countersink")
    return out


def _strain_solids(msp, piece: Piece, layer: str, scale: float, truecolor: bool) -> None:
    """Every triangle as a filled SOLID coloured by its dominant strain, on a scale symmetric about 0."""
    from ezdxf.colors import rgb2int
    from matplotlib import colormaps
    from matplotlib.colors import TwoSlopeNorm

    s = piece.strain_map.strain
    lim = max(float(np.max(np.abs(s))), 1e-6)
    rgba = colormaps["RdBu_r"](TwoSlopeNorm(0.0, -lim, lim)(s))
    for tri, c in zip(piece.strain_map.triangles, rgba):
        p = tri * scale
        attribs = {"layer": layer}
        if truecolor:
            attribs["true_color"] = rgb2int(tuple(int(255 * x) for x in c[:3]))
        else:
            attribs["color"] = 5 if c[2] > c[0] else 1
        msp.add_solid([tuple(p[0]), tuple(p[1]), tuple(p[2])], dxfattribs=attribs)


def _piece(msp, piece: Piece, layers: LayerMap, unit: Unit, options: WriteOptions, r12: bool) -> None:
    scale = 1.0 / unit.mm

    def line(a, b, layer):
        msp.add_line(tuple(np.asarray(a) * scale), tuple(np.asarray(b) * scale), dxfattribs={"layer": layer})

    if layers["cut"] is not None:
        add_loop(msp, piece.outline, layers["cut"].name, scale=scale, r12=r12)
    if layers["hole"] is not None:
        for hole in piece.holes:
            add_loop(msp, hole, layers["hole"].name, scale=scale, r12=r12)
    if piece.allowance and layers["sew"] is not None:
        for loop in piece.sew:
            add_polyline(msp, straight_runs(loop), layers["sew"].name, scale=scale, r12=r12)
    if layers["notch"] is not None:
        for notch in piece.notches:  # a slit from the cut line to its tip, or a V from its tip to its mouth
            for a, b in ([(notch.at, notch.tip)] if notch.mouth is None else [(notch.tip, e) for e in notch.mouth]):
                line(a, b, layers["notch"].name)
    if layers["countersink"] is not None:  # a countersink's or counterbore's rim: a circle to mark, not cut
        for rim in piece.rims:
            add_loop(msp, Loop((rim.circle,)), layers["countersink"].name, scale=scale, r12=r12)
    if layers["drill"] is not None:
        for tip in piece.drills:
            msp.add_point(tuple(tip * scale), dxfattribs={"layer": layers["drill"].name})
    if piece.grain is not None and layers["grain"] is not None:
        line(*piece.grain, layers["grain"].name)
    bend_layers = [layers[_BEND_ROLE[b.direction]] if options.bend_lines else None for b in piece.bends]
    for bend, layer in zip(piece.bends, bend_layers):
        if layer is not None:
            line(*bend.line, layer.name)
    for label in piece_labels(piece, unit):  # a bend's label on its line's layer
        layer = bend_layers[label.of] if label.kind == "bend" else layers["label"]
        if layer is not None:
            add_text(msp, label.text, label.at, label.height, angle=label.angle, layer=layer.name, scale=scale)
    if piece.strain_map is not None and layers["strain"] is not None:
        _strain_solids(msp, piece, layers["strain"].name, scale, truecolor=options.version not in ("R12", None,
                                                                                                   "R2000"))


def write(drawing: Drawing, path, options: WriteOptions) -> None:
    """Write a drawing as a machine-profile DXF (atomically: a failed write leaves nothing)."""
    version = options.version or "R2000"
    unit = Unit(options.units)
    scale = 1.0 / unit.mm
    r12 = version == "R12"
    layers: LayerMap = options.layer_map
    doc = new_doc(version, 0 if r12 else unit.insunits)  # $INSUNITS (R12 has none)
    doc.header["$MEASUREMENT"] = unit.measurement
    used = [layers[r] for r in _roles(drawing, options) if layers[r] is not None]
    declare_linetypes(doc, [layer.linetype for layer in used])
    for layer in dict.fromkeys(used):
        if layer.name not in doc.layers:
            doc.layers.add(layer.name, color=layer.color, linetype=layer.linetype)
    msp = doc.modelspace()
    for piece in drawing.pieces:
        _piece(msp, piece, layers, unit, options, r12)
    th = max((p.text_height for p in drawing.pieces), default=3.0)
    top = max(p.bounds[3] for p in drawing.pieces) if drawing.pieces else 0.0
    left = min(p.bounds[0] for p in drawing.pieces) if drawing.pieces else 0.0
    if drawing.stock and layers["stock"] is not None:
        for x0, y0, x1, y1 in drawing.stock:  # the roll's edges, or each sheet: a nest's marker
            add_polyline(msp, np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), layers["stock"].name, scale=scale,
                         r12=r12)
        top = max(top, max(s[3] for s in drawing.stock))
    if drawing.note and layers["label"] is not None:  # above the drawing, clear of every piece
        add_text(msp, f"{drawing.name}: {drawing.note}", (left, top + 3 * th), th, layer=layers["label"].name,
                 scale=scale, align="BOTTOM_LEFT")
    if r12 and layers["label"] is not None:
        first = drawing.pieces[0].text_height if drawing.pieces else th
        add_text(msp, f"UNITS: {unit.label}", (left, top + first), first, layer=layers["label"].name, scale=scale,
                 align="BOTTOM_LEFT")
    with atomic_output(path, what="DXF file") as tmp:
        save(doc, tmp)
        if r12:
            r12_units(tmp, unit, doc.output_encoding)

