"""Postures and activations from OpenSim's files (spinectl.anatomy.recordings), on models built in the tests.

Every file is written by OpenSim's own API (``TimeSeriesTable`` and ``STOFileAdapter``), in degrees and in
radians; the expected operating point is the same posture or activations passed as Python values, which
reach the linearisation by the path the API always had. The small OpenSim model is spinectl's export of the
paper's chain (five pin joints, thirty Millard muscles); the MJCF model is MyoTorso.
"""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from shared_models import ABSENT, CYCLIST  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.export_osim import export_osim  # noqa: E402
from spinectl.anatomy.recordings import anatomy_point  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.errors import ParameterError  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402

DEG = (2.0, -3.0, 4.0, -1.0, 5.0)
"""A posture of the chain's five joints [deg], far enough from the reference to change K."""


def write_table(path, labels, rows, times=None, degrees="no"):
    """A .mot/.sto written by OpenSim's STOFileAdapter: one row per time, ``inDegrees`` as given (None: absent)."""
    table = osim.TimeSeriesTable()
    table.setColumnLabels(osim.StdVectorString(list(labels)))
    times = range(len(rows)) if times is None else times
    for t, row in zip(times, rows, strict=True):
        table.appendRow(float(t), osim.RowVector(np.asarray(row, float)))
    if degrees is not None:
        table.addTableMetaDataString("inDegrees", degrees)
    osim.STOFileAdapter.write(table, str(path))
    return path


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """spinectl's export of the wagner2012 chain as .osim, loaded by OpenSim: (anatomy, path, coordinates)."""
    path = tmp_path_factory.mktemp("osim") / "chain.osim"
    export_osim(load_preset("wagner2012"), 0.03, 0.04, path)
    loaded = anatomy.load(path)
    return loaded, path, loaded.posture_columns().required


def _paths(loaded, names):
    return [loaded.engine.coordinate(n).getAbsolutePathString() + "/value" for n in names]


def test_a_posture_file_in_degrees_is_the_posture_given_in_radians(chain, tmp_path):
    """The second frame of a file in degrees, by name, reaches the linearisation as the same dict in radians does:
    K equal to rounding; and it is not the reference posture's K (the test can fail)."""
    loaded, _, names = chain
    path = write_table(tmp_path / "ik.mot", names, [np.zeros(5), DEG], times=[0.0, 0.25], degrees="yes")
    read = analyse(loaded, posture=path, time=0.25)
    given = analyse(loaded, posture=dict(zip(names, np.radians(DEG), strict=True)))
    np.testing.assert_allclose(read.free.stiffness, given.free.stiffness, rtol=1e-12, atol=1e-9)
    assert not np.allclose(read.free.stiffness, analyse(loaded).free.stiffness, rtol=1e-6)
    assert read.posture_source == "ik.mot at t = 0.25 s (the time asked)"


def test_a_recording_read_once_gives_each_frame(chain, tmp_path):
    """read_recording reads a file once; each frame it gives is the one anatomy_point reads at that time (a motion
    of three frames in degrees), and the frames differ (the test can fail)."""
    from spinectl.anatomy.recordings import read_recording

    loaded, _, names = chain
    rows = [np.zeros(5), DEG, np.multiply(DEG, 2)]
    path = write_table(tmp_path / "motion.mot", names, rows, times=[0.0, 0.01, 0.02], degrees="yes")
    recording = read_recording(path, "posture")
    columns = loaded.posture_columns()
    frames = [recording.frame(columns, t).values for t in recording.times]
    assert recording.times.tolist() == [0.0, 0.01, 0.02]
    for t, values in zip(recording.times, frames, strict=True):
        assert values == anatomy_point(loaded, posture=path, time=t).posture
    assert frames[2]["L5S1"] == pytest.approx(2 * frames[1]["L5S1"]) and frames[1]["L5S1"] == pytest.approx(
        np.radians(2)
    )


def test_radians_by_path_in_a_states_file_is_the_same_posture(chain, tmp_path):
    """A states file (OpenSim's full paths, speeds and activations beside the values, radians): the values are
    the posture, the other states skipped; the first frame by default, and the table says so."""
    loaded, _, names = chain
    speeds = [p.replace("/value", "/speed") for p in _paths(loaded, names)]
    acts = [f"/forceset/{m}/activation" for m in loaded.muscles[:2]]
    row = [*np.radians(DEG), *np.ones(5), 0.1, 0.2]
    path = write_table(tmp_path / "states.sto", _paths(loaded, names) + speeds + acts, [row], degrees="no")
    point = anatomy_point(loaded, posture=path)
    assert point.posture == pytest.approx(dict(zip(names, np.radians(DEG), strict=True)), rel=1e-12)
    assert point.posture_source == "states.sto at t = 0 s (its one frame)"


