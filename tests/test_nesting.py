"""patterns.nesting: pieces on a roll or on sheets by sparrow, checked with shapely on the placed outlines."""

import json
import re

import build123d as bd
import ezdxf
import numpy as np
import pytest
import shapely

import patterns
from patterns.curves import Motion
from patterns.errors import InputError, LayoutError
from patterns.nesting import NestOptions

from .conftest import SAMPLES

QUICK = {"time_limit": 1, "cache": False}  # sparrow's search, 1 s (enough for these few pieces), searched anew


@pytest.fixture(scope="module")
def plates():
    """Six flat rectangles (a box's faces): 200x100, 200x50, 100x50, two of each."""
    return patterns.flatten(patterns.load(bd.Box(200, 100, 50), max_edge=25))


def _outlines(nest):
    """The placed pieces' cut outlines, from their own points (each piece's outline as drawn)."""
    return [shapely.Polygon(piece.outline.points()) for piece in nest.pieces]


def _disjoint(polys, gap=0.0) -> bool:
    """No two outlines closer than ``gap`` (touching allowed at 0): shapely, pair by pair."""
    return all(polys[i].distance(polys[j]) >= gap - 1e-6 and polys[i].intersection(polys[j]).area < 1e-9
               for i in range(len(polys)) for j in range(i + 1, len(polys)))


def _min_distance(polys):
    return min(polys[i].distance(polys[j]) for i in range(len(polys)) for j in range(i + 1, len(polys)))


@pytest.mark.parametrize(("width", "gap"), [(450.0, 10.0), (230.0, 5.0)])
def test_placed_pieces_keep_the_gap_and_the_roll(plates, width, gap):
    nest = patterns.layout(plates, width=width, gap=gap, **QUICK)
    polys = _outlines(nest)
    assert _min_distance(polys) >= gap - 1e-6
    x = np.concatenate([np.asarray(p.exterior.coords)[:, 0] for p in polys])
    y = np.concatenate([np.asarray(p.exterior.coords)[:, 1] for p in polys])
    assert x.min() >= -1e-6 and x.max() <= width + 1e-6 and y.min() >= -1e-6
    assert nest.length == pytest.approx(y.max(), abs=1e-6)
    area = sum(p.area for p in polys)
    assert area == pytest.approx(2 * (200 * 100 + 200 * 50 + 100 * 50), rel=1e-9)  # nothing rescaled
    assert nest.efficiency == pytest.approx(area / (width * nest.length), rel=1e-9)
    assert _disjoint(polys, gap)
    laid = plates.placed([(p.placement.angle, p.placement.dx, p.placement.dy) for p in nest.pieces])
    assert patterns.check(laid).ok  # the report's own overlap test agrees, on the panels placed as the pieces


def test_four_equal_rectangles_pack_two_by_two():
    """Four 100 x 50 rectangles, grain along the roll, on a 211 mm roll with a 10 mm gap: two fit side
    by side, so the shortest marker is two rows, 50 + 10 + 50 = 110 mm long (sparrow sees each outline
    0.05 mm larger: at most 110.2 mm); three rows would be 170 mm."""
    nest = patterns.layout(_rectangles([(100.0, 50.0)] * 4), width=211.0, gap=10.0, **QUICK)
    assert 110.0 <= nest.length <= 110.2 + 1e-6
    assert nest.efficiency == pytest.approx(4 * 100 * 50 / (211.0 * nest.length), rel=1e-9)


def test_the_grain_stays_along_the_roll(plates):
    """rotations="grain" (the default): every piece turned by 0 or 180 degrees only."""
    nest = patterns.layout(plates, width=450.0, **QUICK)
    for piece in nest.pieces:
        angle = piece.placement.angle % np.pi
        assert min(angle, np.pi - angle) < 1e-9


def _rectangles(sizes, name="rects"):
    """Flat rectangles ``(width along x, height along y)`` mm, as panels with their grain along +Y."""
    from patterns.reading import mesh_model

    vs, fs, offset = [], [], 0
    for k, (w, h) in enumerate(sizes):
        x, y = np.meshgrid(np.linspace(0, w, 5), np.linspace(0, h, 3))
        grid = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 500.0 * k)])
        quads = [(r * 5 + c, r * 5 + c + 1, (r + 1) * 5 + c + 1, (r + 1) * 5 + c) for r in range(2) for c in range(4)]
        tri = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
        vs.append(grid)
        fs.append(tri + offset)
        offset += len(grid)
    return patterns.flatten(mesh_model(np.vstack(vs), np.vstack(fs), name=name), method="isometric",
                            grain=(0, 1, 0))


def test_a_long_piece_is_turned_across_only_when_it_may_turn():
    """A 300 x 40 piece on a 100 mm roll fits only turned by 90 degrees: done with quarter or free
    turns, refused with the grain kept (0 or 180 only) or with no turn at all."""
    pattern = _rectangles([(300.0, 40.0)])
    for rotations in ("quarter", "free"):
        nest = patterns.layout(pattern, width=100.0, rotations=rotations, **QUICK)
        (piece,) = nest.pieces
        assert np.ptp(piece.outline.points()[:, 0]) == pytest.approx(40.0, abs=0.1)  # across the roll
        assert nest.length == pytest.approx(300.0, abs=0.2)
    for rotations in ("grain", "none"):
        with pytest.raises(LayoutError, match="wider than the 100 mm roll in every allowed orientation"):
            patterns.layout(pattern, width=100.0, rotations=rotations, **QUICK)


