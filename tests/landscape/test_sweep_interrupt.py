"""An interrupted sweep leaves the previous output intact: outputs are written atomically (docs/robustness.md)."""

from __future__ import annotations

import pytest

from spinectl.cli import main
from spinectl.optimise import stacked


def test_interrupted_sweep_keeps_the_previous_file(tmp_path, monkeypatch, capsys):
    out = tmp_path / "landscape.nc"
    assert main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", str(out)]) == 0
    before = out.read_bytes()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # Ctrl-C in the middle of the solves

    monkeypatch.setattr(stacked, "solve_stacked", interrupted)
    code = main(["sweep", "--E", "0:0.08:5", "--Lambda", "0:0.08:5", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 130 and err.strip() == "spinectl: interrupted"
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["landscape.nc"]  # no temporary left behind


@pytest.mark.parametrize(
    "command", [["plot", "missing.nc", "--out", "figs"], ["plot", "landscape.nc", "--out", "figs"]]
)
def test_plot_of_a_bad_dataset_is_one_line(tmp_path, monkeypatch, capsys, command):
    """A missing file, or a NetCDF file that is not a sweep, gives one line and exit 2."""
    import xarray as xr

    monkeypatch.chdir(tmp_path)
    xr.Dataset({"x": ("t", [1.0, 2.0])}).to_netcdf(tmp_path / "landscape.nc")
    assert main(command) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "results:" in err
    assert not (tmp_path / "figs").exists()
