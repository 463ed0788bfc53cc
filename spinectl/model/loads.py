"""External loads on the paper's chain: a constant force held at the point mass (docs/chain.md, "External loads").

A load is a force F [N] in the sagittal plane (x ventral, y up: docs/model.md, "Frame and units") applied at the
upper body's point mass P. Fixed in the ground (a weight held in the hands: F does not turn) or fixed in the
upper body (a follower force: F turns with the thorax, by the sum of the joint angles). Its generalised force on
joint j is the moment about the moved CoR c_j,

    tau_j(q) = (P(q) - c_j(q)) x F(q)        (the planar cross product, = J_j(q)^T F),

and, as gravity does, it brings a load stiffness through the geometry. With dP/dq_k = J (P - c_k) and
dc_j/dq_k = J (c_j - c_k) for a joint k below j (J the quarter turn), d(P - c_j)/dq_k = J (P - c_hi), hi the
higher of CoRs j and k, and (J a) x F = -a . F, so at the upright posture

    K_load[j, k] = dtau_j/dq_k = -(P - c_hi) . F                     (ground-fixed F: symmetric),
    K_load[j, k] = -(P - c_hi) . F + (P - c_j) . F = (c_hi - c_j) . F (body-fixed F: dF/dq_k = J F).

A ground-fixed load is conservative (its potential is -F . P(q)), so its K_load is the Hessian of that
potential and symmetric, gravity's K_g being the case F = (0, -m g). A follower force is not conservative:
K_load is not symmetric (zero on and above the diagonal), and a single joint feels no load stiffness from it.
On a single joint at height h below P, a vertical load F_y gives K_load = -F_y h: a weight held (F_y < 0)
destabilises as gravity does (docs/chain.md).

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.

Ziegler H (1968). Principles of Structural Stability. Blaisdell, Waltham MA (follower forces: non-conservative
loads and their non-symmetric stiffness).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import in_range, real_vector, show
from ..errors import ParameterError
from . import geometry
from .params import Model

FRAMES = ("ground", "body")
"""Where a load's force is fixed: in the ground (it keeps its direction) or in the upper body (it turns with it)."""

MAX_LOAD = 1e5
"""Largest magnitude of a load's component [N]: 100 kN, some 150 body weights, far beyond any held load
(0-60 % of body weight in Cholewicki & McGill 1996) and well inside the chain's arithmetic."""


@dataclass(frozen=True)
class PointLoad:
    """A constant force at the upper body's point mass, in the sagittal plane.

    Attributes
    ----------
    force : tuple of float
        (F_x, F_y) [N], x ventral and y up; (0, -200) is a 200 N weight held (about 20 kg).
    frame : str
        ``"ground"`` (the default: the force keeps its direction) or ``"body"`` (it turns with the thorax).
    """

    force: tuple
    frame: str = "ground"

    def __post_init__(self):
        force = tuple(in_range("loads", f, -MAX_LOAD, MAX_LOAD) for f in real_vector("loads", self.force, 2))
        if self.frame not in FRAMES:
            raise ParameterError("loads", f"a load's frame must be one of {FRAMES} (got {show(self.frame)})")
        object.__setattr__(self, "force", force)

    def to_dict(self) -> dict:
        """The load for outputs: its force [N], frame and point.

        Returns
        -------
        dict
        """
        return {"force_N": list(self.force), "frame": self.frame, "at": "point mass"}

    def text(self) -> str:
        """One line: the force, the frame, the point.

        Returns
        -------
        str
        """
        return f"F = ({self.force[0]:g}, {self.force[1]:g}) N at the point mass, fixed in the {self.frame}"


def point_loads(value) -> tuple:
    """The loads of an operating point, validated: a tuple of :class:`PointLoad`.

    Parameters
    ----------
    value : PointLoad, sequence of PointLoad or of (F_x, F_y), or None
        None or () for none.

    Returns
    -------
    tuple of PointLoad
    """
    if value is None:
        return ()
    items = [value] if isinstance(value, PointLoad) else value
    try:
        items = list(items)
    except TypeError:
        raise ParameterError("loads", f"must be a sequence of PointLoad (got {show(value)})") from None
    return tuple(item if isinstance(item, PointLoad) else PointLoad(item) for item in items)


