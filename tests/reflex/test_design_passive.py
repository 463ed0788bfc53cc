"""The chain against the passive stiffness (spinectl.reflex.design.passive: passive_curve, crisco_stiffness)."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.errors import ParameterError
from spinectl.model import chain, config
from spinectl.reflex import design as dz
from spinectl.reflex.design import passive


def _margin(model, e, lam, k, pcsa, local=0.0):
    """Smallest eigenvalue of -K of the chain at passive stiffness k, global PCSA and local stiffness [N m/rad]."""
    at = config.set_parameters(model, {"passive.stiffness": float(k), "passive.convention": "physical"})
    return float(chain.coupled_margin(chain.chain_coefficients(at, e, lam).stiffness(pcsa, local)))


def test_crisco_stiffness_is_where_the_passive_chain_under_88_n_buckles():
    """A second method: bisection on the passive stiffness of the smallest eigenvalue of -K of the chain without
    muscles, 88 N on the spine's top (body.mass = 88 N / g at y = spine_length); it changes sign at the returned
    value to 1e-9. About 37.6 N m/rad per joint, the independent audit's value."""
    model = config.load_preset("wagner2012")
    k = dz.crisco_stiffness(model, 0.0, 0.0)
    loaded = dz.passive_chain_model(model)
    none = np.zeros(len(model.muscle_names))
    lo, hi = 0.0, 500.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _margin(loaded, 0.0, 0.0, mid, none) <= 0 else (lo, mid)
    assert k == pytest.approx(hi, abs=1e-9)
    assert k == pytest.approx(37.6, abs=0.1)


def test_the_top_load_is_the_spines_top_not_the_upper_bodys_mass():
    """The load on L1 (y = spine_length = 0.176 m) buckles a stiffer chain than at the top CoR and a softer one than
    at the upper body's mass (0.326 m): the computed stiffness depends on where Crisco's load stands."""
    model = config.load_preset("wagner2012")
    k = dz.crisco_stiffness(model, 0.0, 0.0)
    y = np.asarray(model.geometry.cor_heights)
    hi = np.minimum.outer(np.arange(y.size), np.arange(y.size))

    def at(h):
        """lambda_max of K_g = W (h - y_hi) (docs/chain.md), with the load at height h."""
        return np.linalg.eigvalsh(dz.CRISCO_LOAD * (h - y[hi]))[-1]

    assert k == pytest.approx(at(model.geometry.spine_length), rel=1e-12)
    assert at(y[0]) < k < at(model.body.mass_height)


@pytest.mark.parametrize(("preset", "low", "high"), [("wagner2012", 36.0, 38.0), ("default", 61.0, 63.0)])
def test_global_muscles_alone_stabilise_the_chain_above_a_passive_stiffness(preset, low, high):
    """The threshold (bisection on the feasibility of problem (b)) lies where the independent audit found it:
    36-37 N m/rad per joint for wagner2012 (37.45 here at point A) and 61-63 for default; at the returned global PCSA
    every feasible point's -K has its smallest eigenvalue >= the stability margin (checked with numpy's eigvalsh, not
    the solver), and 0.05 below the threshold (b) is infeasible."""
    model = config.load_preset(preset)
    ks = np.array([low - 2.0, high + 2.0])
    curve = dz.passive_curve(model, 0.0, 0.0, ks)
    assert low <= curve.threshold <= high
    assert np.isnan(curve.global_pcsa[0]) and curve.global_status[0].startswith("infeasible")
    assert not np.isfinite(passive._global_alone(model, 0.0, 0.0, curve.threshold - 0.05).total_pcsa)
    alone = passive._global_alone(model, 0.0, 0.0, ks[1])
    mu = model.optimisation.stability_margin
    assert _margin(model, 0.0, 0.0, ks[1], alone.pcsa) >= mu * (1 - 1e-3)
    assert curve.global_pcsa[1] == pytest.approx(alone.total_pcsa)


def test_at_crisco_stiffness_wagner2012_is_stable_with_global_muscle_alone():
    """At the computed Crisco stiffness the least global PCSA alone (27.6 cm^2 at A; the audit: 27.7 at 37.6) makes
    -K positive definite (numpy's eigenvalues at the returned PCSA), so the headline 'global muscles alone cannot
    stabilise the chain' fails there."""
    model = config.load_preset("wagner2012")
    curve = dz.passive_curve(model, 0.0, 0.0, [0.0])
    alone = passive._global_alone(model, 0.0, 0.0, curve.crisco)
    assert 1e4 * curve.crisco_global_pcsa == pytest.approx(27.6, abs=0.15)
    assert _margin(model, 0.0, 0.0, curve.crisco, alone.pcsa) >= model.optimisation.stability_margin * (1 - 1e-3)


