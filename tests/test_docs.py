"""Every code block of README.md and docs/*.md runs, and every value its comments show is compared.

Python blocks of one file run in order in one namespace, in a fresh folder where
``samples/`` is the repository's (a block run alone, with ``-k`` or on another xdist worker,
first runs the file's earlier Python blocks); those of docs/freecad.md run so inside FreeCAD
(``freecadcmd``, the workbench installed by ``patterns freecad install`` as that page has a user do),
skipped where FreeCAD is absent.  Shell blocks run their ``patterns`` commands
with this interpreter's entry point and must exit 0 (or the code a ``# exit N``
comment gives).  JSON blocks must parse.  A block that cannot run in a test
says so in the markdown, on the line just before its fence::

    <!-- test: skip (needs a Dask scheduler) -->

and is reported as skipped with that reason.  ``<!-- test: slow -->`` marks a
long block with the ``slow`` marker.

**Values the comments show.**  In a Python block, a comment after the code of a line is a
*value* when it begins with a Python literal -- a number, a quote, ``[``, ``(``, ``{``, ``True``,
``False``, ``None`` -- or with a repr such as ``Model(`` (a capitalised name and a parenthesis);
any other comment is prose (``# or "part.step"``, ``# every panel flat, 1:1``, ``# about 3 s``).
The line's value is compared with it as the line runs (in a loop, the first time): an
expression's value, an assignment's assigned value, a ``print``'s arguments (the comment shows
them separated by spaces, as ``print`` writes them).  A number is compared to the digits it
shows (``328.0901`` means ``round(x, 4) == 328.0901``); ``...`` is a wildcard in a list, a
tuple, a string or a repr (whose text is matched against ``repr()``, ``str()`` for a ``print``'s
argument, numbers again to their digits); after the value may come a unit (``mm``, ``mm²``, ``%``, ``s``, ``°``) and then
prose after ``:``, ``;`` or ``,``.  A value comment the test cannot read fails, so a value
that cannot be compared exactly (a time, a nest's length after a time budget) is written as
prose: ``# about 3 s``, ``# a 900 mm roll: about 450 mm used``.  In a shell block written as
a transcript, the lines after a ``$ patterns ...`` line are its output: each is matched
against the command's output lines (stdout and stderr, in order) the same way, a line ``...``
standing for any number of lines.
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

from .docvalues import _checked_lines, _text_mismatch, run_python_block

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
            # one worker runs a file's blocks, in order (pytest -n with --dist loadgroup, as pyproject sets):
            # each block builds on the ones before it, which another worker would run again
            marks = [pytest.mark.xdist_group(path.name)] + ([pytest.mark.slow] if mark == "slow" else [])
            if mark == "skip":
                marks.append(pytest.mark.skip(reason=reason or "marked skip in the markdown"))
            yield pytest.param(path, line, lang, code, id=f"{path.relative_to(REPO)}:{line}", marks=marks)


def _host_block(code: str, line: int, page: str = "freecad.md") -> str:
    """The code a host's Python (freecadcmd, Blender's) runs for one block of its page: :func:`run_python_block`
    on it, from ``docvalues.py`` (the standard library only, as a host's own Python has it)."""
    return (f"if '__doc_run__' not in globals():\n"
            f"    import importlib.util as _u\n"
            f"    _spec = _u.spec_from_file_location('patterns_doc_values', {str(Path(__file__).parent / 'docvalues.py')!r})\n"
            f"    _m = _u.module_from_spec(_spec)\n"
            f"    __import__('sys').modules[_spec.name] = _m\n"
            f"    _spec.loader.exec_module(_m)\n"
            f"    __doc_run__ = _m.run_python_block\n"
            f"__doc_run__(globals(), {code!r}, {page!r}, {line})\n")


def _transcript(code: str):
    """``[(command, shown output lines or None)]`` of a shell block: a transcript's ``$`` lines and the lines
    after each; or every line a command when no line starts with ``$ ``."""
    lines = [x.rstrip() for x in code.splitlines()]
    if not any(x.startswith("$ ") for x in lines):
        return [(c, None) for c in (x.strip() for x in lines) if c and not c.startswith("#")]
    out = []
    for x in lines:
        if x.startswith("$ "):
            out.append((x[2:].strip(), []))
        elif out and x:
            out[-1][1].append(x)
    return [(c, shown or None) for c, shown in out]


def _output_mismatch(shown: list[str], lines: list[str]) -> str | None:
    """Why the output ``lines`` are not the ``shown`` ones (a line ``...``: any number of lines), or None."""
    if not shown:
        return None if not lines else f"{len(lines)} more lines than shown, from {lines[0]!r}"
    if shown[0].strip() == "...":
        rest = shown[1:]
        if not rest:
            return None
        if rest[0].strip() == "...":
            return _output_mismatch(rest, lines)
        starts = [k for k in range(len(lines)) if _text_mismatch(rest[0], lines[k]) is None]
        if not starts:
            return f"no output line is {rest[0]!r}"
        whys = [_output_mismatch(rest, lines[k:]) for k in starts]
        return None if None in whys else whys[0]
    if not lines:
        return f"the output ends before {shown[0]!r}"
    if (why := _text_mismatch(shown[0], lines[0])) is not None:
        return f"{shown[0]!r}: {why}"
    return _output_mismatch(shown[1:], lines[1:])


@pytest.fixture(scope="module")
def workdirs(tmp_path_factory):
    """One working folder, one namespace and the lines of the Python blocks run so far, per markdown file."""
    made = {}

    def get(path):
        if path not in made:
            folder = tmp_path_factory.mktemp(path.stem)
            (folder / "samples").symlink_to(REPO / "samples")
            made[path] = (folder, {"__name__": "__docs__"}, set())
        return made[path]

    return get


def _python_up_to(path: Path, line: int, workdirs) -> None:
    """Run the Python blocks of ``path`` up to the one at ``line`` that have not run in this process, in
    order: a block run alone (``-k``, another xdist worker) finds what the earlier blocks made."""
    folder, namespace, ran = workdirs(path)
    for start, lang, code, mark, _ in _blocks(path):
        if start > line:
            break
        if lang != "python" or mark == "skip" or start in ran:
            continue
        ran.add(start)
        old = Path.cwd()
        os.chdir(folder)
        try:
            run_python_block(namespace, code, path.name, start)
        except Exception as exc:
            if start == line:
                raise
            pytest.fail(f"the earlier block at {path.name}:{start}, run first, fails:\n{exc}")
        finally:
            os.chdir(old)


def _patterns_command() -> list[str]:
    return [sys.executable, "-m", "patterns"]


FREECAD_DOC = REPO / "docs" / "freecad.md"


@pytest.fixture(scope="module")
def freecad_blocks(tmp_path_factory):
    """Every Python block of docs/freecad.md run in order inside freecadcmd: ``{line: "ok" or traceback}``."""
    import shutil

    if shutil.which("freecadcmd") is None:
        from .test_dxf_pattern import _installed_by_ci

        if "freecad" in _installed_by_ci():
            pytest.fail("freecadcmd is missing although .ci/run installed FreeCAD")
        pytest.skip("FreeCAD is not installed (.ci/run installs it with apt-get)")
    folder = tmp_path_factory.mktemp("freecad-docs")
    (folder / "samples").symlink_to(REPO / "samples")
    user = folder / "freecad-user"  # the workbench installed as docs/freecad.md has a user install it
    subprocess.run([*_patterns_command(), "freecad", "install", "--user-dir", str(user)], check=True,
                   capture_output=True, timeout=120)
    blocks = [(line, _host_block(code, line)) for line, lang, code, mark, _ in _blocks(FREECAD_DOC)
              if lang == "python" and mark != "skip"]
    (folder / "blocks.json").write_text(json.dumps(blocks))
    env = dict(os.environ, FREECAD_USER_HOME=str(user), BLOCKS=str(folder / "blocks.json"),
               OUT=str(folder / "out.json"), HOME=str(folder))
    env.pop("PATTERNS_ENGINE", None)
    proc = subprocess.run(["freecadcmd", str(Path(__file__).parent / "readers" / "freecad_docs_run.py")], cwd=folder,
                          capture_output=True, text=True, env=env, timeout=900, check=False)
    assert (folder / "out.json").exists(), proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads((folder / "out.json").read_text())


BLENDER_DOC = REPO / "docs" / "blender.md"


@pytest.fixture(scope="module")
def blender_blocks(tmp_path_factory):
    """Every Python block of docs/blender.md run in order in Blender's Python (bpy), the add-on installed by
    ``patterns blender install --target``: ``{line: "ok" or traceback}``."""
    from .test_blender import _blender_python

    python = _blender_python()
    folder = tmp_path_factory.mktemp("blender-docs")
    (folder / "samples").symlink_to(REPO / "samples")
    scripts = folder / "scripts"
    subprocess.run([*_patterns_command(), "blender", "install", "--target", str(scripts / "addons")], check=True,
                   capture_output=True, timeout=120)
    blocks = [(line, _host_block(code, line, "blender.md")) for line, lang, code, mark, _ in _blocks(BLENDER_DOC)
              if lang == "python" and mark != "skip"]
    (folder / "blocks.json").write_text(json.dumps(blocks))
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(scripts), BLOCKS=str(folder / "blocks.json"),
               OUT=str(folder / "out.json"), HOME=str(folder))
    for name in ("PATTERNS_ENGINE", "PYTHONPATH", "VIRTUAL_ENV"):
        env.pop(name, None)
    proc = subprocess.run([str(python), str(Path(__file__).parent / "readers" / "blender_docs_run.py")], cwd=folder,
                          capture_output=True, text=True, env=env, timeout=1200, check=False)
    assert (folder / "out.json").exists(), proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads((folder / "out.json").read_text())


