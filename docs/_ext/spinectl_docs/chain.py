"""The numbers of ``docs/chain.md`` (and atlas.md's) that ``stability --coupled`` and ``design --passive`` give.

The chain at the paper's optimum at four points (both presets, A and (3, 4) cm), and the chain against the
passive stiffness at A (``design --passive 0:80:41 --E 0 --Lambda 0``, about five seconds a preset), each
computed once per build and feeding the generated tables and the ``{measured}`chain.*``` values. Also the
page's other examples, each computed once per build (a few seconds in all): the four points with the levels'
weight in K_g, the Pareto front at A, the narrow crossing band of the exact delay margin and the rule's reflex
on the chain at A (``margins --coupled``). The gain searches of "The delayed reflex on the chain" are not
generated: each costs minutes (the page says its margins are those of runs made when it was written).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value

POINTS = (("default", "A: $E = \\Lambda = 0$", 0.0, 0.0), ("default", "$E = 3$, $\\Lambda = 4$ cm", 0.03, 0.04),
          ("wagner2012", "A", 0.0, 0.0), ("wagner2012", "$E = 3$, $\\Lambda = 4$ cm", 0.03, 0.04))  # fmt: skip
"""The first table's rows: preset, position as the page names it, E and Lambda [m]."""

PASSIVE = np.linspace(0.0, 80.0, 41)
"""The passive stiffnesses of the curve at A [N m/rad] (0 to 80 in 41 steps)."""


@cache
def coupled(preset: str, e: float, lam: float):
    """``spinectl stability --coupled --preset P --E e --Lambda lam``."""
    from spinectl.model.config import load_preset
    from spinectl.optimise.coupled.at_activation import coupled_stability_at

    return coupled_stability_at(load_preset(preset), e, lam)


@cache
def stiffness_only(preset: str, e: float, lam: float):
    """The same with ``local.damping = 0`` (the local muscles as springs only)."""
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.optimise.coupled.at_activation import coupled_stability_at

    return coupled_stability_at(set_parameters(load_preset(preset), {"local.damping": 0.0}), e, lam)


@cache
def passive(preset: str):
    """``spinectl design --passive 0:80:41 --E 0 --Lambda 0 --preset P``."""
    from spinectl.model.config import load_preset
    from spinectl.reflex.design.passive import passive_curve

    return passive_curve(load_preset(preset), 0.0, 0.0, PASSIVE)


def _rank(preset: str, e: float, lam: float) -> int:
    from spinectl.model.chain import chain_coefficients
    from spinectl.model.config import load_preset

    gradient = chain_coefficients(load_preset(preset), e, lam).length_gradient
    return int(np.linalg.matrix_rank(gradient))


def _minus(v: float, fmt: str = ".1f") -> str:
    return (f"{v:+{fmt}}" if v > 0 else f"{v:{fmt}}").replace("-", "\u2212")


