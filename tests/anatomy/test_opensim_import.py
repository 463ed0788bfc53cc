"""``.osim`` import with OpenSim as the engine, on spinectl's own export of the paper's chain.

OpenSim computes everything on the import's side (spinectl.anatomy.opensim_engine); spinectl's
side is docs/chain.md's matrices (spinectl.model.chain). Where the curves are the same (geometry,
masses, gravity) the chains agree to rounding; the muscles are Millard's in OpenSim, and the
tests derive the difference from Millard's curve values (OpenSim's calcValue / calcDerivative).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from shared_models import ABSENT, POSE2SIM  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.export_mjcf import fibre_gains  # noqa: E402
from spinectl.anatomy.export_osim import REFERENCE_PCSA_CM2, TENDON_SLACK_RATIO, export_osim  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.model import chain  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402
from spinectl.units import M2_PER_CM2  # noqa: E402

E, LAMBDA = 0.03, 0.04
REVERSED = slice(None, None, -1)  # the mapping's chain runs L5S1 up, spinectl's top down


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    """The wagner2012 preset exported as .osim and imported back: (model, anatomy, free chain, linearisation, path)."""
    model = load_preset("wagner2012")
    path = tmp_path_factory.mktemp("osim") / "chain.osim"
    export_osim(model, E, LAMBDA, path)
    loaded = anatomy.load(path)
    free, _, lin = loaded.chains("sagittal")
    return model, loaded, free, lin, path


def test_geometry_masses_and_gravity_are_the_chains(imported):
    """Moment arms (dl/dq), M and K_0 (gravity, no passive stiffness in the preset) equal chain_coefficients'
    length_gradient, mass_matrix and K_g to 1e-9 (K_0 by central differences of OpenSim's torques: 1e-8)."""
    model, loaded, free, lin, _ = imported
    coefficients = chain.chain_coefficients(model, E, LAMBDA)
    mass = chain.mass_matrix(model, chain.geometry.cor_positions(E, LAMBDA, model.geometry))
    assert loaded.classes == ("global",) * 30
    assert np.max(np.abs(lin.moment_arms[:, REVERSED] - coefficients.length_gradient)) <= 1e-9 * 0.1
    np.testing.assert_allclose(free.mass_matrix[REVERSED, REVERSED], mass, rtol=1e-9, atol=1e-12)
    k0 = coefficients.stiffness(np.zeros(6))
    assert np.max(np.abs(free.stiffness_offset[REVERSED, REVERSED] - k0)) <= 1e-8 * np.max(np.abs(k0))


def _millard_values(path, model):
    """Millard's active force-length value and slope [1/m], force-velocity slope [s/m], at the upright fibre length."""
    built = osim.Model(str(path))
    muscle = osim.Millard2012EquilibriumMuscle.safeDownCast(built.getMuscles().get(0))
    l_opt = muscle.getOptimalFiberLength()
    lengths = fibre_gains(model).length
    lt = lengths[0] * (1 - TENDON_SLACK_RATIO) / l_opt
    active, fv = muscle.getActiveForceLengthCurve(), muscle.getForceVelocityCurve()
    v_unit = l_opt * muscle.getMaxContractionVelocity()
    return active.calcValue(lt), active.calcDerivative(lt, 1) / l_opt, fv.calcDerivative(0.0, 1) / v_unit


def test_muscle_matrices_differ_by_millards_curves_exactly(imported):
    """Per fibre of the first muscle (straight_ventral), OpenSim's K_i and D_i are spinectl's with
    Millard's curve values:

    spinectl per unit f_iso: D = f_l f_H' h h', K = -f_l' h h' - f_l H (docs/chain.md), so from spinectl's K and D
    of the fibre sum, Sigma h h' = D / (f_l f_H') and Sigma H = -(K + f_l' Sigma h h') / f_l; OpenSim per unit
    activation: F_max (-f_AL' Sigma h h' - f_AL Sigma H) and F_max f_AL (-f_V') Sigma h h' (v lengthening)."""
    model, loaded, free, lin, path = imported
    f_al, f_al_slope, f_v_slope = _millard_values(path, model)
    fibres = fibre_gains(model)
    f_iso = model.fibre.specific_tension / 5  # per m^2 of the muscle, per fibre
    f_l = fibres.force[0] / f_iso
    f_l_slope = fibres.length_slope[0] / f_iso
    f_h_slope = fibres.velocity_slope[0] / fibres.force[0]
    coefficients = chain.chain_coefficients(model, E, LAMBDA)
    k_sp = coefficients.stiffness_per_pcsa[..., 0] / f_iso  # sum over the 5 fibres, per unit f_iso of each
    d_sp = coefficients.damping_per_pcsa[..., 0] / f_iso
    hh = d_sp / (f_l * f_h_slope)
    hessian = -(k_sp + f_l_slope * hh) / f_l
    f_max = model.fibre.specific_tension * REFERENCE_PCSA_CM2 * M2_PER_CM2 / 5
    k_osim = f_max * (-f_al_slope * hh - f_al * hessian)
    d_osim = f_max * f_al * (-f_v_slope) * hh
    k_import = free.stiffness_per_control[REVERSED, REVERSED, :5].sum(axis=-1)
    d_import = free.damping_per_control[REVERSED, REVERSED, :5].sum(axis=-1)
    assert np.max(np.abs(k_import - k_osim)) <= 1e-6 * np.max(np.abs(k_osim))
    # D from central differences of OpenSim's own force in the lengthening speed (spinectl.anatomy.opensim_muscles)
    assert np.max(np.abs(d_import - d_osim)) <= 1e-8 * np.max(np.abs(d_osim))
    assert abs(f_al / f_l - 1) > 0.05  # Millard's curve is not the paper's: the difference is real


def test_cli_analyses_the_osim_and_refuses_unmapped_coordinates(imported, tmp_path, capsys):
    """``spinectl anatomy exported.osim`` prints the verdicts with their criteria; a mapping that names
    coordinates the model lacks is one line, exit 2."""
    _, _, _, _, path = imported
    assert main(["anatomy", str(path)]) == 0
    out = capsys.readouterr().out
    assert "joint by joint (others fixed)" in out and "the chain, free" in out
    mapping = tmp_path / "bad.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["ground"]\nvertebrae = ["vertebra_above_L5S1"]\nthorax = ["thorax"]\n'
        '[planes]\nsagittal = ["L5S1", "L9L10"]\n'
    )
    assert main(["anatomy", str(path), "--mapping", str(mapping)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "L9L10" in err


def test_opensims_simulation_grows_at_the_rate_the_imported_chain_predicts(imported):
    """OpenSim's own forward simulation (Manager.integrate, accuracy 1e-10) of the exported model, displaced
    1e-5 rad along the imported chain's fastest growing mode, grows at that mode's eigenvalue to 5 %.

    The chain is linearised at OpenSim's activations (Millard floors them at 0.01, so the optimum's idle
    muscles are at 0.01 there), and the file's counter torques hold the posture against OpenSim's forces
    (export_osim.opensim_counter_torque): the posture is an equilibrium, so the growth is the mode's.
    """
    _, loaded, free, _, path = imported
    model = osim.Model(str(path))
    state = model.initSystem()
    model.equilibrateMuscles(state)
    model.realizeDynamics(state)
    muscles = model.getMuscles()
    act = np.array([muscles.get(i).getActivation(state) for i in range(muscles.getSize())])
    values, vectors = np.linalg.eig(chain.state_matrix(free.mass_matrix, free.stiffness(act), free.damping(act)))
    top = np.argmax(values.real)
    rate, mode = values[top].real, np.real(vectors[:, top])
    mode = mode / np.linalg.norm(mode[:5])
    coords = model.getCoordinateSet()
    for k, name in enumerate(free.joints):
        coords.get(name).setValue(state, 1e-5 * mode[k], False)
        coords.get(name).setSpeedValue(state, 1e-5 * mode[5 + k])
    manager = osim.Manager(model)
    manager.setIntegratorAccuracy(1e-10)
    manager.initialize(state)
    times = 0.001 * np.arange(1, 51)
    amplitude = []
    for time in times:
        s = manager.integrate(float(time))
        amplitude.append(abs(np.array([coords.get(n).getValue(s) for n in free.joints]) @ mode[:5]))
    fitted = np.polyfit(times, np.log(amplitude), 1)[0]
    assert rate > 0 and abs(fitted - rate) <= 0.05 * rate


SLOPE = 0.5  # the test coupler: L1L2 = SLOPE * L2L3


@pytest.fixture(scope="module")
def coupled(imported, tmp_path_factory):
    """spinectl's export with a CoordinateCouplerConstraint (built with OpenSim's API) tying L1L2 = 0.5 L2L3."""
    path = tmp_path_factory.mktemp("coupled") / "coupled.osim"
    built = osim.Model(str(imported[4]))
    coupler = osim.CoordinateCouplerConstraint()
    coupler.setName("rhythm_L1L2")
    independent = osim.ArrayStr()
    independent.append("L2L3")
    coupler.setIndependentCoordinateNames(independent)
    coupler.setDependentCoordinateName("L1L2")
    coupler.setFunction(osim.LinearFunction(SLOPE, 0.0))
    built.addConstraint(coupler)
    built.finalizeConnections()
    built.printToXML(str(path))
    return path


def test_couplers_are_off_in_the_free_chain_and_reduce_the_constrained_one(imported, coupled):
    """With the coupler, the free chain is the uncoupled export's chain (to rounding), and the constrained chain is
    T^T K T, T^T D T, T^T M T of it in closed form, T = dq/dq_ind: the identity on L5S1..L2L3 plus the row
    L1L2 = 0.5 L2L3 (a linear function: no curvature term). The source line names the coupler and its slope."""
    _, _, free0, _, _ = imported
    loaded = anatomy.load(coupled)
    free, constrained, _ = loaded.chains("sagittal")
    a = np.full(free.n_controls, 0.3)
    np.testing.assert_allclose(free.stiffness(a), free0.stiffness(a), rtol=1e-9, atol=1e-9)
    T = np.zeros((5, 4))
    T[:4, :4] = np.eye(4)
    T[4, 3] = SLOPE  # the chain runs L5S1, L4L5, L3L4, L2L3, L1L2
    assert free.joints[3:] == ("L2L3", "L1L2") and constrained.joints == free.joints[:4]
    for ours, full in ((constrained.stiffness(a), free.stiffness(a)), (constrained.damping(a), free.damping(a))):
        np.testing.assert_allclose(ours, T.T @ full @ T, rtol=1e-12, atol=1e-12 * np.max(np.abs(full)))
    np.testing.assert_allclose(constrained.mass_matrix, T.T @ free.mass_matrix @ T, rtol=1e-12, atol=1e-15)
    assert "rhythm_L1L2 (L1L2 on L2L3 slope 0.5)" in free.source


def test_the_cli_names_the_couplers_with_their_slopes(coupled, capsys):
    """`spinectl anatomy coupled.osim` prints the coupler, the coordinate it slaves and its slope, and the chain
    constrained by it in the independent coordinates."""
    assert main(["anatomy", str(coupled)]) == 0
    out = capsys.readouterr().out
    assert "rhythm_L1L2 (L1L2 on L2L3 slope 0.5)" in out and "(4 coordinate(s): L5S1, L4L5, L3L4, L2L3)" in out


def test_the_coupled_coordinate_moves_in_opensim_as_the_reduction_says(imported, coupled):
    """OpenSim's own simulation (Manager.integrate) of the coupled file, started with L2L3 moving: L1L2 follows
    at the slope the import reads off the coupler's function (its T), to the integrator's accuracy."""
    loaded = anatomy.load(coupled)
    slope = loaded.linearise("sagittal")[1].transform[4, 3]
    model = osim.Model(str(coupled))
    state = model.initSystem()
    coords = model.getCoordinateSet()
    coords.get("L2L3").setSpeedValue(state, 0.1)
    coords.get("L1L2").setSpeedValue(state, 0.1 * SLOPE)
    manager = osim.Manager(model)
    manager.setIntegratorAccuracy(1e-10)
    manager.initialize(state)
    state = manager.integrate(0.02)
    moved = coords.get("L2L3").getValue(state)
    assert abs(moved) > 1e-4
    assert abs(coords.get("L1L2").getValue(state) - slope * moved) <= 1e-6 * abs(moved)


@pytest.fixture(scope="module")
def lowest_joint(imported, tmp_path_factory):
    """The export mapped onto a chain of its lowest joint alone (L5S1; the others held): a posture its muscles
    hold without the file's counter torques. The full chain's does not (test_upright_optimum_is_infeasible...)."""
    mapping = tmp_path_factory.mktemp("lowest") / "lowest.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["ground"]\nthorax = ["thorax"]\nvertebrae = ["vertebra_above_L2L3", '
        '"vertebra_above_L3L4", "vertebra_above_L4L5", "vertebra_above_L5S1"]\n[planes]\nsagittal = ["L5S1"]\n'
    )
    return anatomy.load(imported[4], mapping)


def test_optimum_on_opensims_chain_is_the_least_effort_and_stable(lowest_joint):
    """`optimised` on an .osim: the classic optimum's cost equals SciPy's SLSQP on the same problem (min sum w a^2,
    OpenSim's torques tau_per a + tau_0 = 0 on the chain, Millard's floor 0.01 <= a <= 1) to 1e-4; the chain optimum
    holds the
    posture (net torque <= 1e-6 of the gravity torque), its free chain has -K >= mu, and it costs at least the
    classic one."""
    from scipy.optimize import minimize

    from spinectl.anatomy.optimum import optimised, volume_weights

    result = optimised(lowest_joint, equilibrium="free", margin=1.0)
    _, _, lin = lowest_joint.chains()
    tau_per, tau_0 = lin.torque_per_muscle[:1], lin.torque_offset[:1]
    w = volume_weights(lowest_joint)
    ref = minimize(
        lambda a: w @ a**2,
        np.full(w.size, 0.01),
        jac=lambda a: 2 * w * a,
        method="SLSQP",
        bounds=[(0.01, 1)] * w.size,  # Millard's minimum_activation, OpenSim's default
        constraints={"type": "eq", "fun": lambda a: tau_per @ a + tau_0, "jac": lambda a: tau_per},
        options={"ftol": 1e-14, "maxiter": 500},
    )
    assert ref.success and result.classic.ok and result.optimum.ok
    assert abs(result.classic.cost - ref.fun) <= 1e-4 * ref.fun
    assert np.max(np.abs(result.optimum.net_torque)) <= 1e-6 * np.max(np.abs(tau_0))
    assert np.min(result.optimum.eigenvalues) >= 1.0 - 1e-4
    assert result.optimum.cost >= result.classic.cost * (1 - 1e-6)


def test_upright_optimum_is_infeasible_and_check_is_refused(imported, capsys):
    """The upright export without its counter torques: no activations in [0.01, 1] hold it (SciPy's bounded least
    squares leaves a residual > 1 N m), so `spinectl anatomy chain.osim --optimise` answers infeasible (exit 0);
    `--check` (MuJoCo's referee) is one line, exit 2."""
    from scipy.optimize import lsq_linear

    _, _, _, lin, path = imported
    fit = lsq_linear(lin.torque_per_muscle[:5], -lin.torque_offset[:5], bounds=(0.01, 1))
    assert np.linalg.norm(lin.torque_per_muscle[:5] @ fit.x + lin.torque_offset[:5]) > 1.0
    assert main(["anatomy", str(path), "--optimise", "--equilibrium", "free"]) == 0
    assert "infeasible" in capsys.readouterr().out
    assert main(["anatomy", str(path), "--check"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "MJCF" in err


def test_schema_versions_older_are_reported_and_newer_refused(imported, tmp_path, capsys):
    """The file's OpenSim schema (its Version attribute, OpenSim's getDocumentFileVersion): an older one is read
    as OpenSim upgrades it, and the chain's source says so; one newer than this OpenSim's, or one OpenSim cannot
    read, is one line, exit 2."""
    text = imported[4].read_text()
    current = osim.Model(str(imported[4])).getDocumentFileVersion()
    assert f'Version="{current}"' in text
    files = {}
    for version in (current - 1, current + 10000, 20000):
        files[version] = tmp_path / f"v{version}.osim"
        files[version].write_text(text.replace(f'Version="{current}"', f'Version="{version}"', 1))
    free, _, _ = anatomy.load(files[current - 1]).chains()
    assert f"(schema {current - 1}, upgraded by OpenSim {osim.__version__} to {current})" in free.source
    for version in (current + 10000, 20000):  # 20000: OpenSim's 2.x upgrade cannot read a 4.x document
        assert main(["anatomy", str(files[version])]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(files[version].name) in err


def test_a_wrap_touched_at_the_posture_is_named_and_refused(imported, tmp_path, capsys):
    """A WrapCylinder (OpenSim's API) tangent to straight_ventral_0's path at the upright posture: the path wraps
    on one side of L5S1 = 0 only (OpenSim's current path has 4 points there, 2 on the other), so its moment arm
    has a kink at the posture. `spinectl anatomy` names the muscle, the wrap and the coordinate: one line, exit 2."""
    built = osim.Model(str(imported[4]))
    state = built.initSystem()
    path = built.getMuscles().get(0).getGeometryPath()
    points = path.getPathPointSet()
    top, bottom = (np.array(points.get(k).getLocationInGround(state).to_numpy()) for k in range(2))
    along = (bottom - top) / np.linalg.norm(bottom - top)
    radius = 0.01
    cylinder = osim.WrapCylinder()
    cylinder.setName("belly")
    cylinder.set_radius(radius)
    cylinder.set_length(0.2)
    cylinder.set_translation(osim.Vec3(*(0.5 * (top + bottom) + radius * np.array([-along[1], along[0], 0.0]))))
    built.updGround().addWrapObject(cylinder)
    path.addPathWrap(cylinder)
    built.finalizeConnections()
    out = tmp_path / "wrapped.osim"
    built.printToXML(str(out))
    assert main(["anatomy", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "straight_ventral_0" in err and "belly" in err and "L5S1" in err


def test_an_infeasible_equilibrium_is_named_with_its_residual(imported, capsys):
    """`spinectl anatomy chain.osim --optimise`: the classic optimum (no stability criterion) is infeasible too,
    so the table names the equilibrium, not stiffness, and prints the bounded least-squares residual of the net
    torque, SciPy's lsq_linear over [0.01, 1] (Millard's activation floor) on the same equilibrium rows
    (docs/interchange.md: 10.5 N m); the JSON
    says `infeasible_constraint` "equilibrium" and keeps the analysis's keys (nulls with their reasons)."""
    import json

    from scipy.optimize import lsq_linear

    _, _, _, lin, path = imported
    fit = lsq_linear(lin.torque_per_muscle[:5], -lin.torque_offset[:5], bounds=(0.01, 1))
    residual = np.linalg.norm(lin.torque_per_muscle[:5] @ fit.x + lin.torque_offset[:5])
    assert abs(residual - 10.5) <= 0.05
    assert main(["anatomy", str(path), "--optimise"]) == 0
    out = capsys.readouterr().out
    assert "the equilibrium fails" in out and f"{residual:.3g} N m" in out and "no stiffness" not in out
    assert main(["anatomy", str(path), "--optimise", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["infeasible_constraint"] == "equilibrium"
    assert doc["classic"]["equilibrium_residual_Nm"] == pytest.approx(residual, rel=1e-6)
    assert doc["eigenvalues"] is None and doc["eigenvalues_reason"] == "not_computed" and "constrained" in doc


def test_a_file_that_is_not_xml_gives_opensims_reason_on_one_line(tmp_path, capsys):
    """A .osim that is not XML: OpenSim's exception spans several lines, the reason (Simbody's "The given Node
    was not an Element") after the first; `spinectl anatomy` keeps it on its one line (exit 2), the C++ wrapper's
    "std::exception in ..." prefix dropped."""
    bad = tmp_path / "bad.osim"
    bad.write_text("not xml at all\n")
    assert main(["anatomy", str(bad)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert "bad.osim" in captured.err and "not an Element" in captured.err and "std::exception" not in captured.err


def test_the_help_names_osim_files(capsys):
    """`spinectl anatomy --help` names the three kinds of model the positional takes: myotorso, MJCF and .osim."""
    assert main(["anatomy", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "'myotorso', an MJCF file or an OpenSim .osim file" in out


def _run(*args):
    """`python -m spinectl ARGS` in a subprocess: OpenSim's C++ logger writes to the process's file descriptor 1,
    which capsys does not see."""
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "spinectl", *args], capture_output=True, text=True, check=False)


def test_opensims_warnings_of_missing_meshes_stay_off_the_json(imported, tmp_path):
    """A body with a mesh file that is absent (as in a downloaded model without its Geometry folder, added with
    OpenSim's API): OpenSim warns `Couldn't find file 'absent_mesh.vtp'` as it builds the model. `anatomy --json`
    prints a JSON document alone on stdout, the warning on stderr (before: the warning was stdout's first line)."""
    built = osim.Model(str(imported[4]))
    built.getBodySet().get(0).attachGeometry(osim.Mesh("absent_mesh.vtp"))
    built.finalizeConnections()
    out = tmp_path / "meshed.osim"
    built.printToXML(str(out))
    result = _run("anatomy", str(out), "--json")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["plane"] == "sagittal"
    assert "absent_mesh.vtp" in result.stderr and "absent_mesh.vtp" not in result.stdout


SHARED = POSE2SIM


@pytest.mark.skipif(not SHARED.is_file(), reason=ABSENT)
def test_a_downloaded_model_without_meshes_prints_nothing_but_spinectls_own(tmp_path):
    """The Pose2Sim model as distributed, without its Geometry folder: OpenSim warns about about a hundred missing
    meshes; stdout holds the JSON document alone (its De Groote muscles are read, spinectl.anatomy.opensim_muscles;
    before: refused in one line), and the warnings are on stderr."""
    mapping = tmp_path / "p2s.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["sacrum", "pelvis"]\nvertebrae = ["lumbar5", "lumbar4", "lumbar3", "lumbar2", "lumbar1"]\n'
        'thorax = ["torso"]\n[planes]\nsagittal = ["L5_S1_Flex_Ext", "L4_L5_Flex_Ext", "L3_L4_Flex_Ext", '
        '"L2_L3_Flex_Ext", "L1_L2_Flex_Ext"]\n'
    )
    result = _run("anatomy", str(SHARED), "--mapping", str(mapping), "--json")
    assert result.returncode == 0, result.stderr[-300:]
    assert json.loads(result.stdout)["model"]["name"] == "Pose2Sim_WithMusclesAndConstraints"
    assert "Couldn't find file" in result.stderr and "Couldn't find file" not in result.stdout


def test_opensims_model_meets_the_engine_contract(imported):
    """OsimAnatomy is an AnatomyEngine (runtime_checkable: every member of the contract present), and no
    longer a MuJoCo Anatomy (whose MuJoCo-only methods it inherited before the contract)."""
    from spinectl.anatomy.contract import AnatomyEngine
    from spinectl.anatomy.model import Anatomy

    assert isinstance(imported[1], AnatomyEngine) and not isinstance(imported[1], Anatomy)


def test_the_osim_is_drawn_as_mujoco_draws_the_same_export(imported, tmp_path):
    """The figures' points of the .osim export (OpenSim's joint centres, thorax mass centre, muscles' current
    paths, its plane from gravity and the first joint's turning axis) equal those MuJoCo computes on the MJCF
    export of the same model, to 1e-12 m: at the posture and bent along each mode of the MJCF's free chain
    (before: `anatomy chain.osim --plot` raised a TypeError from MuJoCo's kinematics given OpenSim's model)."""
    from spinectl.anatomy.analyses import verdict
    from spinectl.anatomy.drawing import mode_shapes, sagittal_projection
    from spinectl.anatomy.export_mjcf import export_mjcf

    pytest.importorskip("mujoco", reason="MuJoCo is the referee: pip install 'spinectl[anatomy]'")
    model, loaded, *_ = imported
    export_mjcf(model, E, LAMBDA, tmp_path / "chain.xml")
    referee = anatomy.load(tmp_path / "chain.xml", cache=False)
    ours, theirs = sagittal_projection(loaded), sagittal_projection(referee)
    assert ours.muscles == theirs.muscles and ours.joints == theirs.joints
    for name in ("cors", "thorax"):  # projected: the two worlds' axes differ (OpenSim's y up, MuJoCo's z up)
        assert np.allclose(getattr(ours, name), getattr(theirs, name), rtol=0, atol=1e-12), name
    for mine, other in zip(ours.segments, theirs.segments, strict=True):
        assert len(mine) == len(other) == 1 and np.allclose(mine[0], other[0], rtol=0, atol=1e-12)
    at = verdict(referee.chain("sagittal"), np.full(len(referee.muscles), 0.05))
    bent, expected = mode_shapes(loaded, at), mode_shapes(referee, at)
    assert np.allclose(bent.rest, expected.rest, rtol=0, atol=1e-12)
    assert np.allclose(bent.bent, expected.bent, rtol=0, atol=1e-12)
