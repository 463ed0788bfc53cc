"""The net torque at the analysed posture (equilibrium residual) in the table and JSON, and its warning."""

from __future__ import annotations

import json

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from shared_models import ABSENT, CYCLIST, DOCUMENTED_MAPPINGS  # noqa: E402 (tests/anatomy/shared_models.py)
from test_passive_chain import BARE, MAPPING  # noqa: E402 (two hinges with springs, masses of 2 kg)

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.net_torque import EQUILIBRIUM_FLOOR, EQUILIBRIUM_FRACTION  # noqa: E402
from spinectl.cli import main  # noqa: E402


def _bare(mass: float) -> str:
    """test_passive_chain's two hinges, their masses ``mass`` [kg] each."""
    assert BARE.count('mass="2"') == 2
    return BARE.replace('mass="2"', f'mass="{mass:g}"')


@pytest.mark.parametrize("mass", [2.0, 20.0])
def test_a_model_without_muscles_reports_gravity_as_its_net_torque(tmp_path, capsys, mass):
    """Two hinges each carrying masses 2 cm in front of them: the net torque is gravity's, MuJoCo's own -qfrc_bias
    (by hand: m g 0.02 m per mass, 2 masses on j1); below 1 N m (2 kg: 0.78, 0.39 N m) it is near equilibrium, at
    20 kg (7.8, 3.9 N m) far, since no muscle holds anything (the floor EQUILIBRIUM_FLOOR)."""
    model_path, mapping = tmp_path / "bare.xml", tmp_path / "bare.toml"
    model_path.write_text(_bare(mass))
    mapping.write_text(MAPPING)
    model = mujoco.MjModel.from_xml_string(_bare(mass))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    expected = -data.qfrc_bias
    np.testing.assert_allclose(expected, [2 * mass * 9.81 * 0.02, mass * 9.81 * 0.02], rtol=1e-6)
    assert main(["anatomy", str(model_path), "--mapping", str(mapping), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose([doc["net_torque_Nm"][j] for j in ("j1", "j2")], expected, rtol=1e-6)
    far = bool(np.any(np.abs(expected) > EQUILIBRIUM_FLOOR))
    assert doc["far_from_equilibrium"] == (["j1", "j2"] if far else [])
    assert main(["anatomy", str(model_path), "--mapping", str(mapping)]) == 0
    table = capsys.readouterr().out
    line = next(x for x in table.splitlines() if x.startswith("net torque"))
    assert f"largest {expected[0]:.3g} N m at j1" in line
    assert any(x.startswith("warning: far from equilibrium") for x in table.splitlines()) == far


def test_myotorso_net_torque_is_mujocos_and_far_is_relative_to_the_muscles(torso):
    """MyoTorso at its reference posture and activation 0.05: the net torque on the chain is MuJoCo's own
    qfrc_actuator + qfrc_passive - qfrc_bias at those activations (mj_forward, the reference); each joint is far
    from equilibrium where that exceeds EQUILIBRIUM_FRACTION of sum_i |tau_ij| (the muscles' torque range)."""
    a = 0.05
    result = analyse(torso, "sagittal", a)
    model = torso.engine.model
    data = mujoco.MjData(model)
    ctrl = torso.engine.held_controls()
    ctrl[torso.engine.muscle_ids()] = a
    data.ctrl[:] = ctrl
    stateful = model.actuator_actadr >= 0
    data.act[model.actuator_actadr[stateful]] = ctrl[stateful]
    mujoco.mj_forward(model, data)
    dofs = [model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in result.free.joints]
    expected = (data.qfrc_actuator + data.qfrc_passive - data.qfrc_bias)[dofs]
    np.testing.assert_allclose(result.net_torque.torque, expected, rtol=1e-6, atol=1e-6)
    bound = np.maximum(EQUILIBRIUM_FRACTION * result.net_torque.capacity, EQUILIBRIUM_FLOOR)
    joints = result.free.joints
    assert result.net_torque.far == tuple(j for j, t, b in zip(joints, expected, bound, strict=True) if abs(t) > b)
    assert np.all(result.net_torque.capacity > 100)  # 42 global muscles and more span each joint: hundreds of N m


@pytest.mark.slow
@pytest.mark.skipif(not CYCLIST.is_dir(), reason=ABSENT)
def test_the_published_cyclist_at_its_static_trial_is_far_from_equilibrium(tmp_path):
    """The Allaire cyclist at s01static.mot (posture and activations): every lumbar joint's net torque is hundreds
    to thousands of N m (the trial found 287-7818 N m; OpenSim's passive fibre forces reach 35 F_max there), so the
    table warns that its 'self-stable' verdicts are those of a moving body."""
    pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    mapping = _cyclist_mapping(tmp_path)
    trial = CYCLIST / "s01static.mot"
    loaded = anatomy.load(CYCLIST / "s01modelScaled.osim", mapping)
    result = analyse(loaded, "sagittal", trial, posture=trial)
    assert np.all(np.abs(result.net_torque.torque) > 200)
    assert result.net_torque.far == result.free.joints
    assert "warning: far from equilibrium at 6 of 6 joints" in result.table()


def _cyclist_mapping(folder):
    """docs/anatomy.md's cyclist.toml (docs/mappings/, as the page shows it)."""
    return DOCUMENTED_MAPPINGS / "cyclist.toml"


def test_an_optimum_held_by_the_rhythm_is_not_called_far(torso):
    """MyoTorso's classic optimum (10 N m/rad added, equilibrium on the rhythm's coordinates): the net torque on the
    rhythm's coordinates is 0 to the solver's tolerance (the optimum's equality rows), each chain joint's is the
    torque the rhythm carries that the optimum's table prints (its lumbar_torque), so the table says the posture is
    held by the rhythm, without the warning; at activation 0 (the variant) nothing holds it and the warning
    names the rhythm's coordinates too."""
    from spinectl.anatomy.optimum import optimised

    result = optimised(torso, stability="none", joint_stiffness=10.0)
    held = result.analysis.net_torque
    assert np.max(np.abs(held.rhythm_torque)) < 1e-6 * np.max(held.rhythm_capacity)
    lumbar = dict(zip(result.optimum.lumbar_joints, result.optimum.lumbar_torque, strict=True))
    np.testing.assert_allclose(held.torque, [lumbar[j] for j in held.joints], rtol=1e-6, atol=1e-9)
    lines = result.analysis.table().splitlines()
    assert held.far and not held.rhythm_far  # 50 N m at L1_L2_FE on the free joints, carried by the equalities
    assert any(x.startswith("held on the rhythm's coordinates") for x in lines)
    assert not any(x.startswith("warning: far") for x in lines)
    loose = analyse(torso, "sagittal", 0.0)
    assert loose.net_torque.rhythm_far and "joints and on the rhythm's coordinates" in loose.table()
