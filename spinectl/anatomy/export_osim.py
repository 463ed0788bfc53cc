"""The paper's model and its solution as an OpenSim model (``.osim``), built with OpenSim's API (docs/interchange.md).

The same chain as the MJCF export (:mod:`spinectl.anatomy.export_mjcf`): a pin joint at every
CoR (OpenSim's frame: spinectl's x and y, rotation about z), each body with the mass it
carries, every fibre as a muscle on a straight path from its upper attachment (thorax) to
its lower one (ground = pelvis), the intervertebral stiffness as a ``SpringGeneralizedForce``
per joint, the counter torques as ``CoordinateActuator`` s (those that hold the posture against
OpenSim's own forces, :func:`opensim_counter_torque`), and the solution held
by a ``PrescribedController`` of constant controls (also written beside the model as a
controls ``.sto``). A lumbar level's weight enters spinectl's gravity only by
``levels.weight_in_gravity`` (docs/chain.md): OpenSim has no gravity compensation, so the
rest of it is cancelled by a ``PrescribedForce`` at the level's centre of mass, constant in
the ground frame.

The fibres are OpenSim muscles of one of two kinds (``muscle``, :data:`MUSCLES`):

- ``"millard"`` (default, what ``spinectl anatomy`` re-imports): ``Millard2012EquilibriumMuscle`` s
  with a rigid tendon, no activation dynamics, no pennation, no fibre damping, the paper's optimal
  length (1.2 l0) and maximal velocity, and Millard's own curves, so the tension and its slopes at
  the posture differ from spinectl's (docs/interchange.md, "What is lost"), and Millard floors the
  activation at 0.01;
- ``"paper"``: ``RigidTendonMuscle`` s (no tendon length, no pennation, the activation is the
  control, unclamped) whose curves are those of the model's muscle law (``fibre.law``) as OpenSim
  ``ExpressionBasedFunction`` s (:func:`spinectl.model.laws.opensim_curves`; the paper's law: its
  own formulas, no passive curve): OpenSim's tension is then spinectl's at every length and
  velocity, so OpenSim's linearisation of the file is the chain's K and D. A law without such
  expressions is refused in one line.

The geometry, the masses, gravity and the springs are the same either way.

OpenSim is the optional extra ``spinectl[opensim]``.

References
----------
Seth A, Hicks JL, Uchida TK, et al. (2018). OpenSim: Simulating musculoskeletal dynamics and
neuromuscular control to study human and animal movement. PLoS Comput Biol 14(7):e1006223.
doi:10.1371/journal.pcbi.1006223.

Millard M, Uchida T, Seth A, Delp SL (2013). Flexing computational muscle: modeling and
simulation of musculotendon dynamics. J Biomech Eng 135(2):021005. doi:10.1115/1.4023390.
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .._optional import require_module
from .._validate import printable
from ..atomic import atomic_path, check_distinct, full_disk_note
from ..errors import OutputError, ParameterError
from ..model import chain, geometry, laws
from ..model.mechanics import gravity_sign
from ..model.muscle import max_velocity
from ..units import M2_PER_CM2
from .engine import SpinectlError
from .export_mjcf import PaperSolution, body_names, fibre_gains, paper_solution

INSTALL_HINT = "pip install 'spinectl[opensim]'"

REFERENCE_PCSA_CM2 = 100.0
"""PCSA [cm^2] of a muscle at activation 1 in the exported OpenSim model: a fibre's activation is its
muscle's PCSA over this (OpenSim's activations lie in [0, 1]; the paper bounds no PCSA)."""

TENDON_SLACK_RATIO = 1e-4
"""Tendon slack length over the upright fibre length of a Millard muscle: a rigid tendon of (almost) no
length, so that the fibre's length is the path's (Millard's muscle requires a positive slack length;
the ``"paper"`` muscles have none)."""

MUSCLES = ("millard", "paper")
"""The exported fibres' muscle models: Millard's (re-imported by ``spinectl anatomy``) or the paper's
curves on OpenSim's ``RigidTendonMuscle``."""