def test_the_dict_takes_names_and_paths_by_the_same_rules(chain):
    """anatomy_point with a dict: names and paths, every coordinate; a path and a name of one coordinate refused."""
    loaded, _, names = chain
    mixed = dict(zip([names[0], *_paths(loaded, names[1:])], np.radians(DEG), strict=True))
    assert anatomy_point(loaded, posture=mixed).posture == pytest.approx(dict(zip(names, np.radians(DEG), strict=True)))
    with pytest.raises(ParameterError, match="both give coordinate"):
        anatomy_point(loaded, posture={**mixed, names[1]: 0.0})


def _bad_posture_file(case, loaded, names, tmp):
    """A malformed file (or option) of each kind: (path, further arguments, a word its one line must hold)."""
    paths, rad = _paths(loaded, names), np.radians(DEG)
    two = {"times": [0, 1]}
    if case == "unknown column":
        return write_table(tmp / "u.mot", [*names, "knee_angle_r"], [[*rad, 0]]), [], "knee_angle_r"
    if case == "unknown path":  # a coordinate's name under a joint the model lacks
        return write_table(tmp / "p.mot", [*paths[:4], "/jointset/x/L1L2/value"], [rad]), [], "/jointset/x"
    if case == "missing coordinate":
        return write_table(tmp / "m.mot", names[:4], [rad[:4]]), [], "missing 'L1L2'"
    if case == "name and path":
        return write_table(tmp / "d.mot", [*names, paths[0]], [[*rad, 0]]), [], "both give"
    if case in ("times decrease", "time repeated"):  # STOFileAdapter writes increasing times: edited as text
        path = write_table(tmp / "t.mot", names, [rad, rad], **two)
        old, new = ("\n0\t", "\n2\t") if case == "times decrease" else ("\n1\t", "\n0\t")  # 2 then 1; 0 then 0
        path.write_text(path.read_text().replace(old, new))
        return path, [], "greater-than/equal"
    if case == "nan at the frame":
        return write_table(tmp / "n.mot", names, [rad, [np.nan, *rad[1:]]], **two), ["--time", "1"], "NaN"
    if case == "a word for a number":
        path = write_table(tmp / "w.mot", names, [rad])
        lines = path.read_text().splitlines()
        lines[-1] = lines[-1].rsplit("\t", 1)[0] + "\tabc"
        path.write_text("\n".join(lines) + "\n")
        return path, [], "NaN"
    if case == "time not a frame":
        return write_table(tmp / "f.mot", names, [rad, rad], **two), ["--time", "0.5"], "(got 0.5)"
    if case == "no inDegrees":
        return write_table(tmp / "h.mot", names, [rad], degrees=None), [], "inDegrees"
    if case in ("not a table", "header cut short", "empty"):  # OpenSim's reader never returned on these
        text = {"not a table": "not a table\n", "header cut short": "inDegrees=no\nendheader\n\n", "empty": ""}
        (tmp / "x.mot").write_text(text[case])
        return tmp / "x.mot", [], "no OpenSim .mot or .sto file"
    if case == "no rows":
        (tmp / "r.mot").write_text("inDegrees=no\nendheader\ntime\t" + "\t".join(names) + "\n")
        return tmp / "r.mot", [], "no frame"
    if case == "no such file":
        return tmp / "absent.mot", [], "no such file"
    return tmp, [], "not a regular file"


BAD_POSTURES = (
    "unknown column",
    "unknown path",
    "missing coordinate",
    "name and path",
    "times decrease",
    "time repeated",
    "nan at the frame",
    "a word for a number",
    "time not a frame",
    "no inDegrees",
    "not a table",
    "header cut short",
    "empty",
    "no rows",
    "no such file",
    "a folder",
)