def test_the_margin_is_kept_around_each_outline():
    """A margin (a kerf, a cutter's clearance) keeps the outlines gap + 2 x margin apart and the margin
    inside the roll."""
    nest = patterns.layout(_rectangles([(100.0, 50.0)] * 3), width=400.0, gap=10.0, margin=5.0, **QUICK)
    polys = _outlines(nest)
    assert _min_distance(polys) >= 20.0 - 1e-6
    x = np.concatenate([np.asarray(p.exterior.coords)[:, 0] for p in polys])
    assert x.min() >= 5.0 - 1e-6 and x.max() <= 400.0 - 5.0 + 1e-6
    assert nest.area_panels == pytest.approx(3 * 110.0 * 60.0, rel=1e-9)  # each outline with its 5 mm all round


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"width": 0.0}, "width must be a positive number"), ({"width": 100.0, "gap": -1.0}, "gap must be"),
    ({"width": 100.0, "margin": -1.0}, "margin must be"), ({"width": 100.0, "rotations": "some"}, "rotations must"),
    ({"width": 100.0, "sheet": (100, 100)}, "a roll \\(width\\) or on sheets \\(sheet\\), not both"),
    ({"sheet": (100, -1)}, "sheet width \\(mm\\) must be"), ({}, "give a roll width or a sheet"),
    ({"width": 100.0, "copies": 0}, "copies must be"), ({"width": 100.0, "quantities": {"nope": 2}},
                                                         "quantities name piece 'nope'; the pieces are face0, face1, "),
    ({"width": 100.0, "time_limit": 0}, "time_limit must be")])
def test_bad_nest_options(plates, kwargs, words):
    """One line naming the pattern and the option."""
    with pytest.raises(InputError, match=rf"^{plates.name}: .*{words}"):
        patterns.layout(plates, **kwargs)


def test_only_patterns_blanks_and_pieces_are_nested():
    with pytest.raises(InputError, match="expected a patterns.Pattern, Blank or Piece \\(or a list of them\\), got Almost$"):
        patterns.layout(type("Almost", (), {"panels": (), "name": "x"})(), width=100.0)


@pytest.mark.slow
def test_the_same_pieces_and_options_give_the_same_marker(plates, _marker_cache):
    """Sparrow's search stops on time, so a loaded machine could stop it elsewhere: every marker is kept
    (the cache the suite points PATTERNS_CACHE at), and asked again gives the same marker, at once;
    cache=False searches anew, for its whole budget; another seed is another search."""
    from patterns.nesting import cache_folder

    assert cache_folder() == _marker_cache
    before = set(_marker_cache.iterdir())
    a = patterns.layout(plates, width=300.0, rotations="quarter", seed=11, time_limit=1)
    kept = set(_marker_cache.iterdir()) - before
    assert len(kept) == 1
    b = patterns.layout(plates, width=300.0, rotations="quarter", seed=11, time_limit=1)
    assert [p.placement for p in a.pieces] == [p.placement for p in b.pieces]
    assert a.length == b.length and b.cached and not a.cached
    fresh = patterns.layout(plates, width=300.0, rotations="quarter", seed=11, time_limit=1, cache=False)
    assert not fresh.cached and set(_marker_cache.iterdir()) - before == kept
    patterns.layout(plates, width=300.0, rotations="quarter", seed=12, time_limit=1)
    assert len(set(_marker_cache.iterdir()) - before) == 2


def test_copies_and_mirrored_pairs(tmp_path):
    """Two of every piece and each also mirrored: four pieces per panel, the mirrored ones the reflected
    outline (same area, turned the other way), all carrying their source's seams in the DXF (notches at
    both ends of every seam side on every piece)."""
    from .conftest import SAMPLES

    cup = patterns.flatten(patterns.load(SAMPLES / "cup.step"))
    nest = patterns.layout(cup, width=900.0, copies=2, mirror=True, seam_allowance=10.0, **QUICK)
    assert len(nest.pieces) == 16
    names = [p.name for p in nest.pieces]
    assert {"face0", "face0 #2", "face0 mirrored", "face0 #2 mirrored"} <= set(names)
    sources = {p.name: p for p in patterns.pieces_of(cup, seam_allowance=10.0)}
    for piece in nest.pieces:
        source = sources[piece.name.split(" ")[0]]
        assert piece.area == pytest.approx(source.area, rel=1e-9)  # nothing rescaled
        # a mirror image: the same edge lengths, read along its loop the other way round
        a = np.linalg.norm(np.diff(source.outline.points(), axis=0, append=source.outline.points()[:1]), axis=1)
        b = np.linalg.norm(np.diff(piece.outline.points(), axis=0, append=piece.outline.points()[:1]), axis=1)
        assert sorted(np.round(a, 6)) == sorted(np.round(b, 6))
        # every piece is its source moved by its placement: turned and shifted, mirrored for a mirror image
        m = piece.placement.matrix
        assert np.linalg.det(m) == pytest.approx(-1.0 if piece.name.endswith("mirrored") else 1.0)
        assert piece.placement.mirrored == piece.name.endswith("mirrored")
        expected = source.outline.points() @ m.T + piece.placement.shift
        got = piece.outline.points()
        assert min(np.abs(np.roll(got[::-1] if piece.placement.mirrored else got, -k, axis=0) - expected).max()
                   for k in range(len(got))) < 1e-9
    assert _disjoint(_outlines(nest), 10.0)
    path = tmp_path / "marker.dxf"
    patterns.write(nest, path)
    doc = ezdxf.readfile(path)
    assert len(doc.modelspace().query('LINE[layer=="NOTCH"]')) == 16 * 2 * 2  # 2 seams x 2 ends per piece
    (stock,) = doc.modelspace().query('LWPOLYLINE[layer=="STOCK"]')
    assert np.ptp(np.array(stock.get_points("xy"))[:, 0]) == pytest.approx(900.0)
    texts = [t.dxf.text for t in doc.modelspace().query("TEXT")]
    assert any(f"efficiency {nest.efficiency:.1%}" in t for t in texts)


