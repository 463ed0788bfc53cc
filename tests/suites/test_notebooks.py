"""The notebooks in ``notebooks/``: committed clean, paired, and every one runs from top to bottom.

Each notebook is a jupytext pair, ``NAME.ipynb`` (committed without outputs) and
``NAME.py`` (percent format, for diffs). The execution tests run every notebook in a
fresh kernel with nbclient, on the coarse grid :data:`CI_GRID` that the notebooks'
``parameters`` cell reads from ``SPINECTL_NB_GRID`` (a user gets the paper's 81 x 81),
and with this checkout first on the kernel's ``PYTHONPATH``, so that the notebooks
exercise the code under test and not an installed copy (checked from the kernel).
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
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


def _documented(program: str) -> list[str]:
    """The line of docs/notebooks.md's bash block that runs ``program``, as its words (comment removed)."""
    text = (ROOT / "docs" / "notebooks.md").read_text(encoding="utf-8")
    lines = [line for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S) for line in block.splitlines()]
    return next(shlex.split(line, comments=True) for line in lines if line.startswith(program))


def test_the_documented_way_runs_a_notebook(tmp_path):
    """docs/notebooks.md's command line, as written, in a folder holding the notebooks, with the extra that
    the page names installed: it runs a notebook in the ``python3`` kernel and writes it, with its outputs
    and no error, to its output folder, leaving the committed notebook as it was (the old advice,
    ``jupytext --execute``, found no kernel, then no nbconvert, and wrote into notebooks/). A coarse grid
    (``SPINECTL_NB_GRID``, which the page documents) and this checkout first on the path."""
    argv = _documented("jupyter nbconvert")
    assert argv[:2] == ["jupyter", "nbconvert"] and "--execute" in argv
    (tmp_path / "notebooks").symlink_to(ROOT / "notebooks")
    before = {p.name: p.read_bytes() for p in NOTEBOOKS}
    env = {**os.environ, "SPINECTL_NB_GRID": "5"}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    jupyter = shutil.which("jupyter") or str(Path(sys.executable).with_name("jupyter"))
    done = subprocess.run([jupyter, *argv[1:]], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    name = Path(next(word for word in argv if word.endswith(".ipynb"))).name
    written = tmp_path / argv[argv.index("--output-dir") + 1] / name
    cells = json.loads(written.read_text(encoding="utf-8"))["cells"]
    outputs = [o for c in cells if c["cell_type"] == "code" for o in c["outputs"]]
    assert outputs and not [o for o in outputs if o["output_type"] == "error"]
    assert {p.name: p.read_bytes() for p in NOTEBOOKS} == before


def test_the_documented_extra_installs_jupyterlab():
    """``jupyter lab notebooks/``, the page's first way: the ``notebooks`` extra (in ``test`` too) brings it."""
    assert _documented("jupyter lab")[:2] == ["jupyter", "lab"]
    jupyter = shutil.which("jupyter") or str(Path(sys.executable).with_name("jupyter"))
    done = subprocess.run([jupyter, "lab", "--version"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip()[0].isdigit(), done.stderr
