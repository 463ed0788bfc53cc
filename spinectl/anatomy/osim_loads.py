"""External loads on an OpenSim model: J^T F by Simbody's station Jacobian, its load stiffness by differences.

The loads of :mod:`spinectl.anatomy.loads` (a force at a point of a body, fixed in the ground or in the body),
on an ``.osim`` model: the generalised force tau = J_P^T F with J_P OpenSim's own station Jacobian
(``SimbodyMatterSubsystem.calcStationJacobian``, over the mobilities), the force turned into the ground by the
body's frame where it is fixed in the body (``Frame.expressVectorInGround``). The load stiffness
K_load = d(J^T F)/dq is the central difference of that force over the linearised coordinates with step
:data:`~spinectl.anatomy.linearise.STEP`, as the passive torques' (:mod:`spinectl.anatomy.osim_geometry`). The
tests check tau against OpenSim's inverse dynamics with the load as a ``PrescribedForce`` (the referee) and K
against the closed form of a two-pin chain (docs/anatomy.md, "Loads").

References
----------
Sherman MA, Seth A, Delp SL (2011). Simbody: multibody dynamics for biomedical research. Procedia IUTAM
2:241-261. doi:10.1016/j.piutam.2011.04.023.
"""

from __future__ import annotations

import numpy as np

from .._validate import printable
from ..errors import ParameterError
from .export_osim import require_opensim
from .linearise import STEP
from .loads import body_loads, check_bodies


def _generalised_force(engine, loads) -> np.ndarray:
    """J^T F of every load at the set posture, over the mobilities [N m]."""
    osim = require_opensim()
    model, state = engine.model, engine.state
    bodies = model.getBodySet()
    total = np.zeros(state.getNU())
    for load in loads:
        body = bodies.get(load.body)
        force = osim.Vec3(*load.force)
        if load.frame == "body":  # a follower force: the body's frame turns it into the ground's
            force = body.expressVectorInGround(state, force)
        jacobian = osim.Matrix()
        model.getMatterSubsystem().calcStationJacobian(
            state, body.getMobilizedBodyIndex(), osim.Vec3(*load.point), jacobian
        )
        total += jacobian.to_numpy().T @ np.array([force.get(i) for i in range(3)])
    return total


def osim_load_terms(engine, loads, names, values: dict, order: dict) -> tuple:
    """The loads' generalised force and load stiffness over the coordinates ``names`` at a posture.

    Parameters
    ----------
    engine : spinectl.anatomy.opensim_engine.OsimEngine
    loads : sequence of BodyLoad
    names : sequence of str
        The coordinates of the linearisation (s of them).
    values : dict
        Coordinate name -> value [rad] of the posture (others at their defaults).
    order : dict
        Coordinate name -> its mobility index.

    Returns
    -------
    tau : numpy.ndarray, shape (s,)
        J^T F [N m].
    stiffness : numpy.ndarray, shape (s, s)
        d(J^T F)/dq by central differences [N m/rad]; column k the derivative in coordinate k.

    Raises
    ------
    ParameterError
        A load on a body the model lacks.
    """
    loads = body_loads(loads)
    bodies = engine.model.getBodySet()
    check_bodies(loads, [bodies.get(i).getName() for i in range(bodies.getSize())])
    names = list(names)
    index = [order[c] for c in names]
    stiffness = np.zeros((len(names), len(names)))

    def force_at(name: str, step: float) -> np.ndarray:  # J^T F with coordinate ``name`` moved by ``step``
        moved = dict(values)
        moved[name] = values.get(name, engine.coordinate(name).getDefaultValue()) + step
        engine.set_posture(moved)
        return _generalised_force(engine, loads)[index]

    try:
        engine.set_posture(values)
        tau = _generalised_force(engine, loads)[index]
        for k, name in enumerate(names):  # column k: the central difference in coordinate k
            stiffness[:, k] = (force_at(name, STEP) - force_at(name, -STEP)) / (2 * STEP)
    finally:
        engine.set_posture(values)
    return tau, stiffness


def osim_body_weight(self, body: str) -> tuple:
    """OsimAnatomy's ``body_weight``: gravity (``Model.getGravity``) and a centre of mass (``Body.getMassCenter``).

    Parameters
    ----------
    self : OsimAnatomy
        The model.
    body : str
        A body of the model.

    Returns
    -------
    tuple
        (gravity in the ground's frame [m/s^2], the centre of mass in the body's frame [m]), each shape (3,).

    Raises
    ------
    ParameterError
        ``body`` is no body of the model.
    """
    bodies = self.engine.model.getBodySet()
    if not bodies.contains(body):
        raise ParameterError("body", f"must be a body of {self.name} (got {printable(body)})")
    vector = (self.engine.model.getGravity(), bodies.get(body).getMassCenter())
    return tuple(np.array([v.get(i) for i in range(3)]) for v in vector)