def test_quantities_per_panel(plates):
    name = plates.panels[0].name
    nest = patterns.layout(plates, width=450.0, quantities={name: 3}, **QUICK)
    assert [p.name for p in nest.pieces].count(name) == 1
    assert sum(p.name.startswith(f"{name} #") for p in nest.pieces) == 2
    assert len(nest.pieces) == len(plates.panels) + 2


@pytest.mark.slow
def test_sheets_are_filled_one_after_another(plates):
    """Twelve rectangles on 400 x 300 mm sheets: every piece wholly on one sheet, sheets reported one by
    one with the area of their own pieces (shapely's) over the sheet's."""
    nest = patterns.layout(plates, sheet=(400.0, 300.0), copies=2, **QUICK)
    polys = _outlines(nest)
    assert _min_distance(polys) >= 10.0 - 1e-6
    assert sum(len(s.pieces) for s in nest.sheets) == 12
    total = 0.0
    for sheet, (x0, y0, x1, y1) in zip(nest.sheets, nest.stock):
        assert (x1 - x0, y1 - y0) == (300.0, 400.0)  # the sheet's width across, its length along
        mine = [p for f, p in zip(nest.pieces, polys) if f.name in sheet.pieces]
        box = shapely.box(x0, y0, x1, y1)
        assert all(box.buffer(1e-6).contains(p) for p in mine)
        assert sheet.usage == pytest.approx(sum(p.area for p in mine) / (400.0 * 300.0), rel=1e-9)
        total += sum(p.area for p in mine)
    assert nest.efficiency == pytest.approx(total / (len(nest.sheets) * 400.0 * 300.0), rel=1e-9)
    assert total == pytest.approx(4 * (200 * 100 + 200 * 50 + 100 * 50), rel=1e-9)
    n = len(nest.sheets)
    assert str(nest) == (f"{n} sheet{'s' if n != 1 else ''} of 400 x 300 mm, usage "
                         + ", ".join(f"{s.usage:.1%}" for s in nest.sheets) + f" ({nest.efficiency:.1%} in all)")
    assert nest.length == 400.0 * n and nest.area_used == 400.0 * 300.0 * n  # the sheets, end to end
    one = patterns.layout(plates, sheet=(2000.0, 1000.0), **QUICK)
    assert len(one.sheets) == 1 and str(one).startswith("1 sheet of 2000 x 1000 mm, usage ")


def test_a_piece_too_big_for_the_sheet_is_refused(plates):
    with pytest.raises(LayoutError, match="does not fit on a 150 x 300 mm sheet"):
        patterns.layout(plates, sheet=(150.0, 300.0), rotations="none", **QUICK)


def _placed(plates, moves):
    """The plates' pieces moved by ``moves`` ``(angle, dx, dy)`` each: ``(pieces, placed outlines)``."""
    from patterns.nesting import _outline

    laid = [piece.moved(Motion(*m)) for piece, m in zip(patterns.pieces_of(plates), moves)]
    return laid, [_outline(p, 0.0) for p in laid]


def _side_by_side(plates, step):
    """The plates' pieces with piece 1 ``step`` mm to the right of piece 0 (negative: overlapping), the
    others far off: ``(pieces, placed outlines)``."""
    first, second = patterns.pieces_of(plates)[:2]
    return _placed(plates, [(0.0, 0.0, 0.0), (0.0, first.bounds[2] + step - second.bounds[0], 0.0)]
                   + [(0.0, 1000.0 + 400.0 * k, 0.0) for k in range(4)])


def test_a_nest_that_breaks_the_gap_is_refused_not_returned(plates):
    """The shapely check itself: two pieces 1 mm apart under a 10 mm gap are refused."""
    from patterns.nesting import _verify

    laid, placed = _side_by_side(plates, 1.0)
    with pytest.raises(LayoutError, match="under the 10 mm gap"):
        _verify("plates", laid, placed, 5000.0, NestOptions(width=5000.0), [(0.0, -1000.0, 5000.0, None)])


def test_a_gap_under_a_millimetre_is_kept_too(plates):
    """gap=0.5: two pieces 0.2 mm apart are refused."""
    from patterns.nesting import _verify

    laid, placed = _side_by_side(plates, 0.2)
    with pytest.raises(LayoutError, match="lie 0.200 mm apart, under the 0.5 mm gap"):
        _verify("plates", laid, placed, 5000.0, NestOptions(width=5000.0, gap=0.5), [(-1e5, -1e5, 1e5, None)])


