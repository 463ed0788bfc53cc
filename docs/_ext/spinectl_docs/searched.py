"""``docs/reflex.md``'s design answers over every reflex's gains and the rule's beside them, measured at the build.

``spinectl design --delay D --E 0.03 --Lambda 0.04 [--gains search]`` on ``wagner2012`` and on the page's 35 kg
subject (``--mass 35 --K 10``, :data:`.reflex.SUBJECT`): the chain's least local stiffness under the reflex rule
and over every diagonal PD reflex (the seeded gain search, :mod:`spinectl.reflex.design.gain_searched`, seed 0
in the library), its certificate and the cost of a margin; joint by joint the answer over every segment's gains.
Each answer is computed once per build (a module-level memo) and feeds every number and printed table drawn
from it. A gain search costs 12-17 s of CPU with one BLAS thread (about a minute of wall time on the 2-core
machine under load), so the build runs only the four of :data:`SEARCHED`: ``wagner2012`` at 40 ms (the printed
table) and the subject at the reaction times of Radebold et al. (2000) and at 120 ms. The rule's answers
(seconds) are at every other delay the page quotes.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .reflex import SUBJECT
from .values import value

POSITION = (0.03, 0.04)
"""E and Lambda [m] of every answer here."""

REACTION = (0.053, 0.07)
"""The trunk muscles' reaction times of Radebold et al. (2000) [s]: agonists off, antagonists on."""

SEARCHED = (("wagner2012", 0.04), ("subject", REACTION[0]), ("subject", REACTION[1]), ("subject", 0.12))
"""The gain searches the build runs: (who, delay [s]), 12-17 s of CPU each (one BLAS thread). Every other answer
here is the rule's alone (seconds)."""

MINUS = "\u2212"


def model(who: str, delay: float):
    """``wagner2012`` (``who`` "wagner2012") or the page's subject (``"subject"``) at the delay [s]."""
    from spinectl.model.config import load_preset, set_parameters

    return set_parameters(load_preset("wagner2012"), {"reflex.delay": delay} | (SUBJECT if who == "subject" else {}))


@cache
def design(who: str, delay: float):
    """``spinectl design --delay D --E 0.03 --Lambda 0.04 [--mass 35 --K 10] [--gains search]`` (search where
    (who, delay) is in :data:`SEARCHED`), with one BLAS thread as the command runs."""
    from spinectl._threads import one_blas_thread
    from spinectl.reflex.design import answer

    with one_blas_thread():
        return answer(model(who, delay), *POSITION, search=(who, delay) in SEARCHED)


def command(who: str, delay: float) -> str:
    """The command line that prints :func:`design`'s answer."""
    subject = " --mass 35 --K 10" if who == "subject" else ""
    search = " --gains search" if (who, delay) in SEARCHED else ""
    return f"spinectl design --delay {delay:g} --E 0.03 --Lambda 0.04{subject}{search}"


def printed(who: str, delay: float, first: str) -> str:
    """The lines of the command's table from the one that starts with ``first`` to the next blank line, in a
    ``text`` block headed by the command: the table as the command prints it, never pasted."""
    lines = design(who, delay).table().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(first))
    block = lines[start : next((i for i in range(start, len(lines)) if not lines[i].strip()), len(lines))]
    return "```text\n$ " + command(who, delay) + "\n...\n" + "\n".join(block) + "\n```\n"


def chain_search_table() -> str:
    """``design --delay 0.04 --gains search`` on ``wagner2012``: the searched answer's lines (the table's line
    ``over diagonal PD gains (<its stages>): ...``, :meth:`GainSearchedDesign.lines`)."""
    return printed("wagner2012", 0.04, "over diagonal PD gains (")


def joint_search_table() -> str:
    """``design --delay 0.12`` on ``wagner2012``: joint by joint, the answer over every segment's gains."""
    from spinectl.reflex.design.joint_searched import SEARCHED_JOINT_REFLEX

    return printed("wagner2012", 0.12, f"over {SEARCHED_JOINT_REFLEX}")


# --- the numbers a sentence quotes ------------------------------------------------------------------------------


def rule(who: str, delay: float):
    """The chain's answer under the reflex rule (a ``ChainDesign``)."""
    return design(who, delay).chain


