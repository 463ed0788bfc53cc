"""The numbers of docs/chain.md and docs/reproduction.md generated at the build (docs/_ext/spinectl_docs) are
those of the computations the pages describe, and the words around them hold.

Each referee computes the same quantity by another route than the generator's: the narrow band from the chain's
coefficients as tests/reflex/test_mimo.py builds it, the landscape's largest chain margin from one point's
coupled analysis, the Pareto front's kink from the joint optimum.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from spinectl.model.config import load_preset, set_parameters

DOCS = Path(__file__).resolve().parents[2] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
from spinectl_docs import chain, reproduction  # noqa: E402
from spinectl_docs.values import text_of  # noqa: E402


def _band_by_coefficients(local_damping: float):
    """tests/reflex/test_mimo.py's construction of the narrow-band case (K and D from the chain's coefficients,
    the rule's gains times 1 - f), with the local muscles' damping c_loc f k* on D's diagonal."""
    from spinectl.model import chain as mchain
    from spinectl.model import geometry
    from spinectl.optimise.coupled import least_local_stiffness_stacked
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.gains import chain_gains
    from spinectl.reflex.mimo import chain_delay_margin

    model = set_parameters(load_preset("wagner2012"), {"body.mass": 35, "passive.stiffness": 10})
    (e, lam), f, r = chain.BAND_POINT, chain.BAND_FRACTION, model.reflex
    pcsa = chain.BAND_ACTIVATION * np.asarray(solve_point(model, e, lam).pcsa, float)
    coefficients = mchain.chain_coefficients(model, e, lam)
    mass = mchain.mass_matrix(model, geometry.cor_positions(e, lam, model.geometry))
    stiffness, damping = coefficients.stiffness(pcsa), coefficients.damping(pcsa)
    least = least_local_stiffness_stacked(stiffness[None], model.optimisation.stability_margin)[1][0]
    kp, kd = chain_gains(mass, stiffness, damping, least, r.gain_factor, r.damping_ratio)
    damping = damping - local_damping * f * np.diag(least)
    return chain_delay_margin(mass, stiffness - f * np.diag(least), damping, (1 - f) * kp, (1 - f) * kd,
                              r.activation_time_constant)  # fmt: skip


def test_chain_md_narrow_band_is_the_case_of_the_mimo_test_and_needs_springs_only():
    """The page's crossings (two, 0.035 % apart when written), their spread and the margin are those of the case
    built as tests/reflex/test_mimo.py builds it (to the printed digits); with the local muscles' damping
    (``local.damping`` = 1) the band is gone, which is why the page says "as springs only"."""
    exact = _band_by_coefficients(0.0)
    crossings = np.sort(exact.crossovers)
    assert text_of("chain.band_crossings") == " and ".join(f"{w:.2f}" for w in crossings)
    assert text_of("chain.band_margin") == f"{1e3 * exact.margin:.3g}"
    assert float(text_of("chain.band_apart")) == pytest.approx(100 * (crossings[1] / crossings[0] - 1), rel=0.02)
    assert _band_by_coefficients(1.0).status == "delay_independent"


def test_reproduction_md_landscape_margin_is_a_points_coupled_margin_and_guards_its_words(monkeypatch):
    """The landscape's largest chain margin (``spinectl sweep``'s ``coupled_margin_Nm_per_rad`` on the paper's
    1 mm grid) is, at its point, the least eigenvalue of -K of ``stability --coupled`` there (a per-point
    computation); a landscape with a stable point fails the build, since the page says "at every point"."""
    from spinectl.model.chain import coupled_margin
    from spinectl.optimise.coupled.at_activation import coupled_stability_at

    margins = reproduction.chain_margins()
    top = margins.where(margins == margins.max(), drop=True)
    e, lam = (float(top[name][0]) for name in top.dims)
    k = coupled_stability_at(load_preset("wagner2012"), e, lam).chain.stiffness_offset
    assert text_of("reproduction.chain_margin_max") == f"{coupled_margin((k + k.T) / 2):.0f}".replace("-", "\u2212")

    monkeypatch.setattr(reproduction, "chain_margins", lambda: margins.copy(data=np.abs(margins.values)))
    with pytest.raises(RuntimeError, match="unstable at every point"):
        text_of("reproduction.chain_margin_max")


def test_chain_md_pareto_front_words_hold():
    """docs/chain.md's Pareto paragraph: the joint optimum (w_local = 1) sits at the kink, within 1 % of the first
    feasible point's local stiffness, and the front is steeper below it than beyond (the generated words); the
    front's first feasible point is the SDP at its own budget."""
    from spinectl.optimise.coupled.data import coupled_data, result
    from spinectl.optimise.coupled.joint import least_global_within_budget_sdp

    g, k = chain._front()
    assert np.sum(chain.joint().local_stiffness) == pytest.approx(k[0], rel=0.01)
    assert text_of("chain.pareto_inner_steeper") == "steeper" and chain._inner_rate() < chain._beyond_rate()
    model = load_preset("wagner2012")
    again = result(model, coupled_data(model, 0.0, 0.0), 0.0, 0.0,
                   *least_global_within_budget_sdp(coupled_data(model, 0.0, 0.0), float(k[0])))  # fmt: skip
    assert text_of("chain.pareto_first_global") == f"{1e4 * again.total_pcsa:.2f}"


def test_reproduction_md_lordosis_reading_is_the_chains_least_local_stiffness_there():
    """At E = 3 cm and the Lambda of the least counter torques (the sweep's), the page's local stiffness is the
    least local stiffness of ``stability --coupled`` at that point (a per-point SDP, not the sweep's chunk), between
    the least and the most over Lambda that the page compares it with."""
    from spinectl.optimise.coupled.at_activation import coupled_stability_at

    row = reproduction.lordosis_sweep("wagner2012")
    at = coupled_stability_at(load_preset("wagner2012"), reproduction.OPTIMUM[0], row["at"][0] / 100)
    assert text_of("reproduction.lordosis_local") == f"{np.sum(at.local.local_stiffness):.0f}"
    assert row["least"][1] <= row["at"][1] <= row["most"][1]
