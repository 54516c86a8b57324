"""patterns in FreeCAD: parametric patterns and blanks in a real document, the workbench in a real GUI.

Run in ``freecadcmd`` (FreeCAD 0.20, the system's Python) through ``tests/readers/freecad_api_run.py``,
with this interpreter's site-packages in front of FreeCAD's path as docs/freecad.md has a user do; the
GUI under Xvfb.  References: the API in this interpreter on the same part (written by FreeCAD as STEP),
analytic areas, SolidWorks' flat patterns, the files read back.  Skipped where FreeCAD is absent (``.ci/run``
installs it: there they must run).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sysconfig
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


def _run(scenario: str, tmp_path, **args) -> dict:
    """One scenario of ``freecad_api_run.py`` in freecadcmd: its RESULT."""
    _need_freecad()
    env = dict(os.environ, PATTERNS_SITE=sysconfig.get_paths()["purelib"], SCENARIO=scenario, ARGS=json.dumps(args),
               HOME=str(tmp_path), QT_QPA_PLATFORM="offscreen")
    proc = subprocess.run(["freecadcmd", str(READERS / "freecad_api_run.py")], capture_output=True, text=True, env=env,
                          timeout=900, check=False)
    lines = [x for x in proc.stdout.splitlines() if "RESULT " in x]
    assert lines, proc.stdout[-3000:] + proc.stderr[-3000:]
    result = json.loads(lines[-1].split("RESULT ", 1)[1])
    assert "traceback" not in result, result.get("traceback")
    return result


def test_a_cut_flattens_in_its_document_and_grows_with_its_box(tmp_path):
    """``make_pattern`` of a Part::Cut (a 200 x 100 x 50 box less an R20 cylinder at its corner): a flat face
    per CAD face at z = 0, each the area of the API's panel of the same part (FreeCAD's STEP of it, read by
    this interpreter), the planar and cylindrical ones their exact areas; the box made 250 long and recomputed,
    the pieces grow by 2 x 50 x 100 + 2 x 50 x 50 = 15 000 mm²."""
    result = _run("box_minus_cylinder", tmp_path, step=str(tmp_path / "cut.step"))
    api = patterns.flatten(patterns.load(tmp_path / "cut.step"))
    assert result["areas"] == pytest.approx(sorted(p.area for p in api.panels), abs=0.01)
    for exact in (4000.0, 5000.0, 9000.0, 10000.0, np.pi / 2 * 20 * 50):
        assert min(abs(a - exact) for a in result["areas"]) < 1e-6
    assert sum(result["after"]) - sum(result["areas"]) == pytest.approx(15000.0, abs=1e-6)
    assert result["z"] == 0.0 and result["ok"] and result["pieces"] == 7
    assert result["face_strain"] == [0.0] * 7  # every face an exact development
    marks = result["marks"]
    assert set(marks) >= {"notch", "grain", "label"} and marks["grain"][0] == 7
    assert "face0" in marks["label"][2] and marks["label"][1] == len(marks["label"][2])
    assert "Cut: ok (7 panels" in result["report"]


def test_a_bad_option_is_refused_before_anything_is_added(tmp_path):
    result = _run("bad_option", tmp_path)
    assert "seam_allowance (mm) must be a number between 0 and 1000, got -3" in result["error"]
    assert result["objects"] == ["Box", "Cylinder", "Cut"]


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
        assert "label" in result["marks"] and ("bend_up" in result["marks"] or "bend_down" in result["marks"])


def _entities(path):
    doc = ezdxf.readfile(path)
    cut = sorted(shapely.Polygon(np.array(e.get_points("xy"))).area for e in doc.modelspace().query("LWPOLYLINE[layer=='CUT']"))
    counts = {}
    for e in doc.modelspace():
        counts[(e.dxftype(), e.dxf.layer)] = counts.get((e.dxftype(), e.dxf.layer), 0) + 1
    return cut, counts


def test_export_from_the_document_writes_what_the_command_line_writes(tmp_path):
    """The pattern's pieces exported from the document (the project's writers) against ``patterns flatten`` of
    the same part (FreeCAD's STEP of it) with the same options: the same entities on the same layers, the cut
    lines at the same areas; the SVG and the JSON report written too."""
    result = _run("export", tmp_path, path=str(tmp_path / "doc"), step=str(tmp_path / "cut.step"),
                  options={"seam_allowance": 5.0, "notch_spacing": 40.0})
    assert main(["flatten", str(tmp_path / "cut.step"), "-o", str(tmp_path / "cli.dxf"), "--seam-allowance", "5",
                 "--notch-spacing", "40"]) == 0
    ours, theirs = _entities(tmp_path / "doc.dxf"), _entities(tmp_path / "cli.dxf")
    assert ours[0] == pytest.approx(theirs[0], rel=1e-9)
    assert ours[1] == theirs[1]
    report = json.loads((tmp_path / "doc.json").read_text())
    assert report["ok"] and len(report["pieces"]) == 7 and result["report_ok"]
    assert (tmp_path / "doc.svg").read_text().startswith("<?xml")


def test_the_package_file_names_the_workbench_and_its_gui():
    import xml.etree.ElementTree as ET

    root = ET.parse(REPO / "package.xml").getroot()
    ns = {"p": "https://wiki.freecad.org/Package_Metadata"}
    (workbench,) = root.findall("p:content/p:workbench", ns)
    assert workbench.find("p:classname", ns).text == "PatternsWorkbench"
    assert (REPO / "freecad" / "patterns_wb" / "init_gui.py").is_file()
    assert not (REPO / "freecad" / "__init__.py").exists()  # a namespace package: FreeCAD's own owns it
    for icon in root.iter("{https://wiki.freecad.org/Package_Metadata}icon"):
        assert (REPO / icon.text).is_file()
    names = {d.text for d in root.findall("p:depend", ns) if d.get("type") == "python"}
    assert names <= {"numpy", "scipy", "shapely", "trimesh", "ezdxf", "networkx"}  # the Addon Manager's allow-list


def test_the_workbench_loads_in_the_gui_and_registers_its_commands(tmp_path):
    """FreeCAD's GUI under Xvfb, the repository linked into its Mod folder as the Addon Manager would clone it:
    the workbench is listed, activates, and its four commands are registered; a screenshot of it at work."""
    _need_freecad()
    if shutil.which("xvfb-run") is None or shutil.which("freecad") is None:
        from .test_dxf_pattern import _installed_by_ci

        if "xvfb" in _installed_by_ci():
            pytest.fail("xvfb-run is missing although .ci/run installed it")
        pytest.skip("the FreeCAD GUI or xvfb is not installed (.ci/run installs them with apt-get)")
    mod = tmp_path / ".local" / "share" / "FreeCAD" / "Mod"
    mod.mkdir(parents=True)
    (mod / "patterns").symlink_to(REPO)
    out = tmp_path / "gui.json"
    env = dict(os.environ, PATTERNS_SITE=sysconfig.get_paths()["purelib"], HOME=str(tmp_path), OUT=str(out),
               SHOT=str(tmp_path / "workbench.png"), QTWEBENGINE_CHROMIUM_FLAGS="--no-sandbox")
    env.pop("QT_QPA_PLATFORM", None)
    proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1400x900x24", "freecad", str(READERS / "freecad_gui_run.py")],
                          capture_output=True, text=True, env=env, timeout=600, check=False)
    assert out.exists(), proc.stdout[-3000:] + proc.stderr[-3000:]
    result = json.loads(out.read_text())
    assert "PatternsWorkbench" in result["workbenches"], result
    assert result["active"] == "PatternsWorkbench"
    assert set(result["commands"]) >= {"Patterns_Flatten", "Patterns_Unfold", "Patterns_Check", "Patterns_Export"}
    assert result["pattern_ok"] and (tmp_path / "workbench.png").read_bytes()[:4] == b"\x89PNG"
