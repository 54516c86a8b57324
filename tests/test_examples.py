"""The examples in examples/ run and write what they say."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from ezdxf import recover

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
READERS = Path(__file__).parent / "readers"


@pytest.mark.slow
def test_build123d_script(tmp_path):
    proc = subprocess.run([sys.executable, str(EXAMPLES / "build123d_part.py"), str(tmp_path)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "9 panels" in proc.stdout and proc.stdout.count("strain max") == 9
    doc, auditor = recover.readfile(tmp_path / "hood.dxf")
    assert not auditor.has_errors
    # Nine faces: nine outer outlines, plus the hole in the top.
    assert len(doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')) == 10
    report = json.loads((tmp_path / "hood.json").read_text())
    # Planar faces are exact; the fillet and the hole wall carry only the chords' error.
    assert max(p["strain_max"] for p in report["panels"]) < 1e-3
    assert (tmp_path / "hood.png").read_bytes()[:4] == b"\x89PNG"


def test_freecad_macro(tmp_path):
    if shutil.which("freecadcmd") is None:
        pytest.skip("freecadcmd is not installed (.ci/run installs FreeCAD with apt-get)")
    exe = Path(sys.executable).with_name("patterns")
    if not exe.exists():
        pytest.skip(f"the entry point {exe} is not installed")
    out = tmp_path / "tube.dxf"
    env = dict(os.environ, MACRO=str(EXAMPLES / "freecad_flatten.FCMacro"), OUT=str(out), PATTERNS_EXE=str(exe),
               QT_QPA_PLATFORM="offscreen", HOME=str(tmp_path))
    proc = subprocess.run(["freecadcmd", str(READERS / "freecad_macro_run.py")], capture_output=True, text=True,
                          env=env, timeout=600)
    lines = [x for x in proc.stdout.splitlines() if "RESULT " in x]
    assert lines, proc.stdout[-2000:] + proc.stderr[-2000:]
    output = json.loads(lines[-1].split("RESULT ", 1)[1])["output"]
    assert "3 panels, 3 seams" in output
    doc, auditor = recover.readfile(out)
    assert not auditor.has_errors
    assert len(doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')) == 3
    report = json.loads(out.with_suffix(".json").read_text())
    wall = max(report["panels"], key=lambda p: p["area_3d"])
    assert wall["area_3d"] == pytest.approx(2 * 3.141592653589793 * 50 * 120, rel=1e-3)
