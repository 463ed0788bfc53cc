"""Joint angles, not coordinates: the chains per radian of each joint's rotation (spinectl.anatomy.joint_angles).

The model of most tests is built here with OpenSim's API: three bodies on CustomJoints about z whose rotations
are LinearFunction(0.5), (1) and (0.25) of their coordinates q1, q2, q3, a coupler q3 = 0.1 q1, a spring on
each coordinate (SpringGeneralizedForce: -k_j q_j in the coordinate's units) and gravity, no muscles. The
references are OpenSim's own: its inverse dynamics (the generalised forces), its frames (the joints' rotations).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from shared_models import ABSENT, CHRISTOPHY  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.linearise import constrained_chain, free_chain  # noqa: E402
from spinectl.cli import main  # noqa: E402

SLOPES = (0.5, 1.0, 0.25)  # rad of joint j per rad of q_j: the LinearFunctions of the SpatialTransforms
COUPLING = 0.1  # the coupler: q3 = 0.1 q1
SPRINGS = (30.0, 40.0, 50.0)  # N m per coordinate rad
MAPPING = (
    '[bodies]\npelvis = ["ground"]\nvertebrae = ["b1", "b2"]\nthorax = ["b3"]\n'
    '[planes]\nsagittal = ["q1", "q2", "q3"]\n'
)
AXES = ((0, 0, 1), (1, 0, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1))


def _names(*items):
    out = osim.ArrayStr()
    for name in items:
        out.append(name)
    return out


def _custom(name, parent, child, coordinate, function, height):
    """A CustomJoint whose rotation about z is ``function`` of ``coordinate``, every other axis constant."""
    transform = osim.SpatialTransform()
    parts = (
        transform.upd_rotation1(),
        transform.upd_rotation2(),
        transform.upd_rotation3(),
        transform.upd_translation1(),
        transform.upd_translation2(),
        transform.upd_translation3(),
    )
    for k, (axis, part) in enumerate(zip(AXES, parts, strict=True)):
        part.set_axis(osim.Vec3(*axis))
        if k == 0:
            part.append_coordinates(coordinate)
            part.set_function(function)
        else:
            part.set_function(osim.Constant(0.0))
    return osim.CustomJoint(
        name, parent, osim.Vec3(0, height, 0), osim.Vec3(0), child, osim.Vec3(0), osim.Vec3(0), transform
    )


def build(path: Path, springs=SPRINGS, functions=None, muscle=False, slider=False) -> Path:
    """The three-joint model of the module docstring, written to ``path`` with OpenSim's API."""
    functions = functions or [osim.LinearFunction(s, 0.0) for s in SLOPES]
    model = osim.Model()
    model.setName("tiny")
    parent = model.getGround()
    for k, function in enumerate(functions):
        body = osim.Body(f"b{k + 1}", 2.0, osim.Vec3(0.02, 0.05, 0), osim.Inertia(0.01, 0.01, 0.01))
        model.addBody(body)
        model.addJoint(_custom(f"j{k + 1}", parent, body, f"q{k + 1}", function, 0.1 * (k > 0)))
        parent = body
    coupler = osim.CoordinateCouplerConstraint()
    coupler.setName("c3")
    coupler.setIndependentCoordinateNames(_names("q1"))
    coupler.setDependentCoordinateName("q3")
    coupler.setFunction(osim.LinearFunction(COUPLING, 0.0))
    model.addConstraint(coupler)
    for k, stiffness in enumerate(springs):
        spring = osim.SpringGeneralizedForce(f"q{k + 1}")
        spring.setName(f"spring{k + 1}")
        spring.setStiffness(float(stiffness))
        model.addForce(spring)
    if slider:  # a body on the top one that slides: its coordinate s4_coord_0 turns no joint
        body = osim.Body("b4", 1.0, osim.Vec3(0), osim.Inertia(0.01, 0.01, 0.01))
        model.addBody(body)
        model.addJoint(osim.SliderJoint("s4", model.getBodySet().get("b3"), body))
    if muscle:  # a rigid-tendon Millard muscle from ground to the top body, in front of the joints
        fibre = osim.Millard2012EquilibriumMuscle("front", 500.0, 0.15, 0.1, 0.0)
        fibre.set_ignore_tendon_compliance(True)
        fibre.addNewPathPoint("origin", model.getGround(), osim.Vec3(0.08, -0.2, 0))
        fibre.addNewPathPoint("insertion", model.getBodySet().get("b3"), osim.Vec3(0.08, 0.05, 0))
        model.addForce(fibre)
    model.finalizeConnections()
    model.printToXML(str(path))
    return path


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """(the model file, its mapping file, the model loaded by spinectl)."""
    folder = tmp_path_factory.mktemp("tiny")
    path = build(folder / "tiny.osim")
    mapping = folder / "tiny.toml"
    mapping.write_text(MAPPING)
    return path, mapping, anatomy.load(path, mapping)


