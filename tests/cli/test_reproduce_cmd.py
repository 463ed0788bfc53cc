"""``spinectl reproduce``: every output, atomically, on a coarse grid."""

from __future__ import annotations

import pytest

from spinectl.cli import main
from spinectl.landscape import netcdf
from spinectl.paper import figures

OTHER = "landscape_K15_physical.nc"
"""The K = 15 landscape of the convention that the default preset, wagner2012 (convention 'paper'), does not use."""

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
    assert "| `min_pcsa_A` |" in text and "Parameters: preset `wagner2012`" in text and "**calibrated**" in text
    assert [p.split("/")[-1] for p in capsys.readouterr().out.split()] == [
        "landscapes.nc",
        OTHER,
        *figures.figure_names(0.0),
        *figures.figure_names(15.0),
        "report.md",
    ]
    assert [p.name for p in tmp_path.iterdir()] == ["results"]  # no staging folder left behind


def test_a_failure_leaves_the_output_folder_untouched(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise RuntimeError("simulated crash while drawing")

    monkeypatch.setattr(figures, "figure_set", broken)
    out = tmp_path / "results"
    with pytest.raises(RuntimeError):
        main(["reproduce", "--out", str(out), "--points", "3"])
    assert not out.exists() and list(tmp_path.iterdir()) == []


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
    assert "Parameters: preset `default`" in text and "are **not** the calibrated preset" in text
    assert (tmp_path / "landscape_K15_paper.nc").exists()  # default uses the physical convention


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
