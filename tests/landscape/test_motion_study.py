"""A study of motions (spinectl.landscape.study.motion_spec, motion_run): validation, bits, resume, the model cache.

The second path for every number is :func:`spinectl.anatomy.motion.motion_response` run on the trial alone
(every chunk of the study must give its bits, attributes included). The motion is a flexion of MyoTorso's
lumbar joints and its return over one second at 20 Hz (21 frames), written by OpenSim's API
(:func:`spinectl.anatomy.motion.write_motion`).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.motion import motion_response, write_motion  # noqa: E402
from spinectl.anatomy.recordings import read_recording  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.errors import ConfigError, OutputError, ParameterError  # noqa: E402
from spinectl.landscape.study import motion_run  # noqa: E402
from spinectl.landscape.study.motion_run import load_motions, run_motion_study  # noqa: E402
from spinectl.landscape.study.motion_spec import load_motion_study, parse_motion_study  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
TIMES = np.linspace(0.0, 1.0, 21)
FLEXION = -8.0 * np.sin(np.pi * TIMES)
"""Each lumbar joint's angle [deg]: a flexion and return (as tests/anatomy/test_motion.py)."""

STUDY = """
[study]
description = "two trials of one flexion"
chunk_frames = 8

[[trials]]
name = "all"
model = "myotorso"
coordinates = "flexion.mot"

[[trials]]
name = "stiff"
model = "myotorso"
coordinates = "flexion.mot"
frames = "2:20:3"
joint_stiffness = 50.0
"""
"""Trial "all": 21 frames in chunks of 8, 8, 5; trial "stiff": frames 2, 5, ..., 20 (7) in one chunk: 4 chunks."""


@pytest.fixture(scope="module")
def torso():
    return anatomy.load("myotorso")


@pytest.fixture(scope="module")
def folder(torso, tmp_path_factory):
    """A folder with the flexion file."""
    path = tmp_path_factory.mktemp("motions")
    names = list(torso.posture_columns().required)
    rows = np.zeros((TIMES.size, len(names)))
    for joint in torso.plane_joints("sagittal"):
        rows[:, names.index(joint)] = FLEXION
    write_motion(path / "flexion.mot", names, TIMES, rows)
    return path


@pytest.fixture(scope="module")
def reference(torso, folder):
    """Each trial's Dataset from motion_response run on it alone."""
    rec = read_recording(folder / "flexion.mot", "posture")
    return {
        "all": motion_response(torso, rec, progress=False).dataset,
        "stiff": motion_response(torso, rec, frames=(2, 20, 3), joint_stiffness=50.0, progress=False).dataset,
    }


def write(folder: Path, text: str = STUDY) -> Path:
    path = folder / "study.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_the_chunks_are_ranges_of_each_trials_frames(folder):
    """21 frames in chunks of 8: 0-7, 8-15, 16-20; the stepped trial's 7 frames in one chunk, its step kept."""
    parsed = load_motion_study(write(folder))
    frames = [(c.trial, c.frames) for c in (parsed.chunk(i) for i in range(parsed.n_chunks))]
    assert frames == [(0, (0, 7, 1)), (0, (8, 15, 1)), (0, (16, 20, 1)), (1, (2, 20, 3))]


def test_each_trial_is_motion_response_on_it_alone_bit_for_bit(folder, reference, tmp_path):
    """Chunks joined along time equal the trial run alone: values, coordinates and attributes."""
    result = run_motion_study(load_motion_study(write(folder)), tmp_path / "s", scheduler="synchronous", progress=False)
    assert (result.chunks, result.computed, result.complete) == (4, 4, True)
    got = load_motions(tmp_path / "s")
    assert list(got) == ["all", "stiff"]
    for name, expected in reference.items():
        xr.testing.assert_identical(got[name], expected)


