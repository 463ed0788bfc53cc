"""The explorer's matplotlib views: their data read back from the artists, the PNG export not blank."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread

from spinectl.explore import numbers as nb
from spinectl.explore import views
from spinectl.explore.state import initial_state
from spinectl.paper.landmarks import CT_LIMIT


@pytest.fixture(scope="module")
def numbers():
    from spinectl.model.params import Model

    return nb.point_numbers(Model(), initial_state(Model()))


def test_counter_torque_bars_are_the_counter_torques_inside_the_band(numbers):
    """Bar heights = CT_k [N m]; the band spans -30 to +30 N m (paper, Discussion)."""
    ax = views.counter_torque_plot(numbers).axes[0]
    bars = [p for p in ax.patches if p.get_width() < 1]
    np.testing.assert_allclose([b.get_height() for b in bars], numbers.counter_torque, rtol=1e-12)
    band = next(p for p in ax.patches if p.get_label().startswith("±"))
    np.testing.assert_allclose([band.get_y(), band.get_y() + band.get_height()], [-CT_LIMIT, CT_LIMIT])


def test_eigenvalue_markers_are_the_eigenvalues(numbers):
    """One line of two markers per segment at (Re, Im) of its eigenvalues."""
    ax = views.eigenvalue_plot(numbers).axes[0]
    marks = [line for line in ax.lines if line.get_marker() == "x"]
    assert [m.get_label() for m in marks] == list(numbers.segment_names)
    for line, eigs in zip(marks, numbers.eigenvalues, strict=True):
        np.testing.assert_allclose(line.get_xdata(), eigs.real)
        np.testing.assert_allclose(line.get_ydata(), eigs.imag)


def test_delay_margin_bars_in_ms_and_the_delay_line(numbers):
    """Bars = exact delay margins x 1000 [ms]; the dashed line at the delay tau (0.1 s = 100 ms)."""
    ax = views.delay_margin_plot(numbers).axes[0]
    np.testing.assert_allclose([b.get_height() for b in ax.patches], numbers.delay_margin * 1000, rtol=1e-12)
    assert ax.lines[-1].get_ydata()[0] == pytest.approx(100.0)


def test_state_figure_png_has_six_panels_and_content(numbers):
    """The PNG export: drawing, three views, two landscapes (a small grid), not a blank canvas."""
    dataset = nb.landscapes(numbers.model, numbers.state, points=3)
    fig = views.state_figure(numbers, dataset)
    assert len([ax for ax in fig.axes if ax.get_label() != "<colorbar>"]) == 6
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=40)
    image = imread(io.BytesIO(buffer.getvalue()))
    assert image.std() > 0.05 and len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 50
    bars = [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"]
    # the counter-torque landscape is the paper's Figure 4, at the minimum PCSA: its label says so (the point's
    # panel shows CT at the chosen activation, another quantity)
    assert bars == ["minimum PCSA [cm²]", "‖CT‖ [N m] at the minimum PCSA (Fig. 4)"]
    blank = views.state_figure(numbers, None)
    assert sum(ax.axison for ax in blank.axes) == 4  # the landscapes' places empty while they are solved


def test_the_png_export_names_both_criteria(numbers):
    """The PNG export's delay margins are titled joint by joint; its title gives the chain's verdict with its
    criterion, from PointNumbers.chain_row (itself checked against reflex.chain_verdict in test_numbers)."""
    fig = views.state_figure(numbers, None)
    row = numbers.chain_row()
    title = fig.get_suptitle().splitlines()[-1]
    assert title == (
        f"chain (all 5 CoRs free), the same reflex: stable at τ: {row['stable_at_delay']}, delay margin "
        f"{row['delay_margin_s']} s; without reflex {row['modes']}"
    )
    assert any(ax.get_title().startswith("delay margins, joint by joint") for ax in fig.axes)
