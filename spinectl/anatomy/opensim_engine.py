"""OpenSim as the engine of an ``.osim`` model: the same mapping, classes and LinearChain (docs/interchange.md).

Everything is OpenSim's: the model is read and built by :class:`opensim.Model` (spinectl
parses no ``.osim`` of its own), the muscles' path lengths and moment arms
(``Muscle.getLength``, and ``getLengtheningSpeed`` at unit coordinate speeds: what
``computeMomentArm`` returns, every muscle at once, :mod:`~spinectl.anatomy.osim_geometry`;
wrapping and conditional points included), the
muscles' forces along their paths with their stiffness and damping (whatever their law,
:mod:`spinectl.anatomy.opensim_muscles`), the generalised gravity and every passive force (minus the
inverse dynamics at rest with the muscles and actuators off) and the mass matrix
(``SimbodyMatterSubsystem.calcM``). The linearisation is that of
:mod:`spinectl.anatomy.linearise`: K_i = H_i gain_i + gain_i' r_i r_i^T, with the Hessians H_i
by central differences of OpenSim's moment arms, K_0 by central differences of the passive
torques, so the chain is a :class:`~spinectl.model.linear_chain.LinearChain` like MuJoCo's.

Supported muscles: ``Millard2012EquilibriumMuscle``, ``Thelen2003Muscle`` and
``DeGrooteFregly2016Muscle``, rigid or compliant tendon, pennate or not, their activation the
control within [the law's minimum activation, 1]; a rigid tendon's force is affine in the
activation (exact), a compliant one's is linearised at the operating activations
(:mod:`spinectl.anatomy.opensim_muscles`).

Coordinate coupler constraints (``CoordinateCouplerConstraint``, e.g. the lumbar rhythm of
Christophy et al. 2012) are switched off in the engine, so the **free** chain is the chain with
them off. The **constrained** chain is the free linearisation reduced to the independent
coordinates by the couplers' linearised relations, q_dep = f(q_ind): T = dq/dq_ind from the
functions' first derivatives at the posture (OpenSim's ``Function.calcDerivative``) and their
second derivatives as the curvature, by :func:`spinectl.anatomy.linearise.constrained_chain`
(the reduction of MuJoCo's joint equalities).

References
----------
Seth A, Hicks JL, Uchida TK, et al. (2018). OpenSim: Simulating musculoskeletal dynamics and
neuromuscular control to study human and animal movement. PLoS Comput Biol 14(7):e1006223.
doi:10.1371/journal.pcbi.1006223.

Millard M, Uchida T, Seth A, Delp SL (2013). Flexing computational muscle: modeling and
simulation of musculotendon dynamics. J Biomech Eng 135(2):021005. doi:10.1115/1.4023390.

Christophy M, Faruk Senan NA, Lotz JC, O'Reilly OM (2012). A musculoskeletal model for the lumbar
spine. Biomech Model Mechanobiol 11(1-2):19-34. doi:10.1007/s10237-011-0290-6.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, fields, replace

import numpy as np

from .._validate import printable
from ..errors import ModelError, ParameterError
from . import osim_cache
from .contract import MappedModel
from .directions import lordosis_direction, plane_axes
from .engine import engine_output_to_stderr, model_file, opensim_message
from .export_osim import require_opensim
from .joint_angles import JointSlopes
from .linearise import STEP, Linearisation
from .loads import with_loads
from .mapping import Mapping, default_mapping, read_mapping
from .opensim_angles import joint_slopes
from .opensim_classes import check_mapping, classify
from .opensim_couplers import coupler_rhythm, followed, read_couplers
from .opensim_muscles import activation_floor, check_muscle, compliant, tension_terms
from .osim_geometry import geometry
from .osim_loads import osim_body_weight, osim_load_terms

KEPT = 256
"""How many linearisations an engine keeps in memory (:attr:`OsimEngine.linearisations`), the latest."""


@dataclass
class OsimEngine:
    """An OpenSim model built from a ``.osim`` file, with its working state.

    Attributes
    ----------
    model : opensim.Model
    state : SimTK.State
    name, source, sha256 : str
        The model's name, the file's path and the SHA-256 of its bytes.
    couplers : tuple of spinectl.anatomy.opensim_couplers.Coupler
        The model's ``CoordinateCouplerConstraint`` s, switched off in ``model`` (the free chain).
    mobilities : dict
        Coordinate name -> its mobility index, read once (:func:`_mobility_order`).
    cache : bool
        Whether :func:`linearise` reads and writes the cache of linearisations (:mod:`spinectl.anatomy.osim_cache`).
    linearisations : dict
        The latest :data:`KEPT` linearisations made in this process, by their cache key (with or without ``cache``).
    springs : int
        How many muscles have a compliant tendon (linearised at the operating activations, which then
        belong to a linearisation's key).
    """

    model: object
    state: object
    name: str
    source: str
    sha256: str
    couplers: tuple = field(default=())
    mobilities: dict = field(default_factory=dict, repr=False)
    cache: bool = True
    linearisations: dict = field(default_factory=dict, repr=False)
    springs: int = 0

    def coordinate(self, name: str):
        """The coordinate of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        opensim.Coordinate
        """
        return self.model.getCoordinateSet().get(name)

    def spec_factory(self):
        """MuJoCo's referee (``check``) rebuilds an MJCF spec; an OpenSim model has none: one line.

        OpenSim offers no linearisation of its own to compare the chain with, so ``--check`` is
        MuJoCo's, for MJCF models only.

        Raises
        ------
        ParameterError
            Always.
        """
        raise ParameterError(
            "check",
            f"MuJoCo is the referee, for MJCF models only; OpenSim has no linearisation to compare {self.name}'s with",
        )

    def set_posture(self, values: dict) -> None:
        """Set coordinates at zero speed, the others at their defaults, and realise positions.

        Parameters
        ----------
        values : dict
            Coordinate name -> value [rad].
        """
        coords = self.model.getCoordinateSet()
        for i in range(coords.getSize()):
            c = coords.get(i)
            c.setValue(self.state, float(values.get(c.getName(), c.getDefaultValue())), False)
            c.setSpeedValue(self.state, 0.0)
        self.model.realizePosition(self.state)


def load_engine(path, cache: bool = True) -> OsimEngine:
    """Build an ``.osim`` file with OpenSim.

    Parameters
    ----------
    path : str or pathlib.Path
    cache : bool
        Whether its linearisations are read from and written to the cache (:mod:`spinectl.anatomy.osim_cache`).

    Returns
    -------
    OsimEngine
    """
    osim = require_opensim()
    path = model_file(str(path), "an .osim file")
    try:
        with engine_output_to_stderr():  # OpenSim's warnings (e.g. of each missing mesh) are not our output
            model = osim.Model(str(path))
            schema = _schema(osim, model, path)
            couplers = read_couplers(osim, model)
            state = model.initSystem()
    except Exception as exc:  # OpenSim raises its own exception types, one line each
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError("model", f"OpenSim cannot build {path}: {opensim_message(exc)}") from None
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    source = str(path.resolve()) + schema
    muscles = model.getMuscles()
    springs = sum(compliant(muscles.get(i)) for i in range(muscles.getSize()))
    name = model.getName() or path.stem
    return OsimEngine(model, state, name, source, digest, couplers, cache=cache, springs=springs)


def _schema(osim, model, path) -> str:
    """What OpenSim did with the file's schema (its ``Version`` attribute): "" if current, else a note.

    OpenSim upgrades older schemas as it reads them; a schema newer than this OpenSim's may hold
    what it silently ignores, so it is refused in one line.
    """
    major, minor = (int(p) for p in osim.__version__.split(".")[:2])
    latest = 10000 * major + 100 * minor  # OpenSim's XMLDocument::LatestVersion of this release
    version = model.getDocumentFileVersion()
    if version > latest:
        raise ParameterError(
            "model",
            f"{printable(str(path))} has OpenSim schema {version}, newer than OpenSim {osim.__version__}'s "
            f"({latest}); open it with that OpenSim",
        )
    return f" (schema {version}, upgraded by OpenSim {osim.__version__} to {latest})" if version < latest else ""


def _mobility_order(engine: OsimEngine) -> dict:
    """Coordinate name -> its index among the system's mobilities (the order of calcM and the inverse dynamics).

    Read off the state once per engine (OpenSim's Python bindings do not wrap the tree order):
    the entry of U that each coordinate's speed sets. One speed per coordinate (no ball or free joints).
    """
    if engine.mobilities:
        return engine.mobilities
    coords, state = engine.model.getCoordinateSet(), engine.state
    for j in range(coords.getSize()):
        coords.get(j).setSpeedValue(state, 0.0)
    for i in range(coords.getSize()):  # the one speed that a coordinate's speed sets
        coords.get(i).setSpeedValue(state, 1.0)
        engine.mobilities[coords.get(i).getName()] = int(np.argmax(np.abs(state.getU().to_numpy())))
        coords.get(i).setSpeedValue(state, 0.0)
    return engine.mobilities


def linearise(engine: OsimEngine, names, values: dict, n=None, activations=None) -> Linearisation:
    """K_i, K_0, D_i, D_0, M over the given coordinates at a posture, made once (module docstring).


    Made once per process and engine (:attr:`OsimEngine.linearisations`) and, with
    :attr:`OsimEngine.cache`, read from or written to the cache of linearisations
    (:mod:`spinectl.anatomy.osim_cache`): bit for bit what :func:`_linearise` returns.

    Parameters
    ----------
    engine : OsimEngine
    names : sequence of str
        The coordinates involved, the chain's first.
    values : dict
        Coordinate name -> value [rad] of the posture (others at their defaults).
    n : int, optional
        How many of ``names`` are the chain's (default all).
    activations : array_like, shape (m,), optional
        The operating activations, where compliant-tendon muscles are linearised
        (:func:`spinectl.anatomy.opensim_muscles.tension_terms`); default each muscle's floor.

    Returns
    -------
    Linearisation
        Over ``names`` (``dofs`` = 0 ... len(names) - 1), the other coordinates held; a copy.
    """
    names = [str(c) for c in names]
    n = len(names) if n is None else int(n)
    # a rigid tendon's terms are exact at every activation, a compliant one's the tangent at these
    operating = None if activations is None else np.asarray(activations, dtype=float)
    key = osim_cache.key(engine.sha256, names, n, values, operating if engine.springs else None)
    lin = engine.linearisations.get(key) or (osim_cache.read(key) if engine.cache else None)
    if lin is None:
        lin = _linearise(engine, names, values, n, operating)
        if engine.cache:
            osim_cache.write(key, lin)
    engine.linearisations[key] = lin
    if len(engine.linearisations) > KEPT:  # the oldest goes: a sweep over postures holds KEPT at most
        engine.linearisations.pop(next(iter(engine.linearisations)))
    arrays = {f.name: getattr(lin, f.name) for f in fields(lin)}
    return replace(lin, **{name: np.copy(v) for name, v in arrays.items() if isinstance(v, np.ndarray)})


def _linearise(engine: OsimEngine, names, values: dict, n=None, activations=None) -> Linearisation:
    """:func:`linearise` computed, neither kept nor cached (the same parameters and result)."""
    names = list(names)
    s = len(names)
    n = s if n is None else int(n)
    geo = geometry(engine, names, values, _mobility_order(engine))
    arms, passive, dpassive, hessian, lengths = geo.arms, geo.passive, geo.dpassive, geo.hessian, geo.lengths
    operating = np.zeros(len(lengths)) if activations is None else activations
    terms, notes = tension_terms(engine, values, operating, arms, names)
    gain, dgain_dl, dgain_dv, bias, dbias_dl, dbias_dv = terms
    rr = np.einsum("ij,ik->jki", arms, arms)
    return Linearisation(
        dofs=tuple(range(s)),
        n=n,
        stiffness_per_muscle=hessian.transpose(1, 2, 0) * gain + rr * dgain_dl,
        stiffness_offset=0.5 * (dpassive + dpassive.T) + np.einsum("ijk,i->jk", hessian, bias) + rr @ dbias_dl,
        damping_per_muscle=rr * dgain_dv,
        damping_offset=rr @ dbias_dv,  # the fibres' own damping (e.g. Millard's fiber_damping)
        mass=geo.mass,
        torque_per_muscle=arms.T * gain,
        torque_offset=passive + arms.T @ bias,
        moment_arms=arms,
        notes=notes,
    )


@dataclass
class OsimAnatomy(MappedModel):
    """An OpenSim model mapped onto the chain: OpenSim's :class:`~spinectl.anatomy.contract.AnatomyEngine`.

    The free chain has the coordinate couplers off; the constrained chain applies their
    linearised relations (module docstring). MuJoCo's referee (``--check``) needs MJCF.

    Parameters
    ----------
    engine : OsimEngine
    mapping : Mapping
    muscles : tuple of str
        The muscles' names.
    classes : tuple of str
        Each muscle's class.
    """

    rhythm_name = "couplers"
    linearised_at_activations = True  # compliant tendons: the tangent at the operating activations
    body_weight = osim_body_weight  # the contract's body_weight: gravity and a body's centre of mass

    def control_bounds(self) -> tuple:
        """Each muscle's activation range: [its law's floor, 1] (Millard's and Thelen's ``minimum_activation``).

        OpenSim holds a Millard or Thelen muscle's activation at its floor or above, so an
        activation below it is not the muscle's (:func:`~spinectl.anatomy.opensim_muscles.activation_floor`).

        Returns
        -------
        tuple
            (lower, upper), numpy.ndarray of shape (m,).
        """
        muscles = self.engine.model.getMuscles()
        lower = np.array([activation_floor(muscles.get(i)) for i in range(muscles.getSize())])
        return lower, np.ones(len(self.muscles))

    @property
    def control_unit(self) -> str:
        """The muscles' control unit: ``1`` (activations)."""
        return "1"

    def default_controls(self) -> np.ndarray:
        """The activations analysed when none are given: the model's own controls at t = 0, else the floor.

        The model's controllers (spinectl's export: the ``PrescribedController`` of the solution)
        evaluated by OpenSim at the posture's time t = 0 (``Model.realizeVelocity``, then each
        muscle's ``getControl``), as MuJoCo's import takes keyframe 0's; 0 without a controller.
        Clipped to the muscles' control bounds (:meth:`control_bounds`: round-off of the export's
        near-zero controls, and OpenSim's own floor of Millard's and Thelen's activations).

        Returns
        -------
        numpy.ndarray, shape (m,)
        """
        lower, upper = self.control_bounds()
        if not self._controllers():
            return lower
        model, state = self.engine.model, self.engine.state
        state.setTime(0.0)
        model.realizeVelocity(state)
        muscles = model.getMuscles()
        return np.clip([muscles.get(i).getControl(state) for i in range(muscles.getSize())], lower, upper)

    def default_controls_source(self) -> str:
        """Where :meth:`default_controls` come from, as one phrase.

        Returns
        -------
        str
        """
        names = self._controllers()
        if not names:
            return "each muscle's activation floor: the model has no controller"
        return f"the model's controls at t = 0 ({', '.join(names)})"

    def _controllers(self) -> list:
        """The model's enabled controllers, each as ``class name``."""
        controllers = self.engine.model.getControllerSet()
        found = (controllers.get(i) for i in range(controllers.getSize()))
        return [f"{c.getConcreteClassName()} {c.getName()}" for c in found if c.isEnabled()]

    def posture(self, posture=None) -> dict:
        """The posture: the coordinates' default values, or those given.

        Parameters
        ----------
        posture : dict, optional
            Coordinate name -> value [rad]; the others at their defaults.

        Returns
        -------
        dict
        """
        if posture is None:
            return {}
        if not isinstance(posture, dict):
            raise ParameterError("posture", "of an OpenSim model: a dict of coordinate name -> value [rad]")
        return dict(posture)

    def rhythm(self, plane: str = "sagittal", posture=None) -> tuple:
        """The couplers that tie the plane's chain as a Rhythm, at a posture (``opensim_couplers.coupler_rhythm``).

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : dict, optional
            Coordinate name -> value [rad].

        Returns
        -------
        tuple
            (Rhythm, the involved coordinates' names, the chain's first).
        """
        rhy, involved, _ = coupler_rhythm(self.engine, self.plane_joints(plane), self.posture(posture))
        return rhy, involved

    def linearise(self, plane: str = "sagittal", posture=None, activations=None) -> tuple:
        """The linearisation over the plane's coordinates and those its couplers tie.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : dict, optional
            Coordinate name -> value [rad].
        activations : array_like, shape (m,), optional
            Where compliant-tendon muscles are linearised (their forces are not affine in the
            activation); default :meth:`default_controls`. Rigid-tendon muscles are exact at any.

        Returns
        -------
        tuple
            (Linearisation, Rhythm of the couplers (``opensim_couplers.coupler_rhythm``), the involved
            coordinates' names).
        """
        values = self.posture(posture)
        rhy, involved = self.rhythm(plane, values)
        operating = self.default_controls() if activations is None else np.asarray(activations, float)
        return linearise(self.engine, involved, values, len(self.plane_joints(plane)), operating), rhy, involved

    def apply_loads(self, lin: Linearisation, posture, loads, involved) -> Linearisation:  # MappedModel's doc
        terms = osim_load_terms(self.engine, loads, involved, self.posture(posture), _mobility_order(self.engine))
        return with_loads(lin, *terms, lin.dofs)

    def couplers(self, plane: str = "sagittal", posture=None) -> list:
        """The couplers that tie the plane's chain, each as one phrase with its slopes at the posture.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : dict, optional
            Coordinate name -> value [rad].

        Returns
        -------
        list of str
        """
        values = self.posture(posture)
        _, _, used = coupler_rhythm(self.engine, self.plane_joints(plane), values)
        return [c.describe(values, self.engine) for c in used]

    def joint_slopes(self, plane: str = "sagittal", posture=None) -> JointSlopes:
        """How the plane's chain joints turn per unit of its coordinates, by OpenSim's frames (:func:`joint_slopes`).

        A CustomJoint's SpatialTransform may scale its coordinate (Christophy's ``flex_extension``
        turns L5/S1 0.125 rad per radian); the chains are per radian of each joint's rotation.

        Parameters
        ----------
        plane : str
            One of the mapping's planes.
        posture : dict, optional
            Coordinate name -> value [rad].

        Returns
        -------
        JointSlopes
        """
        return joint_slopes(self.engine, self.plane_joints(plane), self.posture(posture))

    def chain_source(self, plane: str, posture=None) -> str:
        """The chains' source line; away from the default posture, with the couplers' slopes there.

        Parameters
        ----------
        plane : str
        posture : dict, optional
            Coordinate name -> value [rad].

        Returns
        -------
        str
        """
        source = f"{self.source}, {plane}"
        if posture and self.engine.couplers:  # the engine's source gives the slopes at the default posture
            source += f"; the couplers at this posture: {'; '.join(self.couplers(plane, posture)) or 'none'}"
        return source

    def equilibrium_rows(self, lin, plane: str, posture, equilibrium: str) -> tuple:
        """The optimum's equilibrium: the chain's coordinates (``"free"``) or the couplers' independent ones.

        With ``"rhythm"`` the couplers carry the rest (T^T tau = 0 over the involved coordinates).

        Parameters
        ----------
        lin : Linearisation
            At the posture, over the involved coordinates (the chain's first).
        plane : str
            The chain.
        posture : dict or None
            Coordinate name -> value [rad].
        equilibrium : str
            ``"rhythm"`` or ``"free"``.

        Returns
        -------
        tuple
            (the chain's rows, torque per control on the equilibrium's rows [N m], the rest [N m]).
        """
        rows = list(range(lin.n))
        if equilibrium == "free":
            return rows, lin.torque_per_muscle[rows], lin.torque_offset[rows]
        rhy, _ = self.joint_rhythm(plane, posture)  # lin is in the joints' angles (MappedModel.chains)
        return rows, rhy.transform.T @ lin.torque_per_muscle, rhy.transform.T @ lin.torque_offset

    def volume_weights(self) -> np.ndarray:
        """w_i proportional to F_max,i l_opt,i (the Millard muscle's volume), normalised to mean 1.

        Returns
        -------
        numpy.ndarray, shape (m,)
        """
        muscles = self.engine.model.getMuscles()
        volume = np.array(
            [
                muscles.get(i).getMaxIsometricForce() * muscles.get(i).getOptimalFiberLength()
                for i in range(muscles.getSize())
            ]
        )
        return volume / volume.mean()

    def lordosis_posture(self, degrees: float, plane: str = "sagittal") -> dict:
        """The default posture with the chain moved along the model's couplers by ``degrees`` in total.

        The couplers' first independent coordinate and the coordinates they slave to it move as the
        couplers' slopes at the default posture distribute them (``opensim_couplers.coupler_rhythm``), the chain's
        joint angles (not its coordinates, :meth:`joint_slopes`) summing to ``degrees``; a coordinate off
        the chain that a coupler slaves to the chain (a routing body's, left out of the rhythm) follows
        its coupler, so the posture is the model's. The engine sets them through OpenSim's coordinates
        (:meth:`OsimEngine.set_posture`).

        Parameters
        ----------
        degrees : float
            The change of the chain's summed angle [deg].
        plane : str

        Returns
        -------
        dict
            Coordinate name -> value [rad].
        """
        rhy, involved = self.rhythm(plane)
        n = len(self.plane_joints(plane))
        step = lordosis_direction(self, rhy, n, degrees, self.joint_slopes(plane))
        engine = self.engine
        values = {n: engine.coordinate(n).getDefaultValue() + float(v) for n, v in zip(involved, step, strict=True)}
        return followed(engine, values)

    def require_referee(self) -> None:
        """Refused: MuJoCo is the referee, for MJCF only (:meth:`OsimEngine.spec_factory`)."""
        self.engine.spec_factory()

    engine_kind = "OpenSim"

    def engine_versions(self) -> dict:
        """OpenSim's version (the model's identity).

        Returns
        -------
        dict
            Package -> version.
        """
        return {"opensim": require_opensim().__version__}

    def posture_columns(self):
        """A posture file's columns: each coordinate by name or by path (``/jointset/<joint>/<name>/value``).

        The model's other states (speeds, activations, fibre lengths: a states file's columns) and its
        muscles' activations by name or path are skipped; the coordinates that OpenSim converts from
        degrees (``SimbodyEngine.convertDegreesToRadians`` on a row of ones) are the rotational ones.

        Returns
        -------
        spinectl.anatomy.recordings.Columns
        """
        from .recordings import posture_columns_of

        osim, model = require_opensim(), self.engine.model
        coords = model.getCoordinateSet()
        names = [coords.get(i).getName() for i in range(coords.getSize())]
        labels = {n: n for n in names}
        labels.update({coords.get(n).getAbsolutePathString() + "/value": n for n in names})
        table = osim.TimeSeriesTable()
        table.setColumnLabels(osim.StdVectorString(names))
        table.appendRow(0.0, osim.RowVector(len(names), 1.0))
        table.addTableMetaDataString("inDegrees", "yes")
        model.getSimbodyEngine().convertDegreesToRadians(table)
        row = table.getRowAtIndex(0).to_numpy()
        rotational = [n for n, v in zip(names, row, strict=True) if v != 1.0]
        muscles = set(self.activation_columns().names)  # a states file's activations, even of a muscle without one
        return posture_columns_of(labels, names, (self._states() | muscles) - set(labels), rotational)

    def activation_columns(self):
        """An activation file's columns: each muscle by name or by path (``/forceset/<name>/activation``).

        Returns
        -------
        spinectl.anatomy.recordings.Columns
        """
        from .recordings import activation_columns_of

        muscles = self.engine.model.getMuscles()
        labels = {m: m for m in self.muscles}
        labels.update({muscles.get(m).getAbsolutePathString() + "/activation": m for m in self.muscles})
        return activation_columns_of(labels, self.muscles, self._states() - set(labels))

    def named_posture(self, values: dict) -> dict:
        """The posture in OpenSim's form: coordinate name -> value.

        Parameters
        ----------
        values : dict
            Coordinate name -> value [rad or m].

        Returns
        -------
        dict
        """
        return dict(values)

    def _states(self) -> set:
        """The paths of the model's state variables (a states file's columns)."""
        states = self.engine.model.getStateVariableNames()
        return {states.get(i) for i in range(states.getSize())}

    def sagittal_axes(self, joints, posture=None) -> tuple:
        """The sagittal plane's (horizontal, vertical) unit axes in ground: up x the first joint's axis.

        Up is against OpenSim's gravity (``Model.getGravity``); the axis is the one about which the
        first coordinate turns its joint's child frame (:func:`_turning_axis`).

        Parameters
        ----------
        joints : sequence of str
            The sagittal chain's coordinates.
        posture : dict, optional
            Coordinate name -> value [rad].

        Returns
        -------
        tuple
            (horizontal, up), numpy.ndarray of shape (3,) each.
        """
        values = self.posture(posture)
        normal = _turning_axis(self.engine, joints[0], values)
        self.engine.set_posture(values)
        return plane_axes(_vec3(self.engine.model.getGravity()), normal, (0.0, 1.0, 0.0))

    def spine(self, joints, basis, posture=None, moved=None) -> tuple:
        """The chain's joint centres (each coordinate's joint's child frame) and the thorax's mass centre, projected.

        Parameters
        ----------
        joints : sequence of str
            The chain's coordinates.
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes (:meth:`sagittal_axes`).
        posture : dict, optional
            Coordinate name -> value [rad].
        moved : array_like, shape (len(joints),), optional
            Added to the joints' angles [rad] (the chains' variables, :meth:`joint_slopes`), the others
            held, the couplers off.

        Returns
        -------
        tuple
            (numpy.ndarray of shape (n, 2), numpy.ndarray of shape (2,)) [m].
        """
        engine = self.engine
        values = self.posture(posture)
        shifted = dict(values)
        if moved is not None:  # the coordinates' change that turns the joints by ``moved``
            slopes = joint_slopes(engine, joints, values)
            moved = moved if slopes.is_identity() else np.linalg.solve(slopes.jacobian, np.asarray(moved, float))
        for name, change in zip(joints, np.zeros(len(joints)) if moved is None else moved, strict=True):
            shifted[name] = values.get(name, engine.coordinate(name).getDefaultValue()) + float(change)
        engine.set_posture(shifted)
        state = engine.state
        cors = np.array(
            [_vec3(engine.coordinate(n).getJoint().getChildFrame().getPositionInGround(state)) for n in joints]
        )
        name = self.mapping.bodies["thorax"][0]
        if name == engine.model.getGround().getName():
            thorax = np.zeros(3)
        else:
            body = engine.model.getBodySet().get(name)
            thorax = _vec3(body.findStationLocationInGround(state, body.getMassCenter()))
        engine.set_posture(values)
        return cors @ basis.T, thorax @ basis.T

    def muscle_paths(self, basis, posture=None) -> tuple:
        """Every muscle's current path (OpenSim's path points, wrapping included, in ground), projected.

        Parameters
        ----------
        basis : numpy.ndarray, shape (2, 3)
            The plane's axes (:meth:`sagittal_axes`).
        posture : dict, optional
            Coordinate name -> value [rad].

        Returns
        -------
        tuple
            Per muscle, a tuple of one branch of shape (p, 2) [m] (none if its path has one point).
        """
        engine = self.engine
        engine.set_posture(self.posture(posture))
        muscles = engine.model.getMuscles()
        out = []
        for i in range(muscles.getSize()):
            path = muscles.get(i).getGeometryPath().getCurrentPath(engine.state)
            points = np.array([_vec3(path.get(k).getLocationInGround(engine.state)) for k in range(path.getSize())])
            out.append((points.reshape(-1, 3) @ basis.T,) if len(points) > 1 else ())
        return tuple(out)


def _vec3(vector) -> np.ndarray:
    """A SimTK Vec3 as a numpy array."""
    return np.array([vector.get(k) for k in range(3)])


def _turning_axis(engine: OsimEngine, name: str, values: dict) -> np.ndarray:
    """The unit axis in ground about which coordinate ``name`` turns its joint's child frame at a posture.

    Read off OpenSim's frames (the child frame's axes in ground, ``expressVectorInGround``) at the
    posture and :data:`~spinectl.anatomy.linearise.STEP` on: the rotation between them is about that axis.
    """
    osim = require_opensim()
    frame = engine.coordinate(name).getJoint().getChildFrame()

    def axes(vals) -> np.ndarray:
        engine.set_posture(vals)
        return np.array([_vec3(frame.expressVectorInGround(engine.state, osim.Vec3(*e))) for e in np.eye(3)]).T

    start = values.get(name, engine.coordinate(name).getDefaultValue())
    turn = axes({**values, name: start + STEP}) @ axes(values).T
    axis = np.array([turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0], turn[1, 0] - turn[0, 1]])
    if not np.linalg.norm(axis) > 0:
        raise ModelError(f"{engine.name}: coordinate {name} turns no frame (a translation?): no sagittal plane to draw")
    return axis / np.linalg.norm(axis)


