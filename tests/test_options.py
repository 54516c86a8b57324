"""One validator for every numeric option: numpy numbers taken, bools, NaN and infinities refused."""

import numpy as np
import pytest

import patterns
from patterns import surfaces
from patterns.errors import InputError
from patterns.options import check_number, is_number

from .conftest import SAMPLES


@pytest.mark.parametrize("value", [3, 3.5, np.float32(3.5), np.float64(3.5), np.int64(3)])
def test_python_and_numpy_numbers_are_numbers(value):
    assert is_number(value) and check_number(value, "x", low=0) == pytest.approx(float(value))


@pytest.mark.parametrize("value", [True, np.bool_(True), "3", None, [3], float("nan"), float("inf")])
def test_bools_strings_and_non_finite_values_are_refused(value):
    with pytest.raises(InputError, match="x must be"):
        check_number(value, "x", name="part")


def test_bounds_and_messages():
    assert check_number(0.0, "tolerance", low=0) == 0.0
    with pytest.raises(InputError, match="part: max_strain must be a positive number, got 0"):
        check_number(0, "max_strain", low=0, low_open=True, name="part")
    with pytest.raises(InputError, match="min_stretch must be a number > 0 and < 1, got 1.0"):
        check_number(1.0, "min_stretch", low=0, high=1, low_open=True, high_open=True)
    # an open end of integers names the first integer in (issue 33: "between 0 and 100000, got 0")
    with pytest.raises(InputError, match=r"^max_iterations must be an integer between 1 and 100000, got 0$"):
        check_number(0, "max_iterations", low=0, high=100_000, low_open=True, integer=True)
    with pytest.raises(InputError, match=r"^n must be an integer between 0 and 9, got 10$"):
        check_number(10, "n", low=-0.5, high=10, high_open=True, integer=True)
    with pytest.raises(InputError, match="an integer >= 0"):
        check_number(2.5, "max_darts", low=0, integer=True)


def test_the_same_number_types_everywhere():
    """np.float32 limits are taken by check as by flatten_mesh (they were refused by one and
    taken by the other); infinite text heights and spacings are refused before a file is written."""
    v, f = surfaces.spherical_cap(radius=100.0, half_angle=30.0, n_faces=300)
    assert patterns.flatten_mesh(v, f, min_stretch=np.float32(0.3)).one_to_one
    pattern = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    assert patterns.check(pattern, max_strain=np.float32(0.03)).ok
    with pytest.raises(InputError, match="max_strain"):
        patterns.check(pattern, max_strain=True)


@pytest.mark.parametrize("option", ["text_height", "notch_spacing", "bend_spacing", "arc_tolerance"])
def test_dxf_lengths_must_be_finite(tmp_path, option):
    pattern = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    out = tmp_path / "x.dxf"
    with pytest.raises(InputError, match=option):
        patterns.write(pattern, out, **{option: float("inf")})
    assert not out.exists()


# --------------------------------------------------------------------------- #
# One declaration per option: the API's records and the CLI's flags
# --------------------------------------------------------------------------- #

import dataclasses  # noqa: E402

from patterns import cli  # noqa: E402
from patterns.pieces.options import PATTERN_ONLY  # noqa: E402
from patterns.options import cli_flags, from_arguments  # noqa: E402

RECORDS = {"load": patterns.LoadOptions, "flatten": patterns.FlattenOptions, "check": patterns.CheckOptions,
           "pieces": patterns.PieceOptions, "write": patterns.WriteOptions, "nest": patterns.NestOptions,
           "batch": patterns.BatchOptions, "unfold": patterns.UnfoldOptions}
COMMANDS = {"flatten": ("load", "flatten", "check", "pieces", "write", "nest"),
            "batch": ("load", "flatten", "unfold", "check", "pieces", "write", "nest", "batch"),
            "unfold": ("unfold", "pieces", "write", "nest"),
            "check": ("load", "flatten", "check"), "info": ("load",)}
FROM_OTHER_FLAGS = {("pieces", name) for name in PATTERN_ONLY}
"""Options a command does not take: a blank has no seams, rulings or strain (``patterns unfold``)."""


