"""Labels on the pieces (issue 34): never below the least text height, inside their piece and clear of its
holes, or left out with a ``label-left-out`` note; and a strain-free part's heat map that says 0 % plainly.

References are independent of the label placer: the written DXF read back with ezdxf (each TEXT's
height, and its glyphs drawn as paths by ezdxf's text2path), the pieces' outlines and holes read from
the CUT layer and compared with shapely, the labels a piece is owed counted from the pattern itself
(one name, one title line, one label per seam side), and the heat map's colour bar and panel names read
through matplotlib's own objects.
"""

from __future__ import annotations

import json
import re

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely
from ezdxf.addons import text2path
from matplotlib.backends.backend_agg import FigureCanvasAgg

import patterns
from patterns import Code, Severity
from patterns.export.heatmap import display_offsets, heat_map_figure

from .conftest import SAMPLES
from .test_unfold import bent_strip

LEAST = 2.0
"""The least text height the docs give (``text_height``: 3 % of each panel's size, 2-12 mm)."""

SEAM_LABEL = re.compile(r"S(\d+) 3D [\d.]+ FLAT [\d.]+ MM")


@pytest.fixture(scope="module")
def holed():
    """The README's box with a hole."""
    return patterns.flatten(patterns.load(bd.Box(200, 100, 50) - bd.Cylinder(20, 50)))


@pytest.fixture(scope="module")
def holed_dxf(holed, tmp_path_factory):
    path = tmp_path_factory.mktemp("labels") / "box.dxf"
    patterns.write(holed, path)
    return ezdxf.readfile(path)


def _texts(doc) -> list:
    return list(doc.modelspace().query("TEXT MTEXT"))


def _height(entity) -> float:
    return float(entity.dxf.height if entity.dxftype() == "TEXT" else entity.dxf.char_height)


def _glyphs(entity) -> shapely.Polygon:
    """The convex hull of the text's glyphs as ezdxf draws them (text2path), mm."""
    points = [(v.x, v.y) for path in text2path.make_paths_from_entity(entity) for v in path.flattening(0.01)]
    return shapely.MultiPoint(points).convex_hull


def _drawn(figure):
    """The figure drawn by Agg, as a PNG would be: ``(figure, renderer)``."""
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    return figure, canvas.get_renderer()


def _pieces(doc) -> list:
    """Each piece's cut polygon (its outline less the CUT loops inside it), read from the CUT layer."""
    loops = [shapely.Polygon([p[:2] for p in e.get_points("xy")]) for e in doc.modelspace().query("LWPOLYLINE[layer=='CUT']")]
    outers = [a for a in loops if not any(b is not a and b.contains(a) for b in loops)]
    return [shapely.Polygon(o.exterior, [h.exterior.coords for h in loops if h is not o and o.contains(h)])
            for o in outers]


def _piece_of(text, pieces):
    """The piece whose outline holds the text's anchor (its middle)."""
    at = shapely.Point(tuple(text.dxf.align_point)[:2])
    (piece,) = [p for p in pieces if shapely.Polygon(p.exterior).contains(at)]
    return piece


# --------------------------------------------------------------------------- #
# The least text height
# --------------------------------------------------------------------------- #


def test_no_label_of_the_box_with_a_hole_is_below_the_least_height(holed, holed_dxf):
    """Every TEXT and MTEXT of the README's box with a hole is 2 mm high or more (it had seam labels of
    0.59, 0.9 and 1.44 mm), and none was dropped to get there: every panel's name, and one label for
    each side of every seam, are in the file."""
    texts = _texts(holed_dxf)
    heights = sorted(_height(t) for t in texts)
    assert heights[0] >= LEAST - 1e-9, heights[:5]
    said = [t.dxf.text for t in texts]
    assert {flat.name for flat in holed.panels} <= set(said)
    seams = sorted(int(m.group(1)) for s in said if (m := SEAM_LABEL.fullmatch(s)))
    assert seams == sorted(2 * [fs.seam.id for fs in holed.seams])


def test_a_smaller_text_height_asked_for_is_kept(holed, tmp_path):
    """text_height=1: the user's own height is the least, so labels go below 2 mm, but none below 1 mm."""
    path = tmp_path / "small.dxf"
    patterns.write(holed, path, text_height=1.0)
    heights = [_height(t) for t in _texts(ezdxf.readfile(path))]
    assert min(heights) >= 1.0 - 1e-9 and min(heights) < LEAST


