"""``spinectl margins``: JSON schema, table, plots and clean failures."""

from __future__ import annotations

import json

import pytest

from spinectl import jsondoc
from spinectl.cli import main
from spinectl.model import config
from spinectl.model.clinical import with_lordosis_angle
from spinectl.reflex.chain_verdict import margins_with_chain

REQUIRED = (
    "name",
    "stiffness_Nm_per_rad",
    "damping_Nms_per_rad",
    "inertia_kgm2",
    "kp_Nm_per_rad",
    "kd_Nms_per_rad",
    "gain_margin",
    "phase_margin_deg",
    "crossover_rad_s",
    "delay_margin_s",
    "delay_margin_pade_s",
    "stable_at_delay",
)


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _model(**reflex):
    """The CLI's model for ``--preset default`` and these reflex options (overridden fields, as the CLI sets them)."""
    return config.set_parameters(config.load_preset("default"), {f"reflex.{k}": v for k, v in reflex.items()})


def test_json_is_the_reports_dict(capsys):
    """``--json`` prints :meth:`MarginsReport.to_dict` with ``lordosis_angle_deg`` beside ``Lambda_m``
    (its schema and values: tests/reflex/test_margins.py)."""
    code, out, _ = run(
        ["margins", "--preset", "default", "--delay", "0.1", "--activation", "0", "--pade-order", "3", "--json"], capsys
    )
    assert code == 0
    report = margins_with_chain(_model(delay=0.1, activation=0.0, pade_order=3), 0.0, 0.0)
    assert out == jsondoc.dumps(with_lordosis_angle(report.to_dict(), _model(delay=0.1, activation=0.0, pade_order=3)))
    doc = json.loads(out)
    assert doc["delay_s"] == 0.1 and doc["optimum_status"] == "skipped"
    assert all(all(key in seg for key in REQUIRED) for seg in doc["segments"])


def test_self_stable_margins_are_unbounded_in_json(capsys):
    """An infinite delay margin is null with the reason 'unbounded' (docs/cli.md, JSON output)."""
    code, out, _ = run(["margins", "--E", "0.03", "--Lambda", "0.04", "--activation", "1", "--json"], capsys)
    assert code == 0
    segments = json.loads(out)["segments"]
    assert all(
        s["delay_margin_s"] is None
        and s["delay_margin_s_reason"] == "unbounded"
        and s["delay_margin_status"] == "delay_independent"
        for s in segments
    )


def test_table_is_the_reports_table(capsys):
    code, out, _ = run(["margins", "--preset", "default", "--activation", "0", "--kp", "150", "--kd", "20"], capsys)
    assert code == 0 and "L5S1" in out and "tau_m" in out and "150.00" in out
    assert out == margins_with_chain(_model(activation=0.0), 0.0, 0.0, kp=150.0, kd=20.0).table() + "\n"


