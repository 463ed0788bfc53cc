"""An ``.osim`` model's coordinate couplers: switched off for the free chain, the rhythm among the chain's own.

OpenSim's ``CoordinateCouplerConstraint`` s read through its API (their functions' values and derivatives,
``Function.calcValue``/``calcDerivative``): off in the free chain, linearised over the chain's own
coordinates in the constrained one, and followed by the coordinates they slave when a posture is set
(docs/anatomy.md, "The rhythm"; MuJoCo's joint equalities are :func:`spinectl.anatomy.linearise.rhythm`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .export_osim import require_opensim
from .linearise import Rhythm


@dataclass(frozen=True)
class Coupler:
    """One ``CoordinateCouplerConstraint``: q_dependent = function(q_independent...).

    Attributes
    ----------
    name, dependent : str
        The constraint's and its dependent coordinate's names.
    independent : tuple of str
        Its independent coordinates.
    function : opensim.Function
        The model's own function of the independent coordinates.
    """

    name: str
    dependent: str
    independent: tuple
    function: object

    def derivatives(self, values: dict, engine) -> tuple:
        """The function's first and second derivatives in each independent coordinate at a posture.

        Parameters
        ----------
        values : dict
            Coordinate name -> value [rad] (others at their defaults).
        engine : OsimEngine

        Returns
        -------
        tuple
            (slopes, curvatures), numpy.ndarray of shape (len(independent),) [1] and [1/rad].
        """
        osim = require_opensim()
        x = osim.Vector(len(self.independent), 0.0)
        for k, name in enumerate(self.independent):
            x.set(k, float(values.get(name, engine.coordinate(name).getDefaultValue())))
        slopes, curvatures, mixed = [], [], []
        for k in range(len(self.independent)):
            slopes.append(self.function.calcDerivative(_orders(k), x))
            curvatures.append(self.function.calcDerivative(_orders(k, k), x))
            mixed += [self.function.calcDerivative(_orders(k, j), x) for j in range(k)]
        if any(abs(v) > 0 for v in mixed):  # the reduction carries each coordinate's own curvature only
            raise ModelError(f"{engine.name}: coupler {self.name} has mixed second derivatives, not supported")
        return np.array(slopes), np.array(curvatures)

    def describe(self, values: dict, engine) -> str:
        """One phrase: the dependent coordinate, what it follows and the slopes at the posture.

        Parameters
        ----------
        values : dict
            Coordinate name -> value [rad].
        engine : OsimEngine

        Returns
        -------
        str
        """
        slopes, _ = self.derivatives(values, engine)
        on = ", ".join(f"{n} slope {v:.4g}" for n, v in zip(self.independent, slopes, strict=True))
        return f"{self.name} ({self.dependent} on {on})"


def _orders(*orders) -> list:
    """OpenSim's derivative-order argument: the indices of the variables differentiated.

    A Python list, which OpenSim's bindings convert themselves: an ``opensim.StdVectorInt`` is refused as
    argument 2 of ``Function.calcDerivative`` once another SWIG-built package (cvxpy's solvers) was imported
    before opensim, so a model with couplers failed to load after any optimum.
    """
    return [int(k) for k in orders]


def read_couplers(osim, model) -> tuple:
    """The model's coordinate couplers, each switched off (before ``initSystem``: the free chain).

    Parameters
    ----------
    osim : module
        The ``opensim`` package.
    model : opensim.Model
        The model, before ``initSystem``.

    Returns
    -------
    tuple of Coupler
    """
    constraints = model.updConstraintSet()
    out = []
    for i in range(constraints.getSize()):
        coupler = osim.CoordinateCouplerConstraint.safeDownCast(constraints.get(i))
        if coupler is None:
            continue
        names = coupler.getIndependentCoordinateNames()
        independent = tuple(names.get(k) for k in range(names.getSize()))
        coupler.set_isEnforced(False)
        out.append(Coupler(coupler.getName(), coupler.getDependentCoordinateName(), independent, coupler.getFunction()))
    return tuple(out)


def coupler_rhythm(engine, chain, values: dict) -> tuple:
    """The couplers among the chain's own coordinates as a :class:`~spinectl.anatomy.linearise.Rhythm`.

    A coupler is the rhythm where its dependent coordinate and every independent one are the
    chain's; one that ties a coordinate off the chain to the chain (the Pose2Sim model's
    ``Abs_r3_con``: its ``Abdomen`` routing body on ``L5_S1_Flex_Ext``; a chain coordinate that
    follows one off it) is named in :attr:`~spinectl.anatomy.linearise.Rhythm.left_out` instead, as
    MuJoCo's joint equalities are (:func:`spinectl.anatomy.linearise.rhythm`). Only couplers whose
    independent coordinates no other coupler slaves are supported.

    Parameters
    ----------
    engine : OsimEngine
    chain : sequence of str
        The chain's coordinates.
    values : dict
        Coordinate name -> value [rad] of the posture.

    Returns
    -------
    tuple
        (Rhythm, the involved coordinates' names (the chain's), the couplers of the rhythm).
    """
    chain = list(chain)
    on_chain = [c for c in engine.couplers if c.dependent in chain and set(c.independent) <= set(chain)]
    left_out = [
        c.describe(values, engine)
        for c in engine.couplers
        if c not in on_chain and (c.dependent in chain or set(c.independent) & set(chain))
    ]
    slaved = {c.dependent: c for c in on_chain}
    if any(name in slaved for c in on_chain for name in c.independent):
        raise ModelError(f"{engine.name}: a coupler on a coordinate that another coupler slaves is not supported")
    independent = [n for n in chain if n not in slaved]
    used = [slaved[n] for n in chain if n in slaved]
    T = np.zeros((len(chain), len(independent)))
    C = np.zeros_like(T)
    for row, name in enumerate(chain):
        if name in slaved:
            slopes, curvatures = slaved[name].derivatives(values, engine)
            cols = [independent.index(n) for n in slaved[name].independent]
            T[row, cols], C[row, cols] = slopes, curvatures
        else:
            T[row, independent.index(name)] = 1.0
    rhy = Rhythm(tuple(chain.index(n) for n in independent), tuple(range(len(chain))), T, C, tuple(left_out))
    return rhy, chain, tuple(used)


def followed(engine, values: dict) -> dict:
    """``values`` with the dependent coordinate of every coupler whose independent ones it gives set by the coupler.

    Parameters
    ----------
    engine : spinectl.anatomy.opensim_engine.OsimEngine
        The model and its couplers.
    values : dict
        Coordinate name -> value [rad].

    Returns
    -------
    dict
        ``values`` and each coordinate a coupler slaves to them.
    """
    osim = require_opensim()
    out = dict(values)
    for c in engine.couplers:
        if c.dependent not in values and set(c.independent) <= set(values):
            x = osim.Vector(len(c.independent), 0.0)
            for k, name in enumerate(c.independent):
                x.set(k, float(values[name]))
            out[c.dependent] = float(c.function.calcValue(x))
    return out
