"""The anatomy figures' data (spinectl/anatomy/drawing.py) checked by geometry, and the figures drawn.

The sagittal plane must be the plane of the flexion-extension joints: the five CoRs lie in it, so
their projected distances equal their 3-D distances (MuJoCo's anchors); its horizontal must point
forward: rectus abdominis lies in front of every CoR, iliocostalis behind. A mode bent by MuJoCo's
kinematics must be a rigid rotation about parallel axes: the lowest CoR stays, and the top segment
(L1_L2 to the thorax's centre of mass) turns by the sum of the mode's joint angles.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.anatomy import drawing, figures


@pytest.fixture(scope="module")
def projection(torso):
    return drawing.sagittal_projection(torso)


def test_the_projection_plane_holds_the_chain_and_faces_forward(torso, projection):
    """Projected CoR spacing = 3-D anchor spacing (to 1e-12 m); rect_abd_r anterior, IL_L1_r posterior of all CoRs."""
    engine = torso.engine
    engine.set_state(torso.posture())
    anchors = engine.data.xanchor[torso.joint_ids(projection.joints)]
    np.testing.assert_allclose(
        np.linalg.norm(np.diff(projection.cors, axis=0), axis=1),
        np.linalg.norm(np.diff(anchors, axis=0), axis=1),
        atol=1e-12,
    )
    front = np.vstack(projection.segments[torso.muscles.index("rect_abd_r")])
    back = np.vstack(projection.segments[torso.muscles.index("IL_L1_r")])
    assert front[:, 0].min() > projection.cors[:, 0].max()
    assert back[:, 0].max() < projection.cors[:, 0].min()
    assert len(projection.segments) == len(torso.muscles) and all(len(s) >= 1 for s in projection.segments)


def test_a_bent_mode_is_a_rotation_about_parallel_axes(torso):
    """For each mode: the lowest CoR does not move, and the top segment's direction turns by sum_j q_j (the angles
    the mode adds, scaled to sum |q_j| = 30 deg): the FE axes are parallel, so the angles add."""
    from spinectl.anatomy.analyses import analyse

    free = analyse(torso, activation=0.05).free
    shapes = drawing.mode_shapes(torso, free)
    assert shapes.bent.shape == (5, 6, 2)
    for k in range(5):
        q = shapes.modes[:, k] * np.radians(shapes.angle_deg) / np.abs(shapes.modes[:, k]).sum()
        np.testing.assert_allclose(shapes.bent[k, 0], shapes.rest[0], atol=1e-12)
        rest, bent = shapes.rest[-1] - shapes.rest[-2], shapes.bent[k, -1] - shapes.bent[k, -2]
        turn = np.arctan2(rest[0] * bent[1] - rest[1] * bent[0], rest @ bent)
        assert abs(turn) == pytest.approx(abs(q.sum()), abs=1e-9)


def test_the_lordosis_figure_leaves_infeasible_postures_as_gaps():
    """A curve with an infeasible posture (NaN cost) is drawn: two panels, three curves each, the gap as NaN."""
    curve = {"lordosis_deg": [-1.0, 0.0, 1.0]}
    for key in ("none", "joints", "chain"):
        curve[key] = {
            "cost": [1.0, np.nan, 2.0],
            "status": ["optimal", "infeasible", "optimal"],
            "margin_Nm_per_rad": [1.0, np.nan, 1.0],
        }
    fig = figures.lordosis_figure(curve)
    top, bottom = fig.axes
    costs = [line.get_ydata() for line in top.lines if len(line.get_xdata()) == 3]
    assert len(costs) == 3 and all(np.isnan(c[1]) for c in costs)


def test_the_lordosis_figure_reads_its_axis_whole_and_says_a_criterion_drawn_nowhere_is_infeasible():
    """The axis label (what the summed angle change means) is wrapped so that no line is wider than the figure's
    text column (before: one line ran past both edges of lordosis.png), the title names the rhythm, not 'the
    lordosis', and a criterion infeasible at every posture (no point drawn: MyoTorso's free chain with no stiffness
    added) says so in its legend entry; a feasible one's entry is its label alone (the variant)."""
    curve = {"lordosis_deg": [-1.0, 0.0, 1.0]}
    for key in ("none", "joints"):
        curve[key] = {"cost": [1.0, 0.5, 2.0], "status": ["optimal"] * 3, "margin_Nm_per_rad": [1.0, 1.0, 1.0]}
    curve["chain"] = {"cost": [np.nan] * 3, "status": ["infeasible"] * 3, "margin_Nm_per_rad": [np.nan] * 3}
    fig = figures.lordosis_figure(curve)
    top, bottom = fig.axes
    assert max(len(line) for line in bottom.get_xlabel().splitlines()) <= 95
    assert "along the rhythm" in top.get_title() and "over the lordosis" not in top.get_title()
    labels = [text.get_text() for text in top.get_legend().get_texts()]
    assert sum(label.endswith(": infeasible at every posture") for label in labels) == 1
    assert not any(label.endswith("infeasible at every posture") for label in labels[:2])
