"""The Patterns workbench in a real FreeCAD: installed by ``patterns freecad install`` into a temporary user
folder, exactly as a user installs it, the engine beside FreeCAD in its own process.

Run in ``freecadcmd`` (FreeCAD 0.20, the system's Python and numpy) through ``tests/readers/freecad_api_run.py``
and in the GUI under Xvfb through ``freecad_gui_run.py``.  References: the API in this interpreter on the same
part (written by FreeCAD as STEP), analytic areas, SolidWorks' flat patterns, the files read back, the
engine's own count of computations, and FreeCAD's own MeshPart ``flatmesh`` run in the same process.
Skipped where FreeCAD is absent (``.ci/run`` installs it: there they must run).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely

import patterns
from patterns.cli import main

pytestmark = pytest.mark.slow  # the real FreeCAD, started per test: run by .ci/run (pytest -m slow), not the quick suite

REPO = Path(__file__).resolve().parent.parent
READERS = Path(__file__).resolve().parent / "readers"
SHEETMETAL = REPO.parent / "shared" / "sheetmetal"
PARTS = {"MMP.00.00.00.002_Back_panel": (79828.8, 15), "MMP.01.00.00.001_Cover": (383025.3, 15),
         "MMP.03.00.00.001_Wheel_bracket_outer": (38289.7, 22), "MMP.05.00.00.001_Support": (16902.6, 12)}


def _need_freecad():
    if shutil.which("freecadcmd") is None:
        from .test_dxf_pattern import _installed_by_ci

        if "freecad" in _installed_by_ci():
            pytest.fail("freecadcmd is missing although .ci/run installed FreeCAD")
        pytest.skip("FreeCAD is not installed (.ci/run installs it with apt-get)")


def installed(tmp_path) -> Path:
    """FreeCAD's user folder with the workbench put in by the command a user runs."""
    user = tmp_path / "freecad-user"
    proc = subprocess.run([sys.executable, "-m", "patterns", "freecad", "install", "--user-dir", str(user)],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    assert (user / "Mod" / "patterns" / "engine.json").is_file()
    return user


def freecad_env(user: Path, **extra) -> dict:
    env = dict(os.environ, FREECAD_USER_HOME=str(user), ENGINE_PREFIX=sys.prefix, QT_QPA_PLATFORM="offscreen",
               **extra)
    for name in ("PATTERNS_ENGINE", "PYTHONPATH", "PATTERNS_SITE"):
        env.pop(name, None)
    return env


def _run(scenario: str, tmp_path, **args) -> dict:
    """One scenario of ``freecad_api_run.py`` in freecadcmd: its RESULT, after the checks every scenario
    shares: nothing of the engine's environment in FreeCAD's process, FreeCAD's own numpy and Unwrap Mesh."""
    _need_freecad()
    env = freecad_env(installed(tmp_path), SCENARIO=scenario, ARGS=json.dumps(args))
    proc = subprocess.run(["freecadcmd", str(READERS / "freecad_api_run.py")], capture_output=True, text=True, env=env,
                          timeout=900, check=False, cwd=tmp_path)
    lines = [x for x in proc.stdout.splitlines() if "RESULT " in x]
    assert lines, proc.stdout[-3000:] + proc.stderr[-3000:]
    result = json.loads(lines[-1].split("RESULT ", 1)[1])
    assert "traceback" not in result, result.get("traceback")
    assert result["foreign"] == [] and result["patterns_loaded"] == []
    assert not result["flatmesh"]["numpy"].startswith("2.") and result["flatmesh"]["nodes"] > 0
    assert not result["flatmesh"]["numpy_file"].startswith(sys.prefix)
    return result


def test_a_cut_flattens_in_its_document_and_grows_with_its_box(tmp_path):
    """``make_pattern`` of a Part::Cut (a 200 x 100 x 50 box less an R20 cylinder at its corner): a flat face
    per CAD face at z = 0, each the area of the API's panel of the same part (FreeCAD's STEP of it, read by
    this interpreter), the planar and cylindrical ones their exact areas; one engine computation to make it,
    none to move it, one when the box is made 250 long, and the pieces grow by 2 x 50 x 100 + 2 x 50 x 50."""
    result = _run("box_minus_cylinder", tmp_path, step=str(tmp_path / "cut.step"))
    api = patterns.flatten(patterns.load(tmp_path / "cut.step"))
    assert result["areas"] == pytest.approx(sorted(p.area for p in api.panels), abs=0.01)
    for exact in (4000.0, 5000.0, 9000.0, 10000.0, np.pi / 2 * 20 * 50):
        assert min(abs(a - exact) for a in result["areas"]) < 1e-6
    assert sum(result["after"]) - sum(result["areas"]) == pytest.approx(15000.0, abs=1e-6)
    assert result["computed"] == [1, 1, 2]
    assert result["z"] == 0.0 and result["ok"] and result["pieces"] == 7
    assert result["face_strain"] == [0.0] * 7  # every face an exact development
    moved, marks_moved = result["moved"], result["marks_moved"]  # moved 450 mm down, and its marks with it
    gap, level = result["beside"]  # laid beside the cut, to its +X side, level with its lowest point
    assert gap > 0 and level == pytest.approx(0, abs=1e-9)
    assert moved[1] == pytest.approx(result["laid"] - 450, abs=1e-9)
    assert moved[0] <= marks_moved[0] and moved[1] <= marks_moved[1]
    assert marks_moved[2] <= moved[2] and marks_moved[3] <= moved[3]
    marks = result["marks"]
    assert set(marks) == {"sew", "notch", "grain", "drill", "bend", "label"}
    assert marks["grain"][0] == 7 and marks["sew"][0] == 0  # no allowance: no sew line
    assert "face0" in marks["label"][2] and marks["label"][1] == len(marks["label"][2])
    assert "Cut: ok (7 panels" in result["report"]


def test_a_bad_option_is_refused_before_anything_is_added(tmp_path):
    result = _run("bad_option", tmp_path)
    assert "seam_allowance (mm) must be a number between 0 and 1000, got -3" in result["seam_allowance"]
    assert "unknown option 'no_such_option'" in result["no_such_option"]
    assert result["objects"] == ["Box", "Cylinder", "Cut"]
    assert result["text_number"] == 5.0


def test_a_failed_create_leaves_nothing_in_the_document(tmp_path):
    result = _run("failed_create", tmp_path)
    assert result["error"] and "Edge" in result["error"]
    assert result["objects"] == ["Edge"]


@pytest.mark.slow
def test_the_shared_parts_unfold_in_the_document_as_the_api_unfolds_them(tmp_path):
    """``make_blank`` of the four OpenAMR parts read into a document: one face per blank, of the API's blank's
    area (and so SolidWorks' within 0.05 %), its holes, its bend lines beside it as edges."""
    if not SHEETMETAL.is_dir():
        pytest.skip(f"{SHEETMETAL} is absent (the shared sheet-metal parts sit beside the repository in CI)")
    for part, (area, holes) in PARTS.items():
        result = _run("blank_of", tmp_path, path=str(SHEETMETAL / f"{part}.STEP"), k_factor=0.47)
        blank = patterns.unfold(SHEETMETAL / f"{part}.STEP", k_factor=0.47)
        assert result["faces"] == 1 and result["holes"] == holes == len(blank.holes)
        assert result["area"] == pytest.approx(blank.area, rel=1e-6)
        assert abs(result["area"] - area) <= 0.0005 * area
        assert result["bend_edges"] == len(blank.bends) and result["ok"]
        assert set(result["marks"]) == {"bend_up", "bend_down", "bend", "label"}
        for way in ("up", "down"):  # each bend's line among the marks of its own way (issue 53: down ones dropped)
            assert result["mark_edges"][f"bend_{way}"] == sum(b.direction == way for b in blank.bends), (part, way)


def test_a_selected_face_of_a_bent_part_is_its_fixed_face(tmp_path):
    """Unfold with one face selected (FreeCAD SheetMetal's habit): the whole solid unfolds, that face fixed --
    FreeCAD's 1-based ``Face2`` is the API's ``fixed_face=1``; the same blank as the API's."""
    step = REPO / "samples" / "bracket.step"
    result = _run("blank_of", tmp_path, path=str(step), k_factor=0.44, face="Face2")
    blank = patterns.unfold(step, k_factor=0.44, fixed_face=1)
    assert result["source"] == [] and result["fixed_face"] == "Face2"
    assert result["faces"] == 1 and result["area"] == pytest.approx(blank.area, rel=1e-9)
    assert result["bend_edges"] == len(blank.bends) == 1


def _entities(path):
    doc = ezdxf.readfile(path)
    cut = sorted(shapely.Polygon(np.array(e.get_points("xy"))).area for e in doc.modelspace().query("LWPOLYLINE[layer=='CUT']"))
    counts = {}
    for e in doc.modelspace():
        counts[(e.dxftype(), e.dxf.layer)] = counts.get((e.dxftype(), e.dxf.layer), 0) + 1
    return cut, counts


def test_export_from_the_document_writes_what_the_command_line_writes(tmp_path):
    """The pattern's pieces exported from the document (the engine's writers, no second computation) against
    ``patterns flatten`` of the same part (FreeCAD's STEP of it) with the same options: the same entities on
    the same layers, the cut lines at the same areas; the SVG and the JSON report written too."""
    result = _run("export_all", tmp_path, path=str(tmp_path / "doc"), step=str(tmp_path / "cut.step"),
                  options={"seam_allowance": 5.0, "notch_spacing": 40.0})
    assert main(["flatten", str(tmp_path / "cut.step"), "-o", str(tmp_path / "cli.dxf"), "--seam-allowance", "5",
                 "--notch-spacing", "40"]) == 0
    ours, theirs = _entities(tmp_path / "doc.dxf"), _entities(tmp_path / "cli.dxf")
    assert ours[0] == pytest.approx(theirs[0], rel=1e-9)
    assert ours[1] == theirs[1]
    report = json.loads((tmp_path / "doc.json").read_text())
    assert report["ok"] and len(report["pieces"]) == 7 and result["report_ok"]
    assert (tmp_path / "doc.svg").read_text().startswith("<?xml")
    assert result["computed"] == [1, 1]


def test_the_hemisphere_cup_is_not_ok_against_the_limit_it_was_given(tmp_path):
    """A hemisphere against a 5 % limit: NOT ok, and the figures are the API's report of the same shape
    (FreeCAD's STEP of it) with the same limit: worst strain, the share above the limit."""
    result = _run("cup", tmp_path, limit=0.05)
    assert result["ok"] is False and "NOT ok" in result["report"]
    figures = result["figures"]
    assert figures["max_strain"] == 0.05 and figures["strain_max"] > 0.05
    assert 0 < figures["share_above_limit"] <= 1
    assert max(result["face_strain"]) == pytest.approx(figures["strain_max"], rel=1e-12)


def test_a_killed_worker_is_started_again_and_the_next_recompute_works(tmp_path):
    result = _run("killed_worker", tmp_path)
    assert result["valid"] and result["starts"] == 2 and result["pids"][0] != result["pids"][1]
    # the 250 x 100 x 50 box less the R20 quarter cylinder: 2 (25000 - 100 pi) + 230 x 50 + 250 x 50 + 80 x 50
    # + 100 x 50 + 500 pi (the arcs' pieces drawn as the flattener's fitted arcs: within 1e-4)
    assert sum(result["areas"]) == pytest.approx(83000 + 300 * np.pi, rel=1e-4)


def test_a_saved_document_reopens_without_computing_and_its_marks_recompute_alone(tmp_path):
    result = _run("reopened", tmp_path, path=str(tmp_path / "saved.FCStd"))
    assert result["valid"]
    assert result["areas"][0] == result["areas"][1]
    assert result["quiet"]  # reopened and recomputed: no engine started, nothing computed
    assert result["computed"] == 1  # the box changed: once (by the engine started for it)
    assert result["sew"][0] > 0 and result["sew"][1] == result["sew"][0] and result["sew_after"] > 0


def test_a_seam_allowance_set_later_adds_the_sew_lines(tmp_path):
    result = _run("allowance_later", tmp_path)
    assert "sew" in result["before"] and result["after"] == result["before"]
    assert result["sew_edges"] > 0
    valid, ok, report = result["bad_later"]  # then made bad: the recompute fails and says why
    assert not valid and not ok and report.startswith("recompute failed: Cut: seam_allowance (mm) must be")


def test_without_an_engine_one_error_says_what_to_run_and_it_works_once_there(tmp_path):
    result = _run("engine_missing", tmp_path)
    assert "patterns freecad install" in result["error"] and "pip install" in result["error"]
    assert "Traceback" not in result["error"]
    assert result["objects"] == ["Box", "Cylinder", "Cut"]
    assert result["then"] == 7


def test_the_package_file_names_the_workbench_and_declares_nothing_it_does_not_import():
    import xml.etree.ElementTree as ET

    addon = REPO / "patterns" / "hosts" / "freecad_addon"
    root = ET.parse(addon / "package.xml").getroot()
    ns = {"p": "https://wiki.freecad.org/Package_Metadata"}
    (workbench,) = root.findall("p:content/p:workbench", ns)
    assert workbench.find("p:classname", ns).text == "PatternsWorkbench"
    assert (addon / "freecad" / "patterns_wb" / "init_gui.py").is_file()
    assert not (addon / "freecad" / "__init__.py").exists()  # a namespace package: FreeCAD's own owns it
    for icon in root.iter("{https://wiki.freecad.org/Package_Metadata}icon"):
        assert (addon / icon.text).is_file()
    assert [d for d in root.iter("{https://wiki.freecad.org/Package_Metadata}depend") if d.get("type") == "python"] == []
    assert root.find("p:version", ns).text == patterns.__version__
    assert "example.invalid" not in (addon / "package.xml").read_text()


def test_the_workbench_in_the_gui(tmp_path):
    """FreeCAD's GUI under Xvfb, the workbench installed as a user installs it: listed, activated while its
    engine cannot start (one dialog saying what to run), then given it (no restart); four commands; Flatten's panel fits the screen and OK makes one engine computation; moving
    the pattern makes none; double-click opens the options; Check shows the figures; the strain overlay
    switches on and off and gives the part its own colours back, also when the pattern is deleted;
    FreeCAD's own Unwrap Mesh afterwards; a screenshot of it at work."""
    _need_freecad()
    if shutil.which("xvfb-run") is None or shutil.which("freecad") is None:
        from .test_dxf_pattern import _installed_by_ci

        if "xvfb" in _installed_by_ci():
            pytest.fail("xvfb-run is missing although .ci/run installed it")
        pytest.skip("the FreeCAD GUI or xvfb is not installed (.ci/run installs them with apt-get)")
    out = tmp_path / "gui.json"
    env = freecad_env(installed(tmp_path), HOME=str(tmp_path), OUT=str(out), SHOT=str(tmp_path / "workbench.png"),
                      PANEL=str(tmp_path / "panel.png"), SAMPLES=str(REPO / "samples"),
                      QTWEBENGINE_CHROMIUM_FLAGS="--no-sandbox",
                      QTWEBENGINE_DISABLE_SANDBOX="1")
    env.pop("QT_QPA_PLATFORM", None)
    proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1400x900x24", "freecad", str(READERS / "freecad_gui_run.py")],
                          capture_output=True, text=True, env=env, timeout=600, check=False)
    assert out.exists(), proc.stdout[-3000:] + proc.stderr[-3000:]
    result = json.loads(out.read_text())
    assert "traceback" not in result, result["traceback"]
    assert "PatternsWorkbench" in result["workbenches"] and result["active"] == "PatternsWorkbench"
    (missing,) = result["missing"]  # activated without an engine: one dialog with the commands to run
    assert missing[0] == "critical" and "patterns freecad install" in missing[2] and not result["started_without"]
    assert result["engine_started"] and result["dialogs"] == []  # then given one: no restart needed
    assert set(result["commands"]) >= {"Patterns_Flatten", "Patterns_Unfold", "Patterns_Check", "Patterns_Export"}
    assert result["panel_open"] and result["panel_height"] <= 900
    assert result["computed"] == [0, 1, 1]  # before OK, after OK, after a move
    assert result["pattern_ok"] and result["edit_open"]
    assert "worst strain" in result["check"] and "largest seam mismatch" in result["check"]
    own = result["colours"]["own"]
    assert result["colours"]["strain"] != own and result["colours"]["off"] == own
    assert result["colours"]["deleted"] == own and result["colours"]["overlay_again"] != own
    assert result["foreign"] == [] and result["flatmesh"] > 0
    assert result["picture_ok"] and (tmp_path / "workbench.png").read_bytes()[:4] == b"\x89PNG"
