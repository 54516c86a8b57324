"""Seam-true flattening (issue 16): seams as long flat as in 3D, both sides equal, strain within 1.3 x free.

Run from the repository root::

    python benchmarks/seams.py                 # best of 3 times (about a minute)
    python benchmarks/seams.py --quick         # timed once
    python benchmarks/seams.py --markdown > seams.md
    python benchmarks/seams.py --max-edge 3    # finer panels (patterns.load's max_edge, mm)

Models (``patterns.load``, default meshing unless ``--max-edge``)
-----------------------------------------------------------------
* ``cup``: ``samples/cup.step``: four freeform gores of a cup, four seams.
* ``bowl``: a 90-degree segment of a bowl (``patterns.samples.bowl_segment``): the spline
  through (0, 0), (80, 25), (150, 100) (tangents (1, 0) and (0.4, 1)) in the XZ
  plane, closed by the straight lines to (0, 100) and back to (0, 0), revolved
  90 degrees about z.  One freeform face (the revolved spline) meets three
  planar faces developed exactly: the top quarter disk (the rim seam, a quarter
  circle of radius 150 mm: 235.62 mm) and the two end faces.
* ``gores``: a sphere of radius 100 mm split by the planes XZ and YZ into four
  gores, pole to pole, the four spherical faces as panels (four seams of
  314.16 mm).

Each model is flattened by ``patterns.flatten(model, seams=...)`` with
``"free"`` (the least-strain boundary: the reference), ``"total"`` (each seam
side's total length held) and ``"true"`` (every seam edge held; the default),
timed (best of 3; once with ``--quick``), and checked by ``patterns.check``.

Printed
-------
* per seam: the 3D length (the CAD edge's), the 3D polyline length (what is
  held), the flat length of each side, each side's error against the 3D
  length in %, and the difference between the two sides in mm;
* per panel: its kind (``freeform`` or the exactly developed surface), one-to-one,
  the area-weighted principal-strain RMS and its ratio to the ``"free"``
  result's for the same panel, the energy and iterations of the relaxation;
* per model and option: time, the worst numbers, the verdicts, and the
  findings of ``check`` other than notes.

Criteria (judged for ``"true"`` and ``"total"``; ``"free"`` shown, not judged):
every seam side within 0.2 % of its 3D length; the two sides of every seam
within 0.2 mm; every panel one-to-one; every panel's strain RMS <= 1.3 x the
``"free"`` result's (a panel with no strain free -- an exact development -- must
stay without: below 1e-9).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_flatten as bench

import patterns
from patterns.samples import bowl_segment, sphere_gores

REPO = Path(__file__).resolve().parent.parent

OPTIONS = ("free", "total", "true")
"""The ``seams`` options of :func:`patterns.flatten`, the reference first."""

JUDGED = ("total", "true")
"""The options judged on the criteria."""

ACCEPT_LENGTH = 0.002
"""Every seam side's flat length within 0.2 % of its 3D length."""

ACCEPT_MISMATCH = 0.2
"""The two sides of a seam within 0.2 mm of each other."""

ACCEPT_STRAIN_RATIO = 1.3
"""Every panel's strain RMS at most 1.3 x the free result's."""

EXACT = 1e-9
"""A panel's strain RMS below this counts as none (an exact development)."""


# --------------------------------------------------------------------------- #
# Models
# --------------------------------------------------------------------------- #


def models(max_edge: float | None):
    """``(name, patterns.Model)`` of the three models."""
    sources = {"cup": REPO / "samples" / "cup.step", "bowl": bowl_segment(), "gores": sphere_gores()}
    return [(name, patterns.load(source, max_edge=max_edge)) for name, source in sources.items()]


# --------------------------------------------------------------------------- #
# Running and judging
# --------------------------------------------------------------------------- #


@dataclass
class Run:
    """One model flattened with one ``seams`` option.

    Attributes
    ----------
    model : str
    option : str
    seconds : float
    report : patterns.Report
    kinds : dict
        Panel name to its kind (``freeform`` or the surface kind).
    """

    model: str
    option: str
    seconds: float
    report: object
    kinds: dict