def _subparser(command):
    parser = cli._parser()
    action = next(a for a in parser._actions if a.dest == "command")
    return action.choices[command]


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_api_option_has_its_cli_flag(command):
    """Every field of every record the command uses is a flag of that command (flatten and batch alike)."""
    flags = {s for a in _subparser(command)._actions for s in a.option_strings}
    for key in COMMANDS[command]:
        missing = {name: flag for name, flag in cli_flags(RECORDS[key]).items()
                   if flag not in flags and not (command == "unfold" and (key, name) in FROM_OTHER_FLAGS)}
        assert not missing, f"patterns {command} lacks flags for {RECORDS[key].__name__}: {missing}"


CLI_VALUES = [  # (flag and text, record, the API's keyword and value)
    (["--max-edge", "2.5"], "load", "max_edge", 2.5),
    (["--chord-tolerance", "0.02"], "load", "chord_tolerance", 0.02),
    (["--panel", "front=0,1", "--panel", "back=2"], "load", "panels", {"front": [0, 1], "back": [2]}),
    (["--no-sew"], "load", "sew", False),
    (["--weld-vertices", "no"], "load", "weld_vertices", False),
    (["--input-units", "in"], "load", "units", "in"),
    (["--units", "in"], "write", "units", "in"),
    (["--method", "isometric"], "flatten", "method", "isometric"),
    (["--no-exact"], "flatten", "exact", False),
    (["--grain", "0,0,2"], "flatten", "grain", (0.0, 0.0, 1.0)),  # a direction, normalised
    (["--ease", "0:face0:2%"], "flatten", "ease", (patterns.Ease(0, "face0", ratio=0.02),)),
    (["--dart-strain", "0.03"], "flatten", "max_strain", 0.03),
    (["--max-darts", "7"], "flatten", "max_darts", 7),
    (["--energy-tolerance", "1e-7"], "flatten", "energy_tolerance", 1e-7),
    (["--max-strain", "0.05"], "check", "max_strain", 0.05),
    (["--max-seam-mismatch", "0.5"], "check", "max_seam_mismatch", 0.5),
    (["--profile", "astm"], "write", "profile", "astm"),
    (["--dxf-version", "R12"], "write", "version", "R12"),
    (["--strain-layer"], "pieces", "strain_layer", True),
    (["--text-height", "4"], "pieces", "text_height", 4.0),
    (["--notch-style", "v"], "pieces", "notch_style", "v"),
    (["--seam-corners", "square"], "pieces", "seam_corners", "square"),
    (["--roll-width", "1500"], "nest", "width", 1500.0),
    (["--sheet", "2500x1250"], "nest", "sheet", (2500.0, 1250.0)),
    (["--nest-gap", "5"], "nest", "gap", 5.0),
    (["--rotations", "quarter"], "nest", "rotations", "quarter"),
    (["--copies", "2"], "nest", "copies", 2),
    (["--mirror"], "nest", "mirror", True),
    (["--quantity", "face0=3", "--quantity", "face1=2"], "nest", "quantities", {"face0": 3, "face1": 2}),
    (["--nest-time", "3"], "nest", "time_limit", 3),
    (["--nest-seed", "7"], "nest", "seed", 7),
    (["--margin", "0.2"], "nest", "margin", 0.2),
    (["--no-bend-lines"], "write", "bend_lines", False),
    (["--layer-map", "updown"], "write", "layer_map", patterns.export.layer_map("updown")),
    (["--no-nest-cache"], "nest", "cache", False),
    (["--crease-angle", "45"], "load", "crease_angle", 45.0),
    (["--area-tolerance", "0.1"], "check", "area_tolerance", 0.1),
    (["--max-distortion", "3"], "check", "max_distortion", 3.0),
]

BATCH_VALUES = [
    (["--jobs", "3"], "jobs", 3), (["--scheduler", "tcp://h:8786"], "scheduler", "tcp://h:8786"),
    (["--timeout", "30"], "timeout", 30.0), (["--memory", "2048"], "memory", 2048.0), (["--wait", "5"], "wait", 5.0),
    (["--no-report"], "report", False), (["--preview"], "preview", True), (["--heat-map"], "heat_map", True),
    (["--quiet"], "quiet", True), (["--unfold"], "unfold", True),
]


@pytest.mark.parametrize(("argv", "name", "value"), BATCH_VALUES)
def test_a_batch_flag_makes_the_record_the_api_makes(argv, name, value):
    args = cli._parser().parse_args(["batch", "parts", "-o", "out", *argv])
    from_cli = from_arguments(patterns.BatchOptions, args)
    assert from_cli == patterns.BatchOptions.of(None, {name: value}) and getattr(from_cli, name) == value


