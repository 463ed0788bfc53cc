"""The stability index along a recorded motion (spinectl.anatomy.motion), on files written by OpenSim's API.

The second path for every number is :func:`spinectl.anatomy.analyses.analyse` called at each frame's time with
the same files (its own reading of them, its own linearisation): the index of each chain, its mode and the
count of unstable modes must be equal to it. The motions are a flexion of the lumbar joints and its return over
one second at 20 Hz (21 frames), on MyoTorso (MuJoCo) and on spinectl's export of the paper's chain (OpenSim).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from shared_models import ABSENT, POSE2SIM  # noqa: E402 (tests/anatomy/shared_models.py)
from test_recordings import write_table  # noqa: E402 (tests/anatomy/test_recordings.py: OpenSim's STOFileAdapter)

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.export_osim import export_osim  # noqa: E402
from spinectl.anatomy.identity import model_identity  # noqa: E402
from spinectl.anatomy.loads import body_loads  # noqa: E402
from spinectl.anatomy.motion import motion_plot, motion_response, select_frames  # noqa: E402
from spinectl.anatomy.recordings import read_recording  # noqa: E402
from spinectl.errors import ParameterError  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402

TIMES = np.linspace(0.0, 1.0, 21)
"""One second at 20 Hz."""

FLEXION = -8.0 * np.sin(np.pi * TIMES)
"""Each lumbar joint's angle [deg]: a flexion (MyoTorso's flex_extension is positive in extension) and return."""


def flexion_file(model, path, plane="sagittal"):
    """A .mot (degrees) of every coordinate of ``model``: the chain's joints flex and return, the rest at 0."""
    names = list(model.posture_columns().required)
    rows = np.zeros((TIMES.size, len(names)))
    for joint in model.plane_joints(plane):
        rows[:, names.index(joint)] = FLEXION
    return write_table(path, names, rows, times=TIMES, degrees="yes")


@pytest.fixture(scope="module")
def torso_motion(torso, tmp_path_factory):
    """MyoTorso's flexion file and the motion computed from it (every frame, the model's own controls)."""
    path = flexion_file(torso, tmp_path_factory.mktemp("motion") / "flexion.mot")
    return path, motion_response(torso, read_recording(path, "posture"), progress=False)


def _assert_as_analysed(result, model, path, activation=None, rtol=0.0):
    """Each frame's index, mode and unstable count equal analyse at that frame's time (bit for bit at rtol 0)."""
    ds = result.dataset
    for i, t in enumerate(ds["time"].values):
        one = analyse(model, posture=path, activation=activation, time=float(t))
        for name, chain in (("free", one.free), ("constrained", one.constrained)):
            np.testing.assert_allclose(ds[f"{name}_eigenvalues"].values[i], chain.eigenvalues, rtol=rtol, atol=0)
            assert ds[f"{name}_index"].values[i] == ds[f"{name}_eigenvalues"].values[i, 0]
            assert ds[f"{name}_unstable_modes"].values[i] == np.sum(chain.eigenvalues <= 0)
            shape = ds[f"{name}_mode_shape"].values[i]
            np.testing.assert_allclose(abs(shape @ chain.modes[:, 0]), 1.0, rtol=1e-12)  # the same mode, up to sign
    return ds


def test_myotorso_index_at_each_frame_is_analyse_at_that_frame(torso, torso_motion):
    """MyoTorso, 21 frames: every frame's index (free and constrained) is analyse's at that time, bit for bit
    (the same linearisation of the same posture); the index changes along the motion (the test can fail)."""
    path, result = torso_motion
    ds = _assert_as_analysed(result, torso, path)
    assert ds.sizes["time"] == 21 and np.ptp(ds["free_index"].values) > 10.0  # N m/rad: the posture matters
    np.testing.assert_allclose(np.degrees(ds["posture"].values[:, 0]), FLEXION, atol=1e-12)  # the file's angles


