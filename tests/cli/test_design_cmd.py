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


def test_mass_and_K_are_the_aliases_they_are_on_margins(capsys):
    """``--mass 35 --K 10`` prints what ``--set body.mass=35 --set passive.stiffness=10`` prints (the issue's
    subject); with --passive, which varies K, --K is one line, exit 2."""
    point = ["design", "--delay", "0.04", "--preset", "wagner2012", "--json"]
    assert main([*point, "--mass", "35", "--K", "10"]) == 0
    aliased = json.loads(capsys.readouterr().out)
    assert main([*point, "--set", "body.mass=35", "--set", "passive.stiffness=10"]) == 0
    assigned = json.loads(capsys.readouterr().out)
    for key in ("activation", "segments", "chain", "status"):  # the provenance lists the options as given
        assert aliased[key] == assigned[key]
    assert (
        aliased["chain"]["local_stiffness_Nm_per_rad"]
        != json.loads(_default_json(capsys))["chain"]["local_stiffness_Nm_per_rad"]
    )
    assert main(["design", "--passive", "0:80:3", "--K", "3"]) == 2
    assert "--K: cannot go with --passive" in capsys.readouterr().err


def test_a_delay_nothing_meets_says_so_in_words(capsys):
    """No activation and no local stiffness meet 50 ms with kp = 300, kd = 0 (docs/reflex.md's example): the table
    says so with the largest delays met, instead of 'none x ...' and a bisection's method; a 5 s delay is in s."""
    assert main(["design", "--delay", "0.05", "--kp", "300", "--kd", "0"]) == 0
    out = capsys.readouterr().out
    assert "no activation in [0, 1] meets the delay" in out and "no local stiffness meets the delay" in out
    assert "none x" not in out and "met for every larger fraction" not in out  # the chain's search found none
    assert main(["design", "--delay", "5", "--E", "0.03", "--Lambda", "0.04", "--mass", "35", "--K", "10"]) == 0
    assert ">= 5 s;" in capsys.readouterr().out


def test_a_design_has_no_truth_value():
    """``if design(...)`` would read an infeasible design as true: TypeError naming what to test instead."""
    answer = design(config.set_parameters(config.load_preset("wagner2012"), {"reflex.delay": 0.04}), 0.03, 0.04)
    with pytest.raises(TypeError, match="status == 'ok'"):
        bool(answer)


def _default_json(capsys) -> str:
    assert main(["design", "--delay", "0.04", "--preset", "wagner2012", "--json"]) == 0
    return capsys.readouterr().out