def test_with_no_gap_pieces_may_touch_but_never_overlap(plates):
    """gap=0: two pieces that share an edge pass the shapely check; two that overlap by 1 mm are refused."""
    from patterns.nesting import _verify

    for step, ok in ((0.0, True), (-1.0, False)):
        laid, placed = _side_by_side(plates, step)
        args = ("plates", laid, placed, 5000.0, NestOptions(width=5000.0, gap=0.0), [(-1e5, -1e5, 1e5, None)])
        if ok:
            _verify(*args)
        else:
            with pytest.raises(LayoutError, match="under the 0 mm gap"):
                _verify(*args)


@pytest.mark.parametrize(("sheet", "words"), [((1e8, 100.0), "sheet length (mm)"), ((100.0, 1e8), "sheet width (mm)"),
                                              ((0.0, 100.0), "sheet length (mm)"), ((100.0, -5.0), "sheet width (mm)"),
                                              ((100.0, 0.0), "sheet width (mm) must be a positive number")])
def test_a_sheet_out_of_bounds_is_named(sheet, words):
    with pytest.raises(InputError, match=re.escape(words)):
        NestOptions(sheet=sheet)


@pytest.mark.parametrize(("value", "words"), [
    ({"face0": 0}, "quantities['face0'] must be an integer between 1 and 2000, got 0"),
    ({"face0": 2001}, "got 2001"), ({"face0": 2.5}, "got 2.5"), ({"face0": True}, "got True"),
    (5, "quantities must map panel names to counts, e.g. {'sleeve': 2}")])
def test_quantities_are_whole_counts_within_bounds(value, words):
    with pytest.raises(InputError, match=re.escape(words)):
        NestOptions(width=100.0, quantities=value)
    assert NestOptions(width=100.0, quantities={"a": 1, 7: 2000}).quantities == {"a": 1, "7": 2000}


@pytest.mark.parametrize("value", [(100.0,), "ab", (1, 2, 3, 4), {"length": 100.0}])
def test_a_sheet_is_two_numbers(value):
    with pytest.raises(InputError, match=r"sheet must be \(length, width\) in mm, or \(length, width, sheets on hand\), "
                                         r"or a list of them, got"):
        NestOptions(sheet=value)


def test_every_input_of_a_search_is_in_its_marker_key():
    """The marker cache's key: the same for the same search (whatever the order its fields come in),
    another for a change to any one of them -- the outlines, the strip, the turns, the gap, the time,
    the seed -- so that a kept marker is only ever given back to the search that found it."""
    from patterns.nesting import _key

    task = {"items": [[[0.0, 0.0], [100.0, 0.0], [0.0, 50.0]]], "strip": 320.0, "orientations": [0.0, 180.0],
            "gap": 10.0, "time": 10, "seed": 0}
    assert _key(dict(reversed(task.items()))) == _key(task)
    changed = {"items": [[[0.0, 0.0], [100.0, 0.0], [0.0, 50.5]]], "strip": 320.5, "orientations": [0.0],
               "gap": 5.0, "time": 11, "seed": 1}
    keys = {_key(task)} | {_key({**task, field: value}) for field, value in changed.items()}
    assert len(keys) == 1 + len(changed)
    assert all(re.fullmatch(r"[0-9a-f]{64}", k) for k in keys)  # a file name on any system


@pytest.mark.slow
def test_the_cache_folder_is_made_and_a_broken_marker_searched_anew(plates, tmp_path, monkeypatch):
    """The cache folder is made (parents too) at the first marker kept; a kept file that is not a marker
    (cut short, edited, another version's, NaN, a turn not allowed) or a marker that fails the check is never
    used: the search runs again and keeps a good one."""
    from patterns.nesting import cache_folder

    monkeypatch.setenv("PATTERNS_CACHE", str(tmp_path / "deep" / "er" / "markers"))
    first = patterns.layout(plates, width=300.0, seed=5, time_limit=1)
    (kept,) = cache_folder().iterdir()
    n = len(plates.panels)
    poisoned = [json.dumps([[float("nan"), 0.0, 0.0]] * n),  # NaN (issue 33: every later run failed)
                json.dumps([[45.0, 0.0, 0.0]] * n),  # a turn the grain does not allow
                json.dumps([[0.0, 0.0, 0.0]] * n)]  # well formed, every piece on one spot: fails the shapely check
    for broken in ("[[0.0, 1.0", "[]", '{"a": 1}', "[[0, 1, 2]]", *poisoned):
        kept.write_text(broken)
        again = patterns.layout(plates, width=300.0, seed=5, time_limit=1)
        assert again.seconds >= 0.5  # searched anew
        assert _disjoint(_outlines(again), 10.0) and len(again.pieces) == len(plates.panels)
        assert len(json.loads(kept.read_text())) == len(plates.panels)  # and the good marker kept again
        assert kept.read_text() != broken and all(np.isfinite(json.loads(kept.read_text())).all(axis=1))
    assert first.length > 0


@pytest.mark.slow
def test_sheets_lie_a_sheet_spacing_apart(plates):
    """The sheets of a nest are drawn one after another along the roll's direction, SHEET_SPACING apart:
    sheet k from k x (length + spacing)."""
    from patterns.nesting import SHEET_SPACING

    nest = patterns.layout(plates, sheet=(300.0, 250.0), copies=2, **QUICK)
    assert len(nest.sheets) >= 2
    for k, rect in enumerate(nest.stock):
        assert rect == pytest.approx((0.0, k * (300.0 + SHEET_SPACING), 250.0, k * (300.0 + SHEET_SPACING) + 300.0))
    assert [s.index for s in nest.sheets] == list(range(len(nest.sheets)))


