"""The sheet-metal torture set: real STEP parts from public repositories (``tests/data/torture``).

Every part either unfolds or is refused with one ``patterns`` error naming the file and the cause, on
one line.  The references are independent of the unfolder: the flat patterns Fusion 360 drew for the
same parts (DXF files in the source repository, read back with ezdxf), the plate face's area and its
holes for a flat plate (build123d), the solid's volume over the thickness (the blank's area at
K = 0.5: the mid-surface), and the bend lines Fusion drew on its ``BEND`` layer.  Provenance and
licence: docs/sheet-metal.md ("Torture set") and the folder's PROVENANCE.md (both licences permit keeping the
files here, with their texts); ``make_torture.py`` there rebuilds the folder from the two source repositories.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import build123d as bd
import ezdxf
import numpy as np
import pytest

import patterns
from patterns.cli import main
from patterns.errors import InputError

DATA = Path(__file__).resolve().parent / "data" / "torture"
with open(DATA / "parts.csv", newline="") as _f:
    ROWS = {row["part"]: row for row in csv.DictReader(_f)}
K = 0.44
"""The K-factor of the Fusion 360 parts' own flat patterns (Fusion 360's default), as parts.csv gives it."""

FUSION = ["l4d_bracket_left", "l4d_chamber_bracket", "l4d_chamber_left", "l4d_chamber_top", "l4d_compartment_right",
          "l4d_corner_bracket", "l4d_labyrinth", "l4d_lid_channel", "l4d_corner_bracket_inch"]
"""Parts whose flat pattern Fusion 360 drew in the source repository (same design revision)."""
PLATES = ["l4d_flat_plate", "l4d_flat_strip", "l4d_thick_plate"]
BY_VOLUME = ["l4d_angle", "l4d_compartment_left", "l4d_mainsheet"]
"""Parts with no flat pattern of the same revision: their blank at K = 0.5 against volume / thickness."""
REFUSED = {  # part: (error, the cause its message names)
    "absaug_anschluss": (InputError, "a closed tube"),
    "l4d_solid_block": (InputError, "not a sheet"),
    # OpenAMR's SolidWorks 2017 parts that are not sheet metal: turned, machined or moulded solids
    "amr_drive_shaft": (InputError, "not a sheet: face"),
    "amr_pt1_adapter": (InputError, "not a sheet: face"),
    "amr_pt1_bracket": (InputError, "not a sheet: face"),
    "amr_pt1_camera_body": (InputError, "not a sheet: face"),
    "amr_pt1_cover": (InputError, "not a sheet: face"),
}
IMPORTED = ["l4d_corner_bracket_nurbs", "l4d_corner_bracket_spline_bend", "l4d_two_corner_brackets"]
"""Parts as other exporters write them: every face a B-spline, only the bends B-splines, two solids in one file."""
DOUBLY_CURVED = ["amr_plastic_cover"]
"""A formed shell of constant thickness whose corners are spheres and tori: it has no flat pattern."""


def _fusion(part: str) -> Path:
    return DATA / ROWS[part]["reference"]


def test_every_part_is_listed_with_its_licence_and_outcome():
    steps = sorted(p.stem for p in DATA.glob("*.step"))
    assert steps == sorted(ROWS)
    listed = (set(FUSION) | set(PLATES) | {"l4d_angle", "l4d_compartment_left", "l4d_mainsheet"} | set(REFUSED)
              | set(IMPORTED) | set(DOUBLY_CURVED))
    assert listed == set(ROWS)
    provenance = (DATA / "PROVENANCE.md").read_text()
    assert all(f"`{part}.step`" in provenance for part in ROWS)
    assert "CERN-OHL-P" in provenance and (DATA / "LICENSE-CERN-OHL-P-2.0.txt").is_file()
    assert "**MIT**" in provenance and "MIT License" in (DATA / "LICENSE-OpenAMR-MIT.txt").read_text()
    assert sum(p.stat().st_size for p in DATA.rglob("*")) < 5e6
    assert all(p.stat().st_size < 1e6 for p in DATA.glob("*.step"))


@pytest.mark.parametrize("part", FUSION)
def test_blank_matches_fusion_360_flat_pattern(part):
    """Area within 0.01 %, the same holes, and one bend per line on Fusion's BEND layer."""
    blank = patterns.unfold(DATA / f"{part}.step", k_factor=float(ROWS[part]["k_factor"]))
    reference = patterns.read_flat_pattern(_fusion(part))
    bend_lines = ezdxf.readfile(_fusion(part)).modelspace().query('LINE[layer=="BEND"]')
    assert blank.ok
    assert blank.area == pytest.approx(reference.area, rel=1e-4)
    assert len(blank.holes) == len(reference.holes)
    assert len(blank.bends) == len(bend_lines)
    assert blank.thickness == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("part", PLATES)