# --------------------------------------------------------------------------- #
# Labels fit their piece
# --------------------------------------------------------------------------- #


def test_every_label_of_the_box_with_a_hole_lies_inside_its_piece_clear_of_its_holes(holed_dxf):
    """Each text's glyphs, as ezdxf draws them, lie inside the outline of the piece it is on and outside
    that piece's holes (two of the pieces have the hole)."""
    pieces = _pieces(holed_dxf)
    assert sum(len(p.interiors) for p in pieces) == 2
    for text in _texts(holed_dxf):
        glyphs = _glyphs(text)
        piece = _piece_of(text, pieces)
        assert piece.contains(glyphs), (text.dxf.text, glyphs.bounds)
        assert not any(shapely.Polygon(h).intersects(glyphs) for h in piece.interiors), text.dxf.text


def test_bend_labels_of_a_narrow_blank_lie_inside_it(tmp_path):
    """A strip 10 mm wide, bent once: its bend line (10 mm) is shorter than its label at 2 mm. The label is
    drawn, 2 mm high or more, and its glyphs lie inside the blank, as do all its other texts."""
    blank = patterns.unfold(bent_strip(width=10.0, la=100.0, lb=80.0), k_factor=0.4)
    assert min(blank.size) == pytest.approx(10.0)
    path = tmp_path / "narrow.dxf"
    patterns.write(blank, path)
    doc = ezdxf.readfile(path)
    (piece,) = _pieces(doc)
    bend, details = doc.modelspace().query("TEXT[layer=='BEND']")
    assert re.fullmatch(r"UP 90\.0 DEG R2", bend.dxf.text)
    allowance = np.pi / 2 * (2.0 + 0.4 * 1.5)  # a quarter turn of the neutral layer, R2 + K t
    assert details.dxf.text == f"BA {allowance:.2f} L 10.00 MM"  # the bend sheet's allowance and length
    assert _glyphs(bend).distance(_glyphs(details)) > 0  # two lines, one beside the other
    (line,) = doc.modelspace().query("LINE[layer=='BEND']")
    x0, y0, x1, y1 = _glyphs(bend).bounds
    assert np.hypot(*(np.array(line.dxf.end) - np.array(line.dxf.start))[:2]) < max(x1 - x0, y1 - y0)
    for text in _texts(doc):
        assert _height(text) >= LEAST - 1e-9, text.dxf.text
        assert piece.contains(_glyphs(text)), (text.dxf.text, _glyphs(text).bounds, piece.bounds)


@pytest.mark.parametrize("size", [8.0, 20.0])
def test_a_label_that_cannot_fit_is_left_out_with_a_note(size, tmp_path):
    """A small cube: its faces hold no seam label at 2 mm (they are longer than the faces), and an 8 mm face
    not even its name. Each label a face is owed (its name, its strain line, one per seam side) is either
    drawn on it, whole and 2 mm high or more, or named by a label-left-out note on that piece -- never
    both, never neither."""
    cube = patterns.flatten(patterns.load(bd.Box(size, size, size)))
    path = tmp_path / "cube.dxf"
    patterns.write(cube, path)
    texts = _texts(ezdxf.readfile(path))
    assert all(_height(t) >= LEAST - 1e-9 for t in texts)
    drawing = patterns.pieces.drawing_of(cube)  # the pieces as written, with their findings
    notes = []
    for piece in drawing.pieces:
        flat = cube.panels[piece.source.index]
        outline = shapely.Polygon(piece.sew[0])
        on = [t for t in texts if outline.contains(shapely.Point(tuple(t.dxf.align_point)[:2]))]
        assert all(outline.contains(_glyphs(t)) for t in on)
        drawn = sorted(t.dxf.text for t in on)
        owed = sorted([flat.name, "STRAIN RMS 0.00% MAX 0.00%"] + [
            f"S{fs.seam.id} 3D {size:.2f} FLAT {size:.2f} MM"
            for fs in cube.seams for p in fs.seam.panels if p == piece.source.index])
        left = [f for f in piece.findings if f.code is Code.LABEL_LEFT_OUT]
        assert all(f.severity is Severity.NOTE and f.panels == (piece.name,) for f in left)
        assert all(f.message.startswith(f"panel {piece.name}: ") and "(2 mm)" in f.message for f in left)
        named = [re.search(r" label '(.*)' does not fit", f.message).group(1) for f in left]
        assert sorted(drawn + named) == owed
        notes += named
    assert any(SEAM_LABEL.fullmatch(n) for n in notes)
    assert (size < 10) == any(n.startswith("face") for n in notes)  # an 8 mm face cannot hold its name


