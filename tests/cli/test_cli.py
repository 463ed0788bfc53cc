"""The command line: output formats and clean failures."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib

import pytest

from spinectl import jsondoc, optimise
from spinectl.cli import main
from spinectl.model import config
from spinectl.model.clinical import with_lordosis_angle
from spinectl.model.stability import segment_stability


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_stability_table(capsys):
    code, out, _ = run(["stability", "--E", "0.03", "--Lambda", "0.04", "--pcsa", "10,10,10"], capsys)
    assert code == 0
    assert "L5S1" in out and "||CT||" in out


def test_stability_prints_the_results_dict_and_table(capsys):
    """``--json`` prints :meth:`StabilityResult.to_dict` (and ``lordosis_angle_deg``), the table
    :meth:`StabilityResult.table` (their schema and values: tests/model/test_stability.py)."""
    argv = ["stability", "--E", "0.03", "--Lambda", "0.04", "--pcsa", "10,10,10", "--K", "15"]
    model = config.set_parameter(config.load_preset(config.DEFAULT_PRESET), "passive.stiffness", 15.0)
    result = segment_stability(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    code, out, _ = run([*argv, "--json"], capsys)
    assert code == 0 and out == jsondoc.dumps(with_lordosis_angle(result.to_dict(model), model))
    code, out, _ = run(argv, capsys)
    assert code == 0 and out == result.table(model) + "\n"


def test_config_show_is_loadable_toml(capsys, tmp_path):
    code, out, _ = run(["config", "show"], capsys)
    assert code == 0
    tomllib.loads(out)
    path = tmp_path / "shown.toml"
    path.write_text(out)
    assert config.load_config(path) == config.load_preset(config.DEFAULT_PRESET)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["stability", "--E", "0.5", "--pcsa", "1,1,1"], "E: must be in"),
        (["stability", "--E", "nan", "--pcsa", "1,1,1"], "--E must be finite"),
        (["stability", "--pcsa", "1,1"], "pcsa: must have 3 values"),
        (["stability", "--pcsa", "a"], "--pcsa must be a number"),
        (["stability", "--pcsa", "1,1,1", "--config", "/no/such.toml"], "file not found"),
        (["stability", "--pcsa", "1,1,1", "--preset", "nope"], "preset: must be one of"),
        (["stability", "--pcsa", "1,1,1", "--K", "-1"], "passive.stiffness: must be >= 0"),
        (["stability", "--pcsa", "1,1,1", "--set", "fibre.law=hil"], "fibre.law: must be one of 'wagner2012'"),
        (["export", "--set", "fibre.law=wagner2021", "--out", "x.xml"], "; did you mean 'wagner2012'?"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_input_is_one_line_exit_2(argv, needle, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2
    assert needle in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_stability_defaults_to_the_minimum_stabilising_pcsa(capsys):
    """Without --pcsa the optimiser's chosen activation is used: self-stable, total = solve_point's."""
    code, out, _ = run(["stability", "--E", "0.03", "--Lambda", "0.04", "--json"], capsys)
    assert code == 0
    doc = json.loads(out)
    assert doc["pcsa_source"] == "min_pcsa" and doc["all_self_stable"]
    assert doc["preset"] == config.DEFAULT_PRESET
    expected = optimise.solve_point(config.load_preset(config.DEFAULT_PRESET), 0.03, 0.04)
    assert doc["chosen_pcsa_total_cm2"] == pytest.approx(expected.total_pcsa * 1e4, rel=1e-9)
    assert doc["total_pcsa_cm2"] == doc["chosen_pcsa_total_cm2"]  # the old key, kept for one release
    assert doc["min_pcsa_cm2"] == pytest.approx(expected.min_pcsa * 1e4, rel=1e-9)  # the LP's own minimum
    # the chosen activation lies within ct_tolerance above the LP minimum (docs/optimisation.md)
    tolerance = config.load_preset(config.DEFAULT_PRESET).optimisation.ct_tolerance
    assert doc["min_pcsa_cm2"] <= doc["chosen_pcsa_total_cm2"] <= doc["min_pcsa_cm2"] * (1 + tolerance) + 1e-9
    code, out, _ = run(["stability", "--E", "0.03", "--Lambda", "0.04"], capsys)
    assert code == 0 and "minimum stabilising" in out


def test_stability_without_a_stabilising_pcsa_is_exit_2(tmp_path, capsys):
    """At most 1 cm^2 per muscle cannot hold the upright body: no default PCSA exists."""
    path = tmp_path / "weak.toml"
    path.write_text("[optimisation]\npcsa_max = 1e-4\n")
    code, _, err = run(["stability", "--config", str(path)], capsys)
    assert code == 2 and "no activation stabilises" in err and len(err.strip().splitlines()) == 1


def test_bad_config_values_from_file(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text("[body]\nmass = -1.0\n")
    code, _, err = run(["stability", "--pcsa", "1,1,1", "--config", str(path)], capsys)
    assert code == 2 and err.strip() == "spinectl: error: body.mass: must be > 0 (got -1)"


def test_module_entry_point_runs_in_a_subprocess():
    proc = subprocess.run(
        [sys.executable, "-m", "spinectl", "stability", "--E", "1", "--pcsa", "1,1,1"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1


def _preset_file(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('preset = "default"\n[body]\nmass = 41.0\n')
    return path


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["calibrate", "--out", "{d}/x.toml", "--history", "{d}/x.toml"], "--history: is the same file as --out"),
        (["calibrate", "--config", "{c}", "--out", "{c}"], "--out: is the same file as --config"),
        (["calibrate", "--config", "{c}", "--history", "{d}/link.toml"], "--history: is the same file as --config"),
        (["calibrate", "--out", "{d}/x.toml", "--history", "{d}/sub/../x.toml"], "--history: is the same file as"),
        (["sweep", "--config", "{c}", "--out", "{d}/link.toml", "--E", "0:0:1", "--Lambda", "0:0:1"], "--out: is"),
        (["margins", "--config", "{d}/bode.png", "--plot", "{d}"], "--plot: is the same file as --config"),
        (["reproduce", "--config", "{d}/report.md", "--out", "{d}"], "--out: is the same file as --config"),
    ],
)
def test_an_output_never_replaces_an_input_or_another_output(tmp_path, capsys, argv, needle):
    """Every spelling of one file (the same name, a symlink, ``sub/..``) is refused before any work, one line.

    Before, ``calibrate --out X --history X`` replaced the preset with the CSV, and
    ``--config X --out X`` the input with the output.
    """
    config = _preset_file(tmp_path)
    (tmp_path / "link.toml").symlink_to(config)
    (tmp_path / "sub").mkdir()
    for name in ("bode.png", "report.md"):
        (tmp_path / name).write_text(config.read_text())
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    assert main([a.format(d=tmp_path, c=config) for a in argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before


def test_a_negative_grid_start_is_a_value(tmp_path, capsys):
    """--E -0.02:0.02:3 parses as the axis (argparse alone took it for an option)."""
    out = tmp_path / "n.nc"
    assert main(["sweep", "--E", "-0.02:0.02:3", "--Lambda", "0.03", "--out", str(out)]) == 0
    from spinectl.landscape import netcdf

    assert netcdf.load(out)["E"].values.tolist() == [-0.02, 0.0, 0.02]


def test_set_errors_are_one_line_as_in_a_file(tmp_path, capsys):
    """--set body.mas=3 and a file with [body] mas = 3 print the same line (exit 2)."""
    path = tmp_path / "bad.toml"
    path.write_text("[body]\nmas = 3\n")
    code, _, from_file = run(["stability", "--config", str(path)], capsys)
    assert code == 2
    code, _, from_set = run(["stability", "--set", "body.mas=3"], capsys)
    assert code == 2 and from_set == from_file and "did you mean 'mass'" in from_set and from_set.count("\n") == 1


def test_set_reaches_every_command_and_is_marked(capsys):
    """The table's first line marks the overridden field; --K is an alias of --set passive.stiffness."""
    code, out, _ = run(["stability", "--pcsa", "10,10,10", "--set", "passive.stiffness=15"], capsys)
    header = out.splitlines()[0]
    assert code == 0 and header.endswith("K = 15 N m/rad, convention physical; overridden: passive.stiffness")
    code, out, _ = run(["stability", "--pcsa", "10,10,10", "--K", "10"], capsys)
    assert code == 0 and out.splitlines()[0].endswith(
        "K = 10 N m/rad, convention physical; overridden: passive.stiffness"
    )
    for argv in (["margins"], ["config", "show"], ["draw", "--geometry-only", "--out", "/nonexistent/x.png"]):
        code, _, err = run([*argv, "--set", "reflex.delay=-1"], capsys)
        assert code == 2 and "reflex.delay: must be" in err


