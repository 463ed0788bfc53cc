"""Segments and reflex loops as python-control systems (docs/reflex.md, "The loop").

One python-control object per segment, for the command line, plots and checks (sweeps use the
vectorised :mod:`spinectl.reflex` instead): the segment G(s) = 1 / (theta s^2 - D s - S), the Padé
delay, the activation lag A(s) = 1/(T_a s + 1), the reflex C(s) = kp + kd s, the loop
L(s) = C(s) e^{-s tau} A(s) G(s), the closed loop and python-control's margins of L, read for an
open-loop unstable plant.
"""

from __future__ import annotations

import contextlib
import warnings
from dataclasses import dataclass

import control as ct
import numpy as np

from ..model.stability import jacobian
from .inputs import validated

STATES = ("alpha", "omega")
"""State names of a segment: angle [rad] and angular velocity [rad/s]."""


@validated
def segment_system(stiffness: float, damping: float, inertia: float, name: str | None = None) -> ct.StateSpace:
    """The segment linearised at the upright equilibrium (paper, Stability analysis).

    x = (alpha, omega), x' = J x + (0, 1/theta) u, y = alpha, with the Jacobian
    J = [[0, 1], [S/theta, D/theta]] of :func:`spinectl.model.stability.jacobian`; so its
    poles are the eigenvalues of paper eq. (1) [1]_.

    Parameters
    ----------
    stiffness, damping, inertia : float
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    name : str, optional
        System name, e.g. the CoR ("L3L4").

    Returns
    -------
    control.StateSpace
        Two states (alpha [rad], omega [rad/s]), input "torque" [N m], output "alpha" [rad].

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13
    """
    a = jacobian(stiffness, damping, inertia)
    b = np.array([[0.0], [1.0 / inertia]])
    c = np.array([[1.0, 0.0]])
    return ct.ss(a, b, c, 0.0, inputs=["torque"], outputs=["alpha"], states=list(STATES), name=name)


@validated
def pade_delay(delay: float, order: int) -> ct.TransferFunction:
    """exp(-s delay) as python-control's [order/order] Padé approximant (1 for no delay).

    Parameters
    ----------
    delay : float
        tau [s].
    order : int
        Order of the approximant.

    Returns
    -------
    control.TransferFunction
        The all-pass [order/order] rational function [1], input "u", output "u_delayed".
    """
    num, den = ct.pade(delay, order)
    return ct.tf(num, den, inputs=["u"], outputs=["u_delayed"])


def activation_lag(lag: float) -> ct.TransferFunction:
    """A(s) = 1/(T_a s + 1): the force generation of the reflex torque (docs/reflex.md, "Force generation").

    Parameters
    ----------
    lag : float
        Activation time constant T_a [s]; 0 gives A = 1.

    Returns
    -------
    control.TransferFunction
        A(s) [1], input "u_delayed", output "u_force".
    """
    return ct.tf([1.0], [lag, 1.0] if lag > 0 else [1.0], inputs=["u_delayed"], outputs=["u_force"])


def reflex_controller(kp: float, kd: float) -> ct.TransferFunction:
    """C(s) = kp + kd s [N m/rad], from alpha to the reflex torque (before the delay and sign).

    Parameters
    ----------
    kp, kd : float
        Reflex gains [N m/rad], [N m s/rad].

    Returns
    -------
    control.TransferFunction
        C(s) [N m/rad], input "alpha", output "reflex".
    """
    return ct.tf([kd, kp], [1.0], inputs=["alpha"], outputs=["reflex"])


@validated
def loop_transfer(
    stiffness, damping, inertia, kp, kd, delay: float, order: int, lag: float = 0.0
) -> ct.TransferFunction:
    """Loop transfer function L(s) = C(s) Pade(s) A(s) G(s), the delay as a Padé approximant.

    The closed loop is 1 + L = 0. G(s) = 1 / (theta s^2 - D s - S) is the transfer
    function of :func:`segment_system`, written from its coefficients (docs/reflex.md,
    "The loop") rather than converted, which is exact.

    Parameters
    ----------
    stiffness, damping, inertia : float
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : float
        Reflex gains [N m/rad], [N m s/rad].
    delay : float
        tau [s].
    order : int
        Order of the Padé approximant (:func:`pade_delay`).
    lag : float, optional
        Activation time constant T_a [s] (:func:`activation_lag`); 0 leaves it out.

    Returns
    -------
    control.TransferFunction
        L(s) [1], the delay replaced by its Padé approximant.
    """
    plant = ct.tf([1.0], [inertia, -damping, -stiffness], inputs=["torque"], outputs=["alpha"])
    loop = reflex_controller(kp, kd) * pade_delay(delay, order)
    return (loop * activation_lag(lag) if lag > 0 else loop) * plant


@validated
def closed_loop(
    stiffness, damping, inertia, kp, kd, delay: float, order: int, name=None, lag: float = 0.0
) -> ct.StateSpace:
    """The segment under the delayed, lagged reflex T_a u' + u = -(kp alpha + kd omega)(t - tau), Padé delay.

    Built in state space (the PD acts on the states, so nothing improper is
    realised): the plant with both states as outputs, fed back through the gain
    row [kp, kd], the Padé system and the activation lag. Input: a disturbing torque [N m];
    output: alpha.
    Its poles converge to the rightmost roots of the quasi-polynomial as the order grows.

    Parameters
    ----------
    stiffness, damping, inertia : float
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : float
        Reflex gains [N m/rad], [N m s/rad].
    delay : float
        tau [s].
    order : int
        Order of the Padé approximant.
    name : str, optional
        System name.
    lag : float, optional
        Activation time constant T_a [s]; 0 leaves the lag out.

    Returns
    -------
    control.StateSpace
        2 + ``order`` states (one more with the lag), input "torque" [N m], output "alpha" [rad].
    """
    plant = segment_system(stiffness, damping, inertia)
    full = ct.ss(plant.A, plant.B, np.eye(2), np.zeros((2, 1)))
    # scipy's realisation, not slycot's: the same matrices whether slycot is installed or not
    delayed = ct.tf2ss(pade_delay(delay, order), method="scipy")
    if lag > 0:
        delayed = ct.tf2ss(activation_lag(lag), method="scipy") * delayed
    feedback_path = delayed * np.array([[kp, kd]])
    loop = ct.feedback(full, feedback_path, sign=-1)
    return ct.ss(loop.A, loop.B, loop.C[:1], loop.D[:1], inputs=["torque"], outputs=["alpha"], name=name)


