"""The ``patterns`` command line.

Subcommands::

    patterns flatten INPUT -o OUT.dxf [--profile machine|astm] [--method ...] [--max-edge MM]
                     [--seam-allowance MM] [--max-strain R] [--report OUT.json] [--preview OUT.png]
                     [--heat-map OUT.png]
    patterns check INPUT [--max-strain R] [--max-seam-mismatch MM] [--report OUT.json]
    patterns info INPUT
    patterns demo [-o DIR]
    patterns serve                     (the engine for a CAD program: JSON lines, docs/worker.md)
    patterns freecad install|uninstall [--user-dir DIR]
    patterns batch DIR -o OUTDIR [--jobs N] [--scheduler ADDRESS] [--timeout S] [--report] [--preview]
                   [--unfold [--k-factor K | --bend-table CSV]]
    patterns unfold PART.STEP -o BLANK.dxf [--k-factor K | --bend-table CSV | --material NAME] [--fixed-face N]
                    [--report OUT.json] [--bend-sheet BENDS.csv] [--compare THEIRS.dxf] [--sheet LxW --copies N] [--layer-map MAP]

Every run plans, then works, then commits: every option, the input and every
output are checked before any work (one line, exit 2, nothing written); the
outputs are written as temporary files and renamed together at the end, so a
run that fails or is stopped (Ctrl-C, SIGTERM) leaves nothing behind.

Exit codes: 0 done, 1 the pattern is not usable or fails a check the user
asked for (``--max-strain``, ``--max-seam-mismatch``), 2 bad input or usage
(one line on stderr; ``--debug``, anywhere on the line, shows the traceback),
130 interrupted, 143 terminated.  Heavy imports happen inside the commands.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from . import signals
from .console import (
    EXIT_CHECK,
    EXIT_OK,
    Run,
    answered_from_index,
    batch_table,
    label_notes,
    loaded,
    nested,
    print_panels,
    table,
    verdict,
    wrote,
)
from .errors import InputError, PatternsError, Terminated
from .terminal import BatchProgress, Progress, Terminal, foreign_home
from .text import counted, printable
from .units import UNIT_NAMES

__all__ = ["main"]

EXIT_INPUT = 2
"""Exit codes."""
EXIT_INTERRUPTED, EXIT_TERMINATED = signals.EXIT_INTERRUPTED, signals.EXIT_TERMINATED
_SHOWN = 10  # places where a blank differs from --compare's drawing printed; the report has them all


DESCRIPTION = ("Flatten 3D surfaces (CAD or mesh) into true-scale 2D cutting patterns, and unfold bent sheet-metal "
               "parts into blanks.")

COMMAND_HELP = {
    "flatten": "flatten a part and write its pattern (.dxf, .svg, or .obj for one panel)",
    "check": "flatten a part and report strain, seams and overlaps (no pattern file)",
    "info": "list a part's panels, seams and areas (no flattening)",
    "demo": "run the whole pipeline on a bundled sample into ./patterns-demo/",
    "unfold": "unfold a bent sheet-metal part into one flat blank with bend lines (.dxf, .svg)",
    "batch": "flatten (or --unfold) every part in a folder, in parallel",
    "serve": "run the engine for a CAD program (FreeCAD's workbench): JSON lines on standard input and output "
             "(docs/worker.md)",
    "freecad": "put the Patterns workbench into FreeCAD (install), or take it out (uninstall); the engine stays in "
               "this environment",
    "blender": "put the Patterns add-on into Blender 4.2+ (install), or take it out (uninstall); the engine stays "
               "in this environment",
}
"""Each command's one line (``patterns --help``, answered without the engine)."""


class _Parser(argparse.ArgumentParser):
    """argparse, with its errors as one line (the valid choices included) and exit code 2."""

    def error(self, message: str):
        raise InputError(f"{message} ({self.prog} --help lists the options)")


