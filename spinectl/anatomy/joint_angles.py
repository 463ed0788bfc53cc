"""Joint angles, not coordinates: the chain's linearisation and rhythm per radian of each joint's rotation.

An engine's chain coordinate q_j is not always its joint's rotation theta_j. In the Christophy family of
OpenSim lumbar models a CustomJoint's SpatialTransform scales its coordinate (``flex_extension``
turns L5/S1 0.125 rad per radian in Christophy's skeleton, and drives the other joints through
couplers); a MuJoCo hinge's coordinate is its angle. Stiffness, added stiffness and the lordosis
(the sum of the joint angles) mean per radian of the joint, so the engines' linearisation in q is
changed to theta here, once for every engine (:meth:`spinectl.anatomy.contract.MappedModel.chains`).

With theta = theta(q) over the chain's n coordinates (S = dtheta/dq their Jacobian at the posture,
the coordinates off the chain left as they are) and W = S^-1:

    tau_theta = W^T tau_q,   K_theta = W^T K_q W + diag(tau_q,j d^2 q_j/dtheta_j^2),
    D_theta = W^T D_q W,     M_theta = W^T M_q W,   r_theta = r_q W (moment arms),

d^2 q_j/dtheta_j^2 = -theta_j''/S_jj^3 (0 for the linear transform functions of the published
lumbar models). The rhythm q = q(q_ind) becomes theta = theta(theta_ind) with
T_theta = S T A^-1, A = (S T)[independent] (for a diagonal S: T_theta[k, a] = S_k T[k, a] / S_a).
The eigenvalues of the chain's dynamics, M^-1 K and the pencil of (M, D, K), do not change with
the variables (a congruence); the stiffness printed per radian does, and so does a stiffness
added per joint radian: k at the joint is S^T k S on the coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import ModelError
from .linearise import Linearisation, Rhythm

UNIT_TOLERANCE = 1e-12
"""A measured Jacobian within this of the identity (and without curvature) is the identity: the
coordinates are the joint angles and the linearisation is passed on unchanged (rounding of an
engine's own unit slope, e.g. a PinJoint's or a LinearFunction(1, 0))."""


@dataclass(frozen=True)
class JointSlopes:
    """How the chain's joints turn per unit of the chain's coordinates at a posture.

    Attributes
    ----------
    jacobian : numpy.ndarray, shape (n, n)
        S_jk = dtheta_j/dq_k: joint j's rotation about its own axis per unit of chain coordinate k
        [rad per coordinate unit].
    curvature : numpy.ndarray, shape (n,)
        d^2 theta_j/dq_j^2 [rad per coordinate unit^2] (0 for a linear transform function).
    """

    jacobian: np.ndarray
    curvature: np.ndarray

    @classmethod
    def identity(cls, n: int) -> JointSlopes:
        """Coordinates that are their joints' angles (a MuJoCo hinge).

        Parameters
        ----------
        n : int
            The number of chain joints.

        Returns
        -------
        JointSlopes
        """
        return cls(np.eye(n), np.zeros(n))

    def is_identity(self) -> bool:
        """Whether the coordinates are the joint angles (to :data:`UNIT_TOLERANCE`).

        Returns
        -------
        bool
        """
        n = len(self.curvature)
        return bool(
            np.all(np.abs(self.jacobian - np.eye(n)) <= UNIT_TOLERANCE)
            and np.all(np.abs(self.curvature) <= UNIT_TOLERANCE)
        )

    @property
    def slopes(self) -> np.ndarray:
        """Each joint's rotation per unit of its own coordinate, S_jj [rad per coordinate unit]."""
        return np.diag(self.jacobian).copy()


def _block(slopes: JointSlopes, s: int) -> tuple:
    """S and d^2 theta/dq^2 over s involved coordinates: the chain's n first, the rest left as they are."""
    n = len(slopes.curvature)
    full = np.eye(s)
    full[:n, :n] = slopes.jacobian
    curvature = np.zeros(s)
    curvature[:n] = slopes.curvature
    return full, curvature


def _require_supported(slopes: JointSlopes, name: str, rhy: Rhythm | None = None) -> None:
    """A joint turned by several chain coordinates is taken to first order only: refused where that is not exact."""
    if np.linalg.matrix_rank(slopes.jacobian) < len(slopes.curvature):
        raise ModelError(
            f"{name}: the chain's joints do not turn independently with its coordinates here (a coordinate that "
            f"turns no joint, e.g. a translation: joint rad per coordinate unit {np.round(slopes.slopes, 4)}): "
            "the chain has no joint angles to report"
        )
    off = slopes.jacobian - np.diag(slopes.slopes)
    if not np.any(np.abs(off) > UNIT_TOLERANCE):
        return
    curved = np.any(np.abs(slopes.curvature) > UNIT_TOLERANCE) or (rhy is not None and np.any(rhy.curvature != 0))
    if curved:
        raise ModelError(
            f"{name}: a chain joint turns with several chain coordinates and not linearly (or under a curved "
            "rhythm): its joint angle is not supported, only each joint's own coordinate or a linear map"
        )