@pytest.mark.parametrize(("path", "line", "lang", "code"), list(_cases()))
def test_code_block_runs(path, line, lang, code, workdirs, request):
    if lang == "python" and path in (FREECAD_DOC, BLENDER_DOC):
        result = request.getfixturevalue("freecad_blocks" if path == FREECAD_DOC else "blender_blocks")[str(line)]
        assert result == "ok", result
    elif lang == "python":
        _python_up_to(path, line, workdirs)
    elif lang in ("bash", "sh", "console", "shell", ""):
        runnable = [(c, shown) for c, shown in _transcript(code) if c.split()[0] in ("patterns", ".venv/bin/patterns")]
        if not runnable:
            pytest.skip("no patterns command in this block (output shown, or set-up commands)")
        _python_up_to(path, line, workdirs)  # the files the earlier blocks wrote
        folder = workdirs(path)[0]
        for command, shown in runnable:
            text, _, comment = command.partition("#")
            want = int(m.group(1)) if (m := re.search(r"exit (?:code )?(\d)", comment)) else 0
            argv = _patterns_command() + shlex.split(text)[1:]
            env = dict(os.environ, FREECAD_USER_HOME=str(folder / "freecad-user"))  # `patterns freecad install`
            proc = subprocess.run(argv, cwd=folder, stdout=subprocess.PIPE, text=True, timeout=600, check=False,
                                  stderr=subprocess.STDOUT if shown else subprocess.PIPE, env=env)
            output = proc.stdout + (proc.stderr or "")
            assert proc.returncode == want, f"{command}: exit {proc.returncode}\n{output[-3000:]}"
            assert "Traceback" not in output
            if shown:
                why = _output_mismatch(shown, proc.stdout.splitlines())
                assert why is None, f"{path.name}:{line}: `{command}` does not print what the block shows: {why}" \
                                    f"\n--- it prints:\n{proc.stdout}"
    elif lang == "json":
        json.loads(code)
    else:
        pytest.skip(f"a {lang} block")


