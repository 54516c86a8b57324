"""Every code block of README.md and docs/*.md runs, so the documentation cannot go stale.

Python blocks of one file run in order in one namespace, in a fresh folder where
``samples/`` is the repository's; those of docs/freecad.md run so inside FreeCAD (``freecadcmd``, this
interpreter's packages in front of its path, as that page has a user do), skipped where FreeCAD is
absent.  Shell blocks run their ``patterns`` commands
with this interpreter's entry point and must exit 0 (or the code a ``# exit N``
comment gives).  JSON blocks must parse.  A block that cannot run in a test
says so in the markdown, on the line just before its fence::

    <!-- test: skip (needs a Dask scheduler) -->

and is reported as skipped with that reason.  ``<!-- test: slow -->`` marks a
long block with the ``slow`` marker.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
FILES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
_FENCE = re.compile(r"^```(\w*)\s*$")
_MARK = re.compile(r"^<!--\s*test:\s*(skip|slow)\s*(?:\((.*)\))?\s*-->\s*$")


def _blocks(path: Path):
    """``(line, language, code, mark, reason)`` of every fenced block of a markdown file."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start, lang = i + 1, m.group(1).lower()
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        mark = _MARK.match(lines[i - 1]) if i > 0 else None
        out.append((start, lang, "\n".join(lines[i + 1:j]), mark and mark.group(1), mark and mark.group(2)))
        i = j + 1
    return out


def _cases():
    for path in FILES:
        for line, lang, code, mark, reason in _blocks(path):
            marks = [pytest.mark.slow] if mark == "slow" else []
            if mark == "skip":
                marks.append(pytest.mark.skip(reason=reason or "marked skip in the markdown"))
            yield pytest.param(path, line, lang, code, id=f"{path.relative_to(REPO)}:{line}", marks=marks)


@pytest.fixture(scope="module")
def workdirs(tmp_path_factory):
    """One working folder and one namespace per markdown file."""
    made = {}

    def get(path):
        if path not in made:
            folder = tmp_path_factory.mktemp(path.stem)
            (folder / "samples").symlink_to(REPO / "samples")
            made[path] = (folder, {"__name__": "__docs__"})
        return made[path]

    return get


def _patterns_command() -> list[str]:
    return [sys.executable, "-m", "patterns"]


FREECAD_DOC = REPO / "docs" / "freecad.md"


@pytest.fixture(scope="module")
def freecad_blocks(tmp_path_factory):
    """Every Python block of docs/freecad.md run in order inside freecadcmd: ``{line: "ok" or traceback}``."""
    import shutil
    import sysconfig

    if shutil.which("freecadcmd") is None:
        from .test_dxf_pattern import _installed_by_ci

        if "freecad" in _installed_by_ci():
            pytest.fail("freecadcmd is missing although .ci/run installed FreeCAD")
        pytest.skip("FreeCAD is not installed (.ci/run installs it with apt-get)")
    folder = tmp_path_factory.mktemp("freecad-docs")
    (folder / "samples").symlink_to(REPO / "samples")
    blocks = [(line, code) for line, lang, code, mark, _ in _blocks(FREECAD_DOC) if lang == "python" and mark != "skip"]
    (folder / "blocks.json").write_text(json.dumps(blocks))
    env = dict(os.environ, PATTERNS_SITE=sysconfig.get_paths()["purelib"], BLOCKS=str(folder / "blocks.json"),
               OUT=str(folder / "out.json"), HOME=str(folder))
    proc = subprocess.run(["freecadcmd", str(Path(__file__).parent / "readers" / "freecad_docs_run.py")], cwd=folder,
                          capture_output=True, text=True, env=env, timeout=900, check=False)
    assert (folder / "out.json").exists(), proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads((folder / "out.json").read_text())


@pytest.mark.parametrize(("path", "line", "lang", "code"), list(_cases()))
def test_code_block_runs(path, line, lang, code, workdirs, request):
    folder, namespace = workdirs(path)
    if lang == "python" and path == FREECAD_DOC:
        result = request.getfixturevalue("freecad_blocks")[str(line)]
        assert result == "ok", result
    elif lang == "python":
        old = Path.cwd()
        os.chdir(folder)
        try:
            exec(compile(code, f"{path.name}:{line}", "exec"), namespace)  # noqa: S102 - the docs' own code
        finally:
            os.chdir(old)
    elif lang in ("bash", "sh", "console", "shell", ""):
        commands = [c for c in (x.strip() for x in code.splitlines()) if c and not c.startswith("#")]
        commands = [c.removeprefix("$ ") for c in commands]
        runnable = [c for c in commands if c.split()[0] in ("patterns", ".venv/bin/patterns")]
        if not runnable:
            pytest.skip("no patterns command in this block (output shown, or set-up commands)")
        for command in runnable:
            text, _, comment = command.partition("#")
            want = int(m.group(1)) if (m := re.search(r"exit (?:code )?(\d)", comment)) else 0
            argv = _patterns_command() + shlex.split(text)[1:]
            proc = subprocess.run(argv, cwd=folder, capture_output=True, text=True, timeout=600)
            assert proc.returncode == want, f"{command}: exit {proc.returncode}\n{proc.stderr}"
            assert "Traceback" not in proc.stderr
    elif lang == "json":
        json.loads(code)
    else:
        pytest.skip(f"a {lang} block")


@pytest.mark.parametrize("command", ["flatten", "batch", "unfold"])
def test_every_flag_is_in_the_cli_doc(command):
    """docs/cli.md names every flag the command has (the flags come from the option records)."""
    from patterns import cli

    parser = cli._parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    text = (REPO / "docs" / "cli.md").read_text()
    missing = [s for a in sub._actions for s in a.option_strings if s.startswith("--") and s != "--help"
               and f"`{s}" not in text]
    assert not missing, f"docs/cli.md lacks {missing}"
