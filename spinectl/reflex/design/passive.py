"""The chain's static stability against the passive stiffness per joint (``spinectl design --passive``).

The least global PCSA alone (problem (b) of docs/chain.md) and the least local stiffness at the paper's
global PCSA, against the passive stiffness; the threshold from which global muscles alone suffice, and
Crisco et al. (1992)'s buckling stiffness of the ligamentous spine marked.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._threads import with_one_blas_thread
from ...model import chain
from ...model.params import Model
from ...model.stability import criterion
from ...optimise.reference import solve_point
from ...units import m2_to_cm2
from .result import _word

CRISCO_LOAD = 88.0
"""The critical load of the ligamentous lumbar spine (L1 to the sacrum, no muscles) measured by Crisco et al.
(1992) [N]; the load stood on L1, at the top of the modelled spine."""

PAPER_PASSIVE = 15.0
"""The paper's passive stiffness per joint [N m/rad] (Wagner et al. 2012), marked on the passive-stiffness curve."""

GLOBAL_ALONE = (
    "the least global PCSA alone: the least total global PCSA that makes the chain (all CoRs free) statically "
    "stable with no local muscles (docs/chain.md, problem (b))"
)
"""Problem (b) in words, where the curve's outputs name it (the table's note and passive.png)."""

THRESHOLD_TOLERANCE = 0.01
"""Width of the bracket of the least passive stiffness at which global muscles alone suffice [N m/rad]."""


def crisco_stiffness(model: Model, eccentricity: float, lordosis: float, load: float = CRISCO_LOAD) -> float:
    """The passive stiffness per joint at which the chain without muscles buckles under ``load`` at the spine's top.

    The passive chain (no muscles, no other weight) under a vertical load W on the top of the spine
    (y = ``geometry.spine_length``, L1, where Crisco et al. 1992 loaded their specimens) has
    K = K_g(W) - k I with the gravity stiffness K_g of docs/chain.md; it is statically stable
    iff k I - K_g is positive definite, so it buckles at k = lambda_max(K_g(W)), the same k at
    every joint (the physical convention).

    Parameters
    ----------
    model : Model
        Supplies the geometry and the gravity sign.
    eccentricity, lordosis : float
        E and Lambda [m].
    load : float
        W [N].

    Returns
    -------
    float
        [N m/rad] per joint.

    References
    ----------
    Crisco JJ, Panjabi MM, Yamamoto I, Oxland TR (1992). Euler stability of the human ligamentous
    lumbar spine. Part II: Experiment. Clin Biomech 7(1):27-32. doi:10.1016/0268-0033(92)90004-N.
    """
    loaded = passive_chain_model(model, load)
    gravity = chain.chain_coefficients(loaded, float(eccentricity), float(lordosis)).gravity_stiffness
    return float(np.linalg.eigvalsh(gravity)[-1])


def passive_chain_model(model: Model, load: float = CRISCO_LOAD, stiffness: float = 0.0) -> Model:
    """The model of Crisco's specimen: the load W on the spine's top, the levels weightless, passive stiffness k.

    Parameters
    ----------
    model : Model
    load : float
        W [N].
    stiffness : float
        k per joint [N m/rad], physical convention.

    Returns
    -------
    Model
    """
    from ...model import config

    return config.set_parameters(
        model,
        {
            "body.mass": load / model.body.gravity,
            "body.mass_height": model.geometry.spine_length,
            "levels.weight_in_gravity": 0.0,
            "passive.stiffness": stiffness,
            "passive.convention": "physical",
        },
    )


