"""Sphinx configuration of the spinectl documentation.

Build from the repository root (warnings are errors, as in CI)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Markdown pages go through MyST (myst-nb, which also executes and renders the
notebooks); docstrings through autodoc and numpydoc. The reference pages are
generated from the code at each build: the API by autosummary (one page per
module, ``api/``, from ``_templates/autosummary/module.rst``), the command line
by sphinx-argparse-cli (``cli.md``), the parameters and the tables of the
reproduction page by the local extension in ``_ext/spinectl_docs``, which also
copies the notebooks of ``notebooks/`` into ``docs/notebooks/``.
"""

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(DOCS.parent))  # this checkout's spinectl, installed or not
# the notebooks' kernels too: they inherit this environment
os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(DOCS.parent), os.environ.get("PYTHONPATH")]))

import spinectl  # noqa: E402

project = "spinectl"
author = "spinectl developers"
copyright = "spinectl developers, BSD-3-Clause"
release = version = spinectl.__version__

extensions = [
    "myst_nb",  # MyST Markdown pages, and notebooks
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",  # the API pages, docs/api.md
    "sphinx_argparse_cli",  # the command-line reference, docs/cli.md
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 from _static/, so equations render without a network
    "sphinx.ext.viewcode",
    "spinectl_docs",
]

root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "_generated", "**/.ipynb_checkpoints"]

# MyST: $...$ and $$...$$ math, \begin{align} environments
myst_enable_extensions = ["dollarmath", "amsmath"]
# Notebooks: committed without outputs, executed at every build ("force"), so that
# the pages always show what the code computes now. "cache" keys on the notebook's
# cells only, and would show stale figures after a change to spinectl itself;
# "off" would need outputs in git. A grid of 33 x 33 (2.5 mm) keeps the build to
# about a minute; SPINECTL_NB_GRID=81 in the environment gives the paper's grid.
nb_execution_mode = "force"
nb_execution_timeout = 600  # s per cell
nb_execution_raise_on_error = True  # a failing notebook fails the build
os.environ.setdefault("SPINECTL_NB_GRID", "33")

# autodoc + numpydoc
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
numpydoc_show_class_members = False  # autodoc lists the members itself
numpydoc_xref_param_type = False

# autosummary: a page per module, walking the package from docs/api.md (:recursive:);
# a package's tables list what its __all__ exports, re-exported names included
autosummary_generate = True
autosummary_ignore_module_all = False

# no intersphinx: the build runs without network

html_theme = "alabaster"
html_title = f"spinectl {release}"
html_theme_options = {
    "description": "Control-theoretic analysis of spinal stability (Wagner et al. 2012)",
    "fixed_sidebar": True,
    "page_width": "1160px",  # room for the equations and the parameter tables
    "sidebar_width": "230px",
}
