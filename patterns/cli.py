"""The ``patterns`` command line.

Subcommands::

    patterns flatten INPUT -o OUT.dxf [--profile machine|astm] [--method ...] [--max-edge MM]
                     [--seam-allowance MM] [--max-strain R] [--report OUT.json] [--preview OUT.png]
                     [--heat-map OUT.png]
    patterns check INPUT [--max-strain R] [--max-seam-mismatch MM] [--report OUT.json]
    patterns info INPUT
    patterns demo [-o DIR]
    patterns batch DIR -o OUTDIR [--jobs N] [--scheduler ADDRESS]
    patterns unfold PART.STEP -o BLANK.dxf [--k-factor K] [--bend-table CSV] [--fixed-face N]
                    [--report OUT.json] [--compare THEIRS.dxf]

Exit codes: 0 done, 1 the pattern fails a check the user asked for
(``--max-strain``, ``--max-seam-mismatch``) or has an overlap, 2 bad input or
usage (one line on stderr; ``--debug`` shows the traceback).  Heavy imports
happen inside the commands.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from .errors import InputError, PatternsError

__all__ = ["main"]

EXIT_OK, EXIT_CHECK, EXIT_INPUT = 0, 1, 2
"""Exit codes."""

OUTPUT_SUFFIXES = (".dxf", ".obj")


class Progress:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal."""

    def __init__(self, label: str, *, stream=None, enabled: bool | None = None):
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.label = label
        self._last = -1.0

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or total <= 0:
            return
        frac = min(max(done / total, 0.0), 1.0)
        if frac - self._last < 0.01 and frac < 1.0:
            return
        self._last = frac
        width = 30
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        self.stream.write(f"\r{self.label} [{bar}] {100 * frac:3.0f}%")
        if frac >= 1.0:
            self.stream.write("\n")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and 0 <= self._last < 1.0:
            self.stream.write("\n")
            self.stream.flush()


