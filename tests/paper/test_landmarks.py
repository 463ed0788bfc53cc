"""The landmark table and its measurements, on landscapes with known answers."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from spinectl.paper import landmarks

AXIS = np.linspace(0.0, 0.08, 81)


def _landscape(pcsa, torque):
    e, lam = np.meshgrid(AXIS, AXIS, indexing="ij")
    return xr.Dataset(
        {"min_pcsa_cm2": (("E", "Lambda"), pcsa(e, lam)), "counter_torque_norm_Nm": (("E", "Lambda"), torque(e, lam))},
        coords={"E": AXIS, "Lambda": AXIS, "K": 0.0},
    )


def test_ridge_rise_fails_on_a_plateau_and_passes_on_the_paper_rise():
    """A ridge whose top equals A's value (a plateau) does not rise: 0, which disagrees with the paper's
    40/35 - 1 = 0.143; a ridge rising from 35 at A to 40 along Lambda = 1.7 E gives exactly 5/35."""

    def rise(top):
        ds = _landscape(lambda e, lam: top(e) - 1e4 * (lam - 1.7 * e) ** 2, lambda e, lam: 0 * e)
        return next(m for m in landmarks.measure(landmarks.Landmarks(ds)) if m.landmark.name == "ridge_rise")

    plateau, rising = rise(lambda e: 35.0 + 0 * e), rise(lambda e: 35.0 + 5.0 * np.minimum(e / 0.03, 1.0))
    assert plateau.value == 0.0 and not plateau.agrees
    assert rising.value == pytest.approx(5.0 / 35.0, rel=1e-12) and rising.agrees


def test_paper_like_landscape_agrees_with_the_paper():
    """A landscape with the paper's ridge and valley passes those landmarks; K = 15 ones are NaN without data."""
    ds = _landscape(lambda e, lam: 40 - 5e3 * (lam - 1.7 * e) ** 2, lambda e, lam: 2e3 * np.abs(lam - e))
    measured = {m.landmark.name: m for m in landmarks.measure(landmarks.Landmarks(ds))}
    assert measured["ridge_slope"].agrees and measured["ct_valley_slope"].agrees and measured["ct_A"].agrees
    assert np.isnan(measured["halving_K15"].value) and not measured["halving_K15"].agrees


@pytest.mark.parametrize(
    ("relation", "paper", "good", "bad"),
    [("~", 35.0, 40.0, 43.0), ("<", 15.0, 14.9, 15.0), (">", 70.0, 70.1, 70.0), ("=", 0.0, 1e-9, 1e-3)],
)
def test_relations(relation, paper, good, bad):
    mark = landmarks.Landmark("x", paper, relation, "1", "", "", lambda d: 0.0)
    assert mark.agrees(good) and not mark.agrees(bad) and not mark.agrees(np.nan)


def test_every_landmark_says_where_and_how():
    names = [m.name for m in landmarks.LANDMARKS]
    assert len(set(names)) == len(names)
    assert all(m.where and m.how and m.unit and m.relation in "~=<>" for m in landmarks.LANDMARKS)


def test_local_pcsa_of_the_paper_limit():
    """Paper, Discussion: 30 N m at a 7 cm lever arm is about 17 cm^2 (25 N/cm^2): 30/(0.07*25) = 17.1."""
    assert landmarks.local_pcsa_equivalent(30.0, 25e4) * 1e4 == pytest.approx(17.14, abs=0.01)


def test_infeasible_columns_do_not_break_the_measurements():
    """NaN (infeasible) points are skipped; an all-NaN landscape measures NaN, never raises."""
    ds = _landscape(lambda e, lam: 40 - 1e4 * (lam - 1.7 * e) ** 2, lambda e, lam: 1e3 * np.abs(lam - e))
    ds["min_pcsa_cm2"][40:, :] = np.nan
    assert landmarks.line_slope(ds, "min_pcsa_cm2", "max") == pytest.approx(1.7, abs=1e-9)
    empty = ds.copy(data={k: np.full(v.shape, np.nan) for k, v in ds.data_vars.items()})
    measured = landmarks.measure(landmarks.Landmarks(empty, empty, empty))
    assert all(np.isnan(m.value) and not m.agrees for m in measured)


def test_a_landmark_off_the_grid_names_the_grid_point_it_read():
    """11 points (8 mm steps): E = 3 cm is read at 3.2 cm, and the measurement says so.

    ‖CT‖ = 1000 E [N m] here, so the value read is 1000 * 0.032 = 32 N m (not 30);
    on the 1 mm grid 3 cm is a grid point and nothing is added to the label.
    """
    axis = np.linspace(0.0, 0.08, 11)  # 0, 0.8, ..., 8 cm: the grid of reproduce --points 11
    e, lam = np.meshgrid(axis, axis, indexing="ij")
    ds = xr.Dataset(
        {"min_pcsa_cm2": (("E", "Lambda"), 0 * e + 30), "counter_torque_norm_Nm": (("E", "Lambda"), 1e3 * e + 0 * lam)},
        coords={"E": axis, "Lambda": axis},
    )
    coarse = {m.landmark.name: m for m in landmarks.measure(landmarks.Landmarks(ds))}
    optimum = coarse["ct_optimum"]
    assert optimum.value == pytest.approx(32.0)
    assert optimum.off_grid == (((0.03, 0.04), (pytest.approx(0.032), pytest.approx(0.04))),)
    assert "nearest grid point: E = 3.2, Λ = 4 cm for E = 3, Λ = 4 cm" in optimum.how
    assert "E = 3.2 cm for E = 3 cm" in coarse["optimum_lordosis"].how
    assert coarse["ct_A"].off_grid == () and coarse["ct_A"].how == coarse["ct_A"].landmark.how
    fine = landmarks.measure(landmarks.Landmarks(_landscape(lambda e, lam: e, lambda e, lam: e)))
    assert next(m for m in fine if m.landmark.name == "ct_optimum").off_grid == ()