def test_config_diff_prints_every_difference_with_its_unit(capsys):
    code, out, _ = run(["config", "diff", "wagner2012", "default"], capsys)
    assert code == 0
    lines = out.splitlines()
    assert lines[0].startswith("--- preset wagner2012") and lines[1].startswith("+++ preset default")
    assert "body.mass [kg]: 24.0566 -> 40" in lines  # the presets' files: 24.0566 kg and 40 kg
    assert not any(line.startswith("passive.convention") for line in lines)  # both physical: not a difference
    code, out, _ = run(["config", "diff", "default", "default"], capsys)
    assert code == 0 and out.splitlines()[-1] == "no parameter differs"


def test_a_file_that_replaces_the_muscles_is_silent_and_shows_its_pairs(tmp_path, capsys):
    """muscles_mode = "replace" is the author's written choice: no warning (before: one on every command),
    and config show lists the file's pair alone."""
    path = tmp_path / "one.toml"
    path.write_text('muscles_mode = "replace"\n[[muscles]]\nname = "only"\nupper = [0.1, 0.25]\nlower = [0.1, 0.0]\n')
    code, out, err = run(["config", "show", "--config", str(path)], capsys)
    assert code == 0 and err == ""
    assert out.splitlines().count("[[muscles]]") == 1 and 'name = "only"' in out and 'name = "straight"' not in out