def test_a_piece_off_the_roll_is_refused(plates):
    """The shapely check: a piece 1 mm past either edge of a 2000 mm roll, or before its start, is
    refused; one on the edges is not."""
    from patterns.nesting import _outline, _verify

    bounds = [_outline(piece, 0.0).bounds for piece in patterns.pieces_of(plates)]
    rest = [(0.0, 300.0 + 350.0 * k - b[0], -b[1]) for k, b in enumerate(bounds[1:])]  # 300 .. 1900 mm across
    x0, y0, x1, _ = bounds[0]
    for dx, dy, ok in ((-x0, -y0, True), (2000.0 - x1, -y0, True), (-x0 - 1.0, -y0, False),
                       (2000.0 - x1 + 1.0, -y0, False), (-x0, -y0 - 1.0, False)):
        laid, placed = _placed(plates, [(0.0, dx, dy), *rest])
        args = ("plates", laid, placed, 2000.0, NestOptions(width=2000.0), [(0.0, 0.0, 2000.0, None)])
        if ok:
            _verify(*args)
        else:
            with pytest.raises(LayoutError, match=f"piece {laid[0].name} lies off the roll or sheet"):
                _verify(*args)


@pytest.mark.parametrize("gap", [10.0, 0.0])
def test_a_piece_as_wide_as_the_roll_fits(gap):
    """Two 100 x 50 mm pieces on a 100 mm roll, not turned: one after the other, each touching both
    edges (sparrow sees every outline 0.05 mm larger, and wants room to spare: the strip it is given
    allows for both, the pieces land on the true roll)."""
    nest = patterns.layout(_rectangles([(100.0, 50.0)] * 2), width=100.0, gap=gap, rotations="none", **QUICK)
    for poly in _outlines(nest):
        x0, _, x1, _ = poly.bounds
        assert x0 == pytest.approx(0.0, abs=1e-4) and x1 == pytest.approx(100.0, abs=1e-4)
    assert nest.length == pytest.approx(100.0 + gap, abs=0.2)


def test_sparrow_giving_up_is_a_layout_error():
    """A panic inside sparrow (here: an item wider than its strip, which layout() never sends) reaches
    the caller as a LayoutError naming the pattern, not as pyo3's PanicException."""
    from patterns.nesting import _sparrow

    task = {"items": [[[0.0, 0.0], [50.0, 0.0], [50.0, 200.0], [0.0, 200.0]]], "strip": 100.0,
            "orientations": [0.0], "gap": 0.0, "time": 1, "seed": 0}
    with pytest.raises(LayoutError, match=r"^wide: sparrow could not nest the pieces \("):
        _sparrow(task, "wide")


def test_a_piece_too_wide_for_a_sheet_says_sheet():
    with pytest.raises(LayoutError, match=r"^rects: piece .* is 300.0 mm wide, wider than the 400 x 100 mm sheet in "):
        patterns.layout(_rectangles([(300.0, 200.0)]), sheet=(400.0, 100.0), **QUICK)


@pytest.mark.parametrize(("size", "sheet"), [((300.0, 40.0), (300.5, 40.5)), ((40.0, 300.0), (300.5, 40.5))])
def test_a_freely_turning_piece_fits_where_only_one_turn_does(size, sheet):
    """A 300 x 40 mm piece on a sheet it fits only lying one way (turned by 90 degrees, or not at all):
    with rotations="free" it is nested, lying that way."""
    nest = patterns.layout(_rectangles([size]), sheet=sheet, rotations="free", **QUICK)
    x0, y0, x1, y1 = _outlines(nest)[0].bounds
    assert (x1 - x0, y1 - y0) == pytest.approx((40.0, 300.0), abs=1e-3)


def test_the_ends_along_the_strip_are_the_placed_outlines():
    """placement.ends (which pieces lie within a sheet's length) places each outline as Pattern.placed does: a
    turn about the panel's own origin, then the move."""
    from patterns.nesting import _outline
    from patterns.placement import ends as _ends

    pattern = _rectangles([(120.0, 30.0), (80.0, 60.0), (50.0, 50.0)])
    moves = {0: (np.pi / 2, 300.0, 40.0), 1: (np.pi, 100.0, 500.0), 2: (0.3, -20.0, 7.0)}
    laid = pattern.placed([moves[i] for i in range(3)])
    ends = _ends([_outline(piece, 0.0) for piece in patterns.pieces_of(pattern)], moves)
    for i, flat in enumerate(laid.panels):
        assert ends[i] == pytest.approx(flat.uv[:, 1].max(), abs=1e-9)


def test_the_options_record_is_the_keywords(plates):
    a = patterns.layout(plates, NestOptions(width=450.0, time_limit=1))
    b = patterns.layout(plates, width=450.0, time_limit=1)  # the same search: the marker kept from a
    assert [p.placement for p in a.pieces] == [p.placement for p in b.pieces]


