"""The house rules that code review would otherwise have to remember: small classes and
functions, no import cycle, layers that point down, no module named like one of its functions."""

import ast
import importlib
import pkgutil
from pathlib import Path

import pytest

import patterns

PACKAGE = Path(patterns.__file__).parent
MAX_CLASS_LINES = 250
MAX_FUNCTION_LINES = 80  # lines of code: docstring, blank and comment lines not counted


def _sources():
    return sorted(p for p in PACKAGE.rglob("*.py"))


def _code_lines(node, lines) -> int:
    body = node.body
    if body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]
    seen = set()
    for stmt in body:
        for ln in range(stmt.lineno, stmt.end_lineno + 1):
            text = lines[ln - 1].strip()
            if text and not text.startswith("#"):
                seen.add(ln)
    return len(seen)


def test_no_class_or_function_is_too_long():
    too_long = []
    for path in _sources():
        lines = path.read_text().splitlines()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef) and node.end_lineno - node.lineno + 1 > MAX_CLASS_LINES:
                too_long.append(f"{path.name}: class {node.name}")
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and path.name != "cli.py" \
                    and _code_lines(node, lines) > MAX_FUNCTION_LINES:
                too_long.append(f"{path.name}: {node.name} ({_code_lines(node, lines)} lines)")
    assert not too_long, too_long


