"""Coupled stability of the lumbar chain: semidefinite programmes per point (docs/chain.md, "Coupled stability").

With all five CoRs free at once (:mod:`spinectl.model.chain`) the upright chain is statically
stable when diag(k) - K(x) >= mu I (Bergmark 1989), K(x) affine in the global PCSA x [cm^2] and
k >= 0 the local muscles' stiffness at each joint [N m/rad]. Three questions, each an SDP
(:mod:`~spinectl.optimise.coupled.sdp` holds the cores on any
:class:`~spinectl.model.linear_chain.LinearChain`):

(a) :func:`least_local_stiffness`: at a given global activation, the least sum of k;
(b) :func:`min_global_pcsa`: global muscles only (k = 0), the least total PCSA;
(c) :func:`joint_optimum`: the least total global PCSA + w * local PCSA, with the local
    PCSA k / kappa of :func:`spinectl.model.local_muscles.local_pcsa` and w ``local.cost_weight``;
    :func:`pareto_front`: every w at once, the least global PCSA for each bound on sum(k).

(b) and (c) keep the per-segment problem's rows (:func:`~spinectl.optimise.problem.inequalities`),
so the coupled feasible set lies inside the per-segment one and the coupled minimum is never below
the paper's. For grids, (a) and (c) also come stacked, one Clarabel problem per chunk
(:func:`least_local_stiffness_stacked`, :func:`joint_optimum_stacked`). A point where no activation
stabilises the chain is an answer: NaN values and the solver's status. One module per programme
(CONTRIBUTING.md's map), every public name re-exported here.

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
"""

from .at_activation import CoupledStability, coupled_stability_at, point_at_activation
from .data import CoupledData, CoupledOptimum, coupled_data
from .global_pcsa import min_global_pcsa, min_global_pcsa_sdp
from .joint import (
    ParetoFront,
    joint_optimum,
    joint_optimum_sdp,
    joint_rows,
    least_global_within_budget_sdp,
    pareto_front,
)
from .local import least_local_stiffness, least_local_stiffness_sdp
from .sdp import (
    least_control_sdp,
    least_cost_with_local_sdp,
    least_local_stiffness_at,
    least_local_stiffness_of,
    lmi,
    shifted,
    svec,
)
from .stacked_sdp import joint_optimum_stacked, least_cost_with_local_stacked, least_local_stiffness_stacked

__all__ = [
    "CoupledData",
    "CoupledOptimum",
    "CoupledStability",
    "ParetoFront",
    "coupled_data",
    "coupled_stability_at",
    "joint_optimum",
    "joint_optimum_sdp",
    "joint_optimum_stacked",
    "joint_rows",
    "least_control_sdp",
    "least_cost_with_local_sdp",
    "least_cost_with_local_stacked",
    "least_global_within_budget_sdp",
    "least_local_stiffness",
    "least_local_stiffness_at",
    "least_local_stiffness_of",
    "least_local_stiffness_sdp",
    "least_local_stiffness_stacked",
    "lmi",
    "min_global_pcsa",
    "min_global_pcsa_sdp",
    "pareto_front",
    "point_at_activation",
    "shifted",
    "svec",
]
