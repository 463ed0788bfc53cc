"""External loads on an anatomical model: a constant force held at a point of a body (docs/anatomy.md, "Loads").

A load is a force F [N] at a point P of a body (in the body's frame [m]), F fixed in the ground (a weight held:
it keeps its direction) or in the body (a follower force: it turns with the body). Its generalised force is

    tau(q) = J_P(q)^T F(q),

J_P the Jacobian of P's position, and like gravity's it brings a load stiffness through the geometry,
K_load = d(J_P^T F)/dq. For a tree of hinges and slides, column j of J_P is a_j x (P - o_j) (hinge j, axis a_j
through o_j) or a_j (slide j); a hinge k turns every vector carried by the bodies beyond it, so with j the
inner of the two (nearer the root) and k the outer,

    d col_j / dq_k = a_j x col_k   (hinge j; 0 for a slide: its axis does not move with an outer joint),
    d col_k / dq_j = a_j x col_k   (hinge j turns col_k rigidly; 0 for a slide j),

the same vector: K_load[j, k] = F . (a_inner x col_outer) is symmetric for a ground-fixed F, the Hessian of the
load's potential -F . P(q) (a conservative load). A body-fixed F turns too, dF/dq_k = a_k x F for a hinge k
carrying the body, which adds col_j . (a_k x F): not symmetric (a follower force is not conservative).
:func:`load_terms` evaluates both with MuJoCo's kinematics (``xaxis``, ``xanchor``, :func:`mujoco.mj_jac`);
the tests check the force against MuJoCo's own :func:`mujoco.mj_applyFT` and the stiffness against its central
differences.

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.

Featherstone R (2008). Rigid Body Dynamics Algorithms. Springer, New York, ch. 4 (the Jacobian of a
kinematic tree and its derivative). doi:10.1007/978-1-4899-7560-7.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from .._validate import in_range, label, printable, real_vector, show
from ..errors import ParameterError
from ..model.loads import FRAMES, MAX_LOAD

MAX_LOAD_OFFSET = 10.0
"""Largest coordinate of a load's point in its body's frame [m]: beyond any body of a human model (about 2 m)."""

SYNTAX = "BODY:FX,FY,FZ[@X,Y,Z][:ground|:body] (a force [N] at a point [m] of BODY, e.g. torso:0,0,-100@0.3,0,0.4)"
"""How ``spinectl anatomy --load`` reads a load."""


@dataclass(frozen=True)
class BodyLoad:
    """A constant force at a point of a body of an anatomical model.

    Attributes
    ----------
    body : str
        The body's name in the model.
    force : tuple of float
        (F_x, F_y, F_z) [N], in the ground's frame or the body's (``frame``).
    point : tuple of float
        Where it acts, in the body's frame [m]; default its origin.
    frame : str
        ``"ground"`` (the default: the force keeps its direction) or ``"body"`` (it turns with the body).
    """

    body: str
    force: tuple
    point: tuple = (0.0, 0.0, 0.0)
    frame: str = "ground"

    def __post_init__(self):
        object.__setattr__(self, "body", label("loads", self.body))
        force = real_vector("loads", self.force, 3)
        point = real_vector("loads", self.point, 3)
        object.__setattr__(self, "force", tuple(in_range("loads", f, -MAX_LOAD, MAX_LOAD) for f in force))
        object.__setattr__(self, "point", tuple(in_range("loads", p, -MAX_LOAD_OFFSET, MAX_LOAD_OFFSET) for p in point))
        if self.frame not in FRAMES:
            raise ParameterError("loads", f"a load's frame must be one of {FRAMES} (got {show(self.frame)})")

    def to_dict(self) -> dict:
        """The load for outputs: body, force [N], point [m], frame.

        Returns
        -------
        dict
        """
        return {"body": self.body, "force_N": list(self.force), "point_m": list(self.point), "frame": self.frame}

    def text(self) -> str:
        """One line: the force, where and in which frame.

        Returns
        -------
        str
        """
        f, p = self.force, self.point
        return (
            f"F = ({f[0]:g}, {f[1]:g}, {f[2]:g}) N at ({p[0]:g}, {p[1]:g}, {p[2]:g}) m of {self.body}, "
            f"fixed in the {self.frame}"
        )


def body_loads(value) -> tuple:
    """Loads validated: a tuple of :class:`BodyLoad`.

    Parameters
    ----------
    value : sequence of BodyLoad or of dict (``body``, ``force``, optional ``point`` and ``frame``), or None

    Returns
    -------
    tuple of BodyLoad
    """
    if value is None:
        return ()
    items = [value] if isinstance(value, (BodyLoad, dict)) else value
    if isinstance(items, (str, bytes)) or not hasattr(items, "__iter__"):
        raise ParameterError("loads", f"must be a sequence of BodyLoad (got {show(value)})")
    out = []
    for item in items:
        if isinstance(item, dict):
            try:
                item = BodyLoad(**item)
            except TypeError:
                raise ParameterError("loads", f"a load is body, force, point and frame (got {show(item)})") from None
        if not isinstance(item, BodyLoad):
            raise ParameterError("loads", f"must be a sequence of BodyLoad (got {show(item)})")
        out.append(item)
    return tuple(out)


def check_bodies(loads, bodies) -> None:
    """Refuse a load on a body the model lacks, in one line naming a few it has.

    Parameters
    ----------
    loads : sequence of BodyLoad
    bodies : sequence of str
        The model's body names.
    """
    known = set(bodies)
    for load in loads:
        if load.body not in known:
            names = ", ".join(sorted(b for b in known if b)[:8])
            raise ParameterError(
                "--load", f"BODY must be a body of the model, e.g. {names}, ... (got {printable(load.body)})"
            )


def _dof_chain(model, body: int) -> list:
    """The dofs that move a body, from the nearest to the root: its last dof and that dof's ancestors."""
    while body > 0 and model.body_dofnum[body] == 0:
        body = int(model.body_parentid[body])
    if body == 0:
        return []
    dof = int(model.body_dofadr[body] + model.body_dofnum[body] - 1)
    chain = []
    while dof >= 0:
        chain.append(dof)
        dof = int(model.dof_parentid[dof])
    return chain[::-1]