def load_osim(path, mapping=None, cache: bool = True) -> OsimAnatomy:
    """Load an ``.osim`` model with OpenSim and map it onto the chain.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.osim`` file.
    mapping : str, pathlib.Path or Mapping, optional
        A mapping TOML (names of OpenSim bodies and coordinates); default the built-in one of the
        model's name (``wagner2012_chain`` for spinectl's own export).
    cache : bool
        Read the model's linearisations from the cache of linearisations and write them there
        (:mod:`spinectl.anatomy.osim_cache`); False linearises anew and leaves the cache alone.
        The model itself is built anew each time (OpenSim has no compiled form to keep).

    Returns
    -------
    OsimAnatomy
    """
    engine = load_engine(path, cache=cache)
    if mapping is None:
        mapping = default_mapping(engine.name)
    elif not isinstance(mapping, Mapping):
        mapping = read_mapping(mapping)
    check_mapping(engine, mapping)
    muscles = engine.model.getMuscles()
    for i in range(muscles.getSize()):
        check_muscle(engine.name, muscles.get(i))
    names = tuple(muscles.get(i).getName() for i in range(muscles.getSize()))
    if engine.springs:  # in the source line too: the chains are exact at the analysed activations only
        engine.source += f"; {engine.springs} compliant-tendon muscles linearised at the analysed activations"
    if engine.couplers:  # in the model's source line, which every table and JSON prints
        described = "; ".join(c.describe({}, engine) for c in engine.couplers)
        engine.source += (
            "; coupler constraints (off in the free chain; those among the chain's coordinates linearised in the "
            f"constrained): {described}"
        )
    return OsimAnatomy(engine, mapping, names, classify(engine, mapping))