INVALID_NAME_CHARACTERS = "\\/*+ \t\n"
"""Characters OpenSim refuses in a component's name (``Component::finalizeFromProperties``: "contains invalid
characters"): the segments' and pairs' names become coordinates, joints, muscles and path points."""


class OpenSimUnavailable(SpinectlError, ImportError):
    """OpenSim is not installed."""


def require_opensim():
    """Import and return :mod:`opensim`, or raise one line saying what to install.

    Returns
    -------
    module
        :mod:`opensim`.
    """
    opensim = require_module("opensim", OpenSimUnavailable, f"OpenSim models need OpenSim: {INSTALL_HINT}")
    opensim.Logger.setLevelString("warn")  # OpenSim's [info] lines are not spinectl's output
    opensim.Logger.removeFileSink()  # nor its opensim.log in the working folder
    return opensim


def coordinate_names(model) -> tuple:
    """The exported model's coordinates: the CoR names, top to bottom.

    Parameters
    ----------
    model : Model

    Returns
    -------
    tuple of str
    """
    return tuple(model.geometry.cor_names)


def _vec(osim, point):
    """spinectl's (x, y) as OpenSim's Vec3 (x, y, 0)."""
    return osim.Vec3(float(point[0]), float(point[1]), 0.0)


def check_muscle(muscle: str) -> str:
    """``muscle`` if it names one of :data:`MUSCLES`, else one line saying what is allowed.

    Parameters
    ----------
    muscle : str

    Returns
    -------
    str
    """
    if muscle not in MUSCLES:
        raise ParameterError("muscle", f"must be one of {list(MUSCLES)} (got {muscle!r})")
    return muscle


def check_names(model) -> None:
    """Refuse, in one line naming the field, a segment or pair name that OpenSim cannot take.

    Parameters
    ----------
    model : Model

    Raises
    ------
    ParameterError
        A name holding one of :data:`INVALID_NAME_CHARACTERS` (OpenSim would throw while the model is built).
    """
    named = [(f"geometry.cor_names[{k}]", name) for k, name in enumerate(model.geometry.cor_names)]
    named += [(f"muscles.{k}.name", pair.name) for k, pair in enumerate(model.muscles)]
    for field, name in named:
        if any(char in INVALID_NAME_CHARACTERS for char in name):
            raise ParameterError(
                field,
                f"must hold no space, tab, line break nor any of \\ / * + in an OpenSim model: OpenSim refuses "
                f"them in a name (got {printable(repr(name))})",
            )


def _millard_fibre(osim, name, f_max, l_opt, length, v_hat):
    """One fibre as a rigid-tendon ``Millard2012EquilibriumMuscle`` with Millard's curves."""
    out = osim.Millard2012EquilibriumMuscle(name, f_max, l_opt, TENDON_SLACK_RATIO * length, 0.0)
    out.set_ignore_tendon_compliance(True)
    out.set_ignore_activation_dynamics(True)
    out.set_fiber_damping(0.0)  # the paper's fibres have no damping of their own
    out.set_max_contraction_velocity(v_hat)
    return out


def _paper_fibre(osim, name, f_max, l_opt, curves, v_hat):
    """One fibre as a ``RigidTendonMuscle`` with its law's curves (:class:`~spinectl.model.laws.OpenSimCurves`)
    and no tendon length."""
    out = osim.RigidTendonMuscle(name, f_max, l_opt, 0.0, 0.0)
    out.set_max_contraction_velocity(v_hat)
    out.set_active_force_length_curve(osim.ExpressionBasedFunction(curves.active_force_length, "x"))
    out.set_force_velocity_curve(osim.ExpressionBasedFunction(curves.force_velocity, "w"))
    passive = curves.passive_force_length  # None: no passive force (the paper's fibres)
    passive = osim.Constant(0.0) if passive is None else osim.ExpressionBasedFunction(passive, "x")
    out.set_passive_force_length_curve(passive)
    return out


