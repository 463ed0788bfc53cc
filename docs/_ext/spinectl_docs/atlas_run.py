"""``docs/atlas.md``'s "What the shipped atlas finds": the shipped atlas run once at the build.

:func:`result` runs ``spinectl atlas examples/atlas.toml`` in this process through the library function the command
calls (:func:`spinectl.landscape.atlas.run_atlas` of :func:`~spinectl.landscape.priors.load_atlas`; nothing written,
no progress bar) with one BLAS thread, as the command runs; every share, Sobol' index and count of the section is
read from that one :class:`~spinectl.landscape.atlas.AtlasResult`. Its time is not quoted (benchmarks/bench_atlas.py).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value

ROOT = __import__("pathlib").Path(__file__).resolve().parents[3]
ATLAS_FILE = ROOT / "examples" / "atlas.toml"
"""The shipped atlas file the page runs."""

WORDS = {
    "lordosis_angle_deg": "the lordosis angle",
    "eccentricity_m": "the eccentricity E",
    "body.mass": "the mass",
    "body.mass_height": "the mass's height",
    "passive.stiffness": "K",
    "reflex.delay": "the delay",
    "reflex.activation_time_constant": "the activation lag",
    "reflex.activation": "the co-contraction",
}
"""Each prior's parameter as the page names it."""

NAMED = 0.05
"""The least total-order index [-] a ranking names: the parameters below it are summed up as 'the others'."""


@cache
def result():
    """The :class:`~spinectl.landscape.atlas.AtlasResult` of :data:`ATLAS_FILE` and its spec (once per build)."""
    from spinectl._threads import one_blas_thread
    from spinectl.landscape import atlas
    from spinectl.landscape.priors import load_atlas

    spec = load_atlas(ATLAS_FILE)
    with one_blas_thread():
        return atlas.run_atlas(spec, None, progress=False), spec


def _percent(p: float) -> str:
    return f"{100 * p:.1f}".rstrip("0").rstrip(".") if p in (0.0, 1.0) else f"{100 * p:.1f}"


def share(verdict: str) -> str:
    """'98.9 % (98.3–99.3 %)': the share of the cohort's draws where ``verdict`` holds, with its Wilson interval."""
    v = result()[0].probabilities[verdict]
    return f"{_percent(v['p'])} % ({_percent(v['low'])}–{_percent(v['high'])} %)"


def failing(verdict: str) -> str:
    """'1.1 %': the share of the cohort's draws where ``verdict`` fails."""
    return f"{100 * (1 - result()[0].probabilities[verdict]['p']):.1f} %"


def _table(output: str, verdict: bool) -> dict:
    found = result()[0]
    table = (found.sobol_verdicts if verdict else found.sobol)[output]
    if table is None:
        raise RuntimeError(f"docs/atlas.md ranks the Sobol' indices of {output}; the atlas gives none")
    return table


def ranking(output: str, verdict: bool = False) -> str:
    """The parameters of ``output`` with ST >= :data:`NAMED`, by ST: the first with ST and S1, then ST (S1).

    For example 'the mass's height (ST 0.47, S1 0.45), then the mass (ST 0.34, S1 0.33), K (ST 0.12, S1 0.12)
    and the eccentricity E (ST 0.08, S1 0.06); the others' ST at most 0.01'.
    """
    table = _table(output, verdict)
    order = sorted(table, key=lambda name: -table[name]["ST"])
    named = [p for p in order if table[p]["ST"] >= NAMED] or order[:1]
    shown = [f"{WORDS[p]} (ST {table[p]['ST']:.2f}, S1 {table[p]['S1']:.2f})" for p in named]
    text = shown[0] if len(shown) == 1 else f"{shown[0]}, then " + _and(shown[1:])
    rest = [table[p]["ST"] for p in order if p not in named]
    return text + (f"; the others' ST at most {max(rest):.2f}" if rest else "")


def _and(texts: list[str]) -> str:
    return texts[0] if len(texts) == 1 else ", ".join(texts[:-1]) + " and " + texts[-1]


def reflex_st(output: str) -> str:
    """'0.00': the largest ST of the three reflex parameters for ``output`` (the optimum does not involve them)."""
    table = _table(output, False)
    return f"{max(abs(v['ST']) for p, v in table.items() if p.startswith('reflex.')):.2f}"


def margin_nonfinite() -> str:
    """'10 draws, all with `reflex.activation` ≥ 0.9994': where the delay margin is not finite (no indices)."""
    found = result()[0]
    if found.sobol["spine_delay_margin_s"] is not None:
        raise RuntimeError("docs/atlas.md says the delay margin has no Sobol' indices; the atlas gives them")
    bad = ~np.isfinite(found.draws["spine_delay_margin_s"])
    low = float(np.min(found.draws["reflex.activation"][bad]))
    return f"{int(bad.sum())} draws, all with reflex.activation ≥ {np.floor(low * 1e4) / 1e4:.4f}"


def behind_apex() -> str:
    """'34 %': the share of the cohort's draws (Saltelli's A and B rows) with E < Lambda."""
    from spinectl.landscape.atlas import probability_rows

    found, spec = result()
    rows = probability_rows(spec, found.n_evaluations)
    e, lam = found.draws["eccentricity_m"][rows], found.draws["lordosis_m"][rows]
    return f"{100 * np.mean(e < lam):.0f} %"


def run_line() -> str:
    """'N = 1024; eight priors, 10 240 evaluations': the design of the shipped atlas."""
    found, spec = result()
    names = {8: "eight", 7: "seven", 9: "nine"}
    d = len(spec.priors)
    evaluations = f"{found.n_evaluations:,}".replace(",", " ")  # the docs' thin-space thousands
    return f"N = {spec.samples}; {names.get(d, d)} priors, {evaluations} evaluations"


value("atlas.run_line")(run_line)
for _verdict in ("stabilisable_joint_by_joint", "counter_torque_within_limit", "chain_stabilisable_locally",
                 "spine_stable_at_delay"):  # fmt: skip
    value(f"atlas.share.{_verdict}")(lambda v=_verdict: share(v))
for _verdict in ("counter_torque_within_limit", "chain_stabilisable_locally", "spine_stable_at_delay"):
    value(f"atlas.rank_verdict.{_verdict}")(lambda v=_verdict: ranking(v, verdict=True))
value("atlas.failing.chain_stabilisable_locally")(lambda: failing("chain_stabilisable_locally"))
for _output in ("min_pcsa_cm2", "counter_torque_norm_Nm", "cocontraction_local_stiffness_total_Nm_per_rad"):
    value(f"atlas.rank.{_output}")(lambda o=_output: ranking(o))
value("atlas.reflex_st.min_pcsa_cm2")(lambda: reflex_st("min_pcsa_cm2"))
value("atlas.margin_nonfinite")(margin_nonfinite)
value("atlas.behind_apex")(behind_apex)
