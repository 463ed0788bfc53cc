"""Loading, the mapping and the muscles' classes; bad input as one-line errors."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from shared_models import ABSENT, SHARED_MODELS  # noqa: E402 (tests/anatomy/shared_models.py)

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

PELVIS_TO_L1 = (
    "Ps_L1_",
    "IL_L1_",
    "LTpL_L1_",
    "QL_post_I.3-L1_",
    "MF_m1t.2_",
    "MF_m1t.3_",
)
"""The pelvis-to-L1 fascicles by their anatomy (psoas from L1's body, transverse process and disc; iliocostalis and
longissimus lumborum to L1; quadratus lumborum's posterior L1 fascicle; multifidus m1 to the sacrum): 16 muscles,
8 a side. MyoTorso has no joint between ``lumbar1`` and ``torso`` (its chain ends at L1_L2), so L1 is the thorax's
rigid piece and these span the whole chain exactly as a thorax-pelvis muscle does."""


def test_global_muscles_are_the_thorax_pelvis_ones(torso):
    """The global class is the rib-cage-to-pelvis muscles by their anatomy and the 16 pelvis-to-L1 fascicles.

    The 16 counted "local" before: ``lumbar1`` was taken as a vertebra though no joint separates it from the
    thorax. Checked independently by MuJoCo's moment arms: each global muscle has one at every lumbar level (any
    of the level's three joints), as a muscle spanning the whole chain must.
    """
    import numpy as np

    by_name = {m for m, c in zip(torso.muscles, torso.classes, strict=True) if c == "global"}
    assert by_name == {m for m in torso.muscles if m.startswith(GLOBAL_PREFIXES + PELVIS_TO_L1)}
    assert len(by_name - {m for m in torso.muscles if m.startswith(GLOBAL_PREFIXES)}) == 16
    levels = _level_arms(torso)
    assert all(np.all(row > 1e-9) for row, c in zip(levels, torso.classes, strict=True) if c == "global")


def _level_arms(torso):
    """Each muscle's largest moment arm at each of the five lumbar levels (over its three joints) [m/rad]."""
    import numpy as np

    engine = torso.engine
    engine.set_state(engine.model.qpos0)
    dofs = [int(engine.model.jnt_dofadr[j]) for j in torso.joint_ids(torso.mapping.planes["3d"])]
    arms = engine.moment_arms()[engine.muscle_ids()][:, dofs]
    return np.abs(arms).reshape(len(torso.muscles), 3, 5).max(axis=1)


def test_muscles_within_the_thorax_are_non_lumbar(torso):
    """MyoTorso's two longissimus thoracis slips from L1 to T1 (``LTpT_T1``) lie within the thorax's rigid piece
    (lumbar1 and torso, no joint between): they cross no chain joint, so "non-lumbar"; MuJoCo gives them no moment
    arm at any lumbar level, and every other muscle has one at some level."""
    import numpy as np

    levels = _level_arms(torso)
    non = {m for m, c in zip(torso.muscles, torso.classes, strict=True) if c == "non-lumbar"}
    assert non == {"LTpT_T1_r", "LTpT_T1_l"}
    assert {m for m, row in zip(torso.muscles, levels, strict=True) if np.all(row <= 1e-12)} == non


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


def test_a_model_without_mapped_bodies_is_refused_and_one_without_muscles_is_its_passive_chain(tmp_path, torso):
    """An MJCF without the mapped bodies gives one line naming the problem; one without muscles loads as its
    passive chain (no controls; test_passive_chain.py checks its numbers)."""
    from spinectl import anatomy
    from spinectl.anatomy.mapping import MAPPINGS

    path = tmp_path / "bare.xml"
    path.write_text(
        '<mujoco><worldbody><body name="sacrum"><body name="l1"><joint name="j" type="hinge"/><geom size=".1"/>'
        '<body name="torso"><geom size=".1"/></body></body></body></worldbody></mujoco>'
    )
    with pytest.raises(ParameterError, match="myotorso.toml: bodies.vertebrae: names bodies that bare lacks"):
        anatomy.load(path, MAPPINGS / "myotorso.toml")
    mapping = tmp_path / "m.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["sacrum"]\nvertebrae = ["l1"]\nthorax = ["torso"]\n[planes]\nsagittal = ["j"]\n'
    )
    passive = anatomy.load(path, mapping, cache=False).chain("sagittal")
    assert passive.joints == ("j",) and passive.n_controls == 0


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


