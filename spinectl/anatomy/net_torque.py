"""The net torque at the analysed posture: how far it is from an equilibrium (docs/anatomy.md, "Equilibrium").

A linearisation's K and D are the stiffness and damping of a held posture only where the net torque on
the chain's joints (the muscles at the analysed activations, passive forces and gravity) is zero. Away
from that the body accelerates: the same matrices then describe a moving body, not a posture that holds.
The table and JSON say the net torque per chain joint, and warn where it is far from zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

EQUILIBRIUM_FRACTION = 0.1
"""A joint is far from equilibrium where its net torque exceeds this fraction of what the muscles could hold there.

What the muscles could hold at joint j is their torque range over their control bounds, sum_i |tau_ij| (u_i -
l_i) [N m]. A net torque above a tenth of it is one that the muscles would need a tenth of their whole range at
that joint to cancel: no small reserve, nor a static optimisation's residual, but a posture these activations do
not hold."""

EQUILIBRIUM_FLOOR = 1.0
"""The least net torque [N m] counted as far from equilibrium, whatever the muscles (a model without muscles holds
nothing): about the gravity torque of a 1 kg segment 10 cm off its joint."""


@dataclass(frozen=True)
class NetTorque:
    """The net torque at each chain joint at the analysed posture and activations.

    Attributes
    ----------
    joints : tuple of str
        The chain's joints.
    torque : numpy.ndarray, shape (n,)
        tau_0 + sum_i a_i tau_i at each joint: muscles at the activations, passive forces and gravity [N m]
        (per radian of each joint's rotation, as the chain).
    capacity : numpy.ndarray, shape (n,)
        What the muscles could hold at each joint, sum_i |tau_ij| (u_i - l_i) [N m] (0 without muscles).
    """

    joints: tuple
    torque: np.ndarray
    capacity: np.ndarray

    @property
    def threshold(self) -> np.ndarray:
        """Each joint's bound of 'near equilibrium' [N m]: :data:`EQUILIBRIUM_FRACTION` of its capacity, at least
        :data:`EQUILIBRIUM_FLOOR`."""
        return np.maximum(EQUILIBRIUM_FRACTION * self.capacity, EQUILIBRIUM_FLOOR)

    @property
    def far(self) -> tuple:
        """The joints whose net torque exceeds their :attr:`threshold`."""
        return tuple(j for j, t, b in zip(self.joints, self.torque, self.threshold, strict=True) if abs(t) > b)

    def to_dict(self) -> dict:
        """JSON-ready: ``net_torque_Nm`` (joint -> N m), the muscles' capacity and the verdict.

        Returns
        -------
        dict
        """
        return {
            "net_torque_Nm": dict(zip(self.joints, self.torque.tolist(), strict=True)),
            "muscle_torque_capacity_Nm": dict(zip(self.joints, self.capacity.tolist(), strict=True)),
            "far_from_equilibrium": list(self.far),
            "far_from_equilibrium_criterion": (
                f"|net torque| > max({EQUILIBRIUM_FRACTION:g} x the muscles' torque range over their control "
                f"bounds at that joint, {EQUILIBRIUM_FLOOR:g} N m)"
            ),
        }

    def lines(self) -> list:
        """The table's line of the net torque and, where far from equilibrium, its warning.

        Returns
        -------
        list of str
        """
        if not self.torque.size:
            return []
        k = int(np.argmax(np.abs(self.torque)))
        each = ", ".join(f"{j} {t:.3g}" for j, t in zip(self.joints, self.torque, strict=True))
        out = [
            f"net torque at the posture (muscles at these activations + passive + gravity): largest "
            f"{abs(self.torque[k]):.3g} N m at {self.joints[k]}; per chain joint [N m]: {each}"
        ]
        far = self.far
        if far:
            out.append(
                f"warning: far from equilibrium at {len(far)} of {len(self.joints)} joints (net torque above "
                f"{EQUILIBRIUM_FRACTION:g} of what the muscles could hold there, at least {EQUILIBRIUM_FLOOR:g} N m): "
                "these activations do not hold this posture, so the stiffness and verdicts below are those of a "
                "moving body, not of a held posture"
            )
        return out


def net_torque(lin, a, bounds, joints) -> NetTorque:
    """The net torque at each chain joint from a linearisation at the analysed activations.

    Parameters
    ----------
    lin : Linearisation
        At the posture (:meth:`~spinectl.anatomy.contract.AnatomyEngine.chains`), its ``torque_per_muscle``
        [N m per unit control] and ``torque_offset`` [N m]; the chain is ``lin.dofs[:lin.n]``.
    a : array_like, shape (m,)
        The activations (controls).
    bounds : tuple of numpy.ndarray
        (lower, upper) control bounds, each shape (m,).
    joints : sequence of str
        The chain's joint names.

    Returns
    -------
    NetTorque
    """
    rows = list(lin.dofs[: lin.n])
    per = np.asarray(lin.torque_per_muscle)[rows]
    torque = per @ np.asarray(a, float) + np.asarray(lin.torque_offset)[rows]
    lower, upper = (np.asarray(b, float) for b in bounds)
    return NetTorque(tuple(joints), torque, np.abs(per) @ (upper - lower))
