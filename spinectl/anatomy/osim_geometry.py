"""An OpenSim model's geometry at a posture: moment arms, their Hessians, passive torques, mass (docs/anatomy.md).

The moment arms are OpenSim's own: with the posture realised once and every speed zero but
coordinate k's at 1 rad/s (``Model.realizeVelocity``), every muscle's lengthening speed
(``Muscle.getLengtheningSpeed``, OpenSim's path: via, conditional and moving points, wrapping)
is its rate of lengthening per unit of q_k, the arm of the forces OpenSim applies along the
path (dL/dq_k wherever OpenSim's path length is smooth and consistent with it). That is what
``computeMomentArm`` returns with no enforced constraint coupling the coordinate to another
(spinectl switches the couplers off), but it realises the whole model again for each muscle and
coordinate: s velocity realisations per posture replace m s position realisations.
The Hessians are central differences of these arms over q with step
:data:`~spinectl.anatomy.linearise.STEP` (truncation STEP^2/6 abs(d^3 r/dq^3), rounding
eps abs(r) / STEP: both about 1e-12 m/rad^2 for arms of 0.1 m), at the 2s postures q +- STEP e_k,
as before; so are the passive torques' (OpenSim's inverse dynamics with the muscles and
actuators off: gravity and every passive force). Every wrapped muscle's contacts are checked
at each of these postures: a muscle that starts or stops wrapping within STEP has a kinked arm
there, which no difference can differentiate (one line, nothing linearised).

Why not differences of the path lengths (``getLength``): where a path wraps an ellipsoid,
OpenSim's length is not the one whose rate its forces follow (latissimus dorsi over the
Pose2Sim model's torso ellipsoid: dL/dq at T12/L1 twice ``computeMomentArm``), and the
generalised forces are the forces' (tests/anatomy/test_osim_geometry.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .export_osim import require_opensim
from .linearise import STEP


@dataclass(frozen=True)
class Geometry:
    """Every muscle's length, moment arms and their Hessian, the passive torques and the mass at one posture.

    Attributes
    ----------
    lengths : numpy.ndarray, shape (m,)
        Path lengths L [m].
    arms : numpy.ndarray, shape (m, s)
        dL/dq over the coordinates, as OpenSim's forces follow it (minus ``computeMomentArm``) [m/rad].
    hessian : numpy.ndarray, shape (m, s, s)
        The arms' derivatives d^2 L/dq^2 [m/rad^2], symmetrised.
    passive : numpy.ndarray, shape (s,)
        Gravity and every passive force, as generalised forces [N m].
    dpassive : numpy.ndarray, shape (s, s)
        d passive / dq [N m/rad] (column k: the derivative in coordinate k).
    mass : numpy.ndarray, shape (s, s)
        The mass matrix over the coordinates [kg m^2].
    """

    lengths: np.ndarray
    arms: np.ndarray
    hessian: np.ndarray
    passive: np.ndarray
    dpassive: np.ndarray
    mass: np.ndarray


def geometry(engine, names, values: dict, order: dict) -> Geometry:
    """Arms, Hessians, passive torques and mass at ``values`` (module docstring), the other coordinates held.

    Parameters
    ----------
    engine : spinectl.anatomy.opensim_engine.OsimEngine
    names : sequence of str
        The coordinates (s of them).
    values : dict
        Coordinate name -> value [rad] of the posture (others at their defaults).
    order : dict
        Coordinate name -> its mobility index (the order of the inverse dynamics and calcM).

    Returns
    -------
    Geometry

    Raises
    ------
    ModelError
        A muscle starts or stops wrapping within STEP of the posture.
    """
    names = list(names)
    s = len(names)
    index = [order[c] for c in names]
    wrapped = _wrapped(engine)
    switched = _actuators_off(engine)
    try:
        engine.set_posture(values)
        lengths, touching = _lengths(engine), _contacts(engine, wrapped)
        arms, passive = _arms(engine, names), _passive(engine, index)
        mass = _mass(engine, index)
        hessian = np.zeros((len(lengths), s, s))
        dpassive = np.zeros((s, s))
        for k, name in enumerate(names):
            sides = []
            for sign in (1.0, -1.0):
                moved = dict(values)
                moved[name] = values.get(name, engine.coordinate(name).getDefaultValue()) + sign * STEP
                engine.set_posture(moved)
                _same_contacts(engine, wrapped, touching, _contacts(engine, wrapped), name)
                sides.append((_arms(engine, names), _passive(engine, index)))
            hessian[:, :, k] = (sides[0][0] - sides[1][0]) / (2 * STEP)
            dpassive[:, k] = (sides[0][1] - sides[1][1]) / (2 * STEP)
    finally:
        _restore(engine, switched)
        engine.set_posture(values)
    hessian = 0.5 * (hessian + hessian.transpose(0, 2, 1))
    return Geometry(lengths, arms, hessian, passive, dpassive, mass)


def _arms(engine, names) -> np.ndarray:
    """dL/dq of every muscle over ``names`` at the set posture: lengthening speeds at unit coordinate speeds [m/rad]."""
    model, state = engine.model, engine.state
    muscles = model.getMuscles()
    out = np.zeros((muscles.getSize(), len(names)))
    for k, name in enumerate(names):
        coordinate = engine.coordinate(name)
        coordinate.setSpeedValue(state, 1.0)
        model.realizeVelocity(state)
        out[:, k] = [muscles.get(i).getLengtheningSpeed(state) for i in range(muscles.getSize())]
        coordinate.setSpeedValue(state, 0.0)
    return out


def _lengths(engine) -> np.ndarray:
    """Every muscle's path length at the set posture [m]."""
    muscles, state = engine.model.getMuscles(), engine.state
    return np.array([muscles.get(i).getLength(state) for i in range(muscles.getSize())])


