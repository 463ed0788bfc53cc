"""Nonlinear time-domain simulation of one segment, or of the chain, under a reflex with the true delay.

The plant is the paper's equation of motion for CoR k (Methods):

    theta alpha'' = sum_i PCSA_i M_i(alpha, omega) + M_ext(alpha) + CT_k - K alpha + u(t),

with the muscle torques of :func:`spinectl.model.mechanics.muscle_torque_per_pcsa`, gravity
from :func:`spinectl.model.mechanics.gravity_torque`, the passive stiffness K of
:func:`spinectl.model.mechanics.passive_stiffness` and the constant counter torque CT_k that
makes upright an equilibrium. The reflex command -(kp alpha + kd omega)(t - tau) becomes the
torque u through the activation lag T_a u' + u = command (docs/reflex.md, "The loop", "Force
generation: the activation lag" and "Nonlinear simulation with the true delay").

Integration: classical Runge-Kutta with a fixed step and a history buffer; delayed
states between grid points come from cubic Hermite interpolation (alpha with slope
omega, omega with slope omega'), which keeps the scheme fourth order. The step is cut
to the delay when the delay is shorter, so every delayed time is already computed.
Before t = 0 the segment is held at the perturbation angle at rest, then released.
Runs are batched: every array argument broadcasts to a batch of independent runs.

The chain runs through the same integrator, one run per joint (:func:`simulate_chain`): the
linearised :class:`ChainPlant` or the nonlinear :class:`NonlinearChainPlant`, M(q) q'' +
c(q, q') = tau(q, q') + u (docs/chain.md, "Nonlinear simulation").
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..model import chain, geometry, mechanics
from ..model.params import Model, Reflex

MAX_STEPS = 1_000_000
"""Most time steps of one simulation: four arrays of this many rows per run, about a minute of work."""

_NOISE = np.sqrt(np.finfo(float).eps)
"""A response that decays below this fraction of its perturbation is in rounding noise: stable."""


@dataclass(frozen=True)
class SegmentPlant:
    """The nonlinear mechanics of one segment at a fixed activation.

    Attributes
    ----------
    model : Model
    cor : numpy.ndarray, shape (2,)
        Position of the CoR [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        PCSA of each muscle [m^2].
    inertia : float
        theta_k [kg m^2].
    passive_stiffness : float
        K as a physical stiffness [N m/rad].
    name : str
        Name of the CoR.
    counter_torque : float
        CT_k = -(sum_i M_i + M_ext) upright [N m] (paper, Methods).
    fibres : tuple of numpy.ndarray
        Upper and lower attachments of every fibre [m] and its isometric force f_iso [N]
        (:func:`spinectl.model.geometry.all_fibres`, PCSA shares times the specific tension).
    """

    model: Model
    cor: np.ndarray
    pcsa: np.ndarray
    inertia: float
    passive_stiffness: float
    name: str
    counter_torque: float
    fibres: tuple

    def torque(self, alpha, omega):
        """Net torque without the reflex [N m], the counter torque included: zero upright.

        sum_i M_i + M_ext + CT_k - K alpha (paper, Methods). The counter torque is
        computed with the same expression at (0, 0) (see :func:`segment_plant`), so
        the equilibrium is exact to rounding and small responses are not swamped by
        a constant offset.

        Parameters
        ----------
        alpha, omega : array_like
            Angle [rad] and angular velocity [rad/s] of the segment.

        Returns
        -------
        numpy.ndarray
            The torque [N m], the broadcast shape of ``alpha`` and ``omega``; 0 (to
            rounding) at alpha = omega = 0.
        """
        return _torque_without_ct(self, alpha, omega) + self.counter_torque

    def acceleration(self, alpha, omega, torque):
        """alpha'' = (net torque + reflex torque) / theta [rad/s^2] (paper, Methods).

        Parameters
        ----------
        alpha, omega, torque : array_like
            Angle [rad], angular velocity [rad/s] and reflex torque [N m], one entry per run.

        Returns
        -------
        numpy.ndarray
            [rad/s^2], the broadcast shape.
        """
        return (self.torque(alpha, omega) + torque) / self.inertia


def _torque_without_ct(plant: SegmentPlant, alpha, omega):
    """sum_i M_i + M_ext - K alpha [N m]: M_i = h_i f_l f_H per unit f_iso times each fibre's f_iso."""
    upper, lower, f_iso = plant.fibres
    alpha, omega = np.asarray(alpha, float), np.asarray(omega, float)
    m = plant.model
    per_fiso = mechanics.fibre_torque(alpha[..., None], omega[..., None], upper, lower, plant.cor, m.fibre, m.errata)
    gravity = mechanics.gravity_torque(alpha, plant.cor, m)
    return per_fiso @ f_iso + gravity - plant.passive_stiffness * alpha


def segment_plant(model: Model, eccentricity: float, lordosis: float, segment, pcsa) -> SegmentPlant:
    """The :class:`SegmentPlant` of one CoR at a configuration and activation.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    segment : int or str
        Index or name of the CoR.
    pcsa : array_like, shape (n_muscles,)
        PCSA of each muscle [m^2].

    Returns
    -------
    SegmentPlant
        The CoR [m], its inertia [kg m^2] and passive stiffness [N m/rad], each fibre's
        f_iso [N] and the counter torque [N m] that makes upright an equilibrium.
    """
    names = model.geometry.cor_names
    if isinstance(segment, str):
        if segment not in names:
            raise ParameterError("segment", f"must be one of {', '.join(names)} (got {segment!r})")
        segment = names.index(segment)
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)[segment]
    theta = float(mechanics.inertia(cor, model))
    pcsa = np.asarray(pcsa, float)
    upper, lower, share = geometry.all_fibres(model)
    plant = SegmentPlant(
        model=model,
        cor=cor,
        pcsa=pcsa,
        inertia=theta,
        passive_stiffness=float(mechanics.passive_stiffness(model, theta)),
        name=names[segment],
        counter_torque=0.0,
        fibres=(upper, lower, model.fibre.specific_tension * share @ pcsa),
    )
    return dataclasses.replace(plant, counter_torque=float(-_torque_without_ct(plant, 0.0, 0.0)))