def test_a_worker_loads_each_model_once(folder, monkeypatch, tmp_path):
    """Four chunks of two trials of one model: one load in the process (without the cache: four)."""
    calls = []
    real = anatomy.load
    monkeypatch.setattr(anatomy, "load", lambda *a, **k: calls.append(a) or real(*a, **k))
    motion_run._anatomy.cache_clear()
    run_motion_study(load_motion_study(write(folder)), tmp_path / "s", scheduler="synchronous", progress=False)
    assert calls == [("myotorso", None)]


def test_a_stopped_study_resumes_computing_only_the_missing_chunks(folder, reference, tmp_path):
    """max_chunks=2, then --resume: the two chunk files done are kept as they are (same inode and time), the
    other two computed; the trials equal the reference."""
    parsed, out = load_motion_study(write(folder)), tmp_path / "s"
    first = run_motion_study(parsed, out, scheduler="synchronous", max_chunks=2, progress=False)
    assert (first.computed, first.complete) == (2, False) and load_motions(out) == {}
    kept = {i: os.stat(out / "chunks" / f"{i}.nc") for i in (0, 1)}
    second = run_motion_study(parsed, out, scheduler="synchronous", resume=True, progress=False)
    assert (second.done_before, second.computed, second.complete) == (2, 2, True)
    for i, stat in kept.items():
        now = os.stat(out / "chunks" / f"{i}.nc")
        assert (now.st_ino, now.st_mtime_ns) == (stat.st_ino, stat.st_mtime_ns)
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(out)[name], expected)


def test_a_damaged_chunk_file_is_computed_again_on_resume(folder, reference, tmp_path):
    """A chunk file whose bytes changed (its checksums fail) counts as missing: the resume computes it alone."""
    parsed, out = load_motion_study(write(folder, STUDY.replace('name = "stiff"', 'name = "s2"'))), tmp_path / "s"
    run_motion_study(parsed, out, scheduler="synchronous", max_chunks=3, progress=False)
    chunk = out / "chunks" / "1.nc"
    data = bytearray(chunk.read_bytes())
    data[-200] ^= 0xFF
    chunk.write_bytes(bytes(data))
    notes = []
    result = run_motion_study(parsed, out, scheduler="synchronous", resume=True, progress=False, notify=notes.append)
    assert (result.done_before, result.computed) == (2, 2) and "damaged" in notes[0]
    xr.testing.assert_identical(load_motions(out)["all"], reference["all"])


def test_killed_cli_run_resumes_without_computing_a_chunk_twice(folder, reference, tmp_path):
    """SIGKILL ``spinectl study`` once two chunk files exist (chunks of 2 frames: 11 + 4), then resume: every chunk
    file made before the kill is kept, the others computed; the trials equal the reference."""
    path = write(
        tmp_path,
        STUDY.replace("chunk_frames = 8", "chunk_frames = 2").replace("flexion.mot", str(folder / "flexion.mot")),
    )
    out = tmp_path / "killed"
    command = [sys.executable, "-m", "spinectl", "study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    env = os.environ | {"PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(command, cwd=ROOT, env=env, start_new_session=True, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None and _chunk_files(out) < 2:
            time.sleep(0.005)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    before = _chunk_files(out)
    assert 2 <= before < 15, "the kill must land mid-study"
    result = run_motion_study(load_motion_study(path), out, scheduler="synchronous", resume=True, progress=False)
    assert (result.done_before, result.computed) == (before, 15 - before)
    assert sorted(p.name for p in (out / "chunks").iterdir()) == sorted(f"{i}.nc" for i in range(15))  # no temporary
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(out)[name], expected)


def _chunk_files(out: Path) -> int:
    folder = out / "chunks"
    return len([p for p in folder.iterdir() if p.name[0] != "."]) if folder.is_dir() else 0  # not a temporary


def test_two_local_workers_give_the_same_bits(folder, reference, tmp_path, monkeypatch):
    """A local Dask cluster of two processes: the same bits as the trial alone."""
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    parsed = load_motion_study(write(folder))
    result = run_motion_study(parsed, tmp_path / "s", workers=2, progress=False)
    assert result.where == "2 local workers" and result.complete
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(tmp_path / "s")[name], expected)


