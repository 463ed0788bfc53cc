"""The OpenSim engine's muscle laws against OpenSim's own generalised forces (spinectl.anatomy.opensim_muscles).

Each model is built here through OpenSim's API: a planar chain of two links on two pin joints
(q0, q1), four muscles crossing one or both joints, every muscle of one law: Millard 2012 with a
rigid or a compliant tendon, Thelen 2003 (compliant), De Groote-Fregly 2016 rigid or compliant,
pennate (0.3 rad at the optimal fibre length) or not. The referee is OpenSim alone: the net
generalised force tau = -(inverse dynamics at zero acceleration) with the muscles at the given
activation (``Muscle.setActivation``, compliant fibres in equilibrium by ``Model.equilibrateMuscles``
at each perturbed posture), differenced centrally in the coordinates (K) and in their speeds (D).
"""

from __future__ import annotations

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from shared_models import ABSENT, SHARED_MODELS  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl.anatomy.opensim_engine import linearise, load_engine, load_osim  # noqa: E402
from spinectl.errors import ModelError  # noqa: E402

NAMES = ["q0", "q1"]
POSTURE = {"q0": 0.1, "q1": 0.2}
ACTIVATIONS = (0.05, 0.5, 1.0)
PENNATION = 0.3  # optimal pennation [rad]
# (origin body, origin point, insertion body, insertion point): two one-joint and two two-joint muscles
PATHS = {
    "front1": ("ground", (0.06, -0.1, 0), "link0", (0.05, 0.2, 0)),
    "back1": ("ground", (-0.07, -0.1, 0), "link0", (-0.05, 0.22, 0)),
    "front2": ("link0", (0.05, 0.1, 0), "link1", (0.04, 0.15, 0)),
    "back2": ("ground", (-0.08, 0.0, 0), "link1", (-0.05, 0.12, 0)),
}
L_OPT = 0.1  # optimal fibre length [m]
DEGROOTE_DAMPING = 0.01


def _muscle(law: str, name: str, compliant: bool, pennation: float):
    """One muscle of the law: F_max 500 N, l_opt 0.1 m, some fibre damping where the law has it."""
    if law == "millard":
        muscle = osim.Millard2012EquilibriumMuscle(name, 500.0, L_OPT, 0.1, pennation)
        muscle.set_fiber_damping(0.1)
    elif law == "thelen":
        muscle = osim.Thelen2003Muscle(name, 500.0, L_OPT, 0.1, pennation)
    else:
        muscle = osim.DeGrooteFregly2016Muscle()
        muscle.setName(name)
        muscle.set_max_isometric_force(500.0)
        muscle.set_optimal_fiber_length(L_OPT)
        muscle.set_pennation_angle_at_optimal(pennation)
        muscle.set_fiber_damping(DEGROOTE_DAMPING)
    if law != "thelen":  # Thelen's tendon is always compliant (OpenSim refuses the flag)
        muscle.set_ignore_tendon_compliance(not compliant)
    return muscle


def build(path, law: str, compliant: bool = False, pennation: float = 0.0, wrap=None) -> str:
    """The two-link chain with four muscles of ``law``, written to ``path``; fibres near l_opt at the default pose."""
    model = osim.Model()
    model.setName("chain")
    parent = model.getGround()
    for k in range(2):
        body = osim.Body(f"link{k}", 2.0, osim.Vec3(0, 0.15, 0), osim.Inertia(0.02, 0.02, 0.02))
        at = osim.Vec3(0, 0.3 * k, 0)
        joint = osim.PinJoint(f"pin{k}", parent, at, osim.Vec3(0), body, osim.Vec3(0), osim.Vec3(0))
        joint.updCoordinate().setName(NAMES[k])
        joint.updCoordinate().setDefaultValue(POSTURE[NAMES[k]])
        model.addBody(body)
        model.addJoint(joint)
        parent = body
    for name, (origin, p0, insertion, p1) in PATHS.items():
        muscle = _muscle(law, name, compliant, pennation)
        frames = [model.getGround() if b == "ground" else model.getBodySet().get(b) for b in (origin, insertion)]
        muscle.addNewPathPoint(f"{name}_origin", frames[0], osim.Vec3(*p0))
        muscle.addNewPathPoint(f"{name}_insertion", frames[1], osim.Vec3(*p1))
        model.addForce(muscle)
    model.finalizeConnections()
    state = model.initSystem()
    for i in range(model.getMuscles().getSize()):  # slack length: fibres at 0.9 ... 1.2 l_opt (along the tendon)
        muscle = model.getMuscles().get(i)
        muscle.setTendonSlackLength(muscle.getLength(state) - L_OPT * np.cos(pennation) * (0.9 + 0.1 * i))
    model.finalizeConnections()
    model.printToXML(str(path))
    return str(path)