def test_plot_writes_three_pngs(tmp_path, capsys):
    config = tmp_path / "short.toml"
    config.write_text("[reflex]\nsim_duration = 1.0\nactivation = 0.0\n")
    out = tmp_path / "plots"
    code, _, _ = run(["margins", "--config", str(config), "--plot", str(out)], capsys)
    assert code == 0
    files = sorted(p.name for p in out.iterdir())
    assert files == ["bode.png", "nyquist.png", "response.png"]  # and no temporary left behind
    assert all((out / f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for f in files)


def test_plot_notes_what_it_did_not_write(tmp_path, capsys):
    """Self-stable at activation 1: no reflex loop, so only response.png, and a note on stderr."""
    config_file = tmp_path / "stable.toml"
    config_file.write_text("[reflex]\nsim_duration = 0.5\nactivation = 1.0\n")
    code, out, err = run(["margins", "--config", str(config_file), "--plot", str(tmp_path / "p"), "--json"], capsys)
    assert code == 0 and json.loads(out)["all_stable_at_delay"]
    assert err == "spinectl: note: not written (nothing to draw): bode.png, nyquist.png\n"
    assert [p.name for p in (tmp_path / "p").iterdir()] == ["response.png"]


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["margins", "--delay", "-1"], "reflex.delay: must be in [0, 10]"),
        (["margins", "--delay", "1e308"], "reflex.delay: must be in [0, 10]"),
        # 3.5e62 s: before the bound, python-control's poles raised LinAlgError and its Nyquist plot warned
        (["margins", "--delay", "3.5e62"], "reflex.delay: must be in [0, 10]"),
        (["margins", "--activation", "11"], "reflex.activation: must be in [0, 10]"),
        (["margins", "--pade-order", "0"], "reflex.pade_order: must be an integer in [1, 10]"),
        (["margins", "--pade-order", "2.5"], "invalid int value"),
        (["margins", "--kp", "-1"], "reflex.kp: must be >= 0"),
        (["margins", "--delay", "inf"], "--delay must be finite"),
        (["margins", "--E", "0.5"], "E: must be in"),
    ],
)
def test_bad_input_is_one_line_exit_2(argv, needle, capsys):
    code, out, err = run(argv, capsys)
    assert code == 2 and needle in err and out == ""
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


@pytest.mark.parametrize("argv", [["--kp", "1e308"], ["--kd", "1e300"]])
def test_absurd_magnitudes_are_a_parameter_error(argv, capsys):
    """Gains above float_max ** 0.25 = 1.16e77 (reflex.inputs.MAX_MAGNITUDE) are refused by name."""
    code, _, err = run(["margins", *argv], capsys)
    assert code == 2 and f"{argv[0][2:]}: must be finite, at most 1.16e+77" in err
    assert len(err.strip().splitlines()) == 1


def test_plot_writes_nothing_when_the_simulation_cannot_run(tmp_path, capsys):
    """A 1 ns delay needs 1.2e10 steps: refused before any PNG is written."""
    code, _, err = run(["margins", "--delay", "1e-9", "--plot", str(tmp_path / "p")], capsys)
    assert code == 2 and "reflex.delay" in err and not (tmp_path / "p").exists()


def test_activation_lag_option_and_toml_key(tmp_path, capsys):
    """--activation-lag sets reflex.activation_time_constant (echoed as activation_time_constant_s), as the TOML
    key does; 0 is the pure delay, whose margins are those of reflex.delay_margin without the lag."""
    code, out, _ = run(["margins", "--activation", "0", "--activation-lag", "0", "--json"], capsys)
    doc = json.loads(out)
    assert code == 0 and doc["activation_time_constant_s"] == 0.0
    from spinectl import reflex

    seg = doc["segments"][2]
    exact = reflex.delay_margin(
        seg["stiffness_Nm_per_rad"], 0.0, seg["inertia_kgm2"], seg["kp_Nm_per_rad"], seg["kd_Nms_per_rad"]
    )
    assert seg["delay_margin_s"] == float(exact.margin)
    config_file = tmp_path / "lag.toml"
    config_file.write_text("[reflex]\nactivation_time_constant = 0.08\n")
    code, out, _ = run(["margins", "--config", str(config_file), "--json"], capsys)
    assert code == 0 and json.loads(out)["activation_time_constant_s"] == 0.08
    code, _, err = run(["margins", "--activation-lag", "5"], capsys)
    assert code == 2 and "activation_time_constant" in err and len(err.strip().splitlines()) == 1


def test_coupled_margins_name_the_chain_criterion(capsys):
    """margins --coupled: the chain under the reflex, all CoRs free; ``coupled.criterion`` in the JSON
    and the table's verdict at the delay starts with it (wagner2012 has 5 CoRs)."""
    argv = ["margins", "--coupled", "--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012"]
    name = "chain (all 5 CoRs free)"
    assert main([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["coupled"]["criterion"] == name
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert f"{name}: stable at the delay: NO" in out
