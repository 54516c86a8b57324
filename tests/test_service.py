"""The worker (``patterns serve``) and the host side's engine client, without FreeCAD: the protocol spoken
through real pipes to a real worker process, the option schema, the installer.  References: the API on the
same shape, the shapes read back by OpenCascade, the files the installer wrote."""

from __future__ import annotations

import ast
import importlib.util
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import build123d as bd
import pytest

import patterns
from patterns.cli import main
from patterns.hosts import freecad as host
from patterns.service import brep, schema
from patterns.service.work import key_of

ADDON = Path(host.ADDON) / "freecad" / "patterns_wb"


def _box_brep(length=200.0) -> str:
    return brep.to_brep((bd.Box(length, 100, 50) - bd.Cylinder(20, 50)).wrapped)


class Worker:
    """``patterns serve`` in a process of its own, spoken to line by line."""

    def __init__(self):
        self.proc = subprocess.Popen([sys.executable, "-m", "patterns", "serve"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)

    def ask(self, message) -> dict:
        line = message if isinstance(message, bytes) else json.dumps(message).encode()
        self.proc.stdin.write(line + b"\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self) -> int:
        self.proc.stdin.close()
        return self.proc.wait(timeout=60)


@pytest.fixture(scope="module")
def worker():
    w = Worker()
    yield w
    if w.proc.poll() is None:
        w.close()


def test_hello_says_the_version_and_sends_the_options(worker):
    reply = worker.ask({"id": 1, "op": "hello", "protocol": 1})
    assert reply["id"] == 1 and reply["ok"]
    result = reply["result"]
    assert result["version"] == patterns.__version__ and result["protocol"] == 1
    assert result["options"] == json.loads(json.dumps(schema()))


def test_another_protocol_is_refused_in_one_line(worker):
    reply = worker.ask({"id": 2, "op": "hello", "protocol": 2})
    assert not reply["ok"] and "\n" not in reply["error"]["message"]
    assert "protocol 1, the host 2" in reply["error"]["message"]


def test_a_shape_is_flattened_as_the_api_flattens_it(worker, tmp_path):
    """The cut box sent as BREP text: pieces (read back by OpenCascade) of the API's panels' areas, the
    check's figures, and a second identical request answered from the kept result."""
    text = _box_brep()
    reply = worker.ask({"id": 3, "op": "make", "kind": "pattern", "shape": text, "name": "Cut", "faces": 7,
                        "options": {"seam_allowance": 0.0}})
    assert reply["ok"], reply
    result = reply["result"]
    pieces = brep.from_brep(result["shape"], "reply")
    api = patterns.flatten(patterns.load(brep.from_brep(text, "Cut")))
    assert sorted(f.area for f in pieces.faces()) == pytest.approx(sorted(p.area for p in api.panels), rel=1e-9)
    assert all(abs(v.Z) == 0 for v in pieces.vertices())
    assert result["pieces"] == 7 and result["ok"] and result["face_strain"] == [0.0] * 7
    assert result["key"] == key_of("pattern", text, {"seam_allowance": 0.0}, "Cut")
    assert set(result["marks"]) == {"notch", "grain", "label"}
    assert len(brep.from_brep(result["marks"]["label"], "labels").vertices()) == len(result["labels"])
    computed = worker.ask({"op": "stats"})["result"]["computed"]
    again = worker.ask({"id": 4, "op": "make", "kind": "pattern", "shape": text, "name": "Cut", "faces": 7,
                        "options": {"seam_allowance": 0.0}})
    assert again["result"]["shape"] == result["shape"]
    assert worker.ask({"op": "stats"})["result"]["computed"] == computed  # not computed again


def test_the_two_strain_limits_are_two_options():
    """``dart_strain`` drives the darts, ``max_strain`` the check, as on the command line (they were one
    property in FreeCAD); the nester's ``gap`` is ``nest_gap`` beside the pieces' ``gap``."""
    from patterns import Bundle

    names = {(p["record"], p["option"]): p["name"] for p in schema()["pattern"]}
    assert names[("FlattenOptions", "max_strain")] == "dart_strain"
    assert names[("CheckOptions", "max_strain")] == "max_strain"
    assert names[("NestOptions", "gap")] == "nest_gap" and names[("PieceOptions", "gap")] == "gap"
    bundle = Bundle.from_json("pattern", {"dart_strain": 0.03, "max_strain": 0.05, "gap": 4.0, "nest_gap": 7.0},
                              name="x")
    assert bundle.flatten.max_strain == 0.03 and bundle.check.max_strain == 0.05
    assert bundle.pieces.gap == 4.0 and bundle.nest.gap == 7.0
    assert len({p["name"] for p in schema()["blank"]}) == len(schema()["blank"])


def test_bad_requests_get_one_error_each_and_the_worker_lives_on(worker):
    bad = worker.ask(b"{not json")
    assert not bad["ok"] and bad["error"]["type"] == "InputError"
    unknown = worker.ask({"id": 7, "op": "fly"})
    assert unknown["id"] == 7 and "unknown operation 'fly'" in unknown["error"]["message"]
    option = worker.ask({"id": 8, "op": "validate", "kind": "pattern", "name": "Cut", "options": {"seam_allowance": -3}})
    assert option["error"] == {"type": "InputError",
                               "message": "Cut: seam_allowance (mm) must be a number between 0 and 1000, got -3"}
    shape = worker.ask({"id": 9, "op": "make", "kind": "pattern", "name": "Cut", "shape": "not brep", "options": {}})
    assert shape["error"]["type"] == "CadError" and "Cut" in shape["error"]["message"]
    kind = worker.ask({"id": 10, "op": "validate", "kind": "sail", "name": "Cut", "options": {}})
    assert "unknown kind 'sail'" in kind["error"]["message"]
    assert worker.ask({"id": 11, "op": "stats"})["ok"]


def test_export_writes_what_the_command_line_writes(worker, tmp_path):
    text = _box_brep()
    (tmp_path / "cut.brep").write_text(text)
    reply = worker.ask({"op": "export", "kind": "pattern", "shape": text, "name": "cut", "options": {},
                        "path": str(tmp_path / "worker.dxf")})
    assert reply["ok"], reply
    assert main(["flatten", str(tmp_path / "cut.brep"), "-o", str(tmp_path / "cli.dxf")]) == 0
    import ezdxf

    ours = sorted((e.dxftype(), e.dxf.layer) for e in ezdxf.readfile(tmp_path / "worker.dxf").modelspace())
    theirs = sorted((e.dxftype(), e.dxf.layer) for e in ezdxf.readfile(tmp_path / "cli.dxf").modelspace())
    assert ours == theirs
    refused = worker.ask({"op": "export", "kind": "pattern", "shape": text, "name": "cut", "options": {},
                          "path": str(tmp_path / "x.dxf"), "write": {"units": "furlong"}})
    assert not refused["ok"] and "units" in refused["error"]["message"] and not (tmp_path / "x.dxf").exists()


def test_standard_output_carries_only_replies_and_the_worker_ends_with_its_input():
    proc = subprocess.run([sys.executable, "-m", "patterns", "serve"], input=b'{"op":"stats","id":1}\n\n{"op":"x"}\n',
                          capture_output=True, timeout=120, check=False)
    assert proc.returncode == 0
    lines = proc.stdout.decode().splitlines()
    assert len(lines) == 2 and all(json.loads(x)["id"] in (1, None) for x in lines)


def test_shutdown_ends_the_worker():
    w = Worker()
    assert w.ask({"id": 1, "op": "shutdown"}) == {"id": 1, "ok": True, "result": {}}
    assert w.proc.wait(timeout=60) == 0


# --------------------------------------------------------------------------- #
# The host side, as FreeCAD runs it: standard library only
# --------------------------------------------------------------------------- #


def _host_engine():
    """FreeCAD's ``engine.py`` with the hosts' worker client beside it, as ``patterns freecad install`` puts them
    (a package of their own, in a temporary folder: nothing of FreeCAD's is needed)."""
    import shutil
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="patterns-host-")) / "patterns_host_side"
    folder.mkdir()
    (folder / "__init__.py").write_text("")
    shutil.copy2(ADDON / "engine.py", folder / "engine.py")
    shutil.copy2(host.CLIENT, folder / "client.py")
    spec = importlib.util.spec_from_file_location("patterns_host_side", folder / "__init__.py",
                                                  submodule_search_locations=[str(folder)])
    package = importlib.util.module_from_spec(spec)
    sys.modules["patterns_host_side"] = package
    spec.loader.exec_module(package)
    return importlib.import_module("patterns_host_side.engine")


