"""(b) The least global PCSA that makes the paper's chain stable without local muscles (docs/chain.md).

The least total PCSA w.x with -K(x) >= mu I (:func:`~spinectl.optimise.coupled.sdp.least_control_sdp`)
and the per-segment rows of :func:`~spinectl.optimise.problem.inequalities`: the damping rows
D_k <= -damping_margin, the bounds on x and the stiffness rows S_k <= -mu, which the LMI implies
(they are its diagonal). So the coupled feasible set lies inside the per-segment one and the
coupled minimum is never below the paper's.
"""

from __future__ import annotations

import numpy as np

from ...model.params import Model
from ..problem import inequalities
from .data import CoupledData, CoupledOptimum, coupled_data, result
from .sdp import least_control_sdp


def min_global_pcsa_sdp(data: CoupledData) -> tuple[str, np.ndarray | None]:
    """(b) The least total global PCSA w.x with -K(x) >= mu I and the per-segment rows, k = 0.

    Parameters
    ----------
    data : CoupledData

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate', 'infeasible', 'infeasible_inaccurate' or 'solver_error'.
    x : numpy.ndarray or None
        Decision variables [cm^2], None unless optimal.
    """
    rows = inequalities(data.problem)
    return least_control_sdp(data.chain, data.problem.weights, data.margin, rows, data.problem.tolerance)


def min_global_pcsa(model: Model, eccentricity: float, lordosis: float) -> CoupledOptimum:
    """(b) The least global PCSA that makes the chain stable without local muscles.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    CoupledOptimum
        ``local_stiffness`` is zero; NaN and status 'infeasible' where no activation can.

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    data = coupled_data(model, eccentricity, lordosis)
    status, x = min_global_pcsa_sdp(data)
    k = None if x is None else np.zeros(data.chain.n_joints)
    return result(model, data, float(eccentricity), float(lordosis), status, x, k)