@pytest.mark.parametrize(("argv", "key", "name", "value"), CLI_VALUES)
def test_a_flag_makes_the_record_the_api_makes(argv, key, name, value):
    args = cli._parser().parse_args(["flatten", "part.step", "-o", "x.dxf", *argv])
    from_cli = from_arguments(RECORDS[key], args)
    assert from_cli == RECORDS[key].of(None, {name: value})
    assert getattr(from_cli, name) == value
    # and the flags not given leave the API's defaults
    defaults = {f.name: f.default for f in dataclasses.fields(RECORDS[key]) if f.name != name}
    assert all(getattr(from_cli, k) == v for k, v in defaults.items())


@pytest.mark.parametrize(("flag", "text", "message"), [
    ("--max-darts", "-1", "--max-darts must be an integer between 0 and 100, got -1"),
    ("--k-factor", "1.5", "--k-factor must be a number between 0 and 1, got 1.5"),
    ("--text-height", "inf", "--text-height must be a positive number <= 1e+07, got inf"),
    ("--max-strain", "0", "--max-strain must be a ratio > 0 and <= 1 (0.03 means 3 %), got 0.0"),
    ("--max-strain", "3", "--max-strain must be a ratio > 0 and <= 1 (0.03 means 3 %), got 3.0; 3 % is 0.03"),
    ("--dart-strain", "5", "--dart-strain must be a ratio > 0 and <= 1 (0.03 means 3 %), got 5.0; 5 % is 0.05"),
    ("--area-tolerance", "2", "--area-tolerance must be a ratio > 0 and <= 1 (0.03 means 3 %), got 2.0"),
    ("--max-iterations", "0", "--max-iterations must be an integer between 1 and 100000, got 0"),
    ("--chord-tolerance", "nan", "--chord-tolerance must be a positive number <= 1e+07, got nan"),
    ("--nest-gap", "-1", "--nest-gap must be a number between 0 and 1e+07, got -1.0"),
])
def test_a_bad_flag_fails_in_one_line_before_loading(tmp_path, capsys, flag, text, message):
    """The CLI's refusal is the API's message with the flag the user typed, given before the (missing) input is
    even read."""
    code = cli.main(["flatten", str(tmp_path / "missing.step"), "-o", str(tmp_path / "x.dxf"), flag, text])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err
    assert not list(tmp_path.iterdir())


def test_unknown_keywords_name_the_options():
    with pytest.raises(InputError, match="unknown option 'max_strian'; did you mean max_strain\\?; the options are max_strain"):
        patterns.CheckOptions.of(None, {"max_strian": 0.1})
    pattern = patterns.flatten(patterns.load(SAMPLES / "hopper.step"))
    with pytest.raises(InputError, match="unknown option 'seam_alowance'"):
        patterns.write(pattern, "never.dxf", seam_alowance=3)


def test_records_are_frozen_and_documented():
    record = patterns.WriteOptions(units="in")
    with pytest.raises(dataclasses.FrozenInstanceError):
        record.units = "mm"
    for cls in RECORDS.values():
        for f in dataclasses.fields(cls):
            assert f"    {f.name} : " in cls.__doc__, (cls.__name__, f.name)


@pytest.mark.parametrize(("unit", "mm", "insunits"), [("mm", 1.0, 4), ("cm", 10.0, 5), ("m", 1000.0, 6),
                                                       ("in", 25.4, 1)])
def test_the_unit_table(unit, mm, insunits):
    """AutoCAD's $INSUNITS codes (1 inch, 4 mm, 5 cm, 6 m) and the size of each unit."""
    assert patterns.Unit(unit).mm == mm and patterns.Unit(unit).insunits == insunits
    assert patterns.Unit(unit).measurement == (0 if unit == "in" else 1)


def test_every_strain_option_is_a_ratio_and_says_how_to_write_a_percentage():
    """Issue 34: max_strain=3 (meant as 3 %) was taken as 300 %; one rule for every strain option."""
    for record, name in ((patterns.CheckOptions, "max_strain"), (patterns.FlattenOptions, "max_strain"),
                         (patterns.CheckOptions, "area_tolerance")):
        assert getattr(record.of(None, {name: 1}), name) == 1.0 and getattr(record.of(None, {name: 0.03}), name) == 0.03
        for bad in (3, 1.0001, 0, -0.03, float("nan"), "3%"):
            with pytest.raises(patterns.InputError, match=rf"^{name} must be a ratio > 0 and <= 1 \(0.03 means 3 %\)"):
                record.of(None, {name: bad})