def _parser() -> argparse.ArgumentParser:
    from . import __version__
    from .audit import CheckOptions
    from .export.dxf import DxfOptions
    from .flattening import FlattenOptions
    from .flattening.sheetmetal import UnfoldOptions
    from .options import add_arguments
    from .reading import LoadOptions

    parser = argparse.ArgumentParser(
        prog="patterns", description="Flatten 3D surfaces (CAD or mesh) into true-scale 2D cutting patterns."
    )
    parser.add_argument("--version", action="version", version=f"patterns {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    # Every option flag below is made from the records the API validates with
    # (patterns.options): a new option there is a new flag here.
    def loading(p, *, positional=True):
        if positional:
            p.add_argument("input", type=Path,
                           help="CAD file (.step .stp .brep .iges .igs) or mesh file (.stl .obj .ply .off .3mf)")
        add_arguments(p.add_argument_group("loading"), LoadOptions)

    def flattening(p):
        add_arguments(p.add_argument_group("flattening"), FlattenOptions)

    def checking(p, *, report=True):
        group = p.add_argument_group("checking")
        add_arguments(group, CheckOptions)
        if report:
            group.add_argument("--report", type=Path, default=None, help="write the JSON report here")

    def output(p):
        group = p.add_argument_group("DXF output")
        add_arguments(group, DxfOptions, skip=("units",))  # --units: one flag with loading's
        group.add_argument("--roll-width", type=float, default=None, metavar="MM",
                           help="nest the panels on a roll this wide (mm) before writing; grain kept along the roll")

    flat = sub.add_parser("flatten", help="flatten a part and write its pattern (.dxf, or .obj for one panel)")
    flat.add_argument("-o", "--output", type=Path, required=True,
                      help="output: .dxf (the pattern for a cutter) or .obj (the flat mesh of a one-panel part)")
    flat.add_argument("--preview", type=Path, default=None, help="render the written DXF at 1:1 (.png or .svg)")
    flat.add_argument("--heat-map", type=Path, default=None, help="strain heat map (.png or .svg)")
    loading(flat)
    flattening(flat)
    checking(flat)
    output(flat)

    chk = sub.add_parser("check", help="flatten a part and report strain, seams and overlaps (no pattern file)")
    loading(chk)
    flattening(chk)
    checking(chk)

    info = sub.add_parser("info", help="list a part's panels, seams and areas (no flattening)")
    loading(info)

    demo = sub.add_parser("demo", help="run the whole pipeline on a bundled sample into ./patterns-demo/")
    demo.add_argument("-o", "--output", type=Path, default=Path("patterns-demo"), help="folder (default ./patterns-demo)")

    unf = sub.add_parser("unfold", help="unfold a bent sheet-metal part into one flat blank with bend lines (.dxf)")
    unf.add_argument("input", type=Path, help="the folded solid: CAD file (.step .stp .brep .iges .igs)")
    unf.add_argument("-o", "--output", type=Path, required=True, help="the blank, .dxf (CUT, BEND, LABEL layers)")
    add_arguments(unf.add_argument_group("unfolding"), UnfoldOptions)
    unf.add_argument("--report", type=Path, default=None, help="write the JSON report here (bends, size, usage)")
    unf.add_argument("--compare", type=Path, default=None, metavar="DXF",
                     help="a flat pattern of the same part from another CAD program: print how far ours lies from it")

    batch = sub.add_parser("batch", help="flatten every CAD and mesh file in a folder, in parallel")
    batch.add_argument("folder", type=Path, help="folder of input files (not searched recursively)")
    batch.add_argument("-o", "--output", type=Path, required=True, help="folder for the patterns and reports")
    batch.add_argument("--jobs", type=int, default=None, help="parallel processes (default: the CPU count)")
    batch.add_argument("--scheduler", default=None,
                       help="run on a Dask distributed cluster at this address (needs patterns[dask])")
    loading(batch, positional=False)
    flattening(batch)
    checking(batch, report=False)
    output(batch)
    return parser


def _records(args, name=None):
    """The option records (load, flatten, check, DXF) from parsed flags: each value checked as the API checks it."""
    from .audit import CheckOptions
    from .export.dxf import DxfOptions
    from .flattening import FlattenOptions
    from .options import from_arguments
    from .reading import LoadOptions

    records = {"load": from_arguments(LoadOptions, args, name=name)}
    if hasattr(args, "method"):
        records["flatten"] = from_arguments(FlattenOptions, args, name=name)
        records["check"] = from_arguments(CheckOptions, args, name=name)
    if hasattr(args, "profile"):
        records["dxf"] = from_arguments(DxfOptions, args, name=name)
    return records


# --------------------------------------------------------------------------- #
# The pipeline, shared by the commands
# --------------------------------------------------------------------------- #


def _load(path, records):
    from .reading import load

    model = load(path, records["load"])
    if model.bookkeeping.welded or model.bookkeeping.unused or model.bookkeeping.cuts:
        print(f"{path}: {model.bookkeeping}")
    return model


def _flatten(model, records):
    from .flattening import flatten

    progress = Progress(f"flattening {len(model.panels)} panels")
    try:
        return flatten(model, records["flatten"], progress=progress)
    finally:
        progress.close()


def _check(pattern, records):
    from .audit import check

    return check(pattern, records["check"])


def _print_panels(report, units_note=""):
    rows = [("panel", "triangles", "area 3D mm2", "area flat mm2", "strain RMS %", "max %", "p95 %", "one-to-one")]
    for p in report.panels:
        rows.append((p.name, str(p.n_triangles), f"{p.area_3d:.1f}", f"{p.area_flat:.1f}",
                     f"{100 * p.strain_rms:.2f}", f"{100 * p.strain_max:.2f}", f"{100 * p.strain_p95:.2f}",
                     "yes" if p.one_to_one else "NO"))
    _table(rows)
    if report.seams:
        rows = [("seam", "panels", "3D mm", "flat mm (side 0)", "flat mm (side 1)", "mismatch mm", "%")]
        for s in report.seams:
            rows.append((str(s.id), f"{s.panels[0]}/{s.panels[1]}", f"{s.length_3d:.2f}",
                         f"{s.length_flat[0]:.2f}", f"{s.length_flat[1]:.2f}", f"{s.mismatch:+.2f}",
                         f"{s.mismatch_percent:+.3f}"))
        _table(rows)


def _table(rows):
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())


