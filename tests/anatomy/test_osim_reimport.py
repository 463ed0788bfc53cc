"""spinectl's ``.osim`` export imported back at its solution, a lordosis along OpenSim couplers, and bad input.

OpenSim computes the import's side (spinectl.anatomy.opensim_engine); spinectl's side is docs/chain.md's
chain (spinectl.model.chain). The muscles are Millard's in OpenSim, so the chain at the solution is
spinectl's with Millard's curve values in place of the paper's: the tests derive that chain from
OpenSim's own curves (calcValue / calcDerivative) and spinectl's geometry.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.export_mjcf import fibre_gains  # noqa: E402
from spinectl.anatomy.export_osim import REFERENCE_PCSA_CM2, TENDON_SLACK_RATIO, export_osim  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.model import chain  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402
from spinectl.units import M2_PER_CM2  # noqa: E402

E, LAMBDA = 0.03, 0.04
REVERSED = slice(None, None, -1)  # the mapping's chain runs L5S1 up, spinectl's top down
SLOPES = {"L4L5": 0.9, "L3L4": 0.8, "L2L3": 0.7, "L1L2": 0.6}  # the test rhythm: each joint = slope * L5S1


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The wagner2012 preset exported as .osim, and the same model with couplers slaving L4L5 ... L1L2 to L5S1
    (OpenSim's CoordinateCouplerConstraint, LinearFunction: a lumbar rhythm as Christophy's model has)."""
    model = load_preset("wagner2012")
    folder = tmp_path_factory.mktemp("osim")
    path = folder / "chain.osim"
    solution = export_osim(model, E, LAMBDA, path)
    built = osim.Model(str(path))
    for dependent, slope in SLOPES.items():
        coupler = osim.CoordinateCouplerConstraint()
        coupler.setName(f"rhythm_{dependent}")
        independent = osim.ArrayStr()
        independent.append("L5S1")
        coupler.setIndependentCoordinateNames(independent)
        coupler.setDependentCoordinateName(dependent)
        coupler.setFunction(osim.LinearFunction(slope, 0.0))
        built.addConstraint(coupler)
    built.finalizeConnections()
    coupled = folder / "rhythm.osim"
    built.printToXML(str(coupled))
    return model, solution, path, coupled


def test_the_chain_at_the_solution_is_spinectls_with_millards_curves(exported):
    """The re-imported .osim's K and D at the exported activations (each fibre's muscle PCSA / 100 cm^2) equal
    spinectl's chain with each muscle's paper curves replaced by Millard's, to 1e-6 relative:

    spinectl per fibre and unit f_iso (docs/chain.md): K = -f_l' h h' - f_l H, D = f_l f_H' h h'; a muscle's fibres
    share one upright length, so its Sigma h h' = D_m / (f_l f_H') and Sigma H = -(K_m + f_l' Sigma h h') / f_l from
    chain_coefficients; OpenSim's per unit activation: F_max (-f_AL' Sigma h h' - f_AL Sigma H) and
    F_max f_AL (-f_V') Sigma h h', f_AL, f_V Millard's (OpenSim's calcValue / calcDerivative). K_0 is spinectl's
    (gravity; the passive curve is 0 below the optimal length). The difference from spinectl's own K is real:
    more than 1 % here."""
    model, solution, path, _ = exported
    loaded = anatomy.load(path)
    free, _, _ = loaded.chains("sagittal")
    fibres = fibre_gains(model)
    coefficients = chain.chain_coefficients(model, E, LAMBDA)
    built = osim.Model(str(path))
    k_expected = coefficients.stiffness(np.zeros(len(model.muscle_names)))
    d_expected = np.zeros_like(k_expected)
    for m in range(len(model.muscle_names)):
        first = int(np.flatnonzero(fibres.muscle == m)[0])
        share = int(np.sum(fibres.muscle == m))
        muscle = osim.Millard2012EquilibriumMuscle.safeDownCast(built.getMuscles().get(first))
        l_opt, v_unit = (
            muscle.getOptimalFiberLength(),
            muscle.getOptimalFiberLength() * muscle.getMaxContractionVelocity(),
        )
        lt = fibres.length[first] * (1 - TENDON_SLACK_RATIO) / l_opt
        active, fv = muscle.getActiveForceLengthCurve(), muscle.getForceVelocityCurve()
        f_al, f_al_slope, f_v_slope = (
            active.calcValue(lt),
            active.calcDerivative(lt, 1) / l_opt,
            fv.calcDerivative(0.0, 1) / v_unit,
        )
        f_iso = model.fibre.specific_tension / share  # per m^2 of the muscle, per fibre
        f_l, f_l_slope = fibres.force[first] / f_iso, fibres.length_slope[first] / f_iso
        f_h_slope = fibres.velocity_slope[first] / fibres.force[first]
        hh = coefficients.damping_per_pcsa[..., m] / f_iso / (f_l * f_h_slope)
        hessian = -(coefficients.stiffness_per_pcsa[..., m] / f_iso + f_l_slope * hh) / f_l
        f_max = model.fibre.specific_tension * REFERENCE_PCSA_CM2 * M2_PER_CM2 / share
        a = solution.pcsa[m] / (REFERENCE_PCSA_CM2 * M2_PER_CM2)
        k_expected = k_expected + a * f_max * (-f_al_slope * hh - f_al * hessian)
        d_expected = d_expected + a * f_max * f_al * (-f_v_slope) * hh
    a = solution.pcsa[fibres.muscle] / (REFERENCE_PCSA_CM2 * M2_PER_CM2)
    k, d = free.stiffness(a)[REVERSED, REVERSED], free.damping(a)[REVERSED, REVERSED]
    assert np.max(np.abs(k - k_expected)) <= 1e-6 * np.max(np.abs(k_expected))
    assert np.max(np.abs(d - d_expected)) <= 1e-6 * np.max(np.abs(d_expected))
    spinectl_k = solution.stiffness
    assert np.max(np.abs(k - spinectl_k)) > 0.01 * np.max(np.abs(spinectl_k))