def _mobilities(model, state, names) -> list:
    """The index in the system's speeds of each coordinate of ``names`` (the others' speeds 0)."""
    coords, out = model.getCoordinateSet(), []
    for name in names:
        for other in names:
            coords.get(other).setSpeedValue(state, float(other == name))
        u = state.getU()
        out.append(int(np.argmax([abs(u.get(k)) for k in range(u.size())])))
    return out


def opensim_torque(model, state, q: dict, u: dict, a) -> np.ndarray:
    """OpenSim's net generalised force on the coordinates of ``q`` at (q, u), every muscle at ``a`` [N m]."""
    names = list(q)
    order = _mobilities(model, state, names)
    coords = model.getCoordinateSet()
    for name in names:
        coords.get(name).setValue(state, q[name], False)
        coords.get(name).setSpeedValue(state, u[name])
    model.realizeVelocity(state)
    muscles = model.getMuscles()
    for i in range(muscles.getSize()):
        muscles.get(i).setActivation(state, float(a[i]))
    model.equilibrateMuscles(state)
    model.realizeDynamics(state)
    needed = osim.InverseDynamicsSolver(model).solve(state, osim.Vector(state.getNU(), 0.0))
    return -np.array([needed.get(k) for k in order])


def referee(path_or_model, a, step=1e-5, posture=None, state=None) -> tuple:
    """(tau, K = dtau/dq, D = dtau/du) by OpenSim alone over the posture's coordinates, central differences of step
    ``step`` [rad, rad/s]; ``path_or_model`` a file (built anew) or a model with its ``state``."""
    posture = POSTURE if posture is None else posture
    if state is None:
        model = osim.Model(path_or_model)
        state = model.initSystem()
    else:
        model = path_or_model
    names, still = list(posture), dict.fromkeys(posture, 0.0)
    tau = opensim_torque(model, state, posture, still, a)
    K, D = np.zeros((len(names), len(names))), np.zeros((len(names), len(names)))
    for k, name in enumerate(names):
        moved = [opensim_torque(model, state, {**posture, name: posture[name] + s * step}, still, a) for s in (1, -1)]
        K[:, k] = (moved[0] - moved[1]) / (2 * step)
        sped = [opensim_torque(model, state, posture, {**still, name: s * step}, a) for s in (1, -1)]
        D[:, k] = (sped[0] - sped[1]) / (2 * step)
    opensim_torque(model, state, posture, still, a)
    return tau, K, D


def spinectl_at(lin, a) -> tuple:
    """(tau, K, D) of the Linearisation at activations ``a``."""
    tau = lin.torque_offset + lin.torque_per_muscle @ a
    return tau, lin.stiffness_offset + lin.stiffness_per_muscle @ a, lin.damping_offset + lin.damping_per_muscle @ a


def _close(mine, theirs, tol=1e-4) -> float:
    """The largest difference relative to the referee's largest entry, asserted <= tol."""
    off = np.max(np.abs(mine - theirs)) / np.max(np.abs(theirs))
    assert off <= tol, (mine, theirs)
    return off


@pytest.mark.parametrize(
    ("law", "pennation"), [("millard", 0.0), ("millard", PENNATION), ("degroote", 0.0), ("degroote", PENNATION)]
)
def test_rigid_tendons_k_d_and_torque_are_opensims_at_every_activation(tmp_path, law, pennation):
    """Rigid tendons: one linearisation (F affine in a) gives tau, K and D at a = 0.05, 0.5 and 1 equal to central
    differences of OpenSim's own generalised forces to 1e-4 of their largest entry, pennate or not (before: the
    Millard curves without pennation, 3-7 % off on a pennate model; De Groote refused)."""
    path = build(tmp_path / "chain.osim", law, pennation=pennation)
    lin = linearise(load_engine(path), NAMES, POSTURE)
    assert lin.notes == ()  # exact: nothing linearised at an operating activation
    for level in ACTIVATIONS:
        a = np.full(4, level)
        for mine, theirs in zip(spinectl_at(lin, a), referee(path, a), strict=True):
            _close(mine, theirs)


