"""Muscle classes and the rhythm, by one rule on both engines, on small models built in the test.

Each model is a pelvis, three chain joints (j1, j2, j3) up to a vertebra ``top`` that has no joint to the
``chest`` (the thorax), a leg (``femur`` on an unmapped hip joint) and, for the rhythm, a routing body
``abd`` on v1 whose own joint a coupling slaves to j1. The expected classes follow from which joints lie
between a muscle's attachments, read off the tree as drawn here; MuJoCo's moment arms check them
independently (a muscle across a chain joint has a moment arm on it, one across none has none).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from shared_models import ABSENT, POSE2SIM  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl.anatomy.classes import Skeleton, classify_muscles

try:  # imported first, as test_opensim_import.py does: imported after the CLI tests' modules, OpenSim's
    import opensim  # noqa: F401  Function.calcDerivative refused its own StdVectorInt (a SWIG type clash)
except ImportError:  # the OpenSim tests skip, one by one
    pass

MAPPING = """
[bodies]
pelvis = ["pelvis"]
vertebrae = ["v1", "v2", "top"]
thorax = ["chest"]

[planes]
sagittal = ["j1", "j2", "j3"]
"""

MUSCLES = {
    "global": ("pelvis", "chest"),
    "to_top": ("pelvis", "top"),
    "local": ("pelvis", "v1"),
    "leg": ("pelvis", "femur"),
    "within": ("top", "chest"),
    "routed": ("pelvis", "abd", "chest"),
}
"""Each muscle's attachment bodies, its path in this order."""

EXPECTED = {
    "global": "global",  # thorax to pelvis
    "to_top": "global",  # top has no joint to the chest: the same rigid piece, so a thorax-pelvis muscle
    "local": "local",  # on a vertebra that j2 and j3 separate from the thorax
    "leg": "non-lumbar",  # across the hip only
    "within": "non-lumbar",  # both ends on one rigid piece
    "routed": "between",  # over the routing body, across every chain joint
}
"""The classes by the tree (module docstring): before the fix ``to_top`` and ``within`` were local, ``leg``
between."""

RHYTHM = (0.5, 0.25)
"""j2 and j3 per radian of j1: the chain's own rhythm. The routing body's joint turns 2 rad per radian of j1."""


def test_the_rule_on_a_bare_tree():
    """The shared rule alone: a vertebra rigid on the thorax counts as thorax, a muscle across no chain joint is
    non-lumbar. Tree: 0 world (pelvis listed), 1 v (chain joint), 2 top (chain joint), 3 chest (rigid on top),
    4 femur (unmapped joint on the pelvis)."""
    tree = Skeleton(
        names=("pelvis", "v", "top", "chest", "femur"),
        parent=(-1, 0, 1, 2, 0),
        rigid=(False, False, False, True, False),
        chain=(False, True, True, False, False),
    )
    bodies = {"pelvis": ("pelvis",), "vertebrae": ("v", "top"), "thorax": ("chest",)}
    got = classify_muscles(tree, bodies, [{0, 2}, {0, 1}, {0, 4}, {2, 3}, {1, 4}])
    assert got == ("global", "local", "non-lumbar", "non-lumbar", "local")


