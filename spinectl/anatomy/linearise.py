"""The anatomical chain linearised at a posture: K(a), D(a), M as a LinearChain (docs/anatomy.md).

At zero velocity the generalised force on the joints is

    tau(q, q', a) = sum_i r_i(q) f_i(l_i, v_i, a_i) + tau_passive(q') - g(q),
    f_i = a_i gain_i(l_i, v_i) + bias_i(l_i),

with r_i = dl_i/dq MuJoCo's moment arms (``actuator_moment``), gain and bias MuJoCo's muscle
curves, or for an actuator without activation dynamics (the ``general`` fibres of spinectl's
export, their control a PCSA) MuJoCo's own force at controls 0 and 1 (:func:`mujoco.mj_fwdActuation`),
g gravity (``qfrc_bias`` at zero velocity) and tau_passive every passive force (``qfrc_passive``:
joint and tendon springs, gravity compensation). It is affine in the activations a,
so K(a) = dtau/dq = K_0 + sum_i a_i K_i with

    K_i = H_i gain_i + gain_i' r_i r_i^T,
    K_0 = d(tau_passive - g)/dq + sum_i (H_i bias_i + bias_i' r_i r_i^T),

H_i = d^2 l_i/dq^2 the Hessian of the muscle's length (central differences of MuJoCo's
moment arms: MuJoCo has no tendon Hessian), gain' and bias' the curves' slopes in length
(central differences of the scalar curves, exact on their quadratic pieces). Likewise
D_i = (d gain_i/dv) r_i r_i^T and D_0 = -diag(joint damping) + sum_i (d bias_i/dv) r_i r_i^T.
An actuator that is no muscle (not on a tendon, e.g. the export's ``counter_*`` joint motors)
is held at its control of keyframe 0 (:meth:`~spinectl.anatomy.engine.Engine.held_controls`):
its terms enter K_0, D_0 and the torque offset, none a control of the chain; a joint motor's
force is constant, so it changes the equilibrium only, not K or D. One pass of 2 s position
evaluations over the s joints involved gives every K_i, whatever a.

Two chains: the **free** chain, every chain joint its own degree of freedom and the model's
equality constraints off (the other joints held); and the chain **constrained** by the
model's own rhythm (MuJoCo joint equalities q_dep = P(q_ind)), reduced to its independent
coordinates: K_c = T^T K T + sum_dep tau_dep P''_dep, M_c = T^T M T, D_c = T^T D T, with
T = dq/dq_ind.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, ParameterError
from ..model.linear_chain import LinearChain
from .engine import Engine, require_mujoco

STEP = 1e-5
"""Central-difference step of the moment arms over q [rad]: truncation ~STEP^2, rounding ~eps/STEP."""


@dataclass(frozen=True)
class Rhythm:
    """The model's joint equalities that involve the chain: q = q0 + T(q_ind) (docs/anatomy.md).

    Attributes
    ----------
    independent : tuple of int
        Dof indices (into ``dofs``) of the independent chain coordinates.
    dofs : tuple of int
        Every dof involved: the chain's and the joints slaved to its independent ones.
    transform : numpy.ndarray, shape (len(dofs), len(independent))
        T = dq/dq_ind at the posture.
    curvature : numpy.ndarray, shape (len(dofs), len(independent))
        d^2 q/dq_ind^2 of each dof on its own independent coordinate (0 for a linear rhythm).
    left_out : tuple of str
        The model's other couplings of a chain coordinate (one side off the chain, e.g. a routing body
        such as an ``Abdomen`` moved by the chain), each as one phrase: named, not in the rhythm.
    """

    independent: tuple
    dofs: tuple
    transform: np.ndarray
    curvature: np.ndarray
    left_out: tuple = ()


def _joint_dof(model, joint: int) -> int:
    return int(model.jnt_dofadr[joint])


def rhythm(engine: Engine, chain_joints) -> Rhythm:
    """The active joint equalities among the chain's own joints, as a map from its independent coordinates.

    Only an equality whose two joints are both the chain's (or that locks a chain joint) is the rhythm;
    one that ties a joint off the chain to a chain joint (MyoTorso's ``Abs_r3``, its ``Abdomen``
    routing body, on ``flex_extension``) is named in :attr:`Rhythm.left_out` instead: a routing body
    does not decide the constrained chain's verdict (docs/anatomy.md, "The rhythm").

    Parameters
    ----------
    engine : Engine
        The compiled model (its posture set by :meth:`Engine.set_state`).
    chain_joints : sequence of int
        Joint ids of the chain.

    Returns
    -------
    Rhythm
    """
    mujoco = require_mujoco()
    model, qpos = engine.model, engine.data.qpos
    chain = list(chain_joints)
    slaved, left_out = {}, []  # dependent chain joint -> (independent chain joint or -1, polynomial coefficients)
    for e in range(model.neq):
        if not model.eq_active0[e]:
            continue
        if model.eq_type[e] != mujoco.mjtEq.mjEQ_JOINT:
            raise ModelError(f"{engine.name}: the constrained chain supports joint equalities only (equality {e})")
        j1, j2 = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        if j1 in chain and (j2 < 0 or j2 in chain):
            slaved[j1] = (j2, np.array(model.eq_data[e][:5]))
        elif j1 in chain or j2 in chain:
            left_out.append(_equality_text(engine, e, j1, j2))
    if any(j2 in slaved for j2, _ in slaved.values() if j2 >= 0):
        raise ModelError(f"{engine.name}: a joint equality on a joint that is itself slaved is not supported")
    independent = [j for j in chain if j not in slaved]
    T = np.zeros((len(chain), len(independent)))
    C = np.zeros_like(T)
    for row, j in enumerate(chain):
        if j in independent:
            T[row, independent.index(j)] = 1.0
            continue
        j2, c = slaved[j]
        if j2 < 0:
            continue  # locked
        x = qpos[model.jnt_qposadr[j2]] - model.qpos0[model.jnt_qposadr[j2]]
        powers = np.arange(5)
        T[row, independent.index(j2)] = np.sum(powers[1:] * c[1:] * x ** (powers[1:] - 1))
        C[row, independent.index(j2)] = np.sum(powers[2:] * (powers[2:] - 1) * c[2:] * x ** (powers[2:] - 2))
    dofs = tuple(_joint_dof(model, j) for j in chain)
    return Rhythm(tuple(chain.index(j) for j in independent), dofs, T, C, tuple(left_out))


def _equality_text(engine: Engine, e: int, j1: int, j2: int) -> str:
    """One joint equality as a phrase: its name (or number), the dependent joint and what it follows."""
    mujoco = require_mujoco()
    name = mujoco.mj_id2name(engine.model, mujoco.mjtObj.mjOBJ_EQUALITY, e) or f"equality {e}"
    first = engine.names("joint", [j1])[0]
    return f"{name} ({first} locked)" if j2 < 0 else f"{name} ({first} on {engine.names('joint', [j2])[0]})"


@dataclass(frozen=True)
class Linearisation:
    """Everything read from MuJoCo at one posture, over the dofs involved (chain and slaved joints).

    Attributes
    ----------
    dofs : tuple of int
        MuJoCo dof indices, the first n those of the chain.
    n : int
        The number of chain joints.
    stiffness_per_muscle, stiffness_offset, damping_per_muscle, damping_offset, mass
        K_i (s, s, m), K_0 (s, s), D_i, D_0, M (s, s), over ``dofs`` [SI per unit activation].
    torque_per_muscle : numpy.ndarray, shape (nv, m)
        r_i gain_i: each muscle's generalised force per unit activation on every dof [N m].
    torque_offset : numpy.ndarray, shape (nv,)
        Passive muscle forces less gravity on every dof at the posture [N m].
    moment_arms : numpy.ndarray, shape (m, nv)
        r_i [m/rad].
    notes : tuple of str
        How the muscles' forces were linearised where it is not exact (e.g. OpenSim's compliant
        tendons, at the operating activations); empty when exact.
    """

    dofs: tuple
    n: int
    stiffness_per_muscle: np.ndarray
    stiffness_offset: np.ndarray
    damping_per_muscle: np.ndarray
    damping_offset: np.ndarray
    mass: np.ndarray
    torque_per_muscle: np.ndarray
    torque_offset: np.ndarray
    moment_arms: np.ndarray
    notes: tuple = ()


def _curves(engine: Engine):
    """Each actuator's gain and bias at the set state and their slopes in length and velocity.

    MuJoCo's muscles by its muscle curves (:func:`mujoco.mju_muscleGain`, :func:`mujoco.mju_muscleBias`);
    any other actuator by MuJoCo's own force (:func:`mujoco.mj_fwdActuation`, at control 0 and 1,
    its tendon's length and velocity moved by central differences), e.g. the affine gain of
    spinectl's export (:func:`spinectl.anatomy.export_mjcf.affine_gain`).
    """
    mujoco = require_mujoco()
    model, d = engine.model, engine.data
    m = model.nu
    out = np.zeros((6, m))  # gain, dgain/dl, dgain/dv, bias, dbias/dl, dbias/dv
    muscle = model.actuator_dyntype == mujoco.mjtDyn.mjDYN_MUSCLE
    for i in np.flatnonzero(muscle):
        lr, acc0 = model.actuator_lengthrange[i], model.actuator_acc0[i]
        gp, bp = model.actuator_gainprm[i][:9], model.actuator_biasprm[i][:9]  # the curves read 9
        length, vel = d.actuator_length[i], d.actuator_velocity[i]
        h = 1e-6 * (lr[1] - lr[0])

        def gain(dl=0.0, dv=0.0, lr=lr, acc0=acc0, gp=gp, length=length, vel=vel):
            return mujoco.mju_muscleGain(length + dl, vel + dv, lr, acc0, gp)

        def bias(dl=0.0, lr=lr, acc0=acc0, bp=bp, length=length):
            return mujoco.mju_muscleBias(length + dl, lr, acc0, bp)

        out[:5, i] = (
            gain(),
            (gain(h) - gain(-h)) / (2 * h),
            (gain(dv=h) - gain(dv=-h)) / (2 * h),
            bias(),
            (bias(h) - bias(-h)) / (2 * h),
        )
    if not np.all(muscle):
        out[:, ~muscle] = _actuator_curves(engine)[:, ~muscle]
    return out


def _actuator_curves(engine: Engine) -> np.ndarray:
    """gain, its slopes, bias and its slopes of every actuator without activation dynamics, by MuJoCo's force.

    The force is gain(l, v) u + bias(l, v) at control u (:func:`mujoco.mj_fwdActuation`, the
    controls unclamped): bias at u = 0, gain = force(1) - force(0); the slopes by central
    differences of MuJoCo's ``actuator_length`` and ``actuator_velocity`` (exact for an affine gain).
    """
    mujoco = require_mujoco()
    model, d = engine.model, engine.data
    length, vel, ctrl = d.actuator_length.copy(), d.actuator_velocity.copy(), d.ctrl.copy()
    span = model.actuator_lengthrange[:, 1] - model.actuator_lengthrange[:, 0]
    h = 1e-6 * np.maximum(np.maximum(span, np.abs(length)), 1e-3)
    flags = model.opt.disableflags
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CLAMPCTRL

    def force(u, dl=0.0, dv=0.0):
        d.ctrl[:] = u
        d.actuator_length[:] = length + dl
        d.actuator_velocity[:] = vel + dv
        mujoco.mj_fwdActuation(model, d)
        return d.actuator_force.copy()

    try:
        values = []
        for u in (1.0, 0.0):
            values += [force(u), (force(u, h) - force(u, -h)) / (2 * h), (force(u, dv=h) - force(u, dv=-h)) / (2 * h)]
    finally:
        model.opt.disableflags = flags
        d.ctrl[:], d.actuator_length[:], d.actuator_velocity[:] = ctrl, length, vel
    at_one, at_zero = np.array(values[:3]), np.array(values[3:])
    return np.concatenate([at_one - at_zero, at_zero])


def linearise(engine: Engine, qpos, dofs, n: int) -> Linearisation:
    """K_i, K_0, D_i, D_0, M at a posture over the given dofs (module docstring).

    Parameters
    ----------
    engine : Engine
        The compiled model.
    qpos : array_like, shape (nq,)
        The posture.
    dofs : sequence of int
        MuJoCo dof indices (hinge joints), the chain's first.
    n : int
        How many of ``dofs`` are the chain's.

    Returns
    -------
    Linearisation
    """
    mujoco = require_mujoco()
    model, d = engine.model, engine.data
    if model.nq != model.nv:
        raise ModelError(f"{engine.name}: free or ball joints are not supported (nq != nv)")
    if np.any(~np.isin(model.actuator_dyntype, [mujoco.mjtDyn.mjDYN_MUSCLE, mujoco.mjtDyn.mjDYN_NONE])):
        raise ModelError(f"{engine.name}: every actuator must be a muscle or have no activation dynamics")
    dofs = list(dofs)
    s, nu = len(dofs), model.nu
    qpos = np.asarray(qpos, float)
    engine.set_state(qpos)
    arms = engine.moment_arms()
    r = arms[:, dofs]
    curves = _curves(engine)
    gravity = -d.qfrc_bias.copy()
    mass = engine.mass_matrix()
    hessian = np.zeros((nu, s, s))
    dgravity = np.zeros((s, s))
    contacts = d.ten_wrapnum.copy()  # path points of every tendon: 2 more per wrap geom it touches
    for k, dof in enumerate(dofs):
        sides = []
        for sign in (1.0, -1.0):
            q = qpos.copy()
            q[model.dof_jntid[dof]] += sign * STEP
            engine.set_state(q)
            _same_contacts(engine, contacts, int(model.dof_jntid[dof]))
            # gravity and every passive force: joint and tendon springs, gravity compensation (mj_passive)
            sides.append((engine.moment_arms()[:, dofs], (d.qfrc_passive - d.qfrc_bias)[dofs].copy()))
        hessian[:, :, k] = (sides[0][0] - sides[1][0]) / (2 * STEP)
        dgravity[:, k] = (sides[0][1] - sides[1][1]) / (2 * STEP)
    engine.set_state(qpos)
    hessian = 0.5 * (hessian + hessian.transpose(0, 2, 1))  # a Hessian: symmetric up to rounding
    rr = np.einsum("ij,ik->jki", r, r)  # (s, s, m): r_i r_i^T
    gain, dgain_dl, dgain_dv, bias, dbias_dl, dbias_dv = curves
    # the actuators that are no muscle (engine.held_controls) add to the offsets at their held controls
    held = engine.held_controls()
    bias, dbias_dl, dbias_dv = bias + held * gain, dbias_dl + held * dgain_dl, dbias_dv + held * dgain_dv
    k_per = hessian.transpose(1, 2, 0) * gain + rr * dgain_dl
    k_0 = 0.5 * (dgravity + dgravity.T) + np.einsum("ijk,i->jk", hessian, bias) + rr @ dbias_dl
    muscles = engine.muscle_ids()
    return Linearisation(
        dofs=tuple(dofs),
        n=n,
        stiffness_per_muscle=k_per[..., muscles],
        stiffness_offset=k_0,
        damping_per_muscle=(rr * dgain_dv)[..., muscles],
        damping_offset=rr @ dbias_dv - np.diag(model.dof_damping[dofs]),
        mass=mass[np.ix_(dofs, dofs)],
        torque_per_muscle=(arms.T * gain)[:, muscles],
        torque_offset=gravity + d.qfrc_passive + arms.T @ bias,
        moment_arms=arms[muscles],
    )


def _same_contacts(engine: Engine, contacts, joint: int) -> None:
    """A muscle's tendon that touches a wrap geom on one side of the posture only has a kinked moment arm: one line."""
    mujoco = require_mujoco()
    model, d = engine.model, engine.data
    for i in engine.muscle_ids():
        t = int(model.actuator_trnid[i, 0])
        if d.ten_wrapnum[t] == contacts[t]:
            continue
        span = range(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t])
        wraps = (int(mujoco.mjtWrap.mjWRAP_SPHERE), int(mujoco.mjtWrap.mjWRAP_CYLINDER))
        geoms = [int(model.wrap_objid[w]) for w in span if int(model.wrap_type[w]) in wraps]
        engine.set_state(model.qpos0)  # leave the engine at a posture of the model
        raise ModelError(
            f"{engine.name}: muscle {engine.names('actuator', [i])[0]} starts or stops wrapping over "
            f"{', '.join(engine.names('geom', geoms)) or 'a wrap geom'} within {STEP:g} rad of the posture "
            f"({engine.names('joint', [joint])[0]}): its moment arm has a kink there, which the linearisation "
            "cannot differentiate; nothing was linearised (move the posture off the contact)"
        )