@pytest.mark.parametrize(("law", "pennation"), [("millard", PENNATION), ("thelen", PENNATION), ("degroote", 0.0)])
def test_compliant_tendons_k_and_torque_are_opensims_at_the_operating_activation(tmp_path, law, pennation):
    """Compliant tendons: linearised at the operating activation, tau and K there equal central differences of
    OpenSim's generalised forces with the fibres in equilibrium at each posture, to 1e-4 of the largest entry (step
    1e-4 rad: De Groote's equilibrium is solved to a tolerance); the linearisation says it is a tangent."""
    path = build(tmp_path / "chain.osim", law, compliant=True, pennation=pennation)
    engine = load_engine(path)
    for level in ACTIVATIONS:
        a = np.full(4, level)
        lin = linearise(engine, NAMES, POSTURE, activations=a)
        assert "linearised at the operating activations" in lin.notes[0]
        tau, K, _ = referee(path, a, step=1e-4)
        mine = spinectl_at(lin, a)
        _close(mine[0], tau)
        _close(mine[1], K)


def _fibre_damping_by_the_curves(muscle, state) -> float:
    """c_F = cos^2(alpha) F_max (a f_L f_V'(0) + beta) / (l_opt v_max) [N s/m] (Millard et al. 2013, eq. 1 and 4;
    De Groote et al. 2016 eq. S1): the fibre force along the tendon differentiated in its velocity along the tendon
    (v_AT = v_M / cos(alpha) at constant muscle thickness), the force-velocity slope by the law's own curve.
    OpenSim's De Groote muscle with a compliant tendon (explicit mode) finds its fibre velocity from the inverse
    force-velocity curve without the fibre damping (DeGrooteFregly2016Muscle.cpp, calcFiberVelocityInfoHelper), so
    in OpenSim's own fibre dynamics beta does not damp it: beta is left out there."""
    a, f_l = muscle.getActivation(state), muscle.getActiveForceLengthMultiplier(state)
    v_unit = muscle.getOptimalFiberLength() * muscle.getMaxContractionVelocity()
    millard = osim.Millard2012EquilibriumMuscle.safeDownCast(muscle)
    if millard is not None:
        slope, beta = millard.getForceVelocityCurve().calcDerivative(0.0, 1), millard.get_fiber_damping()
    else:
        h = 1e-6
        fv = osim.DeGrooteFregly2016Muscle.calcForceVelocityMultiplier
        slope, beta = (fv(h) - fv(-h)) / (2 * h), 0.0  # no damping in OpenSim's explicit fibre velocity
    return muscle.getCosPennationAngle(state) ** 2 * muscle.getMaxIsometricForce() * (a * f_l * slope + beta) / v_unit


@pytest.mark.parametrize("law", ["millard", "degroote"])
def test_compliant_damping_is_the_series_combination(tmp_path, law):
    """A compliant tendon's D is sum_i c_eff,i r_i r_i^T with c_eff = c_F (k_T / (k_T + k_F))^2, the quasi-static
    damping of a tendon spring in series with the fibre's spring and damper, k_T and k_F OpenSim's stiffnesses at the
    equilibrium and c_F from the law's own force-velocity curve (_fibre_damping_by_the_curves), to 1e-4. (OpenSim's
    own equilibrium at a speed is no referee here: Millard's ignores the speed, De Groote's partitions it otherwise.)"""
    path = build(tmp_path / "chain.osim", law, compliant=True, pennation=PENNATION)
    engine = load_engine(path)
    a = np.full(4, 0.5)
    lin = linearise(engine, NAMES, POSTURE, activations=a)
    model = osim.Model(path)
    state = model.initSystem()
    opensim_torque(model, state, POSTURE, dict.fromkeys(NAMES, 0.0), a)
    muscles = [model.getMuscles().get(i) for i in range(4)]
    c_eff = [
        _fibre_damping_by_the_curves(m, state)
        * (m.getTendonStiffness(state) / (m.getTendonStiffness(state) + m.getFiberStiffnessAlongTendon(state))) ** 2
        for m in muscles
    ]
    expected = np.einsum("ij,ik,i->jk", lin.moment_arms, lin.moment_arms, c_eff)
    _close(spinectl_at(lin, a)[2], -expected)


