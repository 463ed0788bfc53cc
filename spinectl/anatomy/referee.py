"""MuJoCo as the referee of an anatomical chain: its own linearisation and its simulation along a mode.

``spinectl anatomy --check`` compares the free chain's eigenvalues with MuJoCo's ``mjd_transitionFD`` at
the reference posture and simulates the leading mode with ``mj_step`` (docs/anatomy.md, "The
linearisation"): their kinematics and forces, our stability.
"""

from __future__ import annotations

import numpy as np

from ..model.linear_chain import LinearChain
from .engine import require_mujoco
from .model import Anatomy


def referee_model(anatomy: Anatomy, chain: LinearChain, a, added) -> tuple:
    """MuJoCo's model of the free chain, held at the reference posture (:func:`mujoco_eigenvalues`).

    Parameters
    ----------
    anatomy : Anatomy
        The model.
    chain : LinearChain
        The free chain, for its joints.
    a : array_like, shape (m,)
        Activations, set as MuJoCo's activation states and controls (so that they stay).
    added : array_like, shape (n,)
        Joint stiffness added at each chain joint [N m/rad].

    Returns
    -------
    tuple
        (mujoco.MjModel, mujoco.MjData) at the posture, forward dynamics run.
    """
    mujoco = require_mujoco()
    spec = anatomy.engine.spec_factory()
    keep = dict(zip(chain.joints, np.asarray(added, float), strict=True))
    for joint in list(spec.joints):
        if joint.name not in keep:
            spec.delete(joint)
    for equality in list(spec.equalities):
        spec.delete(equality)
    model = spec.compile()
    for name, value in keep.items():
        model.jnt_stiffness[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)] = value
    flags = mujoco.mjtDisableBit
    model.opt.disableflags |= flags.mjDSBL_CONTACT | flags.mjDSBL_EQUALITY | flags.mjDSBL_LIMIT
    model.opt.disableflags |= flags.mjDSBL_EULERDAMP
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    data = mujoco.MjData(model)
    ctrl = anatomy.engine.held_controls()  # the actuators that are no muscle at their held controls
    ctrl[anatomy.engine.muscle_ids()] = a
    data.ctrl[:] = ctrl
    stateful = model.actuator_actadr >= 0
    data.act[model.actuator_actadr[stateful]] = ctrl[stateful]  # muscle dynamics drive act to ctrl: held
    mujoco.mj_forward(model, data)
    # held by constant torques where the posture is no equilibrium: off one, a step's
    # derivative would also hold dM^-1/dq times the net torque, which K = dtau/dq leaves out
    data.qfrc_applied[:] = -(data.qfrc_actuator + data.qfrc_passive - data.qfrc_bias)
    mujoco.mj_forward(model, data)
    return model, data


def mujoco_growth_rate(anatomy: Anatomy, chain: LinearChain, a, added, eigenvalue, mode, duration=0.1, step=1e-4):
    """The rate at which MuJoCo's own simulation (:func:`mujoco.mj_step`) grows or decays along a mode.

    Starts at the posture displaced by 1e-5 rad along the mode (its velocity the eigenvalue times
    that), steps MuJoCo's free chain (:func:`referee_model`, time step ``step``) for ``duration``
    and fits the log of the displacement's projection on the mode against time (least squares).

    Parameters
    ----------
    anatomy : Anatomy
        The model.
    chain : LinearChain
        The free chain.
    a : array_like, shape (m,)
        Activations, held.
    added : array_like, shape (n,)
        Joint stiffness added [N m/rad].
    eigenvalue : float
        A real eigenvalue of the state matrix [1/s].
    mode : array_like, shape (n,)
        Its joint-angle part [rad].
    duration, step : float
        Simulated time and MuJoCo's time step [s].

    Returns
    -------
    float
        The fitted rate [1/s].
    """
    mujoco = require_mujoco()
    model, data = referee_model(anatomy, chain, a, added)
    model.opt.timestep = step
    order = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in chain.joints]
    qadr = np.array([model.jnt_qposadr[j] for j in order])
    vadr = np.array([model.jnt_dofadr[j] for j in order])
    v = np.asarray(mode, float) / np.linalg.norm(mode)
    q0 = data.qpos[qadr].copy()
    data.qpos[qadr] += 1e-5 * v
    data.qvel[vadr] = 1e-5 * eigenvalue * v
    times, amplitude = [], []
    for k in range(int(round(duration / step))):
        mujoco.mj_step(model, data)
        times.append((k + 1) * step)
        amplitude.append(abs(v @ (data.qpos[qadr] - q0)))
    return float(np.polyfit(times, np.log(amplitude), 1)[0])


def mujoco_eigenvalues(anatomy: Anatomy, chain: LinearChain, a, added) -> np.ndarray:
    """MuJoCo's own linearisation of the free chain: eigenvalues from :func:`mujoco.mjd_transitionFD`.

    The referee: a copy of the model with every joint off the chain removed (its body
    welded at the reference posture), equality constraints, contacts and limits disabled,
    the added stiffness as MuJoCo joint stiffness, the posture held by constant applied
    torques where it is no equilibrium (as the paper's counter torques would), and Euler's
    implicit joint damping off,
    so that one step is v+ = v + h M^-1 f(q, v) exactly. Its discrete transition's velocity
    rows give the continuous state matrix, [[0, I], [A_vq/h, (A_vv - I)/h]]; the
    activations are states of their own, held.

    Parameters
    ----------
    anatomy : Anatomy
        The model (at its reference posture).
    chain : LinearChain
        The free chain, for its joints.
    a : array_like, shape (m,)
        Activations.
    added : array_like, shape (n,)
        Joint stiffness added at each chain joint [N m/rad].

    Returns
    -------
    numpy.ndarray, shape (2n,)
        Eigenvalues [1/s], by descending real part.
    """
    mujoco = require_mujoco()
    model, data = referee_model(anatomy, chain, a, added)
    n, h = model.nv, model.opt.timestep
    order = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in chain.joints]
    size = 2 * n + model.na
    A = np.zeros((size, size))
    mujoco.mjd_transitionFD(model, data, 1e-6, True, A, None, None, None)
    dofs = np.array([model.jnt_dofadr[j] for j in order])
    a_vq = A[np.ix_(n + dofs, dofs)]
    a_vv = A[np.ix_(n + dofs, n + dofs)]
    cont = np.block([[np.zeros((n, n)), np.eye(n)], [a_vq / h, (a_vv - np.eye(n)) / h]])
    dyn = np.linalg.eigvals(cont)
    return dyn[np.lexsort((-dyn.imag, -dyn.real))]
