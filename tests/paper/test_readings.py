"""Reading a landscape (paper/readings): crest fits and line slopes on landscapes with known answers."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from spinectl.paper import landmarks, readings

AXIS = np.linspace(0.0, 0.08, 81)


def _landscape(pcsa, torque):
    e, lam = np.meshgrid(AXIS, AXIS, indexing="ij")
    return xr.Dataset(
        {"min_pcsa_cm2": (("E", "Lambda"), pcsa(e, lam)), "counter_torque_norm_Nm": (("E", "Lambda"), torque(e, lam))},
        coords={"E": AXIS, "Lambda": AXIS, "K": 0.0},
    )


def test_line_slopes_of_constructed_ridge_and_valley():
    """A ridge along Lambda = 1.7 E and a valley along Lambda = E give exactly those slopes (grid 1 mm)."""
    ds = _landscape(lambda e, lam: 40 - 1e4 * (lam - 1.7 * e) ** 2, lambda e, lam: 1e3 * np.abs(lam - e))
    assert readings.line_slope(ds, "min_pcsa_cm2", "max") == pytest.approx(1.7, abs=1e-9)  # a parabola: exact
    assert readings.line_slope(ds, "counter_torque_norm_Nm", "min") == pytest.approx(1.0, abs=1e-12)


def _ridge_on(points, slope):
    axis = np.linspace(0.0, 0.08, points)
    e, lam = np.meshgrid(axis, axis, indexing="ij")
    pcsa = 40 - 1e4 * (lam - slope * e) ** 2
    return xr.Dataset({"min_pcsa_cm2": (("E", "Lambda"), pcsa)}, coords={"E": axis, "Lambda": axis})


@pytest.mark.parametrize("slope", [1.5, 1.7, 1.97])
def test_crest_slope_does_not_depend_on_the_grid(slope):
    """A parabolic ridge along Lambda = s E: the crest fit returns s on 81 and on 101 points (the vertex of a
    parabola through three grid points is exact), with a standard error of rounding size; the per-column
    grid arg-max alone would be off by up to half a grid step in every column."""
    for points in (81, 101):
        fit = readings.crest_fit(_ridge_on(points, slope), "min_pcsa_cm2", "max")
        assert fit.slope == pytest.approx(slope, abs=1e-9) and fit.uncertainty < 1e-9
        step = 0.08 / (points - 1)
        inside = 0.08 / slope / step  # columns with 0 < s E < 8 cm; the last may round to the edge
        assert inside - 2 <= fit.columns <= inside


def test_crest_fit_follows_the_ridge_from_a_and_reports_its_scatter():
    """A separate maximum beyond the columns where the ridge left the grid is another feature, not the
    ridge (the 101-point grid of wagner2012 has one at E = 7.44 cm); a crest that bends has a scatter."""
    ds = _ridge_on(81, 1.7)
    ds["min_pcsa_cm2"][75, 40] = 100.0  # E = 7.5 cm: far beyond where Lambda = 1.7 E leaves the grid (4.7 cm)
    assert readings.crest_fit(ds, "min_pcsa_cm2", "max").slope == pytest.approx(1.7, abs=1e-9)
    e, lam = np.meshgrid(ds["E"].values, ds["Lambda"].values, indexing="ij")
    bent = ds.assign(min_pcsa_cm2=(("E", "Lambda"), 40 - 1e4 * (lam - 1.7 * e - 20 * e**2) ** 2))
    fit = readings.crest_fit(bent, "min_pcsa_cm2", "max")
    assert fit.slope > 1.7 and fit.uncertainty > 1e-3  # a line through a parabola's crest: residuals of mm


def test_the_landmarks_module_still_offers_the_readings():
    """The readings left paper/landmarks for their own module; the old names there are the same objects."""
    for name in ("at", "grid_point", "label", "CrestFit", "vertex", "crest_fit", "line_slope"):
        assert getattr(landmarks, name) is getattr(readings, name)