def points_table() -> str:
    """The chain at the per-segment optimum: its PCSA, the fibres' rank, the eigenvalues of -K."""
    from spinectl.model.config import load_preset

    lines = [
        "| preset | position | min. PCSA (per segment) | rank $\\partial l/\\partial q$ "
        "| eigenvalues of $-K$ [N m/rad] "
        "| unstable |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for preset, where, e, lam in POINTS:
        c = coupled(preset, e, lam)
        eig = np.linalg.eigvalsh(-(c.chain.stiffness_offset + c.chain.stiffness_offset.T) / 2)
        mass = load_preset(preset).body.mass
        label = f"`{preset}`" + (f" ({mass:.3g} kg)" if e == 0 else "")
        lines.append(
            f"| {label} | {where} | {1e4 * np.sum(c.pcsa):.1f} cm² | {_rank(preset, e, lam)} "
            f"| {', '.join(_minus(v) for v in eig)} | {int(np.sum(eig <= 0))} |"
        )
    return "\n".join(lines) + "\n"


def _damping(eigenvalues) -> tuple:
    """The slowest real part [1/s], the least damping ratio -Re s/abs(s) and that mode's frequency [Hz]."""
    slowest = float(np.max(eigenvalues.real))
    zeta = -eigenvalues.real / np.abs(eigenvalues)
    least = int(np.argmin(zeta))
    return slowest, float(zeta[least]), float(abs(eigenvalues[least].imag) / (2 * np.pi))


def dynamics_table() -> str:
    """The chain's dynamic eigenvalues at the paper's optimum, and with the least local stiffness (damped and not)."""
    lines = [
        "| preset | position | growing modes [1/s] | decaying modes [1/s] | with the least local stiffness |",
        "| --- | --- | --- | --- | --- |",
    ]
    for preset, where, e, lam in POINTS:
        c = coupled(preset, e, lam)
        real = np.sort(c.eigenvalues.real)[::-1]
        growing, decaying = real[real > 0], real[real <= 0]
        damped, springs = _damping(c.local_eigenvalues), _damping(stiffness_only(preset, e, lam).local_eigenvalues)
        stable = "stable" if damped[0] < 0 else "unstable"
        lines.append(
            f"| `{preset}` | {where.split(':')[0]} | {', '.join(f'{v:.1f}' for v in growing)} "
            f"| {', '.join(_minus(v) for v in decaying)} | {stable}; slowest {_minus(damped[0], '.2g')}, least ζ "
            f"{damped[1]:.2f} (stiffness only: {_minus(springs[0], '.2g')}; ζ {springs[1]:.2g} "
            f"at {springs[2]:.0f} Hz) |"
        )
    return "\n".join(lines) + "\n"


def _cm2(m2: float) -> str:
    return f"{1e4 * m2:.2f} cm²" if np.isfinite(m2) else "none (infeasible)"


def _at(curve, k: float):
    i = int(np.argmin(np.abs(curve.passive_stiffness - k)))
    assert abs(curve.passive_stiffness[i] - k) < 1e-9, k  # a point of the scan
    return i


def _from_no_local(curve) -> str:
    total = np.sum(curve.local_stiffness, axis=-1)
    none = np.flatnonzero(total <= 1e-6)
    if not none.size:
        return f"above {curve.passive_stiffness[-1]:g} N m/rad"
    first = curve.passive_stiffness[none[0]]
    return f"{curve.passive_stiffness[none[0] - 1]:g}–{first:g} N m/rad"


def passive_table() -> str:
    """The chain against the passive stiffness at A, both presets."""
    w, d = passive("wagner2012"), passive("default")

    def row(label, cell):
        return f"| {label} | {cell(w)} | {cell(d)} |"

    def global_at(curve, k):
        return curve.global_pcsa[_at(curve, k)]

    def local_at(curve):
        return " / ".join(
            f"{np.sum(curve.local_stiffness[_at(curve, k)]):.1f}".replace(".0", ".0") for k in (0, 20, 40, 80)
        )

    lines = [
        "| | `wagner2012` | `default` |",
        "|---|---|---|",
        row("global muscles alone suffice from $K$ =", lambda c: f"{c.threshold:.2f} N m/rad"),
        f"| least global PCSA alone at $k_\\text{{Crisco}}$ = {w.crisco:.2f} | {_cm2(w.crisco_global_pcsa)} "
        f"| {_cm2(d.crisco_global_pcsa)} |",
        row(
            "least global PCSA alone at 40 / 80 N m/rad",
            lambda c: " / ".join(_cm2(global_at(c, k)).replace(" cm²", "") for k in (40, 80)) + " cm²",
        ),
        row("global PCSA held fixed for (a) (the paper's minimum at the preset's $K$)", lambda c: _cm2(c.paper_pcsa)),
        row("least local stiffness $\\sum_j k_j$ there at $K$ = 0 / 20 / 40 / 80", lambda c: local_at(c) + " N m/rad"),
        row("no local stiffness needed at that PCSA from", _from_no_local),
    ]
    return "\n".join(lines).replace("none (infeasible) / ", "none / ") + "\n"


value("chain.threshold_wagner2012")(lambda: f"{passive('wagner2012').threshold:.2f}")
value("chain.threshold_default")(lambda: f"{passive('default').threshold:.2f}")
value("chain.crisco")(lambda: f"{passive('wagner2012').crisco:.2f}")
value("chain.crisco_global_pcsa")(lambda: f"{1e4 * passive('wagner2012').crisco_global_pcsa:.1f}")
value("chain.stable_mode_range")(
    lambda: "{} to {}".format(
        *(_minus(v, ".0f") for v in sorted(
            np.linalg.eigvalsh(-coupled(p, e, lam).chain.stiffness_offset)[-1] for p, _, e, lam in POINTS
        )[:: len(POINTS) - 1])
    )
)  # fmt: skip
value("chain.local_0_20")(
    lambda: " to ".join(f"{np.sum(passive('wagner2012').local_stiffness[_at(passive('wagner2012'), k)]):.1f}"
                        for k in (0, 20))
)  # fmt: skip
value("chain.local_at_40")(
    lambda: f"{np.sum(passive('wagner2012').local_stiffness[_at(passive('wagner2012'), 40)]):.1f}"
)
value("chain.global_at_40")(lambda: f"{1e4 * passive('wagner2012').global_pcsa[_at(passive('wagner2012'), 40)]:.2f}")
value("chain.paper_pcsa")(lambda: f"{1e4 * passive('wagner2012').paper_pcsa:.2f}")


def _slowest_range() -> str:
    slow = sorted((_damping(coupled(p, e, lam).local_eigenvalues)[0] for p, _, e, lam in POINTS), reverse=True)
    return f"{_minus(slow[0], '.2g')} to {_minus(slow[-1], '.2g')} 1/s ({-1 / slow[-1]:.0f} to {-1 / slow[0]:.0f} s)"


def _zeta_range() -> str:
    zeta = sorted(_damping(coupled(p, e, lam).local_eigenvalues)[1] for p, _, e, lam in POINTS)
    return f"{zeta[0]:.2f}–{zeta[-1]:.2f}"


value("chain.slowest_range")(_slowest_range)
value("chain.zeta_range")(_zeta_range)


def _unstable_range(preset: str, e: float, lam: float) -> str:
    k = coupled(preset, e, lam).chain.stiffness_offset
    eig = np.linalg.eigvalsh(-(k + k.T) / 2)
    bad = eig[eig <= 0]
    return f"{_minus(bad[0])} to {_minus(bad[-1])}"


value("chain.unstable_range_wagner2012_A")(lambda: _unstable_range("wagner2012", 0.0, 0.0))


def _local_total(preset: str, e: float, lam: float, scale: float) -> float:
    """The chain's least local stiffness, summed [N m/rad], with the global muscles at ``scale`` times the
    per-segment minimum PCSA (problem (a); ``stability --coupled --pcsa``)."""
    from spinectl.model.config import load_preset
    from spinectl.optimise.coupled.at_activation import coupled_stability_at

    pcsa = coupled(preset, e, lam).pcsa
    at = coupled(preset, e, lam) if scale == 1 else coupled_stability_at(load_preset(preset), e, lam, scale * pcsa)
    return float(np.sum(at.local.local_stiffness))


def _default_activation() -> float:
    from spinectl.model.config import load_preset

    return load_preset("default").reflex.activation


value("atlas.local_full")(lambda: f"{_local_total('default', 0.03, 0.04, 1.0):.1f}")
value("atlas.local_activation")(lambda: f"{_local_total('default', 0.03, 0.04, _default_activation()):.1f}")
value("atlas.local_zero")(lambda: f"{_local_total('default', 0.03, 0.04, 0.0):.1f}")


@cache
def paper_pairs():
    """``spinectl stability --preset wagner2012 --E 0.03 --Lambda 0.04 --contributions``'s pairs, as a dict."""
    from spinectl import load_preset
    from spinectl.model.contributions import pair_contributions
    from spinectl.model.operating_point import OperatingPoint
    from spinectl.optimise.stabilising import stability_at

    model = load_preset("wagner2012")
    result = stability_at(model, 0.03, 0.04, None, slip_check=False)
    return pair_contributions(OperatingPoint(model, 0.03, 0.04, result.pcsa, slip_check=False)).to_dict()


def _pair(name: str) -> int:
    return paper_pairs()["pairs"].index(name)


value("contributions.chain_index")(lambda: f"{paper_pairs()['muscles']['least_eigenvalue_Nm_per_rad']:.3g}")
value("contributions.outer_share")(lambda: f"{paper_pairs()['chain_share_Nm_per_rad'][_pair('oblique_outer')]:.3g}")


def _outer_cor_shares() -> list:
    return paper_pairs()["cor_share_Nm_per_rad"][_pair("oblique_outer")]


value("contributions.outer_cor_low")(lambda: f"{min(_outer_cor_shares()):.0f}")
value("contributions.outer_cor_high")(lambda: f"{max(_outer_cor_shares()):.0f}")
value("contributions.outer_removed")(
    lambda: f"{paper_pairs()['muscles']['removal']['group:oblique_outer']['percent_change']:.0f}"
)


# --- "The weight of the levels": the four points of the tables with ``levels.weight_in_gravity`` = 1 ---


@cache
def weighted(preset: str, e: float, lam: float):
    """``stability --coupled`` with the levels' full weight in K_g (``--set levels.weight_in_gravity=1``)."""
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.optimise.coupled.at_activation import coupled_stability_at

    return coupled_stability_at(set_parameters(load_preset(preset), {"levels.weight_in_gravity": 1.0}), e, lam)


def _static(c) -> np.ndarray:
    """The eigenvalues of the chain's -K (symmetric part) at the optimum, ascending [N m/rad]."""
    k = c.chain.stiffness_offset
    return np.linalg.eigvalsh(-(k + k.T) / 2)


def _span(values, fmt: str) -> str:
    """``a–b`` from the least to the largest of ``values`` (one value where both print alike)."""
    low, high = f"{min(values):{fmt}}", f"{max(values):{fmt}}"
    return low if low == high else f"{low}–{high}"


def _levels_pairs() -> list:
    """(without, with the levels' weight) ``stability --coupled`` at every point of the tables."""
    return [(coupled(p, e, lam), weighted(p, e, lam)) for p, _, e, lam in POINTS]


def _local_sum(c) -> float:
    return float(np.sum(c.local.local_stiffness))


def _local_change(preset: str) -> str:
    """``391 → 402``: the least local stiffness [N m/rad] at A without and with the levels' weight."""
    return " → ".join(f"{_local_sum(c):.0f}" for c in (coupled(preset, 0.0, 0.0), weighted(preset, 0.0, 0.0)))


def _levels_unstable() -> str:
    """How many modes of -K are unstable with the levels' weight, and whether that is as many as without."""
    counts = [(int(np.sum(_static(a) <= 0)), int(np.sum(_static(b) <= 0))) for a, b in _levels_pairs()]
    if all(a == b == counts[0][0] for a, b in counts):
        return f"{counts[0][0]} modes stay unstable"
    return "the unstable modes go from " + ", ".join(f"{a} to {b}" for a, b in counts)


def _diagonal_shift(preset: str) -> float:
    """The largest change of K's diagonal at A that the levels' weight makes [N m/rad]."""
    a, b = coupled(preset, 0.0, 0.0), weighted(preset, 0.0, 0.0)
    return float(np.max(np.abs(np.diag(b.chain.stiffness_offset) - np.diag(a.chain.stiffness_offset))))


def _mass_eigenvalues(preset: str) -> np.ndarray:
    """The eigenvalues of the chain's M at A [kg m^2], ascending."""
    return np.linalg.eigvalsh(coupled(preset, 0.0, 0.0).mass)


value("chain.levels_diagonal_shift")(lambda: f"{_diagonal_shift('default'):.1f}")
value("chain.mass_range_default")(
    lambda: f"{_mass_eigenvalues('default')[0]:.2g} to {_mass_eigenvalues('default')[-1]:.3g}"
)  # fmt: skip
value("chain.mass_top_wagner2012")(lambda: f"{_mass_eigenvalues('wagner2012')[-1]:.2g}")
value("chain.levels_margin_fall")(
    lambda: _span([_static(a)[0] - _static(b)[0] for a, b in _levels_pairs()], ".1f")
)  # fmt: skip
value("chain.levels_local_rise")(
    lambda: _span([100 * (_local_sum(b) / _local_sum(a) - 1) for a, b in _levels_pairs()], ".0f")
)  # fmt: skip
value("chain.levels_local_default")(lambda: _local_change("default"))
value("chain.levels_local_wagner2012")(lambda: _local_change("wagner2012"))
value("chain.levels_unstable")(_levels_unstable)


# --- "The Pareto front": global PCSA against local stiffness at A ---

PARETO_POINTS = 7
"""Budgets on the front of the page's example (``points`` of :func:`~spinectl.optimise.coupled.joint.pareto_front`)."""

PARETO_INNER = 200.0
"""A budget below the front's kink [N m/rad], where the page reads the front's slope there."""

STIFF = {"passive.stiffness": 100.0}
"""The page's second example: ``default`` with a passive stiffness of 100 N m/rad."""


def _model(preset: str, changes: dict | None = None):
    from spinectl.model.config import load_preset, set_parameters

    return set_parameters(load_preset(preset), changes) if changes else load_preset(preset)


@cache
def pareto(preset: str = "wagner2012", stiff: bool = False):
    """:func:`~spinectl.optimise.coupled.joint.pareto_front` at A, :data:`PARETO_POINTS` budgets."""
    from spinectl.optimise.coupled.joint import pareto_front

    return pareto_front(_model(preset, STIFF if stiff else None), 0.0, 0.0, PARETO_POINTS)


@cache
def pareto_inner():
    """The front of ``wagner2012`` at A at the budget :data:`PARETO_INNER` (the same epsilon-constraint SDP)."""
    from spinectl.optimise.coupled.data import coupled_data, result
    from spinectl.optimise.coupled.joint import least_global_within_budget_sdp

    model = _model("wagner2012")
    return result(model, coupled_data(model, 0.0, 0.0), 0.0, 0.0,
                  *least_global_within_budget_sdp(coupled_data(model, 0.0, 0.0), PARETO_INNER))  # fmt: skip


@cache
def joint():
    """The joint optimum (c) of ``wagner2012`` at A (its ``local.cost_weight``, 1)."""
    from spinectl.optimise.coupled.joint import joint_optimum

    return joint_optimum(_model("wagner2012"), 0.0, 0.0)


def _kappa() -> float:
    """kappa [N m/rad per cm^2] of ``wagner2012``'s local muscles."""
    from spinectl.model.local_muscles import local_stiffness_per_pcsa

    return local_stiffness_per_pcsa(_model("wagner2012")) * 1e-4


def _front() -> tuple:
    """The feasible points of the front: global totals [cm^2] and local totals [N m/rad]."""
    front = pareto()
    ok = np.array([p.status == "optimal" for p in front.points])
    return 1e4 * front.global_total[ok], front.local_total[ok]


def _beyond_rate() -> float:
    """Local stiffness that one cm^2 of global muscle replaces from the first feasible point on [N m/rad/cm^2]."""
    g, k = _front()
    return (k[-1] - k[0]) / (g[0] - g[-1])


def _inner_rate() -> float:
    """The same between the budget :data:`PARETO_INNER` and the first feasible point [N m/rad/cm^2]."""
    g, k = _front()
    return (k[0] - PARETO_INNER) / (1e4 * pareto_inner().total_pcsa - g[0])


def _shape() -> str:
    """How far the feasible points lie from the straight line between the first and the last: 'in a straight
    line' to 0.1 % of the fall, 'almost in a straight line' to 1 %, else 'along a convex curve'."""
    g, k = _front()
    line = g[0] + (g[-1] - g[0]) * (k - k[0]) / (k[-1] - k[0])
    off = np.max(np.abs(g - line)) / (g[0] - g[-1])
    return "in a straight line" if off < 1e-3 else "almost in a straight line" if off < 1e-2 else "along a convex curve"


def _stiff():
    """The front of ``default`` with :data:`STIFF` at A."""
    return pareto("default", True)


def _b0(stiff: bool) -> str:
    return (_stiff() if stiff else pareto()).points[0].status


value("chain.pareto_b0")(lambda: "infeasible" if _b0(False) != "optimal" else "feasible")
value("chain.pareto_first_global")(lambda: f"{_front()[0][0]:.2f}")
value("chain.pareto_first_local")(lambda: f"{_front()[1][0]:.1f}")
value("chain.pareto_first_local_round")(lambda: f"{_front()[1][0]:.0f}")
value("chain.pareto_first_local_pcsa")(lambda: f"{_front()[1][0] / _kappa():.1f}")
value("chain.pareto_shape")(_shape)
value("chain.pareto_last_global")(lambda: f"{_front()[0][-1]:.2g}")
value("chain.pareto_bmax")(lambda: f"{_front()[1][-1]:.0f}")
value("chain.pareto_bmax_pcsa")(lambda: f"{_front()[1][-1] / _kappa():.1f}")
value("chain.pareto_rate")(lambda: f"{_beyond_rate():.0f}")
value("chain.pareto_rate_pcsa")(lambda: f"{_beyond_rate() / _kappa():.1f}")
value("chain.kappa")(lambda: f"{_kappa():.0f}")
value("chain.pareto_inner_global")(lambda: f"{1e4 * pareto_inner().total_pcsa:.2f}")
value("chain.pareto_inner_rate")(lambda: f"{_inner_rate():.0f}")
value("chain.pareto_inner_rate_pcsa")(lambda: f"{_inner_rate() / _kappa():.2f}")
value("chain.pareto_inner_steeper")(lambda: "steeper" if _inner_rate() < _beyond_rate() else "no steeper")
value("chain.joint_global")(lambda: f"{1e4 * joint().total_pcsa:.2f}")
value("chain.joint_local")(lambda: f"{np.sum(joint().local_stiffness):.1f}")
value("chain.pareto_stiff_b0")(lambda: "suffice" if _b0(True) == "optimal" else "do not suffice")
value("chain.pareto_stiff_first")(lambda: f"{1e4 * _stiff().global_total[0]:.2f}")
value("chain.pareto_stiff_last")(lambda: f"{1e4 * _stiff().global_total[-1]:.2g}")
value("chain.pareto_stiff_bmax")(lambda: f"{_stiff().local_total[-1]:.0f}")


# --- "The exact delay margin": the narrow band that the former sweep stepped over ---

BAND = {"body.mass": 35.0, "passive.stiffness": 10.0, "local.damping": 0.0}
"""The case: ``wagner2012``'s subject of docs/reflex.md, the local muscles as springs only."""

BAND_POINT, BAND_ACTIVATION, BAND_FRACTION = (0.03, 0.04), 0.189, 0.9999
"""(E, Lambda) [m], the global muscles' fraction of the minimum PCSA and the local stiffness's of k*."""


@cache
def band():
    """The case's exact delay margin (:func:`spinectl.reflex.mimo.chain_delay_margin`) with the rule's reflex
    times 1 - f (:func:`spinectl.reflex.design.chain.chain_loop_at`), as ``design``'s chain search meets it."""
    from spinectl.model.operating_point import OperatingPoint, chain_at
    from spinectl.optimise.coupled import least_local_stiffness_stacked
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design.chain import chain_loop_at
    from spinectl.reflex.mimo import chain_delay_margin

    model = _model("wagner2012", BAND)
    pcsa = BAND_ACTIVATION * np.asarray(solve_point(model, *BAND_POINT).pcsa, float)
    linear = chain_at(OperatingPoint(model, *BAND_POINT, pcsa, slip_check=False))
    least = least_local_stiffness_stacked(linear.stiffness_offset[None], model.optimisation.stability_margin)[1][0]
    stiffness, damping, kp, kd = chain_loop_at(model, linear, least, BAND_FRACTION)
    return chain_delay_margin(linear.mass_matrix, stiffness, damping, kp, kd, model.reflex.activation_time_constant)


def _band_crossings() -> np.ndarray:
    crossings = np.sort(band().crossovers)
    if band().status != "finite" or crossings.size != 2:
        raise RuntimeError(f"docs/chain.md's narrow band: expected two crossings, found {crossings} ({band().status})")
    return crossings


value("chain.band_crossings")(lambda: " and ".join(f"{w:.2f}" for w in _band_crossings()))
value("chain.band_apart")(lambda: f"{100 * np.ptp(_band_crossings()) / _band_crossings()[0]:.2g}")
value("chain.band_margin")(lambda: f"{1e3 * band().margin:.3g}")


# --- "What it finds": the rule's reflex on the chain at A, exact delay margins ---

RULE_CASES = (("default", 0.5, 0.05), ("default", 0.5, 0.0), ("default", 1.0, 0.05), ("default", 1.0, 0.0),
              ("wagner2012", 0.5, 0.05), ("wagner2012", 1.0, 0.05), ("wagner2012", 1.0, 0.0))  # fmt: skip
"""The table's rows: preset, ``reflex.activation`` [1] and ``reflex.activation_time_constant`` T_a [s]."""


@cache
def rule_margin(preset: str, activation: float, lag: float):
    """``spinectl margins --coupled --E 0 --Lambda 0 --set reflex.activation=A --set
    reflex.activation_time_constant=T``: the exact delay margin of the rule's reflex on the chain."""
    from spinectl.reflex.chain_margins import coupled_margins

    changes = {"reflex.activation": activation, "reflex.activation_time_constant": lag}
    return coupled_margins(_model(preset, changes), 0.0, 0.0).exact


def _rule_cells(exact) -> str:
    if exact.status == "unstable_without_delay":
        return "0 (unstable without delay) | "
    return f"{1e3 * exact.margin:.3f} | {exact.frequency:,.0f}".replace(",", "\u2009")


def margins_table() -> str:
    """The rule's reflex on the chain at A: exact delay margin and crossing frequency per preset, activation, lag."""
    lines = [
        "| preset | activation | $T_a$ [s] | exact delay margin [ms] | at $\\omega$ [rad/s] |",
        "| --- | --- | --- | --- | --- |",
    ]
    for preset, activation, lag in RULE_CASES:
        lines.append(f"| `{preset}` | {activation:g} | {lag:g} | {_rule_cells(rule_margin(preset, activation, lag))} |")
    return "\n".join(lines) + "\n"


def _rule_pair(activation: float, lag: float) -> str:
    """'0.252 and 0.991': the rule's margins [ms] of ``default`` and ``wagner2012`` in one case."""
    return " and ".join(f"{1e3 * rule_margin(p, activation, lag).margin:.3f}" for p in ("default", "wagner2012"))


value("chain.rule_margins_lagless")(lambda: _rule_pair(1.0, 0.0))
value("chain.rule_margins_half")(lambda: _rule_pair(0.5, 0.05))