def test_local_workers_write_the_chunk_and_trial_files_themselves(folder, reference, tmp_path, monkeypatch):
    """The store made by a first run (one chunk), a resume on two local workers: this process writes no file of
    the store (netcdf.save here is counted; the workers are other processes), yet every chunk and trial file is
    there with the reference's bits. Before, this process wrote all five (three chunks, two trials)."""
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    parsed, out = load_motion_study(write(folder)), tmp_path / "s"
    run_motion_study(parsed, out, scheduler="synchronous", max_chunks=1, progress=False)
    written, real = [], motion_run.netcdf.save
    monkeypatch.setattr(motion_run.netcdf, "save", lambda data, path: written.append(path) or real(data, path))
    result = run_motion_study(parsed, out, workers=2, resume=True, progress=False)
    assert (result.where, result.computed) == ("2 local workers", 3)
    assert written == []
    assert sorted(p.name for p in (out / "chunks").iterdir()) == ["0.nc", "1.nc", "2.nc", "3.nc"]
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(out)[name], expected)


def test_an_existing_clusters_workers_send_the_chunks_back(folder, reference, tmp_path, monkeypatch):
    """``scheduler='tcp://...'``: its workers may not see the store, so they write nothing; this process writes
    the four chunk files and the two trials' (counted here), with the reference's bits."""
    from distributed import LocalCluster

    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    written, real = [], motion_run.netcdf.save
    monkeypatch.setattr(
        motion_run.netcdf, "save", lambda data, path: written.append(Path(path).name) or real(data, path)
    )
    with LocalCluster(n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None) as cluster:
        result = run_motion_study(
            load_motion_study(write(folder)), tmp_path / "s", scheduler=cluster.scheduler_address, progress=False
        )
    assert result.complete and sorted(written) == ["0.nc", "1.nc", "2.nc", "3.nc", "all.nc", "stiff.nc"]
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(tmp_path / "s")[name], expected)


def test_a_trial_is_written_once_its_chunks_are_done_before_the_next_chunk(folder, monkeypatch, tmp_path):
    """In-process, chunks 0-2 are trial "all", chunk 3 trial "stiff": "all" is assembled right after chunk 2,
    before chunk 3 is solved (on a cluster, while the others compute), not every trial at the end."""
    events = []
    solve, trial = motion_run.solve_motion_chunk, motion_run._write_trial
    monkeypatch.setattr(motion_run, "solve_motion_chunk", lambda task: events.append(task.index) or solve(task))
    monkeypatch.setattr(motion_run, "_write_trial", lambda out, name, c: events.append(name) or trial(out, name, c))
    run_motion_study(load_motion_study(write(folder)), tmp_path / "s", scheduler="synchronous", progress=False)
    assert events == [0, 1, 2, "all", 3, "stiff"]


def test_a_chunk_file_its_worker_wrote_is_checked_before_it_counts(folder, monkeypatch, tmp_path, capsys):
    """A chunk file written by its worker (in-process here) whose writer left a byte changed after the checksums:
    the worker reads it back before it counts, one line naming it (it cannot be read), exit 2 (unchecked, the
    store would count a damaged chunk done, found only by a resume); the resume computes it again."""
    real = motion_run.netcdf.save

    def damaging(data, path):
        real(data, path)
        if Path(path).name == "1.nc":
            raw = bytearray(Path(path).read_bytes())
            raw[-200] ^= 0xFF
            Path(path).write_bytes(bytes(raw))
        return Path(path)

    monkeypatch.setattr(motion_run.netcdf, "save", damaging)
    out = tmp_path / "s"
    arguments = ["study", str(write(folder)), "--out", str(out), "--scheduler", "synchronous", "--max-chunks", "2"]
    assert main(arguments) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "chunks/1.nc" in err and "run again with --resume" in err
    monkeypatch.setattr(motion_run.netcdf, "save", real)
    assert main([*arguments[:-2], "--resume"]) == 0
    assert "(3 computed now, 1 before)" in capsys.readouterr().out