def test_the_host_side_imports_nothing_but_freecad_and_the_standard_library():
    allowed = set(sys.stdlib_module_names) | {"FreeCAD", "FreeCADGui", "Part", "PySide"}
    for path in [*ADDON.glob("*.py"), Path(host.CLIENT)]:
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module] if isinstance(node, ast.ImportFrom) and not node.level else [])
            for name in names:
                assert name.split(".")[0] in allowed, f"{path.name} imports {name}"


def test_the_host_key_is_the_engines_key():
    module = _host_engine()
    text = _box_brep()
    assert module.key_of("pattern", text, {"seam_allowance": 5.0}, "Cut") == key_of("pattern", text,
                                                                                 {"seam_allowance": 5.0}, "Cut")
    assert key_of("pattern", text, {}, "Cut") != key_of("pattern", text, {}, "Cup")  # the name is in the pieces
    assert module.PROTOCOL == patterns.service.PROTOCOL


def test_the_host_restarts_a_worker_that_died(monkeypatch):
    module = _host_engine()
    monkeypatch.setenv("PATTERNS_ENGINE", f"{sys.executable} -m patterns")
    engine = module.Engine()
    try:
        assert engine.request("stats")["requests"] == 2  # hello, then this
        first = engine.hello["pid"]
        os.kill(first, signal.SIGKILL)
        engine.process.wait()
        assert engine.request("stats")["pid"] != first and engine.starts == 2
        with pytest.raises(module.Refused, match="seam_allowance"):
            engine.request("validate", kind="pattern", options={"seam_allowance": -1}, name="x")
    finally:
        engine.stop()


