"""The anatomical chain's linearisation against MuJoCo's own forces, kinematics and linearisation.

Reference numbers: central finite differences of MuJoCo's generalised forces
(``qfrc_actuator + qfrc_passive - qfrc_bias``, :meth:`Engine.generalised_force`), MuJoCo's
body Jacobians (:func:`mujoco.mj_jacBody`) and :func:`mujoco.mjd_transitionFD`; none of them
goes through spinectl's linearisation.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.anatomy.analyses import analyse
from spinectl.anatomy.referee import mujoco_eigenvalues

H = 1e-6  # central-difference step [rad]: truncation ~1e-12, rounding ~1e-10 relative here


def fd_stiffness(engine, q0, transform, dofs, act):
    """-(d/dx) of T^T tau(q0 + T x) at x = 0 by central differences, tau MuJoCo's own generalised force."""
    out = np.zeros((transform.shape[1], transform.shape[1]))
    for k in range(transform.shape[1]):
        sides = []
        for sign in (1.0, -1.0):
            q = q0.copy()
            q[list(dofs)] += sign * H * transform[:, k]
            sides.append(transform.T @ engine.generalised_force(q, act)[list(dofs)])
        out[:, k] = (sides[0] - sides[1]) / (2 * H)
    return out


@pytest.mark.parametrize("level", ["zero", "random", "full"])
def test_free_stiffness_is_the_finite_difference_of_mujocos_forces(torso, sagittal, level):
    """K(a) = K_0 + sum a_i K_i of the free chain equals the central difference of MuJoCo's generalised forces
    over the five FE joints to 1e-6 relative, at a = 0, a random a in [0, 1]^210 and a = 1 (affine in a)."""
    free, _, lin = sagittal
    a = {"zero": np.zeros(210), "full": np.ones(210), "random": np.random.default_rng(3).uniform(0, 1, 210)}[level]
    n = free.n_joints
    reference = fd_stiffness(torso.engine, torso.posture(), np.eye(n), lin.dofs[:n], a)
    assert np.abs(free.stiffness(a) - reference).max() <= 1e-6 * np.abs(reference).max()


def test_constrained_stiffness_is_the_finite_difference_along_the_rhythm(torso):
    """The chain constrained by MyoTorso's rhythm (one coordinate, flex_extension, moving the four FE joints above
    it and the abdomen by its equality coefficients) has K_c equal to the central difference of T^T tau along the
    rhythm, to 1e-6 relative."""
    lin, rhy, _ = torso.linearise("sagittal")
    _, con, _ = torso.chains("sagittal")
    a = np.full(210, 0.1)
    reference = fd_stiffness(torso.engine, torso.posture(), rhy.transform, rhy.dofs, a)
    assert con.joints == ("flex_extension",)
    assert np.abs(con.stiffness(a) - reference).max() <= 1e-6 * np.abs(reference).max()


def test_the_rhythm_is_the_models_equality_coefficients(torso):
    """T's rows are MyoTorso's joint-equality slopes (eq_data[1]) of each joint slaved to flex_extension."""
    import mujoco

    lin, rhy, involved = torso.linearise("sagittal")
    model = torso.engine.model
    for row, name in enumerate(involved[1:], start=1):
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        eq = [e for e in range(model.neq) if model.eq_obj1id[e] == joint]
        assert len(eq) == 1 and rhy.transform[row, 0] == pytest.approx(model.eq_data[eq[0]][1])


def test_damping_is_the_finite_difference_in_velocity(torso, sagittal):
    """D(a) = dtau/dq' equals a central difference of MuJoCo's generalised forces in the joint velocities."""
    import mujoco

    free, _, lin = sagittal
    engine, a = torso.engine, np.full(210, 0.3)
    dofs = list(lin.dofs[: free.n_joints])
    reference = np.zeros((5, 5))
    for k, dof in enumerate(dofs):
        sides = []
        for sign in (1.0, -1.0):
            engine.set_state(torso.posture(), a)
            engine.data.qvel[dof] = sign * H
            mujoco.mj_fwdVelocity(engine.model, engine.data)
            mujoco.mj_fwdActuation(engine.model, engine.data)
            d = engine.data
            sides.append((d.qfrc_actuator + d.qfrc_passive - d.qfrc_bias)[dofs])
        reference[:, k] = (sides[0] - sides[1]) / (2 * H)
    assert np.abs(free.damping(a) - reference).max() <= 1e-6 * np.abs(reference).max()