# A mapping file is validated as every TOML file of the project (spinectl.model._toml): each case below is one
# edit of the built-in myotorso.toml, and the line names the file and the key.
EDITS = {
    "misspelt section": (("[joint_stiffness]", "[joint_stiffnes]"), "joint_stiffnes: unknown key 'joint_stiffnes'"),
    "misspelt key in a known section": (("Nm_per_rad =", "Nm_per_radian ="), "joint_stiffness.Nm_per_radian: unknown"),
    "misspelt group": (("pelvis = [", "pelvs = ["), "bodies.pelvs: unknown key 'pelvs' (allowed: pelvis, thorax"),
    "unknown plane": (("coronal = [", "frontal = ["), "planes.frontal: unknown key 'frontal'"),
    "bool for a number": (("Nm_per_rad = 343.77", "Nm_per_rad = true"), "Nm_per_rad: must be a number (got True)"),
    "string for a number": (("Nm_per_rad = 343.77", 'Nm_per_rad = "343"'), "Nm_per_rad: must be a number (got '343')"),
    "nan": (("Nm_per_rad = 343.77", "Nm_per_rad = nan"), "joint_stiffness.Nm_per_rad: must be finite (got nan)"),
    "inf": (("Nm_per_rad = 343.77", "Nm_per_rad = inf"), "joint_stiffness.Nm_per_rad: must be finite (got inf)"),
    "beyond the bound": (("Nm_per_rad = 343.77", "Nm_per_rad = 1e7"), "Nm_per_rad: must be at most 1e+06 N m/rad"),
    "negative": (("Nm_per_rad = 343.77", "Nm_per_rad = -1.0"), "Nm_per_rad: must be >= 0 (got -1)"),
    "number for a source": (("source = ", "source = 3 #"), "joint_stiffness.source: must be a string (got 3)"),
    "joint twice in a plane": (('"L4_L5_FE", "L3_L4_FE"', '"L4_L5_FE", "L4_L5_FE"'), "planes.sagittal: must be unique"),
    "joint in two planes": (('"L4_L5_LB", "L3_L4_LB"', '"L4_L5_FE", "L3_L4_LB"'), "planes.coronal: lists 'L4_L5_FE'"),
    "body twice in a group": (('"lumbar5", "lumbar4"', '"lumbar5", "lumbar5"'), "bodies.vertebrae: must be unique"),
    "body in two groups": (('thorax = ["torso"]', 'thorax = ["lumbar1"]'), "bodies.thorax: lists 'lumbar1', which"),
    "string for a list": (('thorax = ["torso"]', 'thorax = "torso"'), "bodies.thorax: must be a list of strings"),
    "number in a list": (('thorax = ["torso"]', "thorax = [3]"), "bodies.thorax[0]: must be a non-empty printable"),
    "empty list": (('thorax = ["torso"]', "thorax = []"), "bodies.thorax: must be a non-empty list of names"),
    "section not a table": (("[joint_stiffness]", "[bodies.more]"), "bodies.more: unknown key 'more'"),
    "value for a section": (
        (("# MyoTorso", "joint_stiffness = 3\n# MyoTorso"), ("\n[joint_stiffness]", "\n[bodies.x]")),
        "m.toml: joint_stiffness: must be a table (got 3)",
    ),
    "array of tables": (("[bodies]", "[[bodies]]"), "bodies: must be a table"),
}


@pytest.mark.parametrize("case", sorted(EDITS))
def test_a_mapping_file_is_validated_key_by_key(tmp_path, case):
    """Unknown sections and keys ("did you mean"), types, finite numbers in bounds, each name once and a joint in
    one plane (3d lists them all): one line naming the file and the key (before: unknown keys were ignored, so a
    misspelt [joint_stiffness] added 0 with --joint-stiffness mapped; `true` was taken as 1; a joint listed twice
    was analysed as a chain of two joints in one; a NaN was blamed on LinearChain.stiffness_offset)."""
    from spinectl.anatomy.mapping import MAPPINGS, read_mapping

    edits, message = EDITS[case]
    text = (MAPPINGS / "myotorso.toml").read_text()
    for old, new in (edits,) if isinstance(edits[0], str) else edits:
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "m.toml"
    path.write_text(text)
    with pytest.raises(ParameterError) as error:
        read_mapping(path)
    assert str(error.value).startswith("...") and "/m.toml: " in str(error.value), str(error.value)
    assert message in str(error.value), str(error.value)
    assert "\n" not in str(error.value)


def test_the_built_in_mappings_pass_the_same_checks():
    """Both built-in mappings read without complaint, myotorso's cited stiffness as written."""
    from spinectl.anatomy.mapping import MAPPINGS, read_mapping

    assert read_mapping(MAPPINGS / "myotorso.toml").joint_stiffness == 343.77
    assert read_mapping(MAPPINGS / "wagner2012_chain.toml").planes["sagittal"]