@pytest.mark.slow
def test_the_marker_of_issue_22():
    """Four of every panel of the cup, the duct and the hopper (36 pieces) on a 1500 mm roll, 10 mm gap,
    turned by multiples of 90 degrees, the default budget: every gap kept (shapely), every piece on the
    roll.  (How short sparrow gets the marker in its time is a benchmark's number, not a test's:
    ``benchmarks/nesting.py``, docs/benchmarks.md.)"""
    from .conftest import SAMPLES

    parts = [patterns.flatten(patterns.load(SAMPLES / f"{n}.step")) for n in ("cup", "duct_transition", "hopper")]
    nest = patterns.layout(parts, width=1500.0, gap=10.0, copies=4, rotations="quarter")
    assert len(nest.pieces) == 36
    assert len({p.name for p in nest.pieces}) == 36 and all("/" in p.name for p in nest.pieces)  # "cup.step/face0 #2"
    polys = _outlines(nest)
    tree = shapely.STRtree(polys)
    a, b = tree.query(polys, predicate="dwithin", distance=10.0 - 1e-6)
    assert not [(i, j) for i, j in zip(a, b) if i < j]  # no two closer than the gap
    assert shapely.box(0.0, 0.0, 1500.0, nest.length).buffer(1e-3).contains(shapely.union_all(polys))


@pytest.mark.parametrize(("past", "kept"), [(0.0021, True), (0.0099, True), (0.5, False)])
def test_a_piece_the_nester_left_a_hair_past_the_sheet_is_moved_back_onto_it(plates, past, kept):
    """Issue 49: sparrow's single-precision noise left a piece 2.1 µm past a 300 mm sheet and the nest was refused.
    A piece placed ``past`` mm beyond the sheet's right edge: moved back by exactly that (its outline's bounds read
    with shapely land on the edge) and the check passes, up to SNAP (0.01 mm); half a millimetre is refused."""
    from patterns.nesting import SNAP, _laid, _verify

    (piece,) = patterns.pieces.pieces_of(plates)[:1]
    _, y0, x1, y1 = shapely.Polygon(piece.outline.points()).bounds
    sheet = (0.0, 0.0, 400.0, 300.0)
    placement = {0: (0.0, sheet[2] - x1 + past, 20.0 - y0)}  # its right edge `past` beyond the sheet's
    laid, placed = _laid([piece], placement, [sheet], 0.0)
    bounds = shapely.Polygon(laid[0].outline.points()).bounds
    opts = NestOptions(sheet=(300.0, 400.0))
    if kept:
        assert past <= SNAP and bounds[2] == pytest.approx(sheet[2], abs=1e-9)
        assert bounds[3] - bounds[1] == pytest.approx(y1 - y0, abs=1e-9)  # moved, not changed
        _verify("plates", laid, placed, 400.0, opts, [sheet])
    else:
        assert bounds[2] == pytest.approx(sheet[2] + past, abs=1e-9)  # left where it was: refused
        with pytest.raises(LayoutError, match="lies off the roll or sheet"):
            _verify("plates", laid, placed, 400.0, opts, [sheet])


@pytest.mark.slow
def test_a_real_blank_nests_on_a_sheet_for_every_seed_and_copy_count():
    """Issue 49: no feasible nest refused for its seed: the bracket's blank, 1 to 12 copies on a sheet with room
    for them, seeds 0 to 9, each nest read back with shapely (on the sheet, apart by the gap)."""
    blank = patterns.unfold(SAMPLES / "bracket.step")
    w, h = blank.size
    for copies in (1, 12):  # the ends of 1 to 12 (CI's time: two counts, ten seeds each)
        for seed in range(10):
            nest = patterns.layout(blank, sheet=(4 * (max(w, h) + 20), 3 * (max(w, h) + 20)), copies=copies,
                                   seed=seed, gap=5.0, rotations="free", **QUICK)
            outlines = _outlines(nest)
            assert len(outlines) == copies
            room = shapely.union_all([shapely.box(*r) for r in nest.stock]).buffer(1e-6)
            assert all(room.contains(o) for o in outlines), (copies, seed)
            assert copies == 1 or _min_distance(outlines) >= 5.0 - 1e-6, (copies, seed)


@pytest.mark.parametrize("sheet", [(600.0, 400.0), (3000.0, 3000.0), (1e7, 1e7)])
def test_a_small_blank_nests_on_any_sheet_up_to_the_documented_largest(sheet):
    """Issue 49: a 40 x 98 mm blank on a 3000 mm sheet (and on the documented largest, 1e7 mm) stopped sparrow
    ("Offset resulted in an empty polygon", "no pole found": its first strip was the pieces' area over the width,
    1.3 mm long). Each nest read back: on its sheet, its pieces apart by the gap."""
    blank = patterns.unfold(SAMPLES / "bracket.step")
    nest = patterns.layout(blank, sheet=sheet, copies=3, gap=5.0, **QUICK)
    outlines = _outlines(nest)
    assert len(nest.sheets) == 1 and len(outlines) == 3
    room = shapely.box(*nest.stock[0]).buffer(1e-6)
    assert all(room.contains(o) for o in outlines) and _min_distance(outlines) >= 5.0 - 1e-6


