"""The chain (every CoR free): the least local stiffness for which the chain under the delayed reflex meets a delay.

At the global activation ``reflex.activation`` (the operating point of ``spinectl margins``; ``--activation``),
the least local stiffness f k* (k* the least local stiffness for static stability, problem (a) of
docs/chain.md; the local muscles of "Local muscles as joint stiffness and damping", which damp the joint by
c_loc f k*: with ``local.damping`` = 0 the global muscles give the chain's only damping, and activation 0
leaves it undamped) for which the chain under the delayed reflex is stable at the delay. The reflex is the
rule on the chain scaled by the deficit left, (1 - f)+ times its gains (:func:`chain_loop_at`), or the
explicit gains.

A fraction meets a delay when the exact multivariable delay margin there
(:func:`spinectl.reflex.mimo.chain_delay_margin`, from the imaginary-axis eigenvalues of a delay-free
problem, no frequency grid) is at least the delay with no critical delay crossed below it, and the rightmost
characteristic root at the delay (:func:`~spinectl.reflex.design.roots.rightmost_root`, Newton's method from
the delay-free poles: a second method that shares none of the margin's steps) lies in the left half-plane.

One search answers one delay and the curve alike (:func:`chain_curve`; :func:`chain_design` is its one-delay
call): the delays in ascending order, each starting from the previous delay's answer (the least local
stiffness does not fall with the delay), the bracket narrowed by a safeguarded inverse interpolation of the
exact margins (:func:`_bracket_root`). Every fraction judged lies on the grid of 2^-20 of the search's range,
and the answer is certified as a bisection's is: it meets the delay, one grid step less does not. Where the
set of designs that meet a delay is an interval in f, that is the least grid point that meets it, whatever
the path: so a delay's answer does not depend on the other delays of the curve.
"""

from __future__ import annotations

import numpy as np

from ...model.chain import coupled_margin
from ...model.checks import arithmetic_guard
from ...model.linear_chain import LinearChain
from ...model.operating_point import OperatingPoint, chain_at
from ...model.params import Model
from ...optimise.coupled import least_local_stiffness_stacked
from .. import gains
from ..chain_margins import stable_at
from ..mimo import chain_delay_margin, delay_free_poles
from ..siso import from_crossings
from .decay import shifted_lag, shifted_loop
from .joint import BISECTIONS
from .result import LOCAL_MAX, ChainDesign
from .roots import SPECTRAL_NODES, rightmost_root

CHAIN_SCAN = 11
"""Local-stiffness fractions in [0, top] whose exact margins give the largest delay met
(:attr:`ChainDesign.largest_delay`) and whether the scan shows the set of designs met to be an interval."""


DECAY_SCAN = 64
"""Intervals of [0, top] scanned where a decay rate is not met at the top (:meth:`_Search._window`): with the
rule, f = 1 leaves no reflex and a slow mode, so the fractions that meet a decay rate form a window below it,
found if it is wider than 1/64 of the range."""


def chain_loop_at(model: Model, linear: LinearChain, least_static, fraction, kp=None, kd=None):
    """The chain with local stiffness f k* and its damping, and its reflex gains: (1 - f)+ times the rule's.

    The rule on the chain (:func:`spinectl.reflex.gains.chain_gains`) at f = 0 compensates the
    whole deficit k*; as the local muscles take over a fraction f of it, the reflex keeps the
    rest, (1 - f)+ times both gains, so that at f >= 1 the chain holds itself without reflex.
    The local muscles damp what they stiffen: c_loc f k* on the diagonal of D
    (:meth:`spinectl.model.linear_chain.LinearChain.damping`; docs/chain.md).

    Parameters
    ----------
    model : Model
        ``reflex``: the rule's settings and gains.
    linear : LinearChain
        The chain at the operating point (:func:`spinectl.model.operating_point.chain_at`): M, K (global
        muscles, gravity, passive), D (global muscles), c_loc.
    least_static : numpy.ndarray, shape (n,)
        k* [N m/rad].
    fraction : float
        f [1].
    kp, kd : float, optional
        Explicit gains for every joint.

    Returns
    -------
    stiffness : numpy.ndarray, shape (n, n)
        K - f diag(k*) [N m/rad].
    damping : numpy.ndarray, shape (n, n)
        D - c_loc f diag(k*) [N m s/rad].
    kp, kd : numpy.ndarray, shape (n,)
        [N m/rad], [N m s/rad].
    """
    k = fraction * np.asarray(least_static, float)  # NaN where (a) was unsolved: NaN matrices, judged undefined
    mass, stiffness, damping = linear.mass_matrix, linear.stiffness_offset, linear.damping_offset
    scale = max(1.0 - fraction, 0.0)  # the reflex hands over to the local muscles: (1 - f)+ times the rule's gains
    p, dd = gains.resolve_chain_gains(model.reflex, mass, stiffness, damping, least_static, kp, kd, scale)
    return linear.stiffness((), k), linear.damping((), k), p, dd