def _verdict(report) -> int:
    print(str(report).splitlines()[0])
    for f in report.findings:
        print(f"  {f.severity.value}: {f.message}")
    return EXIT_OK if report.ok else EXIT_CHECK


# --------------------------------------------------------------------------- #
# Commands
# --------------------------------------------------------------------------- #


def _cmd_flatten(args) -> int:
    suffix = args.output.suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise InputError(f"{args.output}: unknown output type {suffix or '(none)'!r}; use .dxf or .obj")
    for label, value in (("--preview", args.preview), ("--heat-map", args.heat_map)):
        if value is not None and value.suffix.lower() not in (".png", ".svg"):
            raise InputError(f"{value}: {label} writes .png or .svg")
    records = _records(args, name=str(args.input))  # every option checked before any long work
    start = time.perf_counter()
    model = _load(args.input, records)
    loaded = time.perf_counter() - start
    if suffix == ".obj" and len(model.panels) != 1:
        raise InputError(f"{args.input}: {len(model.panels)} panels; a flat .obj holds one, write a .dxf")
    print(f"{args.input}: {len(model.panels)} panels, {len(model.seams)} seams "
          f"(target edge {model.max_edge:.3g} mm), loaded in {loaded:.2f} s")
    start = time.perf_counter()
    pattern = _flatten(model, records)
    print(f"flattened ({records['flatten'].method}) in {time.perf_counter() - start:.2f} s")
    if args.roll_width is not None:
        nest = pattern.layout(width=args.roll_width, margin=_margin(records["dxf"]))
        pattern = nest.pattern
        print(f"nested on a {args.roll_width:g} mm roll: {nest.length:.1f} mm used, efficiency {nest.efficiency:.1%}")
    report = _check(pattern, records)
    _print_panels(report)
    if suffix == ".dxf":
        pattern.to_dxf(args.output, records["dxf"])
        print(f"wrote {args.output} ({records['dxf'].profile} profile, {records['dxf'].units})")
    else:
        from .export import write_flat_obj

        flat = pattern.panels[0]
        write_flat_obj(args.output, flat.uv, flat.faces)
        print(f"wrote {args.output} (flat mesh, z = 0)")
    if args.report is not None:
        report.to_json(args.report)
        print(f"wrote {args.report}")
    if args.heat_map is not None:
        pattern.heat_map(args.heat_map)
        print(f"wrote {args.heat_map}")
    if args.preview is not None:
        if suffix != ".dxf":
            raise InputError(f"{args.preview}: --preview renders the DXF file; write a .dxf")
        from .export.preview import preview_dxf

        preview_dxf(args.output, args.preview)
        print(f"wrote {args.preview} (the DXF at 1:1)")
    return _verdict(report)


def _margin(dxf) -> float:
    """The largest seam allowance of the DXF options (the nesting margin), mm."""
    allowance = dxf.seam_allowance
    return max(allowance.values(), default=0.0) if isinstance(allowance, dict) else allowance


def _cmd_check(args) -> int:
    records = _records(args, name=str(args.input))
    model = _load(args.input, records)
    pattern = _flatten(model, records)
    report = _check(pattern, records)
    _print_panels(report)
    if args.report is not None:
        report.to_json(args.report)
        print(f"wrote {args.report}")
    return _verdict(report)