def _python_blocks():
    for path in FILES:
        for line, lang, code, mark, _ in _blocks(path):
            if lang == "python" and mark != "skip":
                yield path, line, code


def test_every_value_comment_is_read():
    """Every comment that begins like a value reads as one and sits on a line that has a value."""
    errors, count = [], 0
    for path, line, code in _python_blocks():
        try:
            count += len(_checked_lines(code, path.name, line)[1])
        except (ValueError, SyntaxError) as exc:
            errors.append(str(exc))
    assert not errors, "\n".join(errors)
    assert count >= 37, f"only {count} value comments found (37 in issue 34): is the convention still recognised?"


@pytest.mark.parametrize(("line", "comment", "right"), [
    ("x = 328.09012; x", "# 328.0901", True),
    ("x = 328.09012; x", "# 328.0902", False),
    ("x = 328.09012; x", "# 328.09 mm", True),
    ("x = 328.09012; x", "# 328.1 mm²: prose after a colon", True),
    ("x = 5; x", "# 5.0", True),
    ("x = True; x", "# 1", False),
    ("x = 1; x", "# True", False),
    ("x = [('a', 1.04), ('b', 2.0), ('c', 3.0)]; x", "# [('a', 1.0), ...]", True),
    ("x = [('a', 1.04), ('b', 2.0), ('c', 3.0)]; x", "# [('a', 1.0), ..., ('c', 3.0)]", True),
    ("x = [('a', 1.04), ('b', 2.0), ('c', 3.0)]; x", "# [('a', 1.0), ..., ('b', 3.0)]", False),
    ("x = [1.0, 2.0]; x", "# [1.0]", False),
    ("x = [1.0, 2.0]; x", "# (1.0, 2.0)", False),
    ("import numpy as np; x = np.array([1.0, 2.25]); x", "# (1.0, 2.2)", True),
    ("x = 'panel face0: strain above 3.00% on 84.8% of its area'; x", "# 'panel face0: ... 84.8% ...'", True),
    ("x = 'panel face0: strain above 3.00% on 84.8% of its area'; x", "# 'panel face1: ...'", False),
    ("x = (2.0, [100.0, 112.1894]); x", "# 2.0, [100.0, 112.189]: 50 + 2 x 25", True),
    ("x = 7", "# 7: an assignment's value", True),
    ("x = 7", "# 8", False),
    ("print((0, 1), 328.09012, 'one')", "# (0, 1) 328.0901 'one'", True),
    ("print((0, 1), 328.09012, 'one')", "# (0, 1) 328.0901", False),
    ("from fractions import Fraction as F; x = F(1, 3); x", "# Fraction(1, 3)", True),
    ("from fractions import Fraction as F; x = F(1, 3); x", "# Fraction(1, ...)", True),
    ("from fractions import Fraction as F; x = F(1, 3); x", "# Fraction(2, 3)", False),
    ("x = 1; x", "# about 1 s", True),  # prose: not compared
])
def test_the_value_convention(line, comment, right):
    """The comparisons the doc tests make, on small blocks: right values pass, a digit off fails."""
    code = line + "   " + comment
    if right:
        run_python_block({}, code, "test.md", 1)
    else:
        with pytest.raises(AssertionError, match="not what the comments show"):
            run_python_block({}, code, "test.md", 1)


