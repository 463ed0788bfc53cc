"""The stability-constrained static optimum on MyoTorso: its constraints checked with MuJoCo's own forces.

The optimum's equilibrium is checked with MuJoCo's generalised forces at its activations (not the
affine torques the optimiser used), its stability with spinectl's linearisation at those
activations (tested against finite differences in test_linearise.py) and MuJoCo's mjd_transitionFD.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.anatomy.optimum import optimise, optimised, volume_weights
from spinectl.errors import ParameterError


@pytest.fixture(scope="module")
def optima(torso):
    """The optima at 50 N m/rad of added joint stiffness, each criterion, equilibrium on the rhythm."""
    return {s: optimise(torso, stability=s, joint_stiffness=50) for s in ("none", "joints", "rhythm", "chain")}


def test_the_optimum_holds_the_posture_by_mujocos_forces(torso, optima):
    """At each optimum, MuJoCo's own generalised force projected on the rhythm's coordinates (T^T tau, all three
    planes) is zero to 1e-6 N m, and every activation is in [0, 1]."""
    from spinectl.anatomy.linearise import rhythm

    engine = torso.engine
    engine.set_state(torso.posture())
    rhy = rhythm(engine, torso.joint_ids(torso.mapping.planes["3d"]))
    for opt in optima.values():
        assert opt.ok and opt.activations.min() >= 0 and opt.activations.max() <= 1
        tau = engine.generalised_force(torso.posture(), opt.activations)[list(rhy.dofs)]
        assert np.abs(rhy.transform.T @ tau).max() <= 1e-6


def test_each_criterion_holds_at_its_optimum(torso, optima):
    """The chain optimum: least eigenvalue of -K >= mu (to the solver's tolerance), confirmed by MuJoCo's own
    linearisation (all ten dynamic eigenvalues in the left half plane); the joint-by-joint optimum: every diagonal
    entry >= mu; the classic optimum leaves a mode unstable (the criterion binds)."""
    from spinectl.anatomy.analyses import analyse

    mu = 1.0
    assert optima["chain"].eigenvalues.min() >= mu - 1e-6
    assert optima["joints"].joint_stiffness.min() >= mu - 1e-6
    assert optima["none"].eigenvalues.min() < 0
    check = analyse(torso, activation=optima["chain"].activations, joint_stiffness=50, check=True)
    assert check.referee_error() <= 1e-3 and check.mujoco_eigenvalues.real.max() < 0


def test_stability_has_a_price(optima):
    """Each stability criterion adds constraints to the classic problem, so its least cost is no lower; the chain's
    (every joint free) is no lower than the joint-by-joint one here, and strictly higher than the classic one."""
    assert optima["none"].cost <= optima["joints"].cost <= optima["chain"].cost
    assert optima["none"].cost <= optima["rhythm"].cost
    assert optima["chain"].cost > 1.05 * optima["none"].cost


def test_infeasible_is_an_answer(torso):
    """Muscles alone cannot zero the net torque on all fifteen lumbar joints of MyoTorso upright (the least
    worst-case residual is about 8 N m): status 'infeasible', NaN activations and cost."""
    opt = optimise(torso, stability="none", equilibrium="free")
    assert opt.status == "infeasible" and np.isnan(opt.cost) and np.all(np.isnan(opt.activations))
    result = optimised(torso, stability="none", equilibrium="free")
    assert result.analysis is None and result.to_dict()["joints"][0] == "flex_extension"


def test_volume_weights_are_force_times_optimal_length(torso):
    """w_i is proportional to F0_i L0_i, read from MuJoCo's muscle parameters (mean 1)."""
    model = torso.engine.model
    w = volume_weights(torso)
    i, j = 0, 100
    l0 = [
        (model.actuator_lengthrange[k, 1] - model.actuator_lengthrange[k, 0])
        / (model.actuator_gainprm[k, 1] - model.actuator_gainprm[k, 0])
        for k in (i, j)
    ]
    f0 = [model.actuator_gainprm[k, 2] for k in (i, j)]
    assert w.mean() == pytest.approx(1.0)
    assert w[i] / w[j] == pytest.approx(f0[0] * l0[0] / (f0[1] * l0[1]))


def test_bad_criterion_is_refused(torso):
    with pytest.raises(ParameterError, match="stability: must be one of"):
        optimise(torso, stability="diagonal")
    with pytest.raises(ParameterError, match="margin"):
        optimise(torso, margin=-1)
    # the command line's bound holds from Python too (before: NaN eigenvalues at 1e308, exit 0 from the CLI)
    with pytest.raises(ParameterError, match=r"joint_stiffness: must be .* in \[0, 1e\+06\] N m/rad"):
        optimise(torso, joint_stiffness=1e308)


def test_the_lordosis_moves_the_chain_along_the_rhythm(torso):
    """lordosis_posture(10 deg): the five FE angles sum to 10 deg, in the ratios of MyoTorso's equality coefficients
    (each joint's eq_data[1] on flex_extension), the other lumbar joints unmoved; the curve at 0 deg is the optimum
    at the reference posture."""
    import mujoco

    from spinectl.anatomy.optimum import lordosis_curve, lordosis_posture

    q = lordosis_posture(torso, 10.0)
    model = torso.engine.model
    fe = torso.joint_ids(torso.mapping.planes["sagittal"])
    angles = q[[model.jnt_qposadr[j] for j in fe]]
    assert np.degrees(angles.sum()) == pytest.approx(10.0)
    for j, angle in zip(fe[1:], angles[1:], strict=True):
        eq = [e for e in range(model.neq) if model.eq_obj1id[e] == j]
        assert angle / angles[0] == pytest.approx(model.eq_data[eq[0]][1])
    others = torso.joint_ids(torso.mapping.planes["coronal"] + torso.mapping.planes["3d"][10:])
    assert np.all(q[[model.jnt_qposadr[j] for j in others]] == 0)
    abdomen = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "Abs_r3")
    assert q[model.jnt_qposadr[abdomen]] != 0  # slaved to flex_extension by the rhythm
    curve = lordosis_curve(torso, [0.0], joint_stiffness=50)
    assert curve["chain"]["cost"][0] == pytest.approx(optimise(torso, joint_stiffness=50).cost, rel=1e-6)


