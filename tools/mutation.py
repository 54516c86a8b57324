"""Mutation testing of the numerical and export modules with mutmut: the score, and every survivor.

Usage (from the repository root; 20-60 minutes on two cores)::

    python tools/mutation.py                      # the five modules of docs/testing.md
    python tools/mutation.py patterns/measure.py  # one module

mutmut rewrites each function of a module into many small variants ("mutants":
a ``<`` made ``<=``, a constant changed, an argument dropped, ...) and runs the
tests that reach that function against each; a mutant no test notices
"survives".  The score is ``killed / (killed + survived)``, with a timeout
counted as killed (the tests noticed: they hung) -- and, beside it, the score among
the mutants a test decided (timeouts left out): mutmut also stops a mutant on wall
time ((its tests' time + 1 s) x the multiplier), and on a loaded machine, or where a
test's module fixture is paid again in the mutant's own process, that stops mutants
that did not hang.

mutmut imports the package from its own copy (``mutants/``), so it cannot run
where ``patterns`` is installed in editable mode: this script makes a separate
virtual environment (``.mutation-venv``, once: the dependencies from
pyproject.toml, mutmut, pytest) and runs in a copy of the repository (the
samples and tests go with it), so the working tree is never touched.
"""

from __future__ import annotations

import argparse
import fnmatch
import math
import random
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
VENV = REPO / ".mutation-venv"

MODULES = {  # the module mutated and the tests that answer for it (its unit tests and the quick stories)
    "patterns/measure.py": ["tests/test_measure.py", "tests/test_check.py"],
    "patterns/audit.py": ["tests/test_check.py", "tests/test_darts.py::test_the_report_and_the_dxf_list_every_dart"],
    "patterns/export/dxf.py": ["tests/test_dxf_pattern.py", "tests/test_export.py", "tests/test_garments.py",
                               "tests/test_sheet_metal.py::test_bend_lines_on_the_bend_layer",
                               "tests/test_darts.py::test_the_report_and_the_dxf_list_every_dart"],
    "patterns/flattening/develop.py": ["tests/test_develop.py",
                                       "tests/test_sheet_metal.py::test_cone_frustum_blank_is_the_analytic_annular_sector",
                                       "tests/test_sheet_metal.py::test_rolled_cylinder_blank_length_with_thickness_and_k_factor",
                                       "tests/test_sheet_metal.py::test_planar_faces_and_holes_unroll_exactly"],
    "patterns/nesting.py": ["tests/test_nesting.py"],
}

SKIP = "not librecad and not dxf2gcode and not freecad and not inkscape and not openscad"
"""The real readers' tests are left out of the mutation runs (seconds each, in a subprocess);
they read the same files the ezdxf tests check."""


def _venv() -> Path:
    python = VENV / "bin" / "python"
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    # every time (quick when nothing is missing): a dependency added since the venv was made
    meta = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    deps = meta["dependencies"] + meta["optional-dependencies"]["test"] + ["mutmut>=3.3"]
    subprocess.run([str(python), "-m", "pip", "install", "-q", *deps], check=True)
    return python


def _chosen(name: str, only) -> bool:
    return not only or any(fnmatch.fnmatchcase(name, pattern) for pattern in only)