def paper_osim(solution: PaperSolution, counter_torque=None, muscle: str = "millard"):
    """The OpenSim model (:class:`opensim.Model`) of the paper's chain with the solution's controls.

    Parameters
    ----------
    solution : PaperSolution
    counter_torque : array_like, shape (n_cor,), optional
        The counter torques' controls [N m]; default the solution's (those of spinectl's tension).
    muscle : {"millard", "paper"}
        The fibres' muscle model (:data:`MUSCLES`).

    Returns
    -------
    tuple
        (opensim.Model, control names, control values): activations of the fibres [1], then the
        counter torques [N m].
    """
    check_muscle(muscle)
    osim = require_opensim()
    model, cor = solution.model, solution.cor
    n = cor.shape[0]
    out = osim.Model()
    out.setName("wagner2012_chain")
    out.setGravity(osim.Vec3(0.0, -gravity_sign(model) * model.body.gravity, 0.0))
    masses = [model.body.mass] + [model.levels.mass] * (n - 1)
    gyration = [model.body.radius_of_gyration] + [model.levels.radius_of_gyration] * (n - 1)
    centres = [geometry.mass_position(model)] + list(chain.level_positions(np.zeros(n), cor))
    names = body_names(model)
    parent = out.getGround()
    bodies = {}
    for k in range(n - 1, -1, -1):  # from the pelvis up
        moment = masses[k] * gyration[k] ** 2
        body = osim.Body(names[k], masses[k], _vec(osim, centres[k]), osim.Inertia(moment, moment, moment))
        out.addBody(body)
        joint = osim.PinJoint(
            f"{model.geometry.cor_names[k]}_joint",
            parent,
            _vec(osim, cor[k]),
            osim.Vec3(0.0),
            body,
            _vec(osim, cor[k]),
            osim.Vec3(0.0),
        )
        joint.updCoordinate().setName(model.geometry.cor_names[k])
        out.addJoint(joint)
        relief = (1.0 - model.levels.weight_in_gravity) * masses[k] * model.body.gravity * gravity_sign(model)
        if k > 0 and relief != 0.0:
            force = osim.PrescribedForce(f"{names[k]}_weight_relief", body)
            force.setPointIsInGlobalFrame(False)
            force.setForceIsInGlobalFrame(True)
            force.setPointFunctions(*(osim.Constant(float(v)) for v in (centres[k][0], centres[k][1], 0.0)))
            force.setForceFunctions(osim.Constant(0.0), osim.Constant(relief), osim.Constant(0.0))
            out.addForce(force)
        bodies[k] = parent = body
    controller = osim.PrescribedController()
    controller.setName("solution")
    labels, values = [], []
    fibres = fibre_gains(model)
    l_opt = model.fibre.optimal_length_ratio * fibres.length
    reference = REFERENCE_PCSA_CM2 * M2_PER_CM2
    curves = laws.opensim_curves(model.fibre, model.errata) if muscle == "paper" else None
    for f, name in enumerate(fibres.names):
        f_max = float(model.fibre.specific_tension * reference / np.sum(fibres.muscle == fibres.muscle[f]))
        v_hat = float(max_velocity(l_opt[f], model.fibre) / l_opt[f])
        if muscle == "paper":
            fibre = _paper_fibre(osim, name, f_max, float(l_opt[f]), curves, v_hat)
        else:
            fibre = _millard_fibre(osim, name, f_max, float(l_opt[f]), float(fibres.length[f]), v_hat)
        fibre.addNewPathPoint(f"{name}_upper", bodies[0], _vec(osim, fibres.upper[f]))
        fibre.addNewPathPoint(f"{name}_lower", out.getGround(), _vec(osim, fibres.lower[f]))
        out.addForce(fibre)
        labels.append(name)
        values.append(float(solution.pcsa[fibres.muscle[f]] / reference))
    for k, coordinate in enumerate(model.geometry.cor_names):
        spring = osim.SpringGeneralizedForce(coordinate)
        spring.setName(f"{coordinate}_stiffness")
        spring.setStiffness(float(solution.joint_stiffness[k]))
        spring.setRestLength(0.0)
        spring.setViscosity(float(solution.joint_damping[k]))  # the local muscles' damping, 0 without them
        out.addForce(spring)
        actuator = osim.CoordinateActuator(coordinate)
        actuator.setName(f"counter_{coordinate}")
        actuator.setOptimalForce(1.0)
        actuator.setMinControl(-np.inf)
        actuator.setMaxControl(np.inf)
        out.addForce(actuator)
        labels.append(f"counter_{coordinate}")
        values.append(float((solution.counter_torque if counter_torque is None else counter_torque)[k]))
    for label, value in zip(labels, values, strict=True):
        controller.addActuator(out.getComponent(f"forceset/{label}"))
        controller.prescribeControlForActuator(label, osim.Constant(value))
    out.addController(controller)
    out.finalizeConnections()
    return out, labels, values


