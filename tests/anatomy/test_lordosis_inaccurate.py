"""The lordosis curve flags ``optimal_inaccurate`` optima in its table and figure, as ``sweep`` warns of them."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.cli.anatomy_cmd import INACCURATE_MARK, _curve_table


def _curve(chain_status):
    """Three postures; the chain criterion's statuses as given, its least cost (0.5) at the middle one."""
    solved = ["optimal"] * 3
    return {
        "lordosis_deg": [-10.0, 0.0, 10.0],
        "none": {"cost": [0.3, 0.2, 0.3], "status": solved, "margin_Nm_per_rad": [-1.0, -1.0, -1.0]},
        "joints": {"cost": [0.4, 0.3, 0.4], "status": solved, "margin_Nm_per_rad": [-1.0, -1.0, -1.0]},
        "chain": {"cost": [0.6, 0.5, 0.7], "status": chain_status, "margin_Nm_per_rad": [1.0, 1.0, 1.0]},
    }


def test_the_table_marks_inaccurate_optima_and_warns():
    """The middle posture's chain optimum optimal_inaccurate: its cost is marked, the others not, and one WARNING
    line counts it (before: the cost shown as any other); all optimal: no mark, no warning (the variant)."""
    table = _curve_table(_curve(["optimal", "optimal_inaccurate", "optimal"]))
    rows = table.splitlines()
    middle = next(r for r in rows if r.strip().startswith("0 "))
    assert middle.split()[-1] == f"0.5{INACCURATE_MARK}" and INACCURATE_MARK not in middle.split()[-2]
    assert rows[-1].startswith("WARNING: 1 inaccurate (status optimal_inaccurate")
    clean = _curve_table(_curve(["optimal"] * 3))
    assert "WARNING" not in clean and f"0.5{INACCURATE_MARK}" not in clean


def test_the_figure_crosses_inaccurate_optima_and_hollows_their_star():
    """The least-cost star of the chain criterion on an inaccurate optimum is hollow, the point crossed (x) in both
    panels, and the figure's title warns; with every optimum accurate the star is filled and nothing crossed."""
    pytest.importorskip("matplotlib")
    from spinectl.anatomy.figures import lordosis_figure

    def markers(fig):
        top, bottom = fig.axes[:2]
        stars = [ln for ln in top.lines if ln.get_marker() == "*"]
        crosses = [ln for ax in (top, bottom) for ln in ax.lines if ln.get_marker() == "x" and len(ln.get_xdata())]
        return stars, crosses

    fig = lordosis_figure(_curve(["optimal", "optimal_inaccurate", "optimal"]))
    stars, crosses = markers(fig)
    chain_star = next(s for s in stars if np.isclose(s.get_ydata()[0], 0.5))
    assert chain_star.get_markerfacecolor() == "none"
    assert len(crosses) == 2 and all(list(c.get_xdata()) == [0.0] for c in crosses)
    assert "1 inaccurate" in fig._suptitle.get_text()
    fig = lordosis_figure(_curve(["optimal"] * 3))
    stars, crosses = markers(fig)
    assert crosses == [] and all(s.get_markerfacecolor() != "none" for s in stars) and fig._suptitle is None


def test_the_figures_warning_names_only_the_marks_it_draws():
    """The warning said "marked x, a hollow star" where only an x was drawn (an inaccurate optimum that is no
    curve's least cost): it names the hollow star only where one is drawn (figures.inaccurate_marks)."""
    pytest.importorskip("matplotlib")
    from spinectl.anatomy.figures import inaccurate_marks, lordosis_figure

    crossed = lordosis_figure(_curve(["optimal_inaccurate", "optimal", "optimal"]))  # the least cost is accurate
    top = crossed.axes[0]
    assert all(ln.get_markerfacecolor() != "none" for ln in top.lines if ln.get_marker() == "*")
    assert (
        f"marked {inaccurate_marks(0)}:" in crossed._suptitle.get_text() and "star" not in crossed._suptitle.get_text()
    )
    starred = lordosis_figure(_curve(["optimal", "optimal_inaccurate", "optimal"]))  # the least cost inaccurate
    assert f"marked {inaccurate_marks(1)}:" in starred._suptitle.get_text() and "hollow star" in inaccurate_marks(1)
