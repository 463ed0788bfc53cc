"""Coupled stability of the lumbar chain: semidefinite programmes per point (docs/chain.md).

The paper tests each centre of rotation alone. With all five free at once
(:mod:`spinectl.model.chain`), the upright chain is statically stable when its stiffness
matrix is negative definite (Bergmark 1989), here with the margin mu
(``optimisation.stability_margin``, the per-segment margin):

    diag(k) - K(x) >= mu I   (a linear matrix inequality, LMI),

K(x) = K_g - diag(K_pas) + sum_i x_i K_i affine in the global PCSA x [cm^2] (the decision
variables of :class:`~spinectl.optimise.problem.ProblemData`, paired or independent), k >= 0
the stiffness of local muscles at each joint [N m/rad]. Three questions, each an SDP
solved with cvxpy and Clarabel (PSD cone; SCS as the fallback):

(a) :func:`least_local_stiffness`: at a given global activation, the least sum of k;
(b) :func:`min_global_pcsa`: global muscles only (k = 0), the least total PCSA;
(c) :func:`joint_optimum`: the least total global PCSA + w * local PCSA, with the local
    PCSA k / kappa of :func:`spinectl.model.chain.local_pcsa` and w ``local.cost_weight``;
    :func:`pareto_front`: every w at once, the least global PCSA for each bound on sum(k).

(b) and (c) keep the per-segment problem's rows (:func:`~spinectl.optimise.problem.inequalities`):
the damping rows D_k <= -damping_margin and the bounds on x; (b) also its stiffness rows
S_k <= -mu, which the LMI implies (they are its diagonal). So the coupled feasible set lies
inside the per-segment one and the coupled minimum is never below the paper's. A point where
no activation stabilises the chain is an answer: NaN values and the solver's status.

For grids, (a) and (c) also come stacked: the points of a chunk share no variable, so one
Clarabel problem with a PSD cone per point solves them all (:func:`least_local_stiffness_stacked`,
:func:`joint_optimum_stacked`; the landscape's variables), the per-point SDPs the reference.

The solver's k is made exactly feasible by a uniform shift, k + max(0, mu - margin): adding
c to every k_j adds c I to the matrix. The reported margin is that of numpy's eigvalsh.

One module per programme; the SDP cores are written on any
:class:`~spinectl.model.linear_chain.LinearChain` (the paper's from
:func:`spinectl.model.chain.linear_chain`), the paper's rows and results beside them:

- :mod:`~spinectl.optimise.coupled.sdp`: the cores on a LinearChain (the LMI, (a), (b), (c));
- :mod:`~spinectl.optimise.coupled.data`: the paper's chain with its per-segment rows, and the result type;
- :mod:`~spinectl.optimise.coupled.local`: (a) at the paper's global activation;
- :mod:`~spinectl.optimise.coupled.global_pcsa`: (b);
- :mod:`~spinectl.optimise.coupled.joint`: (c) and the Pareto front;
- :mod:`~spinectl.optimise.coupled.stacked_sdp`: (a) and (c) for a chunk of points, one Clarabel problem;
- :mod:`~spinectl.optimise.coupled.at_activation`: the operating point at an activation, and the chain there
  (``spinectl stability --coupled``).

Every public name of these modules is also here: ``spinectl.optimise.coupled.joint_optimum``
as before the split.

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
