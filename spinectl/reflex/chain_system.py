"""The coupled lumbar chain as a python-control system (docs/chain.md, "Dynamic stability").

The multi-input counterpart of :func:`spinectl.reflex.loops.segment_system`: all joints free
at once, M q'' = K q + D q' + u (:func:`spinectl.model.chain.state_matrix`), one torque input
and one angle output per joint; the loop of the diagonal delayed reflex with Padé delays
(:func:`chain_loop`) and its disk margins (:func:`chain_disk_margins`, docs/chain.md,
"The delayed reflex"). The exact delay margin is :func:`spinectl.reflex.mimo.chain_delay_margin`.
Each takes the matrices M, K, D and the joints' names, or any
:class:`~spinectl.model.linear_chain.LinearChain` at its controls (:func:`linear_chain_system`,
:func:`linear_chain_loop`).
"""

from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np

from ..errors import ModelError
from ..model.chain import state_matrix
from ..model.linear_chain import LinearChain


def chain_system(mass, stiffness, damping, names) -> ct.StateSpace:
    """The linearised chain at the upright equilibrium as a ``StateSpace``.

    x = (q, q'), x' = A x + B u, y = q, with A = [[0, I], [M^-1 K, M^-1 D]] and
    B = [[0], [M^-1]]; one joint is :func:`spinectl.reflex.loops.segment_system`, and the
    poles are :func:`spinectl.model.chain.dynamic_eigenvalues`.

    Parameters
    ----------
    mass : array_like, shape (n, n)
        M [kg m^2], regular (:func:`spinectl.model.chain.mass_matrix`).
    stiffness : array_like, shape (n, n)
        K [N m/rad].
    damping : array_like, shape (n, n)
        D [N m s/rad].
    names : sequence of str
        The n joints (``geometry.cor_names``), top to bottom.

    Returns
    -------
    control.StateSpace
        2 n states (``alpha_<name>`` [rad], ``omega_<name>`` [rad/s]), n inputs
        (``torque_<name>`` [N m]), n outputs (``alpha_<name>`` [rad]).

    Raises
    ------
    ModelError
        M is singular (massless levels), or its shape is not one row per joint.

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13.
    """
    mass = np.asarray(mass, float)
    names = list(names)
    n = len(names)
    if mass.shape != (n, n):
        raise ModelError(f"the mass matrix must be {n} x {n}, one row per joint (got shape {mass.shape})")
    a = state_matrix(mass, stiffness, damping)
    if not np.all(np.isfinite(a)):
        raise ModelError("the mass matrix is singular: give the lumbar levels a mass (levels.mass)")
    b = np.concatenate([np.zeros((n, n)), np.linalg.inv(mass)])
    c = np.concatenate([np.eye(n), np.zeros((n, n))], axis=1)
    return ct.ss(
        a,
        b,
        c,
        np.zeros((n, n)),
        inputs=[f"torque_{k}" for k in names],
        outputs=[f"alpha_{k}" for k in names],
        states=[f"alpha_{k}" for k in names] + [f"omega_{k}" for k in names],
        name="chain",
    )


def chain_loop(mass, stiffness, damping, kp, kd, delay: float, order: int, lag: float, names) -> ct.StateSpace:
    """The loop broken at the joint torques: L(s) = A(s) R(s) [K_p K_d] G(s), negative feedback.

    G maps the torques u to the state (q, q') of :func:`chain_system`; [K_p K_d] is the
    diagonal reflex; R(s) the [order/order] Padé approximant of exp(-s tau) at every joint
    (python-control's ``pade``) and A(s) = 1/(T_a s + 1) the force generation. The closed
    loop is u = -L u, so (I + L)^-1 is the sensitivity at the plant input.

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].
    kp, kd : array_like, shape (n,)
        Diagonal gains [N m/rad], [N m s/rad].
    delay : float
        tau [s].
    order : int
        Padé order.
    lag : float
        T_a [s]; 0 none.
    names : sequence of str
        The joints, top to bottom.

    Returns
    -------
    control.StateSpace
        n inputs ``torque_<name>`` [N m], n outputs ``reflex_<name>`` [N m].

    Raises
    ------
    ModelError
        As :func:`chain_system`.
    """
    names = list(names)
    n = len(names)
    plant = chain_system(mass, stiffness, damping, names)
    state = ct.ss(plant.A, plant.B, np.eye(2 * n), np.zeros((2 * n, n)))
    gains = np.concatenate([np.diag(np.broadcast_to(kp, (n,))), np.diag(np.broadcast_to(kd, (n,)))], axis=1)
    # scipy's realisation, as in spinectl.reflex.loops (slycot, installed for AB13MD, would give another)
    one = ct.tf2ss(ct.tf(*ct.pade(delay, order)), method="scipy") if delay > 0 else _static([[1.0]])
    if lag > 0:
        one = ct.tf2ss(ct.tf([1.0], [lag, 1.0]), method="scipy") * one
    delays = ct.append(*([one] * n))
    loop = delays * _static(gains) * state
    return ct.ss(
        loop.A, loop.B, loop.C, loop.D, inputs=[f"torque_{k}" for k in names], outputs=[f"reflex_{k}" for k in names]
    )