def run(name: str, model, option: str, repeats: int) -> Run:
    """Flatten ``model`` with ``seams=option`` (best of ``repeats`` times) and check it."""
    print(f"  {name}: seams={option} ...", file=sys.stderr, flush=True)
    seconds, pattern = bench.best_of(lambda: patterns.flatten(model, seams=option), repeats)
    kinds = {p.name: (p.surface.kind.value if p.surface is not None else "freeform") for p in model.panels}
    return Run(name, option, seconds, patterns.check(pattern), kinds)


def seam_numbers(seam) -> tuple[list[float], float]:
    """Each side's error against the 3D length (ratio - 1), and the sides' difference in mm."""
    errors = [flat / seam.length_3d - 1.0 for flat in seam.length_flat]
    return errors, float(seam.length_flat[0] - seam.length_flat[1])


def strain_ratio(panel, free_panel) -> float | None:
    """``panel``'s strain RMS over the free result's; None where the free one has none (exact)."""
    if free_panel is None or free_panel.strain_rms < EXACT:
        return None
    return panel.strain_rms / free_panel.strain_rms


def strain_ok(panel, free_panel) -> bool:
    """Strain RMS within 1.3 x the free result's (or none where the free one has none)."""
    ratio = strain_ratio(panel, free_panel)
    if ratio is None:
        return free_panel is not None and panel.strain_rms < EXACT
    return ratio <= ACCEPT_STRAIN_RATIO


def verdicts(r: Run, free: Run) -> dict[str, bool]:
    """The criteria of one run: seam lengths, seam sides, one-to-one, strain against free."""
    errors, mismatches = [], []
    for seam in r.report.seams:
        e, m = seam_numbers(seam)
        errors += e
        mismatches.append(m)
    free_panels = {p.name: p for p in free.report.panels}
    return {
        "length": all(abs(e) <= ACCEPT_LENGTH for e in errors),
        "sides": all(abs(m) <= ACCEPT_MISMATCH for m in mismatches),
        "1:1": all(p.one_to_one for p in r.report.panels),
        "strain": all(strain_ok(p, free_panels.get(p.name)) for p in r.report.panels),
    }


CRITERIA = {
    "length": f"every seam side's flat length within {100 * ACCEPT_LENGTH:g} % of its 3D length",
    "sides": f"the two sides of every seam within {ACCEPT_MISMATCH:g} mm",
    "1:1": "every panel one-to-one",
    "strain": f"every panel's strain RMS <= {ACCEPT_STRAIN_RATIO} x the free result's (none where free has none)",
}
"""The short names of the criteria in the tables, and what they mean."""


# --------------------------------------------------------------------------- #
# Tables
# --------------------------------------------------------------------------- #


def _verdict(ok: bool | None) -> str:
    return {True: "PASS", False: "FAIL", None: "n/a"}[ok]


def seams_table(runs: list[Run], markdown: bool) -> str:
    """One row per seam of every run."""
    header = ("model", "seams=", "seam", "panels", "3D mm", "3D polyline mm", "flat side 0 mm", "flat side 1 mm",
              "error % side 0 / 1", f"<= {100 * ACCEPT_LENGTH:g} %", "sides differ mm", f"<= {ACCEPT_MISMATCH:g} mm")
    rows = []
    for r in runs:
        for s in r.report.seams:
            errors, mismatch = seam_numbers(s)
            rows.append([r.model, r.option, s.id, " / ".join(s.panels), f"{s.length_3d:.3f}",
                         f"{s.length_3d_polyline:.3f}", f"{s.length_flat[0]:.3f}", f"{s.length_flat[1]:.3f}",
                         " / ".join(f"{100 * e:+.3f}" for e in errors),
                         _verdict(all(abs(e) <= ACCEPT_LENGTH for e in errors)), f"{mismatch:+.3f}",
                         _verdict(abs(mismatch) <= ACCEPT_MISMATCH)])
    return bench.format_table(header, rows, markdown)


