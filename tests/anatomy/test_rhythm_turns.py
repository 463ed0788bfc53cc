"""The constrained chain's eigenvalues are per radian of the rhythm's coordinate, which turns the whole chain."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl.anatomy.analyses import analyse  # noqa: E402


def _turns_by_the_equalities(torso, plane: str, independent: str) -> float:
    """1 plus the linear coefficients of MuJoCo's joint equalities that tie the plane's chain joints to the
    independent joint (their slope at the reference posture, where it is 0)."""
    model = torso.engine.model
    chain = set(torso.plane_joints(plane))
    joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, independent)
    total = 1.0
    for e in range(model.neq):
        slaved = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, model.eq_obj1id[e])
        if model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT and model.eq_obj2id[e] == joint and slaved in chain:
            total += model.eq_data[e][1]
    return total


@pytest.mark.parametrize(("plane", "independent"), [("sagittal", "flex_extension"), ("coronal", "lat_bending")])
def test_the_constrained_line_says_what_its_radian_turns(torso, plane, independent):
    """MyoTorso's rhythm: one radian of flex_extension turns the sagittal chain 1 + 0.185 + 0.204 + 0.231 + 0.255 =
    1.875 rad (its joint equalities' slopes); the coronal variant by the same rule. The table's constrained line
    says it is per radian of that coordinate (before: N m/rad, as if per joint), and the JSON has the turn."""
    expected = _turns_by_the_equalities(torso, plane, independent)
    result = analyse(torso, plane, 0.0)
    np.testing.assert_allclose(result.rhythm_turns, [expected], rtol=1e-6)
    line = next(x for x in result.table().splitlines() if x.startswith("the chain constrained by the model's rhythm"))
    assert f"N m/rad per radian of the rhythm's coordinate, not of one joint (one radian of {independent} " in line
    assert f"turns the chain's joints {expected:.3g} rad in all)" in line
    np.testing.assert_allclose(result.to_dict()["constrained"]["chain_turn_rad_per_coordinate_rad"], [expected])
