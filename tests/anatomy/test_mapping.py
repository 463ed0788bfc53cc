"""Loading, the mapping and the muscles' classes; bad input as one-line errors."""

from __future__ import annotations

import sys

import pytest

from spinectl.errors import ParameterError

GLOBAL_PREFIXES = (
    "rect_abd_",
    "IL_R12_",
    "QL_ant_I.2-T12",
    "QL_ant_I.3-T12",
    "QL_ant_I.2-12.",
    "QL_ant_I.3-12.",
    "EO5_",
    "EO6_",
    "IO4_",
    "IO5_",
    "IO6_",
)
"""The thorax-pelvis muscles by their anatomy (rectus abdominis, the iliocostalis slip to rib 12, quadratus
lumborum's iliac-to-rib-12 fascicles, external obliques 5-6, internal obliques 4-6), named as in MyoTorso."""


def test_global_muscles_are_the_thorax_pelvis_ones(torso):
    """The global class is exactly the muscles that run from the rib cage to the pelvis by their anatomy."""
    by_name = {m for m, c in zip(torso.muscles, torso.classes, strict=True) if c == "global"}
    assert by_name == {m for m in torso.muscles if m.startswith(GLOBAL_PREFIXES)}


def test_between_muscles_hang_on_the_abdomen(torso):
    """A 'between' muscle has a site on MyoTorso's Abdomen body and none on a vertebra (MuJoCo's site bodies)."""
    from spinectl.anatomy.mapping import muscle_bodies

    names = torso.engine.names("body")
    for bodies, cls in zip(muscle_bodies(torso.engine), torso.classes, strict=True):
        attached = {names[b] for b in bodies}
        assert (cls == "between") == ("Abdomen" in attached and not attached & {f"lumbar{i}" for i in range(1, 6)})


def test_the_chain_is_a_linear_chain_of_activations(sagittal):
    """The LinearChain's controls are the 210 muscles, unit 1, bounds [0, 1]; the joints L5S1 up."""
    free = sagittal[0]
    assert free.n_controls == 210 and free.control_unit == "1"
    assert free.lower.min() == 0 and free.upper.max() == 1
    assert free.joints[0] == "flex_extension" and free.joints[-1] == "L1_L2_FE"


def test_unknown_model_is_one_line():
    pytest.importorskip("mujoco")
    from spinectl import anatomy

    with pytest.raises(ParameterError, match="myotorso"):
        anatomy.load("no-such-model")


def test_a_model_without_muscles_or_mapped_bodies_is_refused(tmp_path, torso):
    """An MJCF without the mapped bodies, and one without muscles, each give one line naming the problem."""
    from spinectl import anatomy
    from spinectl.anatomy.mapping import MAPPINGS

    path = tmp_path / "bare.xml"
    path.write_text(
        '<mujoco><worldbody><body name="sacrum"><joint name="j" type="hinge"/><geom size=".1"/>'
        "</body></worldbody></mujoco>"
    )
    with pytest.raises(ParameterError, match="mapping.bodies.vertebrae: names bodies that bare lacks"):
        anatomy.load(path, MAPPINGS / "myotorso.toml")
    mapping = tmp_path / "m.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["sacrum"]\nvertebrae = ["sacrum"]\nthorax = ["sacrum"]\n[planes]\nsagittal = ["j"]\n'
    )
    with pytest.raises(ParameterError, match="no muscles"):
        anatomy.load(path, mapping)


def test_bad_activation_and_plane_are_refused(torso):
    from spinectl.anatomy.analyses import analyse

    with pytest.raises(ParameterError, match=r"activation: must be in \[0, 1\]"):
        analyse(torso, activation=1.5)
    with pytest.raises(ParameterError, match="plane: must be one of"):
        analyse(torso, plane="axial")
    with pytest.raises(ParameterError, match="joint_stiffness"):
        analyse(torso, joint_stiffness=-1)


def test_without_mujoco_one_line_says_what_to_install(monkeypatch):
    """With MuJoCo missing (its import blocked), loading raises one line naming the extra."""
    from spinectl.anatomy import engine

    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(engine.AnatomyUnavailable, match=r"pip install 'spinectl\[anatomy\]'"):
        engine.load_engine("myotorso")