def _one_load(engine, load: BodyLoad, body: int) -> tuple:
    """(tau (nv,), K (nv, nv)) of one load at the engine's set state (module docstring)."""
    from .engine import require_mujoco

    mujoco = require_mujoco()
    model, d = engine.model, engine.data
    rotation = d.xmat[body].reshape(3, 3)
    point = d.xpos[body] + rotation @ np.asarray(load.point)
    force = rotation @ np.asarray(load.force) if load.frame == "body" else np.asarray(load.force, float)
    jacobian = np.zeros((3, model.nv))
    mujoco.mj_jac(model, d, jacobian, None, point, body)
    tau = jacobian.T @ force
    stiffness = np.zeros((model.nv, model.nv))
    hinge = int(mujoco.mjtJoint.mjJNT_HINGE)
    for position, inner in enumerate(chain := _dof_chain(model, body)):
        joint = int(model.dof_jntid[inner])
        if int(model.jnt_type[joint]) != hinge:  # a slide's axis stays put when an outer joint moves
            continue
        axis = d.xaxis[joint]
        for outer in chain[position:]:  # inner turns col_outer rigidly: d col / dq = a x col, either way round
            stiffness[inner, outer] = stiffness[outer, inner] = force @ np.cross(axis, jacobian[:, outer])
        if load.frame == "body":  # the force turns with the body: dF/dq_inner = a x F on every column
            stiffness[:, inner] += jacobian.T @ np.cross(axis, force)
    return tau, stiffness


def load_terms(engine, loads, qpos) -> tuple:
    """The loads' generalised force and load stiffness at a posture of a MuJoCo model (module docstring).

    Parameters
    ----------
    engine : spinectl.anatomy.engine.Engine
        The compiled model (its state is set to ``qpos`` and left there).
    loads : sequence of BodyLoad
    qpos : array_like, shape (nq,)
        The posture.

    Returns
    -------
    tau : numpy.ndarray, shape (nv,)
        J^T F summed over the loads [N m or N].
    stiffness : numpy.ndarray, shape (nv, nv)
        d(J^T F)/dq [N m/rad]; symmetric unless a load is fixed in its body.

    Raises
    ------
    ParameterError
        A load on a body the model lacks.

    References
    ----------
    Featherstone R (2008). Rigid Body Dynamics Algorithms. Springer, New York. doi:10.1007/978-1-4899-7560-7.
    """
    loads = body_loads(loads)
    check_bodies(loads, engine.names("body"))
    engine.set_state(qpos)
    nv = engine.model.nv
    tau, stiffness = np.zeros(nv), np.zeros((nv, nv))
    for load in loads:
        part = _one_load(engine, load, engine.names("body").index(load.body))
        tau, stiffness = tau + part[0], stiffness + part[1]
    return tau, stiffness


