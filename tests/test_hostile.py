"""Issue 52, the hostile cases of round four: one test per fault, each asserting the exit code, the one line and
that nothing was written (the helpers of tests/test_reliability.py), or the output read back by a second reader
(csv, an XML parser, ezdxf)."""

from __future__ import annotations

import csv
import os
import shutil
import xml.etree.ElementTree as ET

import ezdxf
import numpy as np
import pytest

import patterns
from patterns.errors import InputError

from .conftest import SAMPLES
from .test_reliability import refused, run


@pytest.fixture
def strip(tmp_path):
    """A folder holding the bracket (a bent blank: its bend sheet has rows)."""
    shutil.copy(SAMPLES / "bracket.step", tmp_path / "strip.step")
    return tmp_path


# --------------------------------------------------------------------------- #
# 1. CSV injection: every text cell shown, never run
# --------------------------------------------------------------------------- #

_FORMULA = ("=", "+", "-", "@", "\t", "\r")


@pytest.mark.parametrize("stem", ["=cmd|' -C calc'!A0", "+1+1", "-2-3", "@SUM(A1)"])
def test_a_part_named_like_a_formula_is_a_text_cell_in_the_bend_sheet(strip, capfd, stem):
    """OWASP's rule, read back with the csv module: the part cell is the name after a quote; no text cell starts
    a formula; the numbers (a negative coordinate too) stay numbers."""
    shutil.copy(strip / "strip.step", strip / f"{stem}.step")
    code, out, err = run(["unfold", f"./{stem}.step", "-o", "blank.dxf", "--bend-sheet", "bends.csv"], strip, capfd)
    assert code == 0, err
    with open(strip / "bends.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    assert body and all(row[0] == "'" + stem for row in body)
    numeric = [k for k, name in enumerate(header) if name not in ("part", "direction")]
    for row in body:
        for k, cell in enumerate(row):
            if k in numeric and cell:
                float(cell)  # a number, as written
            else:
                assert not cell.startswith(_FORMULA), cell


def test_spreadsheet_cells():
    from patterns.text import spreadsheet_cell

    for text in ("=1+1", "+1", "-1", "@A1", "\uff1dSUM(A1)"):
        assert spreadsheet_cell(text) == "'" + text
    assert spreadsheet_cell("\tx") == "\\x09x"  # a control character is made visible first: no formula then
    assert spreadsheet_cell("bracket 2") == "bracket 2" and spreadsheet_cell("a=b") == "a=b"


# --------------------------------------------------------------------------- #
# 4. Outputs that are what they say: an SVG is XML whatever the name; two roles never share a layer
# --------------------------------------------------------------------------- #

@pytest.mark.parametrize("stem", ["esc\x1b[31mred\x07bell", "form\x0cfeed", "del\x7f", "one\x01",
                                  os.fsdecode(b"caf\xe9")])
def test_an_svg_is_well_formed_xml_whatever_the_file_is_called(strip, capfd, stem):
    """Control characters and bytes that are not UTF-8 in the part's name: the SVG's title shows them as
    visible escapes, and Python's XML parser reads the file (the same name through flatten too)."""
    os.rename(os.fsencode(strip / "strip.step"), os.fsencode(strip) + b"/" + os.fsencode(stem) + b".step")
    name = os.fsencode(stem) + b".step"
    for command, out in (("unfold", "blank.svg"), ("flatten", "pattern.svg")):
        code, _, err = run([command, name, "-o", out], strip, capfd)
        assert code == 0, err
        root = ET.parse(strip / out).getroot()
        title = root.find("{http://www.w3.org/2000/svg}title")
        assert title is not None and patterns.text.printable(stem) in title.text
        assert not any(ord(c) < 32 and c not in "\t\n\r" for c in (strip / out).read_text(encoding="utf-8"))


@pytest.mark.parametrize(("layers", "words"), [
    ("patterns,cut=bend", "roles cut, bend, bend_up, bend_down would share layer 'bend'"),
    ("patterns,label=cut", "roles cut, hole, label would share layer 'CUT'"),
    ("updown,bend_down=STOCK", "roles bend_down, stock would share layer 'STOCK'"),
    ("solidworks,bend=0", "would share layer '0'"),
])
def test_two_roles_a_machine_treats_differently_never_share_a_layer(strip, capfd, layers, words):
    refused(["unfold", "strip.step", "-o", "blank.dxf", "--layer-map", layers], strip, capfd, words)


def test_roles_of_one_kind_may_share_a_layer_in_any_case(strip, capfd):
    """The outline and the holes are both cut, every bend is bent: ``hole=Cut`` is the CUT layer (declared once,
    read back), ``updown,bend_up=BEND_DOWN`` both bend lines on one layer."""
    code, _, err = run(["unfold", "strip.step", "-o", "a.dxf", "--layer-map", "patterns,hole=Cut"], strip, capfd)
    assert code == 0, err
    assert [layer.dxf.name.upper() for layer in ezdxf.readfile(strip / "a.dxf").layers].count("CUT") == 1
    code, _, err = run(["unfold", "strip.step", "-o", "b.dxf", "--layer-map", "updown,bend_up=bend_down"], strip,
                       capfd)
    assert code == 0, err


@pytest.mark.parametrize("name", ["a<b", "a;b", "a*", "a?", "a|b", "a=b", "a\nb", "a\x1bb", 'a"b'])
def test_a_layer_name_no_dxf_reader_takes_is_refused(strip, capfd, name):
    refused(["unfold", "strip.step", "-o", "blank.dxf", "--layer-map", f"patterns,cut={name}"], strip, capfd,
            "is not a DXF layer name")
    with pytest.raises(InputError, match="is not a DXF layer name"):
        patterns.write(patterns.unfold(strip / "strip.step"), strip / "x.dxf", layer_map={"sew": name})
    assert not (strip / "x.dxf").exists()


# --------------------------------------------------------------------------- #
# 5. Tracebacks: integers past 64 bits, a flat pattern with a NaN
# --------------------------------------------------------------------------- #

HUGE = "99999999999999999999"


@pytest.mark.parametrize(("argv", "words"), [
    (["unfold", "strip.step", "-o", "b.dxf", "--nest-seed", HUGE, "--sheet", "400x300"],
     "--nest-seed must be an integer between 0 and 4294967295, got 99999999999999999999"),
    (["unfold", "strip.step", "-o", "b.dxf", "--copies", HUGE, "--sheet", "400x300"], "--copies must be an integer"),
    (["unfold", "strip.step", "-o", "b.dxf", "--quantity", f"strip={HUGE}", "--sheet", "400x300"],
     "--quantity['strip'] must be an integer"),
    (["flatten", "strip.step", "-o", "b.dxf", "--max-darts", HUGE], "--max-darts must be an integer"),
    (["flatten", "strip.step", "-o", "b.dxf", "--max-iterations", HUGE], "--max-iterations must be an integer"),
    (["unfold", "strip.step", "-o", "b.dxf", "--fixed-face", HUGE], "is not a planar face of the part"),
    (["batch", ".", "-o", "out", "--jobs", HUGE], "--jobs must be an integer between 1 and 1024"),
])
def test_an_integer_past_64_bits_is_refused_in_one_line(strip, capfd, argv, words):
    refused(argv, strip, capfd, words)


def _dxf(path, lines=(), circles=()):
    doc = ezdxf.new()
    for a, b in lines:
        doc.modelspace().add_line(a, b)
    for centre, radius in circles:
        doc.modelspace().add_circle(centre, radius)
    doc.saveas(path)


@pytest.mark.parametrize(("what", "words"), [
    ("nan line", "a LINE (handle"),
    ("nan circle", "a CIRCLE (handle"),
    ("there and back", "a contour of fewer than three points"),
    ("huge", "MB, over the 20 MB a flat pattern to compare with may have"),
])
def test_a_flat_pattern_that_is_no_drawing_is_refused(strip, capfd, what, words):
    nan = float("nan")
    path = strip / "theirs.dxf"
    if what == "nan line":
        _dxf(path, [((0, 0), (100, 0)), ((100, 0), (nan, 50)), ((100, 50), (0, 50)), ((0, 50), (0, 0))])
    elif what == "nan circle":
        _dxf(path, [((0, 0), (100, 0)), ((100, 0), (100, 50)), ((100, 50), (0, 0))], [((10, 10), nan)])
    elif what == "there and back":
        _dxf(path, [((0, 0), (100, 0)), ((100, 0), (0, 0))])
    else:
        _dxf(path, [((0, 0), (100, 0))])
        with open(path, "ab") as fh:
            fh.truncate(21_000_000)  # past the cap: refused on its size, before ezdxf reads a byte
    refused(["unfold", "strip.step", "-o", "b.dxf", "--compare", "theirs.dxf"], strip, capfd, words)


def test_open_pieces_chain_as_the_pair_by_pair_search_did():
    """The contour chaining looks only near each end (a KD-tree) now: a polygon of 2,000 LINEs given in a
    shuffled order, some reversed, reads back as the polygon (its area, shoelace by hand)."""
    from patterns.comparison import _chain

    rng = np.random.default_rng(0)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 2000))
    radius = 100 + 10 * np.sin(5 * angles)
    pts = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    pieces = [np.array([pts[k], pts[(k + 1) % len(pts)]]) for k in range(len(pts))]
    pieces = [p[::-1] if k % 3 == 0 else p for k, p in enumerate(pieces)]
    order = rng.permutation(len(pieces))
    loops, left = _chain([pieces[k] for k in order], "t.dxf")
    assert len(loops) == 1 and not left and len(loops[0]) == 2000
    x, y = loops[0][:, 0], loops[0][:, 1]
    shoelace = abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2
    truth = abs(np.dot(pts[:, 0], np.roll(pts[:, 1], -1)) - np.dot(pts[:, 1], np.roll(pts[:, 0], -1))) / 2
    assert shoelace == pytest.approx(truth, rel=1e-12)