@pytest.mark.parametrize(
    "kind", ["fifo", "folder", "device", "binary", "latin-1", "not toml", "300-character name", "5000-character path"]
)
def test_a_mapping_that_cannot_be_read_is_one_line(tmp_path, kind):
    """What `--config` refuses, `--mapping` refuses by the same reader (spinectl.model._toml.read_text): a FIFO
    and /dev/zero (before: read for ever, or until memory ran out), a folder, bytes that are not UTF-8, text
    that is not TOML, names too long for the file system (before: an OSError traceback)."""
    from spinectl.anatomy.mapping import read_mapping
    from spinectl.errors import ConfigError

    path = tmp_path / "m.toml"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "binary":
        path.write_bytes(bytes(range(256)))
    elif kind == "latin-1":
        path.write_bytes('[bodies]\npelvis = ["sacr\u00fcm"]\n'.encode("latin-1"))
    elif kind == "not toml":
        path.write_text("[bodies\n")
    path = {"folder": tmp_path, "device": "/dev/zero", "300-character name": tmp_path / ("m" * 300 + ".toml")}.get(
        kind, "x" * 5000 if kind == "5000-character path" else path
    )
    expected = {
        "fifo": "not a regular file",
        "folder": "not a regular file",
        "device": "not a regular file",
        "binary": "is not UTF-8 text",
        "latin-1": "is not UTF-8 text",
        "not toml": "is not valid TOML",
        "300-character name": "File name too long",
        "5000-character path": "File name too long",
    }[kind]
    with pytest.raises(ConfigError) as error:
        read_mapping(path)
    assert str(error.value).startswith("mapping: ") and expected in str(error.value) and "\n" not in str(error.value)


def test_a_misspelt_mapped_stiffness_is_refused_at_the_command_line(tmp_path, capsys):
    """`anatomy --mapping m.toml --joint-stiffness mapped` with [joint_stiffnes]: one line, exit 2, nothing on
    stdout (before: 0 N m/rad added, silently, instead of the file's 343.77)."""
    from spinectl.anatomy.mapping import MAPPINGS
    from spinectl.cli import main

    path = tmp_path / "m.toml"
    path.write_text((MAPPINGS / "myotorso.toml").read_text().replace("[joint_stiffness]", "[joint_stiffnes]"))
    assert main(["anatomy", "--mapping", str(path), "--joint-stiffness", "mapped"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1 and "did you mean 'joint_stiffness'?" in captured.err


PUBLISHED = {
    "pose2sim.toml": "pose2sim-beaucage-gauvreau/Model_Pose2Sim_muscles_flex.osim",
    "cyclist.toml": "allaire-cyclist/s01modelScaled.osim",
    "christophy.toml": "christophy-skeleton/Christophy2012_axialRotationUpd_skeletonOnly.osim",
}


def _documented_mappings() -> list:
    """The mappings docs/anatomy.md's "Published models" shows (docs/mappings/, included), in PUBLISHED's order."""
    docs = Path(__file__).resolve().parents[2] / "docs"
    page = (docs / "anatomy.md").read_text(encoding="utf-8")
    assert all(f"{{literalinclude}} mappings/{name}" in page for name in PUBLISHED)
    return [(docs / "mappings" / name).read_text(encoding="utf-8") for name in PUBLISHED]


@pytest.mark.skipif(not SHARED_MODELS.is_dir(), reason=ABSENT)
@pytest.mark.parametrize("index", range(len(PUBLISHED)))
def test_the_documented_mappings_name_the_published_models_bodies_and_coordinates(tmp_path, index):
    """Each mapping of docs/anatomy.md's "Published models" reads as a mapping, and every body and coordinate it
    names is one of its model's (OpenSim's own body and coordinate sets)."""
    osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    from spinectl.anatomy.mapping import read_mapping

    name, model_path = list(PUBLISHED.items())[index]
    path = tmp_path / name
    path.write_text(_documented_mappings()[index], encoding="utf-8")
    mapping = read_mapping(path)
    osim.Logger.setLevelString("error")
    model = osim.Model(str(SHARED_MODELS / model_path))
    bodies = {model.getBodySet().get(i).getName() for i in range(model.getBodySet().getSize())}
    coordinates = {model.getCoordinateSet().get(i).getName() for i in range(model.getCoordinateSet().getSize())}
    assert {b for names in mapping.bodies.values() for b in names} <= bodies
    assert {c for names in mapping.planes.values() for c in names} <= coordinates
    assert len(mapping.planes["sagittal"]) >= 5
