"""The notebooks of ``notebooks/`` as pages of the site: copied in, and listed, at each build.

Sphinx reads sources only below ``docs/``, and the notebooks live at the top of the
repository (where the tests run them and jupytext pairs them). So every
``notebooks/*.ipynb`` is copied to ``docs/notebooks/`` (not in git; copies of removed
notebooks are deleted), and ``_generated/notebooks-toctree.md`` lists them for
``notebooks.md``. myst-nb executes the copies (``nb_execution_mode`` in ``conf.py``).
"""

from __future__ import annotations

from pathlib import Path

FOLDER = "notebooks"
"""Folder of the notebooks, at the top of the repository and, for the copies, in ``docs/``."""


def sources(repository: Path) -> list[Path]:
    """The notebooks of the repository, in the order of their names (``01_...``, ``02_...``).

    Parameters
    ----------
    repository : Path
        Root of the checkout (the parent of ``docs/``).
    """
    return sorted((repository / FOLDER).glob("*.ipynb"))


def copy_notebooks(notebooks: list[Path], src: Path, write) -> list[str]:
    """Copy ``notebooks`` into ``src/notebooks/`` and remove copies without a source; return their docnames.

    Parameters
    ----------
    notebooks : list of Path
        From :func:`sources`.
    src : Path
        The Sphinx source folder, ``docs/``.
    write : callable
        ``write(path, text)``, e.g. one that leaves an unchanged file alone, so that
        Sphinx neither re-reads nor re-executes it.
    """
    target = src / FOLDER
    names = {path.name for path in notebooks}
    for path in notebooks:
        write(target / path.name, path.read_text(encoding="utf-8"))
    for old in target.glob("*.ipynb"):
        if old.name not in names:
            old.unlink()
    return [f"{FOLDER}/{path.stem}" for path in notebooks]


def toctree_markdown(docnames: list[str]) -> str:
    """A MyST toctree of the notebook pages, to be included by ``notebooks.md``.

    Parameters
    ----------
    docnames : list of str
        From :func:`copy_notebooks`.
    """
    entries = "\n".join(docnames)
    return f"```{{toctree}}\n:maxdepth: 1\n\n{entries}\n```\n"
