"""What the anatomy figures draw, computed with MuJoCo's kinematics (docs/anatomy.md, "Figures").

Pure data, no plotting (:mod:`spinectl.anatomy.figures` draws it): the model projected on its
sagittal plane (the CoRs of the chain, the thorax's centre of mass, every muscle's path with its
class) and the chain bent along each mode of -K.

The sagittal plane is the plane normal to the first sagittal chain joint's axis; its vertical is
against gravity and its horizontal is up x axis, which is anterior for MyoTorso (whose
flex_extension axis is -x and whose +y is posterior). Every point is MuJoCo's (``xanchor``,
``xipos``, the tendons' ``wrap_xpos``) at the posture, after :func:`mujoco.mj_kinematics`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .engine import require_mujoco
from .model import Anatomy

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
        Their centres of rotation (MuJoCo's joint anchors).
    thorax : numpy.ndarray, shape (2,)
        The thorax body's centre of mass: the spine line's top.
    muscles : tuple of str
        Muscle names.
    classes : tuple of str
        Each muscle's class.
    segments : tuple of tuple
        Per muscle, its path (MuJoCo's sites and wrapping points in order), split into branches
        where MuJoCo puts a pulley: arrays of shape (p_k, 2).
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


def _axes(anatomy: Anatomy, data, first_joint: int):
    """The sagittal plane's (horizontal, vertical) unit axes: up x normal and against gravity."""
    gravity = np.asarray(anatomy.engine.model.opt.gravity, float)
    up = -gravity / np.linalg.norm(gravity) if np.linalg.norm(gravity) > 0 else np.array([0.0, 0.0, 1.0])
    normal = np.asarray(data.xaxis[first_joint], float)
    horizontal = np.cross(up, normal)
    return horizontal / np.linalg.norm(horizontal), up


def _kinematics(anatomy: Anatomy, qpos):
    """MuJoCo's positions (bodies, anchors, tendon paths) at qpos; the engine's scratch data."""
    mujoco = require_mujoco()
    engine = anatomy.engine
    engine.data.qpos[:] = qpos
    mujoco.mj_kinematics(engine.model, engine.data)
    mujoco.mj_comPos(engine.model, engine.data)
    mujoco.mj_tendon(engine.model, engine.data)
    return engine.data


def _spine(anatomy: Anatomy, data, joint_ids, axes):
    """The chain's anchors and the thorax's centre of mass, projected."""
    mujoco = require_mujoco()
    basis = np.stack(axes)  # (2, 3)
    thorax = mujoco.mj_name2id(anatomy.engine.model, mujoco.mjtObj.mjOBJ_BODY, anatomy.mapping.bodies["thorax"][0])
    return data.xanchor[joint_ids] @ basis.T, data.xipos[thorax] @ basis.T


def sagittal_projection(anatomy: Anatomy, posture=None) -> SagittalProjection:
    """The model's sagittal projection: CoRs, the spine line's top and every muscle's path with its class.

    Parameters
    ----------
    anatomy : Anatomy
        The model.
    posture : array_like, optional
        Full qpos; default the model's reference posture.

    Returns
    -------
    SagittalProjection
    """
    names = anatomy.plane_joints("sagittal")
    ids = anatomy.joint_ids(names)
    data = _kinematics(anatomy, anatomy.posture(posture))
    axes = _axes(anatomy, data, ids[0])
    basis = np.stack(axes)
    cors, thorax = _spine(anatomy, data, ids, axes)
    model = anatomy.engine.model
    points = data.wrap_xpos.reshape(-1, 3) @ basis.T
    objects = data.wrap_obj.reshape(-1)
    segments = []
    for i in anatomy.engine.muscle_ids():
        tendon = int(model.actuator_trnid[i, 0])
        start, count = int(data.ten_wrapadr[tendon]), int(data.ten_wrapnum[tendon])
        pts, obj = points[start : start + count], objects[start : start + count]
        pieces = np.split(pts, np.flatnonzero(obj == -2))  # a pulley (-2) starts the next branch
        branches = [pieces[0]] + [piece[1:] for piece in pieces[1:]]
        segments.append(tuple(b for b in branches if len(b) > 1))
    return SagittalProjection(
        joints=tuple(names),
        cors=cors,
        thorax=thorax,
        muscles=anatomy.muscles,
        classes=anatomy.classes,
        segments=tuple(segments),
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


def mode_shapes(anatomy: Anatomy, chain_verdict, posture=None, angle_deg: float = MODE_ANGLE) -> ModeShapes:
    """The sagittal chain at the posture and bent along each mode of -K, by MuJoCo's kinematics.

    Each mode v (unit) is scaled so that ``sum_j abs(q_j) = angle_deg`` and added to the chain's
    angles (the other joints held, equality constraints ignored: the free chain's modes).

    Parameters
    ----------
    anatomy : Anatomy
        The model.
    chain_verdict : ChainVerdict
        The free sagittal chain's verdict (:func:`~spinectl.anatomy.analyses.verdict`): its
        eigenvalues and modes.
    posture : array_like, optional
        Full qpos; default the model's reference posture.
    angle_deg : float
        The summed absolute angle of each bent spine [deg].

    Returns
    -------
    ModeShapes
    """
    model = anatomy.engine.model
    ids = anatomy.joint_ids(chain_verdict.joints)
    qadr = np.array([model.jnt_qposadr[j] for j in ids])
    q0 = anatomy.posture(posture)
    data = _kinematics(anatomy, q0)
    axes = _axes(anatomy, data, ids[0])

    def line(qpos):
        cors, thorax = _spine(anatomy, _kinematics(anatomy, qpos), ids, axes)
        return np.vstack([cors, thorax])

    rest = line(q0)
    bent = []
    for v in chain_verdict.modes.T:
        q = q0.copy()
        q[qadr] += v * np.radians(angle_deg) / np.abs(v).sum()
        bent.append(line(q))
    return ModeShapes(
        joints=tuple(chain_verdict.joints),
        eigenvalues=np.asarray(chain_verdict.eigenvalues),
        modes=np.asarray(chain_verdict.modes),
        rest=rest,
        bent=np.array(bent),
        angle_deg=float(angle_deg),
    )
