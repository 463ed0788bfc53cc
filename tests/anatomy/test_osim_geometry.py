"""OpenSim's geometry at a posture (spinectl.anatomy.osim_geometry) and the cache of linearisations (osim_cache).

The reference is the path spinectl took before (tests/anatomy/osim_reference.py): every muscle's
``computeMomentArm`` about every coordinate (OpenSim's MomentArmSolver), their central
differences over q with spinectl.anatomy.linearise.STEP for the Hessians, and OpenSim's
inverse dynamics with the actuators off for the passive torques. The model is spinectl's export of the
paper's chain (30 Millard muscles) with a WrapCylinder that one muscle wraps over, built through
OpenSim's API in the test.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from osim_reference import present_geometry, rigid_millard_copy  # noqa: E402 (tests/anatomy/osim_reference.py)
from shared_models import ABSENT, POSE2SIM  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl.anatomy import opensim_engine, osim_cache  # noqa: E402
from spinectl.anatomy.export_osim import export_osim  # noqa: E402
from spinectl.anatomy.osim_geometry import geometry  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402

CHAIN = ["L5S1", "L4L5", "L3L4", "L2L3", "L1L2"]
WRAPPED = 0  # straight_ventral_0


def _wrap_over_first_muscle(source: Path, target: Path) -> None:
    """A WrapCylinder 1 cm in radius whose axis lies 5 mm inside straight_ventral_0's straight path, at its middle:
    the path wraps over it on both sides of the posture (not at a contact's edge)."""
    built = osim.Model(str(source))
    state = built.initSystem()
    path = built.getMuscles().get(WRAPPED).getGeometryPath()
    points = path.getPathPointSet()
    top, bottom = (np.array(points.get(k).getLocationInGround(state).to_numpy()) for k in range(2))
    along = (bottom - top) / np.linalg.norm(bottom - top)
    normal = np.array([-along[1], along[0], 0.0])
    cylinder = osim.WrapCylinder()
    cylinder.setName("belly")
    cylinder.set_radius(0.01)
    cylinder.set_length(0.2)
    cylinder.set_translation(osim.Vec3(*(0.5 * (top + bottom) + 0.005 * normal)))
    built.updGround().addWrapObject(cylinder)
    path.addPathWrap(cylinder)
    built.finalizeConnections()
    built.printToXML(str(target))


@pytest.fixture(scope="module")
def wrapped(tmp_path_factory):
    """The wagner2012 export with the wrap: (path, engine)."""
    folder = tmp_path_factory.mktemp("osim_geometry")
    export_osim(load_preset("wagner2012"), 0.03, 0.04, folder / "chain.osim")
    _wrap_over_first_muscle(folder / "chain.osim", folder / "wrapped.osim")
    return folder / "wrapped.osim", opensim_engine.load_engine(folder / "wrapped.osim", cache=False)


@pytest.mark.parametrize("values", [{}, {"L4L5": 0.05, "L2L3": -0.03}], ids=["upright", "bent"])
def test_the_geometry_is_the_present_paths(wrapped, values):
    """Arms, Hessians, passive torques and their derivatives equal the present path's (present_geometry): the arms
    to 1e-12 of the largest (both are OpenSim's lengthening speed per coordinate speed, to rounding), the Hessians
    to 1e-6 of the largest entry (the same central differences of the same arms), the passive torques to 1e-12
    and their derivatives to 1e-8 of the largest. The wrapped muscle's path touches the cylinder (4 points)."""
    _, engine = wrapped
    engine.set_posture(values)
    assert engine.model.getMuscles().get(WRAPPED).getGeometryPath().getCurrentPath(engine.state).getSize() == 4
    geo = geometry(engine, CHAIN, values, opensim_engine._mobility_order(engine))
    arms, hessian, passive, dpassive = present_geometry(engine, CHAIN, values)
    assert np.max(np.abs(geo.arms - arms)) <= 1e-12 * np.max(np.abs(arms))
    assert np.max(np.abs(geo.hessian - hessian)) <= 1e-6 * np.max(np.abs(hessian))
    assert np.max(np.abs(geo.hessian[WRAPPED] - hessian[WRAPPED])) <= 1e-6 * np.max(np.abs(hessian[WRAPPED]))
    assert np.max(np.abs(geo.passive - passive)) <= 1e-12 * np.max(np.abs(passive))
    assert np.max(np.abs(geo.dpassive - dpassive)) <= 1e-8 * np.max(np.abs(dpassive))


def test_the_arms_are_the_differences_of_opensims_lengths_over_a_cylinder(wrapped):
    """Over a cylinder (a geodesic, so OpenSim's length and the rate its forces follow agree) the arms equal the
    central differences of getLength with step 1e-6 rad (truncation ~1e-12, rounding eps L / h ~ 1e-10 m/rad)
    to 1e-8 of the wrapped muscle's largest arm: the wrap changes them (the same path without it differs)."""
    _, engine = wrapped
    geo = geometry(engine, CHAIN, {}, opensim_engine._mobility_order(engine))
    muscle, h = engine.model.getMuscles().get(WRAPPED), 1e-6
    lengths = []
    for name in CHAIN:
        sides = []
        for sign in (1.0, -1.0):
            engine.set_posture({name: sign * h})
            sides.append(muscle.getLength(engine.state))
        lengths.append((sides[0] - sides[1]) / (2 * h))
    engine.set_posture({})
    scale = np.max(np.abs(geo.arms[WRAPPED]))
    assert np.max(np.abs(geo.arms[WRAPPED] - lengths)) <= 1e-8 * scale
    assert np.max(np.abs(geo.arms[WRAPPED] - geo.arms[WRAPPED + 1])) > 1e-3 * scale  # its twin fibre, unwrapped


def _arrays(lin):
    return {k: np.asarray(v) for k, v in vars(lin).items()}


def _identical(a, b) -> bool:
    """Bit for bit: the same dtypes, shapes and bytes of every field."""
    x, y = _arrays(a), _arrays(b)
    return all(x[k].dtype == y[k].dtype and x[k].shape == y[k].shape and x[k].tobytes() == y[k].tobytes() for k in x)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache folder of the test's own."""
    monkeypatch.setenv("SPINECTL_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _refuse_to_compute(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("linearised anew: the cache was not read")

    monkeypatch.setattr(opensim_engine, "_linearise", refuse)


def test_a_cached_linearisation_is_read_back_bit_for_bit(wrapped, cache, monkeypatch):
    """A model loaded again (a new engine, as a new process) gets its linearisation from the cache, identical bit
    for bit to one computed without the cache; within an engine a posture is linearised once."""
    path, _ = wrapped
    fresh = opensim_engine.load_osim(path, cache=False).linearise("sagittal")[0]
    assert not cache.exists()  # cache=False wrote nothing
    first = opensim_engine.load_osim(path).linearise("sagittal")[0]
    assert len(list(cache.glob("*.osim-lin.npz"))) == 1
    _refuse_to_compute(monkeypatch)
    again = opensim_engine.load_osim(path)
    read = again.linearise("sagittal")[0]
    assert _identical(read, fresh) and _identical(first, fresh)
    read.stiffness_per_muscle[...] = 0.0  # a caller's change stays its own
    assert _identical(again.linearise("sagittal")[0], fresh)


def test_no_cache_neither_reads_nor_writes(wrapped, cache, monkeypatch):
    """With cache=False (``--no-cache``) a cached entry is not read (it is linearised anew) and none is written."""
    path, _ = wrapped
    opensim_engine.load_osim(path).linearise("sagittal")
    entries = {p: p.read_bytes() for p in cache.iterdir()}
    monkeypatch.setattr(osim_cache, "read", lambda key: pytest.fail("read the cache"))
    monkeypatch.setattr(osim_cache, "write", lambda key, lin: pytest.fail("wrote the cache"))
    opensim_engine.load_osim(path, cache=False).linearise("sagittal")
    assert {p: p.read_bytes() for p in cache.iterdir()} == entries


def test_a_changed_file_mapping_or_posture_is_linearised_anew(wrapped, cache, tmp_path):
    """Each of a changed file (one muscle's F_max doubled: its K_i doubles), a mapping over other coordinates
    (four joints) and another posture is a new entry whose linearisation is the one computed without the cache."""
    path, _ = wrapped
    opensim_engine.load_osim(path).linearise("sagittal")
    stronger = tmp_path / "stronger.osim"
    model = osim.Model(str(path))
    muscle = model.getMuscles().get(WRAPPED)
    muscle.setMaxIsometricForce(2 * muscle.getMaxIsometricForce())
    model.printToXML(str(stronger))
    four = tmp_path / "four.toml"
    four.write_text(
        '[bodies]\npelvis = ["ground"]\nthorax = ["thorax"]\nvertebrae = ["vertebra_above_L2L3", '
        '"vertebra_above_L3L4", "vertebra_above_L4L5", "vertebra_above_L5S1"]\n[planes]\nsagittal = ["L5S1", '
        '"L4L5", "L3L4", "L2L3"]\n'
    )
    cases = [(stronger, None, None), (path, four, None), (path, None, {"L4L5": 0.02})]
    before = opensim_engine.load_osim(path, cache=False).linearise("sagittal")[0]
    for k, (model_path, mapping, posture) in enumerate(cases):
        cached = opensim_engine.load_osim(model_path, mapping).linearise("sagittal", posture)[0]
        fresh = opensim_engine.load_osim(model_path, mapping, cache=False).linearise("sagittal", posture)[0]
        assert _identical(cached, fresh) and not _identical(cached, before)
        assert len(list(cache.glob("*.osim-lin.npz"))) == 2 + k
    k_i = before.stiffness_per_muscle[..., WRAPPED]
    ratio = opensim_engine.load_osim(stronger).linearise("sagittal")[0].stiffness_per_muscle[..., WRAPPED] / k_i
    np.testing.assert_allclose(ratio[np.abs(k_i) > 1e-9 * np.abs(k_i).max()], 2.0, rtol=1e-12)


@pytest.mark.parametrize("damage", ["truncated", "other key", "not a zip"])
def test_a_damaged_entry_is_ignored_and_rewritten(wrapped, cache, damage):
    """A cached file cut short, of another key (renamed) or not numpy's zip at all is ignored: the linearisation is
    computed anew (identical to one without the cache) and the file rewritten whole."""
    path, _ = wrapped
    fresh = opensim_engine.load_osim(path, cache=False).linearise("sagittal")[0]
    opensim_engine.load_osim(path).linearise("sagittal")
    (entry,) = cache.glob("*.osim-lin.npz")
    whole = entry.read_bytes()
    if damage == "truncated":
        entry.write_bytes(whole[: len(whole) // 2])
    elif damage == "other key":  # a whole file of another key under this key's name
        osim_cache.write("0" * 64, fresh)
        (cache / ("0" * 64 + ".osim-lin.npz")).replace(entry)
    else:
        entry.write_bytes(b"not numpy's zip")
    assert _identical(opensim_engine.load_osim(path).linearise("sagittal")[0], fresh)
    assert entry.read_bytes() == whole


def test_an_unwritable_cache_folder_is_no_cache(wrapped, tmp_path, monkeypatch):
    """A cache 'folder' that is a file: the linearisation is computed (as without the cache), no error."""
    path, _ = wrapped
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("SPINECTL_CACHE_DIR", str(blocker / "cache"))
    fresh = opensim_engine.load_osim(path, cache=False).linearise("sagittal")[0]
    assert _identical(opensim_engine.load_osim(path).linearise("sagittal")[0], fresh)


SHARED = POSE2SIM
POSE2SIM_CHAIN = [f"{joint}_Flex_Ext" for joint in ("L5_S1", "L4_L5", "L3_L4", "L2_L3", "L1_L2", "L1_T12")]


@pytest.mark.skipif(not SHARED.is_file(), reason=ABSENT)
def test_the_geometry_is_the_present_paths_on_a_published_model(tmp_path):
    """The Pose2Sim model (318 muscles, 41 wrap cylinders and 3 ellipsoids: latissimus dorsi over the torso), its
    muscles made rigid-tendon Millard in a temporary copy: arms, Hessians and passive torques over its lumbar
    flexion coordinates equal the present path's to the tolerances of test_the_geometry_is_the_present_paths.
    Why the arms are not differences of getLength: over the ellipsoid, LD_L2_r's length changes with L1_T12 at
    1.99 times the rate of its arm (central differences, step 1e-6 rad; the arm is what OpenSim's forces follow)."""
    copy = tmp_path / "pose2sim_millard.osim"
    rigid_millard_copy(SHARED, copy)
    engine = opensim_engine.load_engine(copy, cache=False)
    geo = geometry(engine, POSE2SIM_CHAIN, {}, opensim_engine._mobility_order(engine))
    arms, hessian, passive, dpassive = present_geometry(engine, POSE2SIM_CHAIN, {})
    assert np.max(np.abs(geo.arms - arms)) <= 1e-12 * np.max(np.abs(arms))
    assert np.max(np.abs(geo.hessian - hessian)) <= 1e-6 * np.max(np.abs(hessian))
    assert np.max(np.abs(geo.passive - passive)) <= 1e-12 * np.max(np.abs(passive))
    assert np.max(np.abs(geo.dpassive - dpassive)) <= 1e-8 * np.max(np.abs(dpassive))
    muscles = engine.model.getMuscles()
    index = next(i for i in range(muscles.getSize()) if muscles.get(i).getName() == "LD_L2_r")
    sides = []
    for sign in (1.0, -1.0):
        engine.set_posture({"L1_T12_Flex_Ext": sign * 1e-6})
        sides.append(muscles.get(index).getLength(engine.state))
    assert abs((sides[0] - sides[1]) / 2e-6 / geo.arms[index, -1] - 1.99) <= 0.01


def test_an_engine_keeps_its_latest_linearisations_only(wrapped, cache, monkeypatch):
    """With KEPT = 2, three postures leave the last two in the engine's memory (a sweep does not grow it without
    bound); the first is read back from the cache, identical."""
    path, _ = wrapped
    monkeypatch.setattr(opensim_engine, "KEPT", 2)
    anatomy = opensim_engine.load_osim(path)
    first = anatomy.linearise("sagittal", {"L4L5": 0.01})[0]
    for angle in (0.02, 0.03):
        anatomy.linearise("sagittal", {"L4L5": angle})
    assert len(anatomy.engine.linearisations) == 2
    _refuse_to_compute(monkeypatch)
    assert _identical(anatomy.linearise("sagittal", {"L4L5": 0.01})[0], first)
