"""The ``patterns`` command line.

``patterns flatten INPUT -o OUT`` flattens a mesh file and writes the cut
contours (.dxf) or the flat mesh (.obj), printing the strain and the overlap
verdict.  Exit codes: 0 done, 2 bad input or usage (one line on stderr; add
``--debug`` for the traceback).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from .errors import InputError, PatternsError

__all__ = ["main"]

OUTPUT_SUFFIXES = (".dxf", ".obj")


def _parser() -> argparse.ArgumentParser:
    from . import METHODS, __version__
    from .export.dxf import UNITS

    parser = argparse.ArgumentParser(
        prog="patterns", description="Flatten 3D surfaces into true-scale 2D cutting patterns."
    )
    parser.add_argument("--version", action="version", version=f"patterns {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    flat = sub.add_parser("flatten", help="flatten a mesh file (.obj .stl .ply .off)")
    flat.add_argument("input", type=Path, help="mesh file; coordinates taken in --units")
    flat.add_argument("-o", "--output", type=Path, required=True,
                      help="output: .dxf (cut contours on layer CUT) or .obj (flat mesh, z = 0)")
    flat.add_argument("--method", choices=METHODS, default="relaxed", help="flattening method (default relaxed)")
    flat.add_argument("--seed-face", type=int, default=None, help="face laid down first (default: farthest from the boundary)")
    flat.add_argument("--max-iterations", type=int, default=500, help="relaxation iterations at most (default 500)")
    flat.add_argument("--units", choices=tuple(UNITS), default="mm", help="unit of the input coordinates (default mm)")
    return parser


def _flatten(args) -> int:
    from . import flatten_mesh
    from .export import write_flat_obj, write_outline_dxf
    from .load import read_mesh

    suffix = args.output.suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise InputError(f"{args.output}: unknown output type {suffix or '(none)'!r}; use .dxf or .obj")
    mesh = read_mesh(args.input)
    start = time.perf_counter()
    result = flatten_mesh(mesh.vertices, mesh.faces, method=args.method, seed_face=args.seed_face,
                          max_iterations=args.max_iterations, name=str(args.input))
    seconds = time.perf_counter() - start
    if suffix == ".dxf":
        write_outline_dxf(args.output, [result.uv[loop] for loop in result.loops], units=args.units)
    else:
        write_flat_obj(args.output, result.uv, result.faces)
    d = result.distortion
    u = args.units
    welded = f", {mesh.n_welded} duplicate vertices welded" if mesh.n_welded else ""
    print(f"{args.input}: {len(result.faces)} faces, {len(result.loops)} boundary loop(s){welded}")
    how = f"{args.method}, from the {result.start} layout, {result.iterations} iterations" if result.start else args.method
    print(f"flattened ({how}) in {seconds:.2f} s; wrote {args.output}")
    print(f"edge strain: RMS {100 * d.edge_strain_rms:.3f} %, max {100 * d.edge_strain_max:.3f} %")
    print(f"area: 3D {d.area_3d:.6g} {u}2, flat {d.area_flat:.6g} {u}2 ({100 * (d.area_ratio - 1):+.3f} %)")
    print(f"boundary: 3D {d.boundary_3d:.6g} {u}, flat {d.boundary_flat:.6g} {u}")
    print(f"overlap: {result.overlap.message}")
    return 0


def main(argv=None) -> int:
    """Run the command line; returns the exit code."""
    argv = sys.argv[1:] if argv is None else argv
    debug = "--debug" in argv
    try:
        args = _parser().parse_args(argv)
        return _flatten(args)
    except PatternsError as exc:
        if debug:
            raise
        print(f"patterns: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