def _mapping(tmp_path) -> str:
    """A throw-away mapping of the chain: ground the pelvis, link0 a vertebra, link1 the thorax."""
    text = (
        '[bodies]\npelvis = ["ground"]\nvertebrae = ["link0"]\nthorax = ["link1"]\n\n'
        '[planes]\nsagittal = ["q0", "q1"]\n'
    )
    out = tmp_path / "chain.toml"
    out.write_text(text)
    return str(out)


def test_millards_activation_floor_is_the_control_bound(tmp_path):
    """Millard's minimum_activation (set to 0.03 on one muscle here, 0.01 OpenSim's default) is that muscle's lower
    control bound and the default activation without a controller; De Groote's floor is 0."""
    path = tmp_path / "chain.osim"
    build(path, "millard", pennation=PENNATION)
    model = osim.Model(str(path))
    floored = osim.Millard2012EquilibriumMuscle.safeDownCast(model.getMuscles().get(2))
    floored.set_minimum_activation(0.03)
    floored.setMinControl(0.03)  # OpenSim refuses a control below the floor
    model.printToXML(str(path))
    loaded = load_osim(path, mapping=_mapping(tmp_path))
    lower, upper = loaded.control_bounds()
    np.testing.assert_array_equal(lower, [0.01, 0.01, 0.03, 0.01])
    np.testing.assert_array_equal(upper, 1.0)
    np.testing.assert_array_equal(loaded.default_controls(), lower)
    other = load_osim(build(tmp_path / "degroote.osim", "degroote"), mapping=_mapping(tmp_path))
    np.testing.assert_array_equal(other.control_bounds()[0], 0.0)


def test_the_analysis_linearises_compliant_muscles_at_the_given_activations(tmp_path):
    """``analyse(model, activation=0.5)`` on compliant Millard muscles: its free chain's K at 0.5 is the
    linearisation at 0.5 (to rounding), not the tangent at the default activations (the floor), which is off by more
    than 1 % there (the tangent's error away from its point)."""
    from spinectl.anatomy.analyses import analyse

    path = build(tmp_path / "chain.osim", "millard", compliant=True, pennation=PENNATION)
    loaded = load_osim(path, mapping=_mapping(tmp_path))
    a = np.full(4, 0.5)
    result = analyse(loaded, activation=0.5)
    at_half = spinectl_at(linearise(loaded.engine, NAMES, {}, activations=a), a)[1]
    at_floor = spinectl_at(linearise(loaded.engine, NAMES, {}), a)[1]
    _close(result.free.stiffness, at_half, 1e-9)  # K(a) of the free chain (no stiffness added)
    assert np.max(np.abs(at_floor - at_half)) > 0.01 * np.max(np.abs(at_half))
    assert "4 compliant-tendon muscles linearised at the analysed activations" in result.table()


def test_an_activation_below_the_floor_is_refused_naming_the_floor(tmp_path):
    """``activation=0`` on Millard muscles (floor 0.01, OpenSim's default) is one line naming the floor, not
    "[0, 1]"; 0.01 is analysed; on De Groote muscles (no floor) 0 is analysed."""
    from spinectl.anatomy.analyses import analyse
    from spinectl.errors import ParameterError

    millard = load_osim(build(tmp_path / "millard.osim", "millard"), mapping=_mapping(tmp_path))
    with pytest.raises(ParameterError) as caught:
        analyse(millard, activation=0.0)
    assert "minimum activation (0.01 ... 0.01)" in str(caught.value) and "got 0 ... 0" in str(caught.value)
    assert analyse(millard, activation=0.01).activations.min() == 0.01
    degroote = load_osim(build(tmp_path / "degroote.osim", "degroote"), mapping=_mapping(tmp_path))
    assert analyse(degroote, activation=0.0).activations.max() == 0.0


def test_an_unsupported_muscle_class_is_one_line(tmp_path):
    """A muscle of a class OpenSim evaluates but the import does not read (McKibben here, a RigidTendonMuscle in
    tests/anatomy/test_osim_replay.py) is refused naming the muscle, its class and the supported classes."""
    path = tmp_path / "chain.osim"
    build(path, "millard")
    model = osim.Model(str(path))
    other = osim.RigidTendonMuscle("odd", 100.0, L_OPT, 0.2, 0.0)
    other.addNewPathPoint("odd_origin", model.getGround(), osim.Vec3(0.05, -0.1, 0))
    other.addNewPathPoint("odd_insertion", model.getBodySet().get("link0"), osim.Vec3(0.05, 0.1, 0))
    model.addForce(other)
    model.finalizeConnections()
    model.printToXML(str(path))
    with pytest.raises(ModelError) as caught:
        load_osim(path, mapping=_mapping(tmp_path))
    message = str(caught.value)
    assert "\n" not in message and "odd (RigidTendonMuscle)" in message
    assert "Millard2012EquilibriumMuscle, Thelen2003Muscle, DeGrooteFregly2016Muscle" in message


