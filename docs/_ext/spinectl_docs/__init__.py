"""Sphinx extension: spinectl's own reference pages, generated from the code at build time.

The API pages (autosummary) and the command line (sphinx-argparse-cli) come
from maintained extensions (``conf.py``); what is particular to spinectl is
here. At ``builder-inited`` it writes, beside the hand-written pages (only when
a text changed, so that incremental builds stay incremental):

- ``_generated/parameters.md``: every parameter with unit, default and
  documentation, from the field metadata of :mod:`spinectl.model.params`;
- ``_generated/guide-toctree.md``: the toctree of the guide pages, every
  top-level page except the index and the reference pages;
- ``notebooks/*.ipynb`` and ``_generated/notebooks-toctree.md``: copies of the
  notebooks of the repository's ``notebooks/`` and their toctree, included by
  ``notebooks.md`` (myst-nb executes them);
- ``_generated/calibration-parameters.md``, ``_generated/landmark-verdicts.md`` and
  ``_generated/landmark-assumptions.md``: the tables of ``reproduction.md`` (free parameters,
  verdict of every landmark, every landmark under each assumption, measured at the build);
- ``_generated/export-eigenvalues.md``: the exports' eigenvalues in ``interchange.md``, spinectl's
  and OpenSim's own linearisation of each file (measured at the build);
- ``_generated/design-decay.md``: ``design --decay-rate``'s answers in ``reflex.md`` (measured at the build);
- ``_generated/design-chain-searched.md`` and ``design-joint-searched.md``: ``design --gains search``'s lines in
  ``reflex.md`` (:mod:`.searched`);
- ``_generated/chain-points.md``, ``chain-dynamics.md`` and ``chain-passive.md``: ``stability --coupled`` at
  four points and
  ``design --passive`` at A in ``chain.md`` (measured at the build, :mod:`.chain`); ``chain-margins.md``: the rule's
  reflex on the chain at A (``margins --coupled``);
- ``_generated/reflex-margins-*.md``: ``spinectl margins`` joint by joint in ``reflex.md`` (the lag's cost and
  each preset's activations, :mod:`.segment_margins`);
- ``_generated/anatomy-*.md``: ``spinectl anatomy``'s tables on MyoTorso in ``anatomy.md`` (verdicts, optima,
  lordosis, reflex; measured at the build, :mod:`.anatomy`);
- ``_generated/motion-lift.png``: the lift of ``motion.md`` on MyoTorso (:mod:`.lift`);
- ``_generated/studies-estimate.md``: the line ``spinectl study`` states before a long run, in ``studies.md``
  (:mod:`.studies`).

Numbers that a sentence quotes are the ``{measured}`` role's (:mod:`.values`): ``{measured}`anatomy.remedy```
is replaced by what the code gives at the build; the pages that use it are read again at every build, so
that they cannot go stale. The ``published-model`` directive (:mod:`.published`) analyses a published model
with its mapping at the build: one table row of verdicts. Besides the tables' modules, :mod:`.bends` measures
``reflex.md``'s design against K and its design curve's readings, :mod:`.millard` ``interchange.md``'s causes of
Millard's instability (and its curves and re-imported chain), :mod:`.together` ``chain.md``'s local and joint
optima at the first table's points (and ``figures.md``'s coupled ratio) and :mod:`.gainsearch` ``chain.md``'s
gain search (a small stated budget) and bounds; :mod:`.atlas` ``atlas.md``'s lordosis angle conversions
and :mod:`.atlas_run` its shipped atlas's shares and Sobol' indices (the atlas run once per build).

``_generated/`` is excluded from the sources (its files are included by
``parameters.md``, ``index.md``, ``notebooks.md`` and ``reproduction.md``);
``notebooks/``, ``_generated/`` and autosummary's ``api/`` are not in git.

At ``autodoc-process-docstring`` it adds a numpydoc "Parameters" section built
from the same metadata to the parameter dataclasses, so that their API pages
document every field. At ``missing-reference`` it sends a reference to a
re-exported name (``spinectl.Model``, listed on the package's page) to where
the name is documented.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from . import (
    anatomy,
    atlas,
    atlas_run,
    bends,
    chain,
    design,
    errata,
    fields,
    gainsearch,
    guide,
    interchange,
    lift,
    millard,
    notebooks,
    parameters,
    published,
    reexports,
    reflex,
    reproduction,
    searched,
    segment_margins,
    studies,
    together,
    trends,
    values,
)

GENERATED = "_generated"

API_FOLDER = "api"
"""The folder of autosummary's module pages (``:toctree: api`` in ``api.md``)."""