# --------------------------------------------------------------------------- #
# 6. A material table under the size cap is checked in one pass
# --------------------------------------------------------------------------- #

def _brute_overlap(table, materials, eps):
    """The pair-by-pair check the STRtree replaced: the first (row, earlier row) of one material overlapping."""
    for i in range(len(table)):
        for j in range(i):
            a, b = table[i], table[j]
            if materials[i] == materials[j] and min(a[1], b[1]) - max(a[0], b[0]) > eps \
                    and min(a[3], b[3]) - max(a[2], b[2]) > eps:
                return j + 2, i + 2
    return None


@pytest.mark.parametrize("seed", range(6))
def test_overlapping_rows_are_found_as_the_pair_by_pair_check_finds_them(tmp_path, seed):
    """Random tables on a grid (rows that touch at an edge, rows that overlap, two materials): the rows named
    are those the pair-by-pair loop names, or none when it finds none."""
    from patterns.sheetmetal.materials import EPS, read_material_table

    rng = np.random.default_rng(seed)
    n = 150
    t0 = rng.integers(1, 6, n) * 0.5
    rt0 = rng.integers(0, 40, n) * 0.5
    table = np.column_stack([t0, t0 + rng.integers(1, 3, n) * 0.5, rt0, rt0 + rng.integers(1, 3, n) * 0.5,
                             np.full(n, 0.4)])
    materials = [f"m{k}" for k in rng.integers(0, 40 if seed % 2 else 200, n)]
    path = tmp_path / "t.csv"
    path.write_text("material,thickness_min,thickness_max,rt_min,rt_max,k_factor\n" + "".join(
        f"{m},{a:g},{b:g},{c:g},{d:g},{k:g}\n" for m, (a, b, c, d, k) in zip(materials, table)))
    expected = _brute_overlap(table, materials, EPS)
    if expected is None:
        read_material_table(path)
    else:
        with pytest.raises(InputError, match=f"rows {expected[0]} and {expected[1]} both give"):
            read_material_table(path)