def loads_text(loads) -> str:
    """What a chain's source adds for its loads: "; load F = ... N at the point mass, ..." each; "" without.

    Parameters
    ----------
    loads : sequence of PointLoad or BodyLoad
        Anything with a ``text()``.

    Returns
    -------
    str
    """
    return "".join(f"; load {load.text()}" for load in loads)


def _forces(loads, angle=0.0) -> tuple:
    """Each load's force where the thorax has turned by ``angle`` [rad]: (..., L, 2), and the body-fixed mask."""
    force = np.array([load.force for load in loads], float).reshape(-1, 2)
    body = np.array([load.frame == "body" for load in loads], bool)
    angle = np.asarray(angle, float)[..., None] * body  # a ground-fixed force keeps its direction
    c, s = np.cos(angle), np.sin(angle)
    turned = np.stack([c * force[:, 0] - s * force[:, 1], s * force[:, 0] + c * force[:, 1]], axis=-1)
    return turned, body


def load_torque(model: Model, cor, q, loads) -> np.ndarray:
    """Nonlinear generalised torque of the loads on every joint [N m]: tau_j = (P(q) - c_j(q)) x F(q).

    Parameters
    ----------
    model : Model
        Supplies the point mass's height.
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m], top to bottom.
    q : array_like, shape (..., n_cor)
        Joint rotations [rad].
    loads : sequence of PointLoad

    Returns
    -------
    numpy.ndarray, shape (..., n_cor)
        [N m]; zeros without loads.
    """
    from .chain import carried_points, chain_positions  # the chain's kinematics (chain.py imports nothing of this)

    loads = point_loads(loads)
    moved, angle = chain_positions(q, cor)
    if not loads:
        return np.zeros(moved.shape[:-1])
    point = carried_points(geometry.mass_position(model)[None, :], q, cor)  # (..., 1, 2)
    force = _forces(loads, angle)[0].sum(axis=-2)  # (..., 2): every load acts at the same point
    arm = point - moved  # (..., n, 2)
    return arm[..., 0] * force[..., None, 1] - arm[..., 1] * force[..., None, 0]


def load_stiffness(model: Model, cor, loads) -> np.ndarray:
    """K_load = dtau/dq of the loads at the upright posture [N m/rad] (module docstring).

    Parameters
    ----------
    model : Model
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m], top to bottom.
    loads : sequence of PointLoad

    Returns
    -------
    numpy.ndarray, shape (..., n_cor, n_cor)
        -(P - c_hi) . F summed over the loads, plus (P - c_j) . F for the body-fixed ones; symmetric
        unless a load is body-fixed.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    cor = np.asarray(cor, float)
    n = cor.shape[-2]
    loads = point_loads(loads)
    if not loads:
        return np.zeros(cor.shape[:-2] + (n, n))
    force, body = _forces(loads)
    total, follower = force.sum(axis=0), force[body].sum(axis=0)
    arm = geometry.mass_position(model) - cor  # (..., n, 2): P - c_j upright
    # both joints carry P, and moving the higher CoR c_hi moves P and c_j alike: the entry depends on c_hi alone
    higher = np.minimum.outer(np.arange(n), np.arange(n))
    stiffness = -arm[..., higher, :] @ total
    # a follower force turns with the thorax, dF/dq_k = J F for every k: (J_j^T)(J F) = (P - c_j) . F, row j
    return stiffness + (arm @ follower)[..., :, None]


def upright_load_torque(model: Model, cor, loads) -> np.ndarray:
    """The loads' torque on every joint at the upright posture [N m]: :func:`load_torque` at q = 0.

    Parameters
    ----------
    model : Model
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m].
    loads : sequence of PointLoad

    Returns
    -------
    numpy.ndarray, shape (..., n_cor)
    """
    cor = np.asarray(cor, float)
    return load_torque(model, cor, np.zeros(cor.shape[:-1]), loads) + 0.0  # + 0.0: no signed zero
