"""The notebooks in ``notebooks/``: committed clean, paired, and every one runs from top to bottom.

Each notebook is a jupytext pair, ``NAME.ipynb`` (committed without outputs) and
``NAME.py`` (percent format, for diffs). The execution tests run every notebook in a
fresh kernel with nbclient, on the coarse grid :data:`CI_GRID` that the notebooks'
``parameters`` cell reads from ``SPINECTL_NB_GRID`` (a user gets the paper's 81 x 81),
and with this checkout first on the kernel's ``PYTHONPATH``, so that the notebooks
exercise the code under test and not an installed copy (checked from the kernel).
"""

from __future__ import annotations

import os
from pathlib import Path

import jupytext
import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
EXPECTED = ("01_reproducing_the_paper", "02_reflex_versus_self_stability", "03_sensitivity", "04_chain")
"""The notebooks docs/notebooks.md lists: reproduction, delayed reflex, sensitivity, the chain."""

CI_GRID = "17"
"""Grid points per axis in the tests (5 mm): each notebook runs in well under a minute."""

CELL_TIMEOUT = 300
"""Seconds one cell may take before the run counts as hung."""

by_name = pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)


def test_the_issue_notebooks_are_there():
    """The notebooks of :data:`EXPECTED` are in ``notebooks/``; others may be added."""
    assert {p.stem for p in NOTEBOOKS} >= set(EXPECTED)


@by_name
def test_committed_without_outputs(path):
    notebook = nbformat.read(path, as_version=4)
    nbformat.validate(notebook)
    for cell in notebook.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, cell.source[:80]
    assert notebook.metadata.kernelspec.name == "python3"  # Jupyter, nbclient and myst-nb start this kernel


@by_name
def test_pair_says_the_same(path):
    """NAME.py holds the same cells as NAME.ipynb (``jupytext --sync`` after editing either)."""
    pair = path.with_suffix(".py")
    assert pair.is_file(), f"{pair.name} missing: jupytext --sync {path.name}"

    def cells(notebook):
        return [(c.cell_type, c.source.strip(), c.metadata.get("tags", [])) for c in notebook.cells]

    assert cells(jupytext.read(pair)) == cells(jupytext.read(path)), f"out of sync: jupytext --sync {path.name}"


@by_name
def test_grid_is_a_parameter(path):
    """One cell tagged ``parameters`` (papermill's convention) reads the grid from the environment."""
    tagged = [c for c in nbformat.read(path, as_version=4).cells if "parameters" in c.metadata.get("tags", [])]
    assert len(tagged) == 1
    assert 'os.environ.get("SPINECTL_NB_GRID"' in tagged[0].source


@by_name
def test_runs(path, tmp_path, monkeypatch):
    notebook = nbformat.read(path, as_version=4)
    notebook.cells.append(nbformat.v4.new_code_cell("import spinectl\nprint(spinectl.__file__, GRID)"))
    monkeypatch.setenv("SPINECTL_NB_GRID", CI_GRID)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    client = NotebookClient(
        notebook, kernel_name="python3", timeout=CELL_TIMEOUT, resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()  # a cell that raises fails here, with its traceback

    where, grid = notebook.cells[-1].outputs[0].text.split()
    assert Path(where).is_relative_to(ROOT / "spinectl") and grid == CI_GRID
    stderr = [o.text for c in notebook.cells for o in c.get("outputs", []) if o.get("name") == "stderr"]
    assert not stderr, "warnings in the notebook's output (the docs would show them):\n" + "\n".join(stderr)
    figures = sum("image/png" in o.get("data", {}) for c in notebook.cells for o in c.get("outputs", []))
    assert figures > 0
    assert not list(tmp_path.iterdir()), "a notebook wrote files"