SHARED = SHARED_MODELS
POSE2SIM = SHARED / "pose2sim-beaucage-gauvreau" / "Model_Pose2Sim_muscles_flex.osim"
CYCLIST = SHARED / "allaire-cyclist" / "s01modelScaled.osim"


def _shared_check(path, names, levels, step):
    """spinectl's and OpenSim's (tau, K, D) over ``names`` at the default posture (couplers off), per activation."""
    engine = load_engine(path)
    m = engine.model.getMuscles().getSize()
    posture = {n: engine.coordinate(n).getDefaultValue() for n in names}
    out = []
    for level in levels:
        a = np.full(m, level)
        lin = linearise(engine, names, {}, activations=a)
        out.append((lin, spinectl_at(lin, a), referee(engine.model, a, step=step, posture=posture, state=engine.state)))
    return out


@pytest.mark.skipif(not POSE2SIM.is_file(), reason=ABSENT)
def test_the_pose2sim_models_de_groote_muscles_are_opensims():
    """The Pose2Sim model as downloaded (318 rigid-tendon De Groote muscles, 212 pennate; before: refused) over
    L5/S1 ... L3/L4 flexion at a = 0.05 and 0.5: tau and D equal OpenSim's central differences to 1e-6 of their
    largest entry, K to 2e-4 of it against the symmetric part of OpenSim's. OpenSim's own K there is not symmetric
    (its antisymmetric part is 8e-5 at 0.05 and 4.5e-4 at 0.5 of the largest entry, measured; a gradient's is 0):
    the wrapping muscles' moment arms (latissimus dorsi) differ from -dL/dq by up to 3 % of the largest arm, which
    the geometry's linearisation (sum r f, a symmetric Hessian) cannot follow; each muscle's stiffness dF/dL is
    OpenSim's to 2e-9 (measured against central differences of getTendonForce)."""
    names = ["L5_S1_Flex_Ext", "L4_L5_Flex_Ext", "L3_L4_Flex_Ext"]
    for lin, (tau, K, D), (ref_tau, ref_K, ref_D) in _shared_check(POSE2SIM, names, (0.05, 0.5), 1e-5):
        assert lin.notes == ()
        _close(tau, ref_tau, 1e-6)
        _close(D, ref_D, 1e-6)
        _close(K, 0.5 * (ref_K + ref_K.T), 2e-4)


@pytest.mark.slow
@pytest.mark.skipif(not CYCLIST.is_file(), reason=ABSENT)
def test_the_cyclist_models_thelen_and_compliant_millard_muscles_are_opensims():
    """The Allaire/Bruno cyclist model as downloaded (Thelen and compliant Millard muscles; before: refused) over
    L5/S1 and L4/L5 flexion at a = 0.5: tau and K equal OpenSim's central differences (fibres in equilibrium at each
    posture) to 1e-4 of their largest entry, and the linearisation says it is the tangent at that activation."""
    names = ["L5_S1_FE", "L4_L5_FE"]
    ((lin, (tau, K, _), (ref_tau, ref_K, _)),) = _shared_check(CYCLIST, names, (0.5,), 1e-4)
    assert "compliant-tendon muscle(s)" in lin.notes[0]
    _close(tau, ref_tau)
    _close(K, ref_K)


def test_the_optimums_first_line_says_where_compliant_tendons_were_linearised(tmp_path):
    """The optimum on four compliant Millard muscles: its table's first line names the plane, the posture, whose
    activations ('the optimum's', not 'given') and that the optimum took their tangent at the activation floors
    (``optimise`` linearises without activations), the analysis below at the optimum's own (before: the identity
    only). Rigid De Groote muscles (the variant): no such clause, they are exact at every activation."""
    from spinectl.anatomy.optimum import optimised

    path = build(tmp_path / "chain.osim", "millard", compliant=True, pennation=PENNATION)
    first = optimised(load_osim(path, mapping=_mapping(tmp_path)), stability="none").table().splitlines()[0]
    assert ", sagittal plane, posture: the model's reference posture, activations: the optimum's" in first
    assert first.endswith(
        "4 compliant-tendon muscles linearised at their activation floors for the optimum, at the optimum's "
        "activations for the analysis below"
    )
    rigid = build(tmp_path / "degroote.osim", "degroote")
    first = optimised(load_osim(rigid, mapping=_mapping(tmp_path)), stability="none").table().splitlines()[0]
    assert first.endswith("activations: the optimum's")