def search(who: str, delay: float):
    """The chain's answer over every diagonal PD reflex (a ``GainSearchedDesign``)."""
    return design(who, delay).searched


def total(fraction_holder) -> float:
    """The total local stiffness of an answer [N m/rad]."""
    return float(np.sum(fraction_holder.local_stiffness))


def less(who: str, delay: float) -> float:
    """How much less local stiffness the searched answer needs than the rule's [%]."""
    return 100.0 * (1.0 - total(search(who, delay)) / total(rule(who, delay)))


def full_gain_ratio(who: str, delay: float) -> tuple[float, float]:
    """The searched gains as a multiple of the rule's full gains (before the hand-over, summed over the joints):
    (k_p, k_d) [1]. The rule's gains at f are (1 - f) times its full gains."""
    r, s = rule(who, delay), search(who, delay)
    scale = 1.0 - r.fraction
    return float(np.sum(s.kp) / (np.sum(r.kp) / scale)), float(np.sum(s.kd) / (np.sum(r.kd) / scale))


def sci(v: float) -> str:
    """A small number in the page's form: −5.4e−5."""
    mantissa, _, exponent = f"{v:.2g}".partition("e")
    return (mantissa + (f"e{int(exponent)}" if exponent else "")).replace("-", MINUS)


def ms(seconds: float, digits: int = 4) -> str:
    """A delay in ms to ``digits`` decimals."""
    return f"{1e3 * seconds:.{digits}f} ms"


def span(values, fmt: str, unit: str = "") -> str:
    """``a–b`` (or ``a`` where both round alike), smallest first."""
    lo, hi = (format(v, fmt) for v in (min(values), max(values)))
    return (lo if lo == hi else f"{lo}–{hi}") + unit


def percent(v: float) -> str:
    """A share [%] to the unit."""
    return f"{v:.0f} %"


def _reaction(function) -> list:
    return [function("subject", d) for d in REACTION]


def carry_rule() -> str:
    """The share of k* the rule's delayed reflex carries at the reaction times [%]."""
    return span([100 * (1 - rule("subject", d).fraction) for d in REACTION], ".0f", " %")


def carry_search() -> str:
    """The least share of k* a delayed reflex can carry at the reaction times, by the search [%]."""
    return f"{100 * (1 - max(search('subject', d).fraction for d in REACTION)):.0f} %"


@cache
def l1l2_case() -> tuple[float, float]:
    """The issue's joint-by-joint case: at 120 ms (``wagner2012``) L1L2 at 0.6 of its rule co-contraction, with the
    rule's k_p, and with k_d the rule's or 8 N m s/rad: the exact margins with the lag [s]."""
    from spinectl.model.checks import checked_coefficients
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex import gains
    from spinectl.reflex.delay import delay_margin

    at = model("wagner2012", 0.12)
    pcsa = 0.6 * design("wagner2012", 0.12).segments[0].activation * np.asarray(solve_point(at, *POSITION).pcsa, float)
    coefficients = checked_coefficients(at, *POSITION)
    s, d, theta = coefficients.stiffness(pcsa)[0], coefficients.damping(pcsa)[0], coefficients.inertia[0]
    kp, kd = (float(x[0]) for x in gains.resolve_gains([s], [d], [theta], at.reflex))
    lag = at.reflex.activation_time_constant
    margins = delay_margin([s, s], [d, d], [theta, theta], [kp, kp], [kd, 8.0], lag).margin
    return float(margins[0]), float(margins[1])


JOINT_DELAYS = (*REACTION, 0.12, 0.2)
"""The delays [s] of the subject's joint-by-joint answers over every segment's gains (the rule's answers: seconds)."""


def joint_words() -> str:
    """What the subject's joint-by-joint searched answers say beside the rule's, phrased from their values."""
    pairs = [(design("subject", d).joint_searched.activation, design("subject", d).activation) for d in JOINT_DELAYS]
    if max(searched for searched, _ in pairs) == 0:
        return "needs no co-contraction at all at these delays"
    share = max(searched / rule for searched, rule in pairs if rule > 0)
    return f"needs at most {100 * share:.0f} % of the rule's co-contraction at these delays"


