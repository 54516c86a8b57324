"""What the command line prints: the tables, the verdict and its findings, what was loaded, nested and written
(:mod:`patterns.cli` runs the commands; this module only prints their results)."""

from __future__ import annotations

from .errors import InputError
from .text import counted

__all__ = ["MOST_NOTES", "Run", "answered_from_index", "batch_table", "label_notes", "loaded", "nested", "print_panels", "table", "verdict", "wrote"]

EXIT_OK, EXIT_CHECK = 0, 1
"""The exit codes of a run that ended: every check passed, or some failed (:mod:`patterns.cli` has the rest)."""


def print_panels(report):
    rows = [("panel", "triangles", "area 3D mm2", "area flat mm2", "strain RMS %", "max %", "p95 %", "one-to-one")]
    for p in report.panels:
        rows.append((p.name, str(p.n_triangles), f"{p.area_3d:.1f}", f"{p.area_flat:.1f}",
                     f"{100 * p.strain_rms:.2f}", f"{100 * p.strain_max:.2f}", f"{100 * p.strain_p95:.2f}",
                     "yes" if p.one_to_one else "NO"))
    table(rows)
    if report.seams:
        rows = [("seam", "panels", "3D mm", "flat mm (side 0)", "flat mm (side 1)", "mismatch mm", "%")]
        for s in report.seams:
            rows.append((str(s.id), f"{s.panels[0]}/{s.panels[1]}", f"{s.length_3d:.2f}",
                         f"{s.length_flat[0]:.2f}", f"{s.length_flat[1]:.2f}", f"{s.mismatch:+.2f}",
                         f"{s.mismatch_percent:+.3f}"))
        table(rows)


def table(rows):
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())


def verdict(report, drawing=None) -> int:
    print(str(report).splitlines()[0])
    for f in report.findings:
        print(f"  {f.severity.value}: {f.message}")
    if drawing is not None:
        label_notes(drawing)
    return EXIT_OK if report.ok else EXIT_CHECK


MOST_NOTES = 10
"""Label notes printed at most (the report has every one)."""


def label_notes(drawing) -> None:
    """The labels the file leaves out, one note each (the same the report gives its pieces)."""
    from .findings import Code

    notes = [f for p in drawing.pieces for f in p.findings if f.code is Code.LABEL_LEFT_OUT]
    for f in notes[:MOST_NOTES]:
        print(f"  {f.severity.value}: {f.message}")
    if len(notes) > MOST_NOTES:
        print(f"  ... and {len(notes) - MOST_NOTES} more labels left out (the report lists them)")


def loaded(model, seconds):
    if model.bookkeeping != type(model.bookkeeping)():
        print(f"{model.name}: {model.bookkeeping}")
    print(f"{model.name}: {counted(len(model.panels), 'panel')}, {counted(len(model.seams), 'seam')} "
          f"(target edge {model.max_edge:.3g} mm), loaded in {seconds:.2f} s")


def nested(nest) -> None:
    """The nest's line: what it is, and where its time went (a search, or a marker kept from an earlier run)."""
    if nest is None:
        return
    if nest.cached:
        print(f"nested on {nest} (a marker kept from an earlier run with the same pieces and options, "
              f"{nest.seconds:.1f} s; --no-nest-cache searches anew)")
    else:
        print(f"nested on {nest} (sparrow searched {nest.seconds:.1f} s)")
    for sheet in nest.drawing().sheets():
        length, width = sheet.size
        print(f"  sheet {sheet.index + 1} ({length:g} x {width:g} mm): {len(sheet.pieces)} pieces, usage "
              f"{sheet.usage:.1%}, cut {sheet.cut_length:.1f} mm, {sheet.pierces} pierces, {sheet.bends} bends")


def wrote(result, bundle):
    for kind, path in result.outputs.items():
        if kind == "pattern" and path.suffix.lower() == ".dxf":
            opts = bundle.write
            print(f"wrote {path} ({opts.profile or 'machine'} profile, {opts.units}, layers {opts.layer_map})")
            if opts.units in ("cm", "m"):
                print(f"note: {path} is in {opts.units}: Inkscape's DXF import and dxf2gcode read only mm and inches, "
                      f"and take it for mm; write mm or in for them")
        elif kind == "pattern" and path.suffix.lower() == ".svg":
            print(f"wrote {path} (1:1 in mm: red cut, blue score, black engrave)")
        elif kind == "pattern":
            print(f"wrote {path} (flat mesh, z = 0, in {bundle.write.units})")
        elif kind == "preview" and result.part.preview_dpi is not None and path.suffix.lower() == ".png":
            dpi = result.part.preview_dpi
            print(f"wrote {path} (the DXF at 1:1 at {dpi:.3g} dpi"
                  f"{'' if dpi >= 95.9 else ': lowered to stay under 40 megapixels; it prints at 1:1 at that dpi'})")
        elif kind == "preview":
            print(f"wrote {path} (the DXF at 1:1)")
        else:
            print(f"wrote {path}")
    for path in result.part.sheet_files:
        print(f"wrote {path} (one sheet alone)")


class Run:
    """A planned run's outputs and what the work gave, for the printing."""

    def __init__(self, outputs, part):
        self.outputs, self.part = outputs, part


def batch_table(rows, *, unfold: bool) -> None:
    """A batch's table, a row per file: a pattern's panels, seams and strains; with ``unfold``, a blank's
    thickness, size and bends."""
    def value(x, fmt="{}"):
        return "-" if x is None else fmt.format(x)

    if unfold:
        out = [("file", "thickness mm", "size mm", "bends", "seconds", "status")]
        out += [(r.file, value(r.thickness, "{:g}"), "-" if r.size is None else f"{r.size[0]:.1f} x {r.size[1]:.1f}",
                 value(r.bends), f"{r.seconds:.1f}", r.status + (f": {r.reason}" if r.reason else "")) for r in rows]
    else:
        out = [("file", "panels", "seams", "strain RMS %", "max %", "seconds", "status")]
        out += [(r.file, value(r.panels), value(r.seams), "-" if r.strain_rms is None else f"{100 * r.strain_rms:.2f}",
                 "-" if r.strain_max is None else f"{100 * r.strain_max:.2f}", f"{r.seconds:.1f}",
                 r.status + (f": {r.reason}" if r.reason else "")) for r in rows]
    table(out)


def answered_from_index(argv, index) -> int | None:
    """A command's ``--help``, or the first flag it does not have (with the closest it has), answered from
    :data:`patterns.cli.COMMAND_INDEX` (``index``); None when the line is for the parser (or the index is missing)."""
    import difflib
    import json

    try:
        entry = json.loads(index.read_text(encoding="utf-8"))[argv[0]]
    except (OSError, ValueError, KeyError):
        return None
    for word in argv[1:]:
        if word == "--":
            break
        if word in ("-h", "--help"):
            print(entry["help"], end="")
            return EXIT_OK
        flag = word.split("=", 1)[0]
        if flag.startswith("--") and not any(f.startswith(flag) for f in entry["flags"]):  # argparse takes prefixes
            close = difflib.get_close_matches(flag, entry["flags"], n=1, cutoff=0.6)
            raise InputError(f"unknown option {flag}{f'; did you mean {close[0]}?' if close else ''} (patterns "
                             f"{argv[0]} --help lists the options)")
    return None