def _chain(
    lin: Linearisation, rows, T, joints, controls, classes, added, source, curvature=None, bounds=None, unit="1"
):
    """A LinearChain of the linearisation reduced by T (the free chain: T selects the chain's rows)."""
    k_per = np.einsum("ai,abm,bj->ijm", T, lin.stiffness_per_muscle[np.ix_(rows, rows)], T)
    k_0 = T.T @ lin.stiffness_offset[np.ix_(rows, rows)] @ T - T.T @ np.diag(added) @ T
    if curvature is not None:  # the rhythm's second derivative times the slaved joints' torques
        dofs = [lin.dofs[r] for r in rows]
        diag = np.arange(T.shape[1])
        k_0[diag, diag] += curvature.T @ lin.torque_offset[dofs]
        k_per[diag, diag, :] += curvature.T @ lin.torque_per_muscle[dofs]
    return LinearChain(
        joints=joints,
        controls=controls,
        control_class=classes,
        stiffness_per_control=k_per,
        damping_per_control=np.einsum("ai,abm,bj->ijm", T, lin.damping_per_muscle[np.ix_(rows, rows)], T),
        stiffness_offset=k_0,
        damping_offset=T.T @ lin.damping_offset[np.ix_(rows, rows)] @ T,
        mass_matrix=T.T @ lin.mass[np.ix_(rows, rows)] @ T,
        lower=np.zeros(len(controls)) if bounds is None else bounds[0],
        upper=np.ones(len(controls)) if bounds is None else bounds[1],
        control_unit=unit,
        source=source,
    )