@dataclass(frozen=True)
class Simulation:
    """A batch of simulated responses.

    Attributes
    ----------
    time : numpy.ndarray, shape (n,)
        [s].
    alpha, omega, reflex_torque : numpy.ndarray, shape (batch, n)
        Angle [rad], angular velocity [rad/s], reflex torque u [N m]; frozen after divergence.
    delay, kp, kd : numpy.ndarray, shape (batch,)
        [s], [N m/rad], [N m s/rad].
    diverged : numpy.ndarray of bool, shape (batch,)
        abs(alpha) exceeded ``sim_divergence``.
    growth_rate : numpy.ndarray, shape (batch,)
        Growth of the peak abs(alpha) from the middle to the last third [1/s]; inf if diverged.
    """

    time: np.ndarray
    alpha: np.ndarray
    omega: np.ndarray
    reflex_torque: np.ndarray
    delay: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    diverged: np.ndarray
    growth_rate: np.ndarray

    @property
    def stable(self) -> np.ndarray:
        """The verdict: the response shrinks (growth rate < 0) and never diverged."""
        return self.growth_rate < 0


def _delayed(t_query, step, k, alpha, omega, acc, start):
    """(alpha, omega) at t_query per run, by cubic Hermite between grid points 0..k.

    alpha uses the slope omega, omega the slope omega'; before t = 0 the history is
    (start, 0), the segment held still.
    """
    pos = t_query / step
    i = np.floor(np.clip(pos, 0, max(k - 1, 0))).astype(int)  # clip first: a delay of 1e62 s casts badly
    j = np.minimum(i + 1, k)
    u = np.clip(pos - i, 0.0, 1.0)
    runs = np.arange(alpha.shape[1])
    h00, h10, h01, h11 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u, -2 * u**3 + 3 * u**2, u**3 - u**2
    w_i, w_j = omega[i, runs], omega[j, runs]
    a = h00 * alpha[i, runs] + h10 * step * w_i + h01 * alpha[j, runs] + h11 * step * w_j
    w = h00 * w_i + h10 * step * acc[i, runs] + h01 * w_j + h11 * step * acc[j, runs]
    before = t_query <= 0
    return np.where(before, start, a), np.where(before, 0.0, w)