def test_a_home_that_cannot_be_written_leaves_stderr_empty(tmp_path):
    """HOME=/proc (no folder can be made there, not even by root) and no MPLCONFIGDIR: matplotlib falls
    back to a temporary configuration folder; before, it said so in two lines on stderr of a command
    that succeeded."""
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    env = {k: v for k, v in os.environ.items() if k not in ("MPLCONFIGDIR", "XDG_CONFIG_HOME", "XDG_CACHE_HOME")}
    env |= {"HOME": "/proc", "PYTHONPATH": str(root)}
    command = [sys.executable, "-m", "spinectl", "draw", "--E", "0.03", "--Lambda", "0.04", "--out"]
    done = subprocess.run([*command, str(tmp_path / "d.png")], env=env, cwd=root, capture_output=True, text=True)
    assert (done.returncode, done.stderr) == (0, "") and (tmp_path / "d.png").is_file()


@pytest.mark.parametrize("preset", config.list_presets())
def test_config_show_comments_describe_the_shown_value_or_name_the_default(preset, capsys):
    """A comment that justifies a number must be about the value printed under it: where the preset's value
    is not the default, a comment that states the default (e.g. wagner2012's mass, 24.06 kg, under a comment
    of the default's 40 kg) must say that number is the default's."""
    import dataclasses
    import re

    assert main(["config", "show", "--preset", preset]) == 0
    lines = capsys.readouterr().out.splitlines()
    model = config.load_preset(preset)
    checked = 0
    for section in ("body", "levels", "local", "passive", "reflex", "optimisation", "fibre"):
        if not hasattr(model, section):
            continue
        start = lines.index(f"[{section}]")
        for f in dataclasses.fields(getattr(model, section)):
            value, default = getattr(getattr(model, section), f.name), f.default
            if not isinstance(default, float) or value == default:
                continue
            row = next(k for k in range(start, len(lines)) if lines[k].startswith(f"{f.name} = "))
            comment = lines[row - 1]
            unit = re.escape(f.metadata["unit"])
            states_a_value = re.search(rf"(?<![\d.]){re.escape(f'{default:g}')}(?![\d.])", comment) or re.search(
                rf"\d ?{unit}\b", comment.split("]", 1)[1]
            )
            if states_a_value:  # e.g. "55 % of a 73 kg body": a value the shown one is not
                assert "default" in comment, (section, f.name, comment)
            checked += 1
    assert checked > 0 or preset == "default"