def _top(model: Model, kp, kd) -> float:
    """The top of the search [1]: 1 with the rule's gains (no reflex left at f = 1), else :data:`LOCAL_MAX`."""
    return 1.0 if model.reflex.gains == "rule" and kp is None and kd is None else LOCAL_MAX


class _Search:
    """The chain at its operating point, each fraction's exact margin and rightmost roots kept as found.

    The exact margin at f does not depend on the delay, so it is computed once per f; the rightmost root
    once per fraction, at the first delay its margin meets (a root on the right there fails f for every
    longer delay).
    """

    def __init__(self, model: Model, e: float, lam: float, pcsa, kp=None, kd=None, decay: float = 0.0):
        self.model, self.e, self.lam, self.kp, self.kd, self.decay = model, e, lam, kp, kd, decay
        self.chain = chain_at(OperatingPoint(model, e, lam, pcsa, slip_check=False))
        self.mass = self.chain.mass_matrix
        _, least = least_local_stiffness_stacked(self.chain.stiffness_offset[None], model.optimisation.stability_margin)
        self.least, self.lag = least[0], model.reflex.activation_time_constant
        if decay > 0:  # the loop shifted by sigma: its stability at the delay is every root at Re s < -sigma
            self.lag = shifted_lag(self.lag, decay)
        self.margins: dict[float, object] = {}
        self.fails_from: dict[float, float] = {}  # f -> a delay at which f is unstable: f fails every longer one
        self.rooted: set[float] = set()  # the fractions whose rightmost root has been checked
        self.roots: dict[float, tuple[float, complex]] = {}  # f -> (a delay, the rightmost root there)
        self.top = _top(model, kp, kd)
        self.width = self.top / 2**BISECTIONS

    def loop(self, f):
        """K, D, K_p, K_d at f: the chain's, or with a decay rate sigma its loop shifted by sigma (decay.py)."""
        k, d, p, dd = chain_loop_at(self.model, self.chain, self.least, f, self.kp, self.kd)
        if not self.decay > 0:
            return k, d, p, dd
        lag = self.model.reflex.activation_time_constant
        return shifted_loop(self.mass, k, d, p, dd, lag, self.model.reflex.delay, self.decay)[:4]

    def root(self, f, d, nodes: int = 0) -> complex:
        """The rightmost characteristic root at f and d, once per (f, d) (with ``nodes``, afresh)."""
        if nodes or f not in self.roots or self.roots[f][0] != d:
            k, dl, p, dd = self.loop(f)
            with arithmetic_guard(self.e, self.lam):
                found = rightmost_root(self.mass, k, dl, p, dd, d, self.lag, nodes)
            if nodes:
                return found
            self.roots[f] = (d, found)
        return self.roots[f][1]

    def exact(self, f):
        """The exact margin at f, once per f."""
        if f not in self.margins:
            k, dl, p, dd = self.loop(f)
            if not (np.any(p) or np.any(dd)):  # no reflex: stable at every delay or none (no crossing to find)
                self.margins[f] = from_crossings(np.empty(0), np.empty(0), np.empty(0), self._stable(k, dl, p, dd))
            else:
                with arithmetic_guard(self.e, self.lam):
                    self.margins[f] = chain_delay_margin(self.mass, k, dl, p, dd, self.lag)
        return self.margins[f]

    def _stable(self, k, dl, p, dd) -> bool:
        """Without a reflex: the static criterion, or (shifted, its damping no longer dissipative) the poles."""
        if not self.decay > 0:
            return bool(coupled_margin(k) > 0)
        return bool(np.all(delay_free_poles(self.mass, k, dl, p, dd, self.lag).real < 0))

    def met(self, f, d) -> bool:
        """The exact margin at f (already found) meets d."""
        m = self.margins[f]
        return bool(stable_at(m, d) and m.margin >= d)

    def meets(self, f, d) -> bool:
        """The exact margin at f meets d, and (once per f) no root at d in the right half-plane."""
        if f in self.fails_from and self.fails_from[f] <= d:
            return False
        self.exact(f)
        if not self.met(f, d):
            return False  # the margin alone rejects f: no root needed
        if f not in self.rooted and d > 0 and self.root(f, d).real >= 0:  # a true root: unstable
            self.fails_from[f] = d
            return False
        self.rooted.add(f)
        return True

    def answer(self, d, f):
        """The least fraction that meets d, from the previous delay's answer f (0 at the first); NaN if none."""
        if np.isnan(f) or self.meets(f, d):
            return f
        if not self.meets(self.top, d):
            if self.decay > 0:  # the rule's f = 1 has no reflex and a slow mode: a decay rate is met in a window
                return self._window(d)
            return np.nan  # no design meets this delay, nor (the answer does not fall with the delay) any longer one
        # the bracket first narrowed by every fraction already judged
        failing = [g for g, at in self.fails_from.items() if at <= d] + [g for g in self.margins if not self.met(g, d)]
        lo = max([f, *failing])
        hi = min([self.top] + [g for g in self.rooted if g > lo and self.met(g, d)])
        estimate = _inverse_interpolant(self.margins, d, self.met)
        return _bracket_root(lambda x: self.meets(x, d), estimate, lo, hi, self.width)

    def _window(self, d):
        """The least fraction that meets d where the top does not: the first of :data:`DECAY_SCAN` + 1 grid
        fractions in [0, top] that meets it, then bisected against the one below; NaN if none on the scan."""
        scan = [i * self.top / DECAY_SCAN for i in range(DECAY_SCAN + 1)]
        first = next((i for i, g in enumerate(scan) if self.meets(g, d)), None)
        if first is None:
            return np.nan
        if first == 0:
            return 0.0
        estimate = _inverse_interpolant(self.margins, d, self.met)
        return _bracket_root(lambda x: self.meets(x, d), estimate, scan[first - 1], scan[first], self.width)

    def margin_or_zero(self, f) -> float:
        """The exact margin at f [s]; 0 if unstable without delay."""
        exact = self.exact(f)
        return float(exact.margin) if exact.stable_without_delay else 0.0