def test_a_chunk_file_changed_after_its_worker_wrote_it_does_not_count(folder, monkeypatch, tmp_path, capsys):
    """Chunk 1's file, written and checked by its worker (in-process here), then given one byte more (NetCDF still
    reads it, its checksums hold): the run's process compares the bytes with the CRC-32 the worker sent, one
    line naming the file, exit 2; the resume finds it intact by its checksums and computes the others."""
    real, out = motion_run.run_motion_task, tmp_path / "s"

    def then_changed(task):
        result = real(task)
        if result[:3] == ("chunk", 1, None):
            path = out / "chunks" / "1.nc"
            path.write_bytes(path.read_bytes() + b"\0")
        return result

    monkeypatch.setattr(motion_run, "run_motion_task", then_changed)
    arguments = ["study", str(write(folder)), "--out", str(out), "--scheduler", "synchronous"]
    assert main(arguments) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "chunks/1.nc' is not the file its worker wrote" in err
    monkeypatch.setattr(motion_run, "run_motion_task", real)
    assert main([*arguments, "--resume"]) == 0
    assert "(2 computed now, 2 before)" in capsys.readouterr().out


def test_the_study_file_reads_each_recording_once(folder, monkeypatch):
    """Two trials of one motion file: OpenSim's reader reads it once (before: once per trial)."""
    import spinectl.anatomy.recordings as recordings

    calls, real = [], recordings.read_recording
    monkeypatch.setattr(recordings, "read_recording", lambda *a: calls.append(a) or real(*a))
    load_motion_study(write(folder))
    assert calls == [(str(folder / "flexion.mot"), "posture")]


def test_the_workers_take_the_recordings_the_study_read(folder, reference, monkeypatch, tmp_path):
    """The run (in-process here) reads no recording again: each chunk carries those the study file's check read,
    so a worker imports no OpenSim and parses no file (before: each worker read them); the bits are the
    reference's."""
    import spinectl.anatomy.recordings as recordings

    parsed, calls, real = load_motion_study(write(folder)), [], recordings.read_recording
    monkeypatch.setattr(recordings, "read_recording", lambda *a: calls.append(a) or real(*a))
    motion_run._recording.cache_clear()
    run_motion_study(parsed, tmp_path / "s", scheduler="synchronous", progress=False)
    assert calls == []
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(tmp_path / "s")[name], expected)


def test_recordings_past_the_memory_bound_are_read_by_the_workers(folder, reference, monkeypatch, tmp_path):
    """With no bytes to keep (KEPT_BYTES = 0; 256 MiB by default) the study keeps no recording: the run reads the
    file itself (once, its cache), to the reference's bits."""
    import spinectl.anatomy.recordings as recordings
    from spinectl.landscape.study import motion_spec

    monkeypatch.setattr(motion_spec, "KEPT_BYTES", 0)
    parsed, calls, real = load_motion_study(write(folder)), [], recordings.read_recording
    assert parsed.recordings == {}
    monkeypatch.setattr(recordings, "read_recording", lambda *a: calls.append(a) or real(*a))
    motion_run._recording.cache_clear()
    run_motion_study(parsed, tmp_path / "s", scheduler="synchronous", progress=False)
    assert calls == [(str(folder / "flexion.mot"), "posture")]
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(tmp_path / "s")[name], expected)


def test_a_store_is_refused_without_resume_and_for_another_study(folder, tmp_path):
    """An existing store: refused without resume; with resume, refused if the study (or a file) differs."""
    parsed, out = load_motion_study(write(folder)), tmp_path / "s"
    run_motion_study(parsed, out, scheduler="synchronous", max_chunks=1, progress=False)
    with pytest.raises(OutputError, match="add --resume"):
        run_motion_study(parsed, out, scheduler="synchronous", progress=False)
    other = load_motion_study(write(folder, STUDY.replace("joint_stiffness = 50.0", "joint_stiffness = 60.0")))
    with pytest.raises(ParameterError, match="holds another study"):
        run_motion_study(other, out, scheduler="synchronous", resume=True, progress=False)


TRIAL = "[[trials]]\nname='a'\nmodel='myotorso'\ncoordinates='flexion.mot'\n"
"""A valid trial, to which each bad case adds or changes one thing."""

