"""CLI fuzzing: random argument lists never raise, exit 0 or 2, and exit 2 with exactly one line.

Arguments mix the real command and option names with numbers (NaN, inf, huge,
signed zero, unicode digits), comma lists, unicode garbage, undecodable
surrogates, missing values and the names of prepared configuration files
(valid, invalid, overflowing, an attachment on a CoR). Bounded to about 20 s.
"""

from __future__ import annotations

import contextlib
import io
import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spinectl.cli import main

CONFIG_FILES = {
    "good.toml": "[body]\nmass = 55.0\n",
    "bad.toml": "[body]\nmass = -1.0\n",
    "typo.toml": "[bodyy]\nmass = 1.0\n",
    "not_toml.toml": "[body\n",
    "overflow.toml": "[body]\nradius_of_gyration = 1e300\n",
    "on_cor.toml": '[[muscles]]\nname = "p"\nupper = [0.1, 0.3]\nlower = [0.0, 0.005]\nspread = 0.0\nfibres = 1\n',
}
"""Files in the fuzzing folder; on_cor.toml puts an attachment on L5S1 at E = Lambda = 0."""

OPTIONS = [
    "--E",
    "--Lambda",
    "--lordosis-angle",
    "--pcsa",
    "--K",
    "--json",
    "--config",
    "--preset",
    "--help",
    "-h",
    "--version",
]
WORDS = ["stability", "config", "show", "presets", "default", "--", "-", "=", *CONFIG_FILES]
PREFIXES = [[], ["stability"], ["stability", "--pcsa", "10,10,10"], ["config", "show"], ["config", "presets"]]

number_texts = st.one_of(
    st.floats().map(repr),
    st.integers(-(10**400), 10**400).map(str),
    st.sampled_from(["nan", "-nan", "inf", "-inf", "1e999", "-0", "1_0", "0x10", "", " ", "1e-400", "١", "５"]),
)
tokens = st.one_of(
    st.sampled_from(OPTIONS + WORDS),
    number_texts,
    st.lists(number_texts, max_size=7).map(",".join),
    st.tuples(st.sampled_from(OPTIONS), number_texts).map("=".join),
    st.text(max_size=12),
    st.sampled_from(["\udcff", "a\nb", "\u2028", "\x00", "é" * 3]),
)
garbled = st.tuples(st.sampled_from(PREFIXES), st.lists(tokens, max_size=8)).map(lambda t: [*t[0], *t[1]])
"""Mostly caught by argparse."""


def mostly(valid, odd=number_texts):
    """Valid values three times in four, so that most lists get past argparse."""
    return st.one_of(valid, valid, valid, odd)


pcsa_lists = st.lists(st.floats(0, 100).map(repr), min_size=3, max_size=3).map(",".join)
values = {
    "--E": mostly(st.floats(-0.12, 0.12).map(repr)),
    "--Lambda": mostly(st.floats(-0.12, 0.12).map(repr)),
    "--lordosis-angle": mostly(st.floats(-200, 200).map(repr)),
    "--K": mostly(st.floats(0, 100).map(repr)),
    "--pcsa": mostly(pcsa_lists, st.lists(number_texts, max_size=7).map(",".join)),
    "--config": st.one_of(st.sampled_from(sorted(CONFIG_FILES)), st.text(max_size=8)),
    "--preset": st.one_of(st.just("default"), st.text(max_size=8)),
}
COMMAND_OPTIONS = {"stability": sorted(values), "config show": ["--config", "--preset"]}


@st.composite
def well_formed(draw) -> list[str]:
    """Real options with random values: these get past argparse into the model and the physics."""
    command = draw(st.sampled_from(sorted(COMMAND_OPTIONS)))
    argv = command.split()
    for name in draw(st.lists(st.sampled_from(COMMAND_OPTIONS[command]), unique=True)):
        argv += [name, draw(values[name])]
    if command == "stability" and "--pcsa" not in argv and draw(st.booleans()):
        argv += ["--pcsa", draw(pcsa_lists)]
    if command == "stability" and draw(st.booleans()):
        argv.append("--contributions")  # each pair's part of the chain's index, at the same random point
    return argv + (["--json"] if command == "stability" and draw(st.booleans()) else [])


argument_lists = st.one_of(garbled, well_formed())


@pytest.fixture(scope="module")
def fuzz_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    for name, text in CONFIG_FILES.items():
        (folder / name).write_text(text)
    return folder