def _answers(search: _Search, delays):
    """The search at every delay, ascending: (fraction, exact margin at it, rightmost root's Re) per delay."""
    f, out = 0.0, []
    for d in delays:
        f = search.answer(d, f)
        out.append(
            (np.nan, np.nan, np.nan) if np.isnan(f) else (f, float(search.exact(f).margin), search.root(f, d).real)
        )
    return tuple(np.array(x, float) for x in zip(*out, strict=True))


def chain_curve(model: Model, e: float, lam: float, pcsa, delays, kp=None, kd=None):
    """The chain at every delay: (fraction, k*, exact margin at it, rightmost root's Re) per delay.

    Parameters
    ----------
    model : Model
    e, lam : float
        E and Lambda [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        The global PCSA [m^2].
    delays : numpy.ndarray, shape (n_delays,)
        tau, ascending [s].
    kp, kd : float, optional
        Explicit gains for every joint.

    Returns
    -------
    fraction : numpy.ndarray, shape (n_delays,)
        f [1]; NaN where no fraction up to the top meets the delay.
    least : numpy.ndarray, shape (n_cor,)
        k* [N m/rad].
    margin : numpy.ndarray, shape (n_delays,)
        The exact margin at f [s].
    root : numpy.ndarray, shape (n_delays,)
        Re of the rightmost root at f and the delay, from the poles' seeds [1/s].
    """
    search = _Search(model, e, lam, pcsa, kp, kd)
    fraction, margin, root = _answers(search, delays)
    return fraction, search.least, margin, root


