"""Closed rings of an SVG file that a DXF reader wrote (OpenSCAD's export, Inkscape's DXF import).

Used in-process by the tests (the project's Python, with svgelements from build123d's
dependencies): ``rings(svg_path, layer=None)`` returns the closed sub-paths as (k, 2) arrays
in the SVG's user units, from the ``inkscape:label`` layer group when given, else from every
path (and, for Inkscape's ASTM import, from every ``<symbol>``: its pieces).
"""

import xml.etree.ElementTree as ET

import numpy as np
import svgelements as se

INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"
SVG = "{http://www.w3.org/2000/svg}"


def _path_rings(d: str) -> list:
    out, ring = [], []
    for seg in se.Path(d):
        if isinstance(seg, se.Move):
            if len(ring) >= 3:
                out.append(np.array(ring))
            ring = [(seg.end.x, seg.end.y)]
        elif isinstance(seg, se.Close):
            if len(ring) >= 3:
                out.append(np.array(ring))
            ring = []
        elif isinstance(seg, se.Line):
            ring.append((seg.end.x, seg.end.y))
        else:  # arcs and curves, sampled
            ring.extend(map(tuple, np.asarray(seg.npoint(np.linspace(0, 1, 33)[1:])).reshape(-1, 2)))
    if len(ring) >= 3 and np.allclose(ring[0], ring[-1]):
        out.append(np.array(ring))
    return out


def rings(svg_path, layer=None) -> list:
    root = ET.parse(svg_path).getroot()
    if layer is not None:
        groups = [g for g in root.iter(f"{SVG}g") if g.get(f"{INKSCAPE}label") == layer]
        paths = [p for g in groups for p in g.iter(f"{SVG}path")]
    else:
        paths = list(root.iter(f"{SVG}path"))
    return [r for p in paths for r in _path_rings(p.get("d", ""))]


def symbol_rings(svg_path) -> dict:
    """``{symbol id: [rings]}`` of every ``<symbol>`` (an ASTM file's piece blocks, as Inkscape imports them)."""
    root = ET.parse(svg_path).getroot()
    return {s.get("id"): [r for p in s.iter(f"{SVG}path") for r in _path_rings(p.get("d", ""))]
            for s in root.iter(f"{SVG}symbol")}
