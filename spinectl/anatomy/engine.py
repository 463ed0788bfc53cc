"""MuJoCo as the engine of an anatomical model: loading, and the quantities read from it (docs/anatomy.md).

Everything geometric and every force comes from MuJoCo's own functions: the compiled
model's kinematics (:func:`mujoco.mj_fwdPosition`), its muscles' moment arms and lengths
(``actuator_moment``, ``actuator_length``), its muscle curves (:func:`mujoco.mju_muscleGain`,
:func:`mujoco.mju_muscleBias`), gravity (``qfrc_bias`` at zero velocity) and the mass matrix
(:func:`mujoco.mj_fullM`). spinectl parses no MJCF of its own.

MuJoCo and myo-sim (which ships MyoTorso) are the optional extra ``spinectl[anatomy]``;
without them :func:`require_mujoco` raises one line saying what to install.

References
----------
Todorov E, Erez T, Tassa Y (2012). MuJoCo: a physics engine for model-based control.
IROS 2012, 5026-5033. doi:10.1109/IROS.2012.6386109.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._optional import require_module
from ..errors import ParameterError, SpinectlError

BUILTIN = ("myotorso",)
"""Model names that load from an installed package (MyoTorso from myo-sim)."""

INSTALL_HINT = "pip install 'spinectl[anatomy]'"

CONTROL_UNIT = "control_unit"
"""Name of the MJCF custom text (``<custom><text>``) giving the muscles' control unit (spinectl's export: ``cm^2``)."""


class AnatomyUnavailable(SpinectlError, ImportError):
    """MuJoCo (or myo-sim, for a built-in model) is not installed."""


def require_mujoco():
    """Import and return :mod:`mujoco`, or raise one line saying what to install.

    Returns
    -------
    module
        :mod:`mujoco`.
    """
    return require_module("mujoco", AnatomyUnavailable, f"anatomical models need MuJoCo: {INSTALL_HINT}")


@dataclass
class Engine:
    """A compiled MuJoCo model with one scratch ``MjData``, and where it came from.

    Attributes
    ----------
    model : mujoco.MjModel
        The compiled model.
    data : mujoco.MjData
        Scratch data (every function here sets the state it reads).
    name : str
        ``"myotorso"`` or the file's stem.
    source : str
        The package and version, or the file's path.
    sha256 : str
        SHA-256 of the MJCF text the model was compiled from.
    spec_factory : callable
        Returns a fresh, editable ``mujoco.MjSpec`` of the same model (for the referee's copy).
    """

    model: object
    data: object
    name: str
    source: str
    sha256: str
    spec_factory: object = field(repr=False)

    def names(self, kind: str, ids=None) -> list:
        """Names of MuJoCo objects of one kind (``"joint"``, ``"body"``, ``"actuator"``, ...).

        Parameters
        ----------
        kind : str
            The object kind, as in ``mujoco.mjtObj.mjOBJ_<KIND>``.
        ids : iterable of int, optional
            The ids; default all of that kind.

        Returns
        -------
        list of str
        """
        mujoco = require_mujoco()
        obj = getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}")
        count = {
            "joint": self.model.njnt,
            "body": self.model.nbody,
            "actuator": self.model.nu,
            "geom": self.model.ngeom,
        }[kind]
        return [mujoco.mj_id2name(self.model, obj, int(i)) or "" for i in (range(count) if ids is None else ids)]

    @property
    def model_name(self) -> str:
        """The model's own name (MJCF ``<mujoco model="...">``, MuJoCo's first name in ``names``)."""
        return bytes(self.model.names).split(b"\0", 1)[0].decode()

    def muscle_ids(self) -> np.ndarray:
        """The actuators that are the chain's muscles: a tendon transmission, muscle or no activation dynamics.

        MuJoCo's muscles, and the ``general`` actuators of spinectl's export (an affine gain on a
        spatial tendon, the control a PCSA). Any other actuator (a joint motor such as the export's
        ``counter_*``) is held at its control of :meth:`held_controls`.

        Returns
        -------
        numpy.ndarray of int
        """
        mujoco = require_mujoco()
        m = self.model
        tendon = m.actuator_trntype == mujoco.mjtTrn.mjTRN_TENDON
        dyn = np.isin(m.actuator_dyntype, [mujoco.mjtDyn.mjDYN_MUSCLE, mujoco.mjtDyn.mjDYN_NONE])
        return np.flatnonzero(tendon & dyn)

    def held_controls(self) -> np.ndarray:
        """Every actuator's control, held: keyframe 0's if the model has one, else 0; the muscles' set to 0.

        Returns
        -------
        numpy.ndarray, shape (nu,)
            [the actuator's control unit].
        """
        ctrl = self.model.key_ctrl[0].copy() if self.model.nkey else np.zeros(self.model.nu)
        ctrl[self.muscle_ids()] = 0.0
        return ctrl

    def set_state(self, qpos, act=None) -> None:
        """Set qpos, zero velocity and the activations, and run the position and velocity stages.

        Parameters
        ----------
        qpos : array_like, shape (nq,)
            Generalised positions [rad or m].
        act : array_like, shape (na,), optional
            Activations [1]; default 0.
        """
        mujoco = require_mujoco()
        d = self.data
        d.qpos[:] = qpos
        d.qvel[:] = 0.0
        d.act[:] = 0.0 if act is None else act
        mujoco.mj_fwdPosition(self.model, d)
        mujoco.mj_fwdVelocity(self.model, d)

    def moment_arms(self) -> np.ndarray:
        """``actuator_moment`` as a dense (nu, nv) array [m/rad]: d(actuator length)/dq at the set state.

        Returns
        -------
        numpy.ndarray, shape (nu, nv)
        """
        mujoco = require_mujoco()
        out = np.zeros((self.model.nu, self.model.nv))
        d = self.data
        mujoco.mju_sparse2dense(out, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
        return out

    def mass_matrix(self) -> np.ndarray:
        """The joint-space mass matrix at the set state (:func:`mujoco.mj_fullM`) [kg m^2].

        Returns
        -------
        numpy.ndarray, shape (nv, nv)
        """
        mujoco = require_mujoco()
        out = np.zeros((self.model.nv, self.model.nv))
        if hasattr(self.data, "qM"):  # MuJoCo 3: mj_fullM(m, dst, qM)
            mujoco.mj_fullM(self.model, out, self.data.qM)
        else:  # MuJoCo 4: mj_fullM(m, d, dst)
            mujoco.mj_fullM(self.model, self.data, out)
        return out

    def generalised_force(self, qpos, act) -> np.ndarray:
        """MuJoCo's own smooth generalised force at zero velocity [N m]: actuators + passive - bias.

        Constraint forces (equalities, limits, contacts) are left out: this is the free chain's
        force. Used by the tests' finite differences.

        Parameters
        ----------
        qpos : array_like, shape (nq,)
            Generalised positions.
        act : array_like, shape (na,)
            Activations [1].

        Returns
        -------
        numpy.ndarray, shape (nv,)
        """
        mujoco = require_mujoco()
        self.set_state(qpos, act)
        mujoco.mj_fwdActuation(self.model, self.data)
        d = self.data
        return d.qfrc_actuator + d.qfrc_passive - d.qfrc_bias


def _compile(spec, spec_factory, name: str, source: str, digest: str, key: str | None) -> Engine:
    """Compile ``spec`` (or read its compiled model from the cache under ``key``) into an Engine."""
    from . import cache

    mujoco = require_mujoco()
    try:
        model = spec.compile()
    except ValueError as exc:
        raise ParameterError("model", f"MuJoCo cannot compile {source}: {str(exc).splitlines()[0]}") from None
    if key is not None:
        cache.write(key, model, {"sha256": digest})
    return Engine(model, mujoco.MjData(model), name, source, digest, spec_factory)


def _cached(key: str | None, spec_factory, name: str, source: str, digest: str | None = None) -> Engine | None:
    """The Engine of a cached compiled model, or None (no key, no file, or a file that cannot be read).

    ``digest``, where given, is the reported SHA-256 (a file's bytes, read anew); else the
    one stored with the compiled model (the MJCF text of a composed model).
    """
    from . import cache

    hit = None if key is None else cache.read(key)
    if hit is None:
        return None
    model, meta = hit
    digest = digest or meta.get("sha256")
    if not isinstance(digest, str):
        return None
    return Engine(model, require_mujoco().MjData(model), name, source, digest, spec_factory)


def load_engine(model: str | Path, cache: bool = True) -> Engine:
    """Compile a built-in model (``"myotorso"``) or an MJCF file with MuJoCo, or read it from the cache.

    Parameters
    ----------
    model : str or pathlib.Path
        A name of :data:`BUILTIN` or the path of an MJCF (``.xml``) file.
    cache : bool
        Read and write the compiled model in the cache (:mod:`spinectl.anatomy.cache`);
        False compiles it anew and leaves the cache alone.

    Returns
    -------
    Engine
    """
    from . import cache as compiled

    mujoco = require_mujoco()
    text = str(model)
    if text in BUILTIN:
        myo_sim = require_module(
            "myo_sim", AnatomyUnavailable, f"the built-in model {text!r} comes with myo-sim: {INSTALL_HINT}"
        )
        source = f"myo-sim {myo_sim.__version__}, {text}"

        def builtin():
            return myo_sim.load_spec(text)

        key = compiled.builtin_key(text, myo_sim) if cache else None
        engine = _cached(key, builtin, text, source)
        if engine is not None:
            return engine
        spec = builtin()
        # a composed model: the SHA-256 of the MJCF text MuJoCo writes of it
        return _compile(spec, builtin, text, source, hashlib.sha256(spec.to_xml().encode()).hexdigest(), key)
    path = Path(text)
    if not path.is_file():
        what = "no such MJCF file" if path.suffix.lower() in (".xml", ".mjcf") else "not an MJCF file"
        raise ParameterError("model", f"must be one of {BUILTIN} or an MJCF file ({what}: {text!r})")

    def factory():
        try:
            return mujoco.MjSpec.from_file(str(path))
        except ValueError as exc:
            raise ParameterError("model", f"{text} is not a valid MJCF file: {str(exc).splitlines()[0]}") from None

    spec = factory()
    key = compiled.file_key(spec) if cache else None
    source = str(path.resolve())
    digest = hashlib.sha256(path.read_bytes()).hexdigest()  # a file: the SHA-256 of its bytes
    return _cached(key, factory, path.stem, source, digest) or _compile(spec, factory, path.stem, source, digest, key)
