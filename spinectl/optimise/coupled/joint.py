"""(c) The joint optimum of global and local muscle, and the Pareto front between them (docs/chain.md).

The least total global PCSA + w x local PCSA, the local PCSA k / kappa of
:func:`spinectl.model.chain.local_pcsa` and w ``local.cost_weight``
(:func:`~spinectl.optimise.coupled.sdp.least_cost_with_local_sdp`); the per-segment damping rows
and bounds on x hold, the per-segment stiffness rows do not (local stiffness enters each joint:
the LMI's diagonal is S_k - k_k <= -mu). :func:`pareto_front`: every w at once, the least global
PCSA for each bound on sum(k).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...model.params import Model
from ...model.source import header, provenance
from ...units import m2_to_cm2
from ..problem import inequalities
from .data import CoupledData, CoupledOptimum, coupled_data, result
from .local import least_local_stiffness_sdp
from .sdp import least_cost_with_local_sdp


def joint_rows(data: CoupledData) -> tuple[np.ndarray, np.ndarray]:
    """The per-segment rows of (c): :func:`~spinectl.optimise.problem.inequalities` without the stiffness rows.

    Parameters
    ----------
    data : CoupledData

    Returns
    -------
    lhs, rhs : numpy.ndarray
        G [1 per cm^2] and h: the damping rows and the bounds on x.
    """
    lhs, rhs = inequalities(data.problem)
    n_cor = data.chain.n_joints
    return lhs[n_cor:], rhs[n_cor:]  # drop the per-segment stiffness rows (the first n_cor)


def joint_optimum_sdp(data: CoupledData) -> tuple[str, np.ndarray | None, np.ndarray | None]:
    """(c) The least w.x + cost_weight * sum(k) / kappa with diag(k) - K(x) >= mu I, k >= 0.

    The per-segment damping rows and bounds on x hold (:func:`joint_rows`).

    Parameters
    ----------
    data : CoupledData

    Returns
    -------
    status : str
        As for :func:`~spinectl.optimise.coupled.global_pcsa.min_global_pcsa_sdp`.
    x : numpy.ndarray or None
        Global decision variables [cm^2], None unless optimal.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal.
    """
    return least_cost_with_local_sdp(
        data.chain, data.problem.weights, data.margin, joint_rows(data), data.problem.tolerance,
        local_weight=data.cost_weight, local_per_unit=data.local_per_cm2,
    )  # fmt: skip


def least_global_within_budget_sdp(data: CoupledData, budget: float):
    """The least total global PCSA w.x with at most ``budget`` of local stiffness: sum(k) <= budget.

    (c)'s constraints with the local total bounded instead of priced: the epsilon-constraint
    form of the trade-off between the two totals (:func:`pareto_front`). ``budget = inf``
    leaves k free; ``budget = 0`` is (b), global muscles only (the LMI's diagonal then
    implies the per-segment stiffness rows).

    Parameters
    ----------
    data : CoupledData
    budget : float
        The largest sum(k) [N m/rad]; inf: unbounded.

    Returns
    -------
    status : str
        As for :func:`~spinectl.optimise.coupled.global_pcsa.min_global_pcsa_sdp`.
    x : numpy.ndarray or None
        Global decision variables [cm^2], None unless optimal.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal.
    """
    return least_cost_with_local_sdp(
        data.chain, data.problem.weights, data.margin, joint_rows(data), data.problem.tolerance, local_budget=budget
    )


def joint_optimum(model: Model, eccentricity: float, lordosis: float) -> CoupledOptimum:
    """(c) The least total global PCSA plus ``local.cost_weight`` times the local PCSA.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    CoupledOptimum

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
    status, x, k = joint_optimum_sdp(data)
    return result(model, data, float(eccentricity), float(lordosis), status, x, k)