def _cmd_info(args) -> int:
    model = _load(args.input, _records(args, name=str(args.input)))
    print(f"{args.input}: {len(model.panels)} panels, {len(model.seams)} seams, target edge {model.max_edge:.3g} mm")
    rows = [("panel", "CAD faces", "vertices", "triangles", "outline loops", "area mm2")]
    for p in model.panels:
        rows.append((p.name, ",".join(map(str, p.cad_faces)) or "-", str(len(p.vertices)), str(len(p.faces)),
                     str(len(p.loops)), f"{p.area:.1f}"))
    _table(rows)
    if model.seams:
        rows = [("seam", "panels", "CAD edge", "length mm", "points")]
        for s in model.seams:
            rows.append((str(s.id), f"{model.panels[s.panels[0]].name}/{model.panels[s.panels[1]].name}",
                         "-" if s.cad_edge is None else str(s.cad_edge), f"{s.length:.3f}", str(len(s.points))))
        _table(rows)
    return EXIT_OK


def _cmd_demo(args) -> int:
    from build123d import export_step

    from .audit import check
    from .export.preview import preview_dxf
    from .flattening import flatten
    from .reading import load
    from .samples import cup

    out = args.output
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{out}: cannot create the demo folder ({exc.strerror})") from None
    step = out / "cup.step"
    export_step(cup(), step)
    model = load(step)
    pattern = flatten(model)
    report = check(pattern, max_strain=0.05)
    written = [(step, "the part: a hemisphere cup in four panels, built with build123d")]
    pattern.to_dxf(out / "cup.dxf", seam_allowance=10.0)
    written.append((out / "cup.dxf", "cutting pattern, machine profile, 10 mm seam allowance"))
    pattern.to_dxf(out / "cup_astm.dxf", profile="astm", seam_allowance=10.0)
    written.append((out / "cup_astm.dxf", "the same for garment CAD (ASTM D6673)"))
    report.to_json(out / "cup.json")
    written.append((out / "cup.json", "report: strain per panel, seam lengths on both sides, findings"))
    pattern.heat_map(out / "cup_heatmap.png")
    written.append((out / "cup_heatmap.png", "strain heat map"))
    preview_dxf(out / "cup.dxf", out / "cup_preview.png")
    written.append((out / "cup_preview.png", "the DXF rendered at 1:1 (96 dpi)"))
    _print_panels(report)
    _verdict(report)  # shows what a strain limit of 5 % finds on a sphere cut in quarters
    print(f"patterns demo: {len(model.panels)} panels, {len(model.seams)} seams; wrote:")
    for path, what in written:
        print(f"  {path}  {what}")
    return EXIT_OK


def _batch_one(path: str, out: str, records: dict, roll_width) -> dict:
    """Flatten one file into ``out``: a row of the batch summary.  Never raises."""
    from .audit import check
    from .flattening import flatten
    from .reading import load

    start = time.perf_counter()
    row = {"file": Path(path).name, "panels": None, "seams": None, "strain_rms": None, "strain_max": None,
           "status": "", "ok": False, "error": None, "seconds": None}
    try:
        model = load(path, records["load"])
        pattern = flatten(model, records["flatten"])
        if roll_width is not None:
            pattern = pattern.layout(width=roll_width, margin=_margin(records["dxf"])).pattern
        report = check(pattern, records["check"])
        stem = Path(out) / Path(path).stem
        pattern.to_dxf(stem.with_suffix(".dxf"), records["dxf"])
        report.to_json(stem.with_suffix(".json"))
        row.update(panels=len(model.panels), seams=len(model.seams),
                   strain_rms=max(p.strain_rms for p in report.panels),
                   strain_max=max(p.strain_max for p in report.panels), ok=report.ok,
                   status="ok" if report.ok else f"check failed: {report.findings[0].message}")
    except PatternsError as exc:
        row.update(status=f"error: {exc}", error=str(exc))
    except Exception as exc:  # noqa: BLE001 - one bad file must not stop the batch
        row.update(status=f"error: {type(exc).__name__}: {exc}", error=f"{type(exc).__name__}: {exc}")
    row["seconds"] = time.perf_counter() - start
    return row


