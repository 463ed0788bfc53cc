"""The paper's chain at one (E, Lambda) for its programmes, and their result (docs/chain.md, "Coupled stability").

:class:`CoupledData` joins the chain (:func:`spinectl.model.chain.linear_chain`, controls the
decision variables x [cm^2] of the per-segment problem) to the per-segment formulation
(:class:`~spinectl.optimise.problem.ProblemData`: its damping rows, bounds, counter torques) and the
local muscles' price; :class:`CoupledOptimum` is an answer of any of the paper's programmes in SI.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...model import chain, geometry
from ...model.checks import arithmetic_guard, checked_coefficients
from ...model.linear_chain import LinearChain
from ...model.loads import load_stiffness, loads_text, point_loads
from ...model.params import Model
from ...units import M2_PER_CM2
from ..problem import OK_STATUSES, ProblemData, problem_data, to_si


@dataclass(frozen=True)
class CoupledData:
    """The data of the coupled problems at one (E, Lambda), decision variables x in cm^2.

    Attributes
    ----------
    problem : ProblemData
        The per-segment formulation: weights, bounds, damping rows, x -> muscles, CT.
    coefficients : ChainCoefficients
        The chain's matrices per unit PCSA (SI), :func:`spinectl.model.chain.chain_coefficients`.
    chain : LinearChain
        The chain with the controls x (:func:`spinectl.model.chain.linear_chain`): K per unit x
        [N m/rad per cm^2], K at x = 0 (gravity and passive stiffness), M.
    margin : float
        mu [N m/rad] (``optimisation.stability_margin``).
    local_per_cm2 : float
        kappa, joint stiffness per cm^2 of local muscle [N m/rad per cm^2].
    cost_weight : float
        w, the cost of a cm^2 of local muscle in cm^2 of global muscle [1] (``local.cost_weight``).
    """

    problem: ProblemData
    coefficients: chain.ChainCoefficients
    chain: LinearChain
    margin: float
    local_per_cm2: float
    cost_weight: float

    @property
    def stiffness(self) -> np.ndarray:
        """K per unit x, shape (n_cor, n_cor, n_var) [N m/rad per cm^2]: the chain's ``stiffness_per_control``."""
        return self.chain.stiffness_per_control

    @property
    def stiffness_offset(self) -> np.ndarray:
        """K at x = 0, shape (n_cor, n_cor): gravity and passive stiffness [N m/rad]."""
        return self.chain.stiffness_offset

    def matrix(self, x, local_stiffness=0.0) -> np.ndarray:
        """K(x) - diag(k) [N m/rad] for decision variables ``x`` [cm^2] (:meth:`LinearChain.stiffness`).

        Parameters
        ----------
        x : array_like, shape (n_var,)
            Decision variables [cm^2].
        local_stiffness : array_like, shape (n_cor,)
            k [N m/rad]; 0: none.

        Returns
        -------
        numpy.ndarray, shape (n_cor, n_cor)
            [N m/rad].
        """
        return self.chain.stiffness(x, local_stiffness)


def coupled_data(model: Model, eccentricity: float, lordosis: float, loads=()) -> CoupledData:
    """Assemble :class:`CoupledData` at one configuration.

    Parameters
    ----------
    model : Model
        ``optimisation`` (activation, margins, bounds, tolerance) and ``local``.
    eccentricity, lordosis : float
        E and Lambda [m], inside the modelled range.
    loads : sequence of PointLoad, optional
        Loads held at the point mass, fixed in the ground (:mod:`spinectl.model.loads`): their stiffness
        K_load joins the chain's K_0, so the programmes stabilise the loaded chain; default none.

    Returns
    -------
    CoupledData

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range (:func:`~spinectl.model.checks.validate_position`).
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.
    """
    e, lam = float(eccentricity), float(lordosis)
    data = problem_data(model, checked_coefficients(model, e, lam))
    with arithmetic_guard(e, lam):
        coeffs = chain.chain_coefficients(model, e, lam)
        linear = chain.linear_chain(model, e, lam, coeffs)
        if loads:
            linear = loaded_chain(model, linear, e, lam, loads)
    return CoupledData(
        problem=data,
        coefficients=coeffs,
        chain=linear,
        margin=model.optimisation.stability_margin,
        local_per_cm2=chain.local_stiffness_per_pcsa(model) * M2_PER_CM2,
        cost_weight=model.local.cost_weight,
    )


