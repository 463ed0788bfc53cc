"""``spinectl reproduce``: every output, atomically, on a coarse grid."""

from __future__ import annotations

import errno
import os
import pathlib
import threading

import pytest

from spinectl import atomic
from spinectl.cli import main
from spinectl.landscape import netcdf
from spinectl.model import config
from spinectl.paper import figures, grid, reproduction

OTHER = f"landscape_K15_{grid.other_convention(config.load_preset('wagner2012'))}.nc"
"""The K = 15 landscape of the convention that the default preset, wagner2012, does not use (its convention is
picked at its calibrated vector, docs/reproduction.md)."""

EXPECTED = {
    "landscapes.nc",
    OTHER,
    "fig3_min_pcsa.png",
    "fig4_counter_torque.png",
    "figS1_min_pcsa_K15.png",
    "fig4_counter_torque_K15.png",
    "report.md",
}


def test_reproduce_writes_everything(tmp_path, capsys):
    out = tmp_path / "results"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["reproduce", "--out", str(out), "--points", "5"]) == 0
    assert {p.name for p in out.iterdir()} == EXPECTED | {"notes.txt"}
    assert (out / "notes.txt").read_text() == "mine"
    ds = netcdf.load(out / "landscapes.nc")
    assert list(ds["K"].values) == [0.0, 15.0] and ds.sizes["E"] == 5
    assert float(ds["counter_torque_norm_Nm"].sel(K=0.0, E=0.0, Lambda=0.0)) < 1e-9  # CT = 0 at A (paired)
    text = (out / "report.md").read_text()
    assert "| `min_pcsa_A` |" in text and "**calibrated**" in text
    assert "Parameters: preset wagner2012; K = 0 and K = 15 N m/rad with the `physical` convention" in text
    assert [p.split("/")[-1] for p in capsys.readouterr().out.split()] == [
        "landscapes.nc",
        OTHER,
        *figures.figure_names(0.0),
        *figures.figure_names(15.0),
        "report.md",
    ]
    assert [p.name for p in tmp_path.iterdir()] == ["results"]  # no staging folder left behind


@pytest.mark.parametrize("mount", [False, True])
def test_a_run_with_another_convention_leaves_no_stale_landscape(tmp_path, monkeypatch, capsys, mount):
    """A run with the other passive-stiffness convention, then one with the preset's: the folder holds
    exactly the second run's files (and the user's own), not the first run's landscape_K15_paper.nc
    (before: it stayed, beside a report that does not name it). Also into a mount point (simulated)."""
    out = tmp_path / "results"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    if mount:
        monkeypatch.setattr(atomic, "_is_mount", lambda target: pathlib.Path(target) == out)
        monkeypatch.setattr(os, "replace", _mount_point(out))
    physical = tmp_path / "physical.toml"
    physical.write_text('preset = "wagner2012"\n[passive]\nconvention = "physical"\n')
    assert main(["reproduce", "--out", str(out), "--points", "3", "--config", str(physical)]) == 0
    assert "landscape_K15_paper.nc" in {p.name for p in out.iterdir()}
    assert main(["reproduce", "--out", str(out), "--points", "3"]) == 0
    assert {p.name for p in out.iterdir() if not p.name.startswith(".")} == EXPECTED | {"notes.txt"}


