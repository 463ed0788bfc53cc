"""The optimisation at every grid point: minimum PCSA, least counter torque, least-norm activation.

docs/model.md, "The optimisation", and docs/optimisation.md. One formulation
(:mod:`~spinectl.optimise.problem`) is solved three ways: per point with cvxpy, the
readable reference (:mod:`~spinectl.optimise.reference`); for blocks of points by
guessed and verified active sets in batched numpy, the fast path
(:mod:`~spinectl.optimise.active_set`); and for blocks of points as one stacked
Clarabel problem, the fast path's fallback (:mod:`~spinectl.optimise.stacked`). The
solvers' answers are polished to the exact optimum (:mod:`~spinectl.optimise.polish`);
the fast path's are exact KKT points already. The reference imports neither fast path; the
stability of one point at its minimum stabilising PCSA, solved by the fast path, sits above both
(:mod:`~spinectl.optimise.stabilising`). The coupled chain's semidefinite programmes, on any
:class:`~spinectl.model.linear_chain.LinearChain`, are :mod:`~spinectl.optimise.coupled`.

The per-point API is re-exported here: ``optimise.solve_point(model, E, Lambda)``.

Symbols and units: docs/glossary.md.
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
