"""``docs/interchange.md``'s reasons why Millard's chain stays unstable, measured at the build.

The chain's K of the Millard ``.osim`` export (``spinectl export --format osim --with-local-stiffness``, the
paper's model at E = 3 cm, Lambda = 4 cm) is spinectl's with, muscle by muscle, Millard's active force-length
value and slope at the fibre's length and OpenSim's activation (the control, floored at Millard's minimum) in
place of the paper's (``tests/anatomy/test_osim_replay.py::_millard_chain`` checks that all three together give
OpenSim's own K to 1e-6). :func:`chain_with` puts in any of the three alone, so that the page says what each
cause does to the least eigenvalue of -K; the off-diagonal entry and the damping ratio the page quotes are
OpenSim's linearisation's beside spinectl's chain.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .interchange import POINT, exported, opensim_linearised
from .values import value

CAUSES = ("floor", "value", "slope")
"""Millard's activation (its floor), its active force-length curve's value, its slope."""


@cache
def _muscles(local: bool = True):
    """Per muscle: (spinectl's force scale [N], OpenSim's F_max a [N], paper's f_l, f_l', Millard's f_AL, f_AL',
    Sigma h h', Sigma H), from the Millard export with spinectl's least local stiffness (``local``) or without."""
    import opensim as osim

    from spinectl.anatomy.export_mjcf import fibre_gains
    from spinectl.anatomy.export_osim import TENDON_SLACK_RATIO
    from spinectl.model import chain, geometry

    path, solution = exported("osim", "millard", local)
    model = solution.model
    built = osim.Model(str(path))
    state = built.initSystem()
    built.realizeDynamics(state)
    muscles, fibres = built.getMuscles(), fibre_gains(model)
    coefficients = chain.chain_coefficients(model, *POINT)
    share = geometry.all_fibres(model)[2].sum(axis=1)
    rows = []
    for m in range(len(model.muscle_names)):
        f = int(np.flatnonzero(fibres.muscle == m)[0])  # a muscle's fibres share one normalised length
        millard = osim.Millard2012EquilibriumMuscle.safeDownCast(muscles.get(f))
        l_opt = millard.getOptimalFiberLength()
        x = fibres.length[f] * (1 - TENDON_SLACK_RATIO) / l_opt
        curve = millard.getActiveForceLengthCurve()
        iso = model.fibre.specific_tension * share[f]  # f_iso of the fibre per unit PCSA of its muscle
        f_l, f_l_slope = fibres.force[f] / iso, fibres.length_slope[f] / iso
        k_m = coefficients.stiffness_per_pcsa[..., m] / iso
        hh = coefficients.damping_per_pcsa[..., m] / iso / (f_l * fibres.velocity_slope[f] / fibres.force[f])
        hessian = -(k_m + f_l_slope * hh) / f_l
        force = millard.getMaxIsometricForce() * millard.getActivation(state)
        millards = (curve.calcValue(x), curve.calcDerivative(x, 1) / l_opt)
        rows.append((solution.pcsa[m] * iso, force, f_l, f_l_slope, *millards, hh, hessian))
    return rows


def chain_with(causes, local: bool = True) -> np.ndarray:
    """The export's chain K [N m/rad] with Millard's ``causes`` (of :data:`CAUSES`) in place of the paper's, the
    export with spinectl's least local stiffness (``local``) or without."""
    _, solution = exported("osim", "millard", local)
    stiffness = solution.stiffness.copy()
    for paper_force, force, f_l, f_l_slope, f_al, f_al_slope, hh, hessian in _muscles(local):
        scale = force if "floor" in causes else paper_force
        value_ = f_al if "value" in causes else f_l
        slope = f_al_slope if "slope" in causes else f_l_slope
        stiffness += scale * (-slope * hh - value_ * hessian) - paper_force * (-f_l_slope * hh - f_l * hessian)
    return stiffness


def least(stiffness: np.ndarray) -> float:
    """The least eigenvalue of -K's symmetric part [N m/rad]."""
    return float(np.linalg.eigvalsh(-(stiffness + stiffness.T) / 2)[0])


def _minus(v: float, fmt: str) -> str:
    return (f"{v:+{fmt}}" if v > 0 else f"{v:{fmt}}").replace("-", "\u2212")


def damping_ratio() -> str:
    """OpenSim's D over spinectl's chain's on the diagonal, the plain Millard export: ``1.12 to 1.18``."""
    _, solution = exported("osim", "millard", False)
    ratio = np.diag(opensim_linearised("millard", False)[2]) / np.diag(solution.damping)
    return f"{ratio.min():.2f} to {ratio.max():.2f}"


value("interchange.cause_floor")(lambda: _minus(least(chain_with(("floor",))), ".1f"))
value("interchange.cause_value")(lambda: _minus(least(chain_with(("value",))), ".1f"))
value("interchange.cause_slope")(lambda: _minus(least(chain_with(("slope",))), ".1f"))
value("interchange.opensim_l1l2_l2l3")(lambda: _minus(opensim_linearised("millard", False)[1][0, 1], ".1f"))
value("interchange.spinectl_l1l2_l2l3")(lambda: _minus(exported("osim", "millard", False)[1].stiffness[0, 1], ".1f"))
value("interchange.damping_ratio")(damping_ratio)


# --- the curves at the upright posture and the muscles the optimum activates ("Why Millard's chain ...") ---


@cache
def upright() -> dict:
    """At the upright posture of the plain Millard export: every fibre's l/l_opt (one value: the page says so),
    Millard's active force-length value and slope per l_opt there and the paper's (the model's muscle law), the
    muscles the per-segment optimum activates (name, PCSA [m^2], activation) and Millard's activation floor."""
    import opensim as osim

    from spinectl.anatomy.export_mjcf import fibre_gains
    from spinectl.anatomy.export_osim import REFERENCE_PCSA_CM2, TENDON_SLACK_RATIO
    from spinectl.model import geometry
    from spinectl.units import M2_PER_CM2

    path, solution = exported("osim", "millard", False)
    model, fibres = solution.model, fibre_gains(solution.model)
    built = osim.Model(str(path))  # held: its muscles are views into it
    muscles = built.getMuscles()
    iso = model.fibre.specific_tension * geometry.all_fibres(model)[2].sum(axis=1)  # f_iso per unit PCSA
    rows = []
    for f in range(len(fibres.names)):
        millard = osim.Millard2012EquilibriumMuscle.safeDownCast(muscles.get(f))
        x = fibres.length[f] * (1 - TENDON_SLACK_RATIO) / millard.getOptimalFiberLength()
        curve = millard.getActiveForceLengthCurve()
        paper_l_opt = model.fibre.optimal_length_ratio * fibres.length[f]
        rows.append((x, curve.calcValue(x), curve.calcDerivative(x, 1),
                     fibres.force[f] / iso[f], fibres.length_slope[f] / iso[f] * paper_l_opt))  # fmt: skip
    rows = np.array(rows)
    # the page reads one value of each for every fibre, at l/l_opt = 1/optimal_length_ratio (1/1.2, less the
    # rigid tendon's slack length TENDON_SLACK_RATIO l0)
    off = abs(rows[0, 0] * model.fibre.optimal_length_ratio - 1)
    if np.ptp(rows, axis=0).max() > 1e-9 or off > 2 * TENDON_SLACK_RATIO:
        raise RuntimeError(f"docs/interchange.md: the fibres' upright l/l_opt and curves differ: {rows}")
    activation = solution.pcsa / (REFERENCE_PCSA_CM2 * M2_PER_CM2)
    floor = osim.Millard2012EquilibriumMuscle.safeDownCast(muscles.get(0)).getMinimumActivation()
    active = [(n, p, a) for n, p, a in zip(model.muscle_names, solution.pcsa, activation, strict=True) if a > floor]
    return {"x": rows[0, 0], "millard": rows[0, 1:3], "paper": rows[0, 3:5], "active": active, "floor": floor,
            "idle": len(model.muscle_names) - len(active), "reference_cm2": REFERENCE_PCSA_CM2}  # fmt: skip


NUMBERS = ("no", "one", "two", "three", "four", "five", "six")


def _names(names) -> str:
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def active_words() -> str:
    """'oblique_outer_ventral and oblique_outer_dorsal (17.9 cm² each, activation 0.179)'."""
    from .searched import span

    active = upright()["active"]
    each = " each" if len(active) > 1 else ""
    return (f"{_names(n for n, _, _ in active)} ({span([1e4 * p for _, p, _ in active], '.1f')} cm²{each}, "
            f"activation {span([a for _, _, a in active], '.3f')})")  # fmt: skip


def _change(millard: float, paper: float) -> str:
    """Millard's value against the paper's: '+11 %'."""
    return _minus(100 * (millard / paper - 1), ".0f") + " %"


value("interchange.upright_length")(lambda: f"{upright()['x']:.3f}")
value("interchange.curve_change")(lambda: _change(upright()["millard"][0], upright()["paper"][0]))
value("interchange.slope_change")(lambda: _change(upright()["millard"][1], upright()["paper"][1]))
value("interchange.millard_curve")(lambda: "{:.3f}".format(upright()["millard"][0]))
value("interchange.millard_curve_slope")(lambda: "{:.2f}".format(upright()["millard"][1]))
value("interchange.paper_curve")(lambda: "{:.3f}".format(upright()["paper"][0]))
value("interchange.paper_curve_slope")(lambda: "{:.2f}".format(upright()["paper"][1]))
value("interchange.active_muscles")(active_words)
value("interchange.idle_muscles")(lambda: NUMBERS[upright()["idle"]])
value("interchange.millard_floor")(lambda: f"{upright()['floor']:g}")
value("interchange.millard_floor_cm2")(lambda: f"{upright()['floor'] * upright()['reference_cm2']:g}")


# --- "The chain at the solution": the re-imported chain (OpenSim's linearisation of the plain export) ---


def restoring(stiffness) -> str:
    """−K_jj, L1L2 to L5S1, with what they say joint by joint: '0.1, 7.8, … and 80.8 N m/rad (all self-stable
    joint by joint)' (a joint is self-stable where −K_jj > 0)."""
    from .interchange import _and

    diagonal = -np.diag(stiffness)
    stable = int(np.sum(diagonal > 0))
    words = {diagonal.size: "all self-stable", 0: "all self-unstable"}.get(
        stable, f"{stable} of {diagonal.size} self-stable"
    )
    return f"{_and([_minus(v, '.1f').lstrip('+') for v in diagonal], '')} N m/rad ({words} joint by joint)"


def differs(opensim, spinectl) -> str:
    """The largest entry of OpenSim's matrix less spinectl's, against spinectl's largest: '1.2 times' or '12 % of'."""
    ratio = np.max(np.abs(opensim - spinectl)) / np.max(np.abs(spinectl))
    return f"{ratio:.1f} times" if ratio >= 1 else f"{100 * ratio:.0f} % of"


def _plain():
    return exported("osim", "millard", False)[1]


value("interchange.reimport_k_differs")(lambda: differs(opensim_linearised("millard", False)[1], _plain().stiffness))
value("interchange.reimport_d_differs")(lambda: differs(opensim_linearised("millard", False)[2], _plain().damping))
value("interchange.spinectl_restoring")(lambda: restoring(_plain().stiffness))
value("interchange.millard_restoring")(lambda: restoring(opensim_linearised("millard", False)[1]))
value("interchange.millard_restoring_unfloored")(lambda: restoring(chain_with(("value", "slope"), local=False)))
