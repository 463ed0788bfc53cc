"""The net torque at the analysed posture: how far it is from an equilibrium (docs/anatomy.md, "Equilibrium").

A linearisation's K and D are the stiffness and damping of a held posture only where the net torque on
the chain's joints (the muscles at the analysed activations, passive forces and gravity) is zero. Away
from that the body accelerates: the same matrices then describe a moving body, not a posture that holds.
The table and JSON say the net torque per chain joint, and warn where it is far from zero.

Where the model has a rhythm (joint equalities, couplers), its constraint forces may carry the joints' net
torques: the posture is then held on the rhythm's independent coordinates (T^T tau = 0, the optimum's
equilibrium "rhythm") though not joint by joint. The warning is for a posture held by neither.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

EQUILIBRIUM_FRACTION = 0.1
"""A joint is far from equilibrium where its net torque exceeds this fraction of what the muscles could hold there.

What the muscles could hold at joint j is their torque range over their control bounds, sum_i abs(tau_ij) (u_i -
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
        What the muscles could hold at each joint, sum_i abs(tau_ij) (u_i - l_i) [N m] (0 without muscles).
    rhythm_torque, rhythm_capacity : numpy.ndarray, shape (r,) or None
        The same on the rhythm's independent coordinates, T^T tau (the model's equalities carry the rest);
        None without a rhythm [N m].
    """

    joints: tuple
    torque: np.ndarray
    capacity: np.ndarray
    rhythm_torque: np.ndarray | None = None
    rhythm_capacity: np.ndarray | None = None

    @property
    def threshold(self) -> np.ndarray:
        """Each joint's bound of 'near equilibrium' [N m]: :data:`EQUILIBRIUM_FRACTION` of its capacity, at least
        :data:`EQUILIBRIUM_FLOOR`."""
        return _threshold(self.capacity)

    @property
    def far(self) -> tuple:
        """The joints whose net torque exceeds their :attr:`threshold`."""
        return tuple(j for j, t, b in zip(self.joints, self.torque, self.threshold, strict=True) if abs(t) > b)

    @property
    def rhythm_far(self) -> bool:
        """Far from equilibrium on the rhythm's coordinates too (or, without a rhythm, at some joint)."""
        if self.rhythm_torque is None:
            return bool(self.far)
        return bool(np.any(np.abs(self.rhythm_torque) > _threshold(self.rhythm_capacity)))

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
            "net_torque_rhythm_Nm": None if self.rhythm_torque is None else self.rhythm_torque.tolist(),
            "far_from_equilibrium_held_by_nothing": self.rhythm_far,
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
        if far and not self.rhythm_far:
            out.append(
                f"held on the rhythm's coordinates (net torque there at most "
                f"{np.max(np.abs(self.rhythm_torque), initial=0.0):.3g} N m): the model's equalities carry the joints' "
                "net torques, so the constrained chain's verdict is that of a held posture; the free chain's and each "
                "joint's are of joints that would move without those constraint forces"
            )
        elif far:
            rhythm = "" if self.rhythm_torque is None else " and on the rhythm's coordinates"
            out.append(
                f"warning: far from equilibrium at {len(far)} of {len(self.joints)} joints{rhythm} (net torque above "
                f"{EQUILIBRIUM_FRACTION:g} of what the muscles could hold there, at least {EQUILIBRIUM_FLOOR:g} N m): "
                "these activations do not hold this posture, so the stiffness and verdicts below are those of a "
                "moving body, not of a held posture"
            )
        return out


def _threshold(capacity: np.ndarray) -> np.ndarray:
    """Near equilibrium up to :data:`EQUILIBRIUM_FRACTION` of the muscles' capacity, at least the floor [N m]."""
    return np.maximum(EQUILIBRIUM_FRACTION * capacity, EQUILIBRIUM_FLOOR)


def net_torque(lin, a, bounds, joints, rhythm_rows=None) -> NetTorque:
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
    rhythm_rows : tuple, optional
        ``(torque per control, rest)`` on the rhythm's independent coordinates [N m]
        (:meth:`~spinectl.anatomy.contract.AnatomyEngine.equilibrium_rows` with ``"rhythm"``); None without a
        rhythm.

    Returns
    -------
    NetTorque
    """
    rows = list(lin.dofs[: lin.n])
    per = np.asarray(lin.torque_per_muscle)[rows]
    torque = per @ np.asarray(a, float) + np.asarray(lin.torque_offset)[rows]
    lower, upper = (np.asarray(b, float) for b in bounds)
    a, span = np.asarray(a, float), upper - lower
    if rhythm_rows is None:
        return NetTorque(tuple(joints), torque, np.abs(per) @ span)
    rhythm_per, rhythm_rest = (np.asarray(x, float) for x in rhythm_rows)
    rhythm = rhythm_per @ a + rhythm_rest
    return NetTorque(tuple(joints), torque, np.abs(per) @ span, rhythm, np.abs(rhythm_per) @ span)