# --------------------------------------------------------------------------- #
# 2, 3. A stop wherever it lands: swallowed by a library, during the imports, mid-work
# --------------------------------------------------------------------------- #

def test_a_stop_a_library_swallowed_still_writes_nothing(tmp_path):
    """trimesh's loaders catch BaseException: a Ctrl-C raised inside one is dropped there.  Here the same, for
    real: the signal sent to this process under the command line's handlers, its KeyboardInterrupt caught and
    dropped as such a library does; the outputs' commit then refuses (KeyboardInterrupt again), and the file
    that was there is untouched; SIGTERM likewise (Terminated)."""
    import signal

    from patterns import signals
    from patterns.errors import Terminated
    from patterns.files import Outputs, atomic_output

    target = tmp_path / "out.dxf"
    target.write_text("the user's file\n")
    # a shell's background job (.ci/run &, nohup) starts with SIGINT ignored, and install() keeps an ignored
    # signal ignored: give this process the terminal's default first, as a user's shell does
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    for sig, stop in ((signal.SIGINT, KeyboardInterrupt), (signal.SIGTERM, Terminated)):
        restore = signals.install()
        try:
            try:
                os.kill(os.getpid(), sig)
                for _ in range(100):  # the handler runs between bytecodes: soon
                    pass
            except BaseException:  # noqa: BLE001 - as trimesh's loaders do
                pass
            assert signals.received() == sig
            with pytest.raises(stop), Outputs() as out:
                out.stage(target).write_text("half a pattern\n")
                out.stage(tmp_path / "out.json").write_text("{}\n")
                out.commit()
            with pytest.raises(stop), atomic_output(target) as tmp:
                tmp.write_text("half a pattern\n")
        finally:
            restore()
        assert target.read_text() == "the user's file\n"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["out.dxf"]
    signal.signal(signal.SIGINT, inherited)
    assert signals.received() is None  # a run over: later library calls are not stopped by it


