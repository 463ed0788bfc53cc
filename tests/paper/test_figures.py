"""Figures: produced, non-trivial, named after the paper's figures; the plot command."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.image import imread

from spinectl.cli import main
from spinectl.landscape import netcdf, sweep
from spinectl.model.params import Model
from spinectl.paper import figures

AXIS = np.linspace(0.0, 0.08, 5)


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    path = tmp_path_factory.mktemp("plot") / "r.nc"
    return netcdf.save(sweep.stiffness_sweep(Model(), [0.0, 15.0], AXIS, AXIS, progress=False), path)


def _non_trivial(path):
    """A real figure: tens of kB of PNG and many distinct colours, not a blank canvas."""
    image = imread(path)
    coarse = (image[..., :3] * 15.99).astype(np.int64).reshape(-1, 3) @ np.array([256, 16, 1])  # 4 bits a channel
    colours = np.count_nonzero(np.bincount(coarse, minlength=4096))
    return path.stat().st_size > 20_000 and image.std() > 0.05 and colours > 20


def test_figures_3_4_and_s1_are_drawn(results, tmp_path):
    written = figures.draw_figures(netcdf.load(results), tmp_path, Model().fibre.specific_tension)
    names = sorted(p.name for p in written)
    assert names == sorted([*figures.figure_names(0.0), *figures.figure_names(15.0)])
    assert "figS1_min_pcsa_K15.png" in names
    assert all(_non_trivial(p) for p in written)


def test_plot_command(results, tmp_path, capsys):
    assert main(["plot", str(results), "--out", str(tmp_path / "figs")]) == 0
    printed = capsys.readouterr().out.split()
    assert len(printed) == 4 and all(_non_trivial(tmp_path / "figs" / p.split("/")[-1]) for p in printed)


def test_plot_command_missing_file(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "none.nc"), "--out", str(tmp_path)]) == 2
    assert "results: file not found" in capsys.readouterr().err