def test_the_least_local_stiffness_falls_with_the_passive_stiffness_and_is_certified():
    """At the fixed global PCSA, -(K - diag(k)) at the returned k has smallest eigenvalue >= mu (numpy), the total
    does not rise as the passive stiffness grows (each joint's passive stiffness replaces local stiffness one for one
    at most), and at K = 0 it is docs/chain.md's 262 N m/rad for wagner2012 at A."""
    from spinectl.optimise.reference import solve_point

    model = config.load_preset("wagner2012")
    ks = np.array([0.0, 20.0, 40.0])
    curve = dz.passive_curve(model, 0.0, 0.0, ks)
    pcsa = solve_point(model, 0.0, 0.0).pcsa
    mu = model.optimisation.stability_margin
    for k, local in zip(ks, curve.local_stiffness, strict=True):
        assert _margin(model, 0.0, 0.0, k, pcsa, local) >= mu * (1 - 1e-3)
    totals = curve.local_stiffness.sum(axis=1)
    assert np.all(np.diff(totals) <= 1e-6) and totals[0] == pytest.approx(261.6, abs=0.5)


@pytest.mark.parametrize("bad", [[-1.0], [np.nan], []])
def test_a_negative_or_missing_stiffness_is_refused(bad):
    """A passive stiffness below 0 or not a number, or none: ParameterError naming --passive."""
    with pytest.raises(ParameterError, match="--passive"):
        dz.passive_curve(config.load_preset("wagner2012"), 0.0, 0.0, bad)


@pytest.fixture(scope="module")
def near_crisco():
    """wagner2012 at A, K = 30 and 40 N m/rad: the threshold (37.45) is bisected next to Crisco's 37.64."""
    return dz.passive_curve(config.load_preset("wagner2012"), 0.0, 0.0, [30.0, 40.0])


def test_the_two_columns_are_at_different_distributions_and_the_note_says_so(near_crisco):
    """At K = 40 global muscles alone need 23.9 cm^2, yet the fixed 36.3 cm^2 still needs about 64 N m/rad of local
    stiffness: the fixed PCSA is the joint-by-joint optimum's distribution (solve_point, mostly outer obliques),
    not problem (b)'s. Recomputed with least_local_stiffness, problem (b)'s own distribution at K = 40 needs no
    local stiffness (< 1e-3 N m/rad), so the columns differ by distribution; the curve keeps the fixed
    distribution (JSON per muscle) and its table and JSON carry a note naming both."""
    from spinectl.optimise.coupled.local import least_local_stiffness
    from spinectl.optimise.reference import solve_point

    model = config.load_preset("wagner2012")
    curve = near_crisco
    optimum = np.asarray(solve_point(model, 0.0, 0.0).pcsa, float)
    alone = passive._global_alone(model, 0.0, 0.0, 40.0)
    own = least_local_stiffness(passive._physical(model, 40.0), 0.0, 0.0, alone.pcsa, given=False).local_stiffness
    assert np.sum(own) < 1e-3 and curve.local_stiffness[1].sum() > 50.0
    assert alone.total_pcsa < curve.paper_pcsa
    np.testing.assert_allclose(curve.fixed_pcsa, optimum)
    doc = curve.to_dict()
    assert list(doc["local_at_pcsa_per_muscle_cm2"]) == list(model.muscle_names)
    assert sum(doc["local_at_pcsa_per_muscle_cm2"].values()) == pytest.approx(doc["local_at_global_pcsa_cm2"])
    note = curve.columns_note()
    assert doc["columns_note"] == note and note in curve.table().splitlines()
    assert "problem (b)" in note and "joint-by-joint minimum, 36.30 cm^2" in note
    # problem (b) said in words where it is named (before: "problem (b)'s own least distribution", undefined)
    assert passive.GLOBAL_ALONE in note and "statically stable with no local muscles" in passive.GLOBAL_ALONE


def test_the_figure_draws_crisco_and_the_threshold_apart_and_names_no_swept_k(near_crisco):
    """Crisco's 37.64 and the threshold 37.45 are 0.2 N m/rad apart: their lines differ in style and width, and
    each value is written at its own height on the top axes. The titles do not state the model's own K (0 here)
    since the x-axis sweeps K; the bottom title names the fixed PCSA's distribution."""
    from spinectl.reflex.design_plots import passive_figure

    curve = near_crisco
    assert abs(curve.threshold - curve.crisco) < 0.5
    fig = passive_figure(curve)
    top, bottom = fig.axes
    lines = {line.get_label(): line for line in top.get_lines() if line.get_label().startswith(("Crisco", "global"))}
    crisco, threshold = (next(v for k, v in lines.items() if k.startswith(w)) for w in ("Crisco", "global"))
    assert (crisco.get_linestyle(), crisco.get_linewidth()) != (threshold.get_linestyle(), threshold.get_linewidth())
    texts = {t.get_text(): t.xy[1] for t in top.texts}
    assert {f"K = {curve.crisco:.1f}", f"K = {curve.threshold:.1f}"} <= set(texts)
    assert texts[f"K = {curve.crisco:.1f}"] != texts[f"K = {curve.threshold:.1f}"]
    titles = [fig.get_suptitle(), top.get_title(), bottom.get_title()]
    assert not any("K = 0" in t for t in titles) and "K swept" in titles[0]
    assert "joint-by-joint minimum" in titles[2]
    assert " ".join(passive.GLOBAL_ALONE.split()) in " ".join(titles[1].split())  # (b) in words on passive.png too
