"""Previews of DXF files at 1:1, with ezdxf's drawing add-on.

The preview renders the DXF file itself -- what a cutter's software will read
-- not the pattern in memory.  SVG pages are sized in millimetres to the
drawing (1 mm in the file is 1 mm on the page); PNG images carry their
resolution, so that printing at 100 % gives true size.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import atomic_output
from ..options import check_number

__all__ = ["PREVIEW_FORMATS", "preview_dxf"]

PREVIEW_FORMATS = (".png", ".svg")
"""File suffixes :func:`preview_dxf` writes."""


MAX_PIXELS = 40_000_000
"""The most pixels a PNG preview has (40 megapixels, about 160 MB while drawn): a larger drawing is
rendered at a lower resolution, stored in the file, so that it still prints at 1:1."""

_MM_PER_UNIT = {1: 25.4, 4: 1.0, 5: 10.0, 6: 1000.0}
"""``$INSUNITS`` to millimetres per drawing unit (unitless files are taken as mm)."""


def preview_dxf(dxf_path, out_path, *, dpi: float = 96, margin: float = 10.0) -> float:
    """Render a DXF file to a PNG or SVG at 1:1 (millimetres).

    Parameters
    ----------
    dxf_path : str or Path
        A DXF file (read with ezdxf's ``recover``, as a tolerant reader would).
    out_path : str or Path
        ``.png`` or ``.svg``; written atomically.
    dpi : float
        PNG resolution: 1 mm is ``dpi / 25.4`` pixels -- lowered for a drawing
        that would take more than :data:`MAX_PIXELS` (the resolution used is
        stored in the PNG and returned).
    margin : float
        White border around the drawing, mm.

    Returns
    -------
    float
        The PNG's resolution, dots per inch (``dpi``, or lower for a large
        drawing); 0 for an SVG.  Either prints at 1:1: the drawing's unit
        (``$INSUNITS``: mm, cm, m or inches) is honoured.

    Raises
    ------
    InputError
        Unknown output suffix, or a DXF file that cannot be read.
    ExportError
        The preview cannot be written.
    """
    from ezdxf import bbox, recover
    from ezdxf.addons.drawing import Frontend, RenderContext, layout, svg
    from ezdxf.addons.drawing.config import BackgroundPolicy, Configuration

    config = Configuration(background_policy=BackgroundPolicy.WHITE)  # paper: white, colour 7 black

    out_path = Path(out_path)
    dpi = check_number(dpi, "dpi", low=1, high=2400, name=str(out_path))
    margin = check_number(margin, "margin (mm)", low=0, high=1000, name=str(out_path))
    suffix = out_path.suffix.lower()
    if suffix not in PREVIEW_FORMATS:
        raise InputError(f"{out_path}: previews are written as {' or '.join(PREVIEW_FORMATS)}, not {suffix!r}")
    try:
        doc, _ = recover.readfile(str(dxf_path))
    except Exception as exc:  # noqa: BLE001 - any reader failure is the file's fault
        raise InputError(f"{dxf_path}: cannot read this DXF file ({exc})") from None
    msp = doc.modelspace()
    # Files in the ASTM dialect have no layer table (garment CAD reads them
    # that way); name their layers here, in memory, so that colour 7 is drawn
    # black on the white page like every other layer.
    used = {e.dxf.layer for block in doc.blocks for e in block if e.dxf.hasattr("layer")}
    for name in sorted(used - {layer.dxf.name for layer in doc.layers}):
        doc.layers.add(name, color=7)
    extents = bbox.extents(msp)
    if not extents.has_data:
        raise InputError(f"{dxf_path}: the DXF file draws nothing")
    unit = _MM_PER_UNIT.get(int(doc.header.get("$INSUNITS", 4) or 4), 1.0)
    if suffix == ".svg":
        backend = svg.SVGBackend()
        Frontend(RenderContext(doc), backend, config=config).draw_layout(msp)
        page = layout.Page(0, 0, layout.Units.mm, margins=layout.Margins.all(margin))
        text = backend.get_string(page, settings=layout.Settings(fit_page=False, scale=unit))
        with atomic_output(out_path, what="preview") as tmp:
            tmp.write_text(text, encoding="utf-8")
        return 0.0
    from ezdxf.addons.drawing.matplotlib import MatplotlibBackend
    from matplotlib.figure import Figure

    width = extents.size.x * unit + 2 * margin  # mm on paper
    height = extents.size.y * unit + 2 * margin
    pixels = (width / 25.4 * dpi) * (height / 25.4 * dpi)
    if pixels > MAX_PIXELS:
        dpi = dpi * float(np.sqrt(MAX_PIXELS / pixels))
    fig = Figure(figsize=(width / 25.4, height / 25.4), dpi=dpi)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_axis_off()
    Frontend(RenderContext(doc), MatplotlibBackend(ax), config=config).draw_layout(msp, finalize=False)
    pad = margin / unit
    ax.set_xlim(extents.extmin.x - pad, extents.extmax.x + pad)
    ax.set_ylim(extents.extmin.y - pad, extents.extmax.y + pad)
    ax.set_aspect("equal")
    with atomic_output(out_path, what="preview") as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, facecolor="white")
    return float(dpi)
