"""The engine contract: what every anatomy function needs of a model, and which engine loads which file.

An anatomical model on any engine (MuJoCo's :class:`~spinectl.anatomy.model.Anatomy`, OpenSim's
:class:`~spinectl.anatomy.opensim_engine.OsimAnatomy`) is an :class:`AnatomyEngine`: it names its
chain's joints, its muscles and their classes, gives its control bounds and default controls, and
produces the :class:`~spinectl.anatomy.linearise.Linearisation` and the rhythm at an operating point.
The analyses (:mod:`spinectl.anatomy.analyses`), the optimum and the lordosis curve
(:mod:`spinectl.anatomy.optimum`) are written once against it. :class:`MappedModel` holds what is
the same on every engine (the mapping's planes, the added stiffness, the chains built from the
linearisation), so that an engine writes only its own part.

:data:`ENGINES` chooses the engine by the model's name or file suffix; :func:`register_engine` adds
one. A third engine is one module implementing :class:`AnatomyEngine` (a :class:`MappedModel`
subclass) and a loader, plus one :func:`register_engine` call (CONTRIBUTING.md, "Extension points").
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from .._validate import printable, show
from ..errors import ParameterError
from ..model.linear_chain import LinearChain
from ..model.loads import loads_text
from .joint_angles import JointSlopes, linearisation_in_angles, rhythm_in_angles
from .linearise import constrained_chain, free_chain
from .loads import BodyWeight, refuse_body_weight, refuse_loads
from .mapping import MAX_STIFFNESS, Mapping, located


@runtime_checkable
class AnatomyEngine(BodyWeight, Protocol):
    """An anatomical model on one engine, mapped onto the chain: what the anatomy functions call.

    Attributes
    ----------
    name, source, sha256 : str
        The model's name, where it came from and the SHA-256 of its file (every output's ``model``).
    mapping : Mapping
        Its chain joints, body groups and added stiffness.
    muscles, classes : tuple of str
        The muscles' names and classes (``global``, ``local``, ``between``, ``non-lumbar``).
    control_unit : str
        The muscles' control unit (``"1"``: activations).
    """

    name: str
    source: str
    sha256: str
    mapping: Mapping
    muscles: tuple
    classes: tuple
    control_unit: str

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

    def control_bounds(self) -> tuple:
        """Each muscle's control bounds.

        Returns
        -------
        tuple
            (lower, upper), numpy.ndarray of shape (m,) [:attr:`control_unit`].
        """

    def default_controls(self) -> np.ndarray:
        """The controls analysed when none are given (the model's own, else 0).

        Returns
        -------
        numpy.ndarray, shape (m,)
        """

    def default_controls_source(self) -> str:
        """Where :meth:`default_controls` come from, as one phrase.

        Returns
        -------
        str
        """

    def posture(self, posture=None):
        """The operating point in the engine's own form: the reference posture, or ``posture`` checked.

        Parameters
        ----------
        posture : optional
            The engine's posture (MuJoCo: the full qpos; OpenSim: coordinate name -> value [rad]).

        Returns
        -------
        object
        """

    def added_stiffness(self, joint_stiffness, n: int) -> np.ndarray:
        """The stiffness added at each of n chain joints.

        Parameters
        ----------
        joint_stiffness : {"none", "mapped"} or float
            None added, the mapping's cited value, or a value [N m/rad].
        n : int
            The number of chain joints.

        Returns
        -------
        numpy.ndarray, shape (n,)
            [N m/rad].
        """

    def joint_slopes(self, plane: str = "sagittal", posture=None) -> JointSlopes:
        """How the plane's chain joints turn per unit of its coordinates at a posture (identity: a hinge).

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        JointSlopes
        """

    def rhythm(self, plane: str = "sagittal", posture=None) -> tuple:
        """The model's rhythm over the plane's chain at a posture.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        tuple
            (:class:`~spinectl.anatomy.linearise.Rhythm`, names of the coordinates it involves, the chain's first).
        """

    def linearise(self, plane: str = "sagittal", posture=None) -> tuple:
        """The linearisation over the plane's chain and the coordinates its rhythm ties, at a posture.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        tuple
            (:class:`~spinectl.anatomy.linearise.Linearisation`, its Rhythm, names of the involved coordinates).
        """

    def chains(self, plane: str = "sagittal", posture=None, joint_stiffness="none", activations=None) -> tuple:
        """The free chain and the chain constrained by the rhythm.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).
        joint_stiffness : {"none", "mapped"} or float
            Added at each chain joint (:meth:`added_stiffness`).
        activations : array_like, optional
            The operating activations, where an engine whose muscle forces are not affine in them
            linearises (OpenSim's compliant tendons); the others ignore them.

        Returns
        -------
        tuple
            (free LinearChain, constrained LinearChain, Linearisation).
        """

    def rhythm_size(self, plane: str = "sagittal", posture=None) -> int:
        """How many coordinates the rhythm ties to the chain.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        int
            0 without a rhythm.
        """

    def equilibrium_rows(self, lin, plane: str, posture, equilibrium: str) -> tuple:
        """The optimum's equilibrium on the linearisation.

        Parameters
        ----------
        lin : Linearisation
            At the posture (:meth:`chains`).
        plane : str
            The chain.
        posture : object or None
            The operating point (:meth:`posture`).
        equilibrium : str
            ``"rhythm"`` (the rhythm's independent coordinates) or ``"free"`` (every lumbar joint).

        Returns
        -------
        tuple
            (the lumbar rows of ``lin``, torque per control on the equilibrium's rows [N m], the rest [N m]).
        """

    def volume_weights(self) -> np.ndarray:
        """The optimum's cost weights, each muscle's volume normalised to mean 1.

        Returns
        -------
        numpy.ndarray, shape (m,)
        """

    def lordosis_posture(self, degrees: float, plane: str = "sagittal"):
        """The reference posture with the chain moved along the rhythm by ``degrees`` in total.

        Parameters
        ----------
        degrees : float
            The change of the chain's summed angle [deg].
        plane : str
            The chain.

        Returns
        -------
        object
            The posture in the engine's form (:meth:`posture`).
        """

    def require_referee(self) -> None:
        """Return if MuJoCo's referee (``check``) can compare this model; else raise one line."""

    def sagittal_axes(self, joints, posture=None) -> tuple:
        """The sagittal plane's unit axes in the engine's world (the figures).

        Parameters
        ----------
        joints : sequence of str
            The sagittal chain's joints.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        tuple
            (horizontal, up), numpy.ndarray of shape (3,) each.
        """

    def spine(self, joints, basis, posture=None, moved=None) -> tuple:
        """The joints' centres of rotation and the thorax's centre of mass, projected.

        Parameters
        ----------
        joints : sequence of str
            The chain's joints.
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes (:meth:`sagittal_axes`).
        posture : optional
            The operating point (:meth:`posture`).
        moved : array_like, shape (len(joints),), optional
            Added to the joints' angles [rad].

        Returns
        -------
        tuple
            (numpy.ndarray of shape (n, 2), numpy.ndarray of shape (2,)) [m].
        """

    def muscle_paths(self, basis, posture=None) -> tuple:
        """Every muscle's path, projected.

        Parameters
        ----------
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes (:meth:`sagittal_axes`).
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        tuple
            Per muscle, a tuple of branches of shape (p_k, 2) [m].
        """

    def engine_versions(self) -> dict:
        """The versions of the packages that built and read the model (:func:`model_identity`).

        Returns
        -------
        dict
            Package -> version.
        """

    def posture_columns(self):
        """How a posture file's columns name the model's coordinates (:mod:`spinectl.anatomy.recordings`).

        Returns
        -------
        spinectl.anatomy.recordings.Columns
        """

    def activation_columns(self):
        """How an activation file's columns name the model's muscles (:mod:`spinectl.anatomy.recordings`).

        Returns
        -------
        spinectl.anatomy.recordings.Columns
        """

    def named_posture(self, values: dict):
        """The posture in the engine's form (:meth:`posture`) from coordinate name -> value.

        Parameters
        ----------
        values : dict
            Coordinate name -> value [rad or m].

        Returns
        -------
        object
        """


@dataclass
class MappedModel:
    """What every engine's model shares: its mapping, muscles and the chains built from its linearisation.

    A subclass gives the engine's part of :class:`AnatomyEngine` (``linearise``, ``rhythm``,
    ``posture``, the controls, ``equilibrium_rows``, ``volume_weights``, ``lordosis_posture``).

    Attributes
    ----------
    engine : object
        The engine's model, with ``name``, ``source`` and ``sha256``.
    mapping : Mapping
        Its chain joints, body groups and added stiffness.
    muscles : tuple of str
        The muscles' names.
    classes : tuple of str
        Each muscle's class (:func:`spinectl.anatomy.mapping.classify`).
    """

    engine: object
    mapping: Mapping
    muscles: tuple
    classes: tuple

    rhythm_name = "rhythm"
    """What the constrained chain's source says constrains it (OpenSim: its couplers)."""

    linearised_at_activations = False
    """Whether ``linearise`` takes the operating activations (``activations=``): True for an engine whose
    muscle forces are not affine in them (OpenSim's compliant tendons), linearised there."""

    @property
    def name(self) -> str:
        """The model's name."""
        return self.engine.name

    @property
    def source(self) -> str:
        """Where the model came from (a package and version, or a file's path)."""
        return self.engine.source

    @property
    def sha256(self) -> str:
        """SHA-256 of the model's file (or of the text it was composed from)."""
        return self.engine.sha256

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
            if not self.mapping.stiffness_mapped:  # before: 0 added without a word
                raise ParameterError(
                    located(self.mapping.path, "joint_stiffness.Nm_per_rad"),
                    "is missing (no [joint_stiffness] section gives it) and --joint-stiffness mapped reads it: add "
                    "the section, or give --joint-stiffness a number [N m/rad]",
                )
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

    def rhythm_size(self, plane: str = "sagittal", posture=None) -> int:
        """How many coordinates the model's rhythm ties to the chain: 0 without one.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`); default the reference posture.

        Returns
        -------
        int
            The dependent coordinates involved (the constrained chain's coordinates minus its independent ones).
        """
        rhy, _ = self.rhythm(plane, posture)
        return len(rhy.dofs) - len(rhy.independent)

    def chain_source(self, plane: str, posture=None) -> str:
        """The chains' source line: the model's source and the plane.

        Parameters
        ----------
        plane : str
            The chain's plane.
        posture : optional
            The operating point.

        Returns
        -------
        str
        """
        return f"{self.source}, {plane}"

    def joint_slopes(self, plane: str = "sagittal", posture=None) -> JointSlopes:
        """How the plane's chain joints turn per unit of its coordinates: the identity (a hinge's coordinate).

        An engine whose coordinates are not its joints' angles (OpenSim's CustomJoint) measures them.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        JointSlopes
        """
        return JointSlopes.identity(len(self.plane_joints(plane)))

    def joint_rhythm(self, plane: str = "sagittal", posture=None) -> tuple:
        """The rhythm over the joints' angles (:func:`~spinectl.anatomy.joint_angles.rhythm_in_angles`).

        The variables of the chains (:meth:`chains`) and their Linearisation: what their torques pair with.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`).

        Returns
        -------
        tuple
            (Rhythm in joint angles, names of the coordinates it involves, the chain's first).
        """
        rhy, involved = self.rhythm(plane, posture)
        return rhythm_in_angles(rhy, self.joint_slopes(plane, posture), self.name), involved

    apply_loads = refuse_loads  # an engine that computes loads overrides it (docs/anatomy.md, "Loads")
    body_weight = refuse_body_weight  # an engine that reads gravity and centres of mass overrides it

    def chains(
        self, plane: str = "sagittal", posture=None, joint_stiffness="none", activations=None, loads=()
    ) -> tuple:
        """The free chain and the chain constrained by the model's rhythm, as LinearChain objects.

        Both per radian of each joint's rotation, the engine's coordinates changed to the joints' angles
        (:mod:`spinectl.anatomy.joint_angles`, :meth:`joint_slopes`), and so is the stiffness added.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point (:meth:`posture`); default the reference posture.
        joint_stiffness : {"none", "mapped"} or float
            Intervertebral stiffness added at each chain joint (:meth:`added_stiffness`).
        activations : array_like, shape (m,), optional
            The operating activations, for an engine that linearises there
            (:attr:`linearised_at_activations`); ignored by the others (exact at every activation).
        loads : sequence of BodyLoad, optional
            Loads in the torque offset and K_0 (:meth:`apply_loads`, after the linearisation: no cache has them).

        Returns
        -------
        tuple
            (free :class:`~spinectl.model.linear_chain.LinearChain`, constrained one,
            the :class:`~spinectl.anatomy.linearise.Linearisation` in the joints' angles).
        """
        at = {"activations": activations} if activations is not None and self.linearised_at_activations else {}
        lin, rhy, involved = self.linearise(plane, posture, **at)
        lin = self.apply_loads(lin, posture, loads, involved) if loads else lin
        slopes = self.joint_slopes(plane, posture)
        lin, rhy = linearisation_in_angles(lin, slopes, self.name), rhythm_in_angles(rhy, slopes, self.name)
        n = lin.n
        added = self.added_stiffness(joint_stiffness, n)
        source = self.chain_source(plane, posture) + loads_text(loads)
        controls = {"bounds": self.control_bounds(), "unit": self.control_unit}
        free = free_chain(lin, tuple(involved[:n]), self.muscles, self.classes, added, source, **controls)
        full_added = np.concatenate([added, np.zeros(len(involved) - n)])
        constrained = constrained_chain(
            lin,
            rhy,
            involved,
            self.muscles,
            self.classes,
            full_added,
            f"{source}, constrained by the {self.rhythm_name}",
            **controls,
        )
        return free, constrained, lin

    def chain(self, plane: str = "sagittal", posture=None, joint_stiffness="none", constrained=False) -> LinearChain:
        """One chain as a LinearChain (free by default).

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : optional
            The operating point; default the reference posture.
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

    def require_referee(self) -> None:
        """MuJoCo's referee (``check``) rebuilds the model as MJCF: an engine without one refuses, one line.

        Raises
        ------
        ParameterError
            Field ``check``.
        """
        raise ParameterError("check", f"MuJoCo is the referee, for MJCF models only; {self.name} is not one")

    def sagittal_axes(self, joints, posture=None) -> tuple:
        """An engine that gives no geometry draws no figure: one line (see :meth:`spine`).

        Parameters
        ----------
        joints : sequence of str
            The sagittal chain's joints.
        posture : optional
            The operating point.

        Returns
        -------
        tuple
            Never: raises :class:`~spinectl.errors.ParameterError` (field ``plot``).
        """
        raise self._no_geometry()

    def spine(self, joints, basis, posture=None, moved=None) -> tuple:
        """The figures' points (:class:`AnatomyEngine`); an engine without geometry refuses, one line.

        Parameters
        ----------
        joints : sequence of str
            The chain's joints.
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes.
        posture : optional
            The operating point.
        moved : array_like, optional
            Added to the joints' angles [rad].

        Returns
        -------
        tuple
            Never: raises.

        Raises
        ------
        ParameterError
            Field ``plot``.
        """
        raise self._no_geometry()

    def muscle_paths(self, basis, posture=None) -> tuple:
        """An engine that gives no geometry draws no figure: one line (see :meth:`spine`).

        Parameters
        ----------
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes.
        posture : optional
            The operating point.

        Returns
        -------
        tuple
            Never: raises :class:`~spinectl.errors.ParameterError` (field ``plot``).
        """
        raise self._no_geometry()

    def _no_geometry(self) -> ParameterError:
        return ParameterError("plot", f"{self.name}'s engine gives no geometry to draw; analyse it without --plot")

    engine_kind = "unnamed engine"
    """The engine's name as the model's identity gives it (``MuJoCo``, ``OpenSim``)."""

    def engine_versions(self) -> dict:
        """The versions of the packages that built and read the model (the model's identity).

        Returns
        -------
        dict
            Package -> version; empty for an engine that names none.
        """
        return {}

    def posture_columns(self):
        """How a posture file's columns name this model's coordinates; an engine without names refuses, one line.

        Returns
        -------
        spinectl.anatomy.recordings.Columns
            Never here: raises :class:`~spinectl.errors.ParameterError` (field ``posture``).
        """
        raise ParameterError("posture", f"{self.name}'s engine names no coordinates that a file could set")

    def activation_columns(self):
        """How an activation file's columns name this model's muscles: by their names.

        Returns
        -------
        spinectl.anatomy.recordings.Columns
        """
        from .recordings import activation_columns_of

        return activation_columns_of({m: m for m in self.muscles}, self.muscles)

    def named_posture(self, values: dict):
        """The posture in the engine's form from coordinate name -> value; an engine without names refuses.

        Parameters
        ----------
        values : dict
            Coordinate name -> value [rad or m].

        Returns
        -------
        object
            Never here: raises :class:`~spinectl.errors.ParameterError` (field ``posture``).
        """
        raise ParameterError("posture", f"{self.name}'s engine names no coordinates that a file could set")


MUJOCO = "spinectl.anatomy.model:load"
OPENSIM = "spinectl.anatomy.opensim_engine:load_osim"

ENGINES = {"myotorso": MUJOCO, "myofullbody": MUJOCO, ".xml": MUJOCO, ".mjcf": MUJOCO, ".osim": OPENSIM}
"""The engine of each built-in model name and each file suffix: its loader, ``"module:function"`` (imported
when used, so an engine's package is needed only for its models) or a callable,
``loader(model, mapping=None, cache=True) -> AnatomyEngine``. The suffixes are those of
:data:`spinectl.anatomy.interchange.FORMATS`, so that every exported file loads."""


def register_engine(key: str, loader) -> None:
    """Load models of a name or file suffix with ``loader`` (a third engine's one registration).

    Parameters
    ----------
    key : str
        A file suffix with its dot (``".fake"``, matched in lower case) or a built-in model's name.
    loader : str or callable
        ``"module:function"`` or the function, ``loader(model, mapping=None, cache=True)``
        returning an :class:`AnatomyEngine`.
    """
    if not isinstance(key, str) or not key or not (isinstance(loader, str) or callable(loader)):
        raise ParameterError("engine", f"a name or '.suffix' and a loader (got {key!r}, {loader!r})")
    ENGINES[key.lower() if key.startswith(".") else key] = loader


def loader_of(model):
    """The loader of a model: by its name if built in, else by its file's suffix (:data:`ENGINES`).

    Parameters
    ----------
    model : str or pathlib.Path
        A built-in model's name or a model file.

    Returns
    -------
    callable
        ``loader(model, mapping=None, cache=True)``.

    Raises
    ------
    ParameterError
        Field ``model``: neither a built-in name nor a registered suffix, naming those allowed.
    """
    text = str(model)
    try:
        suffix = Path(text).suffix.lower()
    except ValueError:  # a NUL byte
        suffix = ""
    loader = None if text.startswith(".") else ENGINES.get(text)
    if loader is None and suffix:
        loader = ENGINES.get(suffix)
    if loader is None:
        names = sorted(k for k in ENGINES if not k.startswith("."))
        suffixes = ", ".join(sorted(k for k in ENGINES if k.startswith(".")))
        raise ParameterError("model", f"must be one of {names} or a file ending in {suffixes} (got {show(text)})")
    if isinstance(loader, str):
        module, _, function = loader.partition(":")
        loader = getattr(importlib.import_module(module), function)
    return loader


def load(model="myotorso", mapping=None, cache: bool = True) -> AnatomyEngine:
    """Load a model with the engine :data:`ENGINES` names for it, mapped onto the chain.

    Parameters
    ----------
    model : str or pathlib.Path
        A built-in model's name or a model file.
    mapping : str, pathlib.Path or Mapping, optional
        A mapping TOML file; default the built-in one of the model's name.
    cache : bool
        Whether the engine may read and write its cache of compiled models.

    Returns
    -------
    AnatomyEngine
    """
    return loader_of(model)(model, mapping, cache=cache)
