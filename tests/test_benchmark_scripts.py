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
    """``refinement.py``'s ``CAD_TOLERANCES`` go to ``patterns.load`` with ``max_edge``: a 100 mm square
    meshed with them and ``max_edge`` 10 has its area, 10,000 mm²."""
    tolerances = _constant("refinement.py", "CAD_TOLERANCES")
    (face,) = bd.Rectangle(100, 100).faces()
    model = patterns.load(face, max_edge=10.0, **tolerances)
    (panel,) = model.panels
    assert abs(panel.area - 10_000.0) < 1e-6
