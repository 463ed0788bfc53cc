"""Helpers shared by tests/anatomy/test_osim_geometry.py and benchmarks/bench_osim_anatomy.py (no tests here).

:func:`present_geometry` is the path spinectl took before spinectl.anatomy.osim_geometry: every
muscle's ``computeMomentArm`` (OpenSim's MomentArmSolver) about every coordinate, their central
differences over q with spinectl.anatomy.linearise.STEP for the Hessians, OpenSim's inverse
dynamics with the actuators off for the passive torques. :func:`rigid_millard_copy` writes a
model's copy whose muscles spinectl reads (rigid-tendon Millard muscles on the same paths).
"""

from __future__ import annotations

import numpy as np
import opensim as osim

from spinectl.anatomy.linearise import STEP
from spinectl.anatomy.opensim_engine import _mobility_order


def present_geometry(engine, names, values: dict) -> tuple:
    """The previous path's arms (-computeMomentArm), Hessians, passive torques and their derivatives.

    Parameters
    ----------
    engine : spinectl.anatomy.opensim_engine.OsimEngine
    names : sequence of str
        The coordinates.
    values : dict
        Coordinate name -> value [rad] of the posture.

    Returns
    -------
    tuple
        (arms (m, s) [m/rad], Hessians (m, s, s) [m/rad^2], passive (s,) [N m], its derivatives (s, s) [N m/rad]).
    """
    order = _mobility_order(engine)

    def arms_and_passive(vals):
        engine.set_posture(vals)
        muscles, state = engine.model.getMuscles(), engine.state
        coordinates = [engine.coordinate(c) for c in names]
        each = [muscles.get(i) for i in range(muscles.getSize())]
        arms = np.array([[-muscle.computeMomentArm(state, c) for c in coordinates] for muscle in each])
        forces = engine.model.getForceSet()
        for i in range(forces.getSize()):
            forces.get(i).setAppliesForce(state, osim.Actuator.safeDownCast(forces.get(i)) is None)
        engine.model.realizeDynamics(state)
        needed = osim.InverseDynamicsSolver(engine.model).solve(state, osim.Vector(state.getNU(), 0.0))
        for i in range(forces.getSize()):
            forces.get(i).setAppliesForce(state, True)
        return arms, -np.array([needed.get(order[c]) for c in names])

    arms, passive = arms_and_passive(values)
    hessian, dpassive = np.zeros((arms.shape[0], len(names), len(names))), np.zeros((len(names), len(names)))
    for k, name in enumerate(names):
        start = values.get(name, engine.coordinate(name).getDefaultValue())
        up = arms_and_passive({**values, name: start + STEP})
        down = arms_and_passive({**values, name: start - STEP})
        hessian[:, :, k] = (up[0] - down[0]) / (2 * STEP)
        dpassive[:, k] = (up[1] - down[1]) / (2 * STEP)
    engine.set_posture(values)
    return arms, 0.5 * (hessian + hessian.transpose(0, 2, 1)), passive, dpassive


def rigid_millard_copy(source, target) -> None:
    """Write ``source``'s model to ``target`` with every muscle a rigid-tendon Millard muscle on the same path.

    F_max, optimal fibre length and tendon slack length kept, pennation 0.

    Parameters
    ----------
    source, target : pathlib.Path
    """
    model = osim.Model(str(source))
    forces = model.updForceSet()
    for name in [model.getMuscles().get(i).getName() for i in range(model.getMuscles().getSize())]:
        old = osim.Muscle.safeDownCast(forces.get(name))
        new = osim.Millard2012EquilibriumMuscle()
        new.setName(name)
        new.setMaxIsometricForce(old.getMaxIsometricForce())
        new.setOptimalFiberLength(old.getOptimalFiberLength())
        new.setTendonSlackLength(old.getTendonSlackLength())
        new.setPennationAngleAtOptimalFiberLength(0.0)
        new.set_ignore_tendon_compliance(True)
        new.set_path(old.get_path())
        forces.remove(forces.getIndex(name))
        forces.append(new)
    model.finalizeConnections()
    model.printToXML(str(target))