def chain_design(
    model: Model, eccentricity: float, lordosis: float, pcsa, activation: float, kp=None, kd=None, decay: float = 0.0
):
    """The chain: the least local stiffness f k* for which the delayed chain is stable at ``reflex.delay``.

    :func:`chain_curve` at the one delay (the answer is the curve's there), with the certificate's rightmost
    root from :data:`~spinectl.reflex.design.roots.SPECTRAL_NODES` Chebyshev nodes besides the poles' seeds,
    and the largest delay met over :data:`CHAIN_SCAN` fractions in [0, top] and those the search judged.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        The global PCSA [m^2] (NaN: no design).
    activation : float
        Its fraction of the minimum stabilising PCSA [1], for the report.
    kp, kd : float, optional
        Explicit gains for every joint.
    decay : float
        A least decay rate sigma [1/s]: the design meets the delay with every characteristic root at
        Re s < -sigma, judged on the loop shifted by sigma (:mod:`~spinectl.reflex.design.decay`); 0: stable
        at the delay. With sigma > 0, ``largest_delay`` is NaN (the shifted loop's gains hold one delay) and
        ``delay_margin`` and ``max_root_real`` are the chain's own, unshifted.

    Returns
    -------
    ChainDesign
    """
    n, delay = len(model.geometry.cor_names), model.reflex.delay
    if not np.all(np.isfinite(pcsa)):
        nan = np.full(n, np.nan)
        return ChainDesign(activation, np.nan, nan, nan, np.nan, np.nan, np.nan, "none: no global activation")
    e, lam = float(eccentricity), float(lordosis)
    search = _Search(model, e, lam, pcsa, kp, kd, decay)
    fraction = float(_answers(search, [delay])[0][0])
    scan = np.linspace(0.0, search.top, CHAIN_SCAN)
    # the shifted loop's margins hold its gains at this delay's e^{sigma tau}: they say nothing of other delays
    largest = max(search.margin_or_zero(f) for f in [*scan, *list(search.margins)])
    largest = largest if not decay > 0 else np.nan
    least = search.least
    if np.isnan(fraction):
        nan = np.full(n, np.nan)
        method = (
            f"no local stiffness up to {search.top:g} x k* (k*: the least for static stability) meets the delay"
            + (f" with decay rate {decay:g} 1/s" * (decay > 0))
        )
        return ChainDesign(activation, np.nan, nan, least, np.nan, np.nan, float(largest), method)
    ok = np.array([search.met(f, delay) for f in scan])
    upper = bool(np.all(ok[np.argmax(ok) :])) if ok.any() else True  # once met, met for every larger f
    method = "interpolated bisection: " + (
        "met for every larger fraction on the scan" if upper else "not monotone on the scan"
    )
    if decay > 0 and not search.met(search.top, delay):
        method = (
            f"the first of {DECAY_SCAN + 1} fractions in [0, {search.top:g}] with every root at Re s < -{decay:g} 1/s, "
            "then bisected: met in a window below the top, where the reflex handed over leaves a slow mode"
        )
    if decay > 0:  # the certificate in the shifted loop; the chain's own margin and root reported
        margin, root = _unshifted_certificate(search, fraction)
    else:
        root = search.root(fraction, delay, SPECTRAL_NODES)
        margin = float(search.exact(fraction).margin)
    return ChainDesign(activation, fraction, fraction * least, least, margin, float(root.real), float(largest), method)