def test_the_lordosis_posture_follows_opensims_couplers(exported):
    """lordosis_posture on the coupled .osim moves L5S1 and the coordinates its couplers slave by the couplers'
    slopes, their angles summing to the lordosis. OpenSim is the referee: with the couplers enforced, its own
    constraint errors (State.getQErr after realizePosition) vanish at that posture (1e-12 rad), and not at the
    same lordosis put at L5S1 alone (the check can fail)."""
    from spinectl.anatomy.optimum import lordosis_posture

    *_, coupled = exported
    loaded = anatomy.load(coupled)
    posture = lordosis_posture(loaded, 6.0)
    chain_joints = loaded.plane_joints("sagittal")
    assert abs(sum(posture[n] for n in chain_joints) - np.radians(6.0)) <= 1e-15
    model = osim.Model(str(coupled))
    state = model.initSystem()

    def error(values):
        for name in chain_joints:
            model.getCoordinateSet().get(name).setValue(state, values.get(name, 0.0), False)
        model.realizePosition(state)
        qerr = state.getQErr()
        return max(abs(qerr.get(k)) for k in range(qerr.size()))

    assert error(posture) <= 1e-12
    assert error({"L5S1": np.radians(6.0)}) > 1e-3


def test_cli_lordosis_on_an_osim_is_the_optimum_at_each_posture(exported, capsys):
    """`spinectl anatomy rhythm.osim --lordosis -4:4:3 --json`: the curve's classic cost at each posture equals
    SciPy's SLSQP on the same problem (min sum w a^2, the couplers' independent torque T^T (tau_per a + tau_0) = 0,
    Millard's floor 0.01 <= a <= 1) on OpenSim's linearisation at that posture, to 1e-4; the postures differ (so do
    the costs)."""
    from scipy.optimize import minimize

    from spinectl.anatomy.optimum import lordosis_posture, volume_weights

    *_, coupled = exported
    assert main(["anatomy", str(coupled), "--lordosis", "-4:4:3", "--json"]) == 0
    curve = json.loads(capsys.readouterr().out)["lordosis_curve"]
    assert curve["lordosis_deg"] == [-4.0, 0.0, 4.0]
    loaded = anatomy.load(coupled)
    w = volume_weights(loaded)
    for degrees, cost, status in zip(
        curve["lordosis_deg"], curve["none"]["cost"], curve["none"]["status"], strict=True
    ):
        lin, rhy, _ = loaded.linearise("sagittal", lordosis_posture(loaded, degrees))
        tau_per, tau_0 = rhy.transform.T @ lin.torque_per_muscle, rhy.transform.T @ lin.torque_offset
        ref = minimize(
            lambda a: w @ a**2,
            np.full(w.size, 0.01),
            jac=lambda a: 2 * w * a,
            method="SLSQP",
            bounds=[(0.01, 1)] * w.size,  # Millard's minimum_activation, OpenSim's default
            constraints={"type": "eq", "fun": lambda a, p=tau_per, c=tau_0: p @ a + c, "jac": lambda a, p=tau_per: p},
            options={"ftol": 1e-14, "maxiter": 500},
        )
        assert ref.success and status == "optimal"
        assert abs(cost - ref.fun) <= 1e-4 * ref.fun
    assert len(set(np.round(curve["none"]["cost"], 12))) == 3