@pytest.mark.parametrize("case", BAD_POSTURES)
def test_a_malformed_posture_file_is_one_line(chain, tmp_path, capsys, case):
    """Each malformed posture file: exit 2, one line on stderr naming the fault, nothing on stdout."""
    loaded, model_path, names = chain
    path, extra, word = _bad_posture_file(case, loaded, names, tmp_path)
    assert main(["anatomy", str(model_path), "--posture", str(path), *extra]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1 and err.startswith("spinectl: error: ")
    assert word in err


def test_activations_from_a_file_are_the_vector_given(chain, tmp_path):
    """A .sto of activations (names, then paths ending /activation) gives the same K as the vector; the table
    and JSON name the file as the activations' source."""
    loaded, _, _ = chain
    a = np.linspace(0.05, 0.6, len(loaded.muscles))
    by_name = write_table(tmp_path / "so.sto", loaded.muscles, [a])
    by_path = write_table(tmp_path / "p.sto", [f"/forceset/{m}/activation" for m in loaded.muscles], [a])
    expected = analyse(loaded, activation=a).free.stiffness
    for path in (by_name, by_path):
        result = analyse(loaded, activation=path)
        np.testing.assert_allclose(result.free.stiffness, expected, rtol=1e-12)
        assert result.activation_source == f"{path.name} at t = 0 s (its one frame)"
    assert not np.allclose(expected, analyse(loaded, activation=0.01).free.stiffness)


@pytest.mark.parametrize(
    ("change", "word"),
    [
        ("above one", "must be in [0.01, 1]"),
        ("negative", "must be in [0.01, 1]"),
        ("missing", "missing"),
        ("extra", "name no muscle"),
    ],
)
def test_malformed_activations_are_one_line(chain, tmp_path, capsys, change, word):
    """Activations outside [0, 1], a muscle missing, a column naming no muscle: exit 2, one line."""
    loaded, model_path, _ = chain
    labels, a = list(loaded.muscles), np.full(len(loaded.muscles), 0.1)
    if change == "above one":
        a[3] = 1.2
    elif change == "negative":
        a[-1] = -0.01
    elif change == "missing":
        labels, a = labels[1:], a[1:]
    else:
        labels, a = [*labels, "reserve_L5S1"], np.append(a, 0.0)
    path = write_table(tmp_path / "a.sto", labels, [a])
    assert main(["anatomy", str(model_path), "--activations", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1 and word in err


@pytest.mark.parametrize(
    ("argv", "word"),
    [
        (["--time", "0"], "--time"),
        (["--optimise", "--activations", "a.sto"], "--optimise"),
        (["--activation", "0.1", "--activations", "a.sto"], "--activation"),
        (["--posture", "p.mot", "--lordosis", "-1:1:3"], "--lordosis"),
    ],
)
def test_options_that_cannot_go_together_are_one_line(chain, capsys, argv, word):
    """--time without a file, --activations with --optimise or --activation, --posture with --lordosis."""
    assert main(["anatomy", str(chain[1]), *argv]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and word in err


def test_the_model_is_identified_by_its_hash_engine_and_versions(chain, capsys):
    """The JSON's model: the .osim file's SHA-256 (hashlib on its bytes), OpenSim's version (the module's) and
    spinectl's; the table's first line shows the hash's first 12 digits, the engine and the versions."""
    import json

    import spinectl

    _, path, _ = chain
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    assert main(["anatomy", str(path), "--json"]) == 0
    model = json.loads(capsys.readouterr().out)["model"]
    assert model["sha256"] == digest and model["sha256_short"] == digest[:12] and model["engine"] == "OpenSim"
    assert model["versions"] == {"opensim": osim.__version__, "spinectl": spinectl.__version__}
    assert main(["anatomy", str(path)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    versions = f"opensim {osim.__version__}, spinectl {spinectl.__version__}"
    assert first.startswith(f"wagner2012_chain (sha256 {digest[:12]}; OpenSim; {versions}), sagittal plane, posture: ")


def test_opensim_missing_is_one_line_for_an_mjcf_model(torso, tmp_path, monkeypatch):
    """OpenSim is an extra: --posture on MyoTorso without it says what to install, in one line."""
    import sys

    from spinectl.anatomy.export_osim import OpenSimUnavailable

    monkeypatch.setitem(sys.modules, "opensim", None)  # import opensim raises ImportError
    with pytest.raises(OpenSimUnavailable, match=r"--posture reads the file with OpenSim.*pip install"):
        anatomy_point(torso, posture=tmp_path / "p.mot")


def test_myotorso_posture_by_joint_name_in_degrees(torso, tmp_path):
    """MyoTorso (MuJoCo): a posture file of every joint by name, in degrees, is the qpos with the hinges set in
    radians and the slides (the abdomen's translations) in metres, as given; its linearisation equals the one at
    that qpos given directly."""
    import mujoco

    model = torso.engine.model
    columns = torso.posture_columns()
    names = list(columns.required)
    kinds = np.bincount(model.jnt_type, minlength=4)  # MuJoCo's own count: 16 hinges, 2 slides (the abdomen's)
    assert len(names) == model.njnt == kinds[2] + kinds[3] and len(columns.rotational) == kinds[3] == 16
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in names]
    hinge = np.array([model.jnt_type[j] == int(mujoco.mjtJoint.mjJNT_HINGE) for j in ids])
    rng = np.random.default_rng(3)
    given = np.where(hinge, rng.uniform(-3, 3, len(names)), rng.uniform(-0.003, 0.003, len(names)))  # [deg], [m]
    path = write_table(tmp_path / "torso.mot", names, [given], degrees="yes")
    q = model.qpos0.copy()
    q[model.jnt_qposadr[ids]] = np.where(hinge, np.radians(given), given)
    point = anatomy_point(torso, posture=path)
    np.testing.assert_allclose(point.posture, q, rtol=0, atol=1e-15)
    assert np.abs(q - model.qpos0).max() > np.radians(1)  # a posture away from the reference
    read, direct = analyse(torso, posture=path), analyse(torso, posture=q)
    # to MuJoCo's rounding: two linearisations at one qpos differ by 2e-11 relative (its scratch state)
    np.testing.assert_allclose(read.free.stiffness, direct.free.stiffness, rtol=1e-9, atol=1e-8)
    assert not np.allclose(read.free.stiffness, analyse(torso).free.stiffness, rtol=1e-6)


def test_myotorso_activations_by_actuator_name(torso, tmp_path):
    """MyoTorso's activations from a .sto by actuator name equal the same vector given (K of the free chain)."""
    a = np.random.default_rng(4).uniform(0, 0.3, len(torso.muscles))
    path = write_table(tmp_path / "torso.sto", torso.muscles, [a])
    np.testing.assert_allclose(
        analyse(torso, activation=path).free.stiffness, analyse(torso, activation=a).free.stiffness, rtol=1e-12
    )


@pytest.mark.skipif(not CYCLIST.is_dir(), reason=ABSENT)
def test_the_cyclists_static_trial_is_read_as_published(tmp_path):
    """The Bruno/Allaire cyclist (s01modelScaled.osim) and its static trial s01static.mot as distributed: a states
    file of 1,349 columns (values, speeds, activations, fibre lengths; radians) gives all 171 coordinates and
    520 activations; each equals the file's number read by numpy's own text reader. (The model's Thelen muscles
    are read by no muscle law of this branch: the model is built without them through its engine.)"""
    from spinectl.anatomy.mapping import read_mapping
    from spinectl.anatomy.opensim_engine import OsimAnatomy, load_engine

    engine = load_engine(CYCLIST / "s01modelScaled.osim")
    muscles = engine.model.getMuscles()
    names = tuple(muscles.get(i).getName() for i in range(muscles.getSize()))
    mapping = tmp_path / "m.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["pelvis"]\nvertebrae = ["lumbar1"]\nthorax = ["thoracic12"]\n'
        '[planes]\nsagittal = ["L1_L2_FE"]\n'
    )
    model = OsimAnatomy(engine, read_mapping(mapping), names, ("between",) * len(names))
    trial = CYCLIST / "s01static.mot"
    point = anatomy_point(model, posture=trial, activations=trial)
    labels = trial.read_text().splitlines()[6].split("\t")
    row = np.loadtxt(trial, skiprows=7)
    assert len(point.posture) == 171 and point.activation.shape == (520,)
    assert point.posture["L5_S1_FE"] == row[labels.index("/jointset/L5_S1_IVDjnt/L5_S1_FE/value")]
    assert point.activation[0] == row[labels.index(f"/forceset/{names[0]}/activation")]
    assert point.posture_source == "s01static.mot at t = 0.01 s (its one frame)"


def test_the_optimum_at_a_posture_file_is_the_optimum_at_that_posture(torso, tmp_path):
    """optimised(posture=FILE): MyoTorso's chain optimum (50 N m/rad added) at a file's posture (every joint 2 deg
    from the reference, radians) is the optimum at that qpos given directly (same cost), not the reference's, and
    its analysis names the file."""
    from spinectl.anatomy.optimum import optimised

    names = list(torso.posture_columns().required)
    q = torso.named_posture({n: 0.0 for n in names})
    ids = torso.joint_ids(names)
    moved = torso.engine.model.qpos0[torso.engine.model.jnt_qposadr[ids]] + np.radians(2.0)
    path = write_table(tmp_path / "bent.sto", names, [moved], degrees="no")
    q[torso.engine.model.jnt_qposadr[ids]] = moved
    read = optimised(torso, joint_stiffness=50, posture=path)
    given = optimised(torso, joint_stiffness=50, posture=q)
    assert read.optimum.ok and read.optimum.cost == pytest.approx(given.optimum.cost, rel=1e-9)
    assert read.optimum.cost != pytest.approx(optimised(torso, joint_stiffness=50).optimum.cost, rel=1e-3)
    assert read.analysis.posture_source == "bent.sto at t = 0 s (its one frame)"