_STOP_IN_A_CALLBACK = """
import os, signal, sys, weakref
signal.signal(signal.SIGINT, signal.default_int_handler)  # as a user's shell gives it (.ci/run & ignores it)
class Thing:
    pass
def stop(ref):
    os.kill(os.getpid(), signal.{sig})
    for _ in range(1000):  # the handler runs between bytecodes: here, inside the callback
        pass
"""
"""A child script's start: a signal handler as a user's shell leaves it, and ``stop``, a weak reference's
callback that sends signal ``{sig}`` to the process and lets it land there (where Python cannot raise)."""


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_stop_that_lands_where_python_cannot_raise_is_quiet_and_still_a_stop(sig):
    """A signal during the heavy imports can land in importlib's module-lock clean-up (a weak reference's
    callback), where Python cannot raise: it prints "Exception ignored in" and a traceback.  Here the same, for
    real, in a fresh interpreter under the command line's handlers: the signal sent inside a weak reference's
    callback prints nothing, and the stop is still there for the outputs' commit (check() raises it); another
    error in such a callback is still printed, and after restore() a stop is printed as Python does."""
    import subprocess
    import sys

    script = _STOP_IN_A_CALLBACK.format(sig=sig) + f"""
from patterns import signals
from patterns.errors import Terminated
restore = signals.install()
thing = Thing(); ref = weakref.ref(thing, stop); del thing
print("stop received:", signals.received() == signal.{sig}, flush=True)
try:
    signals.check()
except (KeyboardInterrupt, Terminated) as stop_:
    print("check raised:", type(stop_).__name__, flush=True)
def other(ref):
    raise ValueError("another error")
thing = Thing(); ref = weakref.ref(thing, other); del thing
restore()
signal.signal(signal.SIGTERM, lambda *a: (_ for _ in ()).throw(Terminated()))
signal.signal(signal.SIGINT, signal.default_int_handler)
thing = Thing(); ref = weakref.ref(thing, stop); del thing
"""
    run = subprocess.run([sys.executable, "-c", script], check=False, capture_output=True, text=True, timeout=60)
    word = "KeyboardInterrupt" if sig == "SIGINT" else "Terminated"
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines() == ["stop received: True", f"check raised: {word}"]
    ignored = [line for line in run.stderr.splitlines() if line.startswith("Exception ignored in")]
    assert len(ignored) == 2, run.stderr  # the other error, and the stop after restore(): only those
    assert "ValueError: another error" in run.stderr and word in run.stderr.splitlines()[-1], run.stderr


