"""``FigureOptions(lordosis_axis='angle')`` (``spinectl plot --lordosis-axis angle``): the landscapes ticked in degrees.

The second reading is the natural spline's closed form, Lambda = L tan(theta / 2) / 3 (docs/atlas.md).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from spinectl.errors import ParameterError
from spinectl.landscape import sweep
from spinectl.model.config import load_config
from spinectl.paper import figures


@pytest.fixture(scope="module")
def landscape():
    model = load_config(None)
    axis = np.linspace(0.0, 0.08, 5)
    return model, sweep.sweep(model, axis, axis)


def _lordosis_axes(drawn):
    return [ax for fig in drawn.values() for ax in fig.axes if "lordosis" in ax.get_ylabel()]


def test_angle_ticks_sit_at_the_closed_form(landscape):
    """Every landscape's lordosis axis is labelled in degrees, 0, 10, ..., 100 over 0-8 cm (8 cm is
    2 atan(3 x 0.08 / L) = 107.4 deg), each tick at L tan(theta / 2) / 3 in cm to 1e-10; the limits stay."""
    model, dataset = landscape
    plain = _lordosis_axes(figures.figure_set(dataset))
    angled = _lordosis_axes(figures.figure_set(dataset, options=figures.FigureOptions(lordosis_axis="angle")))
    assert angled and len(angled) == len(plain)
    length = model.geometry.spine_length
    for ax, before in zip(angled, plain, strict=True):
        assert ax.get_ylabel() == "lordosis angle θ [deg]" and ax.get_ylim() == before.get_ylim()
        labels = [float(t.get_text()) for t in ax.get_yticklabels()]
        assert labels == [10.0 * i for i in range(11)]
        expected = [100.0 * length * math.tan(math.radians(t) / 2.0) / 3.0 for t in labels]
        np.testing.assert_allclose(ax.get_yticks(), expected, rtol=0, atol=1e-10)


def test_unknown_lordosis_axis_is_refused():
    with pytest.raises(ParameterError, match="--lordosis-axis: must be one of lambda, angle"):
        figures.FigureOptions(lordosis_axis="degrees")