def test_the_host_says_what_to_run_where_there_is_no_engine(monkeypatch):
    module = _host_engine()
    monkeypatch.delenv("PATTERNS_ENGINE", raising=False)
    monkeypatch.setattr(module, "CONFIG", "/nonexistent/engine.json")
    with pytest.raises(module.EngineError, match="patterns freecad install") as caught:
        module.Engine().start()
    assert "pip install ." in str(caught.value)
    monkeypatch.setenv("PATTERNS_ENGINE", "/nonexistent/python -m patterns")
    with pytest.raises(module.EngineError, match="could not be started"):
        module.Engine().start()
    # a Python without patterns: it starts and dies at once, and its last words are said
    monkeypatch.setenv("PATTERNS_ENGINE", f"{sys.executable} -c \"raise SystemExit('No module named patterns')\"")
    with pytest.raises(module.EngineError, match="(?s)did not start .No module named patterns.*patterns freecad install"):
        module.Engine().start()


def test_an_engine_of_another_version_is_said_in_one_line(monkeypatch, tmp_path, capfd):
    module = _host_engine()
    monkeypatch.delenv("PATTERNS_ENGINE", raising=False)
    config = tmp_path / "engine.json"
    config.write_text(json.dumps({"command": [sys.executable, "-m", "patterns"], "version": "0.0.1", "protocol": 1}))
    monkeypatch.setattr(module, "CONFIG", str(config))
    engine = module.Engine()
    try:
        engine.start()
        err = capfd.readouterr().err
        assert err.count("\n") == 1 and f"engine 0.0.1, the engine is {patterns.__version__}" in err
        assert engine.request("stats")["requests"] == 2  # it works all the same: the same protocol
    finally:
        engine.stop()