def free_chain(lin: Linearisation, joints, controls, classes, added, source, bounds=None, unit="1") -> LinearChain:
    """The free chain: every chain joint free, the model's equalities off, the other joints held.

    Parameters
    ----------
    lin : Linearisation
        From :func:`linearise`.
    joints, controls, classes : sequence of str
        Chain joint names, muscle names and classes.
    added : array_like, shape (n,)
        Joint stiffness added at each chain joint [N m/rad].
    source : str
        For outputs.
    bounds : tuple, optional
        (lower, upper) of each control; default [0, 1] (activations).
    unit : str
        The controls' unit (``"1"``: activations).

    Returns
    -------
    LinearChain
    """
    n = lin.n
    added = np.asarray(added, float)
    return _chain(lin, list(range(n)), np.eye(n), joints, controls, classes, added, source, bounds=bounds, unit=unit)


def constrained_chain(
    lin: Linearisation, rhy: Rhythm, joint_names, controls, classes, added, source, bounds=None, unit="1"
) -> LinearChain:
    """The chain constrained by the model's rhythm, in its independent coordinates.

    Parameters
    ----------
    lin : Linearisation
        From :func:`linearise` over ``rhy.dofs``.
    rhy : Rhythm
        From :func:`rhythm`.
    joint_names : sequence of str
        Names of ``rhy.dofs``' joints.
    controls, classes : sequence of str
        Muscle names and classes.
    added : array_like, shape (len(rhy.dofs),)
        Joint stiffness added at each involved joint [N m/rad] (0 off the chain).
    source : str
        For outputs.
    bounds : tuple, optional
        (lower, upper) of each control; default [0, 1] (activations).
    unit : str
        The controls' unit (``"1"``: activations).

    Returns
    -------
    LinearChain
    """
    if tuple(lin.dofs) != tuple(rhy.dofs):
        raise ParameterError("rhythm", "must be over the linearisation's dofs")
    rows = list(range(len(rhy.dofs)))
    joints = tuple(joint_names[i] for i in rhy.independent)
    added = np.asarray(added, float)
    return _chain(
        lin, rows, rhy.transform, joints, controls, classes, added, source, rhy.curvature, bounds=bounds, unit=unit
    )