def loaded_chain(model: Model, linear: LinearChain, e: float, lam: float, loads) -> LinearChain:
    """The chain with ground-fixed loads' stiffness in its K_0 (the programmes' LMI needs a symmetric K).

    Parameters
    ----------
    model : Model
    linear : LinearChain
        :func:`spinectl.model.chain.linear_chain` at (E, Lambda).
    e, lam : float
        E and Lambda [m].
    loads : sequence of PointLoad or of (F_x, F_y) [N]

    Returns
    -------
    LinearChain
        K_0 + K_load (:func:`spinectl.model.loads.load_stiffness`), the loads named in its source.

    Raises
    ------
    ParameterError
        A load fixed in the body: a follower force's K is not symmetric, which no static margin reads.
    """
    loads = point_loads(loads)
    if any(load.frame != "ground" for load in loads):
        raise ParameterError(
            "loads",
            "must be fixed in the ground for the chain's static analyses (a follower force's K is not symmetric)",
        )
    k_load = load_stiffness(model, geometry.cor_positions(e, lam, model.geometry), loads)
    return dataclasses.replace(
        linear,
        stiffness_offset=linear.stiffness_offset + k_load,
        source=linear.source + loads_text(loads),
    )


@dataclass(frozen=True)
class CoupledOptimum:
    """Result of a coupled problem at one (E, Lambda), in SI units; NaN unless optimal.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    status : str
        The solver's status: 'optimal' (or 'optimal_inaccurate'), 'infeasible' (no activation
        within the bounds stabilises the chain) or 'solver_error'.
    pcsa : numpy.ndarray, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    local_stiffness : numpy.ndarray, shape (n_cor,)
        k_j of the local muscles at each joint [N m/rad].
    local_pcsa : numpy.ndarray, shape (n_cor,)
        The least local-muscle PCSA giving k_j [m^2] (:func:`spinectl.model.chain.local_pcsa`).
    counter_torque : numpy.ndarray, shape (n_cor,)
        CT_k at the global activation [N m], as in the per-segment model.
    margin : float
        Smallest eigenvalue of -(K - diag(k)) [N m/rad]; >= stability_margin up to the solver tolerance.
    """

    eccentricity: float
    lordosis: float
    status: str
    pcsa: np.ndarray
    local_stiffness: np.ndarray
    local_pcsa: np.ndarray
    counter_torque: np.ndarray
    margin: float

    @property
    def total_pcsa(self) -> float:
        """Total global PCSA [m^2]."""
        return float(np.sum(self.pcsa))

    @property
    def total_local_pcsa(self) -> float:
        """Total local PCSA over the joints [m^2]."""
        return float(np.sum(self.local_pcsa))

    @property
    def ok(self) -> bool:
        """True if the optimum was found."""
        return self.status in OK_STATUSES


def result(model: Model, data: CoupledData, e: float, lam: float, status: str, x, k) -> CoupledOptimum:
    """A :class:`CoupledOptimum` from decision variables x [cm^2] and k [N m/rad] (None: NaN).

    Parameters
    ----------
    model : Model
        The model (its local muscles give the local PCSA).
    data : CoupledData
        The problem at (E, Lambda).
    e, lam : float
        E and Lambda [m].
    status : str
        The solver's status.
    x : numpy.ndarray or None
        Global decision variables [cm^2].
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad].

    Returns
    -------
    CoupledOptimum
    """
    x = np.full(data.problem.weights.size, np.nan) if x is None else x
    k = np.full(data.chain.n_joints, np.nan) if k is None else k
    _, pcsa, counter_torque = to_si(data.problem, np.nan, x)
    margin = np.nan if np.isnan(x).any() or np.isnan(k).any() else float(chain.coupled_margin(data.matrix(x, k)))
    return CoupledOptimum(e, lam, status, pcsa, k, chain.local_pcsa(k, model), counter_torque, margin)