def _cmd_batch(args) -> int:
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from .reading import CAD_SUFFIXES, MESH_SUFFIXES

    records = _records(args)  # every option checked before any file is read
    if not args.folder.is_dir():
        raise InputError(f"{args.folder}: no such folder")
    if args.jobs is not None and args.jobs < 1:
        raise InputError(f"--jobs must be at least 1, got {args.jobs}")
    files = sorted(p for p in args.folder.iterdir() if p.is_file() and p.suffix.lower() in CAD_SUFFIXES + MESH_SUFFIXES)
    if not files:
        raise InputError(f"{args.folder}: no CAD or mesh files in this folder")
    try:
        args.output.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{args.output}: cannot create the output folder ({exc.strerror})") from None
    progress = Progress(f"batch of {len(files)} files")
    rows = []
    if args.scheduler:
        try:
            from distributed import Client
            from distributed import as_completed as dask_completed
        except ImportError:
            raise InputError("--scheduler needs Dask: pip install 'patterns[dask]'") from None
        try:
            client = Client(args.scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"{args.scheduler}: cannot reach the Dask scheduler ({exc})") from None
        with client:
            futures = [client.submit(_batch_one, str(p), str(args.output), records, args.roll_width, pure=False) for p in files]
            for future in dask_completed(futures):
                rows.append(future.result())
                progress(len(rows), len(files))
        where = f"Dask scheduler {args.scheduler}"
    else:
        jobs = args.jobs or os.cpu_count() or 1
        with ProcessPoolExecutor(max_workers=min(jobs, len(files))) as pool:
            futures = [pool.submit(_batch_one, str(p), str(args.output), records, args.roll_width) for p in files]
            for future in as_completed(futures):
                rows.append(future.result())
                progress(len(rows), len(files))
        where = f"{min(jobs, len(files))} processes"
    progress.close()
    rows.sort(key=lambda r: r["file"])
    table = [("file", "panels", "seams", "strain RMS %", "max %", "seconds", "status")]
    for r in rows:
        table.append((r["file"], "-" if r["panels"] is None else str(r["panels"]),
                      "-" if r["seams"] is None else str(r["seams"]),
                      "-" if r["strain_rms"] is None else f"{100 * r['strain_rms']:.2f}",
                      "-" if r["strain_max"] is None else f"{100 * r['strain_max']:.2f}",
                      f"{r['seconds']:.1f}", r["status"]))
    _table(table)
    errors = [r for r in rows if r["error"]]
    failed = [r for r in rows if not r["error"] and not r["ok"]]
    print(f"batch: {len(rows) - len(errors)} results, {len(errors)} failed, {len(failed)} failing a check "
          f"({where}); wrote {args.output}")
    if errors:
        return EXIT_INPUT
    return EXIT_CHECK if failed else EXIT_OK


