"""The muscle-law seam: what a muscle law is, and the two things every user of one asks of it.

A :class:`MuscleLaw` is a named set of relations of a fibre, per unit of its isometric force
f_iso: the active force-length f_L(x) of the normalised length x = l / l_opt and its slope, the
force-velocity f_V(v) of the shortening velocity v and its slope, an optional passive force-length
f_P(x), and, for the OpenSim export, the same relations as OpenSim expressions (or none). The
tendon is rigid: the fibre's length is its path's (the paper's fibres, docs/model.md, "The muscle
fibre").

Nobody calls a law's relations but this module: the model, the chain and the exports ask for
the fibre's :func:`tension` at a length and velocity (the nonlinear torques) or for its
linearisation :func:`at_rest` (K, D and the MJCF gains). A law that composes otherwise (a
compliant tendon, which makes the fibre's length a state; pennation) changes these two functions
and nothing that calls them (docs/model.md, "The muscle-law seam").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class OpenSimCurves:
    """A law's force-length and force-velocity factors as OpenSim expressions (``ExpressionBasedFunction``).

    Attributes
    ----------
    active_force_length : str
        f_L as an expression in x = l / l_opt [1].
    force_velocity : str
        f_V as an expression in w = V / v_max [1], V the *lengthening* velocity [m/s] and v_max
        :func:`spinectl.model.muscle.max_velocity` (OpenSim's normalised fibre velocity with
        ``max_contraction_velocity`` = v_max / l_opt).
    passive_force_length : str or None
        f_P as an expression in x; None: no passive force.
    """

    active_force_length: str
    force_velocity: str
    passive_force_length: str | None = None


@dataclass(frozen=True)
class MuscleLaw:
    """A fibre's tension law, per unit of its isometric force f_iso, as a named, selectable model.

    Every relation broadcasts over arrays; ``fibre`` is the model's
    :class:`~spinectl.model.params.Fibre` and ``errata`` its :class:`~spinectl.model.params.Errata`
    (a law reads the constants it needs from them).

    Attributes
    ----------
    name : str
        The name that ``fibre.law`` selects it by (:func:`spinectl.model.laws.register_law`).
    active_force_length : callable
        ``(x, fibre) -> f_L`` [1]: the active force at the normalised length x = l / l_opt [1].
    active_force_length_slope : callable
        ``(x, fibre) -> df_L/dx`` [1].
    force_velocity : callable
        ``(v, l_opt, fibre, errata) -> f_V`` [1], v the shortening velocity [m/s] (v >= 0
        concentric) and l_opt [m]; f_V(0) = 1, the isometric force.
    force_velocity_slope : callable
        ``(v, l_opt, fibre, errata) -> df_V/dv`` [s/m]; at v = 0 it damps the fibre.
    passive_force_length : callable or None
        ``(x, fibre) -> f_P`` [1], the passive force, not scaled by activation nor velocity; None:
        the fibre has none (the paper's).
    passive_force_length_slope : callable or None
        ``(x, fibre) -> df_P/dx`` [1]; given with ``passive_force_length``.
    opensim : callable or None
        ``(fibre, errata) -> OpenSimCurves``; None: the law has no such form, and the OpenSim export
        with the law's own curves refuses it.
    reference : str
        Where the law is published (with its DOI).
    """

    name: str
    active_force_length: Callable
    active_force_length_slope: Callable
    force_velocity: Callable
    force_velocity_slope: Callable
    passive_force_length: Callable | None = None
    passive_force_length_slope: Callable | None = None
    opensim: Callable | None = None
    reference: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"MuscleLaw.name must be an identifier, e.g. 'wagner2012' (got {self.name!r})")
        if (self.passive_force_length is None) != (self.passive_force_length_slope is None):
            raise ValueError(f"MuscleLaw {self.name!r}: give passive_force_length and its slope together, or neither")


@dataclass(frozen=True)
class FibreRest:
    """A fibre's tension linearised at rest (v = 0) at a length l0, per unit f_iso.

    T(l, v) ~ tension + length_slope (l - l0) + tension relative_velocity_slope v.

    Attributes
    ----------
    tension : numpy.ndarray
        T(l0, 0) = f_L(x0) + f_P(x0) [1], x0 = l0 / l_opt.
    length_slope : numpy.ndarray
        dT/dl at (l0, 0) [1/m].
    relative_velocity_slope : numpy.ndarray
        (dT/dv) / T at (l0, 0) [s/m]: f_V'(0) when all the tension is active (the paper's), f_L(x0)
        f_V'(0) / T with a passive force, which the force-velocity relation does not scale.
    """

    tension: np.ndarray
    length_slope: np.ndarray
    relative_velocity_slope: np.ndarray


def tension(law: MuscleLaw, length, velocity, optimal_length, fibre, errata, lever_arm=1.0):
    """A fibre's tension per unit f_iso at a length and a shortening velocity [1], or its torque h T [m].

    T = f_L(l / l_opt) f_V(v) + f_P(l / l_opt), the rigid tendon's (module docstring); the paper's
    M_i = h_i f_li f_Hi is h T (docs/model.md, "The muscle fibre"), computed as (h f_L) f_V + h f_P
    with ``lever_arm`` h: the rounding of :func:`spinectl.model.mechanics.fibre_torque` before the seam.

    Parameters
    ----------
    law : MuscleLaw
    length : array_like
        Fibre length l [m].
    velocity : array_like
        Shortening velocity v [m/s].
    optimal_length : array_like
        l_opt [m].
    fibre : Fibre
    errata : Errata
    lever_arm : array_like
        h [m]; 1 (the default) gives the tension itself.

    Returns
    -------
    numpy.ndarray
        h T / f_iso [m], or T / f_iso [1] without ``lever_arm``; the broadcast shape of the arguments.
    """
    ratio = np.asarray(length) / optimal_length
    active = lever_arm * law.active_force_length(ratio, fibre)  # 1 * f_L is f_L to the bit
    out = active * law.force_velocity(velocity, optimal_length, fibre, errata)
    if law.passive_force_length is not None:
        out = out + lever_arm * law.passive_force_length(ratio, fibre)
    return out


def at_rest(law: MuscleLaw, length, optimal_length, fibre, errata) -> FibreRest:
    """A fibre's tension and its slopes in length and velocity at rest at ``length`` (:class:`FibreRest`).

    What K and D are made of (docs/model.md, "Stiffness and damping per unit PCSA"): with the rigid
    tendon, dT/dl = (f_L'(x0) + f_P'(x0)) / l_opt and dT/dv = f_L(x0) f_V'(0) (f_V(0) = 1).

    Parameters
    ----------
    law : MuscleLaw
    length : array_like
        The length l0 about which to linearise [m].
    optimal_length : array_like
        l_opt [m].
    fibre : Fibre
    errata : Errata

    Returns
    -------
    FibreRest
        Each of the broadcast shape of ``length`` and ``optimal_length``.
    """
    ratio = np.asarray(length) / optimal_length
    total = active = law.active_force_length(ratio, fibre)
    slope = law.active_force_length_slope(ratio, fibre)
    velocity_slope = law.force_velocity_slope(np.zeros_like(ratio), optimal_length, fibre, errata)
    if law.passive_force_length is not None:
        total = active + law.passive_force_length(ratio, fibre)
        slope = slope + law.passive_force_length_slope(ratio, fibre)
        velocity_slope = active * velocity_slope / total
    return FibreRest(tension=total, length_slope=slope / optimal_length, relative_velocity_slope=velocity_slope)
