"""What the anatomy figures draw, computed with the engine's kinematics (docs/anatomy.md, "Figures").

Pure data, no plotting (:mod:`spinectl.anatomy.figures` draws it): the model projected on its
sagittal plane (the CoRs of the chain, the thorax's centre of mass, every muscle's path with its
class) and the chain bent along each mode of -K.

The sagittal plane is the plane normal to the first sagittal chain joint's axis; its vertical is
against gravity and its horizontal is up x axis, which is anterior for MyoTorso (whose
flex_extension axis is -x and whose +y is posterior). Every point is the engine's at the posture,
through the contract (:class:`~spinectl.anatomy.contract.AnatomyEngine`: ``sagittal_axes``, ``spine``,
``muscle_paths``): MuJoCo's ``xanchor``, ``xipos`` and the tendons' ``wrap_xpos`` after
:func:`mujoco.mj_kinematics`; OpenSim's joint centres, the thorax's mass centre and the muscles' current
paths in ground.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contract import AnatomyEngine

MODE_ANGLE = 30.0
"""The summed absolute joint angle of each drawn mode [deg]: exaggerated, so that a mode's shape shows."""


@dataclass(frozen=True)
class SagittalProjection:
    """The model in its sagittal plane (:func:`sagittal_projection`); coordinates [m], (horizontal, up).

    Attributes
    ----------
    joints : tuple of str
        The chain's joints, L5S1 up.
    cors : numpy.ndarray, shape (n, 2)
        Their centres of rotation (MuJoCo's joint anchors, OpenSim's joint centres).
    thorax : numpy.ndarray, shape (2,)
        The thorax body's centre of mass: the spine line's top.
    muscles : tuple of str
        Muscle names.
    classes : tuple of str
        Each muscle's class.
    segments : tuple of tuple
        Per muscle, its path (MuJoCo's sites and wrapping points in order, OpenSim's current path), split
        into branches where MuJoCo puts a pulley: arrays of shape (p_k, 2).
    horizontal_axis, vertical_axis : numpy.ndarray, shape (3,)
        The plane's unit axes in world coordinates.
    """

    joints: tuple
    cors: np.ndarray
    thorax: np.ndarray
    muscles: tuple
    classes: tuple
    segments: tuple
    horizontal_axis: np.ndarray
    vertical_axis: np.ndarray


def sagittal_projection(anatomy: AnatomyEngine, posture=None) -> SagittalProjection:
    """The model's sagittal projection: CoRs, the spine line's top and every muscle's path with its class.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    posture : optional
        The operating point (the engine's form); default the model's reference posture.

    Returns
    -------
    SagittalProjection
    """
    names = anatomy.plane_joints("sagittal")
    axes = anatomy.sagittal_axes(names, posture)
    basis = np.stack(axes)  # (2, 3)
    cors, thorax = anatomy.spine(names, basis, posture)
    segments = anatomy.muscle_paths(basis, posture)
    return SagittalProjection(
        joints=tuple(names),
        cors=cors,
        thorax=thorax,
        muscles=anatomy.muscles,
        classes=anatomy.classes,
        segments=segments,
        horizontal_axis=axes[0],
        vertical_axis=axes[1],
    )


@dataclass(frozen=True)
class ModeShapes:
    """The sagittal chain bent along each mode of -K (:func:`mode_shapes`); coordinates [m].

    Attributes
    ----------
    joints : tuple of str
        The chain's joints.
    eigenvalues : numpy.ndarray, shape (n,)
        Of -K, ascending [N m/rad]: <= 0 an unstable mode.
    modes : numpy.ndarray, shape (n, n)
        Unit eigenvectors, one per column [rad per unit].
    rest : numpy.ndarray, shape (n + 1, 2)
        The spine line at the posture: the CoRs and the thorax's centre of mass.
    bent : numpy.ndarray, shape (n, n + 1, 2)
        The spine line with the chain's angles moved along each mode.
    angle_deg : float
        The summed absolute joint angle of each bent spine [deg].
    """

    joints: tuple
    eigenvalues: np.ndarray
    modes: np.ndarray
    rest: np.ndarray
    bent: np.ndarray
    angle_deg: float


def mode_shapes(anatomy: AnatomyEngine, chain_verdict, posture=None, angle_deg: float = MODE_ANGLE) -> ModeShapes:
    """The sagittal chain at the posture and bent along each mode of -K, by the engine's kinematics.

    Each mode v (unit) is scaled so that ``sum_j abs(q_j) = angle_deg`` and added to the chain's
    angles (the other joints held, equality constraints ignored: the free chain's modes).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    chain_verdict : ChainVerdict
        The free sagittal chain's verdict (:func:`~spinectl.anatomy.analyses.verdict`): its
        eigenvalues and modes.
    posture : optional
        The operating point (the engine's form); default the model's reference posture.
    angle_deg : float
        The summed absolute angle of each bent spine [deg].

    Returns
    -------
    ModeShapes
    """
    joints = tuple(chain_verdict.joints)
    basis = np.stack(anatomy.sagittal_axes(joints, posture))

    def line(moved=None):
        cors, thorax = anatomy.spine(joints, basis, posture, moved)
        return np.vstack([cors, thorax])

    rest = line()
    bent = [line(v * np.radians(angle_deg) / np.abs(v).sum()) for v in chain_verdict.modes.T]
    return ModeShapes(
        joints=tuple(chain_verdict.joints),
        eigenvalues=np.asarray(chain_verdict.eigenvalues),
        modes=np.asarray(chain_verdict.modes),
        rest=rest,
        bent=np.array(bent),
        angle_deg=float(angle_deg),
    )