def test_flat_plate_blank_is_its_face(part):
    """A flat plate unfolds to its largest face: the same area, a hole for each inner wire, no bend."""
    solid = bd.import_step(DATA / f"{part}.step")
    face = max(solid.faces(), key=lambda f: f.area)
    blank = patterns.unfold(DATA / f"{part}.step", k_factor=K)
    assert blank.ok and blank.bends == ()
    assert blank.area == pytest.approx(face.area, rel=1e-6)
    assert len(blank.holes) == len(face.inner_wires())
    assert blank.thickness == pytest.approx(solid.volume / face.area, rel=1e-6)


@pytest.mark.parametrize("part", BY_VOLUME)
def test_blank_area_is_volume_over_thickness(part):
    """At K = 0.5 the blank is the mid-surface: its area is the solid's volume over the thickness."""
    blank = patterns.unfold(DATA / f"{part}.step", k_factor=0.5)
    volume = bd.import_step(DATA / f"{part}.step").volume
    assert blank.ok and blank.bends
    assert blank.area == pytest.approx(volume / blank.thickness, rel=1e-4)


@pytest.mark.parametrize("part", sorted(REFUSED))
def test_refused_with_one_line_naming_file_and_cause(part):
    error, cause = REFUSED[part]
    with pytest.raises(error) as info:
        patterns.unfold(DATA / f"{part}.step", k_factor=float(ROWS[part]["k_factor"]))
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{part}: ") and cause in message


@pytest.mark.parametrize("part", DOUBLY_CURVED)
def test_formed_shell_is_of_constant_thickness_and_doubly_curved(part):
    """The evidence against the message below, from build123d alone: every cylinder and sphere of the cover
    has a partner 3 mm larger (the two skins of one 3 mm sheet), the solid's volume is its surface over two
    times 3 mm (within 1.5 %: the rims add surface, no volume), and it has spheres and tori (doubly curved)."""
    solid = bd.import_step(DATA / f"{part}.step")
    radii = {}
    for face in solid.faces():
        kind = face.geom_type
        if kind in (bd.GeomType.CYLINDER, bd.GeomType.SPHERE):
            surface = face.geom_adaptor()
            r = surface.Cylinder().Radius() if kind == bd.GeomType.CYLINDER else surface.Sphere().Radius()
            radii.setdefault(kind, set()).add(round(r, 6))
    assert radii[bd.GeomType.SPHERE] == {17.0, 20.0}
    assert {17.0, 20.0} <= radii[bd.GeomType.CYLINDER]
    assert any(face.geom_type == bd.GeomType.TORUS for face in solid.faces())
    assert solid.volume / (solid.area / 2) == pytest.approx(3.0, rel=0.015)


@pytest.mark.parametrize("part", DOUBLY_CURVED)
def test_formed_shell_is_refused_naming_its_doubly_curved_faces(part):
    with pytest.raises(InputError) as info:
        patterns.unfold(DATA / f"{part}.step", k_factor=float(ROWS[part]["k_factor"]))
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{part}: ") and "doubly curved" in message


@pytest.mark.parametrize("part", IMPORTED)
def test_imported_parts_unfold_as_exactly_as_the_original_or_are_refused_by_name(part):
    """B-spline faces that are planes and cylinders are rebuilt on them (patterns.sheetmetal.imported): the
    bracket unfolds with its bend line to Fusion's area; two solids are refused naming the count."""
    if part == "l4d_two_corner_brackets":
        with pytest.raises(InputError, match=r"l4d_two_corner_brackets: .*2 solids"):
            patterns.unfold(DATA / f"{part}.step", k_factor=K)
        return
    blank = patterns.unfold(DATA / f"{part}.step", k_factor=K)
    assert blank.ok and len(blank.bends) == 1
    assert blank.area == pytest.approx(patterns.read_flat_pattern(_fusion(part)).area, rel=1e-4)