def panels_table(runs: list[Run], markdown: bool) -> str:
    """One row per panel of every run, with its strain against the free result's."""
    free = {r.model: {p.name: p for p in r.report.panels} for r in runs if r.option == "free"}
    header = ("model", "seams=", "panel", "kind", "triangles", "one-to-one", "strain RMS %", "/ free",
              f"<= {ACCEPT_STRAIN_RATIO}", "energy, iterations")
    rows = []
    for r in runs:
        for p in r.report.panels:
            ref = free.get(r.model, {}).get(p.name)
            ratio = strain_ratio(p, ref)
            relax = f"{p.energy}, {p.iterations}" + ("" if p.converged else ", not converged") if p.energy else "exact"
            rows.append([r.model, r.option, p.name, r.kinds.get(p.name, "?"), p.n_triangles,
                         "yes" if p.one_to_one else "no", f"{100 * p.strain_rms:.4g}",
                         "-" if r.option == "free" else ("exact" if ratio is None else f"{ratio:.3f}"),
                         "-" if r.option == "free" else _verdict(strain_ok(p, ref)), relax])
    return bench.format_table(header, rows, markdown)


def summary_table(runs: list[Run], markdown: bool) -> tuple[str, dict[str, list[bool]]]:
    """One row per run: time, worst numbers, verdicts, findings; and the verdicts of the judged runs."""
    free = {r.model: r for r in runs if r.option == "free"}
    header = ("model", "seams=", "seconds", "worst seam error %", "worst sides difference mm",
              "worst strain / free", "verdicts", "findings (not notes)")
    rows, counts = [], {}
    for r in runs:
        worst_error = max(abs(e) for s in r.report.seams for e in seam_numbers(s)[0])
        worst_mismatch = max(abs(seam_numbers(s)[1]) for s in r.report.seams)
        free_panels = {p.name: p for p in free[r.model].report.panels}
        ratios = [x for p in r.report.panels if (x := strain_ratio(p, free_panels.get(p.name))) is not None]
        found = [f"{f.code.value}" for f in r.report.findings if f.severity.value != "note"]
        v = verdicts(r, free[r.model])
        if r.option in JUDGED:
            for key, ok in v.items():
                counts.setdefault(f"seams={r.option}: {CRITERIA[key]}", []).append(ok)
        text = ", ".join(f"{k} {_verdict(ok)}" for k, ok in v.items())
        rows.append([r.model, r.option, f"{r.seconds:.3f}", f"{100 * worst_error:.3f}", f"{worst_mismatch:.3f}",
                     bench._number(max(ratios, default=None), ".3f"),
                     text if r.option in JUDGED else f"(not judged) {text}", ", ".join(found) or "none"])
    return bench.format_table(header, rows, markdown), counts


# --------------------------------------------------------------------------- #
# Driver
# --------------------------------------------------------------------------- #


def main(argv=None) -> int:
    """Command-line entry point; see ``--help``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="time each flattening once (default best of 3)")
    parser.add_argument("--max-edge", type=float, default=None,
                        help="patterns.load's max_edge, mm (default: its own, about 4000 triangles a part)")
    parser.add_argument("--markdown", action="store_true", help="print markdown tables")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else 3
    print(bench.machine_summary())
    runs = []
    for name, model in models(args.max_edge):
        print(f"{name}: {model!r}")
        for option in OPTIONS:
            runs.append(run(name, model, option, repeats))
    bullet = "* " if args.markdown else ""
    for title, text in (("Seams", seams_table(runs, args.markdown)),
                        ("Panels", panels_table(runs, args.markdown))):
        print(f"\n### {title}\n" if args.markdown else f"\n== {title} ==")
        print(text)
    table, counts = summary_table(runs, args.markdown)
    print("\n### Per model and option\n" if args.markdown else "\n== Per model and option ==")
    print("\n".join(f"{bullet}{key}: {text}" for key, text in CRITERIA.items()) + "\n")
    print(table)
    print("\n### PASS/FAIL\n" if args.markdown else "\n== PASS/FAIL ==")
    for key, values in counts.items():
        print(f"{bullet}{key}: PASS on {values.count(True)}, FAIL on {values.count(False)} of {len(values)} models")
    return 0


if __name__ == "__main__":
    sys.exit(main())