@dataclass(frozen=True)
class PassiveCurve:
    """The chain's verdicts against the passive stiffness per joint, at one (E, Lambda).

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    passive_stiffness : numpy.ndarray, shape (m,)
        K per joint [N m/rad] (``passive.stiffness``, physical convention).
    global_pcsa : numpy.ndarray, shape (m,)
        The least total global PCSA for the chain's static stability without local muscles,
        problem (b) of docs/chain.md [m^2]; NaN where none can.
    global_status : tuple of str
    local_stiffness : numpy.ndarray, shape (m, n_cor)
        The least local stiffness per joint at the fixed global PCSA ``paper_pcsa``, problem (a)
        [N m/rad]; NaN without an optimum or a solution.
    paper_pcsa : float
        The global PCSA held fixed: the paper's (joint-by-joint) minimum at the model's own passive
        stiffness [m^2], so that the curve shows the passive stiffness alone.
    fixed_pcsa : numpy.ndarray, shape (n_muscles,)
        Its distribution over the muscles [m^2]. ``global_pcsa`` has another, problem (b)'s own at each K:
        the two columns are not at the same muscles (:meth:`columns_note`).
    threshold : float
        The least K at which global muscles alone stabilise the chain [N m/rad], by bisection on
        the feasibility of (b) to :data:`THRESHOLD_TOLERANCE`; NaN if not in the scanned range.
    crisco : float
        The K at which the passive chain buckles under Crisco et al.'s 88 N (:func:`crisco_stiffness`) [N m/rad].
    crisco_global_pcsa : float
        The least global PCSA alone at K = ``crisco`` [m^2]; NaN if none.
    model : dict
        Provenance and header line.
    fixed_at : str
        The model's own passive stiffness, at which ``paper_pcsa`` is the minimum, e.g. ``"K = 0 N m/rad,
        physical convention"``.
    """

    eccentricity: float
    lordosis: float
    passive_stiffness: np.ndarray
    global_pcsa: np.ndarray
    global_status: tuple[str, ...]
    local_stiffness: np.ndarray
    paper_pcsa: float
    fixed_pcsa: np.ndarray
    threshold: float
    crisco: float
    crisco_global_pcsa: float
    model: dict
    fixed_at: str = ""

    def to_dict(self) -> dict:
        """The document of ``spinectl design --passive ... --json``.

        Returns
        -------
        dict
            Provenance, ``criterion`` (the chain), ``E_m``, ``Lambda_m``, ``passive_stiffness_Nm_per_rad``,
            ``global_pcsa_cm2``, ``global_status``, ``local_stiffness_Nm_per_rad`` (per point, per joint),
            ``local_stiffness_total_Nm_per_rad``, ``local_at_global_pcsa_cm2``, ``global_alone_from_Nm_per_rad``,
            ``crisco_stiffness_Nm_per_rad``, ``crisco_load_N``, ``crisco_global_pcsa_cm2``,
            ``local_at_pcsa_per_muscle_cm2`` (muscle name -> PCSA) and ``columns_note`` (:meth:`columns_note`).
        """
        model = {k: v for k, v in self.model.items() if k not in ("header", "muscles")}
        return model | {
            "criterion": criterion("chain", self.local_stiffness.shape[1]),
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "passive_stiffness_Nm_per_rad": self.passive_stiffness.tolist(),
            "global_pcsa_cm2": m2_to_cm2(self.global_pcsa).tolist(),
            "global_status": list(self.global_status),
            "local_stiffness_Nm_per_rad": self.local_stiffness.tolist(),
            "local_stiffness_total_Nm_per_rad": self.local_stiffness.sum(axis=1).tolist(),
            "local_at_global_pcsa_cm2": float(m2_to_cm2(self.paper_pcsa)),
            "global_alone_from_Nm_per_rad": self.threshold,
            "crisco_stiffness_Nm_per_rad": self.crisco,
            "crisco_load_N": CRISCO_LOAD,
            "crisco_global_pcsa_cm2": float(m2_to_cm2(self.crisco_global_pcsa)),
            "local_at_pcsa_per_muscle_cm2": dict(
                zip(self.model.get("muscles", ()), m2_to_cm2(self.fixed_pcsa).tolist(), strict=False)
            ),
            "columns_note": self.columns_note(),
        }

    def columns_note(self) -> str:
        """Which global PCSA, in which distribution, each column is at.

        Returns
        -------
        str
            One line: the global-alone column is :data:`GLOBAL_ALONE` at each K, in its distribution; the local
            column the paper's joint-by-joint minimum held fixed, which is not the chain's best.
        """
        return (
            f"note: 'global alone' is {GLOBAL_ALONE}, in its own least distribution at each K; 'sum local k' "
            f"is at the paper's joint-by-joint minimum, {_word(m2_to_cm2(self.paper_pcsa), 0, '.2f')} cm^2 held "
            "fixed in its own distribution, which is not the chain's best: a larger total can need local stiffness "
            "where a smaller one alone suffices"
        )

    def table(self) -> str:
        """The curve as rows, with the threshold and Crisco's stiffness.

        Returns
        -------
        str
            No final newline.
        """
        n = self.local_stiffness.shape[1]
        lines = [
            self.model.get("header", "preset unknown"),
            f"{criterion('chain', n)}: static stability against the passive stiffness per joint, "
            f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            f"least local stiffness at a fixed global PCSA of {_word(m2_to_cm2(self.paper_pcsa), 0, '.2f')} cm^2: "
            "the least total PCSA of the global muscles for which every segment is self-stable joint by joint "
            "(each CoR alone, the others fixed: the paper's minimum, eq. 1), solved once at the model's own "
            f"{self.fixed_at or 'passive stiffness'} and held, muscle by muscle, at every K below",
            self.columns_note(),
            f"{'K[N m/rad]':>10} {'global alone[cm2]':>17} {'sum local k[N m/rad]':>20}",
        ]
        lines += [
            f"{k:10.2f} {_word(m2_to_cm2(g), 17, '.2f')} {_word(float(np.sum(loc)), 20, '.1f')}"
            for k, g, loc in zip(self.passive_stiffness, self.global_pcsa, self.local_stiffness, strict=True)
        ]
        lines += [
            f"global muscles alone stabilise the chain from K = {_word(self.threshold, 0, '.2f')} N m/rad per joint"
            + ("" if np.isfinite(self.threshold) else " (not in the scanned range)"),
            f"Crisco et al. 1992 ({CRISCO_LOAD:g} N buckles the passive chain): K = {self.crisco:.2f} N m/rad per "
            f"joint; there "
            + (
                f"global muscles alone need {m2_to_cm2(self.crisco_global_pcsa):.2f} cm^2"
                if np.isfinite(self.crisco_global_pcsa)
                else "no global PCSA alone stabilises the chain"
            ),
        ]
        return "\n".join(lines)


