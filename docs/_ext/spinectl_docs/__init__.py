"""Sphinx extension: spinectl's reference pages, generated from the code at build time.

At ``builder-inited`` it writes, beside the hand-written pages (only when a
text changed, so that incremental builds stay incremental):

- ``_generated/parameters.md``: every parameter with unit, default and
  documentation, from the field metadata of :mod:`spinectl.model.params`;
- ``_generated/cli.md``: every command and sub-command of
  :func:`spinectl.cli.build_parser`;
- ``_generated/api-modules.md`` and ``api/<module>.rst``: one autodoc page per
  module of the package, found by walking it;
- ``_generated/guide-toctree.md``: the toctree of the guide pages, every
  top-level page except the index and the reference pages;
- ``notebooks/*.ipynb`` and ``_generated/notebooks-toctree.md``: copies of the
  notebooks of the repository's ``notebooks/`` and their toctree, included by
  ``notebooks.md`` (myst-nb executes them);
- ``_generated/calibration-parameters.md`` and ``_generated/landmark-verdicts.md``:
  the tables of ``reproduction.md`` (free parameters, verdict of every landmark).

``_generated/`` is excluded from the sources (its files are included by
``parameters.md``, ``cli.md``, ``api.md``, ``index.md``, ``notebooks.md`` and ``reproduction.md``);
``api/``, ``notebooks/`` and ``_generated/`` are not in git. At ``autodoc-process-docstring`` it adds a
numpydoc "Parameters" section built from the same metadata to the parameter
dataclasses, so that their API pages document every field.
"""

from __future__ import annotations

from pathlib import Path

from . import api, cli, fields, guide, notebooks, parameters, reproduction

GENERATED = "_generated"


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` unless it already holds exactly that."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def generate(app) -> None:
    """Write every generated page (the ``builder-inited`` handler)."""
    src = Path(app.srcdir)
    out = src / GENERATED
    write_if_changed(out / "parameters.md", parameters.markdown())
    write_if_changed(out / "cli.md", cli.markdown())
    modules = api.module_names()
    write_if_changed(out / "api-modules.md", api.index_markdown(modules, folder=api.FOLDER))
    stubs = {f"{name}.rst": api.stub(name) for name in modules}
    for name, text in stubs.items():
        write_if_changed(src / api.FOLDER / name, text)
    for old in (src / api.FOLDER).glob("*.rst"):
        if old.name not in stubs:  # a module that was removed or renamed
            old.unlink()
    write_if_changed(out / "guide-toctree.md", guide.toctree_markdown(src))
    pages = notebooks.copy_notebooks(notebooks.sources(src.parent), src, write_if_changed)
    write_if_changed(out / "notebooks-toctree.md", notebooks.toctree_markdown(pages))
    write_if_changed(out / "calibration-parameters.md", reproduction.parameter_table())
    write_if_changed(out / "landmark-verdicts.md", reproduction.landmark_table())


def setup(app):
    app.connect("builder-inited", generate)
    # before numpydoc (priority 500) turns the sections into reST
    app.connect("autodoc-process-docstring", fields.add_parameters_section, priority=400)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