@dataclass(frozen=True)
class LoopMargins:
    """Margins of a loop transfer function from python-control's ``stability_margins``.

    ``stability_margins`` does not know how many open-loop poles are unstable: it
    reports the gain margin nearest to 1 (in dB), whichever side. For a segment below
    self-stability (one open-loop pole in Re s > 0) the Nyquist curve must circle -1
    once counter-clockwise, and the loop gain k is only stable in an interval
    (gain_margin_lower, gain_margin_upper) around 1, the lower end > 0 (at least S/kp:
    too weak a reflex cannot hold the segment). Both ends are the phase crossovers'
    1/abs(L) nearest to 1 from below and above; they are meaningful only if the closed
    loop is stable (``stable``), else NaN.

    Attributes
    ----------
    gain_margin : float
        python-control's gain margin [1] (nearest to 1 in dB; < 1 means a lower margin).
    gain_margin_lower, gain_margin_upper : float
        Stable range of a factor on both gains [1]; 0 and inf where unbounded.
    phase_margin_deg : float
        python-control's phase margin [deg], smallest in magnitude; inf without crossover.
    crossover_rad_s : float
        Gain crossover frequency of that phase margin [rad/s]; NaN without crossover.
    phase_crossover_rad_s : float
        Phase crossover frequency of ``gain_margin`` [rad/s].
    stable : bool
        Closed loop stable, as decided by the caller (exactly, from the quasi-polynomial).
    """

    gain_margin: float
    gain_margin_lower: float
    gain_margin_upper: float
    phase_margin_deg: float
    crossover_rad_s: float
    phase_crossover_rad_s: float
    stable: bool


def loop_margins(loop: ct.TransferFunction, stable: bool) -> LoopMargins:
    """python-control's margins of ``loop`` with the lower/upper reading of :class:`LoopMargins`.

    The closed-loop stability only changes with a gain factor k where k L(jw) = -1,
    i.e. at k = 1/abs(L(jw)) on the phase crossovers (``stability_margins(returnall=True)``),
    so a stable loop stays stable for k between the nearest of these below and above 1.

    Parameters
    ----------
    loop : control.TransferFunction
        L(s), e.g. from :func:`loop_transfer`.
    stable : bool
        Whether the closed loop is stable at k = 1 (decide it exactly, with
        :func:`spinectl.reflex.delay.stable_at_delay`); if not, the gain interval is NaN.

    Returns
    -------
    LoopMargins
        Gain margins [1], phase margin [deg], crossover frequencies [rad/s] and ``stable``.
    """
    with ignoring_underflow():
        every = ct.stability_margins(loop, returnall=True)
    all_gm, all_pm, _, all_wpc, all_wgc, _ = (np.asarray(a, float) for a in every)
    with np.errstate(divide="ignore"):  # a gain margin of 0 is infinitely far from 1
        gm, wpc = _nearest(all_gm, all_wpc, np.abs(np.log(all_gm)))
    pm, wgc = _nearest(all_pm, all_wgc, np.abs(all_pm))
    below, above = all_gm[all_gm < 1.0], all_gm[all_gm > 1.0]
    lower = float(below.max()) if below.size else 0.0
    upper = float(above.min()) if above.size else np.inf
    if not stable:
        lower = upper = np.nan
    return LoopMargins(
        gain_margin=float(gm),
        gain_margin_lower=lower,
        gain_margin_upper=upper,
        phase_margin_deg=float(pm),
        crossover_rad_s=float(wgc),
        phase_crossover_rad_s=float(wpc),
        stable=bool(stable),
    )


def _nearest(margins, frequencies, distance) -> tuple[float, float]:
    """The margin nearest to its neutral value, and its frequency; (inf, NaN) if there is none.

    python-control's own choice for ``stability_margins(returnall=False)`` (0.10): the gain margin
    of least abs(log GM) (an all-infinite list counts as none), the phase margin of least abs(PM),
    the first on a tie; made here from the one ``returnall=True`` call, not a second evaluation.
    """
    if not margins.size or np.isinf(margins).all():
        return np.inf, np.nan
    first = int(np.flatnonzero(distance == np.min(distance))[0])
    return float(margins[first]), float(frequencies[first])


@contextlib.contextmanager
def ignoring_underflow():
    """Silence underflow warnings from python-control's evaluation of L(jw) in the ``with`` block.

    python-control evaluates transfer functions under ``np.errstate(all="warn")``, so a
    subnormal coefficient (e.g. the damping at an activation of 1e-308) warns
    "underflow encountered"; the term is flushed to zero, which changes no result. numpy's
    own default ignores underflow too. Overflow and invalid operations still warn.

    Yields
    ------
    None
        Control returns to the ``with`` block with the underflow warnings filtered.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "underflow encountered", RuntimeWarning)
        yield