def opensim_counter_torque(solution: PaperSolution, muscle: str = "millard") -> np.ndarray:
    """The counter torques that hold the posture against OpenSim's own forces [N m].

    Millard's tension at the posture is not the paper's (docs/interchange.md), so spinectl's
    counter torques -tau_0 leave a net torque in OpenSim. These are OpenSim's inverse dynamics
    at rest of the model with the solution's activations and no counter torque: the posture is
    then an equilibrium of the exported model. With the ``"paper"`` muscles they are spinectl's
    -tau_0 to rounding.

    Parameters
    ----------
    solution : PaperSolution
    muscle : {"millard", "paper"}

    Returns
    -------
    numpy.ndarray, shape (n_cor,)
        Top to bottom, as ``model.geometry.cor_names``.
    """
    osim = require_opensim()
    built, _, _ = paper_osim(solution, np.zeros(len(solution.counter_torque)), muscle)
    state = built.initSystem()
    built.equilibrateMuscles(state)
    built.realizeDynamics(state)
    needed = osim.InverseDynamicsSolver(built).solve(state, osim.Vector(state.getNU(), 0.0))
    coords = built.getCoordinateSet()
    speeds = {}
    for i in range(coords.getSize()):  # the mobility of each coordinate, read off the state
        for j in range(coords.getSize()):
            coords.get(j).setSpeedValue(state, float(i == j))
        u = state.getU()
        speeds[coords.get(i).getName()] = int(np.argmax([abs(u.get(k)) for k in range(u.size())]))
    return np.array([needed.get(speeds[name]) for name in coordinate_names(solution.model)])


def controls_path(out) -> Path:
    """The controls file written beside ``out``: ``<stem>_controls.sto``.

    Parameters
    ----------
    out : str or pathlib.Path

    Returns
    -------
    pathlib.Path
    """
    out = Path(out)
    return out.with_name(f"{out.stem}_controls.sto")


def export_osim(
    model,
    eccentricity: float,
    lordosis: float,
    out,
    *,
    pcsa=None,
    with_local_stiffness: bool = False,
    inputs: dict | None = None,
    muscle: str = "millard",
) -> PaperSolution:
    """Write the paper's model and its solution as ``.osim`` and its controls ``.sto`` beside it, atomically.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    out : str or pathlib.Path
        The ``.osim`` file to write.
    pcsa : array_like, optional
        PCSA [m^2]; default the per-segment optimum.
    with_local_stiffness : bool
        The chain's least local stiffness in the joints' springs.
    inputs : dict, optional
        Option name -> every file read; neither output may be one of them.
    muscle : {"millard", "paper"}
        The fibres' muscle model (:data:`MUSCLES`): Millard's (re-imported by ``spinectl anatomy``) or
        the paper's curves, with which OpenSim's linearisation is the chain's.

    Returns
    -------
    PaperSolution
    """
    check_muscle(muscle)
    check_names(model)
    osim = require_opensim()
    sto = controls_path(out)
    check_distinct({"--out": str(out), "controls": str(sto)}, inputs)
    solution = paper_solution(model, eccentricity, lordosis, pcsa, with_local_stiffness)
    built, labels, values = paper_osim(solution, opensim_counter_torque(solution, muscle), muscle)
    built.initSystem()  # refuse to write what OpenSim cannot build
    table = osim.TimeSeriesTable()
    table.setColumnLabels(labels)
    for time in (0.0, 1.0):
        table.appendRow(time, osim.RowVector(values))
    table.addTableMetaDataString("inDegrees", "no")
    # both written before either is renamed: a model that cannot be written leaves no controls behind
    with atomic_path(sto) as tmp_sto, atomic_path(out) as tmp_out:
        with _opensim_writes(sto):
            osim.STOFileAdapter.write(table, str(tmp_sto))
            read = osim.TimeSeriesTable(str(tmp_sto))  # OpenSim writes a truncated .sto onto a full disk, silently
            if list(read.getColumnLabels()) != labels or read.getNumRows() != 2:
                raise RuntimeError("the file read back is not what was written")
        with _opensim_writes(out):
            built.printToXML(str(tmp_out))
            osim.Model(str(tmp_out))  # read back: whole, and a model OpenSim loads
    return solution