def test_lordosis_without_a_rhythm_is_one_line(exported, capsys):
    """The uncoupled export has no coupler tying its chain: a lordosis has no direction to move along, so
    `--lordosis` is one line, exit 2, nothing on standard output."""
    _, _, path, _ = exported
    assert main(["anatomy", str(path), "--lordosis", "-4:4:3"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1 and "rhythm" in captured.err


def test_an_export_whose_controls_would_overwrite_its_config_is_refused(tmp_path, capsys):
    """`spinectl export --out m.osim` writes m_controls.sto beside it: a --config of that name is one line, exit 2,
    the config unchanged and no model written."""
    config = tmp_path / "m_controls.sto"
    config.write_text("")
    out = tmp_path / "m.osim"
    assert main(["export", "--config", str(config), "--E", "0.03", "--Lambda", "0.04", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--config" in err
    assert config.read_text() == "" and not out.exists()


def test_the_default_activations_of_an_export_are_its_prescribed_controls(exported, capsys):
    """`spinectl anatomy chain.osim` analyses the model at its own PrescribedController's controls at t = 0: the
    same -K as the exported activations given explicitly (each fibre's muscle PCSA / 100 cm^2, as the export
    writes them, held at Millard's floor 0.01 as OpenSim holds them) to 1e-12, not activation 0; its -K_jj are
    docs/interchange.md's "chain at the solution" (L1L2 ... L5S1: -54.0, -59.2, -54.8, -40.6, -19.9 N m/rad, to
    0.05), and the header and JSON say where the activations come from."""
    from spinectl.anatomy.analyses import analyse

    model, solution, path, _ = exported
    loaded = anatomy.load(path)
    fibres = fibre_gains(model)
    given = np.maximum(solution.pcsa[fibres.muscle] / (REFERENCE_PCSA_CM2 * M2_PER_CM2), 0.01)
    default, explicit = analyse(loaded, activation=None), analyse(loaded, activation=given)
    assert np.max(np.abs(default.activations - given)) <= 1e-12
    assert np.allclose(default.free.stiffness, explicit.free.stiffness, rtol=0, atol=1e-9)
    documented = [-54.0, -59.2, -54.8, -40.6, -19.9]  # L1L2 ... L5S1
    assert np.allclose(default.free.joint_stiffness[REVERSED], documented, rtol=0, atol=0.05)
    assert "PrescribedController solution" in default.table().splitlines()[0]
    assert main(["anatomy", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert "PrescribedController" in doc["activation_source"] and doc["activation_mean"] > 0
    assert explicit.activation_source == "given"


def test_a_model_without_a_rhythm_says_so(exported, capsys):
    """spinectl's export has no coupler: `spinectl anatomy chain.osim` says the model has no rhythm and gives the
    free chain's verdict only (no "the rhythm removes 0 modes"), its JSON's constrained criterion says so and
    `rhythm` is false; the same export with four couplers (rhythm.osim) still reports the constrained chain, the
    rhythm removing its four dependent coordinates (L4L5 ... L1L2)."""
    *_, path, coupled = exported
    assert main(["anatomy", str(path)]) == 0
    out = capsys.readouterr().out
    assert "the model has no rhythm" in out and "rhythm removes" not in out
    assert main(["anatomy", str(path), "--json"]) == 0
    constrained = json.loads(capsys.readouterr().out)["constrained"]
    assert constrained["rhythm"] is False and constrained["chain_stable_criterion"].startswith("no rhythm")
    assert main(["anatomy", str(coupled)]) == 0
    out = capsys.readouterr().out
    assert "the rhythm removes 4 modes" in out and "no rhythm" not in out
    assert main(["anatomy", str(coupled), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["constrained"]["rhythm"] is True