def test_each_sheet_says_what_a_shop_quotes_it_from(tmp_path, capsys):
    """Issue 49: a 100 x 50 mm plate with a 10 mm hole cuts 300 + 10 pi mm in 2 pierces (by hand); four of them on
    one sheet: four times that, 8 pierces, no bends; usage their area over the sheet's. From the JSON report read
    back, and the command line's line for the sheet."""
    import math

    step = tmp_path / "plate.step"
    bd.export_step(bd.Box(100, 50, 2) - bd.Cylinder(5, 2), str(step))
    blank = patterns.unfold(step)
    nest = patterns.layout(blank, sheet=(400.0, 300.0), copies=4, gap=5.0, **QUICK)
    patterns.write(nest, tmp_path / "nest.json")
    (sheet,) = json.loads((tmp_path / "nest.json").read_text())["sheets"]
    one = 300.0 + 10.0 * math.pi
    assert sheet["cut_length_mm"] == pytest.approx(4 * one, abs=1e-3)
    assert sheet["pierces"] == 8 and sheet["bends"] == 0 and len(sheet["pieces"]) == 4
    assert sheet["size_mm"] == [400.0, 300.0]
    assert sheet["usage"] == pytest.approx(4 * (100 * 50 - math.pi * 25) / (400 * 300), abs=1e-6)
    from patterns.cli import main

    assert main(["unfold", str(step), "-o", str(tmp_path / "p.dxf"), "--sheet", "400x300", "--copies",
                              "4", "--nest-time", "1", "--no-nest-cache"]) == 0
    out = capsys.readouterr().out
    assert f"sheet 1 (400 x 300 mm): 4 pieces, usage {sheet['usage']:.1%}, cut {4 * one:.1f} mm, 8 pierces, 0 bends" \
        in out


