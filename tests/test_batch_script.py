"""``patterns.batch`` as a user's plain script calls it, and the batch's own bookkeeping: the names its outputs
get (apart on a case-insensitive disk), the row of a part whose results cannot be written, a file given where a
folder is wanted."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap

import pytest

import patterns
from patterns import cli
from patterns.batching import output_stems

from .conftest import SAMPLES

SCRIPT = textwrap.dedent("""\
    import json

    import patterns

    with open("runs.txt", "a") as log:  # the top level: run once, by the user, never again in a worker
        log.write("ran\\n")
    rows = patterns.batch("in", "out", jobs=2)
    print("ROWS", json.dumps([(row.file, row.status) for row in rows.rows]))
""")


def _folder(path, names):
    """``path`` holding copies of samples: ``{name in the folder: sample}``."""
    path.mkdir()
    for name, sample in names.items():
        shutil.copy(SAMPLES / sample, path / name)
    return path


@pytest.mark.slow
def test_a_plain_script_with_no_main_guard_batches_and_runs_once(tmp_path):
    """Issue 34: a script calling ``patterns.batch(..., jobs=2)`` at its top level, with no
    ``if __name__ == "__main__":``, returns its rows; its workers never import it (under multiprocessing's
    spawn every worker ran it again and the batch failed, blaming memory)."""
    _folder(tmp_path / "in", {n: n for n in ("cone.obj", "dish.obj", "cup.step")})
    (tmp_path / "script.py").write_text(SCRIPT)
    proc = subprocess.run([sys.executable, "script.py"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=600, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    rows = json.loads(next(ln for ln in proc.stdout.splitlines() if ln.startswith("ROWS "))[5:])
    assert rows == [["cone.obj", "ok"], ["cup.step", "ok"], ["dish.obj", "ok"]]
    for stem in ("cone", "cup", "dish"):
        assert (tmp_path / "out" / f"{stem}.dxf").is_file() and (tmp_path / "out" / f"{stem}.json").is_file()
    assert (tmp_path / "runs.txt").read_text().splitlines() == ["ran"]
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize(("names", "stems"), [
    (["Part.step", "part.stl"], ["Part.step", "part.stl"]),       # one stem, case aside: whole names
    (["Part.step", "part.step"], ["Part.step", "part.step-2"]),   # one whole name, case aside: numbered
    (["a.STEP", "a.step", "b.obj"], ["a.STEP", "a.step-2", "b"]),
    (["x/a.step", "y/a.step"], ["a.step", "a.step-2"]),           # one name in two folders
    (["a.step", "a.stl", "a.step.obj"], ["a.step", "a.stl", "a.step.obj"]),  # a whole name meets a stem
    (["cup.step", "cup.obj", "cone.obj"], ["cup.step", "cup.obj", "cone"]),
])
def test_output_names_are_apart_on_a_case_insensitive_disk(names, stems):
    found = output_stems(names)
    assert [found[n] for n in names] == stems
    assert len({s.casefold() for s in found.values()}) == len(names)


@pytest.mark.slow
def test_names_that_differ_only_in_case_keep_their_own_results(tmp_path):
    """``Part.obj`` (the cone) and ``part.obj`` (the dish) in one folder of a case-sensitive disk: their results
    get names that differ also on a case-insensitive one (where ``Part.dxf`` and ``part.dxf`` are one file), and
    each report is its own part's."""
    _folder(tmp_path / "in", {"Part.obj": "cone.obj", "part.obj": "dish.obj"})
    result = patterns.batch(tmp_path / "in", tmp_path / "out", jobs=1)
    assert [(r.file, r.status) for r in result.rows] == [("Part.obj", "ok"), ("part.obj", "ok")]
    written = [name for row in result.rows for name in row.written]
    assert len(written) == 4 and len({name.casefold() for name in written}) == 4, written
    for row in result.rows:
        report = next(name for name in row.written if name.endswith(".json"))
        assert json.loads((tmp_path / "out" / report).read_text())["pattern"] == row.file
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(written)


@pytest.mark.slow
def test_a_part_whose_results_cannot_be_written_fails_with_the_reason(tmp_path):
    """A folder already named like the cone's DXF: the cone's row is ``failed`` and says why (nothing of it
    written, all or none), the dish is written, and the batch exits 2."""
    _folder(tmp_path / "in", {n: n for n in ("cone.obj", "dish.obj")})
    (tmp_path / "out" / "cone.dxf").mkdir(parents=True)
    result = patterns.batch(tmp_path / "in", tmp_path / "out", jobs=1)
    rows = {r.file: r for r in result.rows}
    assert rows["cone.obj"].status == "failed", rows["cone.obj"]
    assert rows["cone.obj"].reason.startswith("cannot write its results: ")
    assert "cone.dxf" in rows["cone.obj"].reason and "folder" in rows["cone.obj"].reason
    assert rows["cone.obj"].written == ()
    assert rows["dish.obj"].status == "ok" and rows["dish.obj"].written == ("dish.dxf", "dish.json")
    assert result.exit_code == 2
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["cone.dxf", "dish.dxf", "dish.json"]
    assert not any((tmp_path / "out" / "cone.dxf").iterdir())


def test_batch_of_a_file_says_it_takes_a_folder(tmp_path, capfd):
    """``patterns batch FILE``: one line saying the path is a file and batch takes a folder, exit 2, nothing
    written (it said "no such folder" for a file that exists)."""
    shutil.copy(SAMPLES / "cone.obj", tmp_path / "cone.obj")
    before = sorted(os.listdir(tmp_path))
    code = cli.main(["batch", str(tmp_path / "cone.obj"), "-o", str(tmp_path / "out")])
    err = capfd.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("patterns: error: "), err
    assert "cone.obj: is a file, not a folder; batch takes a folder" in lines[0]
    assert "no such folder" not in lines[0]
    assert sorted(os.listdir(tmp_path)) == before


@pytest.mark.parametrize(("last_words", "memory"), [
    ("ModuleNotFoundError: No module named 'build123d'", False),
    ("MemoryError", True),
    ("OSError: libTKernel.so.7.7: failed to map segment from shared object", True),
])
def test_a_worker_that_cannot_start_is_blamed_on_memory_only_when_memory_was_it(tmp_path, monkeypatch, last_words,
                                                                                 memory):
    """A worker's interpreter that dies at once, its last words on stderr: the batch stops with them, and advises
    more memory only when they name memory (it said "with --memory, give them more" whatever the cause)."""
    from patterns.batching import local
    from patterns.errors import PatternsError

    _folder(tmp_path / "in", {"cone.obj": "cone.obj"})
    python = tmp_path / "python3"
    python.write_text(f"#!/bin/sh\necho 'Traceback (most recent call last):' >&2\necho \"{last_words}\" >&2\nexit 1\n")
    python.chmod(0o755)
    monkeypatch.setattr(local, "_python", lambda: str(python))
    with pytest.raises(PatternsError) as caught:
        patterns.batch(tmp_path / "in", tmp_path / "out", jobs=1)
    message = str(caught.value)
    assert message.startswith(f"the worker processes cannot start (exit code 1: {last_words})"), message
    assert ("--memory" in message) == memory, message
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
