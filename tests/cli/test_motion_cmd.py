"""``spinectl motion``: the NetCDF file and figure it writes, and one line for every malformed option (MyoTorso).

The motion is MyoTorso's lumbar flexion and return over one second at 20 Hz (21 frames), written in the test
through OpenSim's API (``TimeSeriesTable``, ``STOFileAdapter``); the numbers in the file are checked against
the library's :func:`spinectl.anatomy.motion.motion_response` (tests/anatomy/test_motion.py checks those
against ``analyse``).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl.cli import main  # noqa: E402

TIMES = np.linspace(0.0, 1.0, 21)
"""One second at 20 Hz."""


def _write(path, labels, rows, degrees="yes"):
    """A .mot/.sto written by OpenSim's STOFileAdapter, one row per time of :data:`TIMES`."""
    table = osim.TimeSeriesTable()
    table.setColumnLabels(osim.StdVectorString(list(labels)))
    for t, row in zip(TIMES, rows, strict=True):
        table.appendRow(float(t), osim.RowVector(np.asarray(row, float)))
    if degrees is not None:  # an activations file has no inDegrees
        table.addTableMetaDataString("inDegrees", degrees)
    osim.STOFileAdapter.write(table, str(path))
    return path


@pytest.fixture(scope="module")
def torso():
    from spinectl import anatomy

    return anatomy.load("myotorso")


@pytest.fixture(scope="module")
def flexion(torso, tmp_path_factory):
    """MyoTorso's flexion and return (-8 sin(pi t) deg at each sagittal chain joint), every coordinate given."""
    names = list(torso.posture_columns().required)
    rows = np.zeros((TIMES.size, len(names)))
    for joint in torso.plane_joints("sagittal"):
        rows[:, names.index(joint)] = -8.0 * np.sin(np.pi * TIMES)
    return _write(tmp_path_factory.mktemp("motion") / "flexion.mot", names, rows)


