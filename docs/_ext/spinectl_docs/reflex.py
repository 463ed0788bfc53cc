"""The numbers of ``docs/reflex.md``'s margins example that ``spinectl stability`` and ``spinectl margins`` print.

The 35 kg subject (``wagner2012`` with ``body.mass = 35``, ``passive.stiffness = 10``) at E = 3 cm, Lambda = 4 cm
and a 120 ms delay (``margins --delay 0.12 --E 0.03 --Lambda 0.04 --set body.mass=35 --set
passive.stiffness=10``), and ``wagner2012`` at (0, 0) (``stability --E 0 --Lambda 0``), each computed once per
build. The page's design answers (the rule's and the gain searches) are :mod:`.searched`'s; the design against K
and the design curve's readings :mod:`.bends`'.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value

SUBJECT = {"body.mass": 35.0, "passive.stiffness": 10.0}
"""The subject of the page's examples."""


def _model(subject: bool, delay: float | None = None):
    from spinectl.model.config import load_preset, set_parameters

    changes = {**(SUBJECT if subject else {}), **({"reflex.delay": delay} if delay is not None else {})}
    return set_parameters(load_preset("wagner2012"), changes) if changes else load_preset("wagner2012")


@cache
def subject_margins():
    """``spinectl margins --delay 0.12 --E 0.03 --Lambda 0.04 --set body.mass=35 --set passive.stiffness=10``."""
    from spinectl.reflex.chain_verdict import margins_with_chain

    return margins_with_chain(_model(True, 0.12), 0.03, 0.04)


@cache
def stability(subject: bool, e: float, lam: float):
    """``spinectl stability [--mass 35 --K 10] --E e --Lambda lam``: every segment at the minimum PCSA."""
    from spinectl.optimise.stabilising import stability_at

    return stability_at(_model(subject), e, lam)


def slowest(subject: bool, e: float, lam: float) -> float:
    """The slowest time constant of the segments [s] (``stability``'s line)."""
    from spinectl.model.stability import slowest_time_constant

    r = stability(subject, e, lam)
    return float(np.max(slowest_time_constant(r.stiffness, r.damping, r.inertia)))


def _growth_times() -> str:
    from spinectl.reflex.delay import delay_text

    rates = np.real(subject_margins().chain.modes.eigenvalues)
    rates = np.sort(rates[rates > 0])[::-1]
    return f"{delay_text(1 / rates[0], 2)} to {delay_text(1 / rates[-1], 2)}"


value("reflex.subject_l1l2_margin")(lambda: f"{subject_margins().segments[0].delay_margin:.3g} s")


def _chain_margin() -> str:
    exact = subject_margins().chain.exact
    return f"{1e3 * exact.margin:.2g} ms at {exact.frequency:.0f} rad/s"


value("reflex.subject_chain_margin")(_chain_margin)
value("reflex.subject_growth")(_growth_times)
value("reflex.l1l2_stiffness")(lambda: f"{stability(False, 0.0, 0.0).stiffness[0]:.2f}".replace("-", "\u2212"))
value("reflex.l1l2_slowest_00")(lambda: f"{slowest(False, 0.0, 0.0):.0f} s")
value("reflex.l1l2_slowest_subject")(lambda: f"{slowest(True, 0.03, 0.04):.0f} s")


@cache
def stiff_passive():
    """``spinectl design --delay 0.1 --E 0.03 --Lambda 0.04 --K 200`` on ``wagner2012``: where the rule has no
    joint-by-joint design (about 9 s of CPU, one BLAS thread)."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.reflex.design import answer

    model = set_parameters(load_preset("wagner2012"), {"reflex.delay": 0.1, "passive.stiffness": 200.0})
    with one_blas_thread():
        return answer(model, 0.03, 0.04)


def _stiff_largest() -> str:
    from spinectl.reflex.delay import delay_text

    design = stiff_passive()
    if np.isfinite(design.activation):
        raise RuntimeError("docs/reflex.md: design --delay 0.1 --K 200 now has a rule design; the paragraph is stale")
    return delay_text(design.largest_delay)


def _stiff_rule_kd() -> str:
    kd = stiff_passive().joint_searched.rule_kd
    return f"{np.min(kd):.0f}\u2013{np.max(kd):.0f}"


value("reflex.stiff_largest_delay")(_stiff_largest)
value("reflex.stiff_rule_kd")(_stiff_rule_kd)