def test_check_refuses_a_strain_limit_given_in_percent(tmp_path):
    pattern = patterns.flatten(patterns.load(SAMPLES / "cone.obj"))
    with pytest.raises(patterns.InputError, match=r"max_strain must be a ratio .* got 3; 3 % is 0.03"):
        patterns.check(pattern, max_strain=3)
    with pytest.raises(patterns.InputError, match=r"max_strain must be a ratio"):
        patterns.heat_map(pattern, tmp_path / "h.png", max_strain=3)
    assert not list(tmp_path.iterdir())


def test_none_on_the_command_line_leaves_an_optional_option_unset():
    """--area-tolerance None: the help offers it ("none: not checked"), and the record has None."""
    for text in ("None", "none", "NONE"):
        args = cli._parser().parse_args(["flatten", "part.step", "-o", "x.dxf", "--area-tolerance", text])
        assert from_arguments(patterns.CheckOptions, args).area_tolerance is None
    args = cli._parser().parse_args(["flatten", "part.step", "-o", "x.dxf"])
    assert from_arguments(patterns.CheckOptions, args).area_tolerance == 0.05


@pytest.mark.parametrize(("typed", "meant"), [("--seam-alowance", "--seam-allowance"), ("--max-strian", "--max-strain"),
                                              ("--nest-tme", "--nest-time"), ("--roll-widht=100", "--roll-width")])
def test_a_mistyped_flag_gets_a_did_you_mean_and_its_commands_help(tmp_path, capsys, typed, meant):
    code = cli.main(["flatten", str(tmp_path / "missing.step"), "-o", str(tmp_path / "x.dxf"), typed, "5"])
    err = capsys.readouterr().err.strip().splitlines()
    flag = typed.split("=")[0]
    want = f"patterns: error: unknown option {flag}; did you mean {meant}? (patterns flatten --help lists the options)"
    assert code == 2 and err == [want], err
    assert not list(tmp_path.iterdir())


def test_the_api_names_its_keyword_and_the_command_line_its_flag():
    with pytest.raises(patterns.InputError, match=r"^gap 1e\+06 mm \(and margin 0 mm each side\) is as wide"):
        patterns.NestOptions.of(None, {"width": 1500, "gap": 1e6})
    with pytest.raises(patterns.InputError, match=r"^unknown option 'max_strian'; did you mean max_strain\?"):
        patterns.CheckOptions.of(None, {"max_strian": 0.03})
    args = cli._parser().parse_args(["flatten", "p.step", "-o", "x.dxf", "--roll-width", "1500", "--nest-gap", "1e6"])
    with pytest.raises(patterns.InputError, match=r"^--nest-gap 1e\+06 mm \(and --margin 0 mm each side\)"):
        from_arguments(patterns.NestOptions, args)
    assert patterns.options.label("gap") == "gap"  # the flags are named only while the command line makes a record


def test_a_flag_that_turns_an_option_off_says_what_it_does():
    """--no-sew, --no-exact, --no-nest-cache, ...: their help is the option's off= text (what the flag does), never
    the default's description; an option on by default without one is refused when the flags are made."""
    import argparse

    text = " ".join(cli._parser().commands["batch"].format_help().split())
    for record in (patterns.LoadOptions, patterns.FlattenOptions, patterns.NestOptions, patterns.WriteOptions,
                   patterns.BatchOptions):
        for f in dataclasses.fields(record):
            spec = f.metadata.get("spec")
            if spec is not None and f.default is True:
                flag = patterns.options.cli_flags(record)[f.name]
                assert flag.startswith("--no-") and f"{flag} {' '.join(spec.off.split())}" in text, (flag, spec.off)

    @dataclasses.dataclass(frozen=True)
    class Careless(patterns.options.Options):
        thing: bool = patterns.options.option(True, "a thing, on")

    with pytest.raises(TypeError, match="needs off="):
        patterns.options.add_arguments(argparse.ArgumentParser(), Careless)