def _cmd_unfold(args) -> int:
    from .comparison import compare_blank, read_flat_pattern
    from .flattening.sheetmetal import UnfoldOptions, unfold
    from .options import from_arguments

    if args.output.suffix.lower() != ".dxf":
        raise InputError(f"{args.output}: unfold writes a .dxf blank")
    if args.report is not None and args.report.suffix.lower() != ".json":
        raise InputError(f"{args.report}: --report writes .json")
    written = [args.output] + ([args.report] if args.report is not None else [])
    for out in written:
        if out.resolve() == args.input.resolve() or (args.compare and out.resolve() == args.compare.resolve()):
            raise InputError(f"{out}: is an input of this run; name another output")
    if args.report is not None and args.report.resolve() == args.output.resolve():
        raise InputError(f"{args.report}: the report and the blank cannot be the same file")
    for out in written:
        if out.exists() and out.is_dir():
            raise InputError(f"{out}: is a folder; name a file")
        if not (out.parent if str(out.parent) else Path(".")).is_dir():
            raise InputError(f"{out}: folder {out.parent} does not exist")
    options = from_arguments(UnfoldOptions, args, name=str(args.input))  # the bend table read and checked here
    reference = read_flat_pattern(args.compare) if args.compare is not None else None
    start = time.perf_counter()
    blank = unfold(args.input, options)
    seconds = time.perf_counter() - start
    w, h = blank.size
    print(f"{args.input}: sheet {blank.thickness:g} mm, {len(blank.bends)} bends, {len(blank.holes)} holes; "
          f"blank {w:.2f} x {h:.2f} mm, area {blank.area:.1f} mm2, usage {blank.usage:.1%} (unfolded in "
          f"{seconds:.2f} s)")
    rows = [("bend", "direction", "angle deg", "inside R mm", "allowance mm")]
    rows += [(str(k), b.direction, f"{b.angle:.2f}", f"{b.inside_radius:g}", f"{b.allowance:.4f}")
             for k, b in enumerate(blank.bends)]
    if blank.bends:
        _table(rows)
    for f in blank.findings:
        print(f"  {'error' if f.error else 'warning'}: {f.message}")
    extra = {}
    if reference is not None:
        c = compare_blank(blank, reference)
        print(f"against {args.compare}: area {c.area_error:+.4%}, outer perimeter {c.perimeter - c.perimeter_reference:+.3f}"
              f" mm, holes {c.holes}/{c.holes_reference}, bend lines {c.bend_lines}/{c.bend_lines_reference}, outline "
              f"Hausdorff {c.hausdorff:.3f} mm ({c.within:.1%} of it within 0.1 mm)")
        extra["comparison"] = {"reference": str(args.compare), "area_error": c.area_error,
                               "perimeter_mm": c.perimeter, "perimeter_reference_mm": c.perimeter_reference,
                               "holes_reference": c.holes_reference, "bend_lines_reference": c.bend_lines_reference,
                               "hausdorff_mm": c.hausdorff, "hausdorff_all_mm": c.hausdorff_all,
                               "within_0.1mm": c.within, "mirrored": c.mirrored}
    if not blank.ok:
        print(f"{args.output}: not written (the blank cannot be cut as it is)")
        return EXIT_CHECK
    blank.to_dxf(args.output)
    print(f"wrote {args.output}")
    if args.report is not None:
        try:
            blank.to_json(args.report, extra=extra)
        except BaseException:
            args.output.unlink(missing_ok=True)  # a failed run leaves nothing
            raise
        print(f"wrote {args.report}")
    return EXIT_OK


COMMANDS = {"flatten": _cmd_flatten, "check": _cmd_check, "info": _cmd_info, "demo": _cmd_demo, "unfold": _cmd_unfold,
            "batch": _cmd_batch}


class _ClosedPipeSafe:
    """Standard output that outlives its reader.

    ``patterns flatten part.step | head -1`` closes the pipe after one line; the
    files must still be written and no traceback shown, so output to a closed
    pipe is dropped (and the descriptor pointed at ``/dev/null``, so that the
    interpreter's last flush is quiet too).
    """

    def __init__(self, stream):
        self._stream, self._gone = stream, False

    def write(self, text: str) -> int:
        if not self._gone:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self._close()
        return len(text)

    def flush(self) -> None:
        if not self._gone:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._close()

    def _close(self) -> None:
        self._gone = True
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())
        except (OSError, ValueError, AttributeError):  # not a real file (a test's capture)
            pass

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    """Run the command line; returns the exit code."""
    argv = sys.argv[1:] if argv is None else argv
    debug = "--debug" in argv
    stdout, sys.stdout = sys.stdout, _ClosedPipeSafe(sys.stdout)
    try:
        args = _parser().parse_args(argv)
        return COMMANDS[args.command](args)
    except PatternsError as exc:
        if debug:
            raise
        print(f"patterns: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:  # pragma: no cover
        return 130
    finally:
        sys.stdout.flush()
        sys.stdout = stdout


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