def test_installs_restored_in_any_order_leave_the_handlers_and_hook_there_were():
    """The launcher's install and the command line's, nested, restored in either order: the signal handlers and
    the unraisable hook there were before both come back (restoring the outer one first used to leave the
    inner's hook in place for good); a hook someone set after ours stays theirs; a stop received inside is kept
    until the last restore, then forgotten."""
    import signal
    import sys

    from patterns import signals

    kinds = (signal.SIGINT, signal.SIGTERM)
    hook, handlers = sys.unraisablehook, [signal.getsignal(s) for s in kinds]
    for order in ("outer first", "inner first"):
        outer = signals.install()
        signals._RECEIVED.append(signal.SIGTERM)  # as the handler notes a stop
        inner = signals.install()
        assert signals.received() == signal.SIGTERM  # one run: kept
        first, second = (outer, inner) if order == "outer first" else (inner, outer)
        first()
        assert signals.received() == signal.SIGTERM and signal.getsignal(signal.SIGTERM) is signals._handler
        second()
        assert signals.received() is None, order
        assert sys.unraisablehook is hook and [signal.getsignal(s) for s in kinds] == handlers, order

    def theirs(unraisable):
        pass

    outer, inner = signals.install(), signals.install()
    sys.unraisablehook = theirs
    inner()
    outer()
    assert sys.unraisablehook is theirs
    sys.unraisablehook = hook


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_stop_quieted_during_the_heavy_imports_is_not_forgotten_by_the_run(tmp_path, sig):
    """The ``patterns`` command installs the handlers (patterns.launch), imports the command line, whose main()
    installs them again for its run.  A stop that lands where Python cannot raise while patterns.cli is being
    imported (a weak reference's callback, as importlib's module-lock clean-up is) is quieted and remembered:
    here, for real, in a fresh interpreter running the command's own entry point on a sample, the signal sent
    from such a callback as patterns.cli's import starts (an audit hook).  The run ends as stopped, in one line,
    and writes nothing (it used to forget the stop at the second install: exit 0, out.dxf written)."""
    import subprocess
    import sys

    out = tmp_path / "out.dxf"
    script = _STOP_IN_A_CALLBACK.format(sig=sig) + f"""
fired = []
def hook(event, args):
    if event == "import" and args[0] == "patterns.cli" and not fired:
        fired.append(1)
        thing = Thing(); ref = weakref.ref(thing, stop); del thing
sys.addaudithook(hook)
from patterns.launch import main
sys.argv = ["patterns", "unfold", {str(SAMPLES / "bracket.step")!r}, "-o", {str(out)!r}]
sys.exit(main())
"""
    run = subprocess.run([sys.executable, "-c", script], check=False, capture_output=True, text=True, timeout=300)
    word = "interrupted" if sig == "SIGINT" else "terminated"
    assert run.returncode == (130 if sig == "SIGINT" else 143), run.stderr
    assert run.stderr.splitlines() == [f"patterns: {word}; nothing written"], run.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_at_any_moment_ends_the_run_in_one_line(strip, sig):
    """``patterns unfold`` sent the signal at moments from 0.1 s (the heavy imports: numpy, OpenCascade) to the
    writing: each run either finished (exit 0, its outputs whole; or killed by the signal as Python ends, after
    them), or was killed silently as the interpreter started (before any handler: nothing written), or ended with
    130 / 143 and exactly one line, the earlier out.dxf untouched and nothing else written -- never a traceback."""
    import signal
    import subprocess
    import time

    from .test_reliability import EXE, _interruptible, snapshot

    number = getattr(signal, sig)
    code, word = (130, "interrupted") if number == signal.SIGINT else (143, "terminated")
    (strip / "out.dxf").write_text("the user's file\n")
    before = snapshot(strip)
    stopped = 0
    for delay in (0.1, 0.3, 0.8, 2.0, 4.0):
        proc = subprocess.Popen([str(EXE), "unfold", "strip.step", "-o", "out.dxf", "--report", "out.json",
                                 "--bend-sheet", "out.csv"], cwd=strip, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, preexec_fn=_interruptible)
        time.sleep(delay)
        proc.send_signal(number)
        _, err = proc.communicate(timeout=120)
        if proc.returncode == -number and not err and snapshot(strip) == before:
            continue  # killed by the signal as the interpreter started, before any handler (nothing written)
        if proc.returncode in (0, -number):  # done; or done and exiting when the signal came (Python's own end)
            assert "Traceback" not in err and (strip / "out.dxf").read_text() != "the user's file\n", (delay, err)
            assert {p.name for p in strip.iterdir()} == {"out.dxf", "out.json", "out.csv", "strip.step"}
            for name in ("out.json", "out.csv"):
                (strip / name).unlink()
            (strip / "out.dxf").write_text("the user's file\n")
            continue
        stopped += 1
        assert proc.returncode == code, (delay, proc.returncode, err)
        assert err.strip() == f"patterns: {word}; nothing written", (delay, err)
        assert snapshot(strip) == before, delay
    assert stopped >= 3  # the early moments at least (the imports alone take longer than 0.8 s)