def test_global_muscles_see_only_the_thorax_pelvis_motion(torso):
    """The global muscles' moment arms have rank 3 (MyoTorso: thorax-pelvis only, sagittal), the rank of the
    thorax's planar motion on the pelvis (MuJoCo's body Jacobian of ``torso`` over the five FE joints, a second
    method); their null space is the Jacobian's: the thorax does not move along it. All 210 muscles: rank 5."""
    import mujoco

    result = analyse(torso, activation=0.0)
    cert = result.certificate
    engine = torso.engine
    engine.set_state(torso.posture())
    jacp, jacr = np.zeros((3, engine.model.nv)), np.zeros((3, engine.model.nv))
    body = mujoco.mj_name2id(engine.model, mujoco.mjtObj.mjOBJ_BODY, "torso")
    mujoco.mj_jacBody(engine.model, engine.data, jacp, jacr, body)
    lin, _, _ = torso.linearise("sagittal")
    dofs = list(lin.dofs[:5])
    jac = np.vstack([jacp, jacr])[:, dofs]
    assert cert.rank == np.linalg.matrix_rank(jac, tol=1e-9) == 3
    assert np.abs(jac @ cert.null_space).max() <= 1e-9 * np.abs(jac).max()
    assert np.linalg.matrix_rank(lin.moment_arms[:, dofs], tol=1e-9) == 5


@pytest.mark.parametrize(("act", "stiffness"), [(0.05, "none"), (0.2, "mapped")])
def test_eigenvalues_agree_with_mujocos_own_linearisation(torso, sagittal, act, stiffness):
    """The eigenvalues of (M, D, K) of the free chain agree with MuJoCo's mjd_transitionFD (activations held,
    constraints off, Euler's step turned continuous) to 1e-3 relative on every mode; with and without the mapped
    joint stiffness (given to MuJoCo as its joint stiffness)."""
    result = analyse(torso, activation=act, joint_stiffness=stiffness, check=True)
    assert result.mujoco_eigenvalues.size == 10
    assert result.referee_error() <= 1e-3


def test_the_referee_fails_on_a_wrong_mass(torso, sagittal):
    """The referee can fail: the same comparison with the mass matrix off by 1 % differs by more than 1e-3."""
    from dataclasses import replace

    from spinectl.anatomy.analyses import state_matrix

    free = sagittal[0]
    a = np.full(210, 0.05)
    theirs = mujoco_eigenvalues(torso, free, a, np.zeros(5))
    ours = np.linalg.eigvals(state_matrix(replace(free, mass_matrix=free.mass_matrix * 1.01), a))
    worst = max(np.min(np.abs(theirs - lam)) / abs(lam) for lam in ours)
    assert worst > 1e-3


def test_mujocos_simulation_grows_and_decays_at_the_predicted_rate(torso):
    """MuJoCo's own simulation (mj_step, 0.1 ms steps, 0.1 s), started along the leading mode, grows at the
    predicted rate of the most unstable mode at a = 0.05 (+25 1/s) and, at the chain optimum with 50 N m/rad of
    added stiffness, decays at the predicted rate of the slowest mode; both within 5 %."""
    from spinectl.anatomy.optimum import optimise

    unstable = analyse(torso, activation=0.05, check=True)
    assert unstable.free.dynamic_eigenvalues[0].real > 0
    assert unstable.simulated_rate == pytest.approx(unstable.free.dynamic_eigenvalues[0].real, rel=0.05)
    opt = optimise(torso, joint_stiffness=50)
    stable = analyse(torso, activation=opt.activations, joint_stiffness=50, check=True)
    assert stable.free.dynamic_eigenvalues[0].real < 0 and stable.simulated_rate < 0
    assert stable.simulated_rate == pytest.approx(stable.free.dynamic_eigenvalues[0].real, rel=0.05)
