"""Joint labels in the anatomy's tables and figures (spinectl.anatomy.naming): the model's name and the level."""

from __future__ import annotations

from spinectl.anatomy.mapping import default_mapping
from spinectl.anatomy.naming import joint_labels


def test_myotorsos_joints_carry_their_level_from_l5s1_up():
    """MyoTorso's mapping lists flex_extension (which turns lumbar5 on the sacrum) then L4_L5_FE ... L1_L2_FE
    (docs/anatomy.md, "The mapping"): each is labelled with the model's name and its level, so that
    flex_extension reads as L5S1 beside L4_L5_FE; in 3d each of the three chains counts from L5S1 again."""
    mapping = default_mapping("myotorso")
    assert joint_labels(mapping.planes["sagittal"], "sagittal") == (
        "flex_extension (L5S1)", "L4_L5_FE (L4L5)", "L3_L4_FE (L3L4)", "L2_L3_FE (L2L3)", "L1_L2_FE (L1L2)",
    )  # fmt: skip
    three = joint_labels(mapping.planes["3d"], "3d")
    assert three[5] == "lat_bending (L5S1)" and three[10] == "axial_rotation (L5S1)" and three[14].endswith("(L1L2)")


def test_a_joint_named_by_its_level_is_not_labelled_twice_and_the_count_goes_on_into_the_thorax():
    """spinectl's export names its joints by level (L5S1 ... L1L2): the label is the name alone. A chain longer
    than the five lumbar levels goes on as T12L1, T11T12 (a model with thoracolumbar joints)."""
    assert joint_labels(["L5S1", "L4L5", "L3L4", "L2L3", "L1L2"], "sagittal") == (
        "L5S1",
        "L4L5",
        "L3L4",
        "L2L3",
        "L1L2",
    )
    assert joint_labels([f"j{i}" for i in range(7)], "coronal")[5:] == ("j5 (T12L1)", "j6 (T11T12)")
