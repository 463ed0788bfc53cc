"""The optimisation at every grid point: minimum PCSA, least counter torque, least-norm activation.

docs/model.md, "The optimisation", and docs/optimisation.md. One formulation
(:mod:`~spinectl.optimise.problem`) solved three ways: per point with cvxpy, the readable reference
(:mod:`~spinectl.optimise.reference`); for blocks of points by verified active sets, the fast path
(:mod:`~spinectl.optimise.active_set`); as one stacked Clarabel problem, its fallback
(:mod:`~spinectl.optimise.stacked`). The coupled chain's programmes are :mod:`~spinectl.optimise.coupled`.
The per-point API is re-exported here: ``optimise.solve_point(model, E, Lambda)``.
"""

from .problem import (
    DEFAULT_TOLERANCE,
    INFEASIBLE_STATUSES,
    OK_STATUSES,
    RANK_RTOL,
    SLAB_FACTOR,
    SOLVER_ERROR,
    STAGES,
    PointOptimum,
    ProblemData,
    ct_slab,
    inequalities,
    objective,
    point_data,
    polished,
    problem_data,
    solver_options,
    to_si,
    worst_status,
)
from .reference import (
    SOLVERS,
    CounterTorqueFront,
    counter_torque_front,
    least_norm_activation_qp,
    least_total_pcsa_lp,
    min_counter_torque_socp,
    min_norm_activation,
    min_pcsa_lp,
    optimum,
    point_optimum,
    solve_point,
    solve_with_fallback,
)

__all__ = [
    "DEFAULT_TOLERANCE",
    "INFEASIBLE_STATUSES",
    "OK_STATUSES",
    "RANK_RTOL",
    "SLAB_FACTOR",
    "SOLVERS",
    "SOLVER_ERROR",
    "STAGES",
    "CounterTorqueFront",
    "PointOptimum",
    "ProblemData",
    "counter_torque_front",
    "ct_slab",
    "inequalities",
    "least_norm_activation_qp",
    "least_total_pcsa_lp",
    "min_counter_torque_socp",
    "min_norm_activation",
    "min_pcsa_lp",
    "objective",
    "optimum",
    "point_data",
    "point_optimum",
    "polished",
    "problem_data",
    "solve_point",
    "solve_with_fallback",
    "solver_options",
    "to_si",
    "worst_status",
]
