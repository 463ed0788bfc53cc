"""``spinectl design``: the design question on the command line (the search itself: tests/reflex/test_design.py)."""

from __future__ import annotations

import json

import pytest

from spinectl import jsondoc
from spinectl.cli import main
from spinectl.model import config
from spinectl.model.clinical import with_lordosis_angle
from spinectl.reflex.design import answer, design

KEYS = ("activation", "segments", "chain", "delay_s", "activation_time_constant_s", "status")


def test_json_is_the_designs_dict_with_the_keys_for_scripts(capsys):
    """``--json`` prints Design.to_dict() with ``lordosis_angle_deg`` beside ``Lambda_m``:
    the keys scripts read, strict JSON (no NaN), each segment's and the
    chain's answer with its criterion."""
    argv = ["design", "--preset", "wagner2012", "--delay", "0.04", "--E", "0.03", "--Lambda", "0.04", "--json"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    model = config.set_parameters(config.load_preset("wagner2012"), {"reflex.delay": 0.04})
    assert out == jsondoc.dumps(with_lordosis_angle(answer(model, 0.03, 0.04).to_dict(), model))
    doc = json.loads(out, parse_constant=lambda word: pytest.fail(f"{word} in strict JSON"))
    assert all(key in doc for key in KEYS) and doc["delay_s"] == 0.04
    assert all({"name", "activation", "pcsa_cm2", "delay_margin_s"} <= set(s) for s in doc["segments"])
    assert {"local_stiffness_Nm_per_rad", "activation", "delay_margin_s", "max_root_real_per_s"} <= set(doc["chain"])
    assert {"reflex", "global_pcsa_cm2", "kp_Nm_per_rad", "kd_Nms_per_rad"} <= set(doc["chain"])
    assert doc["margin_ratio"] == 1.0 and doc["margin_cost"]["margin_ratio"] == 1.1
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


def _refusal(argv: list[str], capsys) -> str:
    """The one line of an argument list refused with exit 2, after its field (``spinectl: error: FIELD: ``)."""
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1, err
    return err.split(": ", 3)[3].rstrip("\n")


@pytest.mark.parametrize(
    ("option", "spec", "sweep_spec", "needle"),
    [
        ("--delays", "0:0.2:1", "0:0.08:1", "with NUM = 1 must have START = STOP"),  # before: tau = 0 alone, exit 0
        ("--delays", "0.1:0.1:3", "0.01:0.01:3", "with START = STOP must have NUM = 1: 3 values would all be"),
        ("--passive", "5:1:0", "0.05:0.01:0", "must be START:STOP:NUM with START <= STOP and 1 <= NUM <="),
        ("--passive", "30:40:1", "0.03:0.04:1", "with NUM = 1 must have START = STOP"),
    ],
)
def test_a_range_is_refused_as_sweep_refuses_it(capsys, option, spec, sweep_spec, needle):
    """``design --delays``/``--passive`` and ``sweep --E`` follow one START:STOP:NUM rule (``_validate.range_spec``):
    the same words, naming the option and the spec as typed (only the bound of NUM differs)."""
    mine = _refusal(["design", option, spec], capsys)
    theirs = _refusal(["sweep", "--E", sweep_spec, "--out", "x.nc"], capsys)
    assert needle in mine and needle in theirs and f"(got {spec!r})" in mine


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--delays", "0:20:3"], "--delays: must be in [0, 10] s (got '0:20:3': 0 to 20 s)"),  # params.MAX_DELAY
        (["--passive", "0:1e5:3"], "--passive: must be in [0, 10000] N m/rad (got '0:1e5:3'"),
        (["--passive", "0:80:1001"], "1 <= NUM <= 1,000 (got '0:80:1001')"),  # bounds.MAX_CURVE_POINTS
        (["--delays", "0:0.2:41", "--lags", "0.05,0.05"], "--lags: must not repeat a value (repeated: 0.05)"),
    ],
)
def test_a_curve_beyond_its_bounds_is_one_line(capsys, argv, needle):
    """Each curve's bound, with its unit, naming the option and the spec as typed."""
    assert main(["design", *argv]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and needle in err


@pytest.mark.parametrize("lag", ["5", "1.5"])
def test_lags_have_the_bound_of_activation_lag(capsys, lag):
    """``--lags`` and ``--activation-lag`` are one quantity, T_a, with one bound (params.MAX_ACTIVATION_TIME_CONSTANT,
    1 s) and one message (before: --lags took up to 10 s, the curve computed at its first lag before the
    refusal named reflex.activation_time_constant)."""
    lags = _refusal(["design", "--delays", "0:0.2:3", "--lags", f"0.05,{lag}"], capsys)
    single = _refusal(["design", "--activation-lag", lag], capsys)
    assert lags == single and lags.startswith(f"must be in [0, 1] s (got {lag})")


@pytest.mark.parametrize(("delays", "lags", "product"), [("0:0.2:1000", 200, "1,000 x 200 = 200,000"),
                                                         ("0:0.2:101", 100, "101 x 100 = 10,100")])  # fmt: skip
def test_too_many_designs_are_refused_before_any_work(capsys, monkeypatch, delays, lags, product):
    """Delays times lags is bounded (params.bounds.MAX_DESIGNS = 10,000, about 50 ms each): 1000 delays at 200 lags
    (the issue's 200,000 designs, some 3 hours) and 101 delays at 100 lags, one above the bound, are one line,
    before any design is solved (before: accepted, with no estimate)."""
    from spinectl.reflex.design import curve

    monkeypatch.setattr(curve, "checked_coefficients", lambda *a: pytest.fail("solved before the refusal"))
    values = ",".join(f"{i / 1000:g}" for i in range(lags))
    message = _refusal(["design", "--delays", delays, "--lags", values], capsys)
    assert message == f"must give at most 10,000 designs, delays times lags, about 50 ms each (got {product})"


@pytest.mark.parametrize(
    ("argv", "constant", "line"),
    [
        (["--delays", "0:0.1:2", "--lags", "0,0.05"], "DESIGN_SECONDS", "design: 4 designs, about 6.7 min of CPU"),
        (["--passive", "30:40:2"], "PASSIVE_SECONDS", "design: 2 points, about 3.3 min of CPU"),
    ],
)
def test_a_long_curve_is_announced_on_stderr_first(capsys, monkeypatch, argv, constant, line):
    """A curve estimated at NOTICE_SECONDS (10 s) or more says so first, as a sweep does (``budget.design_estimate``).

    With the time of one design set to 100 s, 2 delays x 2 lags are 400 s = 6.7 min, 2 stiffnesses 200 s =
    3.3 min; the real curve is short and runs. At the measured costs the same curves are not announced.
    """
    from spinectl.landscape import budget

    argv = ["design", "--preset", "wagner2012", *argv, "--json"]
    assert main(argv) == 0
    assert capsys.readouterr().err == ""  # 4 x 50 ms, 2 x 12 ms: far below 10 s
    monkeypatch.setattr(budget, constant, 100.0)
    assert main(argv) == 0
    assert capsys.readouterr().err == f"{line} (estimated)\n"


@pytest.mark.parametrize(("option", "value"), [("--delay", "0.1"), ("--kp", "50"), ("--activation", "0.8")])
def test_passive_refuses_the_reflexs_options_it_would_ignore(option, value, capsys):
    """--passive's answers are static (the global PCSA alone, the least local stiffness at the minimum PCSA): a
    reflex option beside it was ignored without a word (before: --delay 0.1 ran and said nothing of it)."""
    message = _refusal(["design", "--passive", "0:80:3", "--E", "0.03", option, value], capsys)
    assert message.startswith("cannot go with --passive, whose answers are static")


@pytest.mark.parametrize(
    ("assignment", "why"),
    [
        ("reflex.delay=0.1", "cannot go with --passive, whose answers are static"),  # the case
        ("reflex.activation_time_constant=0.03", "cannot go with --passive, whose answers are static"),
        ("reflex.activation=0.3", "cannot go with --passive, whose answers are static"),  # as --activation is
    ],
)
def test_passive_refuses_the_same_fields_by_set(assignment, why, capsys):
    """--set of a field --passive does not use was taken and ignored without a word, where its option (--delay,
    --activation-lag, --activation) is refused: one line naming --set FIELD, exit 2, the option's own reason; a
    field it uses (body.mass) still runs."""
    field = assignment.partition("=")[0]
    assert main(["design", "--passive", "0:80:3", "--set", assignment]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == f"spinectl: error: --set {field}: {why}" + err.split(why, 1)[1]
    assert err.count("\n") == 1
    assert main(["design", "--passive", "40", "--set", "body.mass=35", "--json"]) == 0


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--margin", "0.9"], "--margin: must be in [1, "),
        (["--margin", "200"], "--margin: must be in [1, 100]"),  # 200 x 0.1 s is beyond the delay's 10 s
        (["--delays", "0:0.1:3", "--margin", "1.1"], "--margin: cannot go with --delays, which it does not take"),
        (["--delays", "0:0.1:3", "--gains", "search"], "--gains: cannot go with --delays"),
        (["--delays", "0:0.1:3", "--delay", "0.15"], "--delay: cannot go with --delays, whose delays are the curve's"),
        (["--passive", "0:80:3", "--gains", "search"], "--gains: cannot go with --passive"),
        (["--passive", "0:80:3", "--margin", "1.2"], "--margin: cannot go with --passive"),
        (["--decay-rate", "25"], "--decay-rate: must be a decay rate in [0, 20) 1/s, below 1/T_a"),
        (["--decay-rate", "-0.5"], "--decay-rate: must be"),
        (["--decay-rate", "0.1", "--margin", "1.2"], "--decay-rate: cannot go with --margin"),
        (["--decay-rate", "0.1", "--gains", "search"], "--decay-rate: cannot go with --gains search"),
        (["--delays", "0:0.1:3", "--decay-rate", "0.1"], "--decay-rate: cannot go with --delays"),
        (["--passive", "0:80:3", "--decay-rate", "0.1"], "--decay-rate: cannot go with --passive"),
    ],
)
def test_a_margin_or_a_gain_search_where_it_does_not_apply_is_one_line_exit_2(argv, needle, capsys):
    """--margin R below 1 (a design for shorter delays than asked), or R x the delay beyond 10 s, and --gains or
    --margin beside --delays or --passive (which would ignore them) are refused: one line, exit 2, no output."""
    assert (
        main(
            ["design", "--preset", "wagner2012", "--delay", "0.1", *argv]
            if "--passive" not in argv and "--delays" not in argv
            else ["design", "--preset", "wagner2012", *argv]
        )
        == 2
    )
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and needle in err


def test_margin_prints_the_design_at_r_times_the_delay(capsys):
    """``--delay 0.1 --margin 1.2`` prints the design of ``--delay 0.12`` (the same local stiffness), saying it holds
    every delay up to 120 ms."""
    point = ["design", "--preset", "wagner2012", "--E", "0.03", "--Lambda", "0.04"]
    assert main([*point, "--delay", "0.1", "--margin", "1.2", "--json"]) == 0
    robust = json.loads(capsys.readouterr().out)
    assert main([*point, "--delay", "0.12", "--json"]) == 0
    direct = json.loads(capsys.readouterr().out)
    assert robust["chain"]["local_stiffness_Nm_per_rad"] == direct["chain"]["local_stiffness_Nm_per_rad"]
    assert robust["margin_ratio"] == 1.2 and robust["nominal_delay_s"] == 0.1
    assert main([*point, "--delay", "0.1", "--margin", "1.2"]) == 0
    assert "holds every delay up to 120 ms" in capsys.readouterr().out


def test_decay_rate_prints_the_design_whose_roots_lie_beyond_minus_sigma(capsys):
    """``--decay-rate 0.1`` answers the chain's least local stiffness with every root at the delay at Re s < -0.1
    1/s (its rightmost root, the chain's own, in the JSON and the table), above the plain design's, and says what
    it is; joint by joint likewise needs more co-contraction, and has no 'largest delay met' (the shifted loops'
    gains hold the one delay)."""
    point = ["design", "--preset", "wagner2012", "--E", "0.03", "--Lambda", "0.04", "--delay", "0.1"]
    assert main([*point, "--decay-rate", "0.1", "--json"]) == 0
    robust = json.loads(capsys.readouterr().out)
    assert main([*point, "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert robust["decay_rate_per_s"] == 0.1 and "margin_cost" not in robust
    assert robust["chain"]["max_root_real_per_s"] <= -0.1 + 1e-9
    assert robust["chain"]["local_stiffness_fraction"] > plain["chain"]["local_stiffness_fraction"]
    assert robust["activation"] > plain["activation"]  # joint by joint too: each segment's loop beyond -sigma
    assert "largest_delay_met_s" in robust and robust["largest_delay_met_s"] is None
    assert main([*point, "--decay-rate", "0.1"]) == 0
    assert "designed for a least decay rate 0.1 1/s (--decay-rate)" in capsys.readouterr().out


@pytest.mark.parametrize(("extra", "fixed_at"), [([], "K = 0 N m/rad"), (["--set", "passive.stiffness=10"], "K = 10")])
def test_passive_says_which_minimum_its_fixed_global_pcsa_is(extra, fixed_at, capsys):
    """``design --passive`` holds one global PCSA while K varies: the table says what it is, the least total PCSA
    for every segment self-stable joint by joint (the paper's criterion), solved at the model's own K (the preset's
    0, or 10 N m/rad set), and held at every K of the sweep (it said "the paper's minimum" without what over or
    where); its value is solve_point's total at that K."""
    from spinectl.optimise.reference import solve_point
    from spinectl.units import m2_to_cm2

    argv = ["design", "--preset", "wagner2012", "--passive", "0:80:3", "--E", "0.03", "--Lambda", "0.04", *extra]
    assert main(argv) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("least local stiffness at a fixed"))
    assert "self-stable joint by joint (each CoR alone, the others fixed" in line
    assert f"solved once at the model's own {fixed_at}" in line and "held, muscle by muscle, at every K" in line
    stiffness = 10.0 if extra else 0.0
    model = config.set_parameters(config.load_preset("wagner2012"), {"passive.stiffness": stiffness})
    assert f"{m2_to_cm2(solve_point(model, 0.03, 0.04).pcsa.sum()):.2f} cm^2" in line
