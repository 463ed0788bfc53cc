"""An anatomical model loaded with its mapping: its chains as LinearChain objects (docs/anatomy.md)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ModelError, ParameterError
from .contract import MappedModel
from .directions import lordosis_direction, plane_axes
from .engine import CONTROL_UNIT, Engine, load_engine, require_mujoco
from .linearise import Linearisation, linearise, rhythm
from .loads import mujoco_apply_loads
from .mapping import Mapping, check_mapping, classify, default_mapping, read_mapping


@dataclass
class Anatomy(MappedModel):
    """A MuJoCo musculoskeletal model mapped onto the chain: MuJoCo's :class:`~spinectl.anatomy.contract.AnatomyEngine`.

    Its rhythm is the model's joint equalities.

    Parameters
    ----------
    engine : Engine
        The compiled MuJoCo model (:class:`~spinectl.anatomy.engine.Engine`).
    mapping : Mapping
        Its chain joints, body groups and added stiffness.
    muscles, classes : tuple of str
        The actuators' names and their classes (:func:`spinectl.anatomy.mapping.classify`).
    """

    engine: Engine

    def joint_ids(self, names) -> list:
        """MuJoCo joint ids of joint names.

        Parameters
        ----------
        names : iterable of str
            Joint names.

        Returns
        -------
        list of int
        """
        mujoco = require_mujoco()
        return [mujoco.mj_name2id(self.engine.model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names]

    def control_bounds(self) -> tuple:
        """Each muscle's control bounds: [0, 1] for MuJoCo's muscles (activations), else its ``ctrlrange``
        if limited, [0, inf) if not (spinectl's export: a PCSA in cm^2).

        Returns
        -------
        tuple
            (lower, upper), numpy.ndarray of shape (m,) [:attr:`control_unit`].
        """
        mujoco = require_mujoco()
        model, ids = self.engine.model, self.engine.muscle_ids()
        muscle = model.actuator_dyntype[ids] == mujoco.mjtDyn.mjDYN_MUSCLE
        limited = model.actuator_ctrllimited[ids].astype(bool) & ~muscle
        lower = np.where(limited, model.actuator_ctrlrange[ids, 0], 0.0)
        upper = np.where(limited, model.actuator_ctrlrange[ids, 1], np.where(muscle, 1.0, np.inf))
        return lower, upper

    @property
    def control_unit(self) -> str:
        """The muscles' control unit: the model's custom text ``control_unit`` (the export's ``cm^2``), else ``1``."""
        mujoco = require_mujoco()
        model = self.engine.model
        t = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, CONTROL_UNIT)
        if t < 0:
            return "1"
        start = model.text_adr[t]
        return bytes(model.text_data[start : start + model.text_size[t] - 1]).decode()

    def default_controls(self) -> np.ndarray:
        """The muscles' controls of the model's keyframe 0 (spinectl's export: the solution), else 0.

        Returns
        -------
        numpy.ndarray, shape (m,)
            [:attr:`control_unit`].
        """
        model = self.engine.model
        if not model.nkey:
            return np.zeros(len(self.muscles))
        return model.key_ctrl[0][self.engine.muscle_ids()].copy()

    def default_controls_source(self) -> str:
        """Where :meth:`default_controls` come from, as one phrase.

        Returns
        -------
        str
        """
        if not self.engine.model.nkey:
            return "0: the model has no keyframe"
        return "the controls of the model's keyframe 0"

    def posture(self, posture=None) -> np.ndarray:
        """The full qpos: the model's reference posture (``qpos0``) or the one given.

        Parameters
        ----------
        posture : array_like, shape (nq,), optional
            Generalised positions [rad].

        Returns
        -------
        numpy.ndarray, shape (nq,)
        """
        q0 = self.engine.model.qpos0.copy()
        if posture is None:
            return q0
        q = np.asarray(posture, float)
        if q.shape != q0.shape or not np.all(np.isfinite(q)):
            raise ParameterError("posture", f"must be {q0.size} finite generalised positions")
        return q

    def rhythm(self, plane: str = "sagittal", posture=None) -> tuple:
        """The model's joint equalities that tie the plane's chain, at a posture.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : array_like, optional
            Full qpos; default the model's reference posture.

        Returns
        -------
        tuple
            (:class:`~spinectl.anatomy.linearise.Rhythm`, names of the involved joints, the chain's first).
        """
        self.engine.set_state(self.posture(posture))
        rhy = rhythm(self.engine, self.joint_ids(self.plane_joints(plane)))
        model = self.engine.model
        return rhy, self.engine.names("joint", [model.dof_jntid[d] for d in rhy.dofs])

    def linearise(self, plane: str = "sagittal", posture=None) -> tuple:
        """Linearise at a posture over the plane's chain and the joints its rhythm slaves.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : array_like, optional
            Full qpos; default the model's reference posture.

        Returns
        -------
        tuple
            (:class:`~spinectl.anatomy.linearise.Linearisation`,
            :class:`~spinectl.anatomy.linearise.Rhythm`, names of the involved joints).
        """
        q = self.posture(posture)
        rhy, involved = self.rhythm(plane, q)
        return linearise(self.engine, q, rhy.dofs, len(self.plane_joints(plane))), rhy, involved

    apply_loads = mujoco_apply_loads  # docs/anatomy.md, "Loads"

    def equilibrium_rows(self, lin, plane: str, posture, equilibrium: str) -> tuple:
        """The optimum's equilibrium: every lumbar joint (``"free"``) or the rhythm's independent coordinates.

        The lumbar joints are the mapping's ``3d`` plane (this plane's joints if it has none); with
        ``"rhythm"`` the model's joint equalities over them carry the rest (T^T tau = 0).

        Parameters
        ----------
        lin : Linearisation
            At the posture, over every dof.
        plane : str
            The chain.
        posture : array_like or None
            Full qpos; default the model's reference posture.
        equilibrium : str
            ``"rhythm"`` or ``"free"``.

        Returns
        -------
        tuple
            (the lumbar dofs, torque per control on the equilibrium's rows [N m], the rest [N m]).
        """
        lumbar = self.mapping.planes.get("3d", self.plane_joints(plane))
        model = self.engine.model
        rows = [int(model.jnt_dofadr[j]) for j in self.joint_ids(lumbar)]
        if equilibrium == "free":
            return rows, lin.torque_per_muscle[rows], lin.torque_offset[rows]
        self.engine.set_state(self.posture(posture))
        rhy = rhythm(self.engine, self.joint_ids(lumbar))
        dofs = list(rhy.dofs)
        return rows, rhy.transform.T @ lin.torque_per_muscle[dofs], rhy.transform.T @ lin.torque_offset[dofs]

    def volume_weights(self) -> np.ndarray:
        """w_i proportional to F0_i L0_i (MuJoCo's muscle parameters), normalised to mean 1.

        Returns
        -------
        numpy.ndarray, shape (m,)
        """
        mujoco = require_mujoco()
        model, ids = self.engine.model, self.engine.muscle_ids()
        if np.any(model.actuator_dyntype[ids] != mujoco.mjtDyn.mjDYN_MUSCLE):
            raise ModelError(
                f"{self.name}: the optimum's volume weights need MuJoCo muscles (their F0 and L0); its muscles "
                "are general actuators (spinectl's export: analyse it without --optimise and --lordosis)"
            )
        gain = model.actuator_gainprm[ids]
        lr = model.actuator_lengthrange[ids]
        # MuJoCo's muscle: L0 = (lengthrange span) / (operating range span); F0 = force, or scale / acc0 if force < 0
        length0 = (lr[:, 1] - lr[:, 0]) / (gain[:, 1] - gain[:, 0])
        force0 = np.where(gain[:, 2] > 0, gain[:, 2], gain[:, 3] / model.actuator_acc0[ids])
        volume = force0 * length0
        return volume / volume.mean()

    def lordosis_posture(self, degrees: float, plane: str = "sagittal") -> np.ndarray:
        """The reference posture with the plane's chain moved along the model's rhythm by ``degrees`` in total.

        The chain's joints move as the rhythm's coefficients distribute them
        (:func:`~spinectl.anatomy.directions.lordosis_direction`), and a joint off the chain that a joint
        equality slaves to them (MyoTorso's abdomen, left out of the rhythm) follows its equality: the
        posture is the model's. The thorax is not held upright (it turns with the chain).

        Parameters
        ----------
        degrees : float
            The change of the chain's summed angle [deg].
        plane : str
            The chain.

        Returns
        -------
        numpy.ndarray, shape (nq,)
        """
        rhy, _ = self.rhythm(plane)
        q = self.posture()
        q[list(rhy.dofs)] += lordosis_direction(self, rhy, len(self.plane_joints(plane)), degrees)
        return _followed(self.engine.model, q)

    def body_weight(self, body: str) -> tuple:
        """Gravity (``opt.gravity``) and ``body``'s centre of mass (``body_ipos``): the contract's ``body_weight``.

        Parameters
        ----------
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
        model = self.engine.model
        i = require_mujoco().mj_name2id(model, require_mujoco().mjtObj.mjOBJ_BODY, body)
        if i < 0:
            raise ParameterError("body", f"must be a body of {self.name} (got {body!r})")
        return model.opt.gravity.copy(), model.body_ipos[i].copy()

    def require_referee(self) -> None:
        """MuJoCo's own model is the referee of its chain (``check``): nothing to refuse."""

    engine_kind = "MuJoCo"

    def engine_versions(self) -> dict:
        """MuJoCo's version, and myo-sim's for a model it ships (the model's identity).

        Returns
        -------
        dict
            Package -> version.
        """
        from importlib.metadata import PackageNotFoundError, version

        from .engine import BUILTIN

        out = {"mujoco": require_mujoco().__version__}
        if self.name in BUILTIN:
            try:
                out["myo-sim"] = version("myo-sim")
            except PackageNotFoundError:  # loaded from a checkout, not an installed distribution
                out["myo-sim"] = "unknown"
        return out

    def posture_columns(self):
        """A posture file's columns: the model's hinge and slide joints by name (hinges in radians or degrees).

        Ball and free joints have no single value to name and stay at the reference posture.

        Returns
        -------
        spinectl.anatomy.recordings.Columns
        """
        from .recordings import posture_columns_of

        mujoco = require_mujoco()
        model = self.engine.model
        hinge, slide = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)  # jnt_type holds ints
        named = [(j, mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)) for j in range(model.njnt)]
        single = [(j, n) for j, n in named if n and int(model.jnt_type[j]) in (hinge, slide)]
        hinges = [n for j, n in single if int(model.jnt_type[j]) == hinge]
        return posture_columns_of({n: n for _, n in single}, [n for _, n in single], rotational=hinges)

    def named_posture(self, values: dict) -> np.ndarray:
        """The full qpos: the reference posture with the named hinge and slide joints set.

        Parameters
        ----------
        values : dict
            Joint name -> value [rad or m] (:meth:`posture_columns`).

        Returns
        -------
        numpy.ndarray, shape (nq,)
        """
        q = self.posture()
        for name, j in zip(values, self.joint_ids(values), strict=True):
            q[self.engine.model.jnt_qposadr[j]] = values[name]
        return q

    def _kinematics(self, qpos):
        """MuJoCo's positions (bodies, anchors, tendon paths) at qpos; the engine's scratch data."""
        mujoco = require_mujoco()
        engine = self.engine
        engine.data.qpos[:] = qpos
        mujoco.mj_kinematics(engine.model, engine.data)
        mujoco.mj_comPos(engine.model, engine.data)
        mujoco.mj_tendon(engine.model, engine.data)
        return engine.data

    def sagittal_axes(self, joints, posture=None) -> tuple:
        """The sagittal plane's (horizontal, vertical) unit axes in the world: up x the first joint's axis.

        Parameters
        ----------
        joints : sequence of str
            The sagittal chain's joints.
        posture : array_like, optional
            Full qpos; default the model's reference posture.

        Returns
        -------
        tuple
            (horizontal, up), numpy.ndarray of shape (3,) each.
        """
        data = self._kinematics(self.posture(posture))
        normal = data.xaxis[self.joint_ids(joints[:1])[0]]
        return plane_axes(self.engine.model.opt.gravity, normal, (0.0, 0.0, 1.0))

    def spine(self, joints, basis, posture=None, moved=None) -> tuple:
        """The chain's centres of rotation (MuJoCo's joint anchors) and the thorax's centre of mass, projected.

        Parameters
        ----------
        joints : sequence of str
            The chain's joints.
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes (:meth:`sagittal_axes`).
        posture : array_like, optional
            Full qpos; default the model's reference posture.
        moved : array_like, shape (len(joints),), optional
            Added to the joints' angles [rad] (the other joints held, equalities ignored).

        Returns
        -------
        tuple
            (numpy.ndarray of shape (n, 2), numpy.ndarray of shape (2,)) [m].
        """
        mujoco = require_mujoco()
        model = self.engine.model
        ids = self.joint_ids(joints)
        q = self.posture(posture)
        if moved is not None:
            q = q.copy()
            q[np.array([model.jnt_qposadr[j] for j in ids])] += moved
        data = self._kinematics(q)
        thorax = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, self.mapping.bodies["thorax"][0])
        return data.xanchor[ids] @ basis.T, data.xipos[thorax] @ basis.T

    def muscle_paths(self, basis, posture=None) -> tuple:
        """Every muscle's path (MuJoCo's sites and wrapping points in order), projected, split at its pulleys.

        Parameters
        ----------
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes (:meth:`sagittal_axes`).
        posture : array_like, optional
            Full qpos; default the model's reference posture.

        Returns
        -------
        tuple
            Per muscle, a tuple of branches, arrays of shape (p_k, 2) [m].
        """
        data = self._kinematics(self.posture(posture))
        model = self.engine.model
        points = data.wrap_xpos.reshape(-1, 3) @ basis.T
        objects = data.wrap_obj.reshape(-1)
        segments = []
        for i in self.engine.muscle_ids():
            tendon = int(model.actuator_trnid[i, 0])
            start, count = int(data.ten_wrapadr[tendon]), int(data.ten_wrapnum[tendon])
            pts, obj = points[start : start + count], objects[start : start + count]
            pieces = np.split(pts, np.flatnonzero(obj == -2))  # a pulley (-2) starts the next branch
            branches = [pieces[0]] + [piece[1:] for piece in pieces[1:]]
            segments.append(tuple(b for b in branches if len(b) > 1))
        return tuple(segments)