# --------------------------------------------------------------------------- #
# The installer
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize(("platform", "environ", "expected"), [
    ("linux", {}, "home/.local/share/FreeCAD"),
    ("linux", {"XDG_DATA_HOME": "/xdg"}, "/xdg/FreeCAD"),
    ("linux", {"FREECAD_USER_HOME": "/fc"}, "/fc"),
    ("linux", {"FREECAD_USER_DATA": "/data", "FREECAD_USER_HOME": "/fc"}, "/data"),
    ("darwin", {}, "home/Library/Application Support/FreeCAD"),
    ("win32", {"APPDATA": "/appdata"}, "/appdata/FreeCAD"),
])
def test_freecads_user_folder_is_found_as_freecad_finds_it(tmp_path, platform, environ, expected):
    home = tmp_path / "home"
    got = host.user_dir(None, environ=environ, platform=platform, home=home)
    assert got == (tmp_path / expected if expected.startswith("home") else Path(expected))


def test_an_old_freecads_folder_is_not_guessed(tmp_path):
    """FreeCAD 0.20 and later use ``~/.FreeCAD`` only with KeepDeprecatedPaths: the XDG folder is theirs."""
    (tmp_path / ".FreeCAD").mkdir()
    assert host.user_dir(None, environ={}, platform="linux", home=tmp_path) == tmp_path / ".local/share/FreeCAD"


def test_a_link_in_the_way_is_left_alone(tmp_path, capsys):
    """0.1.0 had users link the repository into Mod/patterns: install and uninstall leave the link and say so."""
    (tmp_path / "repo").mkdir()
    (tmp_path / "Mod").mkdir()
    (tmp_path / "Mod" / "patterns").symlink_to(tmp_path / "repo")
    (tmp_path / "repo" / "engine.json").write_text("{}")  # even one that looks like ours
    assert main(["freecad", "install", "--user-dir", str(tmp_path)]) == 2
    assert "0.1.0's clone or link" in capsys.readouterr().err
    assert main(["freecad", "uninstall", "--user-dir", str(tmp_path)]) == 2
    assert (tmp_path / "Mod" / "patterns").is_symlink() and (tmp_path / "repo" / "engine.json").exists()


def test_install_and_uninstall(tmp_path, capsys):
    assert main(["freecad", "install", "--user-dir", str(tmp_path)]) == 0
    folder = tmp_path / "Mod" / "patterns"
    record = json.loads((folder / "engine.json").read_text())
    assert record == {"command": [sys.executable, "-m", "patterns"], "version": patterns.__version__, "protocol": 1}
    installed = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())
    shipped = sorted(p.relative_to(host.ADDON).as_posix() for p in host.ADDON.rglob("*")
                     if p.is_file() and "__pycache__" not in p.parts)
    assert installed == sorted(shipped + ["engine.json", "freecad/patterns_wb/client.py"])
    assert str(folder) in capsys.readouterr().out
    assert main(["freecad", "install", "--user-dir", str(tmp_path)]) == 0  # again: replaced
    assert main(["freecad", "uninstall", "--user-dir", str(tmp_path)]) == 0
    assert not folder.exists() and (tmp_path / "Mod").is_dir()


