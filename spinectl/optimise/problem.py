"""The formulation that the per-point reference and the stacked fast path share.

The decision variables x [cm^2], the self-stable set F = {S x <= b, D x <= -damping_margin,
0 <= x <= pcsa_max} and the counter torques CT(x) = -(T x + g) (:class:`ProblemData`, docs/model.md,
"The optimisation"); the inequalities and objectives of the three stages; the polishing of a
solver's answer to the exact optimum (:mod:`spinectl.optimise.polish`); statuses and the result
of one point. Every solver of :mod:`spinectl.optimise` builds on these, so both paths solve
the same problems.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model import geometry
from ..model.checks import checked_coefficients
from ..model.mechanics import SegmentCoefficients
from ..model.params import Model
from ..units import M2_PER_CM2
from . import polish

OK_STATUSES = ("optimal", "optimal_inaccurate")
"""cvxpy's ``OPTIMAL`` and ``OPTIMAL_INACCURATE``, spelt out: importing cvxpy takes about 2 s, which the
fast path does not need."""


INFEASIBLE_STATUSES = ("infeasible", "infeasible_inaccurate")
"""cvxpy's ``INFEASIBLE`` and ``INFEASIBLE_INACCURATE``, spelt out (as :data:`OK_STATUSES`)."""


SOLVER_ERROR = "solver_error"


DEFAULT_TOLERANCE = 1e-8
"""Clarabel's default feasibility and gap tolerance, used where none is given."""


SLAB_FACTOR = 10.0
"""Half width of the slab that fixes CT in stage 3, in solver tolerances.

It must exceed the feasibility error of the stage-2 optimum (about one
tolerance) so that the slab meets the feasible set in its interior, and be
small enough that CT moves by far less than the 1e-6 agreement (docs/optimisation.md).
"""


RANK_RTOL = float(np.sqrt(np.finfo(float).eps))
"""Singular values of T below this fraction of a single muscle's torque are rounding, not torque.

A direction that changes CT by less than 1.5e-8 of one muscle's torque is below
every tolerance of the comparison; keeping it would pin x along a direction
that T does not really act on (e.g. at position A, where the pairs cancel).
"""


@dataclass(frozen=True)
class ProblemData:
    """The linear data of the optimisation, decision variables x in cm^2.

    Leading dimensions (if any) are those of the grid of (E, Lambda).

    Attributes
    ----------
    stability : numpy.ndarray, shape (..., 2 n_cor, n_var)
        The self-stability constraints ``stability @ x <= stability_bound``: rows
        0..n_cor-1 are dM_k/dalpha per unit x [N m/rad per cm^2], rows n_cor..
        dM_k/domega per unit x [N m s/rad per cm^2]. Both eigenvalues of eq. 1
        have negative real part iff S_k < 0 and D_k < 0.
    stability_bound : numpy.ndarray, shape (..., 2 n_cor)
        Right-hand side: -max(stability_margin, relative_margin * gravity stiffness)
        - (gravity - passive) stiffness [N m/rad]
        for the stiffness rows, -damping_margin [N m s/rad] for the damping rows.
    torque : numpy.ndarray, shape (..., n_cor, n_var)
        Muscle torque per unit x [N m per cm^2].
    gravity_torque : numpy.ndarray, shape (..., n_cor)
        M_ext [N m]; CT = -(torque @ x + gravity_torque).
    weights : numpy.ndarray, shape (n_var,)
        Total PCSA [cm^2] per unit x: 2 for a pair (both sides), 1 for a muscle.
    to_muscles : numpy.ndarray, shape (n_muscles, n_var)
        Per-muscle PCSA [cm^2] = to_muscles @ x.
    upper : float
        Bound on every x [cm^2] (inf = none).
    tolerance : float or None
        Solver tolerance [1] (``optimisation.solver_tolerance``); None = solver defaults.
    torque_scale : numpy.ndarray or None, shape (...)
        Largest torque of a single muscle per cm^2 [N m per cm^2]: the size of the
        terms whose sums (pairs, CoR offsets) make up ``torque``, so the scale of
        its rounding error (:func:`ct_slab`). None = the largest singular value of ``torque``.
    """

    stability: np.ndarray
    stability_bound: np.ndarray
    torque: np.ndarray
    gravity_torque: np.ndarray
    weights: np.ndarray
    to_muscles: np.ndarray
    upper: float
    tolerance: float | None = None
    torque_scale: np.ndarray | None = None

    def point(self, index) -> ProblemData:
        """The data of one grid point, or of a subset of points.

        Parameters
        ----------
        index : int, slice or array of int
            Index into the leading dimensions.

        Returns
        -------
        ProblemData
            The same problem with the grid-point arrays indexed; ``weights``,
            ``to_muscles``, ``upper`` and ``tolerance`` unchanged.
        """
        return replace(
            self,
            stability=self.stability[index],
            stability_bound=self.stability_bound[index],
            torque=self.torque[index],
            gravity_torque=self.gravity_torque[index],
            torque_scale=None if self.torque_scale is None else self.torque_scale[index],
        )

    def counter_torque(self, x):
        """CT [N m] for decision variables ``x`` (paper, Methods: CT makes the upright posture an equilibrium).

        Parameters
        ----------
        x : array_like, shape (..., n_var)
            Decision variables [cm^2].

        Returns
        -------
        numpy.ndarray, shape (..., n_cor)
            CT_k [N m].
        """
        return -(np.einsum("...kn,...n->...k", self.torque, np.asarray(x, float)) + self.gravity_torque)


