"""External loads on an anatomical model (anatomy/loads.py, contract.py's chains; docs/anatomy.md, "Loads").

The referees: MuJoCo's own generalised force of an applied force (mujoco.mj_applyFT), its central differences in q
for the load stiffness, and a closed form on a two-hinge chain built here (K = -F . (P - o_outer), the paper's
-(P - c_hi) . F; docs/anatomy.md).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from spinectl.errors import ParameterError

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl.anatomy.contract import MappedModel  # noqa: E402
from spinectl.anatomy.engine import load_engine  # noqa: E402
from spinectl.anatomy.loads import BodyLoad, body_loads, load_terms  # noqa: E402

TWO_HINGES = """<mujoco model="two_hinges">
  <option gravity="0 0 0"/>
  <worldbody>
    <body name="lower">
      <joint name="bottom" type="hinge" axis="0 1 0" pos="0 0 0"/>
      <geom type="sphere" size="0.02" pos="0 0 0.15" mass="1"/>
      <body name="upper" pos="0 0 0.3">
        <joint name="top" type="hinge" axis="0 1 0" pos="0 0 0"/>
        <geom type="sphere" size="0.02" pos="0 0 0.2" mass="1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _applied(engine, load: BodyLoad, qpos) -> np.ndarray:
    """MuJoCo's generalised force of the load at qpos: mj_applyFT at the point, the force turned for 'body'."""
    engine.set_state(qpos)
    model, d = engine.model, engine.data
    body = engine.names("body").index(load.body)
    rotation = d.xmat[body].reshape(3, 3)
    point = d.xpos[body] + rotation @ np.asarray(load.point)
    force = rotation @ np.asarray(load.force) if load.frame == "body" else np.asarray(load.force, float)
    out = np.zeros(model.nv)
    mujoco.mj_applyFT(model, d, force, np.zeros(3), point, body, out)
    return out


def _differences(engine, load, qpos, step=1e-6) -> np.ndarray:
    """Central differences of mj_applyFT's generalised force in every q: the referee of the load stiffness."""
    n = engine.model.nv
    out = np.zeros((n, n))
    for k in range(n):
        plus, minus = np.array(qpos, float), np.array(qpos, float)
        plus[k] += step
        minus[k] -= step
        out[:, k] = (_applied(engine, load, plus) - _applied(engine, load, minus)) / (2 * step)
    return out


@pytest.fixture(scope="module")
def hinges(tmp_path_factory):
    path = tmp_path_factory.mktemp("loads") / "two_hinges.xml"
    path.write_text(TWO_HINGES)
    return load_engine(path, cache=False)


LOADS = [
    BodyLoad("torso", (20.0, 10.0, -150.0), (0.1, 0.05, 0.2)),
    BodyLoad("torso", (20.0, 10.0, -150.0), (0.1, 0.05, 0.2), "body"),
    BodyLoad("lumbar3", (-5.0, 30.0, 40.0), (0.0, -0.02, 0.01), "body"),
]


@pytest.mark.parametrize("load", LOADS, ids=["torso-ground", "torso-body", "lumbar3-body"])
@pytest.mark.parametrize("bent", [0.0, 0.05])
def test_force_and_stiffness_are_mujocos(torso, load, bent):
    """J^T F equals mj_applyFT to 1e-9 relative; K_load equals central differences of it (MyoTorso, two postures)."""
    qpos = torso.posture() + bent * np.linspace(-1, 1, torso.engine.model.nq)  # a posture off the reference too
    tau, stiffness = load_terms(torso.engine, [load], qpos)
    reference = _applied(torso.engine, load, qpos)
    assert np.max(np.abs(tau - reference)) <= 1e-9 * np.max(np.abs(reference))
    differences = _differences(torso.engine, load, qpos)
    # the central differences' error is O(step^2) times the third derivative: 1e-7 of the largest entry
    assert np.max(np.abs(stiffness - differences)) <= 1e-7 * np.max(np.abs(differences))


