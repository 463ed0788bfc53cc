"""Two landscapes compared: difference and ratio maps on one grid, a clear error on two (spinectl plot --vs)."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.cli import main
from spinectl.errors import ParameterError
from spinectl.landscape import sweep
from spinectl.model import config
from spinectl.paper import comparison

AXIS = np.linspace(0.0, 0.08, 3)


@pytest.fixture(scope="module")
def two():
    """The calibrated and the anatomical preset on one 3 x 3 grid."""
    return (
        sweep.sweep(config.load_preset("wagner2012"), AXIS, AXIS),
        sweep.sweep(config.load_preset("default"), AXIS, AXIS),
    )


def test_maps_are_the_difference_and_the_ratio(two, monkeypatch):
    """The drawn fields are first - second and first / second, point by point (numpy on the same arrays)."""
    drawn = {}
    monkeypatch.setattr(
        comparison.figures, "landscape_figure", lambda field, title, label, blank=None: drawn.setdefault(title, field)
    )
    figures = comparison.comparison_set(*two, labels=("a.nc", "b.nc"))
    assert sorted(figures) == [
        "counter_torque_difference_K0.png",
        "counter_torque_ratio_K0.png",
        "min_pcsa_difference_K0.png",
        "min_pcsa_ratio_K0.png",
    ]
    a, b = (ds["min_pcsa_cm2"].values for ds in two)
    difference = drawn["minimum PCSA: a.nc minus b.nc, K = 0 N m/rad"]
    ratio = drawn["minimum PCSA: a.nc over b.nc, K = 0 N m/rad"]
    np.testing.assert_allclose(difference.values, a - b)
    np.testing.assert_allclose(ratio.values, a / b)


def test_ratios_over_rounding_noise_are_masked_and_the_title_says_so(two, monkeypatch):
    """At position A (E = Lambda = 0) both presets' ‖CT‖ is 0 up to rounding (the optimum balances gravity
    exactly; of order 1e-15 N m), which made a ratio of 17 that set the colour scale of the whole map. The ratio
    is masked where the second file's ‖CT‖ is at most sqrt(eps) times its largest (numpy's machine epsilon;
    the norm of a least-squares optimum is known to about that), drawn elsewhere as first / second, and the
    title counts the masked point apart from infeasible ones."""
    drawn = {}
    monkeypatch.setattr(
        comparison.figures,
        "landscape_figure",
        lambda field, title, label, blank=None: drawn.setdefault(title, (field, blank)),
    )
    comparison.comparison_set(*two, labels=("a.nc", "b.nc"))
    ratio, blank = drawn["‖CT‖: a.nc over b.nc, K = 0 N m/rad"]
    a, b = (ds["counter_torque_norm_Nm"].values for ds in two)
    level = np.sqrt(np.finfo(float).eps) * np.abs(b).max()
    assert a[0, 0] < level and b[0, 0] < level  # A is rounding noise in both
    noise = b <= level
    assert noise.sum() == 1 and b[~noise].min() > 1e3 * level  # the other points are far above it
    assert np.isnan(ratio.values[noise]).all()
    np.testing.assert_allclose(ratio.values[~noise], a[~noise] / b[~noise])
    assert blank.startswith("white (1 of 9 points): ‖CT‖ of b.nc at rounding level") and "undefined (1)" in blank
    assert "no self-stable activation" not in blank


def test_different_grids_are_refused_naming_the_axis(two):
    other = sweep.sweep(config.load_preset("default"), AXIS, AXIS[:2])
    with pytest.raises(ParameterError, match="--vs: the grids differ in Lambda: 3 value"):
        comparison.check_same_grid(two[0], other)


def test_plot_vs_writes_four_maps_or_one_error_line(tmp_path, capsys):
    for name, preset in (("a.nc", "wagner2012"), ("b.nc", "default"), ("c.nc", "default")):
        grid = "0:0.08:3" if name != "c.nc" else "0:0.08:2"
        assert (
            main(["sweep", "--E", grid, "--Lambda", "0:0.08:3", "--preset", preset, "--out", str(tmp_path / name)]) == 0
        )
    capsys.readouterr()
    assert main(["plot", str(tmp_path / "a.nc"), "--vs", str(tmp_path / "b.nc"), "--out", str(tmp_path / "f")]) == 0
    assert len(capsys.readouterr().out.split()) == 4
    assert main(["plot", str(tmp_path / "a.nc"), "--vs", str(tmp_path / "c.nc"), "--out", str(tmp_path / "g")]) == 2
    err = capsys.readouterr().err
    assert "the grids differ in E" in err and err.count("\n") == 1 and not (tmp_path / "g").exists()
