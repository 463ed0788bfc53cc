"""Figures without pyplot: no module selects a backend, figures live on their own Agg canvas, saved atomically."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg

from spinectl.canvas import laid_out, new_figure, save_file
from spinectl.errors import OutputError

ROOT = Path(__file__).resolve().parents[2]

IMPORT_EVERYTHING = """
import importlib, pkgutil
import matplotlib
import spinectl
for module in pkgutil.walk_packages(spinectl.__path__, prefix="spinectl."):
    if module.name != "spinectl.__main__":
        importlib.import_module(module.name)
print(matplotlib.rcParams._get_backend_or_none())
"""


def test_no_module_selects_a_backend_at_import():
    """Importing every module of spinectl leaves matplotlib's backend unresolved (``matplotlib.use`` was
    called at import by ``reflex.plots`` before), so a notebook or an application keeps its own."""
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    proc = subprocess.run(
        [sys.executable, "-c", IMPORT_EVERYTHING], capture_output=True, text=True, env=env, check=True
    )
    assert proc.stdout.strip() == "None"


def test_new_figure_is_not_pyplots():
    fig = new_figure(figsize=(2, 1))
    fig.add_subplot().plot([0, 1])
    assert isinstance(fig.canvas, FigureCanvasAgg) and plt.get_fignums() == []
    assert tuple(fig.get_size_inches()) == (2, 1)


def test_save_file_writes_a_png_and_no_temporary(tmp_path):
    fig = new_figure(figsize=(2, 1))
    path = save_file(fig, tmp_path / "sub" / "f.png", dpi=50)
    assert path == tmp_path / "sub" / "f.png"
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in path.parent.iterdir()] == ["f.png"]


class _Broken(Artist):
    """An artist that fails to draw: a failure while rendering, whichever way the figure is saved."""

    def draw(self, renderer):
        raise RuntimeError("simulated failure while rendering")


@pytest.mark.parametrize("suffix", ["png", "svg"])
def test_a_failed_save_leaves_the_previous_file(tmp_path, suffix):
    target = tmp_path / f"f.{suffix}"
    target.write_bytes(b"previous")
    fig = new_figure()
    fig.add_artist(_Broken())
    with pytest.raises(RuntimeError):
        save_file(fig, target, dpi=50)
    assert target.read_bytes() == b"previous" and [p.name for p in tmp_path.iterdir()] == [target.name]
    with pytest.raises(OutputError, match="cannot write"):
        save_file(new_figure(), target / "below.png", dpi=50)  # a file where a folder should be


def _laid_out_figure():
    """A figure with a layout engine, a colour bar and labels whose extents decide the layout."""
    fig = new_figure(figsize=(3, 2), layout="constrained", dpi=72)
    ax = fig.add_subplot()
    mesh = ax.contourf(np.arange(4.0), np.arange(3.0), np.arange(12.0).reshape(3, 4))
    fig.colorbar(mesh).set_label("a long colour-bar label [cm²]")
    ax.set_title("a title\non two lines")
    return fig


def test_a_png_is_the_file_that_savefig_writes(tmp_path):
    """save_file draws a PNG once (the Agg canvas lays it out and renders it), savefig twice (a draw without
    rendering for the layout first): the same bytes from two equal figures; the figure keeps its own dpi."""
    once = _laid_out_figure()
    save_file(once, tmp_path / "once.png", dpi=90)
    assert once.dpi == 72
    _laid_out_figure().savefig(tmp_path / "twice.png", dpi=90)
    assert (tmp_path / "once.png").read_bytes() == (tmp_path / "twice.png").read_bytes()


@pytest.mark.parametrize("layout", ["constrained", None])
def test_laid_out_measures_as_drawn_without_printing(layout, monkeypatch):
    """After laid_out, an equal-aspect axes' box and a label's extent are those of the next draw (matplotlib's
    own draw_without_rendering, the second method), and nothing was printed: a failing print_png (a full disk)
    cannot fail there."""
    fig = new_figure(figsize=(6, 4), layout=layout)
    ax = fig.add_subplot()
    ax.set_title("a title\nof two lines")
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 2)
    ax.set_aspect("equal")
    label = ax.annotate("label", (5, 1), xytext=(8, 0), textcoords="offset points")

    def refuse(*args, **kwargs):
        raise OSError("printed")

    monkeypatch.setattr(FigureCanvasAgg, "print_png", refuse)
    renderer = laid_out(fig)
    measured = ax.get_window_extent(renderer).bounds, label.get_window_extent(renderer).bounds
    monkeypatch.undo()
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    drawn = ax.get_window_extent(renderer).bounds, label.get_window_extent(renderer).bounds
    np.testing.assert_allclose(measured, drawn, rtol=0, atol=1e-9)
