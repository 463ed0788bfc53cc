"""The numbers of ``docs/chain.md`` (and atlas.md's) that ``stability --coupled`` and ``design --passive`` give.

The chain at the paper's optimum at four points (both presets, A and (3, 4) cm), and the chain against the
passive stiffness at A (``design --passive 0:80:41 --E 0 --Lambda 0``, about five seconds a preset), each
computed once per build and feeding the generated tables and the ``{measured}`chain.*``` values.
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
