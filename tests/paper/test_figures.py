"""Figures: returned without writing, saved as a separate step, non-trivial, named after the paper's figures;
the plot command."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure
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


def test_figure_functions_return_figures_and_write_nothing(results, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    k0 = netcdf.load(results).sel(K=0.0)
    drawn = [figures.min_pcsa_figure(k0), figures.counter_torque_figure(k0, Model().fibre.specific_tension)]
    assert all(isinstance(f, Figure) for f in drawn) and [len(f.axes) for f in drawn] == [2, 2]  # with colour bars
    assert drawn[0].axes[0].get_title().startswith("Fig. 3: minimum PCSA")
    assert list(tmp_path.iterdir()) == [] and plt.get_fignums() == []
    path = figures.save_figure(drawn[0], tmp_path / "f.png")
    assert _non_trivial(path) and [p.name for p in tmp_path.iterdir()] == ["f.png"]


def test_draw_figures_reads_the_specific_tension_of_the_dataset(results, tmp_path):
    """Without it, Figure 4's scale is that of the model the sweep ran with: the same PNG bytes."""
    dataset = netcdf.load(results).sel(K=0.0)
    given = figures.draw_figures(dataset, tmp_path / "given", Model().fibre.specific_tension)
    default = figures.draw_figures(dataset, tmp_path / "default")
    assert [p.read_bytes() for p in default] == [p.read_bytes() for p in given]


def test_plot_command(results, tmp_path, capsys):
    assert main(["plot", str(results), "--out", str(tmp_path / "figs")]) == 0
    printed = capsys.readouterr().out.split()
    assert len(printed) == 4 and all(_non_trivial(tmp_path / "figs" / p.split("/")[-1]) for p in printed)


def test_plot_command_missing_file(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "none.nc"), "--out", str(tmp_path)]) == 2
    assert "results: file not found" in capsys.readouterr().err


def test_an_interrupted_plot_leaves_the_old_figures_not_a_mix(results, tmp_path, monkeypatch, capsys):
    """Ctrl-C while the third of four figures is saved: the folder holds the old four, byte for byte.

    Before, the first two were already the new ones. A file of the user's in the folder is kept
    by the run that finishes, and no staging folder is left beside it.
    """
    from spinectl import canvas

    out = tmp_path / "figs"
    assert main(["plot", str(results), "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine")
    for name in figures.figure_names(0.0) + figures.figure_names(15.0):
        (out / name).write_bytes(b"old " + name.encode())  # old figures that a new run would change
    old = {p.name: p.read_bytes() for p in out.iterdir()}
    save, calls = canvas.save_png, []

    def interrupted(figure, path, dpi):
        calls.append(path)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return save(figure, path, dpi)

    monkeypatch.setattr(canvas, "save_png", interrupted)
    assert main(["plot", str(results), "--out", str(out)]) == 130
    assert {p.name: p.read_bytes() for p in out.iterdir()} == old
    assert [p.name for p in tmp_path.iterdir()] == ["figs"]
    monkeypatch.setattr(canvas, "save_png", save)
    assert main(["plot", str(results), "--out", str(out)]) == 0
    assert (out / "notes.txt").read_text() == "mine" and _non_trivial(out / "fig3_min_pcsa.png")
    assert [p.name for p in tmp_path.iterdir()] == ["figs"]


def test_plot_into_a_folder_with_a_folder_in_a_figure_s_place_writes_nothing(results, tmp_path, capsys):
    """``fig4_counter_torque.png`` is a folder: refused before drawing, one line, the folder as it was."""
    out = tmp_path / "figs"
    (out / "fig4_counter_torque.png").mkdir(parents=True)
    (out / "fig3_min_pcsa.png").write_bytes(b"old")
    assert main(["plot", str(results), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "fig4_counter_torque.png': Is a directory" in err
    assert (out / "fig3_min_pcsa.png").read_bytes() == b"old" and sorted(tmp_path.iterdir()) == [out]


def test_a_link_to_the_output_folder_stays_a_link(results, tmp_path):
    """``--out link`` with link -> real: the figures go into real, the link is left as it is."""
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert main(["plot", str(results), "--out", str(tmp_path / "link")]) == 0
    assert (tmp_path / "link").is_symlink() and (tmp_path / "real" / "fig3_min_pcsa.png").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_the_working_directory_is_not_replaced_as_an_output_folder(results, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["plot", str(results), "--out", "."]) == 2
    assert "it is the working directory or holds it" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("stiffness", "near"), [(15.0, 15.000001), (1e-7, 1.0000001e-7), (123456.0, 123456.5)])
def test_distinct_stiffnesses_give_distinct_figure_names(stiffness, near):
    """``f"{K:g}"`` keeps 6 digits: 15 and 15.000001 (and 123456 and 123456.5) used to share a file name.

    The names must also read back as their K: the part after 'K' parses to the float given.
    """
    names = [figures.figure_names(k) for k in (stiffness, near)]
    assert len(set(names[0]) | set(names[1])) == 4
    for k, (pcsa, _) in zip((stiffness, near), names, strict=True):
        assert float(pcsa.removeprefix("figS1_min_pcsa_K").removesuffix(".png")) == k
    assert figures.figure_names(15.0) == ("figS1_min_pcsa_K15.png", "fig4_counter_torque_K15.png")
