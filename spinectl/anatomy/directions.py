"""The directions every engine's posture and drawing share: the lordosis along the rhythm, a plane's axes.

Pure functions of the rhythm and of vectors in the engine's world (docs/anatomy.md, "The lordosis" and
"Figures"); the engines (:mod:`spinectl.anatomy.model`, :mod:`spinectl.anatomy.opensim_engine`) call them.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError


def lordosis_direction(anatomy, rhy, n: int, degrees: float, slopes=None) -> np.ndarray:
    """The change of the involved coordinates [rad] that moves the chain's joint angles by ``degrees`` in sum.

    The rhythm's first independent coordinate and the joints it slaves move as its column of T;
    a chain whose first joint no rhythm ties to another has no lordosis to move along (one line).
    The sum is of the joints' rotations (S T's column over the chain), not of their coordinates.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (for its name).
    rhy : spinectl.anatomy.linearise.Rhythm
        The rhythm over the involved joints, the chain's n first.
    n : int
        The number of chain joints.
    degrees : float
        The change of the chain's summed joint angle [deg].
    slopes : JointSlopes, optional
        The chain's joint rotation per coordinate
        (:meth:`~spinectl.anatomy.contract.MappedModel.joint_slopes`); default the identity.

    Returns
    -------
    numpy.ndarray, shape (len(rhy.dofs),)
        In the rhythm's coordinates.
    """
    direction = rhy.transform[:, 0]
    turned = direction[:n] if slopes is None or slopes.is_identity() else slopes.jacobian @ direction[:n]
    if n > 1 and np.count_nonzero(direction[:n]) < 2:
        raise ModelError(
            f"lordosis: {anatomy.name} has no rhythm (joint equality or coordinate coupler) that ties its chain's "
            "first joint to the others, so the chain has no lordosis to move along; give the model one "
            "(spinectl's export: export it at another Lambda)"
        )
    return direction * np.radians(degrees) / turned.sum()


def plane_axes(gravity, normal, default_up) -> tuple:
    """A plane's (horizontal, vertical) unit axes: vertical against gravity, horizontal up x the plane's normal.

    Parameters
    ----------
    gravity : array_like, shape (3,)
        The engine's gravity in its world [m/s^2].
    normal : array_like, shape (3,)
        The plane's normal (the first chain joint's axis), in the same world.
    default_up : array_like, shape (3,)
        The world's up where there is no gravity (MuJoCo's +z, OpenSim's +y).

    Returns
    -------
    tuple
        (horizontal, up), numpy.ndarray of shape (3,) each.
    """
    gravity = np.asarray(gravity, float)
    size = np.linalg.norm(gravity)
    up = -gravity / size if size > 0 else np.asarray(default_up, float)
    horizontal = np.cross(up, np.asarray(normal, float))
    return horizontal / np.linalg.norm(horizontal), up