def _parser() -> argparse.ArgumentParser:
    from . import __version__
    from .audit import CheckOptions
    from .batching import BatchOptions
    from .export import WriteOptions
    from .flattening import FlattenOptions
    from .nesting import NestOptions
    from .options import add_arguments
    from .pieces import PieceOptions
    from .pieces.options import PATTERN_ONLY
    from .reading import LoadOptions
    from .sheetmetal import UnfoldOptions

    parser = _Parser(prog="patterns", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"patterns {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors (anywhere on the line)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)

    # Every option flag below is made from the records the API validates with
    # (patterns.options): a new option there is a new flag here, in flatten, unfold and batch alike.
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
            group.add_argument("--report", type=Path, default=None,
                               help="write the JSON report here (the check and every piece, in the DXF's frame)")

    def output(p, *, blank=False):
        add_arguments(p.add_argument_group("pieces"), PieceOptions, skip=PATTERN_ONLY if blank else ())
        add_arguments(p.add_argument_group("output"), WriteOptions)
        add_arguments(p.add_argument_group("nesting (sparrow)"), NestOptions)

    flat = sub.add_parser("flatten", help=COMMAND_HELP["flatten"])
    flat.add_argument("-o", "--output", type=Path, required=True,
                      help="output: .dxf (the pattern for a cutter), .svg (1:1 for laser and vinyl cutters) or .obj "
                           "(the flat mesh of a one-panel part)")
    flat.add_argument("--preview", type=Path, default=None, help="render the written DXF at 1:1 (.png or .svg)")
    flat.add_argument("--heat-map", type=Path, default=None, help="strain heat map (.png or .svg)")
    loading(flat)
    flattening(flat)
    checking(flat)
    output(flat)

    chk = sub.add_parser("check", help=COMMAND_HELP["check"])
    chk.add_argument("--heat-map", type=Path, default=None, help="strain heat map (.png or .svg)")
    loading(chk)
    chk.add_argument("--units", choices=UNIT_NAMES, default=None,
                     help="deprecated (goes in 0.3.0): --input-units")
    flattening(chk)
    checking(chk)

    info = sub.add_parser("info", help=COMMAND_HELP["info"])
    loading(info)
    info.add_argument("--units", choices=UNIT_NAMES, default=None,
                      help="deprecated (goes in 0.3.0): --input-units")

    demo = sub.add_parser("demo", help=COMMAND_HELP["demo"])
    demo.add_argument("-o", "--output", type=Path, default=Path("patterns-demo"), help="folder (default ./patterns-demo)")

    unf = sub.add_parser("unfold", help=COMMAND_HELP["unfold"])
    unf.add_argument("input", type=Path, help="the folded solid: CAD file (.step .stp .brep .iges .igs)")
    unf.add_argument("-o", "--output", type=Path, required=True,
                     help="the blank: .dxf (outline, holes, bend lines, labels) or .svg")
    add_arguments(unf.add_argument_group("unfolding"), UnfoldOptions)
    unf.add_argument("--report", type=Path, default=None,
                     help="write the JSON report here (bends, size, usage, the blank as drawn, in the DXF's frame)")
    unf.add_argument("--preview", type=Path, default=None, help="render the written DXF at 1:1 (.png or .svg)")
    unf.add_argument("--bend-sheet", type=Path, default=None, metavar="CSV",
                     help="write the bend sheet for the press brake here (.csv): a row per bend in the order to bend "
                          "them, with direction, angle, radius, length, K-factor, allowance and the line on the DXF")
    unf.add_argument("--compare", type=Path, default=None, metavar="DXF",
                     help="a flat pattern of the same part from another CAD program: print how far ours lies from it")
    unf.add_argument("--compare-open", choices=("error", "leave-out"), default="error",
                     help="a contour of the --compare file that does not close: an error naming where (default), or "
                          "left out of the comparison and counted")
    output(unf, blank=True)

    batch = sub.add_parser("batch", help=COMMAND_HELP["batch"])
    batch.add_argument("folder", type=Path, help="folder of input files (not searched recursively)")
    batch.add_argument("-o", "--output", type=Path, required=True, help="folder for the patterns and reports")
    add_arguments(batch.add_argument_group("running"), BatchOptions)
    loading(batch, positional=False)
    flattening(batch)
    add_arguments(batch.add_argument_group("unfolding (with --unfold)"), UnfoldOptions)
    checking(batch, report=False)
    output(batch)
    _host_commands(sub)
    parser.commands = sub.choices  # {command: its parser}, for the unknown options' "did you mean"
    return parser


def _host_commands(sub) -> None:
    """``serve`` (the engine for a CAD program), ``freecad install|uninstall`` and ``blender install|uninstall``."""
    sub.add_parser("serve", help=COMMAND_HELP["serve"])
    host = sub.add_parser("freecad", help=COMMAND_HELP["freecad"])
    host.add_argument("action", choices=("install", "uninstall"), help="install or uninstall")
    host.add_argument("--user-dir", type=Path, default=None, metavar="DIR",
                      help="FreeCAD's user data folder (Mod inside; default: $FREECAD_USER_DATA, $FREECAD_USER_HOME, "
                           "or the platform's)")
    blender = sub.add_parser("blender", help=COMMAND_HELP["blender"])
    blender.add_argument("action", choices=("install", "uninstall"), help="install or uninstall")
    blender.add_argument("--target", type=Path, default=None, metavar="DIR",
                         help="the add-ons folder (default: $BLENDER_USER_SCRIPTS/addons, or scripts/addons of every "
                              "Blender 4.2 or later in Blender's user folder)")
    blender.add_argument("--zip", type=Path, default=None, metavar="FILE",
                         help="install: write the add-on as a zip for Preferences > Add-ons > Install from Disk "
                              "instead")


def _answered_early(argv) -> int | None:
    """``--version`` and a mistyped command, answered before the parser (and the engine it declares) is
    imported: in a few hundredths of a second, not the seconds numpy, scipy and OpenCascade take."""
    import difflib

    if argv in ([], ["-h"], ["--help"]):  # the commands and their lines: no option record needed
        parser = _Parser(prog="patterns", description=DESCRIPTION)
        parser.add_argument("--version", action="store_true", help="show the version and exit")
        parser.add_argument("--debug", action="store_true", help="show tracebacks of errors (anywhere on the line)")
        sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
        for name, line in COMMAND_HELP.items():
            sub.add_parser(name, help=line)
        if not argv:
            raise InputError(f"give a command ({', '.join(COMMAND_HELP)}); patterns --help lists them")
        parser.print_help()
        return EXIT_OK
    if argv and argv[0] in COMMAND_HELP:
        return answered_from_index(argv, COMMAND_INDEX)
    if argv == ["--version"]:
        from . import __version__

        print(f"patterns {__version__}")
        return EXIT_OK
    if argv and not argv[0].startswith("-") and argv[0] not in COMMAND_HELP:
        names = list(COMMAND_HELP)
        close = difflib.get_close_matches(argv[0], names, n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise InputError(f"unknown command {printable(argv[0])!r}{hint}; the commands are {', '.join(names)}")
    return None


COMMAND_INDEX = Path(__file__).with_name("commands.json")
"""Each command's flags and its ``--help`` (at 80 columns), made from the full parser by :func:`command_index`
(``python -m patterns.cli`` writes it; a test checks that it is the parser's): a command's ``--help`` and a
mistyped flag are answered from it without importing the engine the parser is made from."""


def command_index() -> dict:
    """``{command: {"flags": [...], "help": its --help at 80 columns}}``, from the full parser."""
    import os

    saved = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "80"
    try:
        commands = _parser().commands
        return {name: {"flags": sorted({f for a in p._actions for f in a.option_strings}), "help": p.format_help()}
                for name, p in commands.items()}
    finally:
        if saved is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = saved


def _parse(argv) -> argparse.Namespace:
    """The parsed command line; an unknown option is named with the command's closest one ("did you mean
    --seam-allowance?") and the command's own --help, not the list of commands."""
    from .options import given_flags, suggest

    parser = _parser()
    args, extras = parser.parse_known_args(argv)
    args.given = given_flags(args) or set()  # the flags given (defaults aside), as the parser read them,
    args.given |= {a.split("=", 1)[0] for a in argv if a.startswith("--")}  # and as typed
    if extras:
        command = parser.commands[args.command]
        known = [flag for action in command._actions for flag in action.option_strings]
        word = next((e for e in extras if e.startswith("-")), extras[0])
        if word.startswith("-"):
            flag = word.split("=", 1)[0]
            raise InputError(f"unknown option {flag}{suggest(flag, known)} ({command.prog} --help lists the options)")
        raise InputError(f"unexpected argument {word!r} ({command.prog} --help lists the arguments)")
    return args


def _bundle(args, name=None):
    """The run's :class:`~patterns.bundle.Bundle` from parsed flags, each value checked as the API checks it:
    kind ``load`` (info), ``unfold`` (unfold, batch --unfold) or ``flatten`` (flatten, check, batch)."""
    from .bundle import Bundle
    from .reading import CAD_SUFFIXES

    if args.command in ("info", "check"):  # no drawing: --units is 0.2.0's name of --input-units, until 0.3.0
        values = {**vars(args), "units": "mm"}
        if args.units is not None and "--input-units" not in args.given:
            print(f"note: --units is --input-units for {args.command} (0.2.0's name, kept until 0.3.0)",
                  file=sys.stderr)
            values["input_units"] = args.units
            values["given"] = args.given | {"--input-units"}
        args = argparse.Namespace(**values)
    if args.command == "info":
        return Bundle.from_arguments("load", args, name=name)
    unfolding = args.command == "unfold" or (args.command == "batch" and args.unfold)
    bundle = Bundle.from_arguments("unfold" if unfolding else "flatten", args, name=name)
    if args.command == "check":
        return bundle
    if not unfolding and "--units" in args.given and "--input-units" not in args.given and args.units != "mm":
        # 0.2.0 read --units as a mesh's unit too: kept, with a word, until 0.3.0 (a CAD file is read in mm anyway)
        from dataclasses import replace

        if args.command == "batch" or Path(args.input).suffix.lower() not in CAD_SUFFIXES:
            print(f"note: --units is the drawing's unit; a mesh's own is --input-units. As in 0.2.0, this run also "
                  f"reads the mesh in {args.units} (until 0.3.0: give --input-units {args.units} to keep it)",
                  file=sys.stderr)
        bundle = replace(bundle, load=replace(bundle.load, units=args.units))
    return bundle


# --------------------------------------------------------------------------- #
# Commands: plan (every check, nothing written), work, commit (all or nothing)
# --------------------------------------------------------------------------- #


def _run_part(args, outputs: dict, bundle):
    """Plan the outputs, then flatten the part and write them all, or none."""
    from .files import Outputs
    from .jobs import flatten_part, inputs_of, plan_outputs
    from .reading import check_source

    check_source(args.input)
    inputs = inputs_of(args.input, bundle)
    planned = plan_outputs(outputs, inputs=inputs, profile=bundle.write.profile)
    progress = Progress("flattening")
    with Outputs(inputs=inputs) as out:
        try:
            part = flatten_part(args.input, bundle, outputs=planned, stage=out.stage, progress=progress,
                                loaded=loaded)
        finally:
            progress.close()
        out.commit()
    return Run(planned, part)


def _cmd_flatten(args) -> int:
    bundle = _bundle(args, name=os.fsdecode(args.input))  # every option checked before any work
    run = _run_part(args, {"pattern": args.output, "report": args.report, "heat_map": args.heat_map,
                           "preview": args.preview}, bundle)
    part = run.part
    print(f"flattened ({bundle.flatten.method}) in {part.seconds['flatten']:.2f} s (the flattening alone)")
    nested(part.nest)
    print_panels(part.report)
    wrote(run, bundle)
    return verdict(part.report, part.drawing if "pattern" in run.outputs else None)


def _cmd_check(args) -> int:
    bundle = _bundle(args, name=os.fsdecode(args.input))
    run = _run_part(args, {"report": args.report, "heat_map": args.heat_map}, bundle)
    print_panels(run.part.report)
    wrote(run, bundle)
    return verdict(run.part.report)


def _cmd_info(args) -> int:
    from .reading import check_source, load

    bundle = _bundle(args, name=os.fsdecode(args.input))
    check_source(args.input)
    start = time.perf_counter()
    model = load(args.input, bundle.load)
    loaded(model, time.perf_counter() - start)
    rows = [("panel", "CAD faces", "vertices", "triangles", "outline loops", "area mm2")]
    for p in model.panels:
        rows.append((p.name, ",".join(map(str, p.cad_faces)) or "-", str(len(p.vertices)), str(len(p.faces)),
                     str(len(p.loops)), f"{p.area:.1f}"))
    table(rows)
    if model.seams:
        rows = [("seam", "panels", "CAD edge", "length mm", "points")]
        for s in model.seams:
            rows.append((str(s.id), f"{model.panels[s.panels[0]].name}/{model.panels[s.panels[1]].name}",
                         "-" if s.cad_edge is None else str(s.cad_edge), f"{s.length:.3f}", str(len(s.points))))
        table(rows)
    print(f"loading: {model.bookkeeping}")
    return EXIT_OK


DEMO_FILES = (("cup.step", "the part: a hemisphere cup in four panels, built with build123d"),
              ("cup.dxf", "cutting pattern, machine profile, 10 mm seam allowance"),
              ("cup_astm.dxf", "the same for garment CAD (ASTM D6673)"),
              ("cup.json", "report: strain per panel, seam lengths on both sides, findings"),
              ("cup_heatmap.png", "strain heat map"),
              ("cup_preview.png", "the DXF rendered at 1:1 (96 dpi)"))


def _cmd_demo(args) -> int:
    import shlex
    from dataclasses import replace

    from build123d import export_step

    from .audit import CheckOptions, checked_drawing
    from .export import heat_map, preview_dxf, write
    from .files import Outputs, output_target
    from .findings import Code
    from .flattening import flatten
    from .pieces import drawing_of
    from .reading import load
    from .samples import cup

    limit = 0.05  # the strain limit the demo checks against, said before the tables; the cup exceeds it
    out = args.output
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: is a file; name a folder for the demo")
    created = not out.exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{out}: cannot create the demo folder ({exc.strerror})") from None
    try:
        for name, what in DEMO_FILES:
            output_target(out / name, what=what.split(":")[0], error=InputError)
        with Outputs() as files:
            step = files.stage(out / "cup.step", what="STEP file")
            export_step(cup(), step)
            model = replace(load(step), name="cup.step")  # read from its temporary name
            pattern = flatten(model)
            drawing = drawing_of(pattern, seam_allowance=10.0)
            report, checked = checked_drawing(pattern, drawing, CheckOptions(max_strain=limit))
            dxf = files.stage(out / "cup.dxf", what="DXF file")
            write(drawing, dxf)
            write(drawing, files.stage(out / "cup_astm.dxf", what="DXF file"), profile="astm")
            write(checked, files.stage(out / "cup.json", what="report"))
            heat_map(pattern, files.stage(out / "cup_heatmap.png", what="heat map"))
            preview_dxf(dxf, files.stage(out / "cup_preview.png", what="preview"))
            files.commit()
    except BaseException:
        if created:
            try:
                out.rmdir()  # a folder the failed run made, and left empty
            except OSError:
                pass
        raise
    print(f"patterns demo: {model.name}, a hemisphere in {counted(len(model.panels), 'panel')}, checked against a "
          f"strain limit of {100 * limit:g} % (as --max-strain {limit:g} would)")
    print_panels(report)
    verdict(report)
    if any(f.code is Code.STRAIN_ABOVE_LIMIT for f in report.findings):
        worst = max(p.strain_max for p in report.panels)
        gores = shlex.join(["patterns", "flatten", os.fsdecode(out / "cup.step"), "-o", os.fsdecode(out / "cup_gores.dxf"),
                            "--seam-allowance", "10", "--dart-strain", f"{limit:g}", "--gores",
                            "--max-strain", f"{limit:g}"])
        print(f"why: a hemisphere is curved in two directions, and a doubly curved panel cannot lie flat without "
              f"stretching: these quarter spheres stretch up to {100 * worst:.2f} %, above the {100 * limit:g} % "
              f"limit. Cut into gores (or, without --gores, darts), the cup comes within it:")
        print(f"  {gores}")
    print(f"patterns demo: {counted(len(model.panels), 'panel')}, {counted(len(model.seams), 'seam')}; wrote:")
    for name, what in DEMO_FILES:
        print(f"  {out / name}  {what}")
    return EXIT_OK


def _cmd_batch(args) -> int:
    from .batching import BatchOptions, batch, plan_batch
    from .options import from_arguments

    bundle = _bundle(args)  # every option checked before any file is read
    options = from_arguments(BatchOptions, args)
    files, _ = plan_batch(args.folder, args.output, unfold=options.unfold)
    progress = BatchProgress(len(files), quiet=options.quiet)
    result = batch(args.folder, args.output, bundle=bundle, options=options, on_row=progress.row,
                   on_start=progress.start)  # the folder: its entries that are no part file listed as skipped
    progress.close()
    batch_table(result.rows, unfold=options.unfold)
    counts = ", ".join(f"{result.count(s)} {s}" for s in ("ok", "check failed", "failed", "timeout", "lost", "not run",
                                                                     "skipped")
                       if result.count(s))
    written = sum(bool(r.written) for r in result.rows)
    stop = f"{result.stopped}: " if result.stopped else ""
    print(f"batch: {stop}{counted(len(result.rows), 'file')}: {counts} ({result.where}); "
          f"{written} written to {os.fsdecode(args.output)}", file=sys.stderr if result.stopped else sys.stdout)
    return result.exit_code


def _cmd_unfold(args) -> int:
    from .comparison import read_flat_pattern
    from .files import Outputs, check_input_file
    from .jobs import inputs_of, plan_outputs, unfold_part
    from .reading import CAD_SUFFIXES, check_source

    bundle = _bundle(args, name=os.fsdecode(args.input))  # the bend table read and checked
    check_source(args.input, CAD_SUFFIXES)
    inputs = inputs_of(args.input, bundle) + ([args.compare] if args.compare is not None else [])
    if args.compare is not None:
        check_input_file(args.compare, what="DXF file")
    planned = plan_outputs({"pattern": args.output, "report": args.report, "preview": args.preview,
                            "bend_sheet": args.bend_sheet}, inputs=inputs,
                           suffixes={"pattern": (".dxf", ".svg")}, profile=bundle.write.profile)
    reference = read_flat_pattern(args.compare, open_contours=args.compare_open) if args.compare is not None else None
    with Outputs(inputs=inputs) as out:
        part = unfold_part(args.input, bundle, outputs=planned, stage=out.stage, reference=reference)
        if part.subject.ok:
            out.commit()
    blank = part.subject
    w, h = blank.size
    print(f"{blank.name}: sheet {blank.thickness:g} mm, {counted(len(blank.bends), 'bend')}, "
          f"{counted(len(blank.holes), 'hole')}; "
          f"blank {w:.2f} x {h:.2f} mm, area {blank.area:.1f} mm2, usage {blank.usage:.1%} (read and unfolded in "
          f"{part.seconds['flatten']:.2f} s)")
    rows = [("bend", "direction", "angle deg", "inside R mm", "length mm", "K", "allowance mm")]  # in sequence
    rows += [(str(r.sequence), r.direction, f"{r.angle_deg:.2f}", f"{r.inside_radius_mm:g}", f"{r.bend_length_mm:.2f}",
              "table" if r.k_factor is None else f"{r.k_factor:g}", f"{r.allowance_mm:.4f}") for r in blank.bend_sheet()]
    if blank.bends:
        table(rows)
    elif args.bend_sheet is not None and blank.ok:
        print(f"  note: {blank.name} has no bends: {args.bend_sheet} has its header only")
    for f in blank.findings:
        print(f"  {f.severity.value}: {f.message}")
    if blank.ok:
        label_notes(part.drawing)
    c = part.comparison
    if c is not None:
        print(f"against {args.compare}: area {c.area_error:+.4%}, outer perimeter {c.perimeter - c.perimeter_reference:+.3f}"
              f" mm, holes {c.holes}/{c.holes_reference}, bend lines {c.bend_lines}/{c.bend_lines_reference}, outline "
              f"Hausdorff {c.hausdorff:.3f} mm ({c.within:.1%} of it within 0.1 mm)")
        for d in c.differences[:_SHOWN]:
            print(f"  differs: {d.describe(args.compare.name)}")
        if len(c.differences) > _SHOWN:
            print(f"  differs: {counted(len(c.differences) - _SHOWN, 'more place')} (the report lists every one)")
        if len(reference.open_contours):
            print(f"  note: {counted(len(reference.open_contours), 'open contour')} of {args.compare} left out")
    if not blank.ok:
        print(f"{', '.join(map(str, planned.values()))}: not written (the blank cannot be cut as it is)")
        return EXIT_CHECK
    nested(part.nest)
    wrote(Run(planned, part), bundle)
    return EXIT_OK


def _serve() -> int:
    """``patterns serve``: the protocol's standard output kept before any import could print to it."""
    from .service.server import protocol_output

    out = protocol_output()
    from .service import serve

    return serve(sys.stdin.buffer, out)


def _cmd_freecad(args) -> int:
    from .hosts import freecad

    if args.action == "install":
        folder = freecad.install(args.user_dir)
        print(f"installed the Patterns workbench in {folder}; its engine is {sys.executable} (this environment). "
              f"Start FreeCAD and pick the Patterns workbench; `patterns freecad uninstall` takes it out")
    else:
        folder = freecad.uninstall(args.user_dir)
        print(f"removed {folder}" if folder else f"no Patterns workbench in {freecad.user_dir(args.user_dir) / 'Mod'}")
    return EXIT_OK


def _cmd_blender(args) -> int:
    from .hosts import blender

    if args.action == "install" and args.zip is not None:
        if args.target is not None:
            raise InputError("give --target or --zip, not both")
        path = blender.write_zip(args.zip)
        print(f"wrote {path}: in Blender, Edit > Preferences > Add-ons > Install from Disk, then enable Patterns; its "
              f"engine is {sys.executable} (this environment)")
    elif args.action == "install":
        for folder in blender.install(args.target):
            print(f"installed the Patterns add-on in {folder}; its engine is {sys.executable} (this environment)")
        print("in Blender: Edit > Preferences > Add-ons, enable Patterns; the tools are in the 3D view's sidebar (N)")
    else:
        if args.zip is not None:
            raise InputError("--zip goes with install")
        gone = blender.uninstall(args.target)
        print("\n".join(f"removed {g}" for g in gone) if gone else "no Patterns add-on found")
    return EXIT_OK


COMMANDS = {"flatten": _cmd_flatten, "check": _cmd_check, "info": _cmd_info, "demo": _cmd_demo, "unfold": _cmd_unfold,
            "batch": _cmd_batch, "freecad": _cmd_freecad, "blender": _cmd_blender}


# --------------------------------------------------------------------------- #
# Signals end cleanly; the terminal (patterns.terminal) shows names as data
# --------------------------------------------------------------------------- #


def main(argv=None) -> int:
    """Run the command line; returns the exit code."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    argv = [a for a in argv if a != "--debug"]  # anywhere on the line
    saved = sys.stdout, sys.stderr
    restore = None
    try:  # from here on a signal, wherever it lands, is the stop it was (_ended)
        restore = signals.install()  # first, inside: a restore that cannot be skipped (its run would never end)
        foreign_home()
        sys.stdout, sys.stderr = Terminal(sys.stdout), Terminal(sys.stderr)
        if argv == ["serve"]:  # the engine for a CAD program (docs/worker.md): its standard output is the protocol's
            return _serve()
        early = _answered_early(argv)
        if early is not None:
            return early
        args = _parse(argv)
        code = COMMANDS[args.command](args)
        signals.check()  # a stop a library swallowed after the last output: still a stop
        return code
    except BaseException as exc:  # noqa: BLE001 - each kind is sorted out (and the rest raised) by _ended
        return _ended(exc, debug)
    finally:
        if restore is not None:
            restore()
        sys.stdout.flush()
        sys.stderr.flush()
        sys.stdout, sys.stderr = saved


def _ended(exc: BaseException, debug: bool) -> int:
    """The exit code, and the one line, of a run that raised ``exc``: a signal received (whatever it turned into
    on its way: an ``ImportError`` of an extension it interrupted, a library's own error) is the stop it was."""
    stop = signals.received()
    if stop is not None and not debug:
        n = signals.written()
        print(f"patterns: {signals.stopped(stop)}; " + (f"{counted(n, 'output')} had been written whole before it"
                                                       if n else "nothing written"), file=sys.stderr)
        return signals.exit_code(stop)
    if isinstance(exc, PatternsError) and not debug:
        print(f"patterns: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    if isinstance(exc, MemoryError) and not debug:
        print("patterns: error: out of memory (the part, or an option, asks for more than this machine has); "
              "nothing written", file=sys.stderr)
        return EXIT_INPUT
    if isinstance(exc, KeyboardInterrupt):
        print("patterns: interrupted; nothing written", file=sys.stderr)
        return EXIT_INTERRUPTED
    if isinstance(exc, Terminated):
        print("patterns: terminated; nothing written", file=sys.stderr)
        return EXIT_TERMINATED
    raise exc  # SystemExit (--help), a bug: as it came

if __name__ == "__main__":  # pragma: no cover -- python -m patterns.cli: write the command index anew
    import json as _json

    COMMAND_INDEX.write_text(_json.dumps(command_index(), indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {COMMAND_INDEX}")