def test_the_delay_margin_at_the_optimum_is_a_root_on_the_imaginary_axis(torso):
    """At the classic optimum under kp = 120 N m/rad, kd = 5 N m s/rad at every joint and a 50 ms lag, the
    reported delay margin tau and frequency w make the characteristic matrix
    (T_a jw + 1)(M (jw)^2 - D jw - K) + (K_p + K_d jw) exp(-jw tau) singular (its smallest singular value over its
    largest below 1e-6): the closed form of the delayed chain, evaluated here without spinectl.reflex."""
    result = optimised(torso, stability="none", reflex=(120.0, 5.0, 0.05))
    reflex = result.analysis.reflex
    tau, w = reflex["delay_margin_s"], reflex["delay_margin_frequency_rad_s"]
    assert reflex["delay_margin_status"] == "finite" and 0 < tau < 0.1
    free = result.analysis.free
    s = 1j * w
    matrix = (0.05 * s + 1) * (free.mass * s**2 - free.damping * s - free.stiffness) + (120 + 5 * s) * np.eye(
        5
    ) * np.exp(-s * tau)
    sv = np.linalg.svd(matrix, compute_uv=False)
    assert sv[-1] / sv[0] < 1e-6


def test_an_infeasible_chain_optimum_says_what_would_make_it_feasible(torso):
    """MyoTorso's joints have no stiffness of their own (docs/anatomy.md, "The stiffness added"): with none added,
    no activation stabilises the free chain (the global muscles leave a mode unstable, test_linearise.py), so the
    chain optimum is infeasible and its table points to --joint-stiffness; at 50 N m/rad added it is feasible and
    the hint is gone."""
    from spinectl.anatomy.remedy import INFEASIBLE_HINT

    bare = optimised(torso, stability="chain")
    assert bare.optimum.status == "infeasible" and INFEASIBLE_HINT in bare.table()
    assert INFEASIBLE_HINT not in optimised(torso, stability="chain", joint_stiffness=50).table()


def test_the_optimum_table_says_infeasible_plainly_and_mu_only_where_there_is_a_criterion(torso):
    """MyoTorso with no stiffness added: the chain optimum's row says 'infeasible' and that no activations meet it,
    with no NaN cost, no NaN price and no NaN eigenvalues; mu (1 N m/rad) is named on the optimum's row, which has
    a criterion, and not on the classic row, which has none; the price line says why there is none; the remedy
    line begins 'remedy:'. The same with the joint-by-joint criterion and mu = 2 (a variant): feasible, its row
    names mu = 2 and the price is the cost ratio."""
    bare = optimised(torso, stability="chain").table().splitlines()

    def row(lines, prefix):  # the rows by their first word: the identity and the rhythm's torque lines between
        return next(line for line in lines if line.startswith(prefix))

    optimum, classic, price, remedy = (row(bare, p) for p in ("optimum", "classic", "price", "remedy"))
    assert optimum.startswith("optimum (the chain free") and "mu = 1 N m/rad" in optimum
    assert "infeasible: no activations within their bounds hold the posture and meet the criterion" in optimum
    assert "mu =" not in classic and classic.startswith("classic (no stability criterion")
    assert price == "price of stability: none (the optimum is infeasible, so it has no cost to compare)"
    assert remedy.startswith("remedy: ") and "--joint-stiffness" in remedy
    assert not any("nan" in line for line in bare)
    solved = optimised(torso, stability="joints", margin=2.0)
    optimum, classic, price = (row(solved.table().splitlines(), p) for p in ("optimum", "classic", "price"))
    assert "mu = 2 N m/rad" in optimum and "mu =" not in classic
    assert price.endswith(f": {solved.optimum.cost / solved.classic.cost:.4g}")