def _generalised_force(path: Path, values: dict) -> np.ndarray:
    """OpenSim's generalised force on q1..q3 at rest (couplers off): minus what its inverse dynamics needs.

    In this serial chain, built in order, Simbody's mobilities are q1, q2, q3 (checked on the state's U).
    """
    model = osim.Model(str(path))
    model.updConstraintSet().get(0).set_isEnforced(False)
    state = model.initSystem()
    coords = [model.getCoordinateSet().get(f"q{k + 1}") for k in range(3)]
    coords[1].setSpeedValue(state, 1.0)
    assert [state.getU().get(k) for k in range(3)] == [0.0, 1.0, 0.0]
    coords[1].setSpeedValue(state, 0.0)
    for c in coords:
        c.setValue(state, float(values.get(c.getName(), 0.0)), False)
    model.realizeDynamics(state)
    needed = osim.InverseDynamicsSolver(model).solve(state, osim.Vector(3, 0.0))
    return -np.array([needed.get(k) for k in range(3)])


def _coordinate_stiffness(path: Path, values=None, h=1e-6) -> np.ndarray:
    """K_q = d tau_q/dq by central differences of OpenSim's generalised forces [N m per coordinate rad^2]."""
    values = values or {}
    out = np.zeros((3, 3))
    for k in range(3):
        name = f"q{k + 1}"
        up = _generalised_force(path, {**values, name: values.get(name, 0.0) + h})
        down = _generalised_force(path, {**values, name: values.get(name, 0.0) - h})
        out[:, k] = (up - down) / (2 * h)
    return out