def _mjcf_spec(weld=False, free_root=False, strap=False, rigid_strap=False, equalities=False, site_weld=False):
    """The test model through MuJoCo's MjSpec API (module docstring); options add the devices of MJCF as published."""
    mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    spec = mujoco.MjSpec()
    spec.modelname = "mini"
    spec.compiler.LRopt.mode = mujoco.mjtLRMode.mjLRMODE_NONE
    y = [0.0, 1.0, 0.0]
    pelvis = spec.worldbody.add_body(name="pelvis", pos=[0, 0, 1.0])
    if free_root:
        pelvis.add_freejoint(name="root")
    bodies = {"pelvis": pelvis}
    parent = pelvis
    for name, joint in (("v1", "j1"), ("v2", "j2"), ("top", "j3")):
        parent = bodies[name] = parent.add_body(name=name, pos=[0, 0, 0.1])
        parent.add_joint(name=joint, axis=y)
    bodies["chest"] = bodies["top"].add_body(name="chest", pos=[0, 0, 0.1])
    bodies["femur"] = pelvis.add_body(name="femur", pos=[0.1, 0, -0.1])
    bodies["femur"].add_joint(name="hip", axis=y)
    bodies["abd"] = bodies["v1"].add_body(name="abd", pos=[0.12, 0, 0.05])
    bodies["abd"].add_joint(name="abd_r", axis=y)
    for name, body in bodies.items():
        body.add_geom(size=[0.04, 0, 0], mass=4.0 if name == "chest" else 1.0)
    for k, (muscle, path) in enumerate(MUSCLES.items()):
        tendon = spec.add_tendon(name=muscle)
        for i, body in enumerate(path):
            site = bodies[body].add_site(name=f"{muscle}_{i}", pos=[0.06 if k % 2 else -0.06, 0.01 * k, 0.02 * i])
            tendon.wrap_site(site.name)
        actuator = spec.add_actuator(name=muscle, target=muscle, trntype=mujoco.mjtTrn.mjTRN_TENDON)
        actuator.set_to_muscle(tausmooth=0.0, force=200.0)
        actuator.lengthrange = [0.05, 0.6]  # given: joints without limits have no range to search
    if equalities:
        for joint, coef in (("j2", RHYTHM[0]), ("j3", RHYTHM[1]), ("abd_r", 2.0)):
            spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=joint, name2="j1", data=[0, coef] + [0] * 10)
    if weld or rigid_strap or strap or site_weld:
        holder = bodies["chest"] if rigid_strap else spec.worldbody
        pos = [0.1, 0, 0.1] if rigid_strap else [0.1, 0, 1.5]  # the chest is at z = 1.4 in the world
        pos = [0.3, 0.2, 1.7] if site_weld else pos  # away from the chest's site: MuJoCo pulls the sites together
        belt = holder.add_body(name="belt", pos=pos)
        if weld:
            belt.add_freejoint(name="belt_free")
            spec.add_equality(
                type=mujoco.mjtEq.mjEQ_WELD, name1="belt", name2="chest", objtype=mujoco.mjtObj.mjOBJ_BODY
            )
        if site_weld:  # on a slide and a hinge of its own, its site welded onto one on the chest's
            belt.add_joint(name="belt_slide", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
            belt.add_joint(name="belt_turn", axis=[0, 0, 1])
            belt.add_site(name="belt_buckle", pos=[0.02, 0, -0.05])
            bodies["chest"].add_site(name="chest_buckle", pos=[0.12, 0, 0.05])
            site = mujoco.mjtObj.mjOBJ_SITE
            spec.add_equality(
                type=mujoco.mjtEq.mjEQ_WELD, name="buckle", name1="belt_buckle", name2="chest_buckle", objtype=site
            )
        belt.add_geom(size=[0.02, 0, 0], mass=0.5)
        belt.add_site(name="belt_site")
        if strap:
            band = spec.add_tendon(name="band", stiffness=300.0)
            band.wrap_site("belt_site")
            band.wrap_site("global_0")
    return spec


def _folder(tmp_path, name):
    """A folder of its own for one model and its mapping."""
    folder = tmp_path / name
    folder.mkdir()
    return folder


def _load_mjcf(tmp_path, name="mini", **options):
    from spinectl import anatomy

    path = tmp_path / f"{name}.xml"
    path.write_text(_mjcf_spec(**options).to_xml())
    mapping = tmp_path / "mapping.toml"
    mapping.write_text(MAPPING)
    return anatomy.load(path, mapping, cache=False)


def test_mujoco_classes_follow_the_tree_and_the_moment_arms(tmp_path):
    """MuJoCo's model: the classes are EXPECTED's; checked by MuJoCo's moment arms on j1-j3 at the reference
    posture: every global muscle (to_top included) has one on each chain joint, the non-lumbar ones none."""
    loaded = _load_mjcf(tmp_path)
    classes = dict(zip(loaded.muscles, loaded.classes, strict=True))
    assert classes == EXPECTED
    engine = loaded.engine
    engine.set_state(engine.model.qpos0)
    dofs = [int(engine.model.jnt_dofadr[j]) for j in loaded.joint_ids(("j1", "j2", "j3"))]
    arms = dict(zip(loaded.muscles, np.abs(engine.moment_arms()[engine.muscle_ids()][:, dofs]), strict=True))
    assert all(np.all(arms[m] > 1e-6) for m, c in classes.items() if c == "global")
    assert all(np.all(arms[m] == 0) for m, c in classes.items() if c == "non-lumbar")


def test_non_lumbar_muscles_add_nothing_to_the_chain(tmp_path):
    """A non-lumbar muscle crosses no chain joint, so its K_i (free and constrained) is zero; the table and JSON
    count it in its own class."""
    from spinectl.anatomy.analyses import analyse

    loaded = _load_mjcf(tmp_path)
    free, _, _ = loaded.chains("sagittal")
    largest = np.abs(free.stiffness_per_control).max()
    for k, c in zip(free.stiffness_per_control.transpose(2, 0, 1), loaded.classes, strict=True):
        assert (np.abs(k).max() <= 1e-12 * largest) == (c == "non-lumbar")  # rounding of the differences only
    result = analyse(loaded, activation=0.2)
    assert result.to_dict()["muscles"]["non-lumbar"] == ["leg", "within"]
    assert "2 global, 1 local, 1 between, 2 non-lumbar" in result.table()


def test_mujoco_rhythm_leaves_the_routing_body_out(tmp_path):
    """Joint equalities j2 = 0.5 j1, j3 = 0.25 j1 and abd_r = 2 j1: the constrained chain is T^T K T of the free
    chain with T = (1, 0.5, 0.25) (the chain's own rhythm, linear: no curvature), to rounding, so the routing body
    ``abd`` does not enter it; its equality is named in the JSON and the table."""
    from spinectl.anatomy.analyses import analyse

    loaded = _load_mjcf(tmp_path, equalities=True)
    free, constrained, _ = loaded.chains("sagittal")
    a = np.full(free.n_controls, 0.3)
    T = np.array([[1.0], [RHYTHM[0]], [RHYTHM[1]]])
    full = free.stiffness(a)
    np.testing.assert_allclose(constrained.stiffness(a), T.T @ full @ T, rtol=1e-10, atol=1e-10 * np.abs(full).max())
    doc = analyse(loaded, activation=0.3).to_dict()
    assert doc["constrained"]["rhythm_left_out"] == ["equality 2 (abd_r on j1)"]
    assert "left out of the rhythm" in analyse(loaded, activation=0.3).table()


def test_a_weld_device_is_taken_into_the_chain(tmp_path):
    """A belt with its own free joint welded to the chest (an exosuit's strap) loads, not refused: it is the chest's
    rigid piece, so the chain is the same model's with the belt built on the chest (no weld), K_0 and M to rounding;
    the table and JSON name the device."""
    from spinectl.anatomy.analyses import analyse

    welded = _load_mjcf(_folder(tmp_path, "w"), weld=True, strap=True)
    rigid = _load_mjcf(_folder(tmp_path, "r"), rigid_strap=True, strap=True)
    ours, theirs = welded.chain("sagittal"), rigid.chain("sagittal")
    a = np.full(ours.n_controls, 0.2)
    np.testing.assert_allclose(ours.stiffness(a), theirs.stiffness(a), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ours.mass_matrix, theirs.mass_matrix, rtol=1e-12, atol=1e-12)
    doc = analyse(welded, activation=0.2).to_dict()
    assert doc["devices"][0] == "weld 0: 'belt' rigid on 'chest' at the reference pose (a device)"
    assert welded.muscles == tuple(MUSCLES)  # the band is no muscle


def test_a_site_weld_on_a_belts_own_joints_is_a_device_too(tmp_path):
    """A variant: the belt on a slide and a hinge of its own (no free joint) in the world, welded by a named weld of
    two sites (MuJoCo makes their frames one): the belt hangs on the chest with the sites together, which puts it
    where the rigid belt is built (chest site at (0.12, 0, 0.05) less belt site at (0.02, 0, -0.05) = (0.1, 0,
    0.1)); K and M as that model's."""
    welded = _load_mjcf(_folder(tmp_path, "w"), site_weld=True)
    rigid = _load_mjcf(_folder(tmp_path, "r"), rigid_strap=True)
    ours, theirs = welded.chain("sagittal"), rigid.chain("sagittal")
    a = np.full(ours.n_controls, 0.2)
    np.testing.assert_allclose(ours.stiffness(a), theirs.stiffness(a), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ours.mass_matrix, theirs.mass_matrix, rtol=1e-12, atol=1e-12)
    assert welded.engine.devices == ("weld buckle: 'belt' rigid on 'chest' at the reference pose (a device)",)


def test_a_strap_tendon_is_a_device_with_its_spring_in_k0(tmp_path):
    """A tendon with a spring and no actuator (a strap from the belt on the chest to the pelvis) is no muscle; its
    spring at its rest length (MuJoCo's default: the length at qpos0) adds -k J J^T to K_0, J its moment arms on
    the chain (central differences of MuJoCo's tendon length), k = 300 N/m."""
    plain = _load_mjcf(_folder(tmp_path, "p"), rigid_strap=True)
    strapped = _load_mjcf(_folder(tmp_path, "s"), rigid_strap=True, strap=True)
    assert strapped.muscles == plain.muscles
    assert strapped.engine.devices[0].startswith("passive tendon 'band' (a spring of 300 N/m, no actuator)")
    engine = strapped.engine
    band = engine.model.tendon("band").id
    jac = []
    for j in strapped.joint_ids(("j1", "j2", "j3")):  # MuJoCo's tendon length, by central differences
        lengths = []
        for step in (1e-6, -1e-6):
            q = engine.model.qpos0.copy()
            q[engine.model.jnt_qposadr[j]] += step
            engine.set_state(q)
            lengths.append(engine.data.ten_length[band])
        jac.append((lengths[0] - lengths[1]) / 2e-6)
    added = strapped.chain("sagittal").stiffness_offset - plain.chain("sagittal").stiffness_offset
    expected = -300.0 * np.outer(jac, jac)  # to 1e-4 of its largest entry: K_0's central differences
    np.testing.assert_allclose(added, expected, rtol=0, atol=1e-4 * np.abs(expected).max())


def test_a_free_root_is_fixed_at_its_reference_and_said(tmp_path, capsys):
    """A full-body model's free root (the pelvis floating) loads: the analysis holds every joint off the chain, so
    the root fixed at its reference is the same chain as the model built without it (K and M to rounding); one
    note line says so."""
    from spinectl.cli import main

    floating = _load_mjcf(_folder(tmp_path, "f"), free_root=True)
    fixed = _load_mjcf(_folder(tmp_path, "x"))
    a = np.full(len(fixed.muscles), 0.2)
    np.testing.assert_allclose(floating.chain().stiffness(a), fixed.chain().stiffness(a), rtol=1e-9, atol=1e-9)
    assert floating.engine.devices == ("free root joint of 'pelvis' fixed at its reference pose (qpos0)",)
    path = tmp_path / "f" / "mini.xml"
    assert main(["anatomy", str(path), "--mapping", str(tmp_path / "f" / "mapping.toml")]) == 0
    out = capsys.readouterr().out
    assert out.count("free root joint of 'pelvis' fixed at its reference pose") == 1


def _osim_model(tmp_path, locked=False):
    """The same tree through OpenSim's API: pelvis welded to ground, j1-j3 pin joints, chest welded on top, a
    femur on a hip pin joint, the routing body abd on v1; couplers j2 = 0.5 j1, j3 = 0.25 j1 and abd_r = 2 j1;
    rigid-tendon Millard muscles along MUSCLES. ``locked``: the chest on a pin joint whose coordinate is locked
    instead of a weld."""
    osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    model = osim.Model()
    model.setName("mini")
    bodies = {"ground": model.getGround()}
    layout = (
        ("pelvis", "ground", None, (0, 1.0, 0)),
        ("v1", "pelvis", "j1", (0, 0.1, 0)),
        ("v2", "v1", "j2", (0, 0.1, 0)),
        ("top", "v2", "j3", (0, 0.1, 0)),
        ("chest", "top", None, (0, 0.1, 0)),
        ("femur", "pelvis", "hip", (0.1, -0.1, 0)),
        ("abd", "v1", "abd_r", (0.12, 0.05, 0)),
    )
    for name, parent, coordinate, offset in layout:
        body = osim.Body(name, 4.0 if name == "chest" else 1.0, osim.Vec3(0), osim.Inertia(0.01, 0.01, 0.01))
        model.addBody(body)
        bodies[name] = body
        args = (f"{name}_joint", bodies[parent], osim.Vec3(*offset), osim.Vec3(0), body, osim.Vec3(0), osim.Vec3(0))
        if coordinate is None and locked and name == "chest":
            joint = osim.PinJoint(*args)
            joint.updCoordinate().setName("chest_tilt")
            joint.updCoordinate().setDefaultLocked(True)
            model.addJoint(joint)
        elif coordinate is None:
            model.addJoint(osim.WeldJoint(*args))
        else:
            joint = osim.PinJoint(*args)
            joint.updCoordinate().setName(coordinate)
            model.addJoint(joint)
    for k, (muscle, path) in enumerate(MUSCLES.items()):
        fibre = osim.Millard2012EquilibriumMuscle(muscle, 500.0, 0.1, 0.05, 0.0)
        fibre.set_ignore_tendon_compliance(True)
        for i, body in enumerate(path):
            where = osim.Vec3(0.06 if k % 2 else -0.06, 0.02 * i, 0.01 * k)
            fibre.addNewPathPoint(f"{muscle}_{i}", bodies[body], where)
        model.addForce(fibre)
    for dependent, slope in (("j2", RHYTHM[0]), ("j3", RHYTHM[1]), ("abd_r", 2.0)):
        coupler = osim.CoordinateCouplerConstraint()
        coupler.setName(f"{dependent}_con")
        independent = osim.ArrayStr()
        independent.append("j1")
        coupler.setIndependentCoordinateNames(independent)
        coupler.setDependentCoordinateName(dependent)
        coupler.setFunction(osim.LinearFunction(slope, 0.0))
        model.addConstraint(coupler)
    model.finalizeConnections()
    path = tmp_path / "mini.osim"
    model.printToXML(str(path))
    mapping = tmp_path / "mapping.toml"
    mapping.write_text(MAPPING)
    return path, mapping


@pytest.mark.parametrize("locked", [False, True], ids=["weld", "locked"])
def test_opensim_classes_are_the_same_rule(tmp_path, locked):
    """OpenSim's model of the same tree (WeldJoints where MuJoCo has no joint; or the chest on a pin joint whose
    coordinate is locked, no free coordinate either): the classes are EXPECTED's."""
    from spinectl import anatomy

    path, mapping = _osim_model(tmp_path, locked)
    loaded = anatomy.load(path, mapping)
    assert dict(zip(loaded.muscles, loaded.classes, strict=True)) == EXPECTED


def test_opensim_rhythm_leaves_the_routing_body_out(tmp_path, capsys):
    """Couplers j2 = 0.5 j1, j3 = 0.25 j1 and abd_r = 2 j1: the constrained chain is T^T K T of the free chain with
    T = (1, 0.5, 0.25) (linear functions: no curvature term), to rounding, the routing body's coupler left out and
    named in the JSON."""
    from spinectl import anatomy
    from spinectl.cli import main

    path, mapping = _osim_model(tmp_path)
    loaded = anatomy.load(path, mapping)
    free, constrained, _ = loaded.chains("sagittal")
    a = np.full(free.n_controls, 0.3)
    T = np.array([[1.0], [RHYTHM[0]], [RHYTHM[1]]])
    full = free.stiffness(a)
    np.testing.assert_allclose(constrained.stiffness(a), T.T @ full @ T, rtol=1e-9, atol=1e-9 * np.abs(full).max())
    assert main(["anatomy", str(path), "--mapping", str(mapping), "--activation", "0.3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["constrained"]["rhythm_left_out"] == ["abd_r_con (abd_r on j1 slope 2)"]
    assert doc["constrained"]["joints"] == ["j1"]


SHARED = str(POSE2SIM)


def test_pose2sims_abdomen_coupler_is_left_out_of_the_rhythm():
    """The Pose2Sim model as downloaded: over its five lumbar flexion coordinates the rhythm is the four couplers
    that slave L4/L5 ... L1/L2 to L5/S1 (read in the file: ``*_Flex_Ext_con``), and the couplers that move the
    ``Abdomen`` routing body (``Abs_r3_con``) and the L1/T12 joint off this chain are named, not used."""
    from pathlib import Path

    if not Path(SHARED).is_file():
        pytest.skip(ABSENT)
    pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    from spinectl.anatomy.opensim_couplers import coupler_rhythm
    from spinectl.anatomy.opensim_engine import load_engine

    engine = load_engine(SHARED)
    chain = [f"{j}_Flex_Ext" for j in ("L5_S1", "L4_L5", "L3_L4", "L2_L3", "L1_L2")]
    rhy, involved, used = coupler_rhythm(engine, chain, {})
    assert involved == chain and [c.dependent for c in used] == chain[1:]
    assert [text.split(" ")[0] for text in rhy.left_out] == ["Abs_r3_con", "L1_T12_Flex_Ext_con"]


def test_myosuites_full_body_loads_with_its_root_fixed_and_limbs_non_lumbar():
    """myo-sim's ``myofullbody`` (MyoTorso with legs, arms and head on a free root) loads as published: its free
    root fixed and said; its muscles with no moment arm on any of the fifteen lumbar joints (MuJoCo's, at the
    reference posture) are exactly the non-lumbar ones, and its trunk muscles keep MyoTorso's 42 global."""
    pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    myo_sim = pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    from spinectl import anatomy

    if "myofullbody" not in getattr(myo_sim, "_composed_models", lambda: {"myofullbody"})():
        pytest.skip(f"myo-sim {myo_sim.__version__} has no myofullbody")
    body = anatomy.load("myofullbody")
    assert body.engine.devices == ("free root joint of 'Full Body' fixed at its reference pose (qpos0)",)
    engine = body.engine
    engine.set_state(engine.model.qpos0)
    dofs = [int(engine.model.jnt_dofadr[j]) for j in body.joint_ids(body.mapping.planes["3d"])]
    idle = np.all(np.abs(engine.moment_arms()[engine.muscle_ids()][:, dofs]) <= 1e-12, axis=1)
    assert [c == "non-lumbar" for c in body.classes] == list(idle)
    assert body.classes.count("global") == 42 and body.classes.count("non-lumbar") > 200


def test_a_weld_that_locks_the_chain_is_one_line(tmp_path, capsys):
    """A weld of the chest to the world ties a body that the chain's joints move, not its own: it would lock the
    chain, which no device does; refused in one line naming the weld and the bodies, exit 2, nothing on stdout."""
    mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    from spinectl.cli import main

    spec = _mjcf_spec()
    spec.add_equality(type=mujoco.mjtEq.mjEQ_WELD, name="lock", name1="chest", objtype=mujoco.mjtObj.mjOBJ_BODY)
    path = tmp_path / "locked.xml"
    path.write_text(spec.to_xml())
    (tmp_path / "mapping.toml").write_text(MAPPING)
    assert main(["anatomy", str(path), "--mapping", str(tmp_path / "mapping.toml")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert "model: mini: weld lock ties 'chest' to 'world' across joints of other bodies" in err


def test_a_free_roots_keyframe_keeps_its_joints_and_controls(tmp_path):
    """A keyframe of the floating model (root 7 numbers, then the hinges) is carried over by joint and actuator name
    when the root is fixed: each hinge keeps its value, each muscle its control (the keyframe as written here)."""
    mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    spec = _mjcf_spec(free_root=True)
    model = spec.compile()
    qpos = model.qpos0.copy()
    hinges = {"j1": 0.1, "j2": 0.2, "j3": 0.3, "hip": 0.4, "abd_r": 0.5}
    for name, value in hinges.items():
        qpos[model.joint(name).qposadr[0]] = value
    spec.add_key(name="pose", qpos=qpos.tolist(), ctrl=[0.05 * (k + 1) for k in range(model.nu)])
    folder = _folder(tmp_path, "k")
    (folder / "mini.xml").write_text(spec.to_xml())
    (folder / "mapping.toml").write_text(MAPPING)
    from spinectl import anatomy

    loaded = anatomy.load(folder / "mini.xml", folder / "mapping.toml", cache=False)
    fixed = loaded.engine.model
    assert fixed.nq == model.nq - 7 and fixed.nkey == 1
    assert {n: fixed.key_qpos[0][fixed.joint(n).qposadr[0]] for n in hinges} == pytest.approx(hinges)
    np.testing.assert_allclose(loaded.default_controls(), [0.05 * (k + 1) for k in range(model.nu)])
    assert mujoco.mj_name2id(fixed, mujoco.mjtObj.mjOBJ_JOINT, "root") < 0