def problem_data(model: Model, coeffs: SegmentCoefficients) -> ProblemData:
    """Assemble :class:`ProblemData` from the segment coefficients (any leading shape).

    ``optimisation.activation = "paired"`` gives one variable per pair (both
    muscles equal, co-contraction); ``"independent"`` one per muscle.

    Parameters
    ----------
    model : Model
        Supplies the ``optimisation`` settings.
    coeffs : SegmentCoefficients
        Per-unit-PCSA mechanics from :func:`~spinectl.model.mechanics.segment_coefficients`.

    Returns
    -------
    ProblemData
        The constraints and torques per cm^2 of each decision variable, with the
        leading shape of ``coeffs``.
    """
    n_muscles = coeffs.stiffness_per_pcsa.shape[-1]
    if model.optimisation.activation == "paired":
        to_muscles = geometry.pairing_matrix(n_muscles // 2)
    else:
        to_muscles = np.eye(n_muscles)
    per_var = to_muscles * M2_PER_CM2  # m^2 of each muscle per cm^2 of x
    opt = model.optimisation
    margin = np.maximum(opt.stability_margin, opt.relative_margin * coeffs.gravity_stiffness)  # the larger binds
    stiffness_bound = -margin - (coeffs.gravity_stiffness - coeffs.passive_stiffness)
    damping_bound = np.full_like(stiffness_bound, -opt.damping_margin)
    return ProblemData(
        stability=np.concatenate([coeffs.stiffness_per_pcsa @ per_var, coeffs.damping_per_pcsa @ per_var], axis=-2),
        stability_bound=np.concatenate([stiffness_bound, damping_bound], axis=-1),
        torque=coeffs.torque_per_pcsa @ per_var,
        gravity_torque=coeffs.gravity_torque,
        weights=to_muscles.sum(axis=0),
        to_muscles=to_muscles,
        upper=model.optimisation.pcsa_max / M2_PER_CM2,
        tolerance=model.optimisation.solver_tolerance,
        torque_scale=np.abs(coeffs.torque_per_pcsa).max(axis=(-2, -1)) * M2_PER_CM2,
    )


def point_data(model: Model, eccentricity: float, lordosis: float) -> ProblemData:
    """:class:`ProblemData` at one configuration, the position checked first.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    ProblemData
        Without leading dimensions.

    Raises
    ------
    ParameterError
        E or Lambda outside the modelled range.
    ModelError
        The model cannot be evaluated there (see :func:`~spinectl.model.checks.validate_position`).
    """
    return problem_data(model, checked_coefficients(model, float(eccentricity), float(lordosis)))


def ct_slab(torque, x_ct, tolerance: float | None, scale=None):
    """Linear constraints abs(rows @ x - centre) <= half_width that fix CT(x) = CT(x_ct).

    Only the row space of T constrains CT (:data:`RANK_RTOL`), so rank-deficient
    T (always, see the module docstring) gives no redundant constraints; where
    T = 0 (position A, paired) nothing is fixed. The slab has a half width of
    :data:`SLAB_FACTOR` times the solver tolerance (relative to the size of
    ``x_ct``) rather than zero, so that the feasible set keeps an interior even
    where the stage-2 optimum is a single vertex. Vectorised over leading dimensions.

    Parameters
    ----------
    torque : array_like, shape (..., n_cor, n_var)
        T [N m per cm^2].
    x_ct : array_like, shape (..., n_var)
        A stage-2 optimum [cm^2].
    tolerance : float or None
        Solver tolerance [1]; None means the solver default, taken as 1e-8.
    scale : array_like, shape (...), optional
        :attr:`ProblemData.torque_scale` [N m per cm^2]; default the largest singular value.

    Returns
    -------
    rows : numpy.ndarray, shape (..., r, n_var)
        Orthonormal right singular vectors of T, r = min(n_cor, n_var) [1].
    keep : numpy.ndarray of bool, shape (..., r)
        Rows whose singular value exceeds :data:`RANK_RTOL` times ``scale``.
    centre : numpy.ndarray, shape (..., r)
        rows @ x_ct [cm^2].
    half_width : numpy.ndarray, shape (...)
        [cm^2].
    """
    x_ct = np.asarray(x_ct, float)
    _, sing, rows = np.linalg.svd(np.asarray(torque, float), full_matrices=False)
    scale = sing[..., 0] if scale is None else np.asarray(scale, float)
    keep = sing > RANK_RTOL * scale[..., None]
    centre = np.einsum("...rn,...n->...r", rows, x_ct)
    tol = DEFAULT_TOLERANCE if tolerance is None else tolerance
    half_width = SLAB_FACTOR * tol * (1.0 + np.max(np.abs(x_ct), axis=-1))
    return rows, keep, centre, half_width


def solver_options(solver: str, tolerance: float | None) -> dict:
    """Keyword options for a cvxpy solver giving a feasibility and gap tolerance.

    Parameters
    ----------
    solver : str
        cvxpy's name of the solver, e.g. 'CLARABEL'.
    tolerance : float or None
        [1]; None: the solver's defaults.

    Returns
    -------
    dict
        Options to pass to ``cvxpy.Problem.solve``: absolute and relative gap and
        feasibility tolerances for 'CLARABEL' and 'SCS'; empty for other solvers or
        without a tolerance.
    """
    if tolerance is None:
        return {}
    if solver == "CLARABEL":
        return {"tol_gap_abs": tolerance, "tol_gap_rel": tolerance, "tol_feas": tolerance}
    if solver == "SCS":
        return {"eps_abs": tolerance, "eps_rel": tolerance}
    return {}


def inequalities(data: ProblemData, total_max=np.inf, x_ct=None) -> tuple[np.ndarray, np.ndarray]:
    """The constraints of a stage as G x <= h; vectorised over leading dimensions.

    Rows, in order: the stability rows (S_k <= -stability_margin and
    D_k <= -damping_margin at every CoR, :class:`ProblemData`), -x <= 0,
    x <= upper (if finite), w.x <= total_max (the band, if finite; finite for
    all points or for none), and, if ``x_ct`` is given, the two sides of the
    slab of :func:`ct_slab` that fixes CT (a row T does not act on reads
    0 <= half width).

    Parameters
    ----------
    data : ProblemData
    total_max : float or array_like, shape (...)
        Budget on the total PCSA w.x [cm^2]; inf: no band.
    x_ct : array_like, shape (..., n_var), optional
        A stage-2 optimum whose counter torques to keep [cm^2].

    Returns
    -------
    lhs : numpy.ndarray, shape (..., r, n_var)
        G: the stability rows equilibrated (:func:`equilibrated`: each row and its bound divided
        by the row's largest magnitude, so [1 per cm^2]); the bound rows [1].
    rhs : numpy.ndarray, shape (..., r)
        h: the equilibrated stability bounds [1], the bounds on x [cm^2].
    """
    lead, n = data.stability.shape[:-2], data.weights.size
    eye = np.broadcast_to(np.eye(n), lead + (n, n))
    stability, bound = equilibrated(data.stability, data.stability_bound)
    lhs, rhs = [stability, -eye], [bound, np.zeros(lead + (n,))]
    if np.isfinite(data.upper):
        lhs.append(eye)
        rhs.append(np.full(lead + (n,), data.upper))
    total_max = np.broadcast_to(np.asarray(total_max, float), lead)
    if np.all(np.isfinite(total_max)):
        lhs.append(np.broadcast_to(data.weights, lead + (1, n)))
        rhs.append(total_max[..., None])
    if x_ct is not None:
        rows, keep, centre, half_width = ct_slab(data.torque, x_ct, data.tolerance, data.torque_scale)
        rows, centre = rows * keep[..., None], centre * keep
        lhs += [rows, -rows]
        rhs += [centre + half_width[..., None], half_width[..., None] - centre]
    return np.concatenate(lhs, axis=-2), np.concatenate(rhs, axis=-1)


def equilibrated(rows, bound):
    """The stability rows and their bounds divided by their largest magnitude: the same set, scaled to 1.

    A row S_k x <= -margin - (gravity - passive stiffness) has coefficients of a few
    N m/rad per cm^2 but a bound of the size of K; with an absurd K (1e12 N m/rad) the
    solver's tolerances, relative to the data, no longer resolve the coefficients and it
    reports 'optimal_inaccurate' answers far off the optimum, or 'infeasible'. Dividing
    each row and its bound by max(max_j abs(G_ij), abs(h_i)) keeps the feasible set and
    gives every row a largest entry of 1 (row equilibration, e.g. Gill, Murray and Wright
    1981 [1]_, section 8.7).

    Parameters
    ----------
    rows : numpy.ndarray, shape (..., r, n_var)
        G [N m/rad or N m s/rad per cm^2].
    bound : numpy.ndarray, shape (..., r)
        h [N m/rad or N m s/rad].

    Returns
    -------
    rows, bound : numpy.ndarray
        G and h divided row by row by their largest magnitude [1 and cm^2 per unit]; a zero row is kept.

    References
    ----------
    .. [1] Gill PE, Murray W, Wright MH (1981). Practical Optimization, section 8.7, "Scaling".
       Academic Press.
    """
    scale = np.maximum(np.abs(rows).max(axis=-1), np.abs(bound))
    scale = np.where(scale > 0, scale, 1.0)
    return rows / scale[..., None], bound / scale


STAGES = ("min_pcsa", "counter_torque", "least_norm")
"""The objectives: total PCSA w.x, ||CT||^2 (same minimisers as ||CT||), ||x||^2."""


def objective(data: ProblemData, stage: str):
    """The objective of ``stage`` as 1/2 x'Hx + q'x: (H or None, q); vectorised.

    ||CT||^2 = ||T x + g||^2 = x'T'Tx + 2 g'T x + g'g, the constant dropped.

    Parameters
    ----------
    data : ProblemData
    stage : str
        One of :data:`STAGES`.

    Returns
    -------
    hessian : numpy.ndarray or None, shape (..., n_var, n_var)
        H; None for the linear objective of 'min_pcsa'. [N^2 m^2 per cm^4] for
        'counter_torque', [1] for 'least_norm'.
    linear : numpy.ndarray, shape (..., n_var)
        q; the weights [1] for 'min_pcsa', [N^2 m^2 per cm^2] for 'counter_torque',
        0 for 'least_norm'.
    """
    lead, n = data.stability.shape[:-2], data.weights.size
    if stage == "min_pcsa":
        return None, np.broadcast_to(data.weights, lead + (n,))
    if stage == "counter_torque":
        hessian = 2.0 * np.einsum("...kn,...km->...nm", data.torque, data.torque)
        return hessian, 2.0 * np.einsum("...kn,...k->...n", data.torque, data.gravity_torque)
    return np.broadcast_to(2.0 * np.eye(n), lead + (n, n)), np.zeros(lead + (n,))


def polished(data: ProblemData, stage: str, x0, total_max=np.inf, x_ct=None):
    """The exact optimum of ``stage`` from the solver's answer ``x0`` (:func:`spinectl.optimise.polish.polish`).

    Polishing imposes CT(x) = CT(x_ct) exactly, as equalities on the row space
    of T, where the solver had the slab of :func:`ct_slab`. Returns x [cm^2]
    and whether it is a verified KKT point, both vectorised over leading dimensions.

    Parameters
    ----------
    data : ProblemData
    stage : str
        One of :data:`STAGES`.
    x0 : array_like, shape (..., n_var)
        The solver's answer [cm^2].
    total_max : float or array_like
        The band of the stage [cm^2], as for :func:`inequalities`.
    x_ct : array_like, optional
        The stage-2 optimum whose counter torques stage 3 keeps [cm^2].

    Returns
    -------
    x : numpy.ndarray, shape (..., n_var)
        The polished optimum [cm^2].
    verified : numpy.ndarray of bool, shape (...)
        True where ``x`` passed the KKT check.
    """
    hessian, linear = objective(data, stage)
    lhs, rhs = inequalities(data, total_max)
    eq_lhs = eq_rhs = None
    if x_ct is not None:
        rows, keep, centre, _ = ct_slab(data.torque, x_ct, data.tolerance, data.torque_scale)
        eq_lhs, eq_rhs = rows * keep[..., None], centre * keep
    tol = DEFAULT_TOLERANCE if data.tolerance is None else data.tolerance
    return polish.polish(hessian, linear, lhs, rhs, x0, tol, RANK_RTOL, eq_lhs, eq_rhs)


def worst_status(*statuses: str) -> str:
    """'optimal_inaccurate' if any stage was inaccurate, else 'optimal' (for optimal stages).

    Parameters
    ----------
    *statuses : str
        cvxpy statuses of the stages, each 'optimal' or 'optimal_inaccurate'.

    Returns
    -------
    str
        The status of the point.
    """
    return "optimal_inaccurate" if "optimal_inaccurate" in statuses else "optimal"


@dataclass(frozen=True)
class PointOptimum:
    """Result of the optimisation at one (E, Lambda).

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    status : str
        'optimal' (or 'optimal_inaccurate'), 'infeasible' (no PCSA within the bounds
        stabilises every segment) or 'solver_error'.
    min_pcsa : float
        Minimum total PCSA for self-stability of every segment [m^2]; NaN unless optimal.
    pcsa : numpy.ndarray, shape (n_muscles,)
        Chosen activation [m^2]: least ||CT|| within ``ct_tolerance`` of the minimum,
        ties broken by least ||x||_2 (module docstring); NaN unless optimal.
    counter_torque : numpy.ndarray, shape (n_cor,)
        CT_k at the chosen activation [N m].
    """

    eccentricity: float
    lordosis: float
    status: str
    min_pcsa: float
    pcsa: np.ndarray
    counter_torque: np.ndarray

    @property
    def counter_torque_norm(self) -> float:
        """||CT||_2 [N m] (paper, Figure 4)."""
        return float(np.linalg.norm(self.counter_torque))

    @property
    def total_pcsa(self) -> float:
        """Total PCSA of the chosen activation [m^2] (>= ``min_pcsa``)."""
        return float(np.sum(self.pcsa))

    @property
    def ok(self) -> bool:
        """True if the optimum was found."""
        return self.status in OK_STATUSES


def to_si(data: ProblemData, total, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Minimum PCSA [m^2], per-muscle PCSA [m^2] and CT [N m] from a total and x [cm^2].

    Vectorised over leading dimensions; NaN in, NaN out.

    Parameters
    ----------
    data : ProblemData
    total : array_like, shape (...)
        Minimum total PCSA [cm^2].
    x : array_like, shape (..., n_var)
        Chosen decision variables [cm^2].

    Returns
    -------
    min_pcsa : numpy.ndarray, shape (...)
        [m^2].
    pcsa : numpy.ndarray, shape (..., n_muscles)
        PCSA of each muscle [m^2].
    counter_torque : numpy.ndarray, shape (..., n_cor)
        CT_k [N m].
    """
    x = np.asarray(x, float)
    pcsa = np.einsum("mn,...n->...m", data.to_muscles, x) * M2_PER_CM2
    return np.asarray(total, float) * M2_PER_CM2, pcsa, data.counter_torque(x)
