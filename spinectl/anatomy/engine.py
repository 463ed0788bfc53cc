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

import contextlib
import ctypes
import hashlib
import os
import re
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._optional import require_module
from .._validate import file_fault, printable, show, show_path
from ..errors import ParameterError, SpinectlError
from .devices import as_published

BUILTIN = ("myotorso", "myofullbody")
"""Model names that load from an installed package (MyoTorso and MyoSuite's full body, its free root fixed
(:mod:`spinectl.anatomy.devices`), from myo-sim)."""

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
    mujoco = require_module("mujoco", AnatomyUnavailable, f"anatomical models need MuJoCo: {INSTALL_HINT}")
    if mujoco.get_mju_user_warning() is None:  # a handler of the caller's own stays
        mujoco.set_mju_user_warning(_mujoco_warning)
    return mujoco


class EngineWarning(UserWarning):
    """A warning of MuJoCo's about the model it loaded (e.g. a NaN in its XML)."""


_heard: list | None = None
"""MuJoCo's warnings while a model loads (:func:`_hearing`): said after the load, or dropped if it fails."""


def _mujoco_warning(text) -> None:
    """MuJoCo's warning handler, in place of its own (which prints to standard output, where spinectl's table
    or JSON goes, and appends to ``MUJOCO_LOG.TXT`` in the working folder)."""
    try:  # never raise: an exception in MuJoCo's C callback aborts the process
        message = f"MuJoCo: {one_line(text)}"
        if _heard is not None:
            _heard.append(message)
        else:
            sys.stderr.write(f"spinectl: warning: {message}\n")
    except BaseException:  # noqa: B036, S110 (the same reason)
        pass


@contextlib.contextmanager
def _hearing():
    """MuJoCo's warnings in the block, each a :class:`EngineWarning` after it; if the block raises a
    :class:`ParameterError`, its message ends with them instead (``XML contains a 'NaN'`` beside the
    compiler's complaint about the mass that was NaN)."""
    global _heard
    outer, _heard = _heard, []
    try:
        yield
        heard = _heard
    except ParameterError as exc:
        if not _heard:
            raise
        said = "; ".join(dict.fromkeys(_heard))
        raise type(exc)(exc.field, f"{exc.message} ({said})") from None
    finally:
        _heard = outer
    for message in dict.fromkeys(heard):
        warnings.warn(message, EngineWarning, stacklevel=4)


def one_line(message: str) -> str:
    """An engine's message on one line: its lines joined, so that the reason on a later line is kept.

    MuJoCo puts the element and the line of an XML error on the line after the error
    (``XML Error: invalid keyword: 'bogus'`` / ``Element 'joint', line 2``).

    Parameters
    ----------
    message : str
        The message, e.g. ``str(exc)`` of the engine's exception.

    Returns
    -------
    str
        Its non-blank lines, stripped and joined by "; ", control characters escaped.
    """
    return printable("; ".join(line.strip() for line in str(message).splitlines() if line.strip()))


def opensim_message(exc: BaseException) -> str:
    """OpenSim's exception as one line of its own words: the C++ wrapper's prefix and the source location dropped.

    OpenSim raises ``std::exception in '<signature>': <reason> ... Thrown at <file>:<line> in <function>.``;
    the reason (Simbody's "The given Node was not an Element", a muscle's "Fiber length is nan" and the object
    it names) is what a user can act on.

    Parameters
    ----------
    exc : BaseException
        The exception OpenSim raised.

    Returns
    -------
    str
        The reason on one line (:func:`one_line`), or the exception's type name if it has no message.
    """
    text = re.sub(r"^std::exception in '[^']*': ", "", one_line(exc))
    return re.split(r";? ?Thrown at ", text)[0].strip(" ;") or type(exc).__name__


@contextlib.contextmanager
def engine_output_to_stderr():
    """Send what the engines' C/C++ code prints to standard output to standard error instead, inside the block.

    OpenSim's logger writes its warnings (``[warning] Couldn't find file 'r_pelvis.vtp'.`` for every
    mesh a downloaded model lacks) and MuJoCo its (``WARNING: XML contains a 'NaN'``) to the
    process's standard output, where spinectl's table or JSON document goes. File descriptor 1 is
    pointed at standard error for the block (after both Python's and C's buffers are flushed, so
    nothing is moved across); where it cannot be (no descriptor 1 or 2), the block runs as it is.

    Yields
    ------
    None
    """
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):  # no standard output to protect
        yield
        return
    try:
        _flush_c_streams()
        os.dup2(2, 1)
    except OSError:
        os.close(saved)
        yield
        return
    try:
        yield
    finally:
        _flush_c_streams()
        os.dup2(saved, 1)
        os.close(saved)