@pytest.mark.parametrize("part", ["l4d_corner_bracket", "absaug_anschluss", "l4d_solid_block", "amr_pt1_bracket"])
def test_cli_exit_code_message_and_output(part, tmp_path, capsys):
    """``patterns unfold PART -o x.dxf``: 0 and the DXF written when it unfolds; 2, one line and nothing
    written when refused."""
    out = tmp_path / "x.dxf"
    code = main(["unfold", str(DATA / f"{part}.step"), "-o", str(out), "--k-factor", ROWS[part]["k_factor"]])
    err = capsys.readouterr().err
    if part in REFUSED:
        assert code == 2 and list(tmp_path.iterdir()) == []
        assert err.count("\n") == 1 and err.startswith(f"patterns: error: {part}: ") and REFUSED[part][1] in err
    else:
        assert code == 0 and err == ""
        assert patterns.read_flat_pattern(out).area == pytest.approx(patterns.read_flat_pattern(_fusion(part)).area,
                                                                     rel=1e-4)


# --------------------------------------------------------------------------- #
# Parts made in another CAD: FreeCAD's SheetMetal workbench (tests/data/torture/freecad)
# --------------------------------------------------------------------------- #

FREECAD_DATA = DATA / "freecad"
with open(FREECAD_DATA / "parts.json") as _f:
    FREECAD_PARTS = json.load(_f)


@pytest.mark.parametrize("part", sorted(FREECAD_PARTS["parts"]))
def test_a_part_made_in_freecad_sheetmetal_matches_its_own_unfold(part):
    """Parts a FreeCAD user makes with the SheetMetal workbench's own features (base wall, walls, corner relief),
    written by FreeCAD's STEP writer: our blank at the workbench's K-factor (0.4, ANSI) against the workbench's
    own flat pattern, its DXF read back (coordinates to 6 significant digits: 3e-6 of the area) and the area of
    its unfolded solid as FreeCAD measured it (``parts.json``); the holes and bend lines it drew."""
    spec = FREECAD_PARTS["parts"][part]
    assert FREECAD_PARTS["k_factor_standard"] == "ansi"
    blank = patterns.unfold(FREECAD_DATA / f"{part}.step", k_factor=FREECAD_PARTS["k_factor"])
    theirs = patterns.read_flat_pattern(FREECAD_DATA / f"{part}.dxf")
    assert blank.area == pytest.approx(spec["flat_area"], rel=2e-6)  # FreeCAD's unfolded solid (its tray's arcs)
    assert blank.area == pytest.approx(theirs.area, rel=1e-5)  # FreeCAD's DXF, 6 digits
    k, t = FREECAD_PARTS["k_factor"], spec["t"]
    holes = sum(np.pi * r * r for _, _, r in spec["holes"])
    (x, y), (wall,) = spec["base"], spec["walls"]
    allowance = np.pi / 2 * (wall["r"] + k * t)  # a quarter turn of the neutral layer; a wall's leg starts past it
    by_hand = {  # the base, the bends and the legs ("Material Outside": the base keeps its size), less the cuts
        "fc_l_bracket": (x + allowance + wall["leg"]) * y - holes,
        "fc_u_channel": (y + 2 * (allowance + wall["leg"])) * x - holes,
        "fc_relief_flange": x * y + (allowance + wall["leg"]) * (y - wall.get("gap1", 0) - wall.get("gap2", 0))
        - holes - 2 * np.prod(wall.get("relief", [0, 0, 0])[1:]),  # two rectangular bend reliefs, 2 x 4
    }
    if part in by_hand:
        assert blank.area == pytest.approx(by_hand[part], rel=1e-9)
    assert len(blank.bends) == len(theirs.bend_lines) == spec["sketch_edges"]["Unfold_Sketch_Bends"]
    assert len(blank.holes) == len(spec["holes"])
    assert blank.ok
    provenance = (FREECAD_DATA / "PROVENANCE.md").read_text()
    assert f"`{part}" in provenance and "cbef3f2" in provenance