def linear_chain_system(chain: LinearChain, u=()) -> ct.StateSpace:
    """:func:`chain_system` of a linearised chain at the controls ``u``: M, K(u), D(u), its joints.

    Parameters
    ----------
    chain : LinearChain
        Fixed at an activation (:meth:`LinearChain.at`), ``u`` is empty.
    u : array_like, shape (m,)
        The controls [control unit].

    Returns
    -------
    control.StateSpace
        As :func:`chain_system`.

    Raises
    ------
    ModelError
        M is singular.
    """
    return chain_system(chain.mass_matrix, chain.stiffness(u), chain.damping(u), chain.joints)


def linear_chain_loop(chain: LinearChain, kp, kd, delay: float, order: int, lag: float, u=()) -> ct.StateSpace:
    """:func:`chain_loop` of a linearised chain at the controls ``u``.

    Parameters
    ----------
    chain : LinearChain
    kp, kd : array_like, shape (n,)
        Diagonal gains [N m/rad], [N m s/rad].
    delay : float
        tau [s].
    order : int
        Padé order.
    lag : float
        T_a [s]; 0 none.
    u : array_like, shape (m,)
        The controls [control unit].

    Returns
    -------
    control.StateSpace
        As :func:`chain_loop`.

    Raises
    ------
    ModelError
        M is singular.
    """
    return chain_loop(chain.mass_matrix, chain.stiffness(u), chain.damping(u), kp, kd, delay, order, lag, chain.joints)


@dataclass(frozen=True)
class DiskMargins:
    """Balanced disk margins of the chain's loop (skew 0; Seiler, Packard and Gahinet 2020).

    Attributes
    ----------
    disk_margin : float
        alpha, the multiloop disk margin [1]: the loop tolerates simultaneous independent
        gain-and-phase variations at every joint inside the disk of size alpha.
    gain_margin : float
        The gain factor it tolerates [1] ((1 + alpha/2)/(1 - alpha/2)); inf for alpha >= 2.
    phase_margin_deg : float
        The phase it tolerates [deg].
    loop_at_a_time : numpy.ndarray, shape (n, 3)
        The same three per joint, the other loops closed.
    """

    disk_margin: float
    gain_margin: float
    phase_margin_deg: float
    loop_at_a_time: np.ndarray


def _static(gain) -> ct.StateSpace:
    """A static gain matrix as a python-control system without states."""
    gain = np.atleast_2d(np.asarray(gain, float))
    return ct.ss(np.zeros((0, 0)), np.zeros((0, gain.shape[1])), np.zeros((gain.shape[0], 0)), gain)


def _factor(gain_db: float) -> float:
    """python-control's disk gain margin [dB] as a factor [1]."""
    return float(ct.db2mag(gain_db))


def chain_disk_margins(loop: ct.StateSpace, omega) -> DiskMargins:
    """Multiloop and loop-at-a-time disk margins of ``loop`` with ``control.disk_margins``.

    The multiloop margin bounds the structured singular value of the balanced sensitivity
    S - I/2 over diagonal complex perturbations (python-control's AB13MD upper bound, through
    slycot); joint j alone sees L_j = L_jj - L_jr (I + L_rr)^-1 L_rj, r the other joints.
    Meaningful only for a closed loop that is stable: the caller checks.

    Parameters
    ----------
    loop : control.StateSpace
        L of :func:`chain_loop`, n x n.
    omega : array_like
        Frequencies [rad/s].

    Returns
    -------
    DiskMargins

    References
    ----------
    Seiler P, Packard A, Gahinet P (2020). An introduction to disk margins. IEEE Control
    Systems Magazine 40(5):78-95. doi:10.1109/MCS.2020.3005277.
    """
    omega = np.asarray(omega, float)
    alpha, gain, phase = ct.disk_margins(loop, omega)
    n = loop.ninputs
    single = []
    for j in range(n):
        rest = [i for i in range(n) if i != j]
        closed = ct.feedback(_static(np.eye(n - 1)), loop[rest, rest]) if rest else None
        siso = loop[j, j] if closed is None else loop[j, j] - loop[[j], rest] * closed * loop[rest, [j]]
        a_j, g_j, p_j = ct.disk_margins(siso, omega)
        single.append((float(a_j), _factor(g_j), float(p_j)))
    return DiskMargins(float(alpha), _factor(gain), float(phase), np.array(single))