def _followed(model, q) -> np.ndarray:
    """q with every joint that an active joint equality slaves set by its polynomial of its master's angle.

    MuJoCo's joint equality: q1 - q1_0 = sum_k c_k (q2 - q2_0)^k, k = 0..4 (``eq_data``); a lock (no
    master) holds q1 at q1_0. The masters are taken as given (a slaved master is refused by the rhythm).
    """
    mujoco = require_mujoco()
    q = np.array(q, float)
    for e in range(model.neq):
        if not model.eq_active0[e] or model.eq_type[e] != mujoco.mjtEq.mjEQ_JOINT:
            continue
        j1, j2 = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        a1 = model.jnt_qposadr[j1]
        x = 0.0 if j2 < 0 else q[model.jnt_qposadr[j2]] - model.qpos0[model.jnt_qposadr[j2]]
        q[a1] = model.qpos0[a1] + np.polyval(model.eq_data[e][4::-1], x)
    return q


def load(model: str | Path = "myotorso", mapping: str | Path | Mapping | None = None, cache: bool = True) -> Anatomy:
    """Load an anatomical model with MuJoCo and map it onto the chain.

    Parameters
    ----------
    model : str or pathlib.Path
        ``"myotorso"`` (from the installed myo-sim) or an MJCF file.
    mapping : str, pathlib.Path or Mapping, optional
        A mapping TOML file; default the built-in one of the model's name.
    cache : bool
        Read the compiled model from the cache of compiled models, and write it there
        (:mod:`spinectl.anatomy.cache`); False compiles it anew and leaves the cache alone.

    Returns
    -------
    Anatomy

    Examples
    --------
    >>> from spinectl import anatomy  # doctest: +SKIP
    >>> torso = anatomy.load("myotorso")  # doctest: +SKIP
    >>> torso.chain("sagittal").joints  # doctest: +SKIP
    ('flex_extension', 'L4_L5_FE', 'L3_L4_FE', 'L2_L3_FE', 'L1_L2_FE')
    """
    engine = load_engine(model, cache=cache)
    if mapping is None:  # by the file's name, else the model's own (spinectl's export: wagner2012_chain)
        mapping = default_mapping(engine.name, engine.model_name)
    elif not isinstance(mapping, Mapping):
        mapping = read_mapping(mapping)
    check_mapping(engine, mapping)
    return Anatomy(engine, mapping, tuple(engine.names("actuator", engine.muscle_ids())), classify(engine, mapping))


__all__ = ["Anatomy", "Linearisation", "load"]