MEASURED_TABLES = (
    ("chain-points.md", chain.points_table),
    ("chain-passive.md", chain.passive_table),
    ("chain-dynamics.md", chain.dynamics_table),
    ("chain-margins.md", chain.margins_table),
    ("anatomy-verdicts.md", anatomy.verdict_table),
    ("anatomy-optimum.md", anatomy.optimum_table),
    ("anatomy-lordosis.md", anatomy.lordosis_table),
    ("anatomy-reflex.md", anatomy.reflex_table),
    ("design-chain-searched.md", searched.chain_search_table),
    ("design-joint-searched.md", searched.joint_search_table),
    ("reflex-margins-lag.md", segment_margins.lag_table),
    ("reflex-margins-default.md", lambda: segment_margins.preset_table("default")),
    ("reflex-margins-wagner2012.md", lambda: segment_margins.preset_table("wagner2012")),
    ("studies-estimate.md", studies.estimate_block),
)
"""The tables of what commands print, measured at the build: (file in ``_generated/``, its generator)."""

MEASURED_VALUES = (
    anatomy,
    atlas,
    atlas_run,
    bends,
    chain,
    errata,
    gainsearch,
    interchange,
    lift,
    millard,
    reflex,
    reproduction,
    searched,
    segment_margins,
    together,
    trends,
)
"""The modules that register ``{measured}`` values (:func:`.values.value`) when imported."""


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` unless it already holds exactly that."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def opensim_first() -> None:
    """Import OpenSim, where installed, before anything imports cvxpy.

    Imported after cvxpy, OpenSim's SWIG wrappers refuse their own ``StdVectorInt`` in
    ``Function.calcDerivative`` (a ``TypeError``; ``python -c "import cvxpy, opensim; ..."`` shows it), which
    loading an ``.osim`` model with couplers calls; the build computes optima (cvxpy) before it analyses the
    published models.
    """
    try:
        import opensim  # noqa: F401
    except ImportError:
        pass


def generate(app) -> None:
    """Write every generated page (the ``builder-inited`` handler)."""
    opensim_first()
    src = Path(app.srcdir)
    out = src / GENERATED
    write_if_changed(out / "parameters.md", parameters.markdown())
    write_if_changed(out / "guide-toctree.md", guide.toctree_markdown(src))
    pages = notebooks.copy_notebooks(notebooks.sources(src.parent), src, write_if_changed)
    write_if_changed(out / "notebooks-toctree.md", notebooks.toctree_markdown(pages))
    write_if_changed(out / "calibration-parameters.md", reproduction.parameter_table())
    write_if_changed(out / "landmark-verdicts.md", reproduction.landmark_table())
    write_if_changed(out / "landmark-assumptions.md", reproduction.assumption_table())
    write_if_changed(out / "export-eigenvalues.md", interchange.export_table())
    write_if_changed(out / "design-decay.md", design.decay_table())
    for name, table in MEASURED_TABLES:
        write_if_changed(out / name, table())
    lift.write_figure(out)


def prune_api_pages(app) -> None:
    """Remove the pages that autosummary wrote for modules that are gone (renamed or removed).

    autosummary writes ``api/<module>.rst`` but never removes one, and a page in
    no toctree fails the build (``-W``); a fresh checkout has none of them.
    """
    for page in (Path(app.srcdir) / API_FOLDER).glob("*.rst"):
        try:
            gone = importlib.util.find_spec(page.stem) is None
        except ModuleNotFoundError:  # its package is gone too
            gone = True
        if gone:
            page.unlink()


def setup(app):
    app.connect("builder-inited", generate)
    app.connect("builder-inited", prune_api_pages, priority=600)  # after autosummary's (500)
    # before numpydoc (priority 500) turns the sections into reST
    app.connect("autodoc-process-docstring", fields.add_parameters_section, priority=400)
    app.connect("missing-reference", reexports.resolve)
    app.add_role("measured", values.measured_role)
    app.add_directive("published-model", published.PublishedModel)
    app.connect("env-get-outdated", values.outdated)
    app.connect("env-purge-doc", values.purge)
    app.connect("env-merge-info", values.merge)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