def _flush_c_streams() -> None:
    """fflush(NULL): C's buffered standard output written out before its descriptor changes."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library by that name (Windows): its streams flush at exit
        pass


def model_file(text: str, allowed: str) -> Path:
    """The path of a model file, if it is a regular file; else one line naming ``model``.

    Parameters
    ----------
    text : str
        The path as given.
    allowed : str
        What the model may be, for the message, e.g. ``"an MJCF file"``.

    Returns
    -------
    pathlib.Path
    """
    path = Path(text)
    try:
        exists, regular = path.exists(), path.is_file()
    except (OSError, ValueError) as exc:  # a name too long for the file system, a NUL byte
        reason = getattr(exc, "strerror", None) or type(exc).__name__
        raise ParameterError("model", f"cannot read {show(text)}: {reason}") from None
    if not regular:
        what = "not a regular file" if exists else "no such file"
        raise ParameterError("model", f"must be {allowed} ({what}: {show(text)})")
    return path


MAX_MODEL_FILE_BYTES = 1 << 30
"""The largest file an MJCF model names that is read (a mesh of a published model is megabytes) [B]."""


def check_files_named(path: Path, seen: frozenset = frozenset()) -> None:
    """Every file an MJCF file names (``<include file>``, a mesh's, a texture's) a regular file, before MuJoCo
    reads them: a FIFO there hung MuJoCo's reader for ever.

    The XML is read with the standard library only to find the ``file`` attributes; MuJoCo parses the model.
    A name is resolved as MuJoCo resolves it, against the file's folder and the compiler's ``meshdir``,
    ``texturedir`` and ``assetdir``; a file that does not exist is MuJoCo's to report. Included files are
    checked in turn.

    Parameters
    ----------
    path : pathlib.Path
        An MJCF file.
    seen : frozenset, optional
        The files on the way here (an include cycle is MuJoCo's to report).

    Raises
    ------
    ParameterError
        Naming the file and what it is (field ``model``).
    """
    import xml.etree.ElementTree as ElementTree

    try:
        root = ElementTree.parse(path).getroot()
    except (ElementTree.ParseError, OSError):
        return  # MuJoCo says why, in its words
    folders = [path.parent] + [
        path.parent / value
        for compiler in root.iter("compiler")
        for key in ("assetdir", "meshdir", "texturedir")
        if (value := compiler.get(key))
    ]
    for element in root.iter():
        name = element.get("file")
        if not name:
            continue
        for candidate in (folder / name for folder in folders):
            if fault := file_fault(candidate, MAX_MODEL_FILE_BYTES):
                raise ParameterError("model", f"{show_path(path)} names {show_path(name)}, which {fault}")
            if element.tag == "include" and candidate.is_file() and candidate not in seen:
                check_files_named(candidate, seen | {path})


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
    notes : tuple of str
        What :func:`spinectl.anatomy.devices.as_published` did to the published model (welds, a free root).
    """

    model: object
    data: object
    name: str
    source: str
    sha256: str
    spec_factory: object = field(repr=False)
    notes: tuple = ()

    @property
    def devices(self) -> tuple:
        """The model's devices and how they enter the chain, one phrase each: :attr:`notes` and every passive tendon.

        Returns
        -------
        tuple of str
        """
        from .devices import passive_tendons

        return tuple(self.notes) + passive_tendons(self.model)

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


ELEMENTS = {
    "body": "body",
    "jnt": "joint",
    "dof": "joint",
    "geom": "geom",
    "site": "site",
    "cam": "camera",
    "light": "light",
    "mesh": "mesh",
    "tendon": "tendon",
    "actuator": "actuator",
    "eq": "equality",
    "key": "key",
}
"""The MJCF element of a compiled field's prefix (``jnt_stiffness`` is a ``<joint>``'s ``stiffness``)."""


def check_finite(model, source: str) -> None:
    """Refuse a compiled model with a NaN or infinite number, naming the element and attribute it came from.

    MuJoCo compiles ``stiffness="nan"`` with a warning only; every quantity spinectl reads
    would then be NaN, and the error would name an internal field instead of the file.

    Parameters
    ----------
    model : mujoco.MjModel
        The compiled model.
    source : str
        The model's source, named in the message.

    Raises
    ------
    ParameterError
        Field ``model``: the source, the element (kind and name, where MuJoCo's field says)
        and the attribute, e.g. ``joint 'L4L5': stiffness is nan (MuJoCo's jnt_stiffness)``.
    """
    mujoco = require_mujoco()
    holders = [(name, getattr(model, name)) for name in dir(model) if not name.startswith("_")]
    holders += [(f"opt_{name}", getattr(model.opt, name)) for name in dir(model.opt) if not name.startswith("_")]
    for name, value in holders:
        if not (isinstance(value, np.ndarray | float) and np.asarray(value).dtype.kind == "f"):
            continue
        bad = ~np.isfinite(np.asarray(value))
        if bad.any():
            row = int(np.argwhere(bad)[0][0]) if np.ndim(value) else 0
            prefix, _, attribute = name.partition("_")
            element = ELEMENTS.get(prefix, "option" if prefix == "opt" else None)
            where = f"<{element}>" if element else "the model"
            if element and element != "option":
                if prefix == "dof":
                    row = int(model.dof_jntid[row])
                obj = getattr(mujoco.mjtObj, f"mjOBJ_{'JOINT' if prefix == 'dof' else element.upper()}", None)
                label = mujoco.mj_id2name(model, obj, row) if obj is not None else None
                where = f"<{element}> {label!r}" if label else f"<{element}> number {row}"
            shown = np.asarray(value)[bad].flat[0]
            raise ParameterError(
                "model", f"{source}: {where}: {attribute} is {shown} (MuJoCo's {name}): every number must be finite"
            )


def _compile(spec, spec_factory, name: str, source: str, digest: str, key: str | None) -> Engine:
    """Compile ``spec`` as published (:func:`~spinectl.anatomy.devices.as_published`) into an Engine, and cache it
    under ``key``."""
    from . import cache

    mujoco = require_mujoco()
    try:
        with engine_output_to_stderr():
            spec, notes = as_published(spec)
            model = spec.compile()
    except SpinectlError:  # a weld as_published refuses, in its words
        raise
    except ValueError as exc:
        raise ParameterError("model", f"MuJoCo cannot compile {source}: {one_line(exc)}") from None
    check_finite(model, source)
    if key is not None:
        cache.write(key, model, {"sha256": digest, "notes": list(notes)})
    return Engine(model, mujoco.MjData(model), name, source, digest, _published(spec_factory), notes)


def _published(spec_factory):
    """A factory of the spec as :func:`_compile` compiles it (the referee's copy is the model analysed)."""

    def factory():
        return as_published(spec_factory())[0]

    return factory


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
    check_finite(model, source)  # a file cached before this check was made
    notes = meta.get("notes", [])
    notes = tuple(notes) if isinstance(notes, list) and all(isinstance(n, str) for n in notes) else ()
    return Engine(model, require_mujoco().MjData(model), name, source, digest, _published(spec_factory), notes)


def load_engine(model: str | Path, cache: bool = True) -> Engine:
    """Compile a built-in model (``"myotorso"``) or an MJCF file with MuJoCo, or read it from the cache.

    MuJoCo's warnings (e.g. ``XML contains a 'NaN'``) come as :class:`EngineWarning` after a model
    that loads, never on standard output.

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
    require_mujoco()
    with _hearing():
        return _load_engine(model, cache)


def _load_engine(model: str | Path, cache: bool) -> Engine:
    """:func:`load_engine`'s work, MuJoCo's warnings heard by the caller."""
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
    path = model_file(text, f"one of {BUILTIN} or an MJCF file")
    check_files_named(path)

    def factory():
        try:
            with engine_output_to_stderr():
                return mujoco.MjSpec.from_file(str(path))
        except ValueError as exc:
            raise ParameterError("model", f"{printable(text)} is not a valid MJCF file: {one_line(exc)}") from None

    spec = factory()
    data = path.read_bytes()
    key = compiled.file_key(spec, data) if cache else None
    source = str(path.resolve())
    digest = hashlib.sha256(data).hexdigest()  # a file: the SHA-256 of its bytes
    return _cached(key, factory, path.stem, source, digest) or _compile(spec, factory, path.stem, source, digest, key)