BAD = [
    (TRIAL + "optimize='chain'\n", ConfigError, "did you mean 'optimise'"),
    (TRIAL.replace("flexion.mot", "absent.mot"), ParameterError, "trials[0].coordinates"),
    (TRIAL + "frames='0:21'\n", ParameterError, "0 <= FIRST <= LAST <= 20"),
    (TRIAL + "frames='0-3'\n", ParameterError, "FIRST:LAST"),
    (TRIAL + "optimise='chain'\nactivations='flexion.mot'\n", ParameterError, "cannot go with optimise"),
    (TRIAL + TRIAL, ParameterError, "trials[1].name"),
    ("[study]\nchunk_frames=0\n" + TRIAL, ParameterError, "study.chunk_frames"),
    ("[[trials]]\nname='a'\nmodel='myotorso'\n", ParameterError, "trials[0].coordinates: is required"),
    (TRIAL + "joint_stiffness=-1\n", ParameterError, "trials[0].joint_stiffness"),
    (TRIAL.replace("'a'", "'a/b'"), ParameterError, "trials[0].name"),
    (TRIAL.replace("'myotorso'", "'absent.xml'"), ParameterError, "trials[0].model"),
    (TRIAL + "removal='groups'\n", ParameterError, "trials[0].removal: is not supported in a study of motions"),
    (TRIAL + "group={back='IL|LTp'}\n", ParameterError, "trials[0].group: is not supported in a study"),
]


@pytest.mark.parametrize(("text", "kind", "needle"), BAD)
def test_study_file_errors_name_the_field(folder, text, kind, needle):
    """Each mistake is refused before any work, naming the key as written."""
    with pytest.raises(kind) as info:
        parse_motion_study(text, folder)
    assert needle in str(info.value)