def test_a_failure_leaves_the_output_folder_untouched(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise RuntimeError("simulated crash while drawing")

    monkeypatch.setattr(figures, "figure_set", broken)
    out = tmp_path / "results"
    with pytest.raises(RuntimeError):
        main(["reproduce", "--out", str(out), "--points", "3"])
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_the_figures_drawn_beside_the_rest_are_those_drawn_here(tmp_path, monkeypatch, capsys):
    """On Linux a worker process draws the figures while this one writes the landscapes and the report; the
    files are byte for byte those that this process draws (the path of the other platforms)."""
    pids = tmp_path / "pids.txt"
    save = figures.save_figure

    def recorded(figure, path, *args, **kwargs):
        with open(pids, "a") as file:
            file.write(f"{os.getpid()}\n")
        return save(figure, path, *args, **kwargs)

    monkeypatch.setattr(figures, "save_figure", recorded)
    assert main(["reproduce", "--out", str(tmp_path / "beside"), "--points", "5"]) == 0
    beside = set(pids.read_text().split())
    pids.unlink()
    monkeypatch.setattr(reproduction, "_beside", reproduction._Here)
    assert main(["reproduce", "--out", str(tmp_path / "here"), "--points", "5"]) == 0
    here = set(pids.read_text().split())
    assert here == {str(os.getpid())}
    if reproduction._can_fork():  # Linux, and no other thread left running by an earlier test
        assert len(beside) == 1 and beside != here
    else:
        assert beside == here
    for name in (*figures.figure_names(0.0), *figures.figure_names(15.0)):
        assert (tmp_path / "beside" / name).read_bytes() == (tmp_path / "here" / name).read_bytes(), name


@pytest.mark.parametrize("points", ["1", "1001", "4" * 400])
def test_reproduce_rejects_a_degenerate_or_oversized_grid(tmp_path, capsys, points):
    """1001 x 1001 exceeds sweep.MAX_GRID_POINTS (10^6); 4...4 (400 digits) once crashed numpy's linspace."""
    assert main(["reproduce", "--out", str(tmp_path), "--points", points]) == 2
    err = capsys.readouterr().err
    assert "--points: must be 3 to 1000 per axis" in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_reproduce_of_another_preset_says_it_is_not_calibrated(tmp_path, capsys):
    assert main(["reproduce", "--out", str(tmp_path), "--points", "3", "--preset", "default"]) == 0
    text = (tmp_path / "report.md").read_text()
    assert "Parameters: preset default; K = 0 and K = 15" in text and "are **not** the calibrated preset" in text
    assert (tmp_path / "landscape_K15_paper.nc").exists()  # default uses the physical convention


def test_reproduce_writes_utf8_under_a_latin1_locale(tmp_path, monkeypatch, capsys):
    """Under an ISO-8859-1 locale the report (with Λ, ≙, cm²) is still written, as UTF-8.

    pathlib asks ``io.text_encoding`` for the encoding of a call without one; under
    an ISO-8859-1 locale it answers 'locale', i.e. latin-1, which cannot encode Λ.
    """
    import io

    real = io.text_encoding
    monkeypatch.setattr(io, "text_encoding", lambda encoding, *a: real(encoding, *a) if encoding else "iso-8859-1")
    out = tmp_path / "results"
    assert main(["reproduce", "--out", str(out), "--points", "3"]) == 0
    assert "Λ" in (out / "report.md").read_bytes().decode("utf-8")


def _mount_point(target):
    """os.replace as if ``target`` were a mount point: a rename from outside it into it fails with EXDEV."""
    real = os.replace

    def replace(src, dst):
        src, dst = pathlib.Path(src), pathlib.Path(dst)
        if dst.parent == target and not src.is_relative_to(target):
            raise OSError(errno.EXDEV, os.strerror(errno.EXDEV))
        return real(src, dst)

    return replace


def test_reproduce_into_a_mount_point(tmp_path, monkeypatch, capsys):
    """The output folder is a mount point (simulated: ``os.path.ismount`` says so, and renames into it
    from its parent fail with EXDEV).

    The staging folder is made inside it, so every file lands by a rename on its own
    file system (before: "Invalid cross-device link" after the whole run).
    """
    out = tmp_path / "mnt"
    out.mkdir()
    monkeypatch.setattr(atomic, "_is_mount", lambda target: pathlib.Path(target) == out)
    monkeypatch.setattr(os, "replace", _mount_point(out))
    assert main(["reproduce", "--out", str(out), "--points", "3"]) == 0
    assert {p.name for p in out.iterdir()} == EXPECTED


def test_an_output_folder_that_refuses_renames_fails_before_the_work(tmp_path, monkeypatch, capsys):
    """A folder that takes no rename at all (simulated EROFS) is refused before any landscape is solved."""
    out = tmp_path / "mnt"
    out.mkdir()
    monkeypatch.setattr(atomic, "_is_mount", lambda target: pathlib.Path(target) == out)
    monkeypatch.setattr(os, "replace", _refuse_all(out))
    monkeypatch.setattr(grid, "paper_landscapes", lambda *a: pytest.fail("solved before checking the output"))
    assert main(["reproduce", "--out", str(out), "--points", "3"]) == 2
    err = capsys.readouterr().err
    assert "Read-only file system" in err and err.count("\n") == 1
    assert list(out.iterdir()) == [] and [p.name for p in tmp_path.iterdir()] == ["mnt"]


def _refuse_all(target):
    """os.replace as if ``target`` were read-only: no rename into it."""
    real = os.replace

    def replace(src, dst):
        if pathlib.Path(dst).parent == target:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))
        return real(src, dst)

    return replace


def test_a_blocked_name_in_the_output_folder_stops_before_the_work(tmp_path, monkeypatch, capsys):
    """``report.md`` is a folder: exit 2 before any sweep, every old file as it was.

    Before, the files were moved in one by one at the end, and 6 of the 7 were already
    the new ones when the seventh failed.
    """
    from spinectl.paper import grid

    out = tmp_path / "results"
    (out / "report.md").mkdir(parents=True)
    old = {name: f"old {name}".encode() for name in EXPECTED - {"report.md"}}
    for name, content in old.items():
        (out / name).write_bytes(content)

    def no_sweep(*args, **kwargs):
        raise AssertionError("the sweeps must not start")

    monkeypatch.setattr(grid, "paper_landscapes", no_sweep)
    assert main(["reproduce", "--out", str(out), "--points", "3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "report.md': Is a directory" in err
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]


def test_a_process_with_other_threads_draws_its_figures_itself():
    """A fork copies only the calling thread (a lock held by another stays locked in the child), so a
    process running another Python thread (a notebook kernel, the explorer) does not fork."""
    release = threading.Event()
    thread = threading.Thread(target=release.wait)
    thread.start()
    try:
        assert not reproduction._can_fork()
        assert isinstance(reproduction._beside(), reproduction._Here)
    finally:
        release.set()
        thread.join()


def test_a_folder_name_the_netcdf_library_cannot_take_is_named_as_typed(tmp_path, monkeypatch, capsys):
    """``reproduce --out Λdir`` under the C locale without Python's UTF-8 mode (file system encoding ASCII, set
    here by hand): one line, exit 2, naming the folder the user typed, before any solve, nothing written.
    Before, the same check met the name at the save, after the solve, and named the staging folder beside it
    (``.Λdir.~<pid>-...``), a folder the user never typed and that was gone by the time they read it."""
    import sys

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "getfilesystemencoding", lambda: "ascii")
    solved, solve = [], grid.paper_landscapes
    monkeypatch.setattr(grid, "paper_landscapes", lambda *a, **k: solved.append(a) or solve(*a, **k))
    assert main(["reproduce", "--out", "Λdir", "--points", "3"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "cannot open 'Λdir/landscapes.nc': the NetCDF library takes only names" in err, err
    assert not solved and list(tmp_path.iterdir()) == []
