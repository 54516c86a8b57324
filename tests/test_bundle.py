"""One bundle of option records for the command line, ``batch``, the worker and every host (issue 47, item 1):
one name per meaning, one validator, a JSON form that reads back."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import patterns
from patterns import Bundle, InputError
from patterns.batching import _options
from patterns.bundle import KINDS
from patterns.cli import _bundle, _parse

REPO = Path(__file__).resolve().parent.parent
SAMPLES = REPO / "samples"


def _cli(argv):
    args = _parse(argv)
    return _bundle(args, name="part")


def test_the_two_strain_limits_and_the_two_gaps_are_two_names_in_every_kind():
    for kind in ("flatten", "pattern"):
        names = {n.name: n.targets for n in Bundle.names(kind)}
        assert names["dart_strain"] == (("flatten", "max_strain"),)
        assert names["max_strain"] == (("check", "max_strain"),)
        assert names["gap"] == (("pieces", "gap"),) and names["nest_gap"] == (("nest", "gap"),)
    for kind in KINDS:  # every name is one option, or one flag two records share (--units)
        entries = Bundle.names(kind)
        assert len({n.name for n in entries}) == len(entries), kind
        targets = [t for n in entries for t in n.targets]
        assert len(set(targets)) == len(targets), kind


def test_the_command_line_batch_and_the_worker_make_the_same_bundle():
    """One value per meaning reaches the same record field through each door."""
    values = {"dart_strain": 0.03, "max_strain": 0.05, "gap": 4.0, "nest_gap": 7.0, "seam_allowance": 6.0}
    cli = _cli(["flatten", "part.step", "-o", "out.dxf", "--dart-strain", "0.03", "--max-strain", "0.05",
                "--gap", "4", "--nest-gap", "7", "--seam-allowance", "6"])
    api = Bundle.of("flatten", values)
    _, batched = _options(None, None, None, dict(values, jobs=1))
    assert cli.to_json() == api.to_json() == batched.to_json() == values
    host = Bundle.from_json("pattern", {k: str(v) for k, v in values.items()})  # a host's text properties
    for slot in ("flatten", "check", "pieces", "nest"):
        assert getattr(host, slot) == getattr(cli, slot), slot
    assert (cli.flatten.max_strain, cli.check.max_strain, cli.pieces.gap, cli.nest.gap) == (0.03, 0.05, 4.0, 7.0)


def test_a_bundle_reads_back_its_json_form(tmp_path):
    table = tmp_path / "bends.csv"
    table.write_text("thickness,radius,angle,deduction\n2,2,90,3.5\n")
    flat = Bundle.of("flatten", {"dart_strain": 0.04, "grain": (0, 0, 1), "ease": [patterns.Ease(1, "a", mm=2.0)],
                                 "sheet": (2500, 1250), "quantities": {"front": 2}, "units": "cm", "input_units": "in",
                                 "layer_map": "solidworks,label=TEXT", "panels": {"top": [0, 1]},
                                 "notch_style": "v", "bend_lines": False, "weld_vertices": True})
    blank = Bundle.of("unfold", {"bend_table": str(table), "fixed_face": 3, "corner_relief": "round"})
    for bundle in (flat, blank):
        text = bundle.to_json()
        again = Bundle.from_json(bundle.kind, text)
        assert again.to_json() == text
        assert Bundle.from_json(bundle.kind, json.loads(json.dumps(text))).to_json() == text
    assert flat.to_json()["ease"] == ["1:a:2.0"] and flat.to_json()["sheet"] == [2500.0, 1250.0]
    assert blank.to_json()["bend_table"] == str(table)
    assert (flat.load.units, flat.write.units) == ("in", "cm")  # a mesh's unit, the drawing's: two names
    assert Bundle.from_json("flatten", {"sheet": "2500x1250", "ease": "1:a:2;2:b:5%"}).flatten.ease[1].ratio == 0.05


def test_messages_name_the_option_as_the_door_it_came_through_names_it():
    with pytest.raises(InputError, match=r"^part: dart_strain must be a ratio > 0 and <= 1 .*got 3; 3 % is 0.03$"):
        Bundle.of("flatten", {"dart_strain": 3}, name="part")
    with pytest.raises(InputError, match=r"^part: --dart-strain must be a ratio"):
        _cli(["flatten", "part.step", "-o", "out.dxf", "--dart-strain", "3"])
    with pytest.raises(InputError, match=r"unknown option 'dart_strian' for a flatten; did you mean dart_strain\?"):
        Bundle.of("flatten", {"dart_strian": 0.03})
    with pytest.raises(InputError, match=r"^x: sheet: expected LENGTHxWIDTH"):
        Bundle.from_json("blank", {"sheet": "2500x"}, name="x")
    with pytest.raises(InputError, match=r"unknown option 'seam_allowance' for a blank"):
        Bundle.of("blank", {"seam_allowance": 3})
    with pytest.raises(InputError, match=r"^seam_allowance is a flattened pattern's option: a unfold has none"):
        Bundle("unfold", pieces=patterns.PieceOptions(seam_allowance=3))
    with pytest.raises(InputError, match=r"^--seam-allowance is a flattened pattern's option"):
        _cli(["batch", "folder", "-o", "out", "--unfold", "--seam-allowance", "3"])
    with pytest.raises(InputError, match=r"^--seam-allowance is a flattened pattern's option"):  # typed at 0
        _cli(["batch", "folder", "-o", "out", "--unfold", "--seam-allowance", "0"])


def test_batch_keeps_the_old_meaning_of_max_strain_and_gap_for_a_minor_version_with_a_warning():
    with pytest.warns(DeprecationWarning, match=r"batch\(max_strain=\) sets max_strain and dart_strain"):
        _, bundle = _options(None, None, None, {"max_strain": 0.04})
    assert (bundle.flatten.max_strain, bundle.check.max_strain) == (0.04, 0.04)
    with pytest.warns(DeprecationWarning, match=r"batch\(gap=\) sets gap and nest_gap"):
        _, bundle = _options(None, None, None, {"gap": 3})
    assert (bundle.pieces.gap, bundle.nest.gap) == (3.0, 3.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, bundle = _options(None, None, None, {"max_strain": 0.04, "dart_strain": 0.02})
    assert (bundle.flatten.max_strain, bundle.check.max_strain) == (0.02, 0.04)
    with pytest.warns(DeprecationWarning, match=r"batch\(records=\) goes in 0.3.0"):
        _, bundle = _options(None, None, {"flatten": patterns.FlattenOptions(max_strain=0.02)}, {})
    assert bundle.flatten.max_strain == 0.02 and bundle.check.max_strain is None


@pytest.mark.slow
def test_a_batch_script_passes_dart_strain_to_the_darts_and_max_strain_to_the_check(tmp_path):
    """Through the real batch: the darts' limit cuts darts, the check's limit judges, in one call."""
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "cup.step").write_bytes((SAMPLES / "cup.step").read_bytes())
    result = patterns.batch(tmp_path / "in", tmp_path / "out", jobs=1, dart_strain=0.03, max_strain=0.2)
    row = result.rows[0]
    assert row.status == "ok", row
    assert row.strain_max is not None and row.strain_max < 0.2
    data = json.loads((tmp_path / "out" / "cup.json").read_text())
    assert data["limits"]["max_strain"] == 0.2
    assert sum(len(p.get("darts", [])) for p in data["panels"]) > 0


def test_the_front_doors_make_their_records_through_the_bundle_only():
    """The command line, batch, the jobs and the worker never build a part's option record themselves: every
    one comes from a Bundle (the walk of a parameter from any door goes through patterns/bundle.py)."""
    records = {"LoadOptions", "MeshingOptions", "FlattenOptions", "UnfoldOptions", "PieceOptions", "NestOptions",
               "CheckOptions", "WriteOptions"}
    doors = [REPO / "patterns" / "cli.py", *sorted((REPO / "patterns" / "batching").glob("*.py")),
             REPO / "patterns" / "jobs.py", *sorted((REPO / "patterns" / "service").glob("*.py"))]
    made = []
    for path in doors:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call):
                func = node.func
                target = func.value if isinstance(func, ast.Attribute) else func
                if isinstance(target, ast.Name) and target.id in records:
                    made.append(f"{path.name} {ast.unparse(func)}")
                if isinstance(func, ast.Name) and func.id in ("from_arguments", "from_text") and node.args and \
                        isinstance(node.args[0], ast.Name) and node.args[0].id in records:
                    made.append(f"{path.name} {func.id}({node.args[0].id})")
    # the demo shows the API as a user calls it; an export's write options are the export's, not a part's
    assert made == ["cli.py CheckOptions", "work.py WriteOptions.of"], made


def test_the_worker_takes_a_bundles_json_form(tmp_path):
    """A Python client sends ``Bundle.to_json()`` as a request's options; the worker reads back the same bundle."""
    bundle = Bundle.of("pattern", {"dart_strain": 0.03, "max_strain": 0.06, "nest_gap": 5.0, "seam_allowance": 8.0})
    request = {"id": 1, "op": "validate", "kind": "pattern", "name": "Cut", "options": bundle.to_json()}
    proc = subprocess.run([sys.executable, "-m", "patterns", "serve"], input=(
        '{"id": 0, "op": "hello", "protocol": 1}\n' + json.dumps(request) + "\n").encode(),
        capture_output=True, timeout=300, env=dict(os.environ), check=False)
    replies = [json.loads(line) for line in proc.stdout.splitlines()]
    assert [r["ok"] for r in replies] == [True, True], replies
    bad = dict(request, options=dict(bundle.to_json(), dart_strain=5))
    proc = subprocess.run([sys.executable, "-m", "patterns", "serve"], input=(
        '{"id": 0, "op": "hello", "protocol": 1}\n' + json.dumps(bad) + "\n").encode(),
        capture_output=True, timeout=300, check=False)
    reply = json.loads(proc.stdout.splitlines()[1])
    assert reply["error"]["message"].startswith("Cut: dart_strain must be a ratio"), reply