def growth_rate(time, alpha, perturbation: float):
    """Growth rate [1/s] of the peak abs(alpha) from the middle to the last third of the run.

    ln(max over the last third / max over the middle third) / (duration / 3): the
    transient of the first third is skipped; the windows should span an oscillation
    period. A response below sqrt(machine epsilon) times the perturbation is rounding
    noise and counts as decayed (-inf).

    Parameters
    ----------
    time : numpy.ndarray, shape (n,)
        [s].
    alpha : numpy.ndarray, shape (batch, n)
        Angles [rad].
    perturbation : float
        Initial angle [rad].

    Returns
    -------
    numpy.ndarray, shape (batch,)
        The growth rate [1/s]; -inf where the response is rounding noise.
    """
    n = time.size
    a, b = n // 3, 2 * n // 3
    middle = np.max(np.abs(alpha[:, a:b]), axis=-1)
    last = np.max(np.abs(alpha[:, b:]), axis=-1)
    span = time[-1] - time[b - 1] if n > 3 else time[-1]
    with np.errstate(divide="ignore"):
        rate = np.log(last / middle) / span
    return np.where(last < _NOISE * perturbation, -np.inf, rate)


def simulate(plant, kp, kd, delay, settings: Reflex, perturbation=None) -> Simulation:
    """Simulate the segment under the delayed, lagged reflex; arrays broadcast to a batch of runs.

    The reflex command -(kp alpha + kd omega)(t - tau) becomes the torque u through the
    activation lag T_a u' + u = command (``settings.activation_time_constant``; u is the
    command itself for T_a = 0). The lag starts at rest on the held history, u(0) = -kp alpha(0).

    Parameters
    ----------
    plant : SegmentPlant, ChainPlant or NonlinearChainPlant
        Anything with ``acceleration(alpha, omega, torque)`` over the runs.
    kp, kd, delay : array_like
        Reflex gains [N m/rad], [N m s/rad] and delay [s]; kp = kd = 0 is "no reflex".
    settings : Reflex
        ``sim_duration``, ``sim_time_step``, ``sim_perturbation``, ``sim_divergence`` and
        ``activation_time_constant``.
    perturbation : float or array_like, optional
        Initial angle [rad] instead of ``settings.sim_perturbation``; one per run for a batch.

    Returns
    -------
    Simulation
        Time [s], alpha [rad], omega [rad/s] and the reflex torque [N m] of every run,
        shape (batch, n), with the divergence flags and growth rates [1/s].

    Raises
    ------
    ParameterError
        A negative or non-finite delay, or more than :data:`MAX_STEPS` steps (the step is cut
        to the delay and to half the activation time constant).
    """
    kp, kd, tau = (
        np.ravel(x) for x in np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, float)) for v in (kp, kd, delay)))
    )
    if np.any(tau < 0) or not np.all(np.isfinite(tau)):
        raise ParameterError("delay", "must be finite and >= 0")
    start = settings.sim_perturbation if perturbation is None else np.asarray(perturbation, float)
    lag = settings.activation_time_constant
    step, n = _steps(settings, tau, lag)
    time = np.arange(n + 1) * step
    alpha, omega, acc, u_hist = (np.zeros((n + 1, tau.size)) for _ in range(4))
    alpha[0] = start
    force = -kp * start  # the lag at rest on the held history (unused without the lag)
    diverged = np.zeros(tau.size, bool)

    def accel(t, a, w, f, k):
        """omega' and the torque applied; with the lag, f is the torque and the command drives f'."""
        delayed_a, delayed_w = _delayed(t - tau, step, k, alpha, omega, acc, start)
        now = tau == 0  # no delay: the reflex sees the stage's own state
        u = -(kp * np.where(now, a, delayed_a) + kd * np.where(now, w, delayed_w))
        if lag > 0:
            return plant.acceleration(a, w, f), f, (u - f) / lag
        return plant.acceleration(a, w, u), u, 0.0

    for k in range(n):
        t, a, w = time[k], alpha[k], omega[k]
        acc[k], u_hist[k], df1 = accel(t, a, w, force, k)
        a2, w2, f2 = a + 0.5 * step * w, w + 0.5 * step * acc[k], force + 0.5 * step * df1
        k2, _, df2 = accel(t + 0.5 * step, a2, w2, f2, k)
        a3, w3, f3 = a + 0.5 * step * w2, w + 0.5 * step * k2, force + 0.5 * step * df2
        k3, _, df3 = accel(t + 0.5 * step, a3, w3, f3, k)
        a4, w4, f4 = a + step * w3, w + step * k3, force + step * df3
        k4, _, df4 = accel(t + step, a4, w4, f4, k)
        new_a = a + step / 6 * (w + 2 * w2 + 2 * w3 + w4)
        new_w = w + step / 6 * (acc[k] + 2 * k2 + 2 * k3 + k4)
        force = force + step / 6 * (df1 + 2 * df2 + 2 * df3 + df4)
        diverged |= np.abs(new_a) > settings.sim_divergence
        alpha[k + 1] = np.where(diverged, a, new_a)
        omega[k + 1] = np.where(diverged, w, new_w)
        if diverged.all():
            alpha[k + 2 :], omega[k + 2 :], u_hist[k + 1 :] = alpha[k + 1], omega[k + 1], u_hist[k]
            break
    else:
        u_hist[n] = accel(time[n], alpha[n], omega[n], force, n)[1]
    rate = np.where(diverged, np.inf, growth_rate(time, alpha.T, start))
    return Simulation(time, alpha.T, omega.T, u_hist.T, tau, kp, kd, diverged, rate)