# --------------------------------------------------------------------------- #
# 7. batch: every entry its own row
# --------------------------------------------------------------------------- #

def test_every_entry_of_a_batch_folder_is_its_own_row(tmp_path):
    """A part that cannot be read (mode 000), one over the 1 GiB limit (sparse), an empty one: each fails alone
    while the readable parts are unfolded; a folder, a pipe, a device link, a link to nothing and a link loop
    named like parts are listed as skipped with why; a name with a newline is a part like any other."""
    from .test_reliability import cmd, no_dac_override

    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("a.step", "locked.step", "new\nline.step"):
        shutil.copy(SAMPLES / "bracket.step", folder / name)
    (folder / "locked.step").chmod(0)
    (folder / "empty.step").write_bytes(b"")
    with open(folder / "huge.step", "wb") as fh:
        fh.truncate(1_100_000_000)
    (folder / "dir.step").mkdir()
    os.mkfifo(folder / "fifo.step")
    (folder / "null.step").symlink_to("/dev/null")
    (folder / "broken.step").symlink_to("missing.step")
    (folder / "loop.step").symlink_to("loop.step")
    done = cmd(["batch", "in", "-o", "out", "--unfold", "--jobs", "1"], tmp_path, prefix=no_dac_override())
    assert done.returncode == 2, done.stderr  # three parts failed
    rows = {line.split()[0]: line for line in done.stdout.splitlines()[1:] if not line.startswith("batch:")}
    assert "ok" in rows["a.step"] and "ok" in rows["new\\x0aline.step"]
    assert "failed: " in rows["locked.step"] and "permission denied" in rows["locked.step"]
    assert "over the limit of 1 GiB" in rows["huge.step"] and "the file is empty" in rows["empty.step"]
    for name, why in (("dir.step", "a folder"), ("fifo.step", "a pipe (FIFO)"),
                      ("null.step", "a device, through a symbolic link"), ("broken.step", "a symbolic link to nothing"),
                      ("loop.step", "a loop of symbolic links")):
        assert f"skipped: {why}, not a part file" in rows[name], rows[name]
    assert "2 ok, 3 failed, 5 skipped" in done.stdout
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.dxf", "a.json", "new\nline.dxf", "new\nline.json"]


def _bow_tie(path):
    """A STEP file of one planar face whose boundary crosses itself: (0,0) (100,100) (100,0) (0,100)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.gp import gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    polygon = BRepBuilderAPI_MakePolygon()
    for x, y in [(0, 0), (100, 100), (100, 0), (0, 100)]:
        polygon.Add(gp_Pnt(x, y, 0))
    polygon.Close()
    writer = STEPControl_Writer()
    writer.Transfer(BRepBuilderAPI_MakeFace(polygon.Wire(), True).Face(), STEPControl_AsIs)
    writer.Write(str(path))


def test_a_face_whose_boundary_crosses_itself_is_refused_naming_it(tmp_path, capfd, monkeypatch):
    """The STEP reader no longer repairs crossing wires (the repair is pairwise over a face's wires and took
    minutes on a plate of 5,000 holes), so the meshing checks them: a bow-tie face is refused at once, in
    one line naming the face, by load, flatten and the command line (it asked for 3e9 points and took the
    machine's memory).  Past the check (a wire of more edges than it looks at), the edge division refuses
    the face of no area before it allocates anything."""
    from patterns.tessellate import topology

    _bow_tie(tmp_path / "bow.step")
    with pytest.raises(patterns.CadError, match=r"bow.step: face 0's boundary crosses itself"):
        patterns.load(tmp_path / "bow.step")
    refused(["flatten", "bow.step", "-o", "bow.dxf"], tmp_path, capfd, "face 0's boundary crosses itself")
    monkeypatch.setattr(topology, "CHECKED_WIRE_EDGES", 0)
    with pytest.raises(patterns.CadError, match=r"bow.step: edge \d+ \(of face 0\) would be cut into .* pieces"):
        patterns.load(tmp_path / "bow.step")