def test_the_file_opens_with_xarray_and_holds_the_librarys_numbers(torso, flexion, tmp_path, capsys):
    """--rate 5 on a 20 Hz file: six frames (0, 0.2, ..., 1 s); the NetCDF file opens with xarray, has the dims,
    the units and the model's hash, its index is the library's; --plot writes motion.png; the summary names both
    criteria."""
    import xarray as xr

    from spinectl.anatomy.identity import model_identity
    from spinectl.anatomy.motion import motion_response
    from spinectl.anatomy.recordings import read_recording

    out, plots = tmp_path / "motion.nc", tmp_path / "figures"
    assert (
        main(
            [
                "motion",
                "myotorso",
                "--coordinates",
                str(flexion),
                "--rate",
                "5",
                "--out",
                str(out),
                "--plot",
                str(plots),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "free" in printed and "rhythm" in printed
    with xr.open_dataset(out) as ds:
        np.testing.assert_allclose(ds["time"].values, np.linspace(0, 1, 6), atol=1e-12)
        assert {"time", "joint", "mode", "muscle"} <= set(ds.sizes)
        assert ds["free_index"].attrs["units"] == "N m/rad" and ds["net_torque"].attrs["units"] == "N m"
        assert ds.attrs["model_sha256"] == model_identity(torso)["sha256"]
        expected = motion_response(torso, read_recording(flexion, "posture"), rate=5.0, progress=False).dataset
        np.testing.assert_array_equal(ds["free_index"].values, expected["free_index"].values)
        np.testing.assert_array_equal(ds["constrained_index"].values, expected["constrained_index"].values)
        from spinectl.anatomy.motion_figures import motion_figure

        assert len(motion_figure(ds).axes) == 3  # the file alone draws the figure again
    assert (plots / "motion.png").stat().st_size > 0


def test_frames_select_the_frames_meant(flexion, tmp_path):
    """--frames 2:14:4: frames 2, 6, 10, 14 (0.1, 0.3, 0.5, 0.7 s)."""
    import xarray as xr

    out = tmp_path / "m.nc"
    assert main(["motion", "myotorso", "--coordinates", str(flexion), "--frames", "2:14:4", "--out", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        np.testing.assert_allclose(ds["time"].values, TIMES[[2, 6, 10, 14]], atol=1e-12)


@pytest.mark.parametrize(
    ("argv", "word"),
    [
        (["--frames", "0:21"], "--frames"),
        (["--frames", "4:3"], "--frames"),
        (["--frames", "1:x"], "--frames"),
        (["--frames", "1"], "--frames"),
        (["--rate", "0"], "--rate"),
        (["--rate", "-1"], "--rate"),
        (["--rate", "20.5"], "20 Hz"),
        (["--rate", "nan"], "--rate"),
        (["--rate", "5", "--frames", "0:3"], "cannot go with"),
        (["--optimise", "chain", "--activations", "a.sto"], "--optimise"),
        (["--optimise", "all"], "--optimise"),
        (["--joint-stiffness", "-3"], "--joint-stiffness"),
        (["--least-stiffness", "-1"], "--least-stiffness"),
        (["--frames", "0:3:-2"], "--frames"),
        (["--removal", "muscles", "--optimise", "joints"], "--removal"),
        (["--removal", "every"], "--removal"),
        (["--group", "back=IL"], "--group"),
        (["--removal", "--group", "back"], "--group"),
        (["--removal", "--group", "back=zzz"], "zzz"),
        (["--removal", "--group", "back=IL["], "regular expression"),
    ],
)
def test_a_malformed_option_is_one_line_and_writes_nothing(flexion, tmp_path, capsys, argv, word):
    """Each: exit 2, one line on stderr naming the option, nothing on stdout, no file written."""
    out = tmp_path / "m.nc"
    assert main(["motion", "myotorso", "--coordinates", str(flexion), "--out", str(out), *argv]) == 2
    printed, err = capsys.readouterr()
    assert printed == "" and len(err.strip().splitlines()) == 1 and err.startswith("spinectl: error: ")
    assert word in err and not out.exists()


@pytest.mark.parametrize("where", ["folder", "file-as-folder"])
def test_an_unwritable_out_is_one_line_before_the_run(flexion, tmp_path, capsys, where):
    """--out a folder, or below a file: one line naming it, exit 2, before any frame is computed."""
    (tmp_path / "folder").mkdir()
    (tmp_path / "plain").write_text("x")
    out = tmp_path / "folder" if where == "folder" else tmp_path / "plain" / "m.nc"
    assert main(["motion", "myotorso", "--coordinates", str(flexion), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and str(out.name) in err


def test_a_nan_frame_in_the_middle_fails_and_leaves_nothing_half_written(torso, tmp_path, capsys):
    """A NaN at frame 12 of 21: exit 2, one line naming the column and time; neither the NetCDF file nor the
    figure's folder exists (nothing is written before every frame is computed)."""
    names = list(torso.posture_columns().required)
    rows = np.zeros((TIMES.size, len(names)))
    rows[12, names.index("L3_L4_FE")] = np.nan
    path = _write(tmp_path / "nan.mot", names, rows)
    out, plots = tmp_path / "m.nc", tmp_path / "figures"
    assert main(["motion", "myotorso", "--coordinates", str(path), "--out", str(out), "--plot", str(plots)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "L3_L4_FE" in err and "0.6" in err
    assert not out.exists() and not plots.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["nan.mot"]  # no temporary left either


@pytest.mark.parametrize(("change", "word"), [("missing", "flex_extension"), ("extra", "knee_angle_r")])
def test_a_column_that_does_not_fit_the_model_is_one_line(torso, tmp_path, capsys, change, word):
    """A coordinate of the model missing from the file, or a column naming none of its coordinates: one line naming
    it, exit 2, nothing written (the rules of anatomy --posture, tests/anatomy/test_recordings.py)."""
    names = list(torso.posture_columns().required)
    names = names[1:] if change == "missing" else [*names, "knee_angle_r"]
    path = _write(tmp_path / "bad.mot", names, np.zeros((TIMES.size, len(names))))
    out = tmp_path / "m.nc"
    assert main(["motion", "myotorso", "--coordinates", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and word in err and not out.exists()


def test_out_naming_the_coordinates_file_is_refused(flexion, capsys):
    """--out the --coordinates file itself: one line, exit 2, the input left as it was."""
    before = flexion.read_bytes()
    assert main(["motion", "myotorso", "--coordinates", str(flexion), "--out", str(flexion)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--out" in err and flexion.read_bytes() == before


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    frames=st.one_of(
        st.none(),
        st.tuples(st.integers(-3, 25), st.integers(-3, 25), st.integers(-1, 12)).map(lambda t: ":".join(map(str, t))),
        st.text("0123456789:-x.", max_size=8),
    ),
    rate=st.one_of(st.none(), st.floats(allow_nan=True, allow_infinity=True).map(repr), st.floats(-5, 30).map(repr)),
)
def test_random_frame_selections_end_in_a_file_or_one_line(flexion, tmp_path, capsys, frames, rate):
    """Any --frames and --rate text: exit 0 with the file written and every time one of the file's frames, or exit
    2 with one error line and no file (the contract of tests/suites/test_cli_fuzz.py, on this command's options)."""
    import xarray as xr

    out = tmp_path / "fuzz.nc"
    out.unlink(missing_ok=True)
    argv = ["motion", "myotorso", "--coordinates", str(flexion), "--out", str(out)]
    argv += [f"--frames={frames}"] if frames is not None else []
    argv += [f"--rate={rate}"] if rate is not None else []
    code = main(argv)
    printed, err = capsys.readouterr()
    assert code in (0, 2), (argv, err)
    if code == 2:
        assert printed == "" and len(err.strip().splitlines()) == 1 and not out.exists(), (argv, err)
    else:
        with xr.open_dataset(out) as ds:
            assert np.isin(np.round(ds["time"].values, 9), np.round(TIMES, 9)).all()


def test_activations_and_the_least_stiffness_reach_the_file(torso, flexion, tmp_path):
    """--activations (a .sto at the same 21 times, written by OpenSim's API) and --least-stiffness 5: the file's
    activations are the .sto's (to its text's round-off), its source names the file, and the least stiffness is
    there with its margin, not zero where the free chain is unstable (tests/anatomy/test_motion.py checks that
    it stabilises)."""
    import xarray as xr

    a = np.random.default_rng(11).uniform(0.0, 0.2, (TIMES.size, len(torso.muscles)))
    sto = _write(tmp_path / "so.sto", torso.muscles, a, degrees=None)
    out = tmp_path / "m.nc"
    argv = ["motion", "myotorso", "--coordinates", str(flexion), "--activations", str(sto), "--frames", "0:20:20"]
    assert main([*argv, "--least-stiffness", "5", "--out", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        np.testing.assert_allclose(ds["activation"].values, a[[0, 20]], rtol=1e-15, atol=1e-16)
        assert ds.attrs["activation_source"] == "activations from so.sto"
        assert ds["least_joint_stiffness"].attrs["margin"] == 5.0
        assert np.all(ds["least_joint_stiffness"].values.sum(axis=1) > 0)  # the free chain is unstable there


def test_an_unwritable_plot_folder_is_one_line_before_anything_is_written(flexion, tmp_path, capsys):
    """--plot naming a regular file: one line, exit 2, before the run; the NetCDF file is not written either (the
    figure is checked first, so the file never stands without it)."""
    plots = tmp_path / "plots"
    plots.write_text("a file")
    out = tmp_path / "m.nc"
    assert main(["motion", "myotorso", "--coordinates", str(flexion), "--out", str(out), "--plot", str(plots)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "plots" in err and not out.exists()


def test_a_load_contributions_and_a_reflex_reach_the_file(torso, flexion, tmp_path, capsys):
    """--load, --contributions, --kp/--kd: the file holds the library's numbers with the same load (a second
    call of motion_response), the load in its attributes and the summary, per-muscle and per-class contributions
    and the delay margin with its gains."""
    import xarray as xr

    from spinectl.anatomy.loads import body_loads
    from spinectl.anatomy.motion import motion_response
    from spinectl.anatomy.recordings import read_recording

    out = tmp_path / "m.nc"
    argv = ["motion", "myotorso", "--coordinates", str(flexion), "--frames", "0:20:20", "--load", "torso:0,0,-100"]
    argv += ["--contributions", "--kp", "400", "--kd", "20", "--joint-stiffness", "200", "--out", str(out)]
    assert main(argv) == 0
    assert "F = (0, 0, -100) N at (0, 0, 0) m of torso" in capsys.readouterr().out
    load = body_loads([{"body": "torso", "force": (0.0, 0.0, -100.0)}])
    expected = motion_response(
        torso,
        read_recording(flexion, "posture"),
        frames=(0, 20, 20),
        joint_stiffness=200.0,
        loads=load,
        contributions=True,
        reflex=(400.0, 20.0, 0.05),
        progress=False,
    ).dataset
    with xr.open_dataset(out) as ds:
        for name in ("free_index", "free_contribution", "constrained_class_contribution"):
            np.testing.assert_array_equal(ds[name].values, expected[name].values)
        # the delay margin is an iterative root (its last bit varies with the solver's warm state): to 1e-12
        np.testing.assert_allclose(ds["delay_margin"].values, expected["delay_margin"].values, rtol=1e-12)
        assert ds["delay_margin"].attrs["kd"] == 20.0 and ds.sizes["muscle_class"] >= 2
        assert "torso" in ds.attrs["loads"]


@pytest.mark.parametrize(
    ("argv", "word"),
    [
        (["--load", "torso:0,0"], "--load"),
        (["--load", "torso:0,0,nan"], "--load"),
        (["--load", "torso:0,0,1e12"], "--load"),
        (["--load", "no_such_body:0,0,-10"], "no_such_body"),
        (["--kp", "-1"], "--kp"),
        (["--kp", "10", "--activation-lag", "inf"], "--activation-lag"),
    ],
)
def test_a_malformed_load_or_reflex_is_one_line_and_writes_nothing(flexion, tmp_path, capsys, argv, word):
    """Each: exit 2, one line on stderr naming the option (or the unknown body), nothing written."""
    out = tmp_path / "m.nc"
    assert main(["motion", "myotorso", "--coordinates", str(flexion), "--frames", "0:0", "--out", str(out), *argv]) == 2
    printed, err = capsys.readouterr()
    assert len(err.strip().splitlines()) == 1 and err.startswith("spinectl: error: ")
    assert word in err and not out.exists()


def test_the_removal_reaches_the_file_and_its_figure(torso, flexion, tmp_path, capsys):
    """--removal --group with --activations and --plot: the file's removal is the library's (motion_response with
    the same arguments, bit for bit), its status 'removed'; removal.png is written beside motion.png and the
    summary names the method."""
    import xarray as xr

    from spinectl.anatomy.motion import motion_response
    from spinectl.anatomy.recordings import read_recording

    a = np.random.default_rng(5).uniform(0.0, 0.2, (TIMES.size, len(torso.muscles)))
    sto = _write(tmp_path / "so.sto", torso.muscles, a, degrees=None)
    out, plots = tmp_path / "m.nc", tmp_path / "figures"
    argv = ["motion", "myotorso", "--coordinates", str(flexion), "--activations", str(sto), "--frames", "0:20:10"]
    assert main([*argv, "--removal", "--group", "back=IL|LTp", "--out", str(out), "--plot", str(plots)]) == 0
    assert "removal: the removed muscles at 0" in capsys.readouterr().out
    expected = motion_response(
        torso,
        read_recording(flexion, "posture"),
        read_recording(sto, "activations"),
        frames=(0, 20, 10),
        removal="groups",
        groups={"back": "IL|LTp"},
        progress=False,
    ).dataset
    with xr.open_dataset(out) as ds:
        assert list(ds["group"].values)[-1] == "group:back" and set(ds["removal_status"].values.ravel()) == {"removed"}
        for name in ("free_removed_index", "constrained_removed_change"):
            np.testing.assert_array_equal(ds[name].values, expected[name].values)
    assert (plots / "removal.png").stat().st_size > 0 and (plots / "motion.png").is_file()