@cache
def issue_40ms() -> tuple[float, float, float]:
    """The issue's chain case at 40 ms (``wagner2012``): at 0.9 of the rule's f, the exact margin [s] and the
    rightmost root's Re [1/s] of 0.40 k_p and 0.30 k_d of the rule's full gains, and the exact margin [s] of the
    rule's own hand-over gains, (1 - 0.9 f) of them (``tests/reflex/test_design_gain_searched.py`` recomputes
    them from the model's chain)."""
    from spinectl.reflex.design.roots import SPECTRAL_NODES, rightmost_root
    from spinectl.reflex.mimo import chain_delay_margin

    chain, f = loop("wagner2012", 0.04), 0.9 * rule("wagner2012", 0.04).fraction
    kp0, kd0 = chain.gains(0.0)
    k, d = chain.loop(f)
    lag = chain.lag
    margin = chain_delay_margin(chain.mass, k, d, 0.40 * kp0, 0.30 * kd0, lag).margin
    root = rightmost_root(chain.mass, k, d, 0.40 * kp0, 0.30 * kd0, 0.04, lag, SPECTRAL_NODES).real
    handed = chain_delay_margin(chain.mass, k, d, (1 - f) * kp0, (1 - f) * kd0, lag).margin
    return float(margin), float(root), float(handed)


def loop(who: str, delay: float):
    """The chain at the rule's operating point (its global PCSA, its k*), as the gain search judges it: the
    library's own loop at each local stiffness f k* (``.loop(f)``) and the rule's gains (``.gains(f)``)."""
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design.gain_searched import _Chain

    at = model(who, delay)
    pcsa = at.reflex.activation * np.asarray(solve_point(at, *POSITION).pcsa, float)
    return _Chain(at, *POSITION, pcsa, rule(who, delay).least_static)


def crossing(who: str, delay: float) -> float:
    """The frequency at which the rule's chain design loses stability, its first crossing [rad/s]."""
    from spinectl.reflex.mimo import chain_delay_margin

    chain, c = loop(who, delay), rule(who, delay)
    k, d = chain.loop(c.fraction)
    return float(chain_delay_margin(chain.mass, k, d, c.kp, c.kd, chain.lag).frequency)


def binding(who: str, delay: float) -> tuple[str, str]:
    """Joint by joint under the rule: the segment that sets the common activation, and how the margins ran."""
    answer = design(who, delay)
    first = max(answer.segments, key=lambda s: s.activation)
    shape = "monotone" if all(s.monotone for s in answer.segments) else "not monotone"
    return first.name, shape


def _joint_activation(who: str, delay: float) -> float:
    return design(who, delay).joint_searched.activation


def _kd_range(who: str, delay: float) -> str:
    return span(design(who, delay).joint_searched.kd, ".0f")


def _cost(who: str, delay: float) -> float:
    """What a margin of 1.1 costs the rule's design [N m/rad]."""
    return total(design(who, delay).margin_cost) - total(rule(who, delay))


def cost_words(who: str, delay: float) -> str:
    """What a margin of 1.1 costs the rule's design, from and to [N m/rad]: ``+3.0 N m/rad (223.7 to 226.7)``."""
    more = f"{_cost(who, delay):+.1f}".replace("-", MINUS)
    return f"{more} N m/rad ({total(rule(who, delay)):.1f} to {total(design(who, delay).margin_cost):.1f})"


def _subject_delays(function, fmt: str, delays=(*REACTION, 0.12)) -> str:
    return (
        ", ".join(format(function("subject", d), fmt) for d in delays[:-1])
        + " and "
        + format(function("subject", delays[-1]), fmt)
    )


