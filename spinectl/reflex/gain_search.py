"""The best diagonal reflex gains for the chain's delay margin, found by a seeded global search (docs/chain.md).

"Changing the gains does not rescue the chain" is a statement about every gain, so it needs a
search over the gains with the best found and a bound (docs/chain.md, "The delayed reflex").
:func:`search_chain_gains` searches the ten (n = 5) diagonal gains k_p,j, k_d,j > 0 of the
joint-wise reflex, the physiological family (each joint's muscles respond to that joint's angle
and angular velocity; full gain matrices would need inter-joint reflex pathways, not searched),
for the largest exact multivariable delay margin (:func:`spinectl.reflex.mimo.chain_delay_margin` [2]_):

1. differential evolution [3]_ from the rule's gains (:func:`spinectl.reflex.gains.chain_gains`) and a
   seeded Latin hypercube of log gains in a box of four decades around the chain's own scales
   (:func:`gain_box`);
2. Nelder-Mead [4]_ from its best, restarted while it gains, in log gains, bounded by the box.

The margin is 0 wherever the delay-free loop is unstable, so an objective of the margin alone
is flat there; :func:`objective` grades it by the rightmost delay-free root instead (the
search moves toward stability first), and the rule is kept if nothing beats it.

The bound beside it, :func:`single_mode_bound`, is Stépán's (1989) [1]_ for one inverted pendulum,
with the activation lag and the mode's damping (:func:`pendulum_delay_bound`), at each
unstable mode of the chain: the longest delay with which any delayed PD on that mode alone
holds it. It bounds the chain's margin under modal feedback where the modes decouple
(M, K, D simultaneously diagonalisable); it is not a proof over diagonal or full joint gains
of the coupled chain, whose other states can act as filters on the loop.

References
----------
.. [1] Stépán G (1989). Retarded Dynamical Systems: Stability and Characteristic Functions.
   Longman Scientific & Technical, Harlow.
.. [2] Louisell J (2001). A matrix method for determining the imaginary axis eigenvalues of a
   delay system. IEEE Trans Autom Control 46(12):2008-2012. doi:10.1109/9.975511.
.. [3] Storn R, Price K (1997). Differential evolution - a simple and efficient heuristic for
   global optimization over continuous spaces. J Glob Optim 11:341-359.
   doi:10.1023/A:1008202821328.
.. [4] Lagarias JC, Reeds JA, Wright MH, Wright PE (1998). Convergence properties of the
   Nelder-Mead simplex method in low dimensions. SIAM J Optim 9(1):112-147.
   doi:10.1137/S1052623496303470.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.stats

from ..errors import ParameterError
from ..model.linear_chain import LinearChain
from ..model.params import Model
from ..optimise.coupled import coupled_stability_at
from .gains import chain_gains
from .margins import operating_point
from .mimo import chain_delay_margin, delay_free_poles

DECADES = 2.0
"""Half-width of the search box in decades of each gain around its scale (:func:`gain_box`)."""

UNSTABLE_OFFSET = 1.0
"""Objective of a delay-free unstable loop: this plus its rightmost root times the time scale [1]."""


def pendulum_delay_bound(stiffness, inertia, lag=0.0, damping=0.0):
    """The longest delay with which any delayed PD can hold theta phi'' = S phi + D phi' [s].

    theta phi'' = S phi + D phi' + u, T_a u' + u = -(k_p phi + k_d phi')(t - tau). The stable
    region of the (k_p, k_d) plane borders the line k_p = S (a root at s = 0); the curve of
    roots s = j w leaves that line into k_p > S, so that a stable region lies between them, only
    if the real part of k_p(w) + j w k_d(w) = (1 + j w T_a)(theta w^2 + S + j D w) exp(j w tau)
    grows from S, k_p(w) = S + w^2 (theta - T_a D - D tau - S (tau^2/2 + T_a tau)) + O(w^4)
    (Stépán's argument [1]_; with T_a = D = 0 his sqrt(2 theta / S)). So tau is below the
    positive root of S tau^2 / 2 + (S T_a + D) tau - (theta - T_a D) = 0; the exact margin of
    gains near (S, sqrt(2 theta S)) approaches it (docs/reflex.md).

    Parameters
    ----------
    stiffness : array_like
        S > 0 [N m/rad] (the pendulum's unstable stiffness).
    inertia : array_like
        theta > 0 [kg m^2].
    lag : array_like, optional
        T_a >= 0 [s].
    damping : array_like, optional
        D [N m s/rad], the sign convention of :mod:`spinectl.model.chain` (D < 0 damps).

    Returns
    -------
    numpy.ndarray or float
        [s]; inf where S <= 0 (no unstable pendulum to hold).

    References
    ----------
    .. [1] Stépán G (1989). Retarded Dynamical Systems: Stability and Characteristic Functions.
       Longman Scientific & Technical, Harlow.
    """
    s, theta, lag, d = np.broadcast_arrays(*(np.asarray(x, float) for x in (stiffness, inertia, lag, damping)))
    a = np.where(s > 0, s, 1.0) / 2.0
    b = s * lag + d
    c = theta - lag * d
    root = 2.0 * c / (b + np.sqrt(b * b + 4.0 * a * c))  # the positive root, without cancellation
    out = np.where(s > 0, root, np.inf)
    return out[()] if out.ndim == 0 else out


@dataclass(frozen=True)
class ModeBound:
    """The single-mode bound of :func:`single_mode_bound`.

    Attributes
    ----------
    bound : float
        The least :func:`pendulum_delay_bound` over the chain's unstable modes [s]; inf if none.
    rate : float
        That mode's rate sqrt(lambda) [1/s], lambda its eigenvalue of K v = lambda M v.
    damping : float
        Its modal damping v^T D v, v M-normalised [N m s/rad per kg m^2] (negative damps).
    coupling : float
        The largest off-diagonal element of V^T D V relative to the largest diagonal one [1]: 0
        where the modes decouple, and the bound is then exact for modal feedback.
    """

    bound: float
    rate: float
    damping: float
    coupling: float


def single_mode_bound(chain: LinearChain, lag: float = 0.0, u=()) -> ModeBound:
    """:func:`pendulum_delay_bound` of each unstable mode of the chain alone; the least of them.

    The modes are those of the undamped chain, K v = lambda M v (M-normalised, v^T M v = 1); mode
    k is the pendulum eta'' = lambda_k eta + c_k eta' + v_k^T u with c_k = v_k^T D v_k. Where
    V^T D V is diagonal the chain is these pendulums side by side, and no delayed PD acting on a
    mode alone (modal feedback) holds it beyond its bound. It is not a bound over the joints'
    diagonal gains or full gain matrices of the coupled chain: through the other modes a static
    joint-space gain acts as a dynamic controller on this one.

    Parameters
    ----------
    chain : LinearChain
        M, K(u), D(u) (fixed at an activation with :meth:`LinearChain.at`, ``u`` empty).
    lag : float, optional
        T_a [s].
    u : array_like, shape (m,)
        The controls [control unit].

    Returns
    -------
    ModeBound

    References
    ----------
    .. [1] Stépán G (1989). Retarded Dynamical Systems: Stability and Characteristic Functions.
       Longman Scientific & Technical, Harlow.
    """
    values, vectors = scipy.linalg.eigh(chain.stiffness(u), chain.mass_matrix)
    modal = vectors.T @ chain.damping(u) @ vectors
    c = np.diag(modal)
    bounds = pendulum_delay_bound(values, 1.0, lag, c)
    k = int(np.argmin(bounds))
    off = modal - np.diag(c)
    coupling = float(np.max(np.abs(off)) / max(np.max(np.abs(c)), np.finfo(float).tiny))
    if not np.isfinite(bounds[k]):
        return ModeBound(np.inf, np.nan, np.nan, coupling)
    return ModeBound(float(bounds[k]), float(np.sqrt(values[k])), float(c[k]), coupling)


def gain_box(chain: LinearChain, u=(), decades: float = DECADES) -> tuple[np.ndarray, np.ndarray]:
    """The search box in log10 gains: each gain within ``decades`` of its joint's scale.

    The scale of k_p,j is s_j = max(abs(K[j, j]), abs(K) row sum over the others): the stiffness the
    joint's reflex works against; that of k_d,j is sqrt(M[j, j] s_j), the derivative gain of
    critical damping of the joint alone.

    Parameters
    ----------
    chain : LinearChain
    u : array_like, shape (m,)
        The controls [control unit].
    decades : float, optional
        Half-width [decades].

    Returns
    -------
    lower, upper : numpy.ndarray, shape (2 n,)
        log10 of (k_p [N m/rad], k_d [N m s/rad]), k_p first.
    """
    stiffness = np.abs(chain.stiffness(u))
    scale = np.maximum(np.diag(stiffness), stiffness.sum(axis=1) - np.diag(stiffness))
    scale = np.where(scale > 0, scale, 1.0)
    centre = np.log10(np.concatenate([scale, np.sqrt(np.diag(chain.mass_matrix) * scale)]))
    return centre - decades, centre + decades


def objective(chain: LinearChain, log_gains, lag: float, time_scale: float, u=()) -> tuple[float, float]:
    """The value the search minimises at log10 gains, and the exact delay margin there.

    -tau_m / time_scale where the delay-free loop is stable (tau_m the exact margin,
    :func:`~spinectl.reflex.mimo.chain_delay_margin`; inf counts as -1e3); where it is
    unstable, :data:`UNSTABLE_OFFSET` + the rightmost delay-free root times ``time_scale``:
    positive, so worse than any stable loop, and smaller the nearer the loop is to stability.

    Parameters
    ----------
    chain : LinearChain
    log_gains : array_like, shape (2 n,)
        log10 of (k_p [N m/rad], k_d [N m s/rad]).
    lag : float
        T_a [s].
    time_scale : float
        [s], e.g. the single-mode bound.
    u : array_like, shape (m,)
        The controls [control unit].

    Returns
    -------
    value : float
        [1].
    margin : float
        [s]; 0 where unstable without delay, NaN undefined.
    """
    n = chain.n_joints
    gains = 10.0 ** np.asarray(log_gains, float)
    kp, kd = gains[:n], gains[n:]
    mass, stiffness, damping = chain.mass_matrix, chain.stiffness(u), chain.damping(u)
    poles = delay_free_poles(mass, stiffness, damping, kp, kd, lag)
    rightmost = float(np.max(poles.real))
    if not rightmost < -1e-12 * max(1.0, float(np.max(np.abs(poles)))):
        return UNSTABLE_OFFSET + max(rightmost, 0.0) * time_scale, 0.0
    margin = float(chain_delay_margin(mass, stiffness, damping, kp, kd, lag).margin)
    if np.isnan(margin):
        return np.inf, margin
    return -min(margin / time_scale, 1e3), margin


@dataclass(frozen=True)
class GainSearch:
    """The best diagonal reflex gains found for the chain's exact delay margin.

    Attributes
    ----------
    kp, kd : numpy.ndarray, shape (n,)
        The best gains found [N m/rad], [N m s/rad] (the rule's if nothing beat them).
    margin : float
        Their exact delay margin [s]; a lower bound on the best over all diagonal gains.
    rule_kp, rule_kd : numpy.ndarray, shape (n,)
        The rule's gains [N m/rad], [N m s/rad].
    rule_margin : float
        The rule's exact delay margin [s] (0 if unstable without delay).
    bound : ModeBound
        The single-mode bound [s] (a bound for one mode under modal feedback, not over joint gains).
    evaluations : int
        Exact margins (or delay-free root checks) computed.
    seed : int
        The seed of the Latin hypercube.
    lag : float
        T_a [s].
    """

    kp: np.ndarray
    kd: np.ndarray
    margin: float
    rule_kp: np.ndarray
    rule_kd: np.ndarray
    rule_margin: float
    bound: ModeBound
    evaluations: int
    seed: int
    lag: float

    def to_dict(self) -> dict:
        """The result as JSON-ready numbers.

        Returns
        -------
        dict
            ``kp_Nm_per_rad``, ``kd_Nms_per_rad``, ``delay_margin_s``, ``rule_kp_Nm_per_rad``,
            ``rule_kd_Nms_per_rad``, ``rule_delay_margin_s``, ``single_mode_bound_s``,
            ``bound_mode_rate_per_s``, ``bound_mode_damping``, ``bound_modal_coupling``,
            ``evaluations``, ``seed``, ``activation_time_constant_s``.
        """
        return {
            "kp_Nm_per_rad": self.kp.tolist(),
            "kd_Nms_per_rad": self.kd.tolist(),
            "delay_margin_s": self.margin,
            "rule_kp_Nm_per_rad": self.rule_kp.tolist(),
            "rule_kd_Nms_per_rad": self.rule_kd.tolist(),
            "rule_delay_margin_s": self.rule_margin,
            "single_mode_bound_s": self.bound.bound,
            "bound_mode_rate_per_s": self.bound.rate,
            "bound_mode_damping": self.bound.damping,
            "bound_modal_coupling": self.bound.coupling,
            "evaluations": self.evaluations,
            "seed": self.seed,
            "activation_time_constant_s": self.lag,
        }


def population_members(population: int, n_joints: int) -> int:
    """The differential evolution's members for ``population`` per gain: ``population`` x 2 n, at least 5.

    Parameters
    ----------
    population : int
        Members per parameter (scipy's ``popsize``) [1].
    n_joints : int
        Joints n; the search has 2 n parameters, k_p and k_d per joint.

    Returns
    -------
    int
        The members of the Latin hypercube that starts the evolution [1].
    """
    return max(int(population) * 2 * int(n_joints), 5)


def search_chain_gains(
    chain: LinearChain,
    rule_kp,
    rule_kd,
    lag: float = 0.0,
    u=(),
    seed: int = 0,
    population: int = 10,
    generations: int = 12,
    restarts: int = 8,
    restart_evaluations: int = 400,
) -> GainSearch:
    """The largest exact delay margin of the chain over positive diagonal gains: a seeded search (see the module).

    Differential evolution (scipy.optimize.differential_evolution, its population a seeded Latin
    hypercube in :func:`gain_box` with the rule's gains as its first member) finds the stable
    region and a good basin; Nelder-Mead, restarted from its own result with a fresh simplex
    (the margin is the least of several critical delays, so a simplex collapses on a kink),
    climbs it until a restart gains less than 1e-4 of the margin or ``restarts`` are spent.

    Parameters
    ----------
    chain : LinearChain
        M, K(u), D(u); fixed at an activation (:meth:`LinearChain.at`), ``u`` empty.
    rule_kp, rule_kd : array_like, shape (n,)
        The rule's gains [N m/rad], [N m s/rad], the reference and a start (a zero starts at its scale,
        :func:`gain_box`, and everything is clipped to the box).
    lag : float, optional
        T_a [s].
    u : array_like, shape (m,)
        The controls [control unit].
    seed : int, optional
        Seed of the Latin hypercube and of the evolution; the same seed gives the same result.
    population : int, optional
        Members per parameter (scipy's ``popsize``), >= 1.
    generations : int, optional
        Generations of the evolution (``maxiter``), >= 0.
    restarts : int, optional
        Nelder-Mead runs at most, >= 0.
    restart_evaluations : int, optional
        Objective evaluations per run, >= 1.

    Returns
    -------
    GainSearch

    Raises
    ------
    ParameterError
        The rule's gains are not one per joint, or a budget is below its least.

    References
    ----------
    .. [1] Storn R, Price K (1997). Differential evolution - a simple and efficient heuristic for
       global optimization over continuous spaces. J Glob Optim 11:341-359.
       doi:10.1023/A:1008202821328.
    .. [2] Lagarias JC, Reeds JA, Wright MH, Wright PE (1998). Convergence properties of the
       Nelder-Mead simplex method in low dimensions. SIAM J Optim 9(1):112-147.
       doi:10.1137/S1052623496303470.
    """
    n = chain.n_joints
    rule_kp, rule_kd = (np.asarray(x, float) for x in (rule_kp, rule_kd))
    for name, x in (("rule_kp", rule_kp), ("rule_kd", rule_kd)):
        if x.shape != (n,) or not np.all(np.isfinite(x)) or np.any(x < 0):
            raise ParameterError(name, f"must be {n} finite gains >= 0, one per joint (got {x!r})")
    budgets = (
        ("population", population, 1), ("generations", generations, 0),
        ("restarts", restarts, 0), ("restart_evaluations", restart_evaluations, 1),
    )  # fmt: skip
    for name, value, least in budgets:
        if not isinstance(value, (int, np.integer)) or value < least:
            raise ParameterError(name, f"must be an integer >= {least} (got {value!r})")
    bound = single_mode_bound(chain, lag, u)
    scale = bound.bound if np.isfinite(bound.bound) else 1.0
    rule = chain_delay_margin(chain.mass_matrix, chain.stiffness(u), chain.damping(u), rule_kp, rule_kd, lag)
    rule_margin = float(rule.margin) if rule.stable_without_delay else 0.0
    lower, upper = gain_box(chain, u)
    seen: dict[bytes, tuple[float, float]] = {}

    def f(x):
        x = np.clip(x, lower, upper)
        key = x.tobytes()
        if key not in seen:
            seen[key] = objective(chain, x, lag, scale, u)
        return seen[key][0]

    rng = np.random.default_rng(seed)
    members = population_members(population, n)
    start = scipy.stats.qmc.scale(scipy.stats.qmc.LatinHypercube(d=2 * n, seed=rng).random(members), lower, upper)
    rule_gains = np.concatenate([rule_kp, rule_kd])
    # a gain the rule sets to 0 starts at its scale: at the box's floor its effect (and the grading's slope) vanishes
    centre = 0.5 * (lower + upper)
    start[0] = np.clip(np.log10(np.where(rule_gains > 0, rule_gains, 10.0**centre)), lower, upper)
    x, value = start[0], f(start[0])
    if generations > 0:
        evolved = scipy.optimize.differential_evolution(
            f, list(zip(lower, upper, strict=True)), maxiter=int(generations), init=start, seed=rng,
            polish=False, tol=0.0,
        )  # fmt: skip
        x, value = evolved.x, float(evolved.fun)
    for _ in range(int(restarts)):
        run = scipy.optimize.minimize(
            f, x, method="Nelder-Mead", bounds=list(zip(lower, upper, strict=True)),
            options={"maxfev": int(restart_evaluations), "xatol": 1e-6, "fatol": 1e-9, "adaptive": True},
        )  # fmt: skip
        gained = value - float(run.fun)
        if gained > 0:
            x, value = np.clip(run.x, lower, upper), float(run.fun)
        if not gained > 1e-4 * abs(value):
            break
    margin = seen[np.clip(x, lower, upper).tobytes()][1]
    if not margin > rule_margin:  # nothing beat the rule (its zeros lie outside the box)
        kp, kd, margin = rule_kp, rule_kd, rule_margin
    else:
        gains = 10.0**x
        kp, kd = gains[:n], gains[n:]
    return GainSearch(
        kp=kp, kd=kd, margin=margin, rule_kp=rule_kp, rule_kd=rule_kd, rule_margin=rule_margin,
        bound=bound, evaluations=len(seen) + 1, seed=int(seed), lag=float(lag),
    )  # fmt: skip


def search_gains_at(
    model: Model, eccentricity: float, lordosis: float, activation=None, lag=None, seed: int = 0, **budget
) -> GainSearch:
    """:func:`search_chain_gains` on the paper's chain at the operating point of ``spinectl margins --coupled``.

    The chain at ``activation`` times the per-segment optimum
    (:func:`spinectl.reflex.margins.operating_point`,
    :func:`spinectl.optimise.coupled.coupled_stability_at`), the rule's gains
    :func:`spinectl.reflex.gains.chain_gains` as the reference, as in
    :func:`spinectl.reflex.chain_margins.coupled_margins`.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    activation : float, optional
        Fraction of the per-segment optimum [1]; ``model.reflex.activation`` by default.
    lag : float, optional
        T_a [s]; ``model.reflex.activation_time_constant`` by default.
    seed : int, optional
        As in :func:`search_chain_gains`.
    **budget
        ``population``, ``generations``, ``restarts``, ``restart_evaluations`` of :func:`search_chain_gains`.

    Returns
    -------
    GainSearch

    Raises
    ------
    ModelError
        No per-segment optimum at (E, Lambda).
    ParameterError
        E, Lambda or a budget out of range.
    """
    settings = model.reflex
    activation = settings.activation if activation is None else float(activation)
    lag = settings.activation_time_constant if lag is None else float(lag)
    point = operating_point(model, eccentricity, lordosis, activation)
    chain = coupled_stability_at(model, eccentricity, lordosis, point.pcsa if point.ok else None)
    kp, kd = chain_gains(
        chain.mass, chain.stiffness, chain.damping, chain.local.local_stiffness,
        settings.gain_factor, settings.damping_ratio,
    )  # fmt: skip
    return search_chain_gains(chain.linear_chain, kp, kd, lag, seed=seed, **budget)