@pytest.mark.parametrize("comment", ["# 12 pieces, 12 seams", "# (n, 3) mm", "# False if it folds"])
def test_a_value_comment_that_cannot_be_read_fails(comment):
    with pytest.raises(ValueError):
        _checked_lines(f"x = 1; x   {comment}", "test.md", 1)


def test_output_lines_are_compared():
    shown = ["cup.step: NOT ok (4 panels, 4 seams, 4 findings)", "...", "  limit: ... up to 12.47% ..."]
    out = ["panel  triangles", "cup.step: NOT ok (4 panels, 4 seams, 4 findings)", "  limit: a",
           "  limit: b, up to 12.4702% at (1, 2) mm", "done"]
    assert _output_mismatch(shown, out[1:]) is not None  # "done" is not shown
    assert _output_mismatch([*shown, "..."], out[1:]) is None
    assert _output_mismatch(["...", *shown, "..."], out) is None
    assert _output_mismatch(["...", shown[0].replace("4 findings", "5 findings"), "..."], out) is not None


@pytest.mark.slow
def test_the_demo_says_its_limit_and_why(tmp_path):
    """``patterns demo`` says first the strain limit it checks against, then why the cup exceeds it, and a
    command that brings the cup within it -- which does (issue 34)."""
    def run(*argv):
        return subprocess.run(_patterns_command() + list(argv), cwd=tmp_path, capture_output=True, text=True,
                              timeout=600, check=False)

    demo = run("demo", "-o", "out")
    assert demo.returncode == 0, demo.stderr
    lines = demo.stdout.splitlines()
    assert "checked against a strain limit of 5 % (as --max-strain 0.05 would)" in lines[0]
    verdict = lines.index("cup.step: NOT ok (4 panels, 4 seams, 4 findings)")
    why = next(i for i, x in enumerate(lines) if x.startswith("why: "))
    assert why > verdict
    assert "a doubly curved panel cannot lie flat without stretching" in lines[why]
    assert "up to 12.47 %, above the 5 % limit" in lines[why]
    argv = shlex.split(lines[why + 1])
    assert argv[:3] == ["patterns", "flatten", "out/cup.step"] and "--gores" in argv, argv
    assert argv[argv.index("--max-strain") + 1] == "0.05"
    within = run(*argv[1:])
    assert within.returncode == 0, within.stdout + within.stderr
    assert "cup.step: ok (" in within.stdout


@pytest.mark.parametrize("command", ["flatten", "batch", "unfold", "freecad", "blender"])
def test_every_flag_is_in_the_cli_doc(command):
    """docs/cli.md names every flag the command has (the flags come from the option records)."""
    from patterns import cli

    parser = cli._parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    text = (REPO / "docs" / "cli.md").read_text()
    missing = [s for a in sub._actions for s in a.option_strings if s.startswith("--") and s != "--help"
               and f"`{s}" not in text]
    assert not missing, f"docs/cli.md lacks {missing}"
