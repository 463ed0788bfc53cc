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

OpenSim has no muscle with the paper's curves: the fibres are ``Millard2012EquilibriumMuscle``
s with a rigid tendon, no activation dynamics, no pennation, no fibre damping, the paper's optimal length
(1.2 l0) and maximal velocity, and Millard's own curves, so the tension and its slopes at
the posture differ from spinectl's (docs/interchange.md, "What is lost"); the geometry, the
masses, gravity and the springs are the same.

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

from pathlib import Path

import numpy as np

from ..atomic import atomic_path, check_distinct
from ..model import chain, geometry
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
"""Tendon slack length over the upright fibre length: a rigid tendon of (almost) no length, so that the
fibre's length is the path's (OpenSim requires a positive slack length)."""


class OpenSimUnavailable(SpinectlError, ImportError):
    """OpenSim is not installed."""


def require_opensim():
    """Import and return :mod:`opensim`, or raise one line saying what to install.

    Returns
    -------
    module
        :mod:`opensim`.
    """
    try:
        import opensim
    except ImportError:
        raise OpenSimUnavailable(f"OpenSim models need OpenSim: {INSTALL_HINT}") from None
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


def paper_osim(solution: PaperSolution, counter_torque=None):
    """The OpenSim model (:class:`opensim.Model`) of the paper's chain with the solution's controls.

    Parameters
    ----------
    solution : PaperSolution
    counter_torque : array_like, shape (n_cor,), optional
        The counter torques' controls [N m]; default the solution's (those of spinectl's tension).

    Returns
    -------
    tuple
        (opensim.Model, control names, control values): activations of the fibres [1], then the
        counter torques [N m].
    """
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
    for f, name in enumerate(fibres.names):
        f_max = model.fibre.specific_tension * reference / np.sum(fibres.muscle == fibres.muscle[f])
        muscle = osim.Millard2012EquilibriumMuscle(
            name, float(f_max), float(l_opt[f]), float(TENDON_SLACK_RATIO * fibres.length[f]), 0.0
        )
        muscle.set_ignore_tendon_compliance(True)
        muscle.set_ignore_activation_dynamics(True)
        muscle.set_fiber_damping(0.0)  # the paper's fibres have no damping of their own
        muscle.set_max_contraction_velocity(float(max_velocity(l_opt[f], model.fibre) / l_opt[f]))
        muscle.addNewPathPoint(f"{name}_upper", bodies[0], _vec(osim, fibres.upper[f]))
        muscle.addNewPathPoint(f"{name}_lower", out.getGround(), _vec(osim, fibres.lower[f]))
        out.addForce(muscle)
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


def opensim_counter_torque(solution: PaperSolution) -> np.ndarray:
    """The counter torques that hold the posture against OpenSim's own forces [N m].

    Millard's tension at the posture is not the paper's (docs/interchange.md), so spinectl's
    counter torques -tau_0 leave a net torque in OpenSim. These are OpenSim's inverse dynamics
    at rest of the model with the solution's activations and no counter torque: the posture is
    then an equilibrium of the exported model.

    Parameters
    ----------
    solution : PaperSolution

    Returns
    -------
    numpy.ndarray, shape (n_cor,)
        Top to bottom, as ``model.geometry.cor_names``.
    """
    osim = require_opensim()
    built, _, _ = paper_osim(solution, np.zeros(len(solution.counter_torque)))
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

    Returns
    -------
    PaperSolution
    """
    osim = require_opensim()
    sto = controls_path(out)
    check_distinct({"--out": str(out), "controls": str(sto)}, inputs)
    solution = paper_solution(model, eccentricity, lordosis, pcsa, with_local_stiffness)
    built, labels, values = paper_osim(solution, opensim_counter_torque(solution))
    built.initSystem()  # refuse to write what OpenSim cannot build
    table = osim.TimeSeriesTable()
    table.setColumnLabels(labels)
    for time in (0.0, 1.0):
        table.appendRow(time, osim.RowVector(values))
    table.addTableMetaDataString("inDegrees", "no")
    # both written before either is renamed: a model that cannot be written leaves no controls behind
    with atomic_path(sto) as tmp_sto, atomic_path(out) as tmp_out:
        osim.STOFileAdapter.write(table, str(tmp_sto))
        built.printToXML(str(tmp_out))
    return solution
