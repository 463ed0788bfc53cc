"""The buckling (critical) load of an anatomical model's chain (docs/anatomy.md, "Buckling load").

A load P >= 0 [N] held at the thorax's centre of mass along gravity (a weight carried) adds the load stiffness
of :mod:`spinectl.anatomy.loads`, which is linear in the force: with K the chain's stiffness at the operating
point (activations, posture, added joint stiffness, other loads) and K_1 the load stiffness of one newton,

    K(P) = K + P K_1,

and the buckling load is the least P >= 0 with lambda_min(-sym(K(P))) = 0 (Bergmark 1989; the index of
Cholewicki & McGill 1996), found by :func:`scipy.optimize.brentq` on lambda_min between 0 and
:data:`spinectl.model.loads.MAX_LOAD`. It is 0 where the chain is unstable already without it, and infinite
(``none up to`` the cap) where it stays stable up to the cap. K_1 is the difference of the chain with a 1 N
load and without it, so each engine's own load stiffness (MuJoCo's closed form, OpenSim's differences) is used.

The thorax body is the first listed in the mapping's ``bodies.thorax``: the one nearest the chain (MyoTorso's
and the Christophy skeleton's ``torso``; the cyclist model's ``thoracic12``).

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.

Cholewicki J, McGill SM (1996). Mechanical stability of the in vivo lumbar spine: implications for injury and
chronic low back pain. Clin Biomech 11(1):1-15. doi:10.1016/0268-0033(95)00035-6.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model.contributions import least_mode
from ..model.loads import MAX_LOAD
from .contract import AnatomyEngine
from .loads import BodyLoad


@dataclass(frozen=True)
class BucklingLoad:
    """The buckling load of the free and the constrained chain (:func:`buckling_load`).

    Attributes
    ----------
    free, constrained : float
        The least load at which each chain loses stability [N]; 0 if unstable without it, ``inf`` if none
        up to :attr:`cap`.
    body : str
        The body that holds the load.
    point : tuple of float
        Its centre of mass, where the load acts, in its own frame [m].
    direction : tuple of float
        Gravity's unit direction in the ground's frame, the load's.
    cap : float
        The largest load searched [N].
    """

    free: float
    constrained: float
    body: str
    point: tuple
    direction: tuple
    cap: float = MAX_LOAD

    def to_dict(self) -> dict:
        """The buckling load for JSON (``buckling_load_N``).

        Returns
        -------
        dict
            ``free``, ``constrained`` [N] (None where there is none up to the cap), ``body``, ``point_m``,
            ``direction``, ``cap_N``.
        """
        shown = {k: (None if np.isinf(v) else v) for k, v in (("free", self.free), ("constrained", self.constrained))}
        return {**shown, "body": self.body, "point_m": list(self.point), "direction": list(self.direction),
                "cap_N": self.cap}  # fmt: skip

    def text(self) -> str:
        """The table's line.

        Returns
        -------
        str
        """
        return (
            f"buckling load (a load at {self.body}'s centre of mass, along gravity, at which the chain loses "
            f"stability): free chain {self._shown(self.free)}, constrained {self._shown(self.constrained)}"
        )

    def _shown(self, load: float) -> str:
        if np.isinf(load):
            return f"none up to {self.cap:.6g} N"
        return "0 N (unstable without it)" if load == 0 else f"{load:.6g} N"


def thorax_body(anatomy: AnatomyEngine) -> str:
    """The body that holds the load: the first of the mapping's ``bodies.thorax`` (the one nearest the chain).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.

    Returns
    -------
    str
    """
    return anatomy.mapping.bodies["thorax"][0]


def weight_load(anatomy: AnatomyEngine, newtons: float, body: str | None = None) -> BodyLoad:
    """A load along gravity at a body's centre of mass, fixed in the ground (a weight held).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (its ``body_weight``).
    newtons : float
        The load's magnitude [N].
    body : str, optional
        Default :func:`thorax_body`.

    Returns
    -------
    BodyLoad

    Raises
    ------
    ModelError
        A model without gravity: no direction for the load.
    """
    body = thorax_body(anatomy) if body is None else body
    gravity, centre = anatomy.body_weight(body)
    g = float(np.linalg.norm(gravity))
    if not g > 0:
        raise ModelError(
            f"buckling: {anatomy.name} has no gravity (0 m/s^2), so a load along gravity has no direction; "
            "hold a --load of your own instead"
        )
    force = tuple(float(newtons) * np.asarray(gravity, float) / g)
    return BodyLoad(body, force, tuple(float(c) for c in centre))


def load_stiffness_per_newton(
    anatomy: AnatomyEngine, plane="sagittal", posture=None, joint_stiffness="none", activations=None, loads=()
) -> tuple:
    """K_1 of the free and the constrained chain: 1 N along gravity at the thorax's centre of mass [N m/rad per N].

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    plane, posture, joint_stiffness, activations, loads
        The operating point, as :meth:`~spinectl.anatomy.contract.AnatomyEngine.chains` takes it.

    Returns
    -------
    tuple
        (K_1 free, K_1 constrained, the free chain, the constrained chain, the unit :class:`BodyLoad`); the chains
        are those without the unit load.
    """
    unit = weight_load(anatomy, 1.0)
    a = None if activations is None else np.asarray(activations, float)
    free, con, _ = anatomy.chains(plane, posture, joint_stiffness, activations=a, loads=tuple(loads))
    free_1, con_1, _ = anatomy.chains(plane, posture, joint_stiffness, activations=a, loads=(*loads, unit))
    u = np.zeros(len(free.controls)) if a is None else a  # K_load is in the offset: any u gives the same K_1
    return free_1.stiffness(u) - free.stiffness(u), con_1.stiffness(u) - con.stiffness(u), free, con, unit


def critical_load(stiffness, per_newton, cap: float = MAX_LOAD) -> float:
    """The least P >= 0 with lambda_min(-sym(K + P K_1)) = 0 [N].

    Parameters
    ----------
    stiffness : array_like, shape (n, n)
        K at the operating point [N m/rad].
    per_newton : array_like, shape (n, n)
        K_1 [N m/rad per N].
    cap : float
        The largest load searched [N].

    Returns
    -------
    float
        0 if unstable at P = 0; ``inf`` if stable up to ``cap``.
    """
    from scipy.optimize import brentq

    stiffness, per_newton = np.asarray(stiffness, float), np.asarray(per_newton, float)

    def index(p):
        return least_mode(stiffness + p * per_newton).eigenvalue

    if index(0.0) <= 0:
        return 0.0
    if index(cap) > 0:
        return float("inf")
    return float(brentq(index, 0.0, cap, xtol=1e-9, rtol=1e-14))


def buckling_load(
    anatomy: AnatomyEngine, plane="sagittal", posture=None, joint_stiffness="none", activations=None, loads=()
) -> BucklingLoad:
    """The buckling load of the free chain and of the chain constrained by the rhythm at an operating point.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (it needs no muscles: ``activations`` may be empty).
    plane : str
        The chain.
    posture : optional
        The operating posture (:meth:`~spinectl.anatomy.contract.AnatomyEngine.posture`).
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    activations : array_like, shape (m,), optional
        The operating activations; default none (the passive chain, all activations 0).
    loads : sequence of BodyLoad
        Other loads held.

    Returns
    -------
    BucklingLoad
    """
    if activations is None:
        activations = np.zeros(len(anatomy.muscles))
    k1_free, k1_con, free, con, unit = load_stiffness_per_newton(
        anatomy, plane, posture, joint_stiffness, activations, loads
    )
    a = np.asarray(activations, float)
    g = np.asarray(unit.force, float)
    return BucklingLoad(
        free=critical_load(free.stiffness(a), k1_free),
        constrained=critical_load(con.stiffness(a), k1_con),
        body=unit.body,
        point=unit.point,
        direction=tuple(float(x) for x in g / np.linalg.norm(g)),
    )