def _steps(settings: Reflex, tau, lag: float) -> tuple[float, int]:
    """The fixed step [s], at most the shortest positive delay and half the lag, and the number of steps."""
    positive = tau[tau > 0]
    step = min(settings.sim_time_step, positive.min()) if positive.size else settings.sim_time_step
    limit = "reflex.delay"
    if 0 < lag < 2 * step:  # explicit RK4 on u' = (command - u) / T_a needs a step below about 2.8 T_a
        step, limit = 0.5 * lag, "reflex.activation_time_constant"
    n = int(np.ceil(settings.sim_duration / step))
    if n > MAX_STEPS:
        raise ParameterError(
            limit,
            f"a simulation of {settings.sim_duration:g} s with steps of {step:g} s (at most the delay, and half "
            f"the activation time constant) needs {n} steps, more than {MAX_STEPS}; use a longer delay or "
            "activation time constant, or a shorter sim_duration",
        )
    return step, n


def simulated_delay_margin(plant: SegmentPlant, kp, kd, settings: Reflex, low, high, batch=8, rounds=3):
    """Bracket the delay where the simulated closed loop turns unstable.

    Each round simulates ``batch`` delays spread evenly inside [low, high] in one
    batched run and keeps the interval between the last stable and the first unstable
    one; ``batch = 1`` is plain bisection. The bracket shrinks by batch + 1 per round.

    Parameters
    ----------
    plant : SegmentPlant
    kp, kd : float
        Reflex gains [N m/rad], [N m s/rad].
    settings : Reflex
        Simulation settings (see :func:`simulate`).
    low, high : float
        Initial bracket of delays [s]: stable at ``low``, unstable at ``high``.
    batch, rounds : int
        Delays simulated per round, and rounds.

    Returns
    -------
    low, high : float
        Delays [s] with the simulation stable at ``low`` and unstable at ``high``
        (the initial bracket must be so).
    """
    return _bracket(lambda delays: simulate(plant, kp, kd, delays, settings).stable, low, high, batch, rounds)


def simulated_chain_delay_margin(plant, kp, kd, settings: Reflex, perturbation, low, high, batch=8, rounds=3):
    """Bracket the delay where the simulated chain turns unstable, as :func:`simulated_delay_margin`.

    Parameters
    ----------
    plant : ChainPlant or NonlinearChainPlant
    kp, kd : array_like, shape (n,)
        Gains per joint [N m/rad], [N m s/rad].
    settings : Reflex
        Simulation settings (see :func:`simulate`).
    perturbation : array_like, shape (n,)
        Initial joint angles [rad] (see :func:`simulate_chain`).
    low, high : float
        Initial bracket of delays [s]: stable at ``low``, unstable at ``high``.
    batch, rounds : int
        Delays simulated per round, and rounds.

    Returns
    -------
    low, high : float
        Delays [s] with the simulated chain stable at ``low`` and unstable at ``high``.
    """
    return _bracket(
        lambda delays: simulate_chain(plant, kp, kd, delays, settings, perturbation)[1], low, high, batch, rounds
    )