def test_activations_from_a_file_are_read_at_each_frames_time(torso, tmp_path):
    """An activation file with a different vector per frame: each frame is analyse(posture=, activation=, time=)
    of the two files, and differs from the model's own controls (the test can fail)."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    rng = np.random.default_rng(7)
    a = rng.uniform(0.0, 0.3, (TIMES.size, len(torso.muscles)))
    sto = write_table(tmp_path / "so.sto", torso.muscles, a, times=TIMES)
    result = motion_response(
        torso, read_recording(path, "posture"), read_recording(sto, "activations"), frames=(0, 20, 5), progress=False
    )
    ds = _assert_as_analysed(result, torso, path, activation=sto)
    np.testing.assert_allclose(ds["activation"].values, a[::5], rtol=1e-15, atol=1e-16)  # the file's text round-off
    assert not np.allclose(ds["free_index"].values, analyse(torso, posture=path).free.eigenvalues[0])


def test_activations_without_a_frame_at_that_time_are_one_line(torso, tmp_path):
    """An activation file sampled at other times than the coordinates: refused, naming the file and its times."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    sto = write_table(tmp_path / "so.sto", torso.muscles, np.full((3, len(torso.muscles)), 0.1), times=[0, 0.3, 0.6])
    with pytest.raises(ParameterError, match="time of so.sto.s frames"):
        motion_response(torso, read_recording(path, "posture"), read_recording(sto, "activations"), progress=False)


def test_the_exported_osim_chain_index_is_analyse_at_each_frame(tmp_path):
    """spinectl's export of the paper's chain (OpenSim, five pin joints): the index at each of 21 frames is
    analyse's at that time, to 1e-12 relative (OpenSim's linearisation is deterministic at one state)."""
    model_path = tmp_path / "chain.osim"
    export_osim(load_preset("wagner2012"), 0.03, 0.04, model_path)
    loaded = anatomy.load(model_path)
    path = flexion_file(loaded, tmp_path / "flexion.mot")
    result = motion_response(loaded, read_recording(path, "posture"), progress=False)
    ds = _assert_as_analysed(result, loaded, path, rtol=1e-12)
    assert np.ptp(ds["free_index"].values) > 0


def test_the_dataset_has_its_dims_units_and_the_models_identity(torso, torso_motion):
    """Dims time, joint, mode, coordinate, constrained_mode, muscle; every variable has units and a description
    naming its criterion where it is a verdict; the model's identity is model_identity's."""
    ds = torso_motion[1].dataset
    assert {"time", "joint", "mode", "muscle", "coordinate", "constrained_mode"} <= set(ds.sizes)
    assert ds.sizes["muscle"] == len(torso.muscles) and tuple(ds["joint"].values) == torso.plane_joints("sagittal")
    for name in ds.data_vars:
        if name != "optimum_status":
            assert ds[name].attrs["units"] and ds[name].attrs["description"], name
    assert "free" in ds["free_index"].attrs["description"] and "rhythm" in ds["constrained_index"].attrs["description"]
    assert ds.attrs["model_sha256"] == model_identity(torso)["sha256"]
    assert ds["time"].attrs["units"] == "s" and ds["free_index"].attrs["units"] == "N m/rad"


def test_the_net_torque_is_the_linearisations_at_that_frame(torso, torso_motion):
    """The net torque on the chain's joints at a frame is the engine's linearisation's torque at that posture and
    the activations (a second computation from chains(), not through the motion's code)."""
    path, result = torso_motion
    rec = read_recording(path, "posture")
    posture = torso.named_posture(rec.frame(torso.posture_columns(), 0.5).values)
    a = torso.default_controls()
    _, _, lin = torso.chains("sagittal", posture)
    dofs = list(lin.dofs[: lin.n])
    expected = lin.torque_per_muscle[dofs] @ a + lin.torque_offset[dofs]
    np.testing.assert_array_equal(result.dataset["net_torque"].sel(time=0.5).values, expected)


def test_the_optimum_per_frame_is_the_optimum_at_that_posture(torso, tmp_path):
    """--optimise chain (50 N m/rad added so that it is feasible): each frame's activations are
    optimise(posture=that frame's) and its index analyse's at those activations."""
    from spinectl.anatomy.optimum import optimise

    path = flexion_file(torso, tmp_path / "flexion.mot")
    rec = read_recording(path, "posture")
    result = motion_response(torso, rec, optimise="chain", frames=(0, 10, 10), joint_stiffness=50.0, progress=False)
    ds = result.dataset
    for i, t in enumerate(ds["time"].values):
        posture = torso.named_posture(rec.frame(torso.posture_columns(), t).values)
        opt = optimise(torso, stability="chain", posture=posture, joint_stiffness=50.0)
        assert ds["optimum_status"].values[i] == opt.status
        np.testing.assert_array_equal(ds["activation"].values[i], opt.activations)
        one = analyse(torso, posture=path, activation=opt.activations, time=float(t), joint_stiffness=50.0)
        assert ds["free_index"].values[i] == one.free.eigenvalues[0]


