"""Figures without pyplot: no module selects a backend, figures live on their own Agg canvas, saved atomically."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from spinectl.canvas import new_figure, save_file
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


def test_a_failed_save_leaves_the_previous_file(tmp_path, monkeypatch):
    target = tmp_path / "f.png"
    target.write_bytes(b"previous")
    fig = new_figure()

    def broken(*args, **kwargs):
        raise RuntimeError("simulated failure while rendering")

    monkeypatch.setattr(fig, "savefig", broken)
    with pytest.raises(RuntimeError):
        save_file(fig, target, dpi=50)
    assert target.read_bytes() == b"previous" and [p.name for p in tmp_path.iterdir()] == ["f.png"]
    with pytest.raises(OutputError, match="cannot write"):
        save_file(new_figure(), target / "below.png", dpi=50)  # a file where a folder should be