def run(module: str, tests: list, python: Path, *, only=(), max_children=None, sample=None, seed=0,
        timeout_multiplier: float = 15.0, show_killed: bool = False) -> dict:
    """Run mutmut on one module in a copy of the repository: ``{"killed", "survived", "timeout", "survivors"}``.

    ``only``: mutant-name patterns (``patterns.export.dxf.x__notches__mutmut_*``) to run instead of
    every mutant of the module; ``max_children``: at most this many test processes at once;
    ``sample``: run a uniform random sample of this many of the mutants (``seed`` picks it) -- for a
    module whose tests are slow, an estimate of the score with its interval; ``timeout_multiplier``:
    mutmut's (a mutant is stopped, and counted killed, past ``2 x multiplier x`` its tests' CPU time);
    ``show_killed``: keep the diffs of the killed mutants too (to check a kill by hand).
    The slow tests are left out."""
    with tempfile.TemporaryDirectory(prefix="patterns-mutation-") as tmp:
        work = Path(tmp) / "repo"
        shutil.copytree(REPO, work, ignore=shutil.ignore_patterns(".git", ".venv", ".mutation-venv", "mutants",
                                                                   "__pycache__", "*.egg-info"))
        config = (f'\n[tool.mutmut]\nsource_paths = ["patterns"]\nonly_mutate = ["{module}"]\n'
                  f"pytest_add_cli_args_test_selection = {tests!r}\nmutate_only_covered_lines = true\n"
                  f"pytest_add_cli_args = {['-k', SKIP, '-m', 'not slow']!r}\n"
                  f"timeout_multiplier = {timeout_multiplier}\n"
                  # each mutant's tests in a process forked from a clean server, not from the one that
                  # ran the suite: forked from that one, a test that calls sparrow (its thread pool
                  # already started there) or a reader hangs, and counts as a timeout
                  'process_isolation = "forkserver"\n'
                  'also_copy = ["samples/", "docs/"]\n').replace("'", '"')
        with open(work / "pyproject.toml", "a") as fh:
            fh.write(config)
        mutmut = [str(python), "-m", "mutmut"]
        children = [] if max_children is None else ["--max-children", str(max_children)]
        total = None
        if sample:  # make the mutants (running none), then draw the sample from their names
            subprocess.run([*mutmut, "run", *children, "patterns.none-such"], cwd=work, capture_output=True)
            listing = subprocess.run([*mutmut, "results", "--all", "true"], cwd=work, capture_output=True,
                                     text=True).stdout
            names = sorted(n for n, _ in re.findall(r"^\s*(\S+): (.+)$", listing, flags=re.M) if _chosen(n, only))
            total = len(names)
            only = tuple(random.Random(seed).sample(names, min(sample, total)))
        done = subprocess.run([*mutmut, "run", *children, *only], cwd=work, capture_output=True, text=True)
        listing = subprocess.run([*mutmut, "results", "--all", "true"], cwd=work, capture_output=True,
                                 text=True).stdout
        shown = ("survived", "killed", "timeout") if show_killed else ("survived",)
        diffs = {name: subprocess.run([*mutmut, "show", name], cwd=work, capture_output=True, text=True).stdout
                 for name, state in re.findall(r"^\s*(\S+): (.+)$", listing, flags=re.M)
                 if state.strip() in shown and _chosen(name, only)}
    status = [(n, st) for n, st in re.findall(r"^\s*(\S+): (.+)$", listing, flags=re.M) if _chosen(n, only)]
    if not status or all(state.strip() not in ("killed", "survived", "timeout") for _, state in status):
        # mutmut stopped before mutating (its clean run of the tests failed, say): show why
        raise SystemExit(f"mutmut made no mutants of {module}:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    out = {"killed": 0, "survived": 0, "timeout": 0, "other": 0, "survivors": [], "diffs": diffs, "total": total}
    for name, state in status:
        key = {"killed": "killed", "survived": "survived", "timeout": "timeout"}.get(state.strip(), "other")
        out[key] += 1
        if key == "survived":
            out["survivors"].append(name)
        elif key in ("killed", "timeout"):
            out.setdefault("kills", []).append(name)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("modules", nargs="*", default=list(MODULES), help="modules (default: the five)")
    parser.add_argument("--only", nargs="+", default=(), metavar="PATTERN",
                        help="run only the mutants whose names match (fnmatch), e.g. 'patterns.export.dxf.x__notches__*'")
    parser.add_argument("--max-children", type=int, default=None, help="test processes at once (default: mutmut's)")
    parser.add_argument("--tests", nargs="+", default=None, metavar="TEST",
                        help="the tests that answer for the mutants (default: the module's, as listed in MODULES)")
    parser.add_argument("--sample", type=int, default=None, metavar="N",
                        help="run a uniform random sample of N mutants (an estimate, with its 95 %% interval)")
    parser.add_argument("--seed", type=int, default=0, help="the sample's seed")
    parser.add_argument("--show-killed", action="store_true",
                        help="print the killed mutants' diffs too (stderr), to check kills by hand")
    parser.add_argument("--timeout-multiplier", type=float, default=15.0,
                        help="mutmut's: a mutant past 2 x this x its tests' CPU time is stopped (killed)")
    args = parser.parse_args(argv)
    python = _venv()
    total_k = total_s = total_t = 0
    rows = []
    print("| module | mutants | killed by a test | stopped on time | survived | score | score, decided only |")
    print("|---|---|---|---|---|---|---|", flush=True)
    for module in args.modules:
        tests = args.tests or MODULES.get(module, ["tests/"])
        r = run(module, tests, python, only=args.only, max_children=args.max_children, sample=args.sample,
                seed=args.seed, timeout_multiplier=args.timeout_multiplier, show_killed=args.show_killed)
        killed = r["killed"] + r["timeout"]
        total_k, total_s, total_t = total_k + killed, total_s + r["survived"], total_t + r["timeout"]
        n = max(killed + r["survived"], 1)
        score = killed / n
        decided = r["killed"] / max(r["killed"] + r["survived"], 1)
        note = ""
        if r["total"] is not None:  # a sample: the normal interval of a proportion, finite population
            half = 1.96 * math.sqrt(score * (1 - score) / n * max(r["total"] - n, 0) / max(r["total"] - 1, 1))
            note = f" (a sample of {n} of {r['total']} mutants, seed {args.seed}; 95 % interval +-{half:.1%})"
        rows.append(f"| `{module}` | {killed + r['survived']} | {r['killed']} | {r['timeout']} | {r['survived']} | "
                    f"{score:.1%}{note} | {decided:.1%} |")
        print(rows[-1], flush=True)
        for name in r["survivors"]:
            print(f"survived: {name}\n{r['diffs'].get(name, '')}", file=sys.stderr, flush=True)
        for name in r.get("kills", []) if args.show_killed else ():
            print(f"killed: {name}\n{r['diffs'].get(name, '')}", file=sys.stderr, flush=True)
    print(f"| all | {total_k + total_s} | {total_k - total_t} | {total_t} | {total_s} | "
          f"{total_k / max(total_k + total_s, 1):.1%} | {(total_k - total_t) / max(total_k - total_t + total_s, 1):.1%} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