def _imports():
    """``{module: {imported patterns module, ...}}`` from every import, module- or function-level."""
    graph = {}
    for path in _sources():
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        name = ".".join(parts)
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[:len(base) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                if target.startswith("patterns"):
                    submodules = [f"{target}.{a.name}" for a in node.names
                                  if _is_package(target) and _is_module(f"{target}.{a.name}")]
                    found |= set(submodules) if submodules else {target}  # "from . import grow": the module
            elif isinstance(node, ast.Import):
                found |= {a.name for a in node.names if a.name.startswith("patterns")}
        graph[name] = found - {name}
    return graph


def _path(name):
    """The file of module ``name`` of this package, found without importing it (``patterns.freecad``
    imports FreeCAD, which plain Python has not)."""
    return PACKAGE.parent.joinpath(*name.split("."))


def _is_package(name):
    return (_path(name) / "__init__.py").is_file()


def _is_module(name):
    return _is_package(name) or _path(name).with_suffix(".py").is_file()


def test_no_import_cycle():
    graph = _imports()

    def reach(start):
        seen, todo = set(), [start]
        while todo:
            for nxt in graph.get(todo.pop(), ()):
                if nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return seen

    cycles = [m for m in graph if m in reach(m) and m != "patterns"]
    assert not cycles, cycles


def test_no_module_shares_a_name_with_a_function_of_the_package():
    """`patterns.check` is the function; its module is `patterns.audit` (and so on)."""
    modules = {m.name for m in pkgutil.iter_modules(patterns.__path__)}
    functions = {n for n in patterns.__all__ if callable(getattr(patterns, n)) and n[0].islower()}
    assert not modules & functions, modules & functions
    for name in ("audit", "flattening", "nesting", "reading"):
        module = importlib.import_module(f"patterns.{name}")
        assert module.__name__ == f"patterns.{name}"
    assert patterns.audit.Severity is patterns.Severity


@pytest.mark.parametrize("name", sorted(patterns.__all__))
def test_every_export_is_documented(name):
    obj = getattr(patterns, name)
    if callable(obj) and not isinstance(obj, type(patterns)):
        assert (obj.__doc__ or "").strip(), name


MAX_MODULE_LINES = 650


def test_no_module_is_too_long():
    """Rooms are split along their jobs before they grow past 650 lines (the mesher, sheet metal, the writers)."""
    long = {str(p.relative_to(PACKAGE)): n for p in _sources() if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES}
    assert not long, long


def test_no_type_is_erased_and_no_type_is_guessed():
    """No field or parameter of the package is annotated ``object`` (name the type: the layers allow it), and no
    ``hasattr`` stands in for a type test (``isinstance`` with the type, or ``Mapping`` for a mapping)."""
    erased, guessed = [], []
    for path in _sources():
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            annotation = getattr(node, "annotation", None) or getattr(node, "returns", None)
            if isinstance(annotation, ast.Name) and annotation.id == "object":
                erased.append(f"{path.name}:{node.lineno}")
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "hasattr":
                guessed.append(f"{path.name}:{node.lineno}")
    assert not erased and not guessed, (erased, guessed)


def test_every_module_is_named_in_the_architecture_doc():
    """docs/architecture.md names every module of the package -- a top-level one as ``name.py``, one in a
    sub-package by its name -- so that the map of the house is the house (FreeCAD's workbench, copied into
    FreeCAD, is named as its folder)."""
    import re

    text = (PACKAGE.parent / "docs" / "architecture.md").read_text()
    missing = []
    for path in _sources():
        rel = path.relative_to(PACKAGE)
        if path.stem == "__init__" or "freecad_addon" in rel.parts or "blender_addon" in rel.parts:
            continue
        named = f"{path.stem}.py" in text if len(rel.parts) == 1 else re.search(rf"\b{path.stem}\b", text)
        if not named:
            missing.append(str(rel))
    assert "freecad_addon/" in text and "blender_addon/" in text
    assert not missing, missing


_DEPRECATED = r"goes in 0\.3\.0: use patterns\."


@pytest.fixture(scope="module")
def duct():
    return patterns.flatten(patterns.load(PACKAGE.parent / "samples" / "duct_transition.step"))


def test_pattern_to_dxf_warns_and_writes_what_write_writes(duct, tmp_path):
    """0.1.0's public methods, removed without a word while 0.2.0 was made, are back for one minor version:
    each warns with its replacement and does what it did (here: the file read back against ``write``'s)."""
    import ezdxf

    with pytest.warns(DeprecationWarning, match=_DEPRECATED):
        duct.to_dxf(tmp_path / "old.dxf", seam_allowance=5)
    patterns.write(duct, tmp_path / "new.dxf", seam_allowance=5)
    kinds = [sorted((e.dxftype(), e.dxf.layer) for e in ezdxf.readfile(tmp_path / f).modelspace())
             for f in ("old.dxf", "new.dxf")]
    assert kinds[0] == kinds[1] and kinds[0]


def test_pattern_layout_warns_and_nests(duct):
    with pytest.warns(DeprecationWarning, match=_DEPRECATED):
        nest = duct.layout(width=1500, time_limit=1)
    assert len(nest.drawing().pieces) == len(duct.panels) and nest.length > 0


def test_report_to_json_warns_and_writes_the_report(duct, tmp_path):
    import json

    report = patterns.check(duct)
    with pytest.warns(DeprecationWarning, match=_DEPRECATED):
        report.to_json(tmp_path / "report.json")
    assert json.loads((tmp_path / "report.json").read_text()) == json.loads(json.dumps(report.to_dict()))


def test_piece_options_largest_allowance_warns_and_works():
    with pytest.warns(DeprecationWarning, match=_DEPRECATED):
        assert patterns.PieceOptions(seam_allowance={"front": 4.0, "back": 12.5}).largest_allowance == 12.5
    with pytest.warns(DeprecationWarning, match=_DEPRECATED):
        assert patterns.PieceOptions(seam_allowance=6.0).largest_allowance == 6.0


def test_the_service_records_of_warns_and_gives_the_bundles_records():
    from patterns.service import records_of

    with pytest.warns(DeprecationWarning, match=r"records_of goes in 0.3.0"):
        records = records_of("pattern", {"dart_strain": 0.03}, name="x")
    assert records[patterns.FlattenOptions].max_strain == 0.03 and records[patterns.CheckOptions].max_strain is None


def test_a_panels_placement_is_the_motion_a_piece_has(duct):
    """One meaning per name: ``FlatPanel.motion`` is its placement as the ``Motion`` a piece's ``placement`` is;
    the drawing's pieces of a laid-out pattern sit where their panels' motions put them."""
    import numpy as np

    laid = duct.placed([(0.3 * k, 100.0 * k, -50.0 * k) for k in range(len(duct.panels))])
    for flat in laid.panels:
        np.testing.assert_allclose(flat.motion(flat.flattening.uv), flat.uv, atol=1e-12)
        a, dx, dy = flat.placement
        c, s = np.cos(a), np.sin(a)
        np.testing.assert_allclose(flat.uv, flat.flattening.uv @ np.array([[c, -s], [s, c]]).T + [dx, dy], atol=1e-9)