@contextmanager
def _opensim_writes(target):
    """An error of OpenSim's writer (or of reading its file back) as one line naming ``target``.

    OpenSim reports a full disk as a ``RuntimeError`` of SimTK's ``Xml::writeToFile`` with neither the
    error number nor the output's name (the temporary's instead); the free space says which it was
    (:func:`spinectl.atomic.full_disk_note`).
    """
    try:
        yield
    except RuntimeError as exc:
        if isinstance(exc, SpinectlError):
            raise
        full = full_disk_note(target)
        detail = printable(str(exc).strip().splitlines()[0]) if str(exc).strip() else type(exc).__name__
        raise OutputError(f"cannot write {str(target)!r}: OpenSim's writer failed{full or f' ({detail})'}") from None


STEP = (1e-6, 1e-7)
"""Central-difference steps of :func:`opensim_linearisation`: in the angles [rad] and in the speeds [rad/s].
The speeds' is smaller because the paper's force-velocity curve changes branch at v = 0 (its two
curvatures differ, which leaves an error of the order of the step in a central difference)."""


def opensim_linearisation(path, names) -> tuple:
    """OpenSim's own linearisation of a model file about its default posture at rest, controls held.

    The generalised force of every force element (muscles, springs, counter torques, gravity) is
    minus OpenSim's inverse dynamics at zero acceleration (``InverseDynamicsSolver``); K and D are its
    central differences in the coordinates and their speeds (:data:`STEP`), M is ``calcM``. The
    exported muscles have no state (rigid tendon, activation = control), so (q, q') is the whole
    state and M q'' = f0 + K q + D q' to first order (docs/chain.md's sign convention: stable when
    the state matrix [[0, I], [M^-1 K, M^-1 D]] has only eigenvalues of negative real part).

    Parameters
    ----------
    path : str or pathlib.Path
        An ``.osim`` file.
    names : sequence of str
        The coordinates, in the order of the matrices' rows.

    Returns
    -------
    tuple of numpy.ndarray
        (f0 [N m], K [N m/rad], D [N m s/rad], M [kg m^2]) over ``names``.
    """
    osim = require_opensim()
    model = osim.Model(str(path))
    state = model.initSystem()
    coordinates = model.getCoordinateSet()
    order = [coordinates.getIndex(name) for name in names]  # a chain of pin joints: coordinate i is mobility i
    solver = osim.InverseDynamicsSolver(model)
    n = len(order)

    def force(q, u):
        for k, name in enumerate(names):
            coordinates.get(name).setValue(state, float(q[k]), False)
            coordinates.get(name).setSpeedValue(state, float(u[k]))
        model.realizeDynamics(state)
        needed = solver.solve(state, osim.Vector(state.getNU(), 0.0))
        return -np.array([needed.get(i) for i in order])

    zero = np.zeros(n)
    stiffness, damping = np.zeros((n, n)), np.zeros((n, n))
    for j in range(n):
        dq, du = STEP[0] * np.eye(n)[j], STEP[1] * np.eye(n)[j]
        stiffness[:, j] = (force(dq, zero) - force(-dq, zero)) / (2 * STEP[0])
        damping[:, j] = (force(zero, du) - force(zero, -du)) / (2 * STEP[1])
    f0 = force(zero, zero)
    mass = osim.Matrix()
    model.getMatterSubsystem().calcM(state, mass)
    full = np.array([[mass.get(i, j) for j in range(mass.ncol())] for i in range(mass.nrow())])
    return f0, stiffness, damping, full[np.ix_(order, order)]