def test_cli_runs_resumes_and_refuses_in_one_line(folder, tmp_path, capsys):
    """spinectl study on a file of [[trials]]: the study's closing line; a bad file or --set: one line, exit 2."""
    path, out = write(folder), tmp_path / "s"
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    assert main([*arguments, "--max-chunks", "1"]) == 0
    line = capsys.readouterr().out.strip()
    assert line.startswith("study: 1 of 4 chunks done") and "run again with --resume" in line
    assert main([*arguments, "--resume"]) == 0
    assert capsys.readouterr().out.startswith("study: 4 of 4 chunks done (3 computed now, 1 before)")
    assert main([*arguments, "--resume", "--set", "body.mass=50"]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    bad = write(tmp_path, "[[trials]]\nname='a'\nmodel='myotorso'\ncoordinates='nope.mot'\n")
    assert main(["study", str(bad), "--out", str(tmp_path / "t")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("spinectl: error: trials[0].coordinates:") and err.count("\n") == 1
    assert not (tmp_path / "t").exists()


def test_an_interrupted_study_of_motions_says_how_much_is_saved_and_how_to_continue(
    folder, tmp_path, capsys, monkeypatch
):
    """Ctrl-C while the third chunk file is saved: the line counts the two chunks in the store and says how to
    continue (the parameter study's words, run.RESUME); the resume computes exactly the other two. Before, a study
    of motions said only "spinectl: interrupted"."""
    from spinectl.landscape.study import run
    from spinectl.landscape.study.interrupt import interrupted_text

    path, out = write(folder), tmp_path / "s"
    save, saved = motion_run.netcdf.save, []

    def interrupted(dataset, target, *args, **kwargs):
        if "chunks" in str(target) and len(saved) == 2:
            raise KeyboardInterrupt
        written = save(dataset, target, *args, **kwargs)
        saved.append(target)
        return written

    monkeypatch.setattr(motion_run.netcdf, "save", interrupted)
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    assert main(arguments) == 130
    assert capsys.readouterr().err == f"spinectl: {interrupted_text(2, 4, str(out), run.RESUME)}\n"
    monkeypatch.setattr(motion_run.netcdf, "save", save)
    assert main([*arguments, "--resume"]) == 0
    assert capsys.readouterr().out.startswith("study: 4 of 4 chunks done (2 computed now, 2 before)")


@pytest.mark.parametrize(("key", "field"), [("model", "model"), ("mapping", "mapping")])
def test_a_model_that_does_not_load_is_one_line_naming_the_trial_and_leaves_no_store(
    folder, tmp_path, capsys, key, field
):
    """A model or mapping file that its engine refuses (read by the worker, once): one line naming the file's
    field and the trial, exit 2, no store made (it is made at the first chunk written)."""
    (tmp_path / "bad.xml").write_text("<mujoco")
    text = TRIAL.replace("'flexion.mot'", repr(str(folder / "flexion.mot")))
    text += f"{key} = {str(tmp_path / 'bad.xml')!r}\n" if key == "mapping" else ""
    text = text.replace("'myotorso'", repr(str(tmp_path / "bad.xml"))) if key == "model" else text
    out = tmp_path / "s"
    assert main(["study", str(write(tmp_path, text)), "--out", str(out), "--scheduler", "synchronous"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"spinectl: error: {field}:") and err.rstrip().endswith("(trial 'a')")
    assert err.count("\n") == 1 and not out.exists()


def test_a_full_disk_while_a_chunk_is_written_is_one_line_and_resumable(
    folder, reference, tmp_path, capsys, monkeypatch
):
    """ENOSPC from the NetCDF writer at the second chunk (simulated): one line naming the chunk's file, exit 2, no
    temporary left; the chunk written before is kept and --resume finishes the store with the reference's bits."""
    import errno

    real, calls = xr.Dataset.to_netcdf, []

    def full_at_second(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *args, **kwargs)

    out = tmp_path / "s"
    arguments = ["study", str(write(folder)), "--out", str(out), "--scheduler", "synchronous"]
    monkeypatch.setattr(xr.Dataset, "to_netcdf", full_at_second)
    assert main(arguments) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "No space left on device" in err and "chunks/1.nc" in err
    assert sorted(p.name for p in (out / "chunks").iterdir()) == ["0.nc"]  # no temporary
    monkeypatch.setattr(xr.Dataset, "to_netcdf", real)
    assert main([*arguments, "--resume"]) == 0
    assert "(3 computed now, 1 before)" in capsys.readouterr().out
    for name, expected in reference.items():
        xr.testing.assert_identical(load_motions(out)[name], expected)


def test_every_option_of_a_trial_is_motion_responses(torso, folder, tmp_path):
    """Activations from a file, the optimum per frame, the least stiffness: each trial (chunks of one frame) equals
    motion_response with the same options on the trial alone, bit for bit."""
    a = np.random.default_rng(1).uniform(0.0, 0.3, (TIMES.size, len(torso.muscles)))
    write_motion(folder / "so.sto", torso.muscles, TIMES, a, in_degrees=None)
    text = (
        "[study]\nchunk_frames = 1\n"
        + TRIAL.replace("'a'", "'acts'")
        + "activations = 'so.sto'\nframes = '0:20:10'\n"
        + TRIAL.replace("'a'", "'opt'")
        + "optimise = 'chain'\njoint_stiffness = 50.0\nframes = '0:10:10'\n"
        + TRIAL.replace("'a'", "'least'")
        + "least_stiffness = 5.0\nframes = '0:20:10'\n"
    )
    run_motion_study(load_motion_study(write(folder, text)), tmp_path / "s", scheduler="synchronous", progress=False)
    got = load_motions(tmp_path / "s")
    rec = read_recording(folder / "flexion.mot", "posture")
    expected = {
        "acts": motion_response(torso, rec, read_recording(folder / "so.sto", "activations"), frames=(0, 20, 10)),
        "opt": motion_response(torso, rec, optimise="chain", joint_stiffness=50.0, frames=(0, 10, 10)),
        "least": motion_response(torso, rec, least_stiffness=5.0, frames=(0, 20, 10)),
    }
    for name, result in expected.items():
        xr.testing.assert_identical(got[name], result.dataset)