def test_the_least_stiffness_stabilises_the_free_chain(torso, tmp_path):
    """least_stiffness=mu: at each frame -K + diag(k) has its least eigenvalue at least mu (eigvalsh, a second
    computation), and k is not zero where the free chain is unstable."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    rec = read_recording(path, "posture")
    ds = motion_response(torso, rec, frames=(0, 20, 10), least_stiffness=5.0, progress=False).dataset
    for i, t in enumerate(ds["time"].values):
        k = ds["least_joint_stiffness"].values[i]
        posture = torso.named_posture(rec.frame(torso.posture_columns(), t).values)
        stiffness = torso.chains("sagittal", posture)[0].stiffness(torso.default_controls())
        assert np.linalg.eigvalsh(-stiffness + np.diag(k)).min() >= 5.0 - 1e-9
        assert ds["free_index"].values[i] < 0 and k.sum() > 0


def test_frames_and_rate_select_the_frames_meant():
    """FIRST:LAST:STEP includes LAST; a rate picks the frame nearest each 1/rate s (20 Hz file: 3 Hz is 0, 1/3,
    2/3 s, nearest frames 0, 7 (0.35 s) and 13 (0.65 s); 5 Hz every fourth frame; the file's own rate all)."""
    np.testing.assert_array_equal(select_frames(TIMES, (1, 7, 3)), [1, 4, 7])
    np.testing.assert_array_equal(select_frames(TIMES, (20, 20, 1)), [20])
    np.testing.assert_array_equal(select_frames(TIMES, rate=3.0), [0, 7, 13, 20])
    np.testing.assert_array_equal(select_frames(TIMES, rate=5.0), np.arange(0, 21, 4))
    np.testing.assert_array_equal(select_frames(TIMES, rate=20.0), np.arange(21))
    np.testing.assert_array_equal(select_frames(TIMES), np.arange(21))


@pytest.mark.parametrize(
    ("frames", "rate", "word"),
    [
        ((0, 21, 1), None, "LAST <= 20"),
        ((5, 4, 1), None, "FIRST <= LAST"),
        ((-1, 3, 1), None, "0 <="),
        ((0, 3, 0), None, "STEP >= 1"),
        (None, 0.0, "> 0"),
        (None, -2.0, "> 0"),
        (None, 20.5, "20 Hz"),
        (None, float("nan"), "> 0"),
        ((0, 3, 1), 5.0, "cannot go with"),
    ],
)
def test_a_frame_selection_outside_the_file_is_refused(frames, rate, word):
    """Out of range, a step below 1, a rate <= 0, above the file's rate or NaN, both given: one ParameterError."""
    with pytest.raises(ParameterError, match=word):
        select_frames(TIMES, frames, rate)


def test_the_figure_names_its_criteria(torso_motion):
    """motion_plot: three panels (index, unstable modes, posture) sharing time; the index's legend names both
    criteria and the title says which index it is."""
    figure = motion_plot(torso_motion[1])
    index, modes, posture = figure.axes[:3]
    labels = [t.get_text() for t in index.get_legend().get_texts()]
    assert any("free" in label for label in labels) and any("rhythm" in label for label in labels)
    assert "Cholewicki-McGill" in index.get_title() and len(posture.get_lines()) == 5


@pytest.mark.skipif(not POSE2SIM.is_file(), reason=ABSENT)
def test_the_pose2sim_models_index_is_analyse_at_each_frame(tmp_path):
    """The shared Pose2Sim model (OpenSim, 318 muscles, its lumbar couplers as the rhythm), with docs/anatomy.md's
    mapping: a flexion of its six sagittal joints from the model's default posture (every other coordinate at its
    default), four frames; each frame's index, free and constrained, is analyse's at that time to 1e-12."""
    from test_mapping import _documented_mappings  # tests/anatomy/test_mapping.py: the mapping as documented

    mapping = tmp_path / "pose2sim.toml"
    mapping.write_text(_documented_mappings()[0], encoding="utf-8")
    model = anatomy.load(POSE2SIM, mapping)
    names = list(model.posture_columns().required)
    rotational = model.posture_columns().rotational
    default = [model.engine.coordinate(n).getDefaultValue() for n in names]
    rows = np.tile([np.degrees(v) if n in rotational else v for n, v in zip(names, default, strict=True)], (4, 1))
    times = np.array([0.0, 0.25, 0.5, 0.75])
    for joint in model.plane_joints("sagittal"):
        rows[:, names.index(joint)] += -5.0 * np.sin(np.pi * times)
    path = write_table(tmp_path / "flexion.mot", names, rows, times=times, degrees="yes")
    result = motion_response(model, read_recording(path, "posture"), progress=False)
    ds = _assert_as_analysed(result, model, path, rtol=1e-12)
    assert np.ptp(ds["free_index"].values) > 1.0  # N m/rad: the posture matters


def test_write_motion_is_read_back_by_opensims_reader(tmp_path):
    """write_motion: OpenSim's reader gives back the labels, times, values (to the 1e-15 of the file's text) and
    inDegrees, for a posture in degrees and an activation file without the header key; no temporary is left."""
    from spinectl.anatomy.motion import write_motion

    rows = np.column_stack([FLEXION, 0.5 * FLEXION])
    posture = read_recording(write_motion(tmp_path / "m.mot", ["a", "b"], TIMES, rows), "posture")
    assert posture.labels == ("a", "b") and posture.in_degrees
    np.testing.assert_allclose(posture.times, TIMES, rtol=0, atol=1e-15)
    np.testing.assert_allclose(posture.values, rows, rtol=1e-15, atol=1e-15)
    acts = read_recording(write_motion(tmp_path / "a.sto", ["m1"], TIMES[:2], [[0.1], [0.2]], None), "activations")
    np.testing.assert_allclose(acts.values[:, 0], [0.1, 0.2], rtol=1e-15)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.sto", "m.mot"]


def test_the_progress_bar_goes_to_stderr_when_asked(torso, torso_motion, capsys):
    """progress=True: a bar named motion counting frames on stderr, nothing on stdout; progress=False: none."""
    rec = read_recording(torso_motion[0], "posture")
    motion_response(torso, rec, frames=(0, 2, 1), progress=True)
    out, err = capsys.readouterr()
    assert out == "" and "motion" in err and "3/3" in err and "frame" in err
    motion_response(torso, rec, frames=(0, 2, 1), progress=False)
    assert capsys.readouterr().err == ""


HAND_LOAD = body_loads(({"body": "torso", "force": (0.0, 0.0, -100.0), "point": (0.3, 0.0, 0.0), "frame": "ground"},))
"""100 N down, 0.3 m off the torso body's origin (a load held ahead of the thorax), fixed in the ground."""


def test_a_load_enters_every_frame_as_analyse_with_that_load(torso, tmp_path):
    """loads=: each frame's index, mode and unstable count equal analyse(..., loads=) at that frame's time, bit for
    bit; the net torque differs from the unloaded motion's (the load is in the equilibrium: the test can fail);
    the Dataset's attributes and the summary name the load."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    rec = read_recording(path, "posture")
    loaded = motion_response(torso, rec, frames=(0, 20, 10), loads=HAND_LOAD, progress=False)
    ds = loaded.dataset
    for i, t in enumerate(ds["time"].values):
        one = analyse(torso, posture=path, time=float(t), loads=HAND_LOAD)
        for name, chain in (("free", one.free), ("constrained", one.constrained)):
            np.testing.assert_array_equal(ds[f"{name}_eigenvalues"].values[i], chain.eigenvalues)
    bare = motion_response(torso, rec, frames=(0, 20, 10), progress=False).dataset
    assert not np.allclose(ds["net_torque"].values, bare["net_torque"].values)
    assert not np.allclose(ds["free_index"].values, bare["free_index"].values)
    assert json.loads(ds.attrs["loads"])[0]["force_N"] == [0.0, 0.0, -100.0]
    assert "F = (0, 0, -100) N at (0.3, 0, 0) m of torso" in loaded.summary()


def test_a_load_enters_the_optimum_per_frame(torso, tmp_path):
    """optimise='chain' with a load: the frame's activations are optimise(posture=, loads=)'s (the optimum holds
    the load), not the unloaded optimum's."""
    from spinectl.anatomy.optimum import optimise

    path = flexion_file(torso, tmp_path / "flexion.mot")
    rec = read_recording(path, "posture")
    ds = motion_response(
        torso, rec, optimise="chain", frames=(10, 10, 1), joint_stiffness=50.0, loads=HAND_LOAD, progress=False
    ).dataset
    posture = torso.named_posture(rec.frame(torso.posture_columns(), 0.5).values)
    opt = optimise(torso, stability="chain", posture=posture, joint_stiffness=50.0, loads=HAND_LOAD)
    np.testing.assert_array_equal(ds["activation"].values[0], opt.activations)
    bare = optimise(torso, stability="chain", posture=posture, joint_stiffness=50.0)
    assert not np.allclose(opt.activations, bare.activations)


def test_a_load_on_a_body_the_model_lacks_is_one_line(torso, tmp_path):
    """A load on a body MyoTorso has not: ParameterError naming loads (before any frame's result is kept)."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    bad = ({"body": "no_such_body", "force": (0.0, 0.0, -10.0)},)
    with pytest.raises(ParameterError, match="no_such_body"):
        motion_response(torso, read_recording(path, "posture"), frames=(0, 0, 1), loads=bad, progress=False)


def test_the_contributions_at_a_frame_are_contributions_on_that_frames_chain(torso, tmp_path):
    """contributions=True, with a load and random activations: at each frame the per-muscle d lambda_min / d a_i
    of both chains is spinectl.model.contributions.contributions on the chain that frame linearises (chains() at
    that posture, a second path), the class sums are its sums; Euler's identity holds (offset + sum a_i d_i =
    the index); they change along the motion (the test can fail)."""
    from spinectl.model.contributions import contributions

    path = flexion_file(torso, tmp_path / "flexion.mot")
    rec = read_recording(path, "posture")
    a = np.random.default_rng(3).uniform(0.0, 0.3, (TIMES.size, len(torso.muscles)))
    sto = write_table(tmp_path / "so.sto", torso.muscles, a, times=TIMES)
    result = motion_response(
        torso,
        rec,
        read_recording(sto, "activations"),
        frames=(0, 20, 10),
        loads=HAND_LOAD,
        contributions=True,
        progress=False,
    )
    ds = result.dataset
    classes = list(ds["muscle_class"].values)
    for i, t in enumerate(ds["time"].values):
        posture = torso.named_posture(rec.frame(torso.posture_columns(), t).values)
        at = ds["activation"].values[i]
        free, con, _ = torso.chains("sagittal", posture, activations=at, loads=HAND_LOAD)
        for name, chain in (("free", free), ("constrained", con)):
            c = contributions(chain, at)
            assert list(c.controls) == list(ds["muscle"].values)
            np.testing.assert_array_equal(ds[f"{name}_contribution"].values[i], c.derivative)
            sums = [c.sums(c.classes()[k])[0] for k in classes]
            np.testing.assert_array_equal(ds[f"{name}_class_contribution"].values[i], sums)
            np.testing.assert_allclose(c.offset + at @ c.derivative, ds[f"{name}_index"].values[i], rtol=1e-9)
    assert not np.allclose(ds["free_contribution"].values[0], ds["free_contribution"].values[1])
    assert ds["free_contribution"].attrs["units"] == "N m/rad per control unit"


def test_the_delay_margin_at_a_frame_is_analyses_reflex_margin(torso, tmp_path):
    """reflex=(kp, kd, lag) with 200 N m/rad added so that the chain is stable without delay: each frame's delay
    margin and crossing frequency are analyse(..., reflex=)'s at that frame (the same exact margin); finite and
    positive (the test can fail)."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    reflex = (400.0, 20.0, 0.05)
    ds = motion_response(
        torso,
        read_recording(path, "posture"),
        frames=(10, 10, 1),
        joint_stiffness=200.0,
        reflex=reflex,
        progress=False,
    ).dataset
    one = analyse(torso, posture=path, time=0.5, joint_stiffness=200.0, reflex=reflex).reflex
    # the same exact margin: an iterative root, whose last bit varies with the solver's warm state
    np.testing.assert_allclose(ds["delay_margin"].values[0], one["delay_margin_s"], rtol=1e-12)
    assert ds["delay_margin_status"].values[0] == one["delay_margin_status"]
    np.testing.assert_allclose(ds["delay_margin_frequency"].values[0], one["delay_margin_frequency_rad_s"], rtol=1e-9)
    assert ds["delay_margin"].attrs["kp"] == 400.0 and 0 < ds["delay_margin"].values[0] < np.inf


def test_the_figure_has_a_class_panel_with_contributions(torso, tmp_path):
    """contributions=True: a fourth panel between the modes and the posture, one line per class, its values the
    Dataset's free_class_contribution (the figure draws the file's numbers)."""
    path = flexion_file(torso, tmp_path / "flexion.mot")
    result = motion_response(
        torso, read_recording(path, "posture"), frames=(0, 20, 10), contributions=True, progress=False
    )
    axes = motion_plot(result).axes
    ds = result.dataset
    assert len(axes) == 4 and len(axes[2].get_lines()) == ds.sizes["muscle_class"] + 1  # and the zero line
    np.testing.assert_array_equal(axes[2].get_lines()[0].get_ydata(), ds["free_class_contribution"].values[:, 0])