@dataclass(frozen=True)
class ParetoFront:
    """The trade-off between the global PCSA total and the local stiffness total at one (E, Lambda).

    Point i is the least global PCSA with at most ``budgets[i]`` of local stiffness
    (:func:`least_global_within_budget_sdp`); the budgets run from 0 (global muscles only,
    problem (b)) to the least local stiffness at the global minimum with k free (the other end).

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    budgets : numpy.ndarray, shape (m,)
        Largest sum of k allowed [N m/rad], increasing.
    points : tuple of CoupledOptimum
        The optimum at each budget; NaN and the status where infeasible (e.g. at budget 0
        when no global activation alone stabilises the chain).
    """

    eccentricity: float
    lordosis: float
    budgets: np.ndarray
    points: tuple[CoupledOptimum, ...]

    @property
    def global_total(self) -> np.ndarray:
        """Global PCSA total of each point [m^2], shape (m,); non-increasing along the front."""
        return np.array([p.total_pcsa for p in self.points])

    @property
    def local_total(self) -> np.ndarray:
        """Local stiffness total sum(k) of each point [N m/rad], shape (m,)."""
        return np.array([float(np.sum(p.local_stiffness)) for p in self.points])

    @property
    def local_pcsa_total(self) -> np.ndarray:
        """Local-muscle PCSA total of each point [m^2], shape (m,) (:func:`spinectl.model.chain.local_pcsa`)."""
        return np.array([p.total_local_pcsa for p in self.points])

    def to_dict(self, model: Model) -> dict:
        """The front as a JSON-ready dict.

        Parameters
        ----------
        model : Model
            The model the front was computed with.

        Returns
        -------
        dict
            The model's :func:`~spinectl.model.source.provenance`, ``E_m``, ``Lambda_m`` and ``pareto``:
            ``local_budget_Nm_per_rad``, ``global_pcsa_total_cm2``, ``local_stiffness_total_Nm_per_rad``,
            ``local_pcsa_total_cm2``, ``status`` (m each), ``pcsa_cm2`` (m x n_muscles) and
            ``local_stiffness_Nm_per_rad`` (m x n_cor); NaN where a point is infeasible.
        """
        return provenance(model) | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "pareto": {
                "local_budget_Nm_per_rad": self.budgets.tolist(),
                "global_pcsa_total_cm2": m2_to_cm2(self.global_total).tolist(),
                "local_stiffness_total_Nm_per_rad": self.local_total.tolist(),
                "local_pcsa_total_cm2": m2_to_cm2(self.local_pcsa_total).tolist(),
                "status": [p.status for p in self.points],
                "pcsa_cm2": [m2_to_cm2(p.pcsa).tolist() for p in self.points],
                "local_stiffness_Nm_per_rad": [p.local_stiffness.tolist() for p in self.points],
            },
        }

    def table(self, model: Model) -> str:
        """The front as readable text, one row per point.

        Parameters
        ----------
        model : Model
            The model the front was computed with.

        Returns
        -------
        str
            No final newline.
        """
        lines = [
            header(model),
            f"Pareto front at E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            f"{'budget [N m/rad]':>17}{'global [cm^2]':>15}{'local k [N m/rad]':>19}{'local [cm^2]':>14}  status",
        ]
        for budget, g, k, a, p in zip(
            self.budgets, m2_to_cm2(self.global_total), self.local_total, m2_to_cm2(self.local_pcsa_total), self.points,
            strict=True,
        ):  # fmt: skip
            lines.append(f"{budget:17.2f}{g:15.3f}{k:19.2f}{a:14.3f}  {p.status}")
        return "\n".join(lines)


def pareto_front(model: Model, eccentricity: float, lordosis: float, points: int = 11) -> ParetoFront:
    """The Pareto front between the global PCSA total and the local stiffness total (epsilon-constraint).

    The far end minimises the global PCSA with k free and takes the least local stiffness
    at that activation (problem (a)), sum k = k_max; the front is then the least global
    PCSA under sum(k) <= b for ``points`` budgets b evenly from 0 to k_max
    (:func:`least_global_within_budget_sdp`). Every problem is convex, so every Pareto
    point is reached, including those the weighted sum of :func:`joint_optimum` skips
    where the front is straight; the joint optimum at any ``local.cost_weight`` lies on it.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    points : int, optional
        Budgets on the front, >= 2.

    Returns
    -------
    ParetoFront

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range, or ``points`` < 2.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Miettinen K (1999). Nonlinear Multiobjective Optimization. Kluwer, Boston, ch. 3.2 (the
    epsilon-constraint method). doi:10.1007/978-1-4615-5563-6.
    """
    if int(points) < 2:
        raise ParameterError("points", f"must be an integer >= 2 (got {points!r})")
    e, lam = float(eccentricity), float(lordosis)
    data = coupled_data(model, e, lam)
    status, x, k = least_global_within_budget_sdp(data, np.inf)
    if x is not None:
        status, k = least_local_stiffness_sdp(data, x)
    if k is None:  # no activation within the bounds, whatever the local muscles: nothing to trade
        empty = result(model, data, e, lam, status, None, None)
        return ParetoFront(e, lam, np.full(int(points), np.nan), (empty,) * int(points))
    budgets = np.linspace(0.0, float(np.sum(k)), int(points))
    far = result(model, data, e, lam, status, x, k)
    inner = [result(model, data, e, lam, *least_global_within_budget_sdp(data, b)) for b in budgets[:-1]]
    return ParetoFront(e, lam, budgets, tuple(inner) + (far,))
