"""The fast path equals the per-point reference, and failures fall back per point."""

from __future__ import annotations

import dataclasses
import types

import numpy as np
import pytest

from spinectl import optimise
from spinectl.model.mechanics import segment_coefficients
from spinectl.model.params import Passive
from spinectl.optimise import stacked

RTOL = 1e-6
"""The agreement the fast path promises (docs/optimisation.md, "Benchmark"): 1e-6 relative (to each point's
total PCSA or ||CT||, at least 1 N m)."""

GRID = np.linspace(0.0, 0.08, 5)


def _data(model):
    E, L = np.meshgrid(GRID, GRID, indexing="ij")
    return optimise.problem_data(model, segment_coefficients(model, E.ravel(), L.ravel()))


def _assert_same(fast, ref):
    assert np.array_equal(np.isnan(fast.min_pcsa), np.isnan(ref.min_pcsa))
    ok = np.isfinite(ref.min_pcsa)
    same = (fast.status == ref.status) | (np.isin(fast.status, optimise.OK_STATUSES) & ok)
    assert same.all()
    scale = ref.min_pcsa[ok]
    np.testing.assert_array_less(np.abs(fast.min_pcsa[ok] - scale), RTOL * scale)
    np.testing.assert_array_less(np.abs(fast.pcsa[ok] - ref.pcsa[ok]).max(axis=1), RTOL * scale)
    ct_scale = np.maximum(np.linalg.norm(ref.counter_torque[ok], axis=1), 1.0)
    np.testing.assert_array_less(np.abs(fast.counter_torque[ok] - ref.counter_torque[ok]).max(axis=1), RTOL * ct_scale)


def _variants(model):
    opt = model.optimisation
    return {
        "paired": model,
        "independent": model.replace(optimisation=dataclasses.replace(opt, activation="independent")),
        "bounded": model.replace(optimisation=dataclasses.replace(opt, pcsa_max=12e-4)),
        "K15-paper": model.replace(passive=Passive(15.0, "paper")),
    }


@pytest.mark.parametrize("variant", ["paired", "independent", "bounded", "K15-paper"])
def test_fast_path_equals_the_reference(model, variant):
    m = _variants(model)[variant]
    data = _data(m)
    fast = stacked.solve_stacked(data, m.optimisation.ct_tolerance)
    ref = stacked.solve_points(data, m.optimisation.ct_tolerance)
    assert fast.per_point == 0 and ref.per_point == len(GRID) ** 2
    _assert_same(fast, ref)
    if variant == "bounded":  # the bound makes the symmetric corner infeasible: both paths say so
        assert "infeasible" in set(fast.status) and "optimal" in set(fast.status)


@pytest.mark.parametrize("variant", ["paired", "bounded"])
def test_min_pcsa_only_gives_the_same_minimum(model, variant):
    """Stage 1 alone (the calibration's K = 15 landscapes) gives the full path's minimum PCSA, infeasible
    points included; its activation is a minimum-PCSA one (total equal to the minimum)."""
    m = _variants(model)[variant]
    data = _data(m)
    full = stacked.solve_stacked(data, m.optimisation.ct_tolerance)
    first = stacked.solve_stacked(data, m.optimisation.ct_tolerance, min_pcsa_only=True)
    assert list(first.status) == list(full.status)
    np.testing.assert_allclose(first.min_pcsa, full.min_pcsa, rtol=RTOL, equal_nan=True)
    np.testing.assert_allclose(first.pcsa.sum(axis=1), first.min_pcsa, rtol=RTOL, equal_nan=True)


def test_a_failing_block_falls_back_to_the_reference(model, monkeypatch):
    data = _data(model)
    ref = stacked.solve_points(data, model.optimisation.ct_tolerance)

    def broken(*args, **kwargs):
        return optimise.SOLVER_ERROR, np.full((len(args[1]), np.shape(args[1])[-1]), np.nan)

    monkeypatch.setattr(stacked, "stacked_qp", broken)
    fast = stacked.solve_stacked(data, model.optimisation.ct_tolerance)
    assert fast.per_point == len(GRID) ** 2
    _assert_same(fast, ref)


def test_an_inaccurate_block_is_polished_not_redone(model, monkeypatch):
    """Clarabel's 'almost solved' answer, 1e-7 off, polishes to the exact optimum point by point."""
    data = _data(model)
    ref = stacked.solve_points(data, model.optimisation.ct_tolerance)
    exact_solver = stacked.stacked_qp
    rng = np.random.default_rng(1)

    def sloppy(*args, **kwargs):
        status, x = exact_solver(*args, **kwargs)
        return "optimal_inaccurate", x + rng.normal(0, 1e-7, x.shape) * (status == "optimal")

    monkeypatch.setattr(stacked, "stacked_qp", sloppy)
    fast = stacked.solve_stacked(data, model.optimisation.ct_tolerance)
    assert fast.per_point < len(GRID) ** 2 // 2
    _assert_same(fast, ref)


def test_a_raising_solver_is_an_unsolved_block(model, monkeypatch):
    """Clarabel raising (bad data, a panic) must not escape: the block goes to the reference."""

    class Exploding:
        def __init__(self, *args, **kwargs):
            raise RuntimeError("simulated panic")

    stacked_only = types.SimpleNamespace(**{**vars(stacked.clarabel), "DefaultSolver": Exploding})
    monkeypatch.setattr(stacked, "clarabel", stacked_only)  # cvxpy's own Clarabel, for the reference, still works
    data = _data(model)
    fast = stacked.solve_stacked(data, model.optimisation.ct_tolerance)
    assert fast.per_point == len(GRID) ** 2 and set(fast.status) == {"optimal"}