def _bracket(stable_at, low, high, batch, rounds):
    """Shrink [low, high] by batch + 1 per round: keep the last stable and the first unstable delay."""
    for _ in range(rounds):
        delays = np.linspace(low, high, batch + 2)[1:-1]
        stable = stable_at(delays)
        first_unstable = int(np.argmin(stable)) if not stable.all() else batch
        grid = np.concatenate([[low], delays, [high]])
        low, high = grid[first_unstable], grid[first_unstable + 1]
    return float(low), float(high)


def _per_chain(n: int, alpha, omega, torque):
    """The runs (batch * n,), joint fastest, as (batch, n) arrays of angles, velocities and torques."""
    return (np.broadcast_to(x, np.shape(alpha)).reshape(-1, n) for x in (alpha, omega, torque))


@dataclass(frozen=True)
class ChainPlant:
    """The linearised chain M q'' = K q + D q' + u (docs/chain.md, "Dynamic stability") for :func:`simulate`.

    Its runs are the joints of a batch of chains, joint index fastest: run r is joint r mod n
    of chain r // n, so that :func:`simulate` integrates every joint with the true delay and the
    cubic Hermite history of a segment.

    Attributes
    ----------
    mass, stiffness, damping : numpy.ndarray, shape (n, n)
        M [kg m^2] (regular), K [N m/rad], D [N m s/rad].
    """

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    @property
    def joints(self) -> int:
        """n, the joints of one chain."""
        return self.mass.shape[0]

    def acceleration(self, alpha, omega, torque):
        """q'' = M^-1 (K q + D q' + u) of every chain of the batch [rad/s^2].

        Parameters
        ----------
        alpha, omega, torque : numpy.ndarray, shape (batch * n,)
            Joint angles [rad], angular velocities [rad/s] and reflex torques [N m], joint fastest.

        Returns
        -------
        numpy.ndarray, shape (batch * n,)
            [rad/s^2].
        """
        q, qdot, u = _per_chain(self.joints, alpha, omega, torque)
        force = q @ self.stiffness.T + qdot @ self.damping.T + u
        return np.linalg.solve(self.mass, force.T).T.reshape(-1)


@dataclass(frozen=True)
class NonlinearChainPlant:
    """The nonlinear chain M(q) q'' + c(q, q') = tau(q, q') + u (docs/chain.md, "Nonlinear simulation").

    tau is what :class:`ChainPlant`'s K q + D q' linearises: the global muscles' torques from the
    nonlinear fibre lengths, lever arms and Hill forces
    (:func:`~spinectl.model.chain.chain_muscle_torque_per_pcsa`), gravity
    (:func:`~spinectl.model.chain.chain_gravity_torque`), the passive and local stiffness
    -(K_pas + k) q, the local muscles' damping -c_loc k q' (their Hill slope at rest,
    :func:`~spinectl.model.chain.local_damping`; linear, like their stiffness), and the
    constant counter torques that make upright an equilibrium (as
    :class:`SegmentPlant`'s). M(q) is the posture's mass matrix
    (:func:`~spinectl.model.chain.mass_matrix`) and c the Coriolis and centripetal terms
    (:func:`~spinectl.model.chain.velocity_torque`). Runs as :class:`ChainPlant`'s.

    Attributes
    ----------
    model : Model
    cor : numpy.ndarray, shape (n, 2)
        Upright CoR positions [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    stiffness : numpy.ndarray, shape (n,)
        K_pas + k per joint [N m/rad]: passive and local.
    counter_torque : numpy.ndarray, shape (n,)
        Constant torques [N m] making tau(0, 0) = 0.
    local_damping : numpy.ndarray or float, shape (n,)
        c_loc k per joint [N m s/rad]: the local muscles' damping; 0: none.
    """

    model: Model
    cor: np.ndarray
    pcsa: np.ndarray
    stiffness: np.ndarray
    counter_torque: np.ndarray
    local_damping: np.ndarray | float = 0.0

    @property
    def joints(self) -> int:
        """n, the joints of one chain."""
        return self.cor.shape[0]

    def torque(self, q, qdot):
        """tau(q, q') [N m], the counter torques included: zero upright.

        Parameters
        ----------
        q, qdot : array_like, shape (..., n)
            Joint angles [rad] and angular velocities [rad/s].

        Returns
        -------
        numpy.ndarray, shape (..., n)
            [N m].
        """
        return _chain_torque_without_ct(self, q, qdot) + self.counter_torque

    def acceleration(self, alpha, omega, torque):
        """q'' = M(q)^-1 (tau(q, q') + u - c(q, q')) of every chain of the batch [rad/s^2].

        Parameters
        ----------
        alpha, omega, torque : numpy.ndarray, shape (batch * n,)
            Joint angles [rad], angular velocities [rad/s] and reflex torques [N m], joint fastest.

        Returns
        -------
        numpy.ndarray, shape (batch * n,)
            [rad/s^2].
        """
        n = self.joints
        q, qdot, u = _per_chain(n, alpha, omega, torque)
        force = self.torque(q, qdot) + u - chain.velocity_torque(self.model, self.cor, q, qdot)
        return np.linalg.solve(chain.mass_matrix(self.model, self.cor, q), force[..., None])[..., 0].reshape(-1)