@with_one_blas_thread
def passive_curve(model: Model, eccentricity: float, lordosis: float, stiffnesses) -> PassiveCurve:
    """The least global PCSA and the least local stiffness for the chain against the passive stiffness.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    stiffnesses : array_like, shape (m,)
        Passive stiffness per joint [N m/rad], >= 0 (physical convention).

    Returns
    -------
    PassiveCurve

    Raises
    ------
    ParameterError
        A stiffness negative or not finite; E or Lambda out of range.
    """
    from ...model.params.bounds import passive_axis
    from ...model.source import origin, provenance

    ks = np.array(passive_axis(np.asarray(stiffnesses, float).ravel().tolist()))
    e, lam = float(eccentricity), float(lordosis)
    optimum = np.asarray(solve_point(model, e, lam).pcsa, float)
    points = [_passive_point(model, e, lam, k, optimum) for k in ks]
    feasible = np.array([np.isfinite(p[0]) for p in points])
    threshold = _threshold(model, e, lam, ks, feasible)
    crisco = crisco_stiffness(model, e, lam)
    return PassiveCurve(
        eccentricity=e,
        lordosis=lam,
        passive_stiffness=ks,
        global_pcsa=np.array([p[0] for p in points]),
        global_status=tuple(p[1] for p in points),
        local_stiffness=np.array([p[2] for p in points]),
        paper_pcsa=float(np.sum(optimum)),
        fixed_pcsa=optimum,
        threshold=threshold,
        crisco=crisco,
        crisco_global_pcsa=_global_alone(model, e, lam, crisco).total_pcsa,
        # K is swept: the header names the origin, not the model's own K
        model=provenance(model)
        | {"header": f"{origin(model)}; K swept, physical convention", "muscles": tuple(model.muscle_names)},
        fixed_at=f"K = {model.passive.stiffness:g} N m/rad, {model.passive.convention} convention",
    )


def _physical(model: Model, k: float) -> Model:
    """``model`` with passive stiffness k per joint, physical convention."""
    from ...model import config

    return config.set_parameters(model, {"passive.stiffness": float(k), "passive.convention": "physical"})


def _global_alone(model: Model, e: float, lam: float, k: float):
    """Problem (b) at passive stiffness k."""
    from ...optimise.coupled.global_pcsa import min_global_pcsa

    return min_global_pcsa(_physical(model, k), e, lam)


def _passive_point(model: Model, e: float, lam: float, k: float, optimum: np.ndarray):
    """(global PCSA alone [m^2], its status, least local stiffness at the global PCSA ``optimum`` [N m/rad])."""
    from ...optimise.coupled.local import least_local_stiffness

    alone = _global_alone(model, e, lam, k)
    local = np.full(len(model.geometry.cor_names), np.nan)
    if np.all(np.isfinite(optimum)):
        local = least_local_stiffness(_physical(model, k), e, lam, optimum, given=False).local_stiffness
    return alone.total_pcsa, alone.status, np.asarray(local, float)


def _threshold(model: Model, e: float, lam: float, ks: np.ndarray, feasible: np.ndarray) -> float:
    """The least K where (b) is feasible: bisection between the scan's last infeasible and first feasible K."""
    order = np.argsort(ks)
    ks, feasible = ks[order], feasible[order]
    if not feasible.any():
        return np.nan
    i = int(np.argmax(feasible))
    if i == 0:
        return float(ks[0])
    lo, hi = float(ks[i - 1]), float(ks[i])
    while hi - lo > THRESHOLD_TOLERANCE:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if np.isfinite(_global_alone(model, e, lam, mid).total_pcsa) else (mid, hi)
    return hi