def test_sheet_files_write_each_sheet_alone(tmp_path, capsys):
    """``--sheet-files``: the nest's DXF and one per sheet beside it, each read back: its CUT outlines are the
    pieces the report puts on that sheet, all inside its STOCK rectangle; every piece on exactly one sheet."""
    from patterns.cli import main

    out = tmp_path / "b.dxf"
    assert main(["unfold", str(SAMPLES / "bracket.step"), "-o", str(out), "--sheet", "200x100", "--copies", "5",
                 "--nest-time", "1", "--no-nest-cache", "--sheet-files", "--report", str(tmp_path / "b.json")]) == 0
    sheets = json.loads((tmp_path / "b.json").read_text())["sheets"]
    assert len(sheets) >= 2 and sum(len(s["pieces"]) for s in sheets) == 5
    for k, sheet in enumerate(sheets, start=1):
        doc = ezdxf.readfile(tmp_path / f"b-{k}.dxf")
        cuts = [shapely.Polygon([p[:2] for p in e.get_points("xy")])
                for e in doc.modelspace().query("LWPOLYLINE[layer=='CUT']")]
        (stock,) = [shapely.Polygon([p[:2] for p in e.get_points("xy")])
                    for e in doc.modelspace().query("LWPOLYLINE[layer=='STOCK']")]
        assert len(cuts) == len(sheet["pieces"]) and all(stock.buffer(1e-6).contains(c) for c in cuts)
        assert sorted(stock.bounds[2:]) == pytest.approx(sorted(np.array(stock.bounds[:2]) + [200, 100]))
    assert not (tmp_path / f"b-{len(sheets) + 1}.dxf").exists()
    capsys.readouterr()
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "bracket.step").write_bytes((SAMPLES / "bracket.step").read_bytes())
    assert main(["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), "--sheet-files"]) == 2
    assert "not to a batch" in capsys.readouterr().err


def test_small_pieces_go_into_the_holes_of_big_ones():
    """Issue 49: a 200 x 200 mm frame with a 150 x 150 mm window and four 60 x 60 mm squares go on one 220 x 220 mm
    sheet (the squares fit only in the window), not two; read back with shapely: every square inside the window,
    everything apart by the gap, on the sheet."""
    frame = bd.Box(200, 200, 2) - bd.Box(150, 150, 2)
    squares = [patterns.unfold(bd.Box(60, 60, 2), name=f"square{k}") for k in range(4)]
    nest = patterns.layout([patterns.unfold(frame, name="frame"), *squares], sheet=(220.0, 220.0), gap=5.0,
                           rotations="none", **QUICK)
    assert len(nest.sheets) == 1 and len(nest.sheets[0].pieces) == 5
    pieces = {p.name: p for p in nest.pieces}
    (host,) = [p for p in pieces.values() if p.holes]
    window = shapely.Polygon(host.holes[0].points())
    guests = [shapely.Polygon(p.outline.points()) for p in pieces.values() if p is not host]
    assert all(window.buffer(-5.0 + 1e-6).contains(g) for g in guests)
    assert _min_distance(guests) >= 5.0 - 1e-6
    sheet = shapely.box(*nest.stock[0]).buffer(1e-6)
    assert sheet.contains(shapely.Polygon(host.outline.points()))


def test_the_last_sheet_is_the_smallest_size_that_takes_what_is_left():
    """Issue 49, remnants: with stock of several sizes the sheet that takes every piece left is the smallest
    such: one 50 x 50 mm square goes on the 200 x 150 remnant, not on the 2000 x 1000 sheet given first; a
    300 mm-wide piece that fits only the big sheet goes there (with the square: one sheet, not two)."""
    nest = patterns.layout(_rectangles([(50.0, 50.0)]), sheet=[(2000.0, 1000.0), (200.0, 150.0)], **QUICK)
    assert [s.size for s in nest.sheets] == [(200.0, 150.0)]
    assert nest.sheets[0].usage == pytest.approx(50.0 * 50.0 / (200.0 * 150.0), rel=1e-9)
    assert nest.area_used == 200.0 * 150.0 and nest.length == 200.0 and nest.width == 150.0
    assert str(nest).startswith("1 sheet of 200 x 150 mm, usage 8.3%")
    both = patterns.layout(_rectangles([(300.0, 100.0), (50.0, 50.0)]), sheet=[(200.0, 150.0), (2000.0, 1000.0)],
                           **QUICK)
    assert [s.size for s in both.sheets] == [(2000.0, 1000.0)] and len(both.sheets[0].pieces) == 2


def test_sheets_on_hand_are_counted_and_each_piece_lies_on_its_own_sheet(tmp_path):
    """Two 200 x 150 mm remnants on hand, two 120 x 120 mm squares (one a sheet: 120 + gap + 120 > 150 and > 200):
    both remnants used, each square inside its own sheet's rectangle read back from the DXF; three squares
    do not fit the two remnants, five are refused before any search (their area alone is larger); four on one
    remnant and full sheets bought as needed go onto a 400 x 300 sheet too (the report and the drawing say
    each sheet's size)."""
    squares = _rectangles([(120.0, 120.0)])
    nest = patterns.layout(squares, sheet=[(200.0, 150.0, 2)], copies=2, **QUICK)
    assert [s.size for s in nest.sheets] == [(200.0, 150.0)] * 2
    assert str(nest) == "2 sheets of 200 x 150 mm, usage 48.0%, 48.0% (48.0% in all)"
    patterns.write(nest, tmp_path / "nest.dxf")
    doc = ezdxf.readfile(tmp_path / "nest.dxf")
    cuts = [shapely.Polygon([p[:2] for p in e.get_points("xy")])
            for e in doc.modelspace().query("LWPOLYLINE[layer=='CUT']")]
    stock = [shapely.Polygon([p[:2] for p in e.get_points("xy")])
             for e in doc.modelspace().query("LWPOLYLINE[layer=='STOCK']")]
    assert len(cuts) == 2 and len(stock) == 2
    assert sorted(sorted(np.subtract(s.bounds[2:], s.bounds[:2]).round(6)) for s in stock) == [[150, 200]] * 2
    assert all(sum(s.buffer(1e-6).contains(c) for s in stock) == 1 for c in cuts)
    assert len({max(range(2), key=lambda k: stock[k].intersection(c).area) for c in cuts}) == 2
    with pytest.raises(LayoutError, match=r"the sheets on hand \(200 x 150 mm \(2 on hand\)\) run out with 1 piece "):
        patterns.layout(squares, sheet=[(200.0, 150.0, 2)], copies=3, **QUICK)
    with pytest.raises(LayoutError, match=r"the sheets on hand \(200 x 150 mm \(2 on hand\)\) are smaller in all"):
        patterns.layout(squares, sheet=[(200.0, 150.0, 2)], copies=5, time_limit=60, cache=False)  # no search: at once
    mixed = patterns.layout(squares, sheet=[(200.0, 150.0, 1), (400.0, 300.0)], copies=4, **QUICK)
    assert sum(len(s.pieces) for s in mixed.sheets) == 4
    assert sum(s.size == (200.0, 150.0) for s in mixed.sheets) <= 1
    assert mixed.area_used == pytest.approx(sum(a * b for a, b in (s.size for s in mixed.sheets)), rel=1e-12)
    for sheet, (x0, y0, x1, y1) in zip(mixed.sheets, mixed.stock):
        assert (y1 - y0, x1 - x0) == sheet.size


@pytest.mark.parametrize(("value", "words"), [
    ([(400.0, 300.0), (200.0, 150.0, 0)], "sheet[1] sheets on hand must be an integer between 1 and"),
    ([(400.0, 300.0), (400.0, 300.0, 2)], "sheet names a size twice"),
    ([(400.0, 300.0), (200.0,)], "sheet[1] must be (length, width) in mm, or (length, width, sheets on hand)"),
    ([(400.0, 300.0), (1e8, 150.0)], "sheet[1] length (mm) must be")])
def test_sheets_on_hand_are_checked(value, words):
    with pytest.raises(InputError, match=re.escape(words)):
        NestOptions(sheet=value)


def test_sheets_on_hand_on_the_command_line(tmp_path, capsys):
    """``--sheet 400x300,200x150:1``: parsed to the sizes and the count, each sheet's line names its size."""
    from patterns.cli import main
    from patterns.stock import parse_sheet

    assert parse_sheet("2500x1250,1200x800:2") == ((2500.0, 1250.0), (1200.0, 800.0, 2))
    step = tmp_path / "plate.step"
    bd.export_step(bd.Box(100, 50, 2), str(step))
    assert main(["unfold", str(step), "-o", str(tmp_path / "p.dxf"), "--sheet", "2000x1000,200x150:1",
                 "--nest-time", "1", "--no-nest-cache"]) == 0
    assert "sheet 1 (200 x 150 mm): 1 pieces" in capsys.readouterr().out
    assert main(["unfold", str(step), "-o", str(tmp_path / "q.dxf"), "--sheet", "2000x1000,200x150:x"]) == 2
    assert "--sheet" in capsys.readouterr().err and not (tmp_path / "q.dxf").exists()
