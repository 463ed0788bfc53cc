"""(a) The least local stiffness that makes the paper's chain stable at a global activation (docs/chain.md).

At the global PCSA given, the least sum(k) with diag(k) - K(x) >= mu I, k >= 0
(:func:`~spinectl.optimise.coupled.sdp.least_local_stiffness_at` on the paper's chain).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ...model.checks import expand_pcsa
from ...model.params import Model
from ...units import M2_PER_CM2
from .data import CoupledData, CoupledOptimum, coupled_data, result
from .sdp import least_local_stiffness_of


def least_local_stiffness_sdp(data: CoupledData, x) -> tuple[str, np.ndarray | None]:
    """(a) The least total local stiffness sum(k) with diag(k) - K(x) >= mu I, k >= 0.

    :func:`~spinectl.optimise.coupled.sdp.least_local_stiffness_of` the chain at x.

    Parameters
    ----------
    data : CoupledData
    x : array_like, shape (n_var,)
        Global activation as decision variables [cm^2].

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate' or 'solver_error'.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal.
    """
    return least_local_stiffness_of(data.chain, x, data.margin, data.problem.tolerance)


def least_local_stiffness(
    model: Model, eccentricity: float, lordosis: float, pcsa, *, given: bool = True, loads=()
) -> CoupledOptimum:
    """(a) The least local stiffness that makes the chain stable at a global activation.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like
        Global PCSA [m^2], one value per pair (both sides) or per muscle, whatever
        ``optimisation.activation`` says.
    given : bool
        False for a PCSA that spinectl computed (:func:`spinectl.model.checks.expand_pcsa`).
    loads : sequence of PointLoad, optional
        Ground-fixed loads at the point mass (:func:`~spinectl.optimise.coupled.data.coupled_data`); default none.

    Returns
    -------
    CoupledOptimum
        ``pcsa`` is the given activation, ``local_stiffness`` the least k.

    Raises
    ------
    ParameterError
        ``pcsa`` has the wrong length or a negative or non-finite entry; E or Lambda is
        outside the modelled range.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    independent = model.replace(optimisation=dataclasses.replace(model.optimisation, activation="independent"))
    data = coupled_data(independent, eccentricity, lordosis, loads)  # one variable per muscle: x = pcsa in cm^2
    x = expand_pcsa(model, pcsa, given=given) / M2_PER_CM2
    status, k = least_local_stiffness_sdp(data, x)
    return result(model, data, float(eccentricity), float(lordosis), status, x, k)