def test_opensims_message_keeps_its_reason_and_drops_the_wrapper_and_source_location():
    """OpenSim's exceptions read ``std::exception in '<signature>': <reason> ... Thrown at <file>:<line> ...``
    (the shape of the cyclist model's Thelen failure below): the one line keeps the reason and its object only."""
    from spinectl.anatomy.engine import opensim_message

    exc = RuntimeError(
        "std::exception in 'void OpenSim::Model::equilibrateMuscles(SimTK::State &)': Unable to compute "
        "equilibrium.\n  Fiber length is nan\n\n\tIn Object 'E0_R5_r' of type Thelen2003Muscle.\n"
        "\tThrown at Thelen2003Muscle.cpp:374 in computeInitialFiberEquilibrium()."
    )
    assert opensim_message(exc) == (
        "Unable to compute equilibrium.; Fiber length is nan; In Object 'E0_R5_r' of type Thelen2003Muscle."
    )
    assert opensim_message(RuntimeError("")) == "RuntimeError"


def _posture_file(path, model_file, moved: dict) -> str:
    """Two frames: every coordinate of the model at its default at t = 0 s, and at t = 1 s those of ``moved``
    turned by their value [rad]; an .sto written through OpenSim's own adapter."""
    model = osim.Model(str(model_file))
    coordinates = model.getCoordinateSet()
    labels = osim.StdVectorString()
    rows = [osim.RowVector(coordinates.getSize(), 0.0) for _ in range(2)]
    for i in range(coordinates.getSize()):
        c = coordinates.get(i)
        labels.append(c.getName())
        rows[0][i] = c.getDefaultValue()
        rows[1][i] = c.getDefaultValue() + moved.get(c.getName(), 0.0)
    table = osim.TimeSeriesTable()
    table.setColumnLabels(labels)
    for time, row in enumerate(rows):
        table.appendRow(float(time), row)
    table.addTableMetaDataString("inDegrees", "no")
    osim.STOFileAdapter.write(table, str(path))
    return str(path)


@pytest.mark.skipif(not CYCLIST.is_file(), reason=ABSENT)
def test_a_posture_where_opensim_finds_no_fibre_equilibrium_is_one_line_naming_the_muscle(tmp_path):
    """The cyclist model (Thelen 2003 muscles) with its six lumbar flexion coordinates 8 degrees past their
    defaults: OpenSim's ``equilibrateMuscles`` finds no fibre length for E0_R5_r (a RuntimeError that escaped as a
    traceback, exit 1). Now one ParameterError on the posture, OpenSim's reason and the muscle kept; along a
    motion, the frame's time is named too."""
    from shared_models import DOCUMENTED_MAPPINGS

    from spinectl import anatomy
    from spinectl.anatomy.analyses import analyse
    from spinectl.anatomy.motion import motion_response
    from spinectl.anatomy.recordings import read_recording
    from spinectl.errors import ParameterError

    joints = ["L5_S1_FE", "L4_L5_FE", "L3_L4_FE", "L2_L3_FE", "L1_L2_FE", "T12_L1_FE"]
    posture = _posture_file(tmp_path / "extended.sto", CYCLIST, dict.fromkeys(joints, np.radians(8.0)))
    model = anatomy.load(CYCLIST, DOCUMENTED_MAPPINGS / "cyclist.toml")
    with pytest.raises(ParameterError) as raised:
        analyse(model, "sagittal", posture=posture, time=1.0)
    message = str(raised.value)
    assert raised.value.field == "posture" and "\n" not in message
    assert "fibres in equilibrium" in message and "'E0_R5_r' of type Thelen2003Muscle" in message
    assert "Thrown at" not in message
    with pytest.raises(ParameterError, match=r"^posture: at t = 1 s of the motion: OpenSim cannot put"):
        motion_response(model, read_recording(posture, "posture"), progress=False)
