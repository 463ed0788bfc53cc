"""OpenSim as the referee of the exported chain's dynamics: its own linearisation and its forward simulation.

OpenSim's side is computed by OpenSim from the written ``.osim``: the linearisation by central differences
of its inverse dynamics at zero acceleration (export_osim.opensim_linearisation; M from calcM), the
replay by ``Manager.integrate``. spinectl's side is docs/chain.md's chain (the PaperSolution's K, D, M and
coupled_stability_at). Two muscle models are exported (export_osim.MUSCLES):

- ``paper``: RigidTendonMuscles with the paper's force-length and force-velocity formulas. OpenSim's
  linearisation is then the chain's, the least local stiffness as joint springs makes every mode decay,
  and without it the chain diverges at spinectl's rates.
- ``millard`` (the default, what ``spinectl anatomy`` re-imports): Millard's curves and activation floor.
  OpenSim's K differs from spinectl's by exactly those (derived here from OpenSim's curve values), and
  spinectl's least local stiffness leaves OpenSim's chain unstable, as its simulation shows; the least
  local stiffness of OpenSim's own K makes it stable.
"""

from __future__ import annotations

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from spinectl.anatomy.export_mjcf import fibre_gains  # noqa: E402
from spinectl.anatomy.export_osim import (  # noqa: E402
    TENDON_SLACK_RATIO,
    export_osim,
    opensim_counter_torque,
    opensim_linearisation,
)
from spinectl.cli import main  # noqa: E402
from spinectl.model import chain, geometry, laws  # noqa: E402
from spinectl.model import muscle as fibre_law  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402

