"""``spinectl margins --coupled``'s library call: the chain at the operating point of ``margins`` (docs/chain.md)."""

from __future__ import annotations

import json

import control as ct
import numpy as np

from spinectl import jsondoc
from spinectl.cli import main
from spinectl.model import config
from spinectl.model.clinical import with_lordosis_angle
from spinectl.reflex.chain_margins import coupled_margins
from spinectl.reflex.chain_system import chain_loop

KEYS = (
    "stiffness_matrix_Nm_per_rad",
    "gravity_stiffness_matrix_Nm_per_rad",
    "stiffness_matrix_per_cm2",
    "damping_matrix_Nms_per_rad",
    "mass_matrix_kgm2",
    "pcsa_cm2",
    "local_stiffness_Nm_per_rad",
    "margin_Nm_per_rad",
    "eigenvalues",
    "self_stable",
    "kp_Nm_per_rad",
    "kd_Nms_per_rad",
    "delay_margin_s",
    "delay_margin_pade_s",
    "disk_gain_margin",
    "disk_phase_margin_deg",
    "stable_at_delay",
)


def _model(**reflex):
    """wagner2012 with reflex fields set as the CLI sets them (so its provenance names them as overridden)."""
    return config.set_parameters(config.load_preset("wagner2012"), {f"reflex.{k}": v for k, v in reflex.items()})


def _pade_closed_loop_stable(result, model):
    c = result.chain
    loop = chain_loop(
        c.mass, c.stiffness, c.damping, result.kp, result.kd, result.delay, 6, result.activation_time_constant,
        c.segment_names,
    )  # fmt: skip
    return bool(np.all(ct.feedback(loop, ct.ss([], [], [], np.eye(5))).poles().real < 0))


def test_at_the_papers_delay_the_chain_is_unstable(capsys):
    """delay 0.1 s: the rule's reflex cannot hold the chain (its unstable modes grow in 10-65 ms);
    python-control's Padé closed loop (order 6) agrees; no disk margin. The JSON has the issue's keys."""
    assert main(["margins", "--coupled", "--delay", "0.1", "--preset", "wagner2012", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert set(KEYS) <= set(printed["coupled"])
    model = _model(delay=0.1)
    result = coupled_margins(model, 0.0, 0.0)
    # NaN: null with its reason; the command adds the lordosis angle beside Lambda (0 deg at Lambda = 0)
    assert printed == json.loads(jsondoc.dumps(with_lordosis_angle(result.to_dict(model), model)))
    assert printed["lordosis_angle_deg"] == 0.0
    assert result.stable_at_delay is False and result.exact.margin < 0.1
    assert _pade_closed_loop_stable(result, model) is False
    assert printed["coupled"]["disk_gain_margin"] is None and printed["coupled"]["disk_gain_margin_reason"] == "none"


def test_below_the_margin_the_loop_is_stable_with_disk_margins():
    """At half the exact margin the loop is stable (python-control's Padé closed loop too) and the disk
    margins exist: 0 < alpha < 2, the loop-at-a-time margins never below the multiloop one."""
    probe = coupled_margins(_model(activation_time_constant=0.0), 0.0, 0.0)
    model = _model(activation_time_constant=0.0, delay=0.5 * probe.exact.margin)
    result = coupled_margins(model, 0.0, 0.0)
    assert result.stable_at_delay and _pade_closed_loop_stable(result, model)
    assert 0 < result.disk.disk_margin < 2
    assert np.all(result.disk.loop_at_a_time[:, 0] >= result.disk.disk_margin * (1 - 1e-6))
    assert "exact delay margin" in result.table(model)


def test_command_line_errors_are_one_line(capsys):
    """--plot has no chain version; gains orders of magnitude off overflow: exit 2, one line, no traceback."""
    for argv, field in (
        (["margins", "--coupled", "--plot", "out"], "--plot"),
        (["margins", "--coupled", "--kp", "1e300"], "arithmetic"),
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert field in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_the_margins_of_any_linear_chain_follow_its_delay_margin():
    """chain_reflex_margins on a LinearChain written down (two uncoupled joints, M = I, K = diag(1, 2),
    D = -0.5 I, kp = 10, kd = 2): each joint is the segment s^2 + 0.5 s - lambda + (10 + 2 s) e^{-s tau}, with
    one destabilising crossing (kp > |lambda|, tests/reflex/test_mimo.py), so the true-delay loop is stable
    below the margin and not above; the disk margins exist only where it is. The Padé estimate of order 6 is
    the exact margin to 1e-9: the crossing is at w tau = 0.72 rad, where the phase error of the [6/6]
    approximant, of order (w tau)^13 (n!)^2 / ((2n)! (2n + 1)!), is below 1e-12 rad."""
    from spinectl.model.linear_chain import LinearChain
    from spinectl.reflex.chain_margins import chain_reflex_margins

    chain = LinearChain(
        joints=("a", "b"), controls=(), control_class=(), stiffness_per_control=np.zeros((2, 2, 0)),
        damping_per_control=np.zeros((2, 2, 0)), stiffness_offset=np.diag([1.0, 2.0]),
        damping_offset=-0.5 * np.eye(2), mass_matrix=np.eye(2), lower=np.zeros(0), upper=np.zeros(0),
    )  # fmt: skip
    kp, kd = np.full(2, 10.0), np.full(2, 2.0)
    first = chain_reflex_margins(chain, kp, kd, 0.0, 6, 0.0)
    margin = first.exact.margin
    assert first.exact.status == "finite"
    np.testing.assert_allclose(first.delay_margin_pade, margin, rtol=1e-9)
    below, above = (chain_reflex_margins(chain, kp, kd, f * margin, 6, 0.0) for f in (0.5, 1.5))
    assert below.stable_at_delay and below.disk is not None and 0 < below.disk.disk_margin
    assert not above.stable_at_delay and above.disk is None