# the rule's answer at 40 ms and the issue's gains that need less
value("reflex.rule_f_40")(lambda: f"{rule('wagner2012', 0.04).fraction:.4f}")
value("reflex.issue_40_margin")(lambda: ms(issue_40ms()[0], 1))
value("reflex.issue_40_root")(lambda: f"{issue_40ms()[1]:.2f}".replace("-", MINUS))
value("reflex.issue_40_handed")(lambda: ms(issue_40ms()[2], 1))
# the printed table's command; the subject's rule and searched answers
value("reflex.search_command", code=True)(lambda: command("wagner2012", 0.04))
value("reflex.subject_search_command", code=True)(lambda: command("subject", REACTION[0]))
value("reflex.subject_rule_f")(lambda: _subject_delays(lambda w, d: rule(w, d).fraction, ".4f"))
value("reflex.subject_rule_total")(lambda: _subject_delays(lambda w, d: total(rule(w, d)), ".1f"))
value("reflex.subject_search_f")(lambda: _subject_delays(lambda w, d: search(w, d).fraction, ".4f"))
value("reflex.subject_search_total")(lambda: _subject_delays(lambda w, d: total(search(w, d)), ".1f"))
value("reflex.subject_search_less")(lambda: _subject_delays(less, ".0f") + " %")
value("reflex.subject_kp_ratio")(lambda: span([r[0] for r in _reaction(full_gain_ratio)], ".2f"))
value("reflex.subject_kd_ratio")(lambda: span([r[1] for r in _reaction(full_gain_ratio)], ".2f"))
value("reflex.carry_rule")(carry_rule)
value("reflex.carry_search")(carry_search)
value("reflex.carry_search_120")(lambda: percent(100 * (1 - search("subject", 0.12).fraction)))
value("reflex.subject_rule_f_reaction")(lambda: span([rule("subject", d).fraction for d in REACTION], ".2f"))
value("reflex.subject_search_f_reaction")(lambda: span([search("subject", d).fraction for d in REACTION], ".2f"))
# the subject at 120 ms under the rule (the design question's examples and the curve's reading)
value("reflex.subject_f_120")(lambda: f"{rule('subject', 0.12).fraction:.3f}")
value("reflex.subject_f2_120")(lambda: f"{rule('subject', 0.12).fraction:.2f}")
value("reflex.subject_total_120")(lambda: f"{total(rule('subject', 0.12)):.0f}")
value("reflex.subject_static_120")(lambda: f"{np.sum(rule('subject', 0.12).least_static):.0f}")
value("reflex.subject_share_120")(lambda: percent(100 * (1 - rule("subject", 0.12).fraction)))
value("reflex.subject_crossing_120")(lambda: f"{crossing('subject', 0.12):.1f} rad/s")
value("reflex.subject_activation_120")(lambda: f"{design('subject', 0.12).activation:.3f}")
value("reflex.subject_pcsa_120")(lambda: f"{1e4 * design('subject', 0.12).pcsa:.1f} cm²")
value("reflex.subject_binding_120")(lambda: binding("subject", 0.12)[0])
value("reflex.subject_scan_120")(lambda: binding("subject", 0.12)[1])
value("reflex.subject_l5s1_120")(lambda: f"{design('subject', 0.12).segments[-1].activation:.3f}")
# a design sits on its boundary; the searched ones need not; what a margin costs
value("reflex.boundary_margins")(
    lambda: (
        f"{ms(rule('wagner2012', 0.04).delay_margin)} at 40 ms and {ms(rule('wagner2012', 0.12).delay_margin)} "
        "at 120 ms"
    )
)
value("reflex.boundary_roots")(
    lambda: f"{sci(rule('wagner2012', 0.04).max_root_real)} and {sci(rule('wagner2012', 0.12).max_root_real)}"
)
value("reflex.boundary_root_subject")(lambda: sci(rule("subject", 0.12).max_root_real))
value("reflex.searched_margins")(
    lambda: (
        f"{ms(search('wagner2012', 0.04).delay_margin, 2)} at 40 ms and "
        f"{ms(search('subject', REACTION[0]).delay_margin, 2)} at {1e3 * REACTION[0]:.0f} ms"
    )
)
value("reflex.cost_53")(lambda: cost_words("subject", REACTION[0]))
value("reflex.cost_120")(lambda: f"{_cost('subject', 0.12):+.1f}".replace("-", MINUS))
# joint by joint over every segment's gains
value("reflex.l1l2_rule_margin")(lambda: ms(l1l2_case()[0], 1))
value("reflex.l1l2_kd8_margin")(lambda: ms(l1l2_case()[1], 1))
value("reflex.l1l2_verdict")(lambda: "holds" if l1l2_case()[1] >= 0.12 else "does not hold")
value("reflex.subject_joint_search")(lambda: _subject_delays(_joint_activation, ".4f", JOINT_DELAYS))
value("reflex.subject_joint_rule")(lambda: _subject_delays(lambda w, d: design(w, d).activation, ".4f", JOINT_DELAYS))
value("reflex.subject_joint_kd_120")(lambda: _kd_range("subject", 0.12))
value("reflex.subject_joint_words")(joint_words)