def _actuators_off(engine) -> list:
    """Switch every actuator's force off (muscles included) for the inverse dynamics; the forces switched."""
    osim = require_opensim()
    forces = engine.model.getForceSet()
    switched = []
    for i in range(forces.getSize()):
        force = forces.get(i)
        if osim.Actuator.safeDownCast(force) is not None and force.appliesForce(engine.state):
            force.setAppliesForce(engine.state, False)
            switched.append(force)
    return switched


def _restore(engine, forces) -> None:
    """Switch the actuators' forces back on."""
    for force in forces:
        force.setAppliesForce(engine.state, True)


def _passive(engine, index) -> np.ndarray:
    """Gravity and the passive forces at the set posture and zero speed, on the mobilities ``index`` [N m]."""
    osim = require_opensim()
    model, state = engine.model, engine.state
    model.realizeDynamics(state)
    needed = osim.InverseDynamicsSolver(model).solve(state, osim.Vector(state.getNU(), 0.0))
    return -needed.to_numpy()[index]


def _mass(engine, index) -> np.ndarray:
    """The mass matrix over the mobilities ``index`` at the set posture [kg m^2] (Simbody's calcM)."""
    osim = require_opensim()
    mass = osim.Matrix()
    engine.model.getMatterSubsystem().calcM(engine.state, mass)
    return mass.to_numpy()[np.ix_(index, index)]


def _wrapped(engine) -> dict:
    """Muscle index -> the names of the wrap objects on its path, for the muscles that have any."""
    muscles = engine.model.getMuscles()
    out = {}
    for i in range(muscles.getSize()):
        wraps = muscles.get(i).getGeometryPath().getWrapSet()
        if wraps.getSize():
            out[i] = [wraps.get(k).getWrapObject().getName() for k in range(wraps.getSize())]
    return out


def _contacts(engine, wrapped: dict) -> dict:
    """Muscle index -> how many points its current path has (2 more per wrap it touches), at the set posture."""
    muscles = engine.model.getMuscles()
    engine.model.realizePosition(engine.state)
    return {i: muscles.get(i).getGeometryPath().getCurrentPath(engine.state).getSize() for i in wrapped}


def _same_contacts(engine, wrapped: dict, before: dict, after: dict, coordinate: str) -> None:
    """A muscle that touches a wrap on one side of the posture only has a kinked length there: one line."""
    for i, count in before.items():
        if after[i] != count:
            muscle = engine.model.getMuscles().get(i).getName()
            raise ModelError(
                f"{engine.name}: muscle {muscle} starts or stops wrapping over {', '.join(wrapped[i])} within "
                f"{STEP:g} rad of the posture ({coordinate}): its moment arm has a kink there, which the "
                "linearisation cannot differentiate; nothing was linearised (move the posture off the contact)"
            )