def test_two_hinges_closed_form(hinges):
    """A vertical load F_z at height h above a hinge: -F_z h (the paper's -(P - c_hi) . F), and a follower's extra.

    P at 0.7 m above the bottom hinge and 0.4 m above the top one: K = -F_z [[0.7, 0.4], [0.4, 0.4]] for a
    ground-fixed force; fixed in the body, K = F_z [[0, 0.3], [0, 0]] ((o_outer - o_j) . F: the follower's
    dF/dq adds (P - o_j) . F to row j, docs/anatomy.md).
    """
    f_z = -100.0
    ground = BodyLoad("upper", (0.0, 0.0, f_z), (0.0, 0.0, 0.4))
    tau, k = load_terms(hinges, [ground], np.zeros(2))
    assert np.allclose(tau, 0.0, atol=1e-12)  # upright: the load's line passes through both hinges
    assert np.allclose(k, -f_z * np.array([[0.7, 0.4], [0.4, 0.4]]), rtol=1e-12)
    follower = BodyLoad("upper", (0.0, 0.0, f_z), (0.0, 0.0, 0.4), "body")
    _, k_body = load_terms(hinges, [follower], np.zeros(2))
    assert np.allclose(k_body, f_z * np.array([[0.0, 0.3], [0.0, 0.0]]), rtol=1e-12, atol=1e-12)
    # one hinge alone (the top): a follower force has no load stiffness there, a ground-fixed one -F_z h
    assert k_body[1, 1] == pytest.approx(0.0, abs=1e-12) and k[1, 1] == pytest.approx(-f_z * 0.4)


def test_chains_take_the_loads(torso, sagittal):
    """The free chain's K_0 gains K_load, the linearisation's torque offset J^T F; unloaded again after."""
    load = LOADS[0]
    free, _, lin = torso.chains("sagittal", loads=[load])
    tau, k = load_terms(torso.engine, [load], torso.posture())
    n = free.n_joints
    dofs = list(lin.dofs[:n])
    assert np.allclose(free.stiffness_offset - sagittal[0].stiffness_offset, k[np.ix_(dofs, dofs)], rtol=1e-12)
    assert np.allclose(lin.torque_offset - sagittal[2].torque_offset, tau, rtol=1e-12, atol=1e-12)
    assert "load F = (20, 10, -150) N" in free.source
    again, _, _ = torso.chains("sagittal")  # nothing cached holds the load
    assert np.array_equal(again.stiffness_offset, sagittal[0].stiffness_offset)


def test_unknown_body_and_bad_loads_refused(torso):
    """A body the model lacks, a force of two components, a frame unknown: ParameterError in one line."""
    with pytest.raises(ParameterError, match="BODY must be a body of the model"):
        torso.chains("sagittal", loads=[BodyLoad("thorax", (0.0, 0.0, -1.0))])
    with pytest.raises(ParameterError, match="loads"):
        body_loads([{"body": "torso", "force": (0.0, 1.0)}])
    with pytest.raises(ParameterError, match="frame"):
        BodyLoad("torso", (0.0, 0.0, 1.0), frame="world")
    with pytest.raises(ParameterError, match="loads"):
        body_loads([{"body": "torso", "force": (0.0, 0.0, 1.0), "mass": 3}])


def test_engine_without_loads_refuses_in_one_line():
    """An engine that does not override apply_loads (a made-up one) refuses a load naming --load."""
    with pytest.raises(ParameterError, match="--load: is not available"):
        MappedModel.apply_loads(SimpleNamespace(name="made-up"), None, None, LOADS[:1], ())


def test_optimum_holds_the_load(torso):
    """The least-effort optimum with a load balances the load's J^T F too: on the rhythm's rows (MuJoCo's equalities
    carrying the rest), T^T (tau_per a + tau_0 + J^T F) = 0, J^T F from load_terms (MuJoCo's mj_applyFT, above)."""
    import dataclasses

    from spinectl.anatomy.optimum import optimise

    loads = [BodyLoad("torso", (0.0, 0.0, -100.0), (0.1, 0.0, 0.3))]
    opt = optimise(torso, stability="none", equilibrium="rhythm", loads=loads)
    assert opt.ok
    _, _, lin = torso.chains("sagittal")
    _, per, offset = torso.equilibrium_rows(lin, "sagittal", None, "rhythm")
    tau, _ = load_terms(torso.engine, loads, torso.posture())
    _, _, held = torso.equilibrium_rows(dataclasses.replace(lin, torque_offset=tau), "sagittal", None, "rhythm")
    residual = per @ opt.activations + offset + held
    assert np.max(np.abs(residual)) <= 1e-6 * np.max(np.abs(held))
    assert np.max(np.abs(per @ opt.activations + offset)) > 0.1 * np.max(np.abs(held))  # the load is what it holds
    unloaded = optimise(torso, stability="none", equilibrium="rhythm")
    assert opt.cost > unloaded.cost  # holding 100 N more costs effort