def _chain_torque_without_ct(plant: NonlinearChainPlant, q, qdot):
    """Muscles, gravity, -(K_pas + k) q and the local damping -c_loc k q' [N m]."""
    m, q = plant.model, np.asarray(q, float)
    muscles = chain.chain_muscle_torque_per_pcsa(m, plant.cor, q, qdot) @ plant.pcsa
    springs = muscles + chain.chain_gravity_torque(m, plant.cor, q) - plant.stiffness * q
    return springs - plant.local_damping * np.asarray(qdot, float)


def nonlinear_chain_plant(model: Model, eccentricity: float, lordosis: float, pcsa, local_stiffness=0.0):
    """The :class:`NonlinearChainPlant` at a configuration, global activation and local stiffness.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    local_stiffness : array_like, shape (n,)
        k_j of the local muscles [N m/rad], with their damping c_loc k_j; 0: none.

    Returns
    -------
    NonlinearChainPlant
        Linearised upright, its torques are :meth:`spinectl.model.chain.ChainCoefficients.stiffness`
        and ``damping`` at ``pcsa`` and ``local_stiffness``, its mass matrix
        :func:`~spinectl.model.chain.mass_matrix`.
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)
    n = cor.shape[0]
    passive = mechanics.passive_stiffness(model, mechanics.inertia(cor, model))  # as chain_coefficients
    stiffness = np.broadcast_to(passive + np.asarray(local_stiffness, float), (n,)).copy()
    damping = np.broadcast_to(chain.local_damping(local_stiffness, model), (n,)).copy()
    plant = NonlinearChainPlant(model, cor, np.asarray(pcsa, float), stiffness, np.zeros(n), damping)
    return dataclasses.replace(plant, counter_torque=-_chain_torque_without_ct(plant, np.zeros(n), np.zeros(n)))


def simulate_chain(plant: ChainPlant, kp, kd, delay, settings: Reflex, perturbation):
    """Simulate a batch of chains under the diagonal delayed reflex -(K_p q + K_d q')(t - tau).

    Every joint is a run of :func:`simulate` (same integrator, history and activation lag);
    a chain is stable when the largest joint angle shrinks (:func:`growth_rate` of
    max_j abs(q_j)).

    Parameters
    ----------
    plant : ChainPlant or NonlinearChainPlant
    kp, kd : array_like, shape (n,)
        Gains per joint [N m/rad], [N m s/rad].
    delay : array_like, shape (batch,)
        One delay per chain [s].
    settings : Reflex
        The simulation settings (see :func:`simulate`).
    perturbation : array_like, shape (n,)
        Initial joint angles [rad], held before t = 0.

    Returns
    -------
    simulation : Simulation
        Per run (batch * n, joint fastest).
    stable : numpy.ndarray of bool, shape (batch,)
        The verdict per chain.

    Raises
    ------
    ParameterError
        As :func:`simulate`.
    """
    n = plant.joints
    delay = np.atleast_1d(np.asarray(delay, float))
    tile = np.tile  # joint fastest
    start = tile(np.asarray(perturbation, float), delay.size)
    run = simulate(plant, tile(kp, delay.size), tile(kd, delay.size), np.repeat(delay, n), settings, start)
    largest = np.max(np.abs(run.alpha).reshape(delay.size, n, -1), axis=1)
    rate = growth_rate(run.time, largest, float(np.max(np.abs(start))))
    diverged = run.diverged.reshape(delay.size, n).any(axis=1)
    return run, ~diverged & (rate < 0)