# --------------------------------------------------------------------------- #
# The heat map
# --------------------------------------------------------------------------- #


def test_the_heat_map_of_a_strain_free_part_says_0_percent_plainly(holed):
    """A box is all planar: strain exactly 0. Its colour bar's ticks are percentages with 0 % among them,
    symmetric about it over a sensible range (not +-1e-6), with no multiplier or offset text."""
    assert max(float(np.abs(p.strains.dominant).max()) for p in holed.panels) == 0.0
    fig, _ = _drawn(heat_map_figure(holed))
    _, bar = fig.axes
    labels = [t.get_text() for t in bar.get_yticklabels() if t.get_text()]
    assert bar.yaxis.get_offset_text().get_text() == ""
    assert all(label.endswith("%") and "e" not in label.lower() for label in labels), labels
    values = [float(label[:-1].replace("\N{MINUS SIGN}", "-")) for label in labels]
    assert "0%" in labels and values == sorted(values) and values == [-v for v in values[::-1]]
    lo, hi = bar.get_ylim()
    assert lo == -hi and 0.01 <= hi <= 5.0  # in %: a range a reader takes for "nothing", not 1e-6


def test_the_heat_map_of_a_strained_part_has_percent_ticks(tmp_path):
    """The cup (strain up to about 15 %): ticks in whole percent, 0 % in the middle, no multiplier; the
    file is written."""
    cup = patterns.flatten(patterns.load(SAMPLES / "cup.step"))
    fig, _ = _drawn(heat_map_figure(cup, max_strain=0.03))
    _, bar = fig.axes
    labels = [t.get_text() for t in bar.get_yticklabels() if t.get_text()]
    assert labels == ["\N{MINUS SIGN}3%", "\N{MINUS SIGN}2%", "\N{MINUS SIGN}1%", "0%", "1%", "2%", "3%"]
    assert bar.yaxis.get_offset_text().get_text() == ""
    patterns.heat_map(cup, tmp_path / "cup.png")
    assert (tmp_path / "cup.png").stat().st_size > 0


def test_the_heat_map_names_each_panel_inside_it_not_in_its_hole(holed):
    """Each panel's name, as matplotlib lays out its text, lies inside the panel as drawn and clear of its
    hole (the plate's names sat in the hole)."""
    fig, renderer = _drawn(heat_map_figure(holed))
    ax = fig.axes[0]
    offsets = display_offsets(holed)
    names = {t.get_text(): t for t in ax.texts}
    to_data = ax.transData.inverted()
    for flat, off in zip(holed.panels, offsets):
        uv = flat.uv + off
        panel = shapely.Polygon(uv[flat.loops[0]], [uv[loop] for loop in flat.loops[1:]])
        box = names[flat.name].get_window_extent(renderer)
        (x0, y0), (x1, y1) = to_data.transform([[box.x0, box.y0], [box.x1, box.y1]])
        assert panel.contains(shapely.box(x0, y0, x1, y1)), (flat.name, (x0, y0, x1, y1), panel.bounds)


def test_the_written_report_keeps_each_label_left_out(tmp_path):
    """The check's findings join a piece's own when the pattern is written: the JSON report's pieces still name
    the labels the DXF leaves out, at the same points."""
    cube = patterns.flatten(patterns.load(bd.Box(8.0, 8.0, 8.0)))
    patterns.write(cube, tmp_path / "cube.json")
    report = json.loads((tmp_path / "cube.json").read_text())
    in_json = {p["name"]: sorted(f["message"] for f in p["findings"] if f["code"] == "label-left-out")
               for p in report["pieces"]}
    drawing = patterns.pieces.drawing_of(cube)  # the pieces with their own findings
    own = {p.name: sorted(f.message for f in p.findings if f.code is Code.LABEL_LEFT_OUT) for p in drawing.pieces}
    assert in_json == own and all(own.values())  # every face of the 8 mm cube leaves a label out
