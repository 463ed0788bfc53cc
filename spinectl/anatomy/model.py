"""An anatomical model loaded with its mapping: its chains as LinearChain objects (docs/anatomy.md)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validate import printable
from ..errors import ParameterError
from ..model.linear_chain import LinearChain
from .engine import CONTROL_UNIT, Engine, load_engine, require_mujoco
from .linearise import Linearisation, constrained_chain, free_chain, linearise, rhythm
from .mapping import MAX_STIFFNESS, Mapping, check_mapping, classify, default_mapping, read_mapping


@dataclass
class Anatomy:
    """A MuJoCo musculoskeletal model, mapped onto the chain.

    Attributes
    ----------
    engine : Engine
        The compiled model.
    mapping : Mapping
        Its chain joints, body groups and added stiffness.
    muscles : tuple of str
        The actuators' names.
    classes : tuple of str
        Each muscle's class (:func:`spinectl.anatomy.mapping.classify`).
    """

    engine: Engine
    mapping: Mapping
    muscles: tuple
    classes: tuple

    @property
    def name(self) -> str:
        """The model's name."""
        return self.engine.name

    def plane_joints(self, plane: str) -> tuple:
        """The chain's joint names in ``plane``.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.

        Returns
        -------
        tuple of str
        """
        if plane not in self.mapping.planes:
            raise ParameterError("plane", f"must be one of {sorted(self.mapping.planes)} (got {printable(plane)})")
        return self.mapping.planes[plane]

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

    def added_stiffness(self, joint_stiffness, n: int) -> np.ndarray:
        """The stiffness added at each of n chain joints [N m/rad].

        Parameters
        ----------
        joint_stiffness : {"none", "mapped"} or float
            None added, the mapping's cited value, or a value [N m/rad] >= 0.
        n : int
            The number of chain joints.

        Returns
        -------
        numpy.ndarray, shape (n,)
        """
        if joint_stiffness == "none":
            value = 0.0
        elif joint_stiffness == "mapped":
            value = self.mapping.joint_stiffness
        else:
            try:
                value = float(joint_stiffness)
            except (TypeError, ValueError):
                value = -1.0
            if not (np.isfinite(value) and 0 <= value <= MAX_STIFFNESS):  # the command line's bound, for Python too
                raise ParameterError(
                    "joint_stiffness",
                    f"must be 'none', 'mapped' or a number in [0, {MAX_STIFFNESS:g}] N m/rad, beyond which the "
                    f"chain's arithmetic fails (got {joint_stiffness!r})",
                )
        return np.full(n, value)

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
        names = self.plane_joints(plane)
        q = self.posture(posture)
        self.engine.set_state(q)
        rhy = rhythm(self.engine, self.joint_ids(names))
        lin = linearise(self.engine, q, rhy.dofs, len(names))
        model = self.engine.model
        involved = self.engine.names("joint", [model.dof_jntid[d] for d in rhy.dofs])
        return lin, rhy, involved

    def rhythm_size(self, plane: str = "sagittal", posture=None) -> int:
        """How many coordinates the model's rhythm (its joint equalities) ties to the chain: 0 without one.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : array_like, optional
            Full qpos; default the model's reference posture.

        Returns
        -------
        int
            The dependent coordinates involved (the constrained chain's dofs minus its independent ones).
        """
        self.engine.set_state(self.posture(posture))
        rhy = rhythm(self.engine, self.joint_ids(self.plane_joints(plane)))
        return len(rhy.dofs) - len(rhy.independent)

    def chains(self, plane: str = "sagittal", posture=None, joint_stiffness="none") -> tuple:
        """The free chain and the chain constrained by the model's rhythm, as LinearChain objects.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : array_like, optional
            Full qpos; default the model's reference posture.
        joint_stiffness : {"none", "mapped"} or float
            Intervertebral stiffness added at each chain joint (:meth:`added_stiffness`).

        Returns
        -------
        tuple
            (free :class:`~spinectl.model.linear_chain.LinearChain`, constrained one,
            the :class:`~spinectl.anatomy.linearise.Linearisation`).
        """
        lin, rhy, involved = self.linearise(plane, posture)
        n = lin.n
        added = self.added_stiffness(joint_stiffness, n)
        source = f"{self.engine.source}, {plane}"
        controls = {"bounds": self.control_bounds(), "unit": self.control_unit}
        free = free_chain(lin, involved[:n], self.muscles, self.classes, added, source, **controls)
        full_added = np.concatenate([added, np.zeros(len(involved) - n)])
        constrained = constrained_chain(
            lin,
            rhy,
            involved,
            self.muscles,
            self.classes,
            full_added,
            source + ", constrained by the rhythm",
            **controls,
        )
        return free, constrained, lin

    def chain(self, plane: str = "sagittal", posture=None, joint_stiffness="none", constrained=False) -> LinearChain:
        """One chain as a LinearChain (free by default).

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : array_like, optional
            Full qpos; default the model's reference posture.
        joint_stiffness : {"none", "mapped"} or float
            Added at each chain joint.
        constrained : bool
            The chain constrained by the model's rhythm instead of the free chain.

        Returns
        -------
        LinearChain
        """
        free, con, _ = self.chains(plane, posture, joint_stiffness)
        return con if constrained else free


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
