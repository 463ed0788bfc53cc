"""Stability-constrained static optimisation on an anatomical model (docs/anatomy.md, "The optimum").

The least muscle effort that holds the posture::

    minimise    sum_i w_i a_i^2
    subject to  equilibrium, tau_0 + sum_i a_i tau_i = 0:
                  "free":   on every lumbar joint, the model's equality constraints off;
                  "rhythm": on the rhythm's independent coordinates (T^T tau = 0 in all three
                            planes); the model's joint equalities carry the rest, as constant
                            torques (the paper's counter torques, here the rhythm's),
                0 <= a_i <= 1,
                and the stability criterion:
                  "chain":  -K(a) >= mu I           (the free chain, every joint free at once),
                  "joints": -K_jj(a) >= mu, each j  (the paper's joint-by-joint criterion),
                  "rhythm": -K_c(a) >= mu I         (the chain constrained by the model's rhythm),
                  "none":   nothing (classic static optimisation).

The cost is OpenSim's static optimisation criterion sum a_i^2 (Anderson and Pandy 2001)
with ``weights="none"``; with ``weights="volume"`` (the default) each muscle counts by its
volume, w_i proportional to F0_i L0_i (maximal isometric force times optimal fibre length,
so PCSA times fibre length at a common specific tension), normalised to mean 1: a large
muscle's activation costs more than a small one's. Convex in a (a quadratic cost, linear
equalities and bounds, one linear matrix inequality), solved by the chain programmes of
:mod:`spinectl.optimise.coupled.sdp` (:func:`~spinectl.optimise.coupled.sdp.least_quadratic_cost_sdp`,
cvxpy and Clarabel) on the :class:`~spinectl.model.linear_chain.LinearChain` of the model.

References
----------
Anderson FC, Pandy MG (2001). Static and dynamic optimization solutions for gait are
practically equivalent. J Biomech 34(2):153-161. doi:10.1016/S0021-9290(00)00155-X.
Goulart PJ, Chen Y (2024). Clarabel: an interior-point solver for conic programs with
quadratic objectives. arXiv:2405.12762.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..model.linear_chain import LinearChain
from .contract import AnatomyEngine
from .identity import identity_text, model_identity
from .remedy import INFEASIBLE_HINT, REMEDY_RERUN, remedy, remedy_text

STABILITY = ("chain", "joints", "rhythm", "none")
EQUILIBRIUM = ("rhythm", "free")
WEIGHTS = ("volume", "none")
MARGIN = 1.0
"""Default static margin mu [N m/rad] of the stability constraints."""


def volume_weights(anatomy: AnatomyEngine) -> np.ndarray:
    """The optimum's volume weights, w_i proportional to each muscle's volume, normalised to mean 1.

    Each engine reads its own muscle parameters (MuJoCo's F0 and L0, OpenSim's maximal isometric
    force and optimal fibre length): :meth:`~spinectl.anatomy.contract.AnatomyEngine.volume_weights`.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.

    Returns
    -------
    numpy.ndarray, shape (m,)
    """
    return anatomy.volume_weights()


def solve_on_chain(chain: LinearChain, tau_per, tau_0, weights, stability: str, margin: float):
    """The optimum on a LinearChain with equilibrium rows; ``(status, a)`` (a NaN where infeasible).

    :func:`spinectl.optimise.coupled.sdp.least_quadratic_cost_sdp` with the equilibrium
    tau_per a + tau_0 = 0 as its equality rows and the chain's bounds 0 <= a <= 1.

    Parameters
    ----------
    chain : LinearChain
        The chain whose K(a) the criterion constrains; its bounds bound a.
    tau_per : numpy.ndarray, shape (r, m)
        Each control's generalised force per unit on the r equilibrium rows [N m].
    tau_0 : numpy.ndarray, shape (r,)
        The rest of the net torque on those rows [N m].
    weights : numpy.ndarray, shape (m,)
        Cost weights w_i.
    stability : str
        ``"chain"``, ``"joints"`` or ``"none"``
        (:data:`~spinectl.optimise.coupled.sdp.QUADRATIC_CRITERIA`).
    margin : float
        mu [N m/rad].

    Returns
    -------
    tuple
        (cvxpy's status, numpy.ndarray of shape (m,)).
    """
    from ..optimise.coupled.sdp import least_quadratic_cost_sdp

    status, a = least_quadratic_cost_sdp(chain, weights, margin, stability, equalities=(tau_per, -tau_0))
    return status, (np.full(chain.n_controls, np.nan) if a is None else a)


@dataclass(frozen=True)
class Optimum:
    """One optimum (:func:`optimise`).

    Attributes
    ----------
    stability : str
        The criterion imposed (:data:`STABILITY`).
    status : str
        cvxpy's status; the numbers are NaN unless it is optimal.
    activations : numpy.ndarray, shape (m,)
        [1].
    cost : float
        sum w_i a_i^2.
    equilibrium : str
        ``"rhythm"`` or ``"free"``.
    net_torque : numpy.ndarray, shape (r,)
        On every equilibrium row at the optimum [N m] (0 up to the solver's tolerance).
    lumbar_torque : numpy.ndarray, shape (l,)
        The net torque on every lumbar joint at the optimum [N m]: what the rhythm carries
        (0 with ``"free"``).
    eigenvalues : numpy.ndarray, shape (n,)
        Of -K(a) of the free chain [N m/rad]: the least is the margin.
    joint_stiffness : numpy.ndarray, shape (n,)
        Diagonal of -K(a) [N m/rad].
    residual : float
        Where infeasible: the bounded least-squares residual of the equilibrium, min ||tau_per a +
        tau_0|| over the bounds (SciPy's ``lsq_linear``) [N m]; NaN where solved.
    lumbar_joints : tuple of str
        The names of ``lumbar_torque``'s rows (:func:`lumbar_joints`).
    """

    stability: str
    status: str
    activations: np.ndarray
    cost: float
    equilibrium: str
    net_torque: np.ndarray
    lumbar_torque: np.ndarray
    eigenvalues: np.ndarray
    joint_stiffness: np.ndarray
    residual: float = float("nan")
    lumbar_joints: tuple = ()

    @property
    def ok(self) -> bool:
        """Solved (optimal or optimal_inaccurate)."""
        return self.status in ("optimal", "optimal_inaccurate")


def optimise(
    anatomy: AnatomyEngine,
    plane: str = "sagittal",
    stability: str = "chain",
    margin: float = MARGIN,
    posture=None,
    joint_stiffness="none",
    weights: str = "volume",
    equilibrium: str = "rhythm",
    loads=(),
) -> Optimum:
    """The least-effort activations that hold the posture, with a stability criterion.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    plane : str
        The chain whose stability is imposed (equilibrium holds on every lumbar joint: the
        mapping's ``3d`` plane, or this plane's joints if it has none).
    stability : str
        ``"chain"``, ``"joints"`` or ``"none"`` (module docstring).
    margin : float
        mu [N m/rad], >= 0.
    posture : optional
        The operating point in the engine's form (MuJoCo: the full qpos; OpenSim: coordinate name ->
        value [rad]); default the model's reference posture.
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    weights : str
        ``"volume"`` or ``"none"`` (:func:`volume_weights`).
    equilibrium : str
        ``"rhythm"`` or ``"free"`` (module docstring).
    loads : sequence of BodyLoad, optional
        External loads held (:mod:`spinectl.anatomy.loads`): in the equilibrium and in K; default none.

    Returns
    -------
    Optimum
    """
    check_choices(stability, equilibrium, margin, weights)
    if not len(anatomy.muscles):  # before: numpy's warnings, then the solver's solver_error
        raise ParameterError(
            "optimise", f"{anatomy.name} has no muscles: there are no activations to optimise (--optimise, --lordosis)"
        )
    free, constrained, lin = anatomy.chains(plane, posture, joint_stiffness, loads=loads)
    rows, tau_per, tau_0 = anatomy.equilibrium_rows(lin, plane, posture, equilibrium)
    w = anatomy.volume_weights() if weights == "volume" else np.ones(free.n_controls)
    opt = optimum_on_chains(free, constrained, lin, rows, tau_per, tau_0, w, stability, equilibrium, margin)
    return dataclasses.replace(opt, lumbar_joints=lumbar_joints(anatomy, plane, len(rows)))


def lumbar_joints(anatomy: AnatomyEngine, plane: str, rows: int) -> tuple:
    """The joints of the equilibrium's lumbar rows (:meth:`~spinectl.anatomy.contract.AnatomyEngine.equilibrium_rows`).

    MuJoCo's rows are the mapping's ``3d`` joints (this plane's if it has none), OpenSim's the plane's
    chain: whichever has as many joints as there are rows.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    plane : str
        The chain.
    rows : int
        How many lumbar rows the equilibrium has.

    Returns
    -------
    tuple of str
    """
    own = anatomy.plane_joints(plane)
    every = tuple(anatomy.mapping.planes.get("3d", own))
    return every if len(every) == rows else tuple(own)[:rows]


def check_choices(stability, equilibrium, margin, weights="volume"):
    """Refuse a stability criterion, weighting, equilibrium or margin outside what :func:`optimise` takes.

    Parameters
    ----------
    stability : str
        One of :data:`STABILITY`.
    equilibrium : str
        One of :data:`EQUILIBRIUM`.
    margin : float
        mu [N m/rad], >= 0.
    weights : str
        One of :data:`WEIGHTS`.

    Returns
    -------
    None

    Raises
    ------
    ParameterError
        Naming the field and what is allowed.
    """
    if stability not in STABILITY:
        raise ParameterError("stability", f"must be one of {STABILITY} (got {stability!r})")
    if weights not in WEIGHTS:
        raise ParameterError("weights", f"must be one of {WEIGHTS} (got {weights!r})")
    if equilibrium not in EQUILIBRIUM:
        raise ParameterError("equilibrium", f"must be one of {EQUILIBRIUM} (got {equilibrium!r})")
    if not (np.isfinite(margin) and margin >= 0):
        raise ParameterError("margin", f"must be >= 0 [N m/rad] (got {margin!r})")


def optimum_on_chains(free, constrained, lin, rows, tau_per, tau_0, w, stability, equilibrium, margin):
    """Solve the optimum on the linearised chains and summarise it; shared by both engines.

    Parameters
    ----------
    free, constrained : chain
        The chain with every joint free and the one with the rhythm imposed.
    lin : linearisation
        Its ``torque_per_muscle`` [N m] and ``torque_offset`` [N m] over all dofs.
    rows : list of int
        The lumbar dofs in ``lin``'s rows.
    tau_per, tau_0 : numpy.ndarray
        The equilibrium's torque per activation [N m] and offset [N m].
    w : numpy.ndarray
        Cost weights per muscle.
    stability, equilibrium : str
        As :func:`optimise`; ``"rhythm"`` solves the chain criterion on ``constrained``.
    margin : float
        mu [N m/rad].

    Returns
    -------
    Optimum
    """
    free, constrained = _lumbar_only(free), _lumbar_only(constrained)
    chain, criterion = (constrained, "chain") if stability == "rhythm" else (free, stability)
    status, a = solve_on_chain(chain, tau_per, tau_0, w, criterion, margin)
    k = free.stiffness(a) if np.all(np.isfinite(a)) else np.full((free.n_joints,) * 2, np.nan)
    ok = np.all(np.isfinite(k))
    return Optimum(
        stability=stability,
        status=status,
        activations=a,
        cost=float(w @ a**2),
        equilibrium=equilibrium,
        net_torque=tau_per @ a + tau_0,
        lumbar_torque=lin.torque_per_muscle[rows] @ a + lin.torque_offset[rows],
        eigenvalues=np.linalg.eigvalsh(-0.5 * (k + k.T)) if ok else np.full(free.n_joints, np.nan),
        joint_stiffness=-np.diag(k),
        residual=float("nan") if status in ("optimal", "optimal_inaccurate") else _residual(chain, tau_per, tau_0),
    )


def _lumbar_only(chain: LinearChain) -> LinearChain:
    """The chain with its non-lumbar controls held at their lower bound: a muscle that crosses no chain joint adds
    no torque to the lumbar equilibrium and no stiffness, so it has no part in the lumbar optimum (left free, it
    would take an activation of the solver's tolerance, 1e-3 on MyoTorso, where its volume weight is small)."""
    idle = np.array([c == "non-lumbar" for c in chain.control_class], bool)
    if not idle.any():
        return chain
    return dataclasses.replace(chain, upper=np.where(idle, chain.lower, chain.upper))


def _residual(chain, tau_per, tau_0) -> float:
    """min ||tau_per a + tau_0|| over the chain's bounds [N m]: how far the equilibrium is from holding."""
    from scipy.optimize import lsq_linear

    free = chain.upper > chain.lower  # the controls held at a bound (non-lumbar: _lumbar_only) are constants
    rest = tau_0 + tau_per[:, ~free] @ chain.lower[~free]
    bounds = (chain.lower[free], chain.upper[free])
    return float(np.linalg.norm(lsq_linear(tau_per[:, free], -rest, bounds=bounds).fun))


def _optimum_dict(anatomy: AnatomyEngine, opt: Optimum) -> dict:
    return {
        "stability": opt.stability,
        "equilibrium": opt.equilibrium,
        "status": opt.status,
        "cost": opt.cost,
        "activation_sum": float(np.sum(opt.activations)),
        "eigenvalues": opt.eigenvalues.tolist(),
        "restoring_stiffness_Nm_per_rad": opt.joint_stiffness.tolist(),
        "net_torque_Nm": opt.net_torque.tolist(),
        "lumbar_torque_Nm": opt.lumbar_torque.tolist(),
        "lumbar_joints": list(opt.lumbar_joints),
        "equilibrium_residual_Nm": opt.residual,
    }


KEPT_WHERE_INFEASIBLE = (
    "model",
    "plane",
    "posture_source",
    "joints",
    "muscles",
    "control_unit",
    "mass_matrix_kgm2",
    "joint_stiffness_Nm_per_rad",
    "joint_stiffness_source",
    "global_rank",
    "global_singular_values_m_per_rad",
    "global_null_space",
    "modes_removed",
    "rhythm",
    "devices",
    "rhythm_left_out",
    "kp_Nm_per_rad",
    "kd_Nms_per_rad",
    "activation_lag_s",
)
"""The analysis's keys that do not depend on the activations: kept in the JSON of an infeasible optimum."""


def _not_computed(doc: dict) -> dict:
    """The analysis's keys with every value that depends on the activations null, its ``<key>_reason`` beside it.

    The strict-JSON convention of :mod:`spinectl.jsondoc`: an infeasible optimum has the same keys as a
    feasible one, the numbers it has no activations for ``null`` with the reason ``not_computed``.
    """
    out = {}
    for key, value in doc.items():
        if key in KEPT_WHERE_INFEASIBLE or key.endswith("_criterion"):
            out[key] = value
        elif isinstance(value, dict):
            out[key] = _not_computed(value)
        else:
            out[key], out[f"{key}_reason"] = None, "not_computed"
    return out


@dataclass(frozen=True)
class OptimisedResult:
    """The optimum with a stability criterion, beside classic static optimisation, and the analysis at it.

    Attributes
    ----------
    anatomy : AnatomyEngine
        The model.
    optimum : Optimum
        With the criterion asked for.
    classic : Optimum
        Without a stability criterion (classic static optimisation).
    margin : float
        mu [N m/rad].
    plane : str
        The chain's plane.
    analysis : AnatomyResult or None
        :func:`~spinectl.anatomy.analyses.analyse` at the optimum's activations; None where infeasible.
    skeleton : AnatomyResult or None
        Where infeasible: the analysis at the lower control bounds, whose keys (the numbers
        nulled) the JSON keeps (:func:`_not_computed`).
    remedy : float
        Where only the stability criterion fails: the least stiffness [N m/rad] at each chain joint
        (``--joint-stiffness``) from which the optimum is feasible (:func:`least_joint_stiffness`);
        inf where none up to :data:`MAX_REMEDY` is; NaN where not asked (the optimum solved, or the
        equilibrium fails).
    rerun : str
        What follows ``spinectl anatomy`` in the remedy's command to analyse this model again (its file and
        mapping, :func:`~spinectl.anatomy.remedy.remedy_text`); the command line sets it.
    """

    anatomy: AnatomyEngine
    optimum: Optimum
    classic: Optimum
    margin: float
    plane: str
    analysis: object
    skeleton: object = None
    remedy: float = float("nan")
    rerun: str = REMEDY_RERUN

    @property
    def infeasible_constraint(self) -> str:
        """Which constraint fails: ``"none"`` (solved), ``"equilibrium"`` (classic static optimisation,
        without a stability criterion, is infeasible too) or ``"stability"`` (only the criterion fails)."""
        if self.optimum.ok:
            return "none"
        return "equilibrium" if not self.classic.ok else "stability"

    @property
    def price(self) -> float:
        """The price of stability: the optimum's cost over the classic optimum's (NaN if either is infeasible)."""
        return self.optimum.cost / self.classic.cost if self.classic.cost > 0 else float("nan")

    def to_dict(self) -> dict:
        """JSON-ready: the analysis at the optimum, ``activations`` by muscle, ``cost``, ``net_torque_Nm``.

        Returns
        -------
        dict
        """
        if self.analysis is not None:
            out = self.analysis.to_dict()
        elif self.skeleton is not None:
            out = _not_computed(self.skeleton.to_dict())
        else:
            out = self._header()
        out.update(
            {
                "infeasible_constraint": self.infeasible_constraint,
                "activations": dict(zip(self.anatomy.muscles, self.optimum.activations.tolist(), strict=True)),
                "cost": self.optimum.cost,
                "net_torque_Nm": self.optimum.net_torque.tolist(),
                "margin_Nm_per_rad": self.margin,
                "optimum": _optimum_dict(self.anatomy, self.optimum),
                "classic": _optimum_dict(self.anatomy, self.classic),
                "price_of_stability": self.price,
                "feasible_from_joint_stiffness_Nm_per_rad": self.remedy,
            }
        )
        return out

    def _header(self) -> dict:
        """The model and the chain, where there is no analysis (an infeasible optimum)."""
        anatomy = self.anatomy
        return {
            "model": model_identity(anatomy),
            "plane": self.plane,
            "joints": list(self.anatomy.plane_joints(self.plane)),
        }

    def table(self) -> str:
        """The optimum and the classic one, each with its criterion; then the analysis at the optimum.

        Returns
        -------
        str
        """
        rows = (("optimum", self.optimum), ("classic", self.classic))
        lines = [self._first_line()]
        for label, opt in rows:
            lines.append(_optimum_line(label, opt, self.margin))
            lines += hidden_torque_lines(opt)
        lines.append(self._price_line())
        if self.infeasible_constraint == "equilibrium":
            lines.append(EQUILIBRIUM_HINT.format(residual=self.classic.residual, rows=self.classic.net_torque.size))
        elif self.infeasible_constraint == "stability":
            lines.append(INFEASIBLE_HINT + remedy_text(self.remedy, self.rerun))
        if self.analysis is not None:
            lines += ["", "at the optimum's activations:", self.analysis.table()]
        return "\n".join(lines)

    def _first_line(self) -> str:
        """The model, plane, posture and whose activations; for compliant tendons, where they were linearised."""
        from .analyses import REFERENCE_POSTURE, plane_text

        shown = self.analysis or self.skeleton
        posture = shown.posture_source if shown is not None else REFERENCE_POSTURE
        line = (
            f"{identity_text(model_identity(self.anatomy))}, {plane_text(self.plane)}, posture: {posture}, "
            "activations: the optimum's"
        )
        springs = getattr(getattr(self.anatomy, "engine", None), "springs", 0)
        if springs:  # the optimum's chains were taken without activations: the tangent at each floor
            line += (
                f"; {springs} compliant-tendon muscles linearised at their activation floors for the optimum, at "
                "the optimum's activations for the analysis below"
            )
        return line

    def _price_line(self) -> str:
        """The price of stability, or why there is none (an infeasible optimum has no cost to compare)."""
        if self.optimum.ok and self.classic.ok:
            return f"price of stability (the optimum's cost over the classic one's): {self.price:.4g}"
        which = "the optimum" if not self.optimum.ok else "the classic optimum"
        return f"price of stability: none ({which} is infeasible, so it has no cost to compare)"


CRITERION_TEXT = {
    "chain": "the chain free, -K >= mu I",
    "joints": "joint by joint, each -K_jj >= mu",
    "rhythm": "the chain constrained by the rhythm, -K_c >= mu",
    "none": "no stability criterion: classic static optimisation",
}
"""Each ``--stability`` criterion in the optimum's table: -K's least eigenvalue (or each diagonal entry) >= mu."""


def _optimum_line(label: str, opt: Optimum, margin: float) -> str:
    """One optimum in the table: its criterion (mu only where it has one), then its answer or 'infeasible'."""
    mu = f", mu = {margin:g} N m/rad" if opt.stability != "none" else ""
    head = f"{label} ({CRITERION_TEXT[opt.stability]}{mu}; equilibrium {opt.equilibrium}): "
    if not opt.ok:
        meet = "hold the posture" + (" and meet the criterion" if opt.stability != "none" else "")
        status = f" (the solver: {opt.status})" if opt.status != "infeasible" else ""
        none = "no cost, activations or eigenvalues"
        return head + f"infeasible: no activations within their bounds {meet}{status}; {none}"
    eig = ", ".join(f"{v:.4g}" for v in opt.eigenvalues)
    return head + (
        f"{opt.status}; cost {opt.cost:.4g}, sum of activations {np.sum(opt.activations):.4g}; "
        f"eigenvalues of -K (free chain) {eig} N m/rad"
    )


HIDDEN_TORQUE = (
    "  torque the rhythm carries (equilibrium on the rhythm's coordinates only; the model's equalities, not its "
    "muscles, hold the rest): largest {largest:.3g} N m at {joint}; per lumbar joint [N m]: {each}"
)
"""What the table says beside an optimum whose equilibrium holds on the rhythm's coordinates only."""


def hidden_torque_lines(opt: Optimum) -> list:
    """The torque the rhythm carries at each lumbar joint, as the table shows it beside the optimum's verdict.

    With ``equilibrium="rhythm"`` the muscles balance the posture on the rhythm's independent coordinates
    only (T^T tau = 0); each lumbar joint may still carry a net torque, which the model's joint equalities
    (MuJoCo) or couplers (OpenSim) hold as constraint forces. The verdicts at that optimum rest on it.

    Parameters
    ----------
    opt : Optimum
        An optimum.

    Returns
    -------
    list of str
        One line, or none (equilibrium ``"free"``, where it is zero by construction; an infeasible optimum).
    """
    if opt.equilibrium != "rhythm" or not opt.ok or not opt.lumbar_joints:
        return []
    torque = opt.lumbar_torque
    k = int(np.argmax(np.abs(torque)))
    each = ", ".join(f"{j} {t:.3g}" for j, t in zip(opt.lumbar_joints, torque, strict=True))
    return [HIDDEN_TORQUE.format(largest=abs(torque[k]), joint=opt.lumbar_joints[k], each=each)]


EQUILIBRIUM_HINT = (
    "the equilibrium fails, not the stability criterion: no activations within their bounds hold the posture even "
    "without a criterion (the classic optimum is infeasible too); the bounded least-squares residual of the net torque "
    "is {residual:.3g} N m over the {rows} equilibrium rows: the posture needs torques besides the muscles' "
    "(spinectl's export: its counter torques, actuators that the optimum does not hold)"
)
"""What the table adds where the classic optimum is infeasible too: the equilibrium's residual."""


def optimised(
    anatomy: AnatomyEngine,
    plane: str = "sagittal",
    stability: str = "chain",
    margin: float = MARGIN,
    joint_stiffness="none",
    equilibrium: str = "rhythm",
    check: bool = False,
    reflex=None,
    posture=None,
    time=None,
    loads=(),
) -> OptimisedResult:
    """The optimum with a criterion and without, at a posture, and the analysis at the optimum.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    plane : str
        The chain.
    stability : str
        One of :data:`STABILITY`.
    margin : float
        mu [N m/rad].
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    equilibrium : str
        One of :data:`EQUILIBRIUM`.
    check : bool
        MuJoCo's own eigenvalues at the optimum (:func:`~spinectl.anatomy.referee.mujoco_eigenvalues`).
    reflex : tuple, optional
        ``(kp, kd, lag)``: the chain's exact delay margin at the optimum
        (:func:`~spinectl.anatomy.analyses.reflex_margin`).
    posture : optional
        The engine's posture, or an OpenSim ``.mot``/``.sto`` file of every coordinate
        (:func:`spinectl.anatomy.recordings.recorded_point`); default the model's reference posture.
    time : float, optional
        The posture file's frame [s]; default its first.
    loads : sequence of BodyLoad, optional
        External loads held (:func:`optimise`); default none.

    Returns
    -------
    OptimisedResult
    """
    from .analyses import analyse
    from .recordings import recorded_point

    if check:  # refused before any optimum is solved, on an engine MuJoCo cannot referee
        anatomy.require_referee()
    point = recorded_point(anatomy, posture, None, time)
    kwargs = {"plane": plane, "margin": margin, "joint_stiffness": joint_stiffness, "equilibrium": equilibrium}
    kwargs["posture"] = point.posture
    if loads:  # only then: the engines' optimise of a made-up engine need not know loads
        kwargs["loads"] = loads
    opt = optimise(anatomy, stability=stability, **kwargs)
    classic = opt if stability == "none" else optimise(anatomy, stability="none", **kwargs)
    analysis = None
    at = {"posture": point.posture, "joint_stiffness": joint_stiffness, "reflex": reflex}
    if opt.ok:
        analysis = analyse(anatomy, plane, opt.activations, check=check, loads=loads, **at)
        analysis = dataclasses.replace(analysis, activation_source="the optimum's")
    empty = skeleton(anatomy, opt, **kwargs, reflex=reflex)
    if point.posture_source:  # the file and its frame, where analyse saw the posture it read
        analysis, empty = (r and dataclasses.replace(r, posture_source=point.posture_source) for r in (analysis, empty))
    fix = remedy(anatomy, optimise, opt, classic, joint_stiffness, kwargs)
    return OptimisedResult(anatomy, opt, classic, float(margin), plane, analysis, empty, fix)


def skeleton(
    anatomy: AnatomyEngine, opt: Optimum, plane: str, joint_stiffness, reflex=None, posture=None, loads=(), **_
):
    """Where the optimum is infeasible, the analysis at the lower control bounds (its JSON's keys); else None.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    opt : Optimum
        The optimum.
    plane : str
        The chain.
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    reflex : tuple, optional
        ``(kp, kd, lag)``.
    posture : optional
        The engine's posture; default the reference posture.
    loads : sequence of BodyLoad, optional
        External loads (:func:`optimise`).

    Returns
    -------
    AnatomyResult or None
    """
    from .analyses import analyse

    if opt.ok:
        return None
    lower = anatomy.control_bounds()[0]
    return analyse(anatomy, plane, lower, posture=posture, joint_stiffness=joint_stiffness, reflex=reflex, loads=loads)


def lordosis_posture(anatomy: AnatomyEngine, degrees: float, plane: str = "sagittal"):
    """The reference posture with the plane's chain moved along the model's rhythm by ``degrees`` in total.

    The chain's joints (and those the rhythm slaves: MyoTorso's abdomen, the coordinates an
    ``.osim``'s couplers tie) move as the rhythm distributes them, their angles summing to
    ``degrees`` over the chain (:func:`~spinectl.anatomy.directions.lordosis_direction`); the thorax
    is not held upright (it turns with the chain).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    degrees : float
        The change of the chain's summed angle [deg].
    plane : str
        The chain.

    Returns
    -------
    object
        The posture in the engine's form (MuJoCo: the full qpos; OpenSim: coordinate name -> value [rad]).
    """
    return anatomy.lordosis_posture(degrees, plane)


CURVE_MEANING = (
    "the lordosis moves the chain along the model's rhythm from its posture, so the thorax above it tilts too: "
    "not a lordosis at a fixed upright trunk"
)
"""What the anatomy's lordosis axis is, said wherever its curve is shown (table and figure)."""

CURVE_INACCURATE = (
    "WARNING: {count} inaccurate (status optimal_inaccurate, marked {mark}: the solver did not meet its tolerances, "
    "values may be far off)"
)
"""What the lordosis curve's table and figure say where some optima are ``optimal_inaccurate``, as ``sweep`` does."""

CURVE_AXIS = "summed angle change [deg]"
CURVE_AXIS_MEANING = (
    "the chain's summed joint angle minus the model's posture's, moved along the rhythm (+: the rhythm's "
    "positive direction, extension for MyoTorso)"
)
"""The lordosis curve's axis: its title (with its unit) and what it measures, in the table and the figure."""


def lordosis_curve(
    anatomy: AnatomyEngine,
    degrees,
    plane: str = "sagittal",
    margin: float = MARGIN,
    joint_stiffness="none",
    equilibrium: str = "rhythm",
    loads=(),
) -> dict:
    """The three optima (classic, joint by joint, the chain) over the lordosis.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    degrees : array_like
        Changes of the chain's summed angle about the reference posture [deg].
    plane, margin, joint_stiffness, equilibrium, loads
        As in :func:`optimise`.

    Returns
    -------
    dict
        ``lordosis_deg`` and, per criterion (``none``, ``joints``, ``chain``), ``cost``,
        ``status`` and ``margin_Nm_per_rad`` (the least eigenvalue of -K) lists.
    """
    degrees = np.asarray(degrees, float)
    postures = [anatomy.lordosis_posture(d, plane) for d in degrees]
    out = {"lordosis_deg": degrees.tolist()}
    for criterion in ("none", "joints", "chain"):
        rows = [
            optimise(
                anatomy,
                plane=plane,
                stability=criterion,
                margin=margin,
                posture=posture,
                joint_stiffness=joint_stiffness,
                equilibrium=equilibrium,
                **({"loads": loads} if loads else {}),
            )
            for posture in postures
        ]
        out[criterion] = {
            "cost": [r.cost for r in rows],
            "status": [r.status for r in rows],
            "margin_Nm_per_rad": [float(r.eigenvalues[0]) for r in rows],
        }
    return out
