"""Resources: a sweep counts every axis, is estimated before the work, and is refused in one line when it cannot fit.

The limits are injected (a tiny point limit, memory or free disk), never met by a real allocation.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.errors import OutputError, ParameterError
from spinectl.landscape import budget, sweep

E_AXIS = np.array([0.0, 0.08])
L_AXIS = np.array([0.0, 0.04])


def test_the_point_limit_counts_every_k(model, tmp_path, monkeypatch):
    """E x Lambda x K is what a sweep solves: 2 x 2 points at 3 values of K are 12, beyond a limit of 8 (before,
    only E x Lambda = 4 was counted, so 10 values of K on a 1000 x 1000 grid ran until memory ran out)."""
    monkeypatch.setattr(sweep, "MAX_GRID_POINTS", 8)
    out = tmp_path / "k.nc"
    with pytest.raises(ParameterError, match=r"at most 8 points in all \(got 2 x 2 x 3 = 12\)") as info:
        sweep.write_sweep(model, E_AXIS, L_AXIS, out, stiffnesses=[0.0, 5.0, 15.0], progress=False)
    assert info.value.field == "grid" and not out.exists()
    sweep.write_sweep(model, E_AXIS, L_AXIS, out, stiffnesses=[0.0, 15.0], progress=False)  # 8 points: allowed
    assert out.is_file()


def test_a_sweep_beyond_the_available_memory_is_refused_before_any_solve(model, monkeypatch):
    """With 1 kB of memory available, any sweep (its estimate includes a chunk's working memory, 16 kB a
    point) is refused in one line naming the memory, before the grid is solved."""
    monkeypatch.setattr(budget, "available_memory", lambda: 1e3)
    with pytest.raises(ParameterError, match=r"4 points need about .* of memory, and 1 kB is available") as info:
        sweep.sweep(model, E_AXIS, L_AXIS, progress=False)
    assert info.value.field == "sweep" and "\n" not in str(info.value)


def test_a_file_beyond_the_free_disk_is_refused_before_any_solve(model, tmp_path, monkeypatch):
    """With 100 bytes free where the file goes, the sweep (1.5 kB a point on disk) is refused, nothing written."""
    monkeypatch.setattr(budget, "free_disk", lambda path: 100.0)
    out = tmp_path / "x.nc"
    with pytest.raises(OutputError, match=r"cannot write .*x\.nc': 4 points need about .*, and its file system has"):
        sweep.write_sweep(model, E_AXIS, L_AXIS, out, progress=False)
    assert list(tmp_path.iterdir()) == []


def test_the_estimate_is_the_answers_bytes_and_is_told_for_long_work(model, tmp_path, monkeypatch):
    """The estimate's bytes a point are those of the Dataset the sweep returns (its variables' nbytes over
    its points, a second count of the same thing), and long work (here: any, NOTICE_SECONDS = 0) is announced
    in one line naming points, disk, memory and CPU time before it starts."""
    monkeypatch.setattr(budget, "NOTICE_SECONDS", 0.0)
    lines = []
    dataset = sweep.write_sweep(
        model, E_AXIS, L_AXIS, tmp_path / "x.nc", stiffnesses=[0.0, 15.0], progress=False, notify=lines.append
    )
    assert len(lines) == 1 and lines[0].startswith("sweep: 8 points, about ") and lines[0].endswith("(estimated)")
    answer = sum(v.nbytes for v in dataset.data_vars.values()) / 8
    cost = sweep.estimate(model, E_AXIS[:1], L_AXIS[:1], 8, 1024, False)
    assert cost.disk == pytest.approx(8 * answer * budget.NETCDF_BYTES_PER_BYTE)
    assert cost.seconds == pytest.approx(8 * budget.SWEEP_SECONDS_PER_POINT)


def test_short_work_is_not_announced(model):
    """A sweep estimated below NOTICE_SECONDS says nothing before its answer (the CLI's quiet runs stay quiet)."""
    lines = []
    sweep.sweep(model, E_AXIS, L_AXIS, progress=False, notify=lines.append)
    assert lines == []


@pytest.mark.parametrize(
    ("nbytes", "text"), [(999, "999 B"), (1500, "1.5 kB"), (8.1e6, "8.1 MB"), (97e9, "97 GB"), (2.5e12, "2.5 TB")]
)
def test_sizes_read_in_decimal_units(nbytes, text):
    """Sizes as a reader writes them: two or three significant digits, kB = 1000 B."""
    assert budget.size(nbytes) == text


def test_available_memory_and_free_disk_are_read_from_the_system(tmp_path):
    """MemAvailable is at most the machine's total memory (/proc/meminfo or sysconf), and the free disk of a
    file not yet made is that of its folder (shutil.disk_usage of tmp_path)."""
    import os
    import shutil

    total = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    assert 0 < budget.available_memory() <= total
    assert budget.free_disk(tmp_path / "new" / "x.nc") == pytest.approx(shutil.disk_usage(tmp_path).free, rel=0.01)


def test_a_design_curve_is_estimated_from_its_designs():
    """``design_estimate``: the designs times the measured cost each (DESIGN_SECONDS, 50 ms; PASSIVE_SECONDS, 12 ms),
    and a line without the disk or memory it does not estimate: 10,000 designs x 50 ms = 500 s = 8.3 min; 1000
    stiffnesses x 12 ms = 12 s, over NOTICE_SECONDS (10 s); 41 delays x 50 ms = 2 s, under it."""
    long = budget.design_estimate(10_000)
    assert long.line() == "design: 10,000 designs, about 8.3 min of CPU (estimated)" and long.long
    assert budget.design_estimate(1000, passive=True).line() == "design: 1,000 points, about 12 s of CPU (estimated)"
    assert not budget.design_estimate(41).long
    sweep_line = budget.Estimate("sweep", 4, 2e6, 3e3, 20.0).line()  # the others' lines keep every part
    assert sweep_line == "sweep: 4 points, about 3 kB on disk, 2 MB of memory, 20 s of CPU (estimated)"