def test_the_remedy_is_the_least_joint_stiffness_that_makes_the_optimum_feasible(torso):
    """The remedy's bracket, checked by the optimum itself (a second call per side, not the search): feasible
    at the value named, infeasible 2 rtol below it; the table names a --joint-stiffness that is feasible and
    the JSON carries the value. MyoTorso (myo-sim 0.2.4) needs about 40 N m/rad at each joint (docs/anatomy.md)."""
    from spinectl.anatomy.remedy import REMEDY_RTOL

    bare = optimised(torso, stability="chain")
    value = bare.remedy
    assert 1.0 < value < 1e3
    assert optimise(torso, stability="chain", joint_stiffness=value).ok
    assert not optimise(torso, stability="chain", joint_stiffness=value * (1 - 2 * REMEDY_RTOL)).ok
    named = float(bare.table().split("--joint-stiffness ")[-1].split()[0])
    assert named >= value and optimise(torso, stability="chain", joint_stiffness=named).ok
    assert bare.to_dict()["feasible_from_joint_stiffness_Nm_per_rad"] == value
    assert np.isnan(optimised(torso, stability="chain", joint_stiffness=50).remedy)  # solved: nothing to remedy


def test_the_remedy_search_brackets_a_known_threshold():
    """A feasibility that switches at c* = 39.87 (and at none): the bracket's upper end within rtol of c*,
    and inf where nothing up to MAX_REMEDY is feasible."""
    from spinectl.anatomy.remedy import MAX_REMEDY, REMEDY_RTOL, least_joint_stiffness

    calls = []

    def feasible(c):
        calls.append(c)
        return c >= 39.87

    found = least_joint_stiffness(feasible)
    assert 39.87 <= found <= 39.87 * (1 + REMEDY_RTOL) and len(calls) < 30
    assert least_joint_stiffness(feasible, start=10.0) == pytest.approx(found, rel=REMEDY_RTOL)
    assert (
        least_joint_stiffness(lambda c: False) == np.inf and least_joint_stiffness(lambda c: c > MAX_REMEDY) == np.inf
    )


def test_non_lumbar_muscles_take_no_effort_at_the_optimum(torso, optima):
    """MyoTorso's two non-lumbar muscles (LTpT_T1, L1 to T1 on the thorax's rigid piece) have no moment arm on the
    lumbar joints (MuJoCo's, at the reference posture), so no torque on the equilibrium's rows and no K_i: the optimum
    holds them at 0 (left free, the solver gave them 6e-4 to 1e-3, its tolerance on their small volume weights)."""
    non = [i for i, c in enumerate(torso.classes) if c == "non-lumbar"]
    assert [torso.muscles[i] for i in non] == ["LTpT_T1_r", "LTpT_T1_l"]
    for opt in optima.values():
        assert np.abs(opt.activations[non]).max() <= 1e-9


def test_the_torque_the_rhythm_carries_is_in_the_table_beside_the_verdict(torso):
    """MyoTorso's chain optimum with 50 N m/rad added, equilibrium on the rhythm's coordinates: the table shows,
    under the optimum's verdict, the net torque at each lumbar joint, which is MuJoCo's own generalised force at
    the optimum's activations (mj_fwdActuation: actuators + passive - bias, constraint forces left out), largest
    at L1_L2_FE (about 52 N m); with the equilibrium on every joint (free) it is zero and not shown."""
    result = optimised(torso, stability="chain", joint_stiffness=50)
    model, engine = torso.engine.model, torso.engine
    act = np.zeros(model.na)
    act[model.actuator_actadr[engine.muscle_ids()]] = result.optimum.activations
    force = engine.generalised_force(model.qpos0, act)
    joints = result.optimum.lumbar_joints
    expected = force[[model.jnt_dofadr[j] for j in torso.joint_ids(joints)]]
    lines = result.table().splitlines()
    line = lines[lines.index(next(x for x in lines if x.startswith("optimum ("))) + 1]
    shown = dict(cell.rsplit(" ", 1) for cell in line.split("per lumbar joint [N m]: ")[1].split(", "))
    assert list(shown) == list(joints)
    np.testing.assert_allclose([float(v) for v in shown.values()], expected, rtol=5e-3, atol=1e-3)
    assert f"largest {abs(expected).max():.3g} N m at L1_L2_FE" in line and 45 < abs(expected).max() < 60
    free = optimised(torso, stability="chain", joint_stiffness=50, equilibrium="free")
    assert "torque the rhythm carries" not in free.table()


def test_the_optimums_table_names_plane_posture_and_the_optimums_activations(torso):
    """MyoTorso's optimum (10 N m/rad added: feasible in the coronal plane too): the first line names the plane, the
    posture and 'activations: the optimum's'; the analysis at the optimum says '(the optimum's)' and its JSON
    ``activation_source`` too (before: 'given')."""
    for plane, words in (("sagittal", "sagittal plane"), ("coronal", "coronal plane")):
        result = optimised(torso, plane=plane, stability="none", joint_stiffness=10.0)
        lines = result.table().splitlines()
        assert f", {words}, posture: the model's reference posture, activations: the optimum's" in lines[0]
        assert result.to_dict()["activation_source"] == "the optimum's"
        analysed = lines[lines.index("at the optimum's activations:") + 1]
        assert analysed.endswith("(the optimum's)")
