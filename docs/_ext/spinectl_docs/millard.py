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
def _muscles():
    """Per muscle: (spinectl's force scale [N], OpenSim's F_max a [N], paper's f_l, f_l', Millard's f_AL, f_AL',
    Sigma h h', Sigma H), from the Millard export with spinectl's least local stiffness."""
    import opensim as osim

    from spinectl.anatomy.export_mjcf import fibre_gains
    from spinectl.anatomy.export_osim import TENDON_SLACK_RATIO
    from spinectl.model import chain, geometry

    path, solution = exported("osim", "millard", True)
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


def chain_with(causes) -> np.ndarray:
    """The export's chain K [N m/rad] with Millard's ``causes`` (of :data:`CAUSES`) in place of the paper's."""
    _, solution = exported("osim", "millard", True)
    stiffness = solution.stiffness.copy()
    for paper_force, force, f_l, f_l_slope, f_al, f_al_slope, hh, hessian in _muscles():
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
