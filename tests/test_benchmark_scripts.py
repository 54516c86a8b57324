"""The benchmark scripts call the library as it is now: options they pass that the library renamed stop them
only when they are run (``benchmarks/refinement.py`` passed ``tolerance=`` to ``patterns.load`` for months
after it became ``chord_tolerance``, and its table could not be rerun).  libigl, which the scripts import,
is not a test dependency, so their option tables are read from their source and tried on the library."""

from __future__ import annotations

import ast
from pathlib import Path

import build123d as bd

import patterns

BENCHMARKS = Path(__file__).resolve().parent.parent / "benchmarks"


def _constant(script: str, name: str):
    tree = ast.parse((BENCHMARKS / script).read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError(f"{script} has no {name}")


def test_the_refinement_studys_mesher_tolerances_are_options_load_takes():
    """``refinement.py``'s ``CAD_TOLERANCES`` go to ``patterns.load`` with ``max_edge``, loose "so that
    ``max_edge`` alone sets the face count": ``load`` takes them (a renamed key raises), and they bite: a
    cylinder R 20 x 40 meshed with them and ``max_edge`` 10 has under a fifth of the triangles the default
    tolerances give it (their chord error, not ``max_edge``, sets that mesh)."""
    tolerances = _constant("refinement.py", "CAD_TOLERANCES")
    face = bd.Cylinder(20, 40).faces().filter_by(bd.GeomType.CYLINDER)[0]
    (loose,) = patterns.load(face, max_edge=10.0, **tolerances).panels
    (default,) = patterns.load(face, max_edge=10.0).panels
    assert 5 * len(loose.faces) < len(default.faces)