def _unshifted_certificate(search: _Search, fraction: float):
    """The chain's own exact delay margin [s] and rightmost root at the delay [1/s] at f, without the shift."""
    k, dl, p, dd = chain_loop_at(search.model, search.chain, search.least, fraction, search.kp, search.kd)
    lag, delay = search.model.reflex.activation_time_constant, search.model.reflex.delay
    with arithmetic_guard(search.e, search.lam):
        root = rightmost_root(search.mass, k, dl, p, dd, delay, lag, SPECTRAL_NODES)
        if not (np.any(p) or np.any(dd)):  # no reflex: no delay to lose
            return (np.inf if root.real < 0 else 0.0), root
        return float(chain_delay_margin(search.mass, k, dl, p, dd, lag).margin), root


def _inverse_interpolant(margins, d, met):
    """An estimate of the fraction whose exact margin is d, from the margins already found, or None.

    Inverse interpolation: the fraction as a polynomial in the margin through the (up to) three fractions
    whose margins are nearest to d, among those whose margin is finite and agrees with the verdict at d (a
    margin that a crossing count overrules says nothing about where the verdict changes). Inverse quadratic
    interpolation is the step of Brent's method [1]_; the margin does not depend on the delay, so the
    fractions judged at shorter delays serve too.

    Returns
    -------
    callable
        () -> the estimate [1] or None (fewer than two such margins).

    References
    ----------
    .. [1] Brent RP (1973). Algorithms for Minimization without Derivatives, ch. 4. Prentice-Hall.
    """

    def estimate():
        known = [
            (abs(m.margin - d), g, m.margin)
            for g, m in margins.items()
            if m.stable_without_delay and np.isfinite(m.margin) and met(g, d) == (m.margin >= d)
        ]
        near: dict[float, float] = {}  # margin -> fraction, the nearest first, one fraction per margin
        for _, g, t in sorted(known):
            if len(near) < 3:
                near.setdefault(t, g)
        if len(near) < 2:
            return None
        # Lagrange's polynomial in the margin through the nearest (margin, fraction) pairs, at d
        return sum(g * np.prod([(d - u) / (t - u) for u in near if u != t]) for t, g in near.items())

    return estimate


def _bracket_root(meets, estimate, lo, hi, width):
    """The least f in (lo, hi] that meets, on the grid of ``width``: a safeguarded interpolation search on a bracket.

    ``lo`` fails and ``hi`` meets, both on the grid (multiples of ``width``); each step judges one grid
    fraction strictly inside the bracket and keeps the part that still brackets the change, so the answer
    is certified exactly as by bisection: it meets, and the grid fraction below it fails (``hi - lo`` is one
    ``width`` on return). The step is the estimate (:func:`_inverse_interpolant`) rounded to the grid and
    kept at least one step inside each end, so that, once the estimate is accurate, the next step lands on
    the other side of the change and closes the bracket; where the estimate is missing or outside the
    bracket, or the last three steps did not halve the bracket (a margin that jumps or bends, when the
    crossing that limits it changes), the step is the midpoint, as in bisection. Brent's method keeps its
    steps inside the bracket the same way [1]_. Correctness does not depend on the estimate, only the number
    of steps: at most four per halving. On the grid, the answer where the fractions that meet form an
    interval is its least grid point, whichever steps led there.

    Parameters
    ----------
    meets : callable
        f -> bool, the verdict at the delay.
    estimate : callable
        () -> the estimated change [1] or None, from the fractions judged so far.
    lo, hi : float
        A failing and a meeting fraction [1] on the grid, lo < hi.
    width : float
        The grid's step [1] (a power of 2 times the search's range, so that grid points are exact).

    Returns
    -------
    float
        ``hi`` at the end [1].

    References
    ----------
    .. [1] Brent RP (1973). Algorithms for Minimization without Derivatives, ch. 4. Prentice-Hall.
    """
    lo_i, hi_i = round(lo / width), round(hi / width)
    spans = [hi_i - lo_i]
    while hi_i - lo_i > 1:
        x = estimate()
        if x is None or not lo_i * width < x < hi_i * width or (len(spans) > 3 and spans[-1] > 0.5 * spans[-4]):
            i = (lo_i + hi_i) // 2
        else:
            i = min(max(round(x / width), lo_i + 1), hi_i - 1)
        lo_i, hi_i = (lo_i, i) if meets(i * width) else (i, hi_i)
        spans.append(hi_i - lo_i)
    return hi_i * width