def run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning would be an unexplained extra line on stderr
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def check(argv: list[str]) -> None:
    code, _, err = run(argv)
    assert code in (0, 2), (argv, code, err)
    if code == 2:
        assert err.endswith("\n") and err.count("\n") == 1 and len(err.splitlines()) == 1, (argv, err)
        assert "Traceback" not in err
    else:  # the notes a run may print after its answer: a tiny --pcsa (m^2 typed for cm^2), a tiny
        # --lordosis-angle (radians typed for degrees), one line each (docs/robustness.md)
        notes = ("spinectl: warning: --pcsa: ", "spinectl: warning: --lordosis-angle: ")
        assert all(line.startswith(notes) for line in err.splitlines()), (argv, err)


@settings(max_examples=1500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(argument_lists)
def test_random_arguments_never_raise(fuzz_folder, argv):
    with contextlib.chdir(fuzz_folder):  # relative --config names; nothing outside is read
        check(argv)


@pytest.mark.parametrize(
    "argv",
    [
        ["--version"],
        ["stability", "--help"],
        ["stability", "--pcsa", "1,1,1", "a\nb"],
        ["stability", "--pcsa", "1e300,1e300,1e300"],
        ["stability", "--pcsa", "10,10,10", "--config", "overflow.toml"],
        ["stability", "--pcsa", "10,10,10", "--config", "on_cor.toml"],
        ["stability", "--pcsa", "10", "--config", "\x00"],
        ["stability", "--pcsa", "10,10,10", "--config", "x" * 5000],
        ["config", "show", "--preset", ""],
        ["config", "show", "--config", "/dev/zero"],
        ["\udcff"],
    ],
)
def test_arguments_that_used_to_escape(fuzz_folder, argv):
    """Each of these once raised SystemExit, a raw exception, or printed two lines."""
    with contextlib.chdir(fuzz_folder):
        check(argv)


grid_specs = mostly(
    st.tuples(st.floats(0, 0.04), st.floats(0.04, 0.08), st.integers(1, 3)).map(lambda t: f"{t[0]!r}:{t[1]!r}:{t[2]}"),
    st.one_of(
        st.tuples(st.floats(-0.12, 0.12), st.floats(-0.12, 0.12), st.integers(-1, 3)).map(
            lambda t: f"{t[0]!r}:{t[1]!r}:{t[2]}"
        ),
        st.lists(number_texts, max_size=3).map(":".join),
    ),
)
ANALYSIS_VALUES = {
    "--E": mostly(st.floats(-0.12, 0.12).map(repr)),
    "--Lambda": mostly(st.floats(-0.12, 0.12).map(repr)),
    "--delay": mostly(st.floats(0, 0.5).map(repr)),
    "--activation-lag": mostly(st.floats(0, 0.2).map(repr)),
    "--kp": mostly(st.floats(0, 500).map(repr)),
    "--kd": mostly(st.floats(0, 50).map(repr)),
    "--activation": mostly(st.floats(0, 1.5).map(repr)),
    "--pade-order": mostly(st.integers(0, 12).map(str)),
    "--K": mostly(st.floats(0, 100).map(repr)),
    "--method": st.sampled_from(["fast", "per-point", "slow"]),
    "--chunk-size": mostly(st.integers(-1, 20).map(str)),
    "--config": st.sampled_from(sorted(CONFIG_FILES)),
}
ANALYSIS_COMMANDS = {
    "margins": [
        "--E",
        "--Lambda",
        "--delay",
        "--activation-lag",
        "--kp",
        "--kd",
        "--activation",
        "--pade-order",
        "--config",
    ],
    "sweep --out out.nc": ["--K", "--method", "--chunk-size", "--config"],
    "plot tiny.nc --out figures": ["--E", "--vmin", "--vmax"],  # plot takes no --E: an argparse error
    "draw --out model.png": ["--E", "--Lambda", "--pcsa", "--config"],
}


@st.composite
def analysis_arguments(draw) -> list[str]:
    """The analysis commands with real options and random values; sweeps stay tiny (<= 3 x 3)."""
    command = draw(st.sampled_from(sorted(ANALYSIS_COMMANDS)))
    argv = command.split()
    if argv[0] == "sweep":
        argv += ["--E", draw(grid_specs), "--Lambda", draw(grid_specs)]
    for name in draw(st.lists(st.sampled_from(ANALYSIS_COMMANDS[command]), unique=True, max_size=4)):
        argv += [name, draw(ANALYSIS_VALUES.get(name, number_texts))]
    return argv


@pytest.fixture(scope="module")
def analysis_folder(fuzz_folder):
    """The fuzzing folder plus a tiny sweep for 'plot' to read."""
    with contextlib.chdir(fuzz_folder):
        assert main(["sweep", "--E", "0:0.08:2", "--Lambda", "0:0.08:2", "--out", "tiny.nc"]) == 0
    return fuzz_folder


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(analysis_arguments())
def test_random_arguments_to_the_analysis_commands_never_raise(analysis_folder, argv):
    """margins, sweep, plot and draw: the same contract, fewer examples (each runs a solver or draws)."""
    with contextlib.chdir(analysis_folder):
        check(argv)


@pytest.mark.parametrize(
    "argv",
    [
        # python-control evaluates L(jw) under np.errstate(all="warn"): a subnormal
        # activation made it warn "underflow encountered in divide" on stderr.
        ["margins", "--E", "0.0", "--delay", "0.0", "--activation", "1.1125369292536007e-308"],
        # K = 1.3e154 N m/rad: S^2 overflowed in the sweep's reflex columns, a numpy warning.
        ["sweep", "--out", "out.nc", "--E", "0:0.0625:1", "--Lambda", "0:0.0625:1", "--K", "1.3407807929942597e+154"],
        # equilibrated stability rows (docs/robustness.md): a subnormal singular value of the polishing's KKT
        # system made 1/sigma overflow, "overflow encountered in divide" (optimise/polish.py).
        [
            "sweep",
            "--out",
            "out.nc",
            "--E",
            "0.03125:0.0625:1",
            "--Lambda",
            "0.0:0.0625:1",
            "--K",
            "127.0",
            "--config",
            "on_cor.toml",
        ],
        # a delay of 3.5e62 s: python-control's poles raised LinAlgError (now beyond spinectl.model.params.MAX_DELAY).
        ["margins", "--delay", "3.524191256302076e+62"],
    ],
)
def test_analysis_arguments_that_used_to_escape(analysis_folder, argv):
    """Each of these once printed a warning or a traceback from the analysis commands."""
    with contextlib.chdir(analysis_folder):
        check(argv)


JOB_VALUES = {
    "--points": mostly(st.integers(3, 4).map(str), st.sampled_from(["2", "-1", "1001", "4" * 400, "x"])),
    "--starts": mostly(st.integers(1, 2).map(str)),
    "--seed": mostly(st.integers(-2, 5).map(str)),
    "--grid": mostly(st.integers(3, 4).map(str)),
    "--verify-grid": mostly(st.integers(3, 4).map(str)),
    "--popsize": mostly(st.integers(1, 2).map(str)),
    "--refine": mostly(st.integers(0, 2).map(str)),
    "--activation": st.sampled_from(["paired", "independent", "x"]),
    "--conventions": st.sampled_from(["physical", "paper", "physical,paper", "phys", "", ",", "paper,paper"]),
    "--parameters": st.sampled_from(["mass", "spread", "mass,spread", "mas", "", "mass,mass"]),
    "--history": st.sampled_from(["h.csv", "sub/h.csv", "/proc/x.csv"]),
    "--config": st.sampled_from(sorted(CONFIG_FILES)),
    "--preset": st.sampled_from(["default", "wagner2012", "nope"]),
}
JOB_COMMANDS = {
    "reproduce --out rep --points 3": ["--points", "--config", "--preset"],
    "calibrate --grid 3 --verify-grid 3 --generations 1 --popsize 1 --refine 0 --parameters mass": sorted(
        set(JOB_VALUES) - {"--points"}
    ),
}
"""The long jobs, kept to seconds: tiny grids and budgets unless an option overrides them."""


@st.composite
def job_arguments(draw) -> list[str]:
    argv = draw(st.sampled_from(sorted(JOB_COMMANDS))).split()
    for name in draw(st.lists(st.sampled_from(JOB_COMMANDS[" ".join(argv)]), unique=True, max_size=3)):
        argv += [name, draw(JOB_VALUES[name])]
    return argv


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(job_arguments())
def test_random_arguments_to_reproduce_and_calibrate_never_raise(analysis_folder, argv):
    """The same contract, except that stderr may carry progress lines before the one error line
    (a calibration whose every candidate the model rejects fails at the verification)."""
    with contextlib.chdir(analysis_folder):
        code, _, err = run(argv)
    assert code in (0, 2), (argv, code, err)
    assert "Traceback" not in err and "Warning" not in err, (argv, err)
    errors = [line for line in err.splitlines() if "error:" in line]  # ours and argparse's
    if code == 2:
        assert err.endswith("\n") and errors == err.splitlines()[-1:], (argv, err)
    else:
        assert errors == [], (argv, err)