def test_stiffness_per_joint_radian_is_the_engines_generalised_force_over_the_slope_squared(tiny):
    """theta_j = s_j q_j (a LinearFunction), so with V the potential, tau_q = -dV/dq and tau_theta = -dV/dtheta =
    tau_q / s_j; K_theta_jk = d tau_theta_j/d theta_k = K_q_jk / (s_j s_k), on the diagonal K_q_jj / s_j^2.
    K_q is OpenSim's own: central differences of its inverse dynamics. The slopes shown are the functions'."""
    path, _, loaded = tiny
    free = loaded.chain("sagittal")
    expected = _coordinate_stiffness(path) / np.outer(SLOPES, SLOPES)
    np.testing.assert_allclose(free.stiffness_offset, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_allclose(np.diag(free.stiffness_offset), np.diag(_coordinate_stiffness(path)) / np.square(SLOPES))
    np.testing.assert_allclose(loaded.joint_slopes("sagittal").slopes, SLOPES, rtol=1e-12)


def test_added_joint_stiffness_is_k_per_joint_radian_and_s_k_s_on_the_coordinates(tiny, tmp_path):
    """k added at each joint is -k I on the free chain in joint angles, and the same chain as OpenSim's springs of
    k s_j^2 per coordinate rad (1/2 k theta_j^2 = 1/2 k s_j^2 q_j^2: S^T k S on the coordinates). On the chain
    constrained by q3 = 0.1 q1, theta3 = 0.25 * 0.1 q1 = 0.05 theta1: k (1 + 0.05^2) on theta1, k on theta2."""
    path, mapping, loaded = tiny
    k = 20.0
    free0, con0, _ = loaded.chains("sagittal")
    free, con, _ = loaded.chains("sagittal", joint_stiffness=k)
    np.testing.assert_allclose(free.stiffness_offset - free0.stiffness_offset, -k * np.eye(3), atol=1e-12)
    np.testing.assert_allclose(
        con.stiffness_offset - con0.stiffness_offset, -k * np.diag([1 + (0.25 * COUPLING / 0.5) ** 2, 1.0]), atol=1e-9
    )
    springs = [s + k * g**2 for s, g in zip(SPRINGS, SLOPES, strict=True)]
    sprung = anatomy.load(build(tmp_path / "sprung.osim", springs), mapping)
    np.testing.assert_allclose(sprung.chain("sagittal").stiffness_offset, free.stiffness_offset, rtol=1e-7)


def test_the_chains_dynamics_keep_their_eigenvalues_in_joint_angles(tiny):
    """A change of variables is a congruence (W^T K W, W^T M W): the eigenvalues of M^-1 K, the chain's
    dynamics, are those of the engine's coordinates (with k added at a joint as S^T k S there, free and
    constrained); the eigenvalues of -K alone, printed per radian, are not."""
    _, _, loaded = tiny
    k = 20.0
    free, con, _ = loaded.chains("sagittal", joint_stiffness=k)
    lin, rhy, involved = loaded.linearise("sagittal")  # the engine's own, in coordinates
    added = k * np.square(SLOPES)
    args = (loaded.muscles, loaded.classes)
    coord_free = free_chain(lin, tuple(involved), *args, added, "q")
    coord_con = constrained_chain(lin, rhy, involved, *args, added, "q")

    def dynamics(chain):
        return np.sort(np.linalg.eigvals(np.linalg.solve(chain.mass_matrix, chain.stiffness_offset)).real)

    for ours, theirs in ((free, coord_free), (con, coord_con)):
        np.testing.assert_allclose(dynamics(ours), dynamics(theirs), rtol=1e-9)
    statics = np.linalg.eigvalsh(free.stiffness_offset), np.linalg.eigvalsh(coord_free.stiffness_offset)
    assert not np.allclose(*statics, rtol=1e-3)


def _joint_angles(path: Path, values: dict) -> np.ndarray:
    """Each joint's rotation about z (child frame relative to parent frame) by OpenSim's frames [rad]."""
    model = osim.Model(str(path))
    model.updConstraintSet().get(0).set_isEnforced(False)
    state = model.initSystem()
    for name, value in values.items():
        model.getCoordinateSet().get(name).setValue(state, float(value), False)
    model.realizePosition(state)
    out = []
    for k in range(3):
        joint = model.getJointSet().get(f"j{k + 1}")
        x = joint.getChildFrame().expressVectorInAnotherFrame(state, osim.Vec3(1, 0, 0), joint.getParentFrame())
        out.append(np.arctan2(x.get(1), x.get(0)))
    return np.array(out)


def test_the_lordosis_sums_the_joint_angles_opensims_frames_measure(tiny):
    """--lordosis moves the chain along the rhythm so that the joints' rotations (OpenSim's frames), not their
    coordinates, sum to the angle asked: here 0.5 dq1 + 0.25 * 0.1 dq1 = 6 deg (coordinates: dq1 + 0.1 dq1)."""
    path, _, loaded = tiny
    posture = loaded.lordosis_posture(6.0)
    assert np.degrees(_joint_angles(path, posture).sum()) == pytest.approx(6.0, rel=1e-9)
    assert posture["q3"] == pytest.approx(COUPLING * posture["q1"], rel=1e-12)


def test_a_joint_that_turns_nonlinearly_carries_its_torque_through_the_curvature(tmp_path):
    """theta2 = q2 + 0.5 q2^2 (a PolynomialFunction) at q2 = 0.2, where springs and gravity load it: K_theta's
    column 2 is d tau_theta/d theta2 with tau_theta_j = tau_q_j / s_j(q_j), s_2 = 1 + q2, and q2 = -1 +
    sqrt(1 + 2 theta2); by central differences of OpenSim's generalised forces in theta2. Without the term
    tau_q,2 d^2q2/dtheta2^2 the diagonal misses about 8 / 1.2^3 N m/rad."""
    functions = [osim.LinearFunction(0.5, 0.0), osim.PolynomialFunction(osim.Vector([0.5, 1.0, 0.0])),
                 osim.LinearFunction(0.25, 0.0)]  # fmt: skip
    path = build(tmp_path / "curved.osim", functions=functions)
    mapping = tmp_path / "curved.toml"
    mapping.write_text(MAPPING)
    q2 = 0.2
    loaded = anatomy.load(path, mapping)
    free = loaded.chain("sagittal", posture={"q2": q2})

    def tau_theta(theta2):
        q = -1 + np.sqrt(1 + 2 * theta2)
        return _generalised_force(path, {"q2": q}) / np.array([0.5, 1 + q, 0.25])

    theta, h = q2 + 0.5 * q2**2, 1e-5
    column = (tau_theta(theta + h) - tau_theta(theta - h)) / (2 * h)
    np.testing.assert_allclose(free.stiffness_offset[:, 1], column, rtol=1e-6, atol=1e-6)
    assert loaded.joint_slopes("sagittal", {"q2": q2}).curvature[1] == pytest.approx(1.0, rel=1e-6)


def test_moment_arms_are_per_joint_radian(tmp_path):
    """A muscle's moment arm about joint j per joint radian is OpenSim's (per coordinate) over the slope,
    dl/dtheta_j = (dl/dq_j) / s_j: what the global muscles' certificate reads."""
    path = build(tmp_path / "muscled.osim", muscle=True)
    mapping = tmp_path / "muscled.toml"
    mapping.write_text(MAPPING)
    loaded = anatomy.load(path, mapping)
    _, _, lin = loaded.chains("sagittal")
    model = osim.Model(str(path))
    model.updConstraintSet().get(0).set_isEnforced(False)
    state = model.initSystem()
    muscle = model.getMuscles().get(0)
    arms = [-muscle.computeMomentArm(state, model.getCoordinateSet().get(f"q{k + 1}")) for k in range(3)]
    assert np.all(np.abs(arms) > 1e-3)
    np.testing.assert_allclose(lin.moment_arms[0, :3], np.array(arms) / SLOPES, rtol=1e-9)


def test_a_model_without_muscles_answers_its_passive_chain_with_the_slopes_shown(tiny, capsys):
    """An .osim without muscles (as Christophy's skeleton) is its passive chain: springs, gravity and the
    stiffness added; the table and the JSON show each joint's rotation per coordinate radian where it is not 1."""
    path, mapping, _ = tiny
    assert main(["anatomy", str(path), "--mapping", str(mapping), "--joint-stiffness", "20", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["joint_rad_per_coordinate_rad"] == pytest.approx(list(SLOPES), rel=1e-12)
    assert doc["muscles"] == {"global": [], "local": [], "between": [], "non-lumbar": []}
    assert doc["chain_stable"] is True
    assert doc["joint_stiffness_Nm_per_rad"] == [20.0] * 3
    assert main(["anatomy", str(path), "--mapping", str(mapping)]) == 0
    assert "the joints turn q1 0.5, q2 1, q3 0.25 rad per coordinate rad" in capsys.readouterr().out


def test_a_chain_coordinate_that_turns_no_joint_is_refused_in_one_line(tmp_path, capsys):
    """A mapping that puts a translation (a SliderJoint's coordinate) in the chain has no joint angle there:
    one line naming the coordinate, exit 2, nothing on stdout."""
    path = build(tmp_path / "slid.osim", slider=True)
    mapping = tmp_path / "slid.toml"
    mapping.write_text(MAPPING.replace('"q3"]', '"s4_coord_0"]'))
    assert main(["anatomy", str(path), "--mapping", str(mapping)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "spinectl: error: tiny: chain coordinate(s) ['s4_coord_0'] turn no joint" in captured.err
    assert len(captured.err.strip().splitlines()) == 1


def test_myotorsos_coordinates_are_its_joint_angles(torso):
    """MuJoCo's hinges turn 1 rad per rad: the chains are the engine's own, and the JSON has no slopes."""
    assert torso.joint_slopes("sagittal").is_identity()
    assert "joint_rad_per_coordinate_rad" not in analyse(torso).to_dict()


CHRISTOPHY_MAPPING = (
    '[bodies]\npelvis = ["sacrum"]\nvertebrae = ["lumbar5", "lumbar4", "lumbar3", "lumbar2", "lumbar1"]\n'
    'thorax = ["torso"]\n[planes]\nsagittal = ["flex_extension", "L4_L5_FE", "L3_L4_FE", "L2_L3_FE", "L1_L2_FE"]\n'
)


@pytest.mark.skipif(not CHRISTOPHY.is_file(), reason=ABSENT)
def test_christophys_skeleton_turns_l5s1_by_its_transforms_slope_and_answers_its_passive_chain(tmp_path):
    """Christophy's skeleton as distributed: each chain joint's measured rotation per coordinate rad is its
    SpatialTransform's rotation1 function's derivative read through OpenSim's API (0.125 at L5/S1 for
    flex_extension, which also drives L4/L5..L1/L2 through couplers; 1 at L1/L2 in this file), and the model,
    which has no muscles, answers its passive chain, 50 N m/rad added as 50 per joint radian."""
    mapping = tmp_path / "christophy.toml"
    mapping.write_text(CHRISTOPHY_MAPPING)
    loaded = anatomy.load(CHRISTOPHY, mapping)
    model = loaded.engine.model
    x = osim.Vector(1, 0.0)
    orders = osim.StdVectorInt()
    orders.append(0)
    transforms = []
    for name in loaded.plane_joints("sagittal"):
        joint = osim.CustomJoint.safeDownCast(model.getCoordinateSet().get(name).getJoint())
        transforms.append(joint.getSpatialTransform().getTransformAxis(0).getFunction().calcDerivative(orders, x))
    slopes = loaded.joint_slopes("sagittal").slopes
    np.testing.assert_allclose(slopes, transforms, rtol=1e-12)
    assert slopes[0] == pytest.approx(0.125) and slopes[-1] == pytest.approx(1.0)
    free0, _, _ = loaded.chains("sagittal")
    result = analyse(loaded, joint_stiffness=50.0)
    assert result.to_dict()["joint_rad_per_coordinate_rad"] == pytest.approx(list(transforms))
    np.testing.assert_allclose(result.free.stiffness - free0.stiffness_offset, -50.0 * np.eye(5), atol=1e-9)


def _composite(q0_posture: float):
    """A rhythm over three coordinates (q1 = 0.3 q0 + 0.2 q0^2 on the chain, q2 = 0.5 q0 off it) and a chain of two
    joints that turn nonlinearly (theta0 = q0 + 0.4 q0^2, theta1 = 0.7 q1 + 0.1 q1^2): the Rhythm and JointSlopes
    at q0, and theta(theta0) in closed form, the reference."""
    from spinectl.anatomy.joint_angles import JointSlopes
    from spinectl.anatomy.linearise import Rhythm

    q0 = q0_posture
    q1 = 0.3 * q0 + 0.2 * q0**2
    rhy = Rhythm((0,), (0, 1, 2), np.array([[1.0], [0.3 + 0.4 * q0], [0.5]]), np.array([[0.0], [0.4], [0.0]]))
    slopes = JointSlopes(np.diag([1 + 0.8 * q0, 0.7 + 0.2 * q1]), np.array([0.8, 0.2]))

    def angles(theta0):
        q = (-1 + np.sqrt(1 + 1.6 * theta0)) / 0.8  # q0 of theta0
        dep = 0.3 * q + 0.2 * q**2
        return np.array([theta0, 0.7 * dep + 0.1 * dep**2, 0.5 * q])

    return rhy, slopes, angles, q0 + 0.4 * q0**2


def test_the_rhythm_in_joint_angles_is_the_composite_maps_derivatives():
    """T_theta and its curvature are the first and second derivatives of theta(theta_ind), the rhythm composed with
    the joints' curved transforms, by central differences of the closed form (the off-chain coordinate as it is)."""
    from spinectl.anatomy.joint_angles import rhythm_in_angles

    rhy, slopes, angles, theta0 = _composite(0.1)
    ours = rhythm_in_angles(rhy, slopes)
    h = 1e-4
    first = (angles(theta0 + h) - angles(theta0 - h)) / (2 * h)
    second = (angles(theta0 + h) - 2 * angles(theta0) + angles(theta0 - h)) / h**2
    np.testing.assert_allclose(ours.transform[:, 0], first, rtol=1e-7)
    np.testing.assert_allclose(ours.curvature[:, 0], second, rtol=1e-5, atol=1e-6)


def test_a_joint_turned_by_several_coordinates_is_linear_or_refused():
    """A full Jacobian S (joint 0 turned by q0 and q1) is a linear change of variables, K_theta = W^T K W with
    W = S^-1 exactly; with a curved transform as well it is refused in one line (the curvature of a joint turned by
    several coordinates is not taken)."""
    from spinectl.anatomy.joint_angles import JointSlopes, linearisation_in_angles
    from spinectl.anatomy.linearise import Linearisation
    from spinectl.errors import ModelError

    rng = np.random.default_rng(3)
    k = rng.normal(size=(2, 2))
    k = k + k.T
    lin = Linearisation(
        (0, 1), 2, np.zeros((2, 2, 0)), k, np.zeros((2, 2, 0)), np.zeros((2, 2)), np.eye(2),
        np.zeros((2, 0)), np.array([1.0, -2.0]), np.zeros((0, 2)),
    )  # fmt: skip
    jacobian = np.array([[0.5, 0.2], [0.0, 1.0]])
    w = np.linalg.inv(jacobian)
    ours = linearisation_in_angles(lin, JointSlopes(jacobian, np.zeros(2)))
    np.testing.assert_allclose(ours.stiffness_offset, w.T @ k @ w, rtol=1e-14)
    np.testing.assert_allclose(ours.torque_offset, w.T @ np.array([1.0, -2.0]), rtol=1e-14)
    with pytest.raises(ModelError, match="several chain coordinates and not linearly"):
        linearisation_in_angles(lin, JointSlopes(jacobian, np.array([0.1, 0.0])))


def test_a_model_with_couplers_loads_after_an_optimum_has_imported_cvxpy(tiny):
    """A user who solves an optimum first (cvxpy and its SWIG-built solvers imported before opensim) then loads
    an .osim with a coupler: OpenSim's Function.calcDerivative refused an opensim.StdVectorInt as its argument 2
    in that import order (a TypeError); the coupler's slope read through the model is still COUPLING. A fresh
    process, since the import order is the process's."""
    path, mapping, _ = tiny
    code = (
        "import cvxpy, sys\n"
        "from spinectl.anatomy import load\n"
        f"anatomy = load({str(path)!r}, {str(mapping)!r})\n"
        "slopes, _ = anatomy.engine.couplers[0].derivatives({}, anatomy.engine)\n"
        "print(float(slopes[0]))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.split()[-1]) == pytest.approx(COUPLING, rel=1e-12)