def test_install_leaves_a_folder_that_is_not_ours(tmp_path, capsys):
    other = tmp_path / "Mod" / "patterns"
    other.mkdir(parents=True)
    (other / "mine.txt").write_text("x")
    assert main(["freecad", "install", "--user-dir", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a patterns workbench" in err
    assert main(["freecad", "uninstall", "--user-dir", str(tmp_path)]) == 2
    assert (other / "mine.txt").read_text() == "x" and sorted(os.listdir(tmp_path / "Mod")) == ["patterns"]


def test_freecads_face_name_is_a_fixed_face(tmp_path):
    """``--fixed-face Face2`` (FreeCAD's 1-based name) is ``fixed_face=1``; a bad one is one line, exit 2."""
    from patterns.options import from_text
    from patterns.sheetmetal import UnfoldOptions

    assert from_text(UnfoldOptions, {"fixed_face": "Face2"}).fixed_face == 1
    assert from_text(UnfoldOptions, {"fixed_face": "1"}).fixed_face == 1
    assert main(["unfold", "samples/bracket.step", "-o", str(tmp_path / "b.dxf"), "--fixed-face", "Edge2"]) == 2
    assert not (tmp_path / "b.dxf").exists()


def test_the_old_freecad_module_warns_and_names_its_replacement(monkeypatch):
    """``patterns.freecad`` (0.1.0's engine inside FreeCAD) warns, naming ``freecad.patterns_wb``, and forwards
    its four names there (resolved where FreeCAD imports: here the workbench's package, not its FreeCAD part)."""
    import importlib

    monkeypatch.syspath_prepend(str(host.ADDON))
    monkeypatch.delitem(sys.modules, "patterns.freecad", raising=False)
    with pytest.warns(DeprecationWarning, match=r"0\.3\.0.*from freecad.patterns_wb import make_pattern"):
        old = importlib.import_module("patterns.freecad")
    assert sorted(old.__all__) == ["export", "make_blank", "make_pattern", "report_of"]
    with pytest.raises(AttributeError):
        old.flatten  # noqa: B018 - not one of the forwarded names


def test_an_edited_table_file_is_a_new_request(tmp_path):
    """An option naming a file (a bend table) keys the request by the file's size and time: the same text,
    an edited file, another key (a recompute then asks the engine again)."""
    import time

    table = tmp_path / "bends.csv"
    table.write_text("thickness,radius,angle,deduction\n2,3,90,3.9\n")
    first = key_of("blank", "BREP", {"bend_table": str(table)}, "Part")
    assert key_of("blank", "BREP", {"bend_table": str(table)}, "Part") == first
    time.sleep(0.01)
    table.write_text("thickness,radius,angle,deduction\n2,3,90,4.1\n")
    assert key_of("blank", "BREP", {"bend_table": str(table)}, "Part") != first
    assert _host_engine().key_of("blank", "BREP", {"bend_table": str(table)}, "Part") == \
        key_of("blank", "BREP", {"bend_table": str(table)}, "Part")


def test_a_mesh_is_sent_as_arrays_and_flattened_as_the_api_flattens_it(worker):
    """``mesh`` instead of ``shape`` (a host whose model is a mesh: Blender next): the piece's area is the API's
    panel's (``mesh_model`` of the same arrays), read back from the reply's BREP; a blank of a mesh is refused."""
    from patterns import surfaces
    from patterns.reading import mesh_model

    vertices, faces = surfaces.paraboloid_dish(diameter=600, sag=54, n_faces=2000)
    mesh = {"vertices": vertices.tolist(), "faces": faces.tolist()}
    reply = worker.ask({"id": 20, "op": "make", "kind": "pattern", "name": "dish", "mesh": mesh, "options": {}})
    assert reply["ok"], reply
    (piece,) = brep.from_brep(reply["result"]["shape"], "reply").faces()
    (panel,) = patterns.flatten(mesh_model(vertices, faces, name="dish")).panels
    assert piece.area == pytest.approx(panel.area, rel=1e-9)
    refused = worker.ask({"id": 21, "op": "make", "kind": "blank", "name": "dish", "mesh": mesh, "options": {}})
    assert "unfolded from a CAD shape" in refused["error"]["message"]


def test_a_shape_only_displayed_keeps_its_key():
    """FreeCAD flips a shape's flags line when it merely tessellates it for display (0111000 -> 0101000,
    measured on a Part sphere): the key leaves the flags out, so a displayed part is not a new request."""
    import re

    text = _box_brep()
    flags = re.findall(r"(?m)^[01]{7}$", text)
    assert flags  # every shape of the BREP has its flags line
    shown = re.sub(r"(?m)^([01])1([01]{5})$", r"\g<1>0\g<2>", text)
    assert shown != text
    assert key_of("pattern", shown, {}, "Cut") == key_of("pattern", text, {}, "Cut")
    assert _host_engine().key_of("pattern", shown, {}, "Cut") == key_of("pattern", text, {}, "Cut")
    assert key_of("pattern", text.replace("200", "201", 1), {}, "Cut") != key_of("pattern", text, {}, "Cut")