@pytest.mark.parametrize(
    ("argv", "option", "hint"),
    [
        (["stability", "--E", "3"], "--E", "if you meant 3 cm, give 0.03"),
        (["margins", "--Lambda", "4"], "--Lambda", "if you meant 4 cm, give 0.04"),
        (["draw", "--E", "-2", "--out", "never.png"], "--E", "if you meant -2 cm, give -0.02"),
        (["stability", "--E", "0.5"], "--E", ""),  # 5 times the range: no likely cm slip, no hint
        (["stability", "--E", "30"], "--E", ""),  # 30 cm is out of range too
    ],
)
def test_a_length_in_cm_gets_a_hint_naming_the_option(argv, option, hint, capsys, tmp_path, monkeypatch):
    """The range check names the option typed, and a value that is in range once read as cm says so
    (the model's range is [-0.1, 0.1] m: docs/model.md)."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run(argv, capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith(f"spinectl: error: {option}: must be in [-0.1, 0.1] m, the modelled range (got ")
    assert (hint in err) if hint else ("if you meant" not in err)
    assert not (tmp_path / "never.png").exists()


def test_a_grid_out_of_range_names_the_spec_typed_and_the_spec_in_metres(tmp_path, capsys):
    """Before: 'E: must be in [-0.1, 0.1] m ... (got 0.2)', the first bad grid point, not what was typed."""
    out_file = tmp_path / "r.nc"
    code, _, err = run(["sweep", "--E", "0:8:81", "--out", str(out_file)], capsys)
    assert code == 2 and err.count("\n") == 1 and not out_file.exists()
    assert "--E: must be in [-0.1, 0.1] m, the modelled range (got '0:8:81': 0 to 8 m)" in err
    assert err.rstrip().endswith("if you meant 0:8:81 cm, give 0:0.08:81")
    code, _, err = run(["sweep", "--Lambda", "0:0.5:3", "--out", str(out_file)], capsys)
    assert code == 2 and "(got '0:0.5:3': 0 to 0.5 m)" in err and "if you meant" not in err


def test_a_study_grid_out_of_range_is_one_line_naming_the_axis_as_written(tmp_path, capsys):
    """``spinectl study`` says what ``spinectl sweep`` says, in the study file's words: exit 2, one line,
    no store (the range [-0.1, 0.1] m: docs/model.md)."""
    path, out_dir = tmp_path / "s.toml", tmp_path / "s.zarr"
    path.write_text("[axes]\nE = { start = 0, stop = 8, num = 81 }\nLambda = [0.0]\n")
    code, out, err = run(["study", str(path), "--out", str(out_dir)], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1 and not out_dir.exists()
    assert err.startswith("spinectl: error: axes.E: must be in [-0.1, 0.1] m, the modelled range (got ")
    assert err.rstrip().endswith(
        "if you meant { start = 0, stop = 8, num = 81 } cm, give { start = 0, stop = 0.08, num = 81 }"
    )


def test_a_pcsa_in_square_metres_gets_a_warning_and_runs(capsys):
    """0.001 typed for 0.001 m^2 (10 cm^2): a warning naming --pcsa and the value to give; zeros and
    plausible values warn of nothing."""
    code, out, err = run(["stability", "--pcsa", "0.001,0.002,0"], capsys)
    assert code == 0 and "L5S1" in out
    assert err == (
        "spinectl: warning: --pcsa: 0.001 cm^2 is less than any muscle's PCSA (below 0.1 cm^2); PCSA is in "
        "cm^2 here: if you meant 0.001 m^2, give 10\n"
    )
    code, _, err = run(["stability", "--pcsa", "0,10,0.5"], capsys)
    assert code == 0 and err == ""
    code, _, err = run(["stability", "--pcsa", "0.001,0.001,0.001", "--E", "3"], capsys)  # failed: error only
    assert code == 2 and err.count("\n") == 1 and err.startswith("spinectl: error: --E")


def test_an_optimum_beyond_any_muscle_can_be_fed_back_to_pcsa(capsys):
    """A 100 kg body on fibres of 1e4 N/m^2 needs about 1857 cm^2 in each outer oblique at E = 3, Lambda = 4 cm:
    `stability` prints that optimum, and `--pcsa` with it (refused before, above 1000 cm^2 per muscle) gives the
    same table, S(L1L2) at the optimiser's stability margin, -0.1 N m/rad (optimisation.stability_margin), with
    one warning line that the PCSA is more than any muscle's. Only a PCSA beyond which the torques overflow
    (checks.MAX_PCSA, 1e104 cm^2) is refused, in cm^2."""
    heavy = ["stability", "--E", "0.03", "--Lambda", "0.04", "--set", "body.mass=100", "--set"]
    heavy.append("fibre.specific_tension=1e4")
    code, out, err = run(heavy, capsys)
    assert code == 0 and err == ""
    pcsa = out.splitlines()[2].split(": ", 1)[1].split("  (total")[0]
    per_muscle = [float(item.rsplit(" ", 1)[1]) for item in pcsa.split(", ")]
    assert max(per_muscle) > 1000
    code, again, err = run([*heavy, "--pcsa", ",".join(f"{p:.6f}" for p in per_muscle)], capsys)
    assert code == 0 and err.count("\n") == 1 and "more than any muscle's PCSA (above 1000 cm^2" in err
    assert float(again.splitlines()[5].split()[1]) == pytest.approx(-0.1, abs=2e-3)
    code, out, err = run(["stability", "--pcsa", "1e300,1,1"], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("spinectl: error: --pcsa: must be at most 1e+104 cm^2 per muscle, beyond which the torques")


def test_k_1e308_is_answered(capsys):
    """docs/robustness.md, "extreme but harmless values": --K 1e308 gives a table, exit 0 (before: the
    discriminant D^2 + 4 theta S overflowed, a ModelError). S = -1e308 N m/rad at every CoR, printed as such
    (not 309 digits); the eigenvalues are D / (2 theta) +- j sqrt(-S / theta) to rounding (closed form). Their
    real part gives the segment's time constant 2 theta / |D|: "marginal" where it exceeds the threshold
    (:data:`spinectl.model.stability.MARGINAL_TIME_CONSTANT`), "yes" below it."""
    from spinectl.model.stability import MARGINAL_TIME_CONSTANT

    code, out, err = run(["stability", "--E", "0.03", "--Lambda", "0.04", "--K", "1e308"], capsys)
    assert code == 0 and err == ""
    row = out.splitlines()[5].split()  # L1L2: S, D, theta, lambda_1, lambda_2, stable, CT
    damping, theta = float(row[2]), float(row[3])
    expected = "marginal" if 2 * theta / abs(damping) > MARGINAL_TIME_CONSTANT else "yes"
    assert row[0] == "L1L2" and row[1] == "-1.000e+308" and row[-2] == expected
    imag = float(row[4].split("+", 1)[1].rstrip("j"))
    assert imag == pytest.approx((1e308 / theta) ** 0.5, rel=1e-3)  # theta as printed, to 4 decimals
    assert max(len(line) for line in out.splitlines()[4:10]) < 120  # the header and rows of the table


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["stability", "--E", "nan"], "spinectl: error: stability: argument --E: --E must be finite (got 'nan')"),
        (["stability", "--pcsa"], "spinectl: error: stability: argument --pcsa: expected one argument"),
        (
            ["margins", "--delya", "0.05"],
            "spinectl: error: margins: unrecognized arguments: --delya 0.05; did you mean --delay?",
        ),
        (
            ["margins", "--activaton=1"],
            "spinectl: error: margins: unrecognized arguments: --activaton=1; did you mean --activation?",
        ),
        (["stability", "--frob"], "spinectl: error: stability: unrecognized arguments: --frob"),
        (["stabilty"], "spinectl: error: argument COMMAND: invalid choice: 'stabilty' (choose from "),
    ],
)
def test_argparse_errors_read_like_the_others_with_a_suggestion(argv, line, capsys):
    """One line, 'spinectl: error: ...' as the library's errors (before: 'error: spinectl stability: ...'), exit 2;
    a mistyped option or command gets difflib's closest name."""
    code, out, err = run(argv, capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith(line)
    if argv == ["stabilty"]:
        assert err.rstrip().endswith("; did you mean stability?")
    if argv == ["stability", "--frob"]:
        assert "did you mean" not in err  # nothing close: no guess


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        # before: K = 15 whatever the order, silently
        (["stability", "--K", "15", "--set", "passive.stiffness=0"], "--K: sets passive.stiffness, as does --set"),
        (["sweep", "--K", "15", "--set", "passive.stiffness=0", "--out", "k.nc"], "--K: sets passive.stiffness"),
        (["margins", "--delay", "0.1", "--set", "reflex.delay=0.2"], "--delay: sets reflex.delay, as does --set"),
        # before: the single point E = 0, silently
        (["sweep", "--E", "0:0.08:1", "--out", "one.nc"], "--E: with NUM = 1 must have START = STOP"),
        # before: NetCDF written under the .csv name
        (["sweep", "--E", "0.03", "--Lambda", "0.04", "--out", "x.csv"], "--out: must end in .nc"),
        # before: "must be in [0, 10]" without a unit
        (["margins", "--delay", "100"], "reflex.delay: must be in [0, 10] s (got 100); if you meant 100 ms, give 0.1"),
    ],
)
def test_silent_choices_are_refused(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(argv, capsys)
    assert code == 2 and message in err and err.count("\n") == 1
    assert not list(tmp_path.iterdir())  # nothing written


def test_a_one_point_sweep_says_point(capsys, tmp_path):
    code, out, _ = run(["sweep", "--E", "0.03", "--Lambda", "0.04", "--out", str(tmp_path / "one.nc")], capsys)
    assert code == 0 and ": 1 point (1 solved" in out


def test_no_cm_hint_for_a_plain_value_beyond_a_narrow_range(capsys):
    """examples/coronal.toml allows E within +-1 mm: --E 0.03 is out of range, and reading it as 0.03 cm
    (0.3 mm) would fit, but nobody types 0.03 meaning cm. The hint is kept for --E 3 against the usual range."""
    from pathlib import Path

    coronal = Path(__file__).resolve().parents[2] / "examples" / "coronal.toml"
    assert main(["stability", "--config", str(coronal), "--E", "0.03", "--Lambda", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--E: must be in [-0.001, 0.001] m" in err and "if you meant" not in err
    assert main(["stability", "--E", "3", "--Lambda", "0.04"]) == 2
    assert "if you meant 3 cm, give 0.03" in capsys.readouterr().err


class _FailingStdout:
    """A standard output whose every write fails with ``error`` (a full device, a closed pipe)."""

    def __init__(self, error: OSError):
        self.error = error

    def write(self, text):
        raise self.error

    def flush(self):
        pass


@pytest.mark.parametrize("argv", [["config", "show"], ["--help"], ["--version"]])
def test_standard_output_on_a_full_device_is_one_line_exit_2(argv, capsys, monkeypatch):
    """ENOSPC on stdout: one line naming standard output, exit 2, no traceback (before: a traceback, or for
    --help and --version nothing at all and exit 0, argparse swallowing the OSError)."""
    import errno

    capsys.readouterr()
    monkeypatch.setattr(sys, "stdout", _FailingStdout(OSError(errno.ENOSPC, "No space left on device")))
    assert main(argv) == 2
    assert capsys.readouterr().err == "spinectl: error: cannot write to standard output: No space left on device\n"


def test_a_closed_pipe_ends_quietly(capsys, monkeypatch):
    """The reader of a pipe stopped reading (``spinectl config show | head -1``): exit 0, nothing on stderr."""
    monkeypatch.setattr(sys, "stdout", _FailingStdout(BrokenPipeError(32, "Broken pipe")))
    assert main(["config", "show"]) == 0
    assert capsys.readouterr().err == ""


def test_dev_full_as_standard_output_in_a_real_process():
    """``spinectl stability ... > /dev/full``, as a shell does it: one line, exit 2, and nothing from the
    interpreter's own flush at exit ("Exception ignored", exit 120)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    env = os.environ | {"PYTHONPATH": str(root)}
    command = [sys.executable, "-m", "spinectl", "stability", "--E", "0.03", "--Lambda", "0.04"]
    with open("/dev/full", "w") as full:
        done = subprocess.run(command, stdout=full, stderr=subprocess.PIPE, text=True, env=env, cwd=root)
    assert (done.returncode, done.stderr) == (
        2,
        "spinectl: error: cannot write to standard output: No space left on device\n",
    )


def test_a_plot_input_name_too_long_is_one_line(capsys):
    """A RESULTS or --vs name longer than the file system takes (ENAMETOOLONG): argparse's one line, exit 2
    (before: an OSError traceback from the first stat)."""
    long = "a" * 5000 + ".nc"
    for argv in (["plot", long, "--out", "o"], ["plot", "x.nc", "--vs", long, "--out", "o"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "cannot read 'aaa" in err and err.endswith("File name too long\n")


def test_a_utf8_output_name_under_the_c_locale(tmp_path):
    """LC_ALL=C without Python's UTF-8 mode: ``Λ.png`` arrives as surrogate escapes, which were refused as
    not printable; its bytes are UTF-8, so it is written. A NetCDF name the library cannot encode (it takes
    the file system's encoding, ASCII here) is refused in one line saying why, before the sweep."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    env = os.environ | {"PYTHONPATH": str(root), "LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0"}
    env.pop("PYTHONIOENCODING", None)
    base = [sys.executable, "-m", "spinectl"]
    draw = subprocess.run(
        [*base, "draw", "--E", "0.03", "--Lambda", "0.04", "--out", "Λ.png"], cwd=tmp_path, env=env, capture_output=True
    )
    assert (draw.returncode, draw.stderr) == (0, b"") and (tmp_path / "Λ.png").is_file()
    sweep = subprocess.run(
        [*base, "sweep", "--E", "0", "--Lambda", "0", "--out", "Λ.nc"], cwd=tmp_path, env=env, capture_output=True
    )
    assert sweep.returncode == 2 and sweep.stderr.count(b"\n") == 1 and b"UTF-8 locale" in sweep.stderr
    assert not (tmp_path / "Λ.nc").exists()


def test_the_largest_stiffness_in_a_sweep_is_one_line(tmp_path, capsys):
    """``sweep --K 1e308``: the arithmetic of the reflex columns overflows (as for K = 1.3e154), one line,
    exit 2, no file; before, the solver's "overflow encountered in divide" warning came first, a second line."""
    out = tmp_path / "k.nc"
    assert main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--K", "1e308", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the model's arithmetic fails on the grid" in err and not out.exists()


def test_sweep_states_its_estimate_on_stderr_before_long_work(tmp_path, capsys, monkeypatch):
    """The command prints the library's estimate line on stderr when the work is long (NOTICE_SECONDS = 0
    here), before the solves: 2 x 2 points at 2 values of K are 8 points; stdout keeps the one result line."""
    from spinectl.landscape import budget

    monkeypatch.setattr(budget, "NOTICE_SECONDS", 0.0)
    out = tmp_path / "x.nc"
    assert main(["sweep", "--E", "0:0.08:2", "--Lambda", "0:0.08:2", "--K", "0,15", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert captured.err.startswith("sweep: 8 points, about ") and captured.err.count("\n") == 1
    assert captured.out.startswith(f"wrote {out}")
