"""The Markdown report: honest about calibration, one table row per landmark."""

from __future__ import annotations

import dataclasses

import numpy as np
import xarray as xr

from spinectl.paper import landmarks, report, verdicts

AXIS = np.linspace(0.0, 0.08, 9)


def _measurements(axis=AXIS):
    e, lam = np.meshgrid(axis, axis, indexing="ij")
    ds = xr.Dataset(
        {"min_pcsa_cm2": (("E", "Lambda"), 60 - 100 * e), "counter_torque_norm_Nm": (("E", "Lambda"), 1e3 * e)},
        coords={"E": axis, "Lambda": axis},
    )
    half = ds.assign(min_pcsa_cm2=ds["min_pcsa_cm2"] / 2)
    return landmarks.measure(landmarks.Landmarks(ds, half, ds))


RUN = report.Run("preset `default`", "physical", "paper", 9, 1.0, ("landscapes.nc", "report.md"), 25e4)


def test_report_is_honest_and_complete():
    measured = _measurements()
    text = report.render(measured, RUN)
    assert "are **not** the calibrated preset" in text and "**calibrated**" not in text
    assert f"{sum(m.agrees for m in measured)} of {len(measured)} landmarks agree" in text
    rows = [line for line in text.splitlines() if line.startswith("| `")]
    assert len(rows) == len(landmarks.LANDMARKS)
    assert all(row.count("|") == 9 for row in rows)  # no stray pipes (e.g. ||CT||) breaking the table
    assert "`physical`" in text and "`paper`" in text and "[`report.md`](report.md)" in text


def test_report_of_the_calibrated_preset_gives_the_documented_verdicts():
    """Each row carries the verdict of docs/reproduction.md; a value that differs from the documented one
    is flagged (these constructed landscapes are not the preset)."""
    measured = _measurements()
    text = report.render(measured, dataclasses.replace(RUN, calibrated=True))
    assert "**calibrated**" in text
    for m in measured:
        row = next(line for line in text.splitlines() if line.startswith(f"| `{m.landmark.name}` |"))
        documented = verdicts.VERDICTS[m.landmark.name]
        assert documented.verdict in row
        assert ("documented for `wagner2012`" in row) == (not documented.holds(m.value))
        if not documented.holds(m.value):  # the run's own agreement comes first, never contradicted
            assert ("this run's value agrees" in row) == m.agrees


def test_halving_names_the_closer_convention():
    """K = 15 halves the landscape exactly with the model's convention (constructed): it is named closer."""
    text = report.render(_measurements(), RUN)
    assert "0.5 of its K = 0 value with the model's `physical` convention" in text
    assert "`physical` comes closer" in text


def test_report_embeds_the_figures_it_links():
    """Every PNG (or SVG) of the run appears as a Markdown image and as a link; other files only as links."""
    files = ("landscapes.nc", "fig3_min_pcsa.png", "figS1_min_pcsa_K15.svg", "report.md")
    text = report.render(_measurements(), dataclasses.replace(RUN, files=files))
    for name in files[1:3]:
        assert f"![{name}]({name})" in text and f"[`{name}`]({name})" in text
    assert "![landscapes.nc]" not in text and "![report.md]" not in text
    assert "No figures were written." in report.render(_measurements(), RUN)


def test_report_names_the_grid_point_of_an_off_grid_landmark():
    """On a 9-point grid (1 cm steps) C on the ridge line, E = 8/1.7 = 4.71 cm, is read at E = 5 cm.

    The report's row says so, and the optimum (3, 4 cm: a grid point) is labelled as it is.
    """
    text = report.render(_measurements(), RUN)
    row = next(line for line in text.splitlines() if line.startswith("| `ct_D_over_C_ridge` |"))
    assert "nearest grid point: E = 5, Λ = 8 cm for E = 4.706, Λ = 8 cm" in row
    assert "E = 3, Λ = 4 cm: 30 N m" in text  # ‖CT‖ = 1000 E at E = 3 cm
    coarse = report.render(_measurements(np.linspace(0.0, 0.08, 11)), RUN)  # reproduce --points 11
    assert "E = 3.2, Λ = 4 cm (nearest grid point to E = 3, Λ = 4 cm): 32 N m" in coarse