E, LAMBDA = 0.03, 0.04  # a point of docs/chain.md's table ("Dynamic stability"), as the MJCF tests
KINDS = [("paper", False), ("paper", True), ("millard", False), ("millard", True)]
ACCURACY = 1e-8  # Manager's integrator accuracy


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The wagner2012 preset at (E, Lambda) exported four times: each muscle model, without and with the least
    local stiffness; each with OpenSim's linearisation of the written file. (muscle, local) -> (path, solution,
    (f0, K, D, M))."""
    model = load_preset("wagner2012")
    folder = tmp_path_factory.mktemp("replay")
    out = {}
    for muscle, local in KINDS:
        path = folder / f"{muscle}_{int(local)}.osim"
        solution = export_osim(model, E, LAMBDA, path, with_local_stiffness=local, muscle=muscle)
        out[muscle, local] = path, solution, opensim_linearisation(path, model.geometry.cor_names)
    return model, out


def _modes(linearisation):
    """Eigenvalues and eigenvectors of the state matrix [[0, I], [M^-1 K, M^-1 D]] of a linearisation."""
    _, stiffness, damping, mass = linearisation
    return np.linalg.eig(chain.state_matrix(mass, stiffness, damping))


def _replay(path, names, x0, times):
    """OpenSim's forward simulation (Manager.integrate) of the file displaced by x0 = (q, q'): (q, q') at ``times``."""
    model = osim.Model(str(path))
    state = model.initSystem()
    coordinates = model.getCoordinateSet()
    for k, name in enumerate(names):
        coordinates.get(name).setValue(state, float(x0[k]), False)
        coordinates.get(name).setSpeedValue(state, float(x0[len(names) + k]))
    manager = osim.Manager(model)
    manager.setIntegratorAccuracy(ACCURACY)
    manager.initialize(state)
    out = []
    for time in times:
        state = manager.integrate(float(time))
        out.append(
            [coordinates.get(n).getValue(state) for n in names]
            + [coordinates.get(n).getSpeedValue(state) for n in names]
        )
    return np.array(out)


def _values(function, points):
    """OpenSim's value of a one-argument Function at each point."""
    return np.array([function.calcValue(osim.Vector(1, float(p))) for p in points])


def test_the_papers_curves_in_the_file_are_spinectls_formulas(exported):
    """The ``paper`` file's curves, evaluated by OpenSim (calcValue of the RigidTendonMuscle's curves), are the
    paper's force_length and force_velocity (spinectl.model.muscle) over the whole range to 1e-14: x = l / l_opt in
    [0.5, 1.5], w = V / v_max from -0.9 (shortening) to 2 (lengthening), 0 included; and with the printed eccentric
    constant C (its branches do not meet at v = 0) OpenSim takes the concentric branch at w = 0, as spinectl does."""
    import dataclasses

    model, files = exported
    built = osim.Model(str(files["paper", False][0]))
    fibre = osim.RigidTendonMuscle.safeDownCast(built.getMuscles().get(0))
    assert fibre.getTendonSlackLength() == 0.0 and fibre.getPennationAngleAtOptimalFiberLength() == 0.0
    l_opt = fibre.getOptimalFiberLength()
    x, w = np.linspace(0.5, 1.5, 21), np.array([-0.9, -0.3, -1e-6, 0.0, 1e-6, 0.3, 2.0])
    for errata in ("corrected", "printed"):  # the printed C last: the assertion after the loop
        variant = dataclasses.replace(model, errata=dataclasses.replace(model.errata, eccentric_constant=errata))
        if errata == model.errata.eccentric_constant:  # the file's own curves
            length, velocity = fibre.get_active_force_length_curve(), fibre.get_force_velocity_curve()
        else:
            expressions = laws.opensim_curves(variant.fibre, variant.errata)
            length = osim.ExpressionBasedFunction(expressions.active_force_length, "x")
            velocity = osim.ExpressionBasedFunction(expressions.force_velocity, "w")
        hill = fibre_law.hill_constants(np.asarray(l_opt), variant.fibre, variant.errata)
        v_max = fibre_law.max_velocity(l_opt, variant.fibre)
        np.testing.assert_allclose(
            _values(length, x), fibre_law.force_length(x * l_opt, l_opt, variant.fibre), atol=1e-14
        )
        np.testing.assert_allclose(_values(velocity, w), fibre_law.force_velocity(-w * v_max, hill), atol=1e-14)
    assert abs(_values(velocity, [1e-12])[0] - 1) > 0.1  # the printed C: the branches differ


@pytest.mark.parametrize("local", [False, True], ids=["plain", "local"])
def test_with_the_papers_curves_opensims_linearisation_is_the_chains(exported, local):
    """With the ``paper`` muscles, OpenSim's K, D and M of the file are the chain's (PaperSolution: docs/chain.md's
    closed forms) to the central differences' error (K 1e-8, D 1e-6 relative to the largest entry, M 1e-12), its ten
    eigenvalues are those of ``stability --coupled`` (coupled_stability_at, with the least local stiffness for
    "local") to 1e-6, the posture is an equilibrium, and the counter torques that hold it against OpenSim's forces
    (opensim_counter_torque, OpenSim's inverse dynamics) are spinectl's -tau_0 to 1e-9."""
    from spinectl.optimise.coupled import coupled_stability_at

    model, files = exported
    path, solution, linearisation = files["paper", local]
    f0, stiffness, damping, mass = linearisation
    assert np.max(np.abs(stiffness - solution.stiffness)) <= 1e-8 * np.max(np.abs(solution.stiffness))
    assert np.max(np.abs(damping - solution.damping)) <= 1e-6 * np.max(np.abs(solution.damping))
    np.testing.assert_allclose(mass, solution.mass, rtol=1e-12, atol=1e-15)
    reference = coupled_stability_at(model, E, LAMBDA)
    values, _ = _modes(linearisation)
    for value in reference.local_eigenvalues if local else reference.eigenvalues:
        assert np.min(np.abs(values - value)) <= 1e-6 * abs(value)
    assert np.max(np.abs(f0)) <= 1e-9 * np.max(np.abs(solution.counter_torque))
    counter = opensim_counter_torque(solution, "paper")
    assert np.max(np.abs(counter - solution.counter_torque)) <= 1e-9 * np.max(np.abs(solution.counter_torque))


def test_without_springs_opensim_diverges_at_the_chains_rate(exported):
    """``paper`` muscles, no local stiffness: displaced 1e-7 rad along the fastest growing mode of OpenSim's own
    linearisation, OpenSim's simulation grows at that mode's eigenvalue to 5 % (least-squares fit of log |q . mode|
    over 0.1 s, sampled every ms), and that eigenvalue is spinectl's largest (68.3 1/s) to 1e-6."""
    model, files = exported
    path, solution, linearisation = files["paper", False]
    values, vectors = _modes(linearisation)
    top = np.argmax(values.real)
    rate, mode = values[top].real, np.real(vectors[:, top])
    assert abs(rate - solution.eigenvalues[0].real) <= 1e-6 * rate and rate > 0
    mode = mode / np.linalg.norm(mode[:5])
    times = 1e-3 * np.arange(1, 101)
    path_ = _replay(path, model.geometry.cor_names, 1e-7 * mode, times)
    fitted = np.polyfit(times, np.log(np.abs(path_[:, :5] @ mode[:5])), 1)[0]
    assert abs(fitted - rate) <= 0.05 * rate


def test_with_the_least_local_stiffness_every_mode_decays_in_opensim(exported):
    """``paper`` muscles with the chain's least local stiffness as joint springs: every mode of OpenSim's own
    linearisation decays (negative real parts), and in OpenSim's simulation from all ten modes excited at once by
    1e-6, every modal amplitude is smaller after 10 s than at the start, the slowest mode's (its eigenvalue, about
    -0.086 1/s) as that eigenvalue predicts (5 %), and the chain stays within 10 times its start."""
    model, files = exported
    path, _, linearisation = files["paper", True]
    values, vectors = _modes(linearisation)
    assert np.all(values.real < 0)
    x0 = 1e-6 * np.real(vectors @ np.ones(10))
    times = np.linspace(0.5, 10.0, 20)
    path_ = _replay(path, model.geometry.cor_names, x0, times)
    start, end = np.linalg.solve(vectors, x0), np.linalg.solve(vectors, path_[-1])
    assert np.all(np.abs(end) < np.abs(start))
    slow = np.argmax(values.real)
    predicted = np.abs(start[slow]) * np.exp(10.0 * values[slow].real)
    assert abs(np.abs(end[slow]) - predicted) <= 0.05 * predicted
    assert np.max(np.abs(path_[:, :5])) <= 10 * np.max(np.abs(x0[:5]))


def _millard_chain(model, solution, path):
    """The chain's K and D with every fibre's curves and activation replaced by the Millard muscle's in the file.

    Per muscle (its fibres share one length, so one l / l_opt = 1 / 1.2 and one set of curve values), spinectl's
    K_m and D_m per unit f_iso of a fibre give Sigma h h' = D_m / (f_l f_H') and Sigma H = -(K_m + f_l' Sigma h h')
    / f_l (docs/chain.md); OpenSim's are F_max a (-f_AL' Sigma h h' - f_AL Sigma H) and F_max a f_AL (-f_V')
    Sigma h h', with Millard's values and slopes (calcValue / calcDerivative of the file's curves at the fibre's
    normalised length and at zero velocity) and the activation a that OpenSim holds (getActivation: the control,
    floored at Millard's minimum activation). Gravity and the springs are the chain's."""
    built = osim.Model(str(path))
    state = built.initSystem()
    built.realizeDynamics(state)
    muscles, fibres = built.getMuscles(), fibre_gains(model)
    coefficients = chain.chain_coefficients(model, E, LAMBDA)
    share = geometry.all_fibres(model)[2].sum(axis=1)
    stiffness, damping = solution.stiffness.copy(), solution.damping.copy()
    for m in range(len(model.muscle_names)):
        f = int(np.flatnonzero(fibres.muscle == m)[0])
        millard = osim.Millard2012EquilibriumMuscle.safeDownCast(muscles.get(f))
        l_opt = millard.getOptimalFiberLength()
        x = fibres.length[f] * (1 - TENDON_SLACK_RATIO) / l_opt
        f_al = millard.getActiveForceLengthCurve().calcValue(x)
        f_al_slope = millard.getActiveForceLengthCurve().calcDerivative(x, 1) / l_opt
        f_v_slope = millard.getForceVelocityCurve().calcDerivative(0.0, 1) / (
            l_opt * millard.getMaxContractionVelocity()
        )
        iso = model.fibre.specific_tension * share[f]  # f_iso of the fibre per unit PCSA of its muscle
        f_l, f_l_slope = fibres.force[f] / iso, fibres.length_slope[f] / iso
        f_h_slope = fibres.velocity_slope[f] / fibres.force[f]
        k_m = coefficients.stiffness_per_pcsa[..., m] / iso
        d_m = coefficients.damping_per_pcsa[..., m] / iso
        hh = d_m / (f_l * f_h_slope)
        hessian = -(k_m + f_l_slope * hh) / f_l
        force = millard.getMaxIsometricForce() * millard.getActivation(state)
        stiffness += (
            force * (-f_al_slope * hh - f_al * hessian) - solution.pcsa[m] * coefficients.stiffness_per_pcsa[..., m]
        )
        damping += force * f_al * (-f_v_slope) * hh - solution.pcsa[m] * coefficients.damping_per_pcsa[..., m]
    return stiffness, damping


@pytest.mark.parametrize("local", [False, True], ids=["plain", "local"])
def test_millards_stiffness_is_the_chains_with_millards_curves_and_floor(exported, local):
    """``millard`` muscles: OpenSim's own K and D (central differences) are the chain's with Millard's curve values
    and OpenSim's activations in place of the paper's (_millard_chain) to 1e-6 of the largest entry, and far from
    spinectl's (every joint's diagonal entry off by more than 10 % of spinectl's largest)."""
    model, files = exported
    path, solution, (_, stiffness, damping, _) = files["millard", local]
    expected_k, expected_d = _millard_chain(model, solution, path)
    assert np.max(np.abs(stiffness - expected_k)) <= 1e-6 * np.max(np.abs(expected_k))
    assert np.max(np.abs(damping - expected_d)) <= 1e-6 * np.max(np.abs(expected_d))
    off = np.abs(np.diag(stiffness) - np.diag(solution.stiffness))
    assert np.all(off > 0.1 * np.max(np.abs(solution.stiffness)))


def test_spinectls_local_stiffness_leaves_millards_chain_unstable_in_opensim(exported):
    """``millard`` muscles with spinectl's least local stiffness: spinectl's -K has its smallest eigenvalue at the
    margin mu (stable), OpenSim's -K has a negative one and its linearisation a growing mode, and OpenSim's
    simulation from 1e-7 rad along that mode grows at its eigenvalue to 5 % (fit of log |q . mode| over 0.4 s)."""
    model, files = exported
    path, solution, linearisation = files["millard", True]
    margin = model.optimisation.stability_margin
    assert np.min(np.linalg.eigvalsh(-solution.stiffness)) == pytest.approx(margin, rel=1e-3)
    assert np.min(np.linalg.eigvalsh(-(linearisation[1] + linearisation[1].T) / 2)) < 0
    values, vectors = _modes(linearisation)
    top = np.argmax(values.real)
    rate, mode = values[top].real, np.real(vectors[:, top])
    assert rate > 0 and abs(values[top].imag) == 0
    mode = mode / np.linalg.norm(mode[:5])
    times = 0.01 * np.arange(1, 41)
    path_ = _replay(path, model.geometry.cor_names, 1e-7 * mode, times)
    fitted = np.polyfit(times, np.log(np.abs(path_[:, :5] @ mode[:5])), 1)[0]
    assert abs(fitted - rate) <= 0.05 * rate


def test_the_least_local_stiffness_of_opensims_own_k_makes_millards_chain_stable(exported, tmp_path):
    """The recipe for Millard's muscles: the least local stiffness computed on OpenSim's own K of the plain file
    (least_local_stiffness_at, the same SDP and margin as spinectl's chain), added to the file's springs through
    OpenSim's API, gives a file whose OpenSim linearisation has -K >= mu (to 1e-6) and only decaying modes."""
    from spinectl.optimise.coupled.sdp import least_local_stiffness_at

    model, files = exported
    path, _, (_, stiffness, _, _) = files["millard", False]
    margin = model.optimisation.stability_margin
    status, local = least_local_stiffness_at(stiffness, margin)
    assert status == "optimal"
    built = osim.Model(str(path))
    for k, name in enumerate(model.geometry.cor_names):
        spring = osim.SpringGeneralizedForce.safeDownCast(built.getForceSet().get(f"{name}_stiffness"))
        spring.setStiffness(spring.getStiffness() + float(local[k]))
    stable = tmp_path / "millard_own_local.osim"
    built.printToXML(str(stable))
    linearisation = opensim_linearisation(stable, model.geometry.cor_names)
    assert np.min(np.linalg.eigvalsh(-(linearisation[1] + linearisation[1].T) / 2)) >= margin - 1e-6
    assert np.all(_modes(linearisation)[0].real < 0)


def test_the_millard_exports_verdicts_are_spinectls_and_opensims(exported, tmp_path, capsys):
    """``export --format osim --with-local-stiffness`` (Millard's curves): spinectl's chain is stable with its least
    local stiffness while OpenSim's linearisation of the same file grows; each line names whose it is, and
    OpenSim's growth is that of the module's own linearisation of the same export (the replay tests above)."""
    model, files = exported
    _, solution, linearisation = files["millard", True]
    out = tmp_path / "m.osim"
    argv = ["export", "--format", "osim", "--E", str(E), "--Lambda", str(LAMBDA), "--with-local-stiffness"]
    assert main([*argv, "--out", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    growth = np.max(_modes(linearisation)[0].real)
    assert lines[0] == f"wrote {out} and {out.with_name('m_controls.sto')} (osim): E = 3 cm, Lambda = 4 cm"  # as all
    assert lines[1].startswith("exported: global PCSA") and "N m/rad in all as joint springs" in lines[1]
    assert lines[2] == (
        "spinectl's chain with them (all CoRs free, the paper's muscle laws): stable, largest real part of its "
        f"eigenvalues {np.max(solution.eigenvalues.real):.6g} 1/s"
    )
    assert lines[3].endswith("for a file whose dynamics are spinectl's chain: --osim-muscle paper")
    assert lines[3].startswith(
        "OpenSim's own linearisation of the file (Millard's muscle curves): unstable, largest real part of its "
        f"eigenvalues {growth:.6g} 1/s"
    )
    assert growth > 0 > np.max(solution.eigenvalues.real)


def test_the_paper_exports_verdicts_are_spinectls_and_opensims_and_they_agree(exported, tmp_path, capsys):
    """``export --format osim --with-local-stiffness --osim-muscle paper``: OpenSim's own linearisation's line was
    printed for the Millard export only, though --help says that with the paper's curves it is the chain's; it is
    printed here too, naming the curves, its value that of the module's own linearisation of the same export
    (the fixture), and it agrees with spinectl's verdict (both stable, no remedy)."""
    _, files = exported
    _, solution, linearisation = files["paper", True]
    out = tmp_path / "p.osim"
    argv = ["export", "--format", "osim", "--E", str(E), "--Lambda", str(LAMBDA), "--with-local-stiffness"]
    assert main([*argv, "--osim-muscle", "paper", "--out", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    growth = np.max(_modes(linearisation)[0].real)
    assert lines[2].startswith("spinectl's chain with them (all CoRs free, the paper's muscle laws): stable")
    assert lines[3] == (
        "OpenSim's own linearisation of the file (the paper's curves on a RigidTendonMuscle): stable, largest real "
        f"part of its eigenvalues {growth:.6g} 1/s, 0 of {2 * len(solution.local_stiffness)} eigenvalues with Re >= 0"
    )
    assert growth < 0 and growth == pytest.approx(np.max(solution.eigenvalues.real), rel=1e-3)


def test_cli_exports_the_papers_curves_and_the_import_names_what_it_reads(tmp_path, capsys):
    """``spinectl export --osim-muscle paper`` writes RigidTendonMuscles; ``spinectl anatomy`` of that file is one
    line naming the muscle class (the import reads Millard's muscle only), exit 2; --osim-muscle with MJCF is one
    line, exit 2, nothing written."""
    out = tmp_path / "paper.osim"
    assert main(["export", "--E", "0.03", "--Lambda", "0.04", "--osim-muscle", "paper", "--out", str(out)]) == 0
    capsys.readouterr()
    assert osim.Model(str(out)).getMuscles().get(0).getConcreteClassName() == "RigidTendonMuscle"
    capsys.readouterr()
    assert main(["anatomy", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "RigidTendonMuscle" in err
    mjcf = tmp_path / "chain.xml"
    assert main(["export", "--osim-muscle", "paper", "--out", str(mjcf)]) == 2
    assert capsys.readouterr().err.count("\n") == 1 and not mjcf.exists()
