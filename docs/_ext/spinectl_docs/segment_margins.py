"""``docs/reflex.md``'s delay margins joint by joint, measured at the build.

``spinectl margins --preset P --E 0.03 --Lambda 0.04 --activation A --activation-lag T_a`` is
:func:`spinectl.reflex.margins.margins_report` on the preset with ``reflex.activation`` = A and
``reflex.activation_time_constant`` = T_a (the command's aliases): the page's three tables (the lag's cost on
``default``, and each preset at the activations of the page with its default lag, the lagless margin beside) and
the sentences that read them. Each report is a closed form per segment (milliseconds); about 2 s of CPU in all.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value

POSITION = (0.03, 0.04)
"""E and Lambda [m] of the tables."""

LAGS = (0.0, 0.05, 0.1)
"""T_a [s] of the lag's table."""

ACTIVATIONS = (0.0, 0.5, 0.8, 1.0)
"""``--activation`` of the presets' tables."""

LAG = 0.05

PRESETS = ("default", "wagner2012")
"""The presets' own T_a [s] (``reflex.activation_time_constant``), the presets' tables' lag."""


@cache
def report(preset: str, activation: float, lag: float, position: tuple = POSITION):
    """``spinectl margins --preset P --E e --Lambda lam --activation A --activation-lag T_a``."""
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.reflex.margins import margins_report

    changes = {"reflex.activation": activation, "reflex.activation_time_constant": lag}
    return margins_report(set_parameters(load_preset(preset), changes), *position)


def margins(preset: str, activation: float, lag: float, position: tuple = POSITION) -> np.ndarray:
    """The exact delay margins [s], L1L2 to L5S1 (inf: any delay)."""
    return np.array([s.delay_margin for s in report(preset, activation, lag, position).segments])


def seconds(margin: float) -> str:
    """A margin as the tables print it: '0.101 s' or 'unbounded'."""
    return "unbounded" if np.isinf(margin) else f"{margin:.3f} s"


def _header(first: str) -> list[str]:
    names = [s.name for s in report("default", 0.0, 0.0).segments]
    columns = first.count("|") + 1 + len(names)
    return [f"| {first} | " + " | ".join(names) + " |", "| " + " | ".join(["---"] * columns) + " |"]


def lag_table() -> str:
    """``default`` at activation 0 and 0.5 with T_a = 0, 0.05 and 0.1 s."""
    lines = _header("activation | T_a [s]")
    for activation in (0.0, 0.5):
        for lag in LAGS:
            cells = " | ".join(seconds(m) for m in margins("default", activation, lag))
            lines.append(f"| {activation:g} | {lag:g} | {cells} |")
    return "\n".join(lines) + "\n"


def _cell(lagged: float, lagless: float) -> str:
    """'0.057 s (0.101)': the margin with the lag, without it in parentheses where it differs."""
    text = seconds(lagged)
    return text if seconds(lagless) == text else f"{text} ({lagless:.3f})"


def preset_table(preset: str) -> str:
    """The preset at :data:`ACTIVATIONS` with its lag, the lagless margin in parentheses."""
    lines = _header("activation")
    for activation in ACTIVATIONS:
        pairs = zip(margins(preset, activation, LAG), margins(preset, activation, 0.0), strict=True)
        lines.append(f"| {activation:g} | " + " | ".join(_cell(*pair) for pair in pairs) + " |")
    return "\n".join(lines) + "\n"


def stepan(lag: float) -> float:
    """The exact margin [s] of a Stépán-type segment (theta = S = 1, D = 0, k_p = 1.5, k_d = 1.2)."""
    from spinectl.reflex.delay import delay_margin

    return float(delay_margin([1.0], [0.0], [1.0], [1.5], [1.2], lag).margin[0])


def spine(preset: str, activation: float, lag: float) -> float:
    """The least margin over the joints [s]."""
    return float(np.min(margins(preset, activation, lag)))


def lag_cost() -> float:
    """The median fall of the finite margins of both presets' tables from T_a = 0 to their lag [s]."""
    with np.errstate(invalid="ignore"):  # unbounded less unbounded: NaN, left out
        falls = np.concatenate([margins(p, a, 0.0) - margins(p, a, LAG) for p in PRESETS for a in ACTIVATIONS])
    return float(np.median(falls[np.isfinite(falls)]))


def _phase(preset: str, activation: float, lag: float) -> float:
    """The phase margin [deg] at the configured delay of the joint with the least delay margin."""
    segments = report(preset, activation, lag).segments
    return float(min(segments, key=lambda s: s.delay_margin).phase_margin_deg)


def _times() -> str:
    """'more than triples': the half co-contraction's least margin over the reflex-only one, both with the lag."""
    ratio = spine("default", 0.5, LAG) / spine("default", 0.0, LAG)
    for n, word in ((3, "triples"), (2, "doubles")):
        if ratio > n:
            return f"more than {word}"
    return f"multiplies by {ratio:.1f}"


def _listed(values) -> str:
    """'0.195, 0.251, 0.392, 0.970 s and unbounded' (the finite ones in s, then the unbounded)."""
    finite = [f"{m:.3f}" for m in values if np.isfinite(m)]
    unbounded = int(np.sum(np.isinf(values)))
    texts = ([", ".join(finite) + " s"] if finite else []) + ["unbounded"] * unbounded
    return ", ".join(texts[:-1]) + " and " + texts[-1] if len(texts) > 1 else texts[0]


value("reflex.stepan_margins")(lambda: f"{stepan(0.0):.3f} s to {stepan(0.1):.3f} s")
value("reflex.spine_lag_margins")(lambda: f"{spine('default', 0.0, 0.0):.3f} s to {spine('default', 0.0, LAG):.3f} s")
value("reflex.wagner_half_lagged")(lambda: _listed(margins("wagner2012", 0.5, LAG)))
value("reflex.spine_lag_34")(lambda: f"{spine('default', 0.0, LAG):.3f} and {spine('default', 0.0, 0.1):.3f} s")
value("reflex.l1l2_origin_lags")(
    lambda: (
        ", ".join(f"{margins('wagner2012', 0.5, t, (0.0, 0.0))[0]:.3f}" for t in LAGS[:-1])
        + f" and {margins('wagner2012', 0.5, LAGS[-1], (0.0, 0.0))[0]:.3f} s"
    )
)
value("reflex.lag_cost")(lambda: f"{lag_cost():.3f} s")
value("reflex.reflex_only_ms")(lambda: f"{1e3 * spine('default', 0.0, 0.0):.0f} ms")
value("reflex.reflex_only_phase")(lambda: f"{_phase('default', 0.0, 0.0):.1f}°")
value("reflex.reflex_only_lag_ms")(lambda: f"{1e3 * spine('default', 0.0, LAG):.0f} ms")
value("reflex.half_times")(_times)
value("reflex.wagner_l1l2_half")(
    lambda: f"{margins('wagner2012', 0.5, LAG)[0]:.3f} s, {margins('wagner2012', 0.5, 0.0)[0]:.3f} s"
)