def with_loads(lin, tau, stiffness, dofs):
    """A linearisation with the loads' generalised force in its torque offset and their stiffness in K_0.

    Parameters
    ----------
    lin : spinectl.anatomy.linearise.Linearisation
    tau : numpy.ndarray
        J^T F over the indices of ``lin.torque_offset`` [N m].
    stiffness : numpy.ndarray
        K_load over the same indices [N m/rad].
    dofs : sequence of int
        The indices of ``lin.dofs`` among them.

    Returns
    -------
    Linearisation
    """
    k_load = np.asarray(stiffness)[np.ix_(list(dofs), list(dofs))]
    return replace(lin, stiffness_offset=lin.stiffness_offset + k_load, torque_offset=lin.torque_offset + tau)


def mujoco_apply_loads(self, lin, posture, loads, involved=()):
    """MuJoCo's ``apply_loads``: J^T F in the torque offset, d(J^T F)/dq in K_0 (:func:`load_terms`).

    Parameters
    ----------
    lin : spinectl.anatomy.linearise.Linearisation
        At the posture (``Anatomy.linearise``).
    posture : array_like, optional
        Full qpos; default the model's reference posture.
    loads : sequence of BodyLoad
    involved : sequence of str
        The joints of ``lin.dofs`` (unused: MuJoCo's dofs index the linearisation).

    Returns
    -------
    Linearisation
    """
    return with_loads(lin, *load_terms(self.engine, loads, self.posture(posture)), lin.dofs)


def refuse_loads(self, lin, posture, loads, involved):
    """An engine's ``apply_loads`` by default: the linearisation with external loads, here refused in one line.

    An engine that computes loads overrides it (MuJoCo: :func:`mujoco_apply_loads`; OpenSim:
    :func:`spinectl.anatomy.osim_loads.osim_load_terms`): J^T F in the torque offset, K_load in K_0.

    Parameters
    ----------
    lin : spinectl.anatomy.linearise.Linearisation
        At the posture, over its dofs.
    posture : optional
        The operating point (``posture``).
    loads : sequence of BodyLoad
        Not empty.
    involved : sequence of str
        The names of the linearisation's coordinates (its ``dofs``), the chain's first.

    Returns
    -------
    Linearisation

    Raises
    ------
    ParameterError
        Always: ``--load: is not available on this engine's models yet``.
    """
    raise ParameterError("--load", f"is not available on this engine's models yet (got a load on {self.name})")


def analysed_loads(loads, check: bool) -> tuple:
    """The loads of an analysis, validated; refused with the referee (``check``), whose copy of the model holds none.

    Parameters
    ----------
    loads : sequence of BodyLoad or dict
    check : bool
        MuJoCo's referee asked for.

    Returns
    -------
    tuple of BodyLoad
    """
    loads = body_loads(loads)
    if check and loads:
        raise ParameterError("--check", "compares the chain without loads (MuJoCo's referee holds none)")
    return loads


class BodyWeight(Protocol):
    """The engine contract's part for a load along gravity (:class:`~spinectl.anatomy.contract.AnatomyEngine`'s)."""

    def body_weight(self, body: str) -> tuple:
        """Gravity and a body's centre of mass: where and which way a weight held on it acts.

        Parameters
        ----------
        body : str
            A body of the model.

        Returns
        -------
        tuple
            (gravity in the ground's frame [m/s^2], the body's centre of mass in its own frame [m]), each shape (3,).
        """


def refuse_body_weight(self, body: str) -> tuple:
    """An engine's ``body_weight`` by default: refused in one line (MuJoCo's and OpenSim's models override it).

    Parameters
    ----------
    body : str
        A body of the model.

    Returns
    -------
    tuple
        Never: it raises.

    Raises
    ------
    ParameterError
        Always: ``buckling: is not available on this engine's models yet``.
    """
    raise ParameterError("buckling", f"is not available on this engine's models yet (got {self.name})")
