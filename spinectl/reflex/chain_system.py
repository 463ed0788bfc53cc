"""The coupled lumbar chain as a python-control system (docs/chain.md, "Dynamic stability").

The multi-input counterpart of :func:`spinectl.reflex.loops.segment_system`: all joints free
at once, M q'' = K q + D q' + u (:func:`spinectl.model.chain.state_matrix`), one torque input
and one angle output per joint. The delayed reflex on the chain is not built yet.
"""

from __future__ import annotations

import control as ct
import numpy as np

from ..errors import ModelError
from ..model.chain import state_matrix


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
