"""Each OpenSim chain joint's rotation per unit of its coordinate, by OpenSim's own kinematics (docs/anatomy.md).

A CustomJoint turns its child frame by its SpatialTransform's functions of its coordinates: in the
Christophy family of lumbar models ``flex_extension`` turns L5/S1 by 0.125 rad per radian (and the
other joints through couplers). :func:`joint_slopes` reads how each chain joint turns from the
frames' angular velocities per unit coordinate speed (``Frame.getAngularVelocityInGround``, the
couplers off), which :mod:`spinectl.anatomy.joint_angles` turns into per-joint-radian chains.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .joint_angles import JointSlopes
from .linearise import STEP


def _relative_spins(engine, names, values: dict) -> np.ndarray:
    """omega[j, k]: the angular velocity in ground of coordinate j's joint (child frame less parent frame)
    per unit speed of coordinate k, at a posture [rad per coordinate unit]: OpenSim's kinematics, exact."""
    engine.set_posture(values)
    model, state = engine.model, engine.state
    joints = [engine.coordinate(n).getJoint() for n in names]
    out = np.zeros((len(names), len(names), 3))
    for k, name in enumerate(names):
        engine.coordinate(name).setSpeedValue(state, 1.0)
        model.realizeVelocity(state)
        for j, joint in enumerate(joints):
            child = joint.getChildFrame().getAngularVelocityInGround(state).to_numpy()
            out[j, k] = child - joint.getParentFrame().getAngularVelocityInGround(state).to_numpy()
        engine.coordinate(name).setSpeedValue(state, 0.0)
    model.realizePosition(state)
    return out


def joint_slopes(engine, names, values: dict) -> JointSlopes:
    """How each chain coordinate's joint turns per unit of the chain's coordinates at a posture.

    Joint j's angle is its child frame's rotation relative to its parent frame about its own axis
    a_j, the direction in which its own coordinate turns it (OpenSim's frame velocities per unit
    coordinate speed, :func:`_relative_spins`), signed to agree with the first joint's (the plane's
    normal), so that the chain's angles sum as one lordosis. S_jk = omega_jk . a_j; the curvature
    d S_jj/dq_j by central differences of the same (0 for a LinearFunction, as in Christophy's model).

    Parameters
    ----------
    engine : OsimEngine
    names : sequence of str
        The chain's coordinates.
    values : dict
        Coordinate name -> value [rad] of the posture.

    Returns
    -------
    JointSlopes
    """
    names = list(names)
    spins = _relative_spins(engine, names, values)
    own = np.array([spins[j, j] for j in range(len(names))])
    sizes = np.linalg.norm(own, axis=1)
    if not np.all(sizes > 0):
        still = [n for n, size in zip(names, sizes, strict=True) if not size > 0]
        raise ModelError(
            f"{engine.name}: chain coordinate(s) {still} turn no joint here (a translation?): no joint angle"
        )
    axes = own / sizes[:, None]
    axes *= np.where(axes @ axes[0] < 0, -1.0, 1.0)[:, None]
    jacobian = np.einsum("jkx,jx->jk", spins, axes)
    curvature = np.zeros(len(names))
    for j, name in enumerate(names):
        start = values.get(name, engine.coordinate(name).getDefaultValue())
        sides = [_relative_spins(engine, [name], {**values, name: start + h})[0, 0] @ axes[j] for h in (STEP, -STEP)]
        curvature[j] = (sides[0] - sides[1]) / (2 * STEP)
    engine.set_posture(values)
    return JointSlopes(jacobian, curvature)