def linearisation_in_angles(lin: Linearisation, slopes: JointSlopes, name: str = "model") -> Linearisation:
    """The linearisation per radian of each chain joint's rotation (module docstring).

    Parameters
    ----------
    lin : Linearisation
        Over the involved coordinates, the chain's ``lin.n`` first.
    slopes : JointSlopes
        Of the chain's coordinates at the same posture.
    name : str
        The model's name, for a refusal.

    Returns
    -------
    Linearisation
        ``lin`` itself where the coordinates are the joint angles (:meth:`JointSlopes.is_identity`).
    """
    if slopes.is_identity():
        return lin
    _require_supported(slopes, name)
    dofs = list(lin.dofs)
    s = len(dofs)
    jac, second = _block(slopes, s)
    w = np.linalg.inv(jac)
    # d^2 q_j/dtheta_j^2 of a coordinate whose joint turns nonlinearly (each on its own joint only)
    qpp = -second / np.diag(jac) ** 3

    def congruent(matrices):  # W^T K W over the first two axes, for one matrix or one per control
        return np.einsum("ai,ab...,bj->ij...", w, matrices, w)

    torque_per = lin.torque_per_muscle.copy()
    torque_0 = lin.torque_offset.copy()
    arms = lin.moment_arms.copy()
    k_per = congruent(lin.stiffness_per_muscle)
    k_0 = congruent(lin.stiffness_offset)
    diag = np.arange(s)
    k_per[diag, diag, :] += qpp[:, None] * lin.torque_per_muscle[dofs]
    k_0[diag, diag] += qpp * lin.torque_offset[dofs]
    torque_per[dofs] = w.T @ lin.torque_per_muscle[dofs]
    torque_0[dofs] = w.T @ lin.torque_offset[dofs]
    arms[:, dofs] = lin.moment_arms[:, dofs] @ w
    return replace(
        lin,
        stiffness_per_muscle=k_per,
        stiffness_offset=k_0,
        damping_per_muscle=congruent(lin.damping_per_muscle),
        damping_offset=congruent(lin.damping_offset),
        mass=congruent(lin.mass),
        torque_per_muscle=torque_per,
        torque_offset=torque_0,
        moment_arms=arms,
    )


def rhythm_in_angles(rhy: Rhythm, slopes: JointSlopes, name: str = "model") -> Rhythm:
    """The rhythm as a map of the joint angles from the independent coordinates' joint angles.

    theta = theta(theta_ind): T_theta = S T A^-1 with A = (S T)[independent]; its curvature
    d^2 theta_k/dtheta_a^2 = theta_k'' (T_ka/S_a)^2 + S_k (C_ka/S_a^2 + T_ka q_a''), q_a'' =
    -theta_a''/S_a^3 (a diagonal S; a full one is taken linear, :func:`linearisation_in_angles`).

    Parameters
    ----------
    rhy : Rhythm
        Over the involved coordinates, the chain's n first.
    slopes : JointSlopes
        Of the chain's coordinates at the posture.
    name : str
        The model's name, for a refusal.

    Returns
    -------
    Rhythm
        ``rhy`` itself where the coordinates are the joint angles.
    """
    if slopes.is_identity():
        return rhy
    _require_supported(slopes, name, rhy)
    jac, second = _block(slopes, len(rhy.dofs))
    ind = list(rhy.independent)
    a_inv = np.linalg.inv((jac @ rhy.transform)[ind])
    transform = jac @ rhy.transform @ a_inv
    sigma = np.diag(jac)
    own = sigma[ind]  # each independent coordinate's own slope
    qpp = -second[ind] / own**3
    if np.allclose(jac, np.diag(sigma), rtol=0, atol=UNIT_TOLERANCE):
        curved = second[:, None] * (rhy.transform / own) ** 2
        curvature = curved + sigma[:, None] * (rhy.curvature / own**2 + rhy.transform * qpp)
    else:  # a full S is linear and the rhythm uncurved (_require_supported): no curvature
        curvature = np.zeros_like(rhy.curvature)
    return replace(rhy, transform=transform, curvature=curvature)
