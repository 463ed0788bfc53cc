"""``spinectl design``: the design question on the command line (the search itself: tests/reflex/test_design.py)."""

from __future__ import annotations

import json

import pytest

from spinectl import jsondoc
from spinectl.cli import main
from spinectl.model import config
from spinectl.model.clinical import with_lordosis_angle
from spinectl.reflex.design import design

KEYS = ("activation", "segments", "chain", "delay_s", "activation_time_constant_s", "status")


def test_json_is_the_designs_dict_with_the_keys_for_scripts(capsys):
    """``--json`` prints Design.to_dict() with ``lordosis_angle_deg`` beside ``Lambda_m``:
    the keys scripts read, strict JSON (no NaN), each segment's and the
    chain's answer with its criterion."""
    argv = ["design", "--preset", "wagner2012", "--delay", "0.04", "--E", "0.03", "--Lambda", "0.04", "--json"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    model = config.set_parameters(config.load_preset("wagner2012"), {"reflex.delay": 0.04})
    assert out == jsondoc.dumps(with_lordosis_angle(design(model, 0.03, 0.04).to_dict(), model))
    doc = json.loads(out, parse_constant=lambda word: pytest.fail(f"{word} in strict JSON"))
    assert all(key in doc for key in KEYS) and doc["delay_s"] == 0.04
    assert all({"name", "activation", "pcsa_cm2", "delay_margin_s"} <= set(s) for s in doc["segments"])
    assert {"local_stiffness_Nm_per_rad", "activation", "delay_margin_s", "max_root_real_per_s"} <= set(doc["chain"])
    assert doc["criterion"].startswith("joint by joint") and doc["chain"]["criterion"].startswith("chain")


@pytest.mark.parametrize("delay", ["-0.1", "1e9", "nan"])
def test_a_negative_or_absurd_delay_is_one_line_exit_2(delay, capsys):
    """A delay outside [0, 10] s (reflex.delay's range) or not a number: one line on stderr, exit 2, no output."""
    assert main(["design", f"--delay={delay}"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "delay" in err


def test_passive_prints_the_curves_dict_and_plots_it(capsys, tmp_path):
    """``--passive 30:40:2 --json --plot DIR`` prints PassiveCurve.to_dict() (strict JSON, the chain's criterion,
    the computed Crisco stiffness) and writes passive.png, a PNG."""
    from spinectl.reflex.design import passive_curve

    argv = ["design", "--preset", "wagner2012", "--passive", "30:40:2", "--json", "--plot", str(tmp_path)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    expected = passive_curve(config.load_preset("wagner2012"), 0.0, 0.0, [30.0, 40.0]).to_dict()
    assert out == jsondoc.dumps(expected)
    doc = json.loads(out, parse_constant=lambda word: pytest.fail(f"{word} in strict JSON"))
    assert doc["criterion"].startswith("chain") and doc["crisco_stiffness_Nm_per_rad"] > 0
    assert (tmp_path / "passive.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("argv", [["--passive", "0:80"], ["--passive", "-5:80:3"], ["--plot", "out"]])
def test_a_bad_passive_axis_or_a_plot_without_it_is_one_line_exit_2(argv, capsys, tmp_path):
    """Not START:STOP:N, a negative stiffness, or --plot without --passive: one line naming the option, exit 2."""
    assert main(["design", *argv]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and argv[0] in err


def test_delays_prints_the_curves_dict_and_plots_it(capsys, tmp_path):
    """``--delays 0:0.1:2 --lags 0,0.05 --json --plot DIR`` prints DesignCurve.to_dict() (strict JSON, both criteria
    per lag, the reaction times marked) and writes design_curve.png, a PNG."""
    from spinectl.reflex.design import delay_curve

    argv = ["design", "--preset", "wagner2012", "--delays", "0:0.1:2", "--lags", "0,0.05", "--json"]
    assert main([*argv, "--plot", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    expected = delay_curve(config.load_preset("wagner2012"), 0.0, 0.0, [0.0, 0.1], [0.0, 0.05]).to_dict()
    assert out == jsondoc.dumps(expected)
    doc = json.loads(out, parse_constant=lambda word: pytest.fail(f"{word} in strict JSON"))
    assert [c["activation_time_constant_s"] for c in doc["curves"]] == [0.0, 0.05]
    assert doc["curves"][0]["joint"]["criterion"].startswith("joint by joint")
    assert doc["curves"][0]["chain"]["criterion"].startswith("chain") and doc["reaction_times_s"]
    assert (tmp_path / "design_curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "argv", [["--delays", "0:11:3"], ["--lags", "0.05"], ["--passive", "0:80:3", "--delays", "0:0.2:3"]]
)
def test_a_bad_delay_axis_or_a_lone_lags_is_one_line_exit_2(argv, capsys):
    """Delays beyond 10 s, --lags without --delays, or two curves at once: one line naming the option, exit 2."""
    assert main(["design", *argv]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and argv[0] in err
