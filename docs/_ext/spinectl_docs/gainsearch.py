"""``docs/chain.md``'s seeded gain search over the chain's diagonal gains and Stépán's single-mode bounds, at the build.

:func:`spinectl.reflex.gain_search.search_gains_at` at position A for each case of :data:`CASES` with the small
budget :data:`BUDGET` (600 exact margins a case, seed 0: 3-6 s of CPU each with one BLAS thread, about 35 s for
the eight), so that the page quotes margins the build found, with the command that reproduces them; the
library's default budget (about 4 500 margins, 30-45 s a case) is not run at the build. Each search's
:class:`~spinectl.reflex.gain_search.ModeBound` (:func:`~spinectl.reflex.gain_search.single_mode_bound`, no
search) gives the bounds.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value

BUDGET = {"population": 5, "generations": 5, "restarts": 2, "restart_evaluations": 150}
"""The search's budget at the build (``search_gains_at``'s keyword arguments)."""

PRESETS = ("default", "wagner2012")
CASES = tuple((p, a, lag) for a in (1.0, 0.5) for lag in (0.05, 0.0) for p in PRESETS)
"""(preset, activation [1], T_a [s]) of each search."""

REFERENCE_DELAY = 0.1
"""The paper's reflex delay of up to 100 ms [s], against which the bounds are set."""


@cache
def found(preset: str, activation: float, lag: float):
    """``search_gains_at(load_preset(preset), 0, 0, activation=..., lag=..., **BUDGET)`` (a ``GainSearch``)."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset
    from spinectl.reflex.gain_search import search_gains_at

    with one_blas_thread():
        return search_gains_at(load_preset(preset), 0.0, 0.0, activation=activation, lag=lag, **BUDGET)


def pair(what, activation: float, lag: float, fmt: str) -> str:
    """``default``'s and ``wagner2012``'s ``what(search)`` [s] in ms: ``0.285 and 0.333``."""
    return " and ".join(format(1e3 * what(found(p, activation, lag)), fmt) for p in PRESETS)


def command() -> str:
    """The call that reproduces the build's search at the optimum with the lag (``default``)."""
    budget = ", ".join(f"{k}={v}" for k, v in BUDGET.items())
    return f'search_gains_at(load_preset("default"), 0, 0, activation=1, {budget})'


def share_of_bound() -> str:
    """The largest margin found as a share of its case's bound: ``a fifth`` style, in per cent."""
    return f"{100 * max(found(*c).margin / found(*c).bound.bound for c in CASES):.0f} %"


def below_reference(lag: float) -> str:
    """How many times the bounds lie below 100 ms, over both presets and activations: ``16 to 34``."""
    ratios = [REFERENCE_DELAY / found(p, a, lag).bound.bound for p in PRESETS for a in (1.0, 0.5)]
    return f"{min(ratios):.0f} to {max(ratios):.0f}"


def pendulum_example() -> str:
    """The lag-alone bound sqrt(T_a^2 + 2/lambda^2) - T_a of ``default``'s binding mode at the optimum, with
    sqrt(2)/lambda: ``2.2 ms at 94/s where sqrt 2/lambda is 15 ms``."""
    from spinectl.reflex.gain_search import pendulum_delay_bound

    rate, lag = found("default", 1.0, 0.05).bound.rate, 0.05
    bound = float(pendulum_delay_bound(rate**2, 1.0, lag))
    return f"{1e3 * bound:.1f} ms at {rate:.0f}/s where √2/λ is {1e3 * np.sqrt(2) / rate:.0f} ms"


def coupling() -> str:
    """The off-diagonal of V^T D V relative to its largest diagonal element, over the cases: ``0.67 to 0.96``."""
    values = [found(*c).bound.coupling for c in CASES]
    return f"{min(values):.2f} to {max(values):.2f}"


def _margin(search) -> float:
    return search.margin


def _bound(search) -> float:
    return search.bound.bound


value("chain.search_call", code=True)(command)
value("chain.search_optimum_lag")(lambda: pair(_margin, 1.0, 0.05, ".3f"))
value("chain.search_optimum")(lambda: pair(_margin, 1.0, 0.0, ".2f"))
value("chain.search_half_lag")(lambda: pair(_margin, 0.5, 0.05, ".3f"))
value("chain.search_half")(lambda: pair(_margin, 0.5, 0.0, ".2f"))
value("chain.search_share_of_bound")(share_of_bound)
value("chain.bound_optimum_lag")(lambda: pair(_bound, 1.0, 0.05, ".2f"))
value("chain.bound_optimum")(lambda: pair(_bound, 1.0, 0.0, ".1f"))
value("chain.bound_half_lag")(lambda: pair(_bound, 0.5, 0.05, ".2f"))
value("chain.bound_half")(lambda: pair(_bound, 0.5, 0.0, ".1f"))
value("chain.bound_rate_default")(lambda: f"{found('default', 1.0, 0.05).bound.rate:.0f}/s")
value("chain.bound_rate_wagner2012")(lambda: f"{found('wagner2012', 1.0, 0.05).bound.rate:.0f}/s")
value("chain.bound_below_100_lag")(lambda: below_reference(0.05))
value("chain.bound_below_100")(lambda: below_reference(0.0))
value("chain.pendulum_example")(pendulum_example)
value("chain.modal_coupling")(coupling)
