"""The reference pages: spinectl's generators in docs/_ext, and the pages that maintained extensions make.

The whole Sphinx build runs in .ci/run; :func:`reference_site` builds the
command-line page and the API pages of one subpackage, as plain text, with the
settings of docs/conf.py, so that a test can read what they list.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from spinectl.cli import build_parser
from spinectl.model.config import to_dict
from spinectl.model.params import Model

DOCS = Path(__file__).resolve().parents[2] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
from spinectl_docs import (  # noqa: E402
    API_FOLDER,
    design,
    guide,
    notebooks,
    parameters,
    prune_api_pages,
    reexports,
    reproduction,
    write_if_changed,
)


def test_parameters_page_lists_every_parameter_with_its_unit():
    # the parameters as the TOML dict has them, independently of the field metadata the page is built from
    page = parameters.markdown()
    rows = 0
    for section, fields in to_dict(Model()).items():
        if isinstance(fields, dict):
            for name in fields:
                assert f"| `{section}.{name}` |" in page
                rows += 1
        else:  # a list of tables, e.g. muscles: one row per field, one default column per entry
            for name in fields[0]:
                assert f"| `{name}` |" in page
                rows += 1
    assert rows > 30
    assert "| `body.mass` | kg | `40.0` |" in page


SITE_CONF = f"""
import runpy

globals().update(runpy.run_path({str(DOCS / "conf.py")!r}))
extensions = [name for name in extensions if name != "spinectl_docs"]  # no notebooks, no generated pages
templates_path = [{str(DOCS / "_templates")!r}]
exclude_patterns = ["_build"]
"""

SITE_INDEX = """# Reference

```{toctree}
cli
api
```
"""

SITE_API = """API
===

.. autosummary::
   :toctree: api
   :recursive:

   spinectl.model
"""


@pytest.fixture(scope="module")
def reference_site(tmp_path_factory) -> Path:
    """docs/cli.md and the API pages of spinectl.model, built as text (in a subprocess: the
    argparse extension removes spinectl.cli from ``sys.modules`` after reading its parser)."""
    pytest.importorskip("sphinx_argparse_cli", reason="the docs extra is not installed")
    src = tmp_path_factory.mktemp("site")
    (src / "conf.py").write_text(SITE_CONF)
    (src / "index.md").write_text(SITE_INDEX)
    (src / "api.rst").write_text(SITE_API)
    shutil.copy(DOCS / "cli.md", src / "cli.md")
    command = [sys.executable, "-m", "sphinx", "-q", "-b", "text", str(src), str(src / "_build")]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return src / "_build"


def command_paths(parser: argparse.ArgumentParser, prefix: str = "spinectl") -> list[str]:
    """Every sub-command below ``parser``, as typed (``spinectl config show``), aliases once."""
    paths = []
    for action in parser._actions:  # argparse has no public walk of its sub-commands
        if isinstance(action, argparse._SubParsersAction):
            seen = set()
            for name, sub in action.choices.items():
                if id(sub) not in seen:
                    seen.add(id(sub))
                    paths += [f"{prefix} {name}", *command_paths(sub, f"{prefix} {name}")]
    return paths


def test_cli_page_has_a_section_for_every_command(reference_site):
    """The built CLI page has a section for every command and sub-command of the parser, with its options."""
    page = (reference_site / "cli.txt").read_text()
    headings = {line.strip() for line in page.splitlines()}
    paths = command_paths(build_parser())
    assert {"spinectl config show", "spinectl config presets", "spinectl study"} <= set(paths)
    assert [path for path in paths if path not in headings] == []
    assert "--preset NAME" in page and "--pcsa CM2,..." in page  # the options, with their metavars


def test_api_pages_one_per_module_internal_ones_marked(reference_site):
    """One API page per module; internal modules are marked on their page and listed apart on their package's."""
    pages = {p.stem: p.read_text() for p in (reference_site / "api").glob("*.txt")}
    assert {"spinectl.model", "spinectl.model.params", "spinectl.model._toml"} <= set(pages)
    assert "Internal module" in pages["spinectl.model._toml"]
    assert "Internal module" not in pages["spinectl.model.params"]
    package = pages["spinectl.model"]  # tables of its modules, public first: "| "params" | Model parameters ..."
    public, internal = package.split("-[ Modules ]-")[1].split("-[ Internal modules ]-")
    assert '| "params"' in public and '"_toml"' not in public
    assert '| "_toml"' in internal.split("-[")[0]


def test_api_pages_of_modules_that_are_gone_are_pruned(tmp_path):
    """Pages of modules that no longer exist are removed; the others stay."""
    pages = ["spinectl.model.params", "spinectl.model.gone", "spinectl.gone.module"]
    (tmp_path / API_FOLDER).mkdir()
    for name in pages:
        (tmp_path / API_FOLDER / f"{name}.rst").write_text(name)
    prune_api_pages(SimpleNamespace(srcdir=tmp_path))
    assert [p.stem for p in (tmp_path / API_FOLDER).iterdir()] == ["spinectl.model.params"]


def test_reexported_names_link_to_their_home():
    """A re-exported name resolves to the module that defines it; others resolve to nothing."""
    assert reexports.canonical("spinectl.Model") == "spinectl.model.params.model.Model"  # params: one module a section
    assert reexports.canonical("spinectl.model.params.Model") == "spinectl.model.params.model.Model"
    assert reexports.canonical("spinectl.optimise.counter_torque_front") == (
        "spinectl.optimise.reference.counter_torque_front"
    )
    assert reexports.canonical("spinectl.model.params.model.Model") is None  # already its home
    assert reexports.canonical("spinectl.no_such_name") is None
    assert reexports.canonical("numpy.ndarray") is None  # not spinectl's


def test_guide_pages_leave_out_the_index_and_the_references(tmp_path):
    names = ("index.md", "model.md", "api.md", "cli.md", "parameters.md", "glossary.md", "reflex.md", "optimisation.md")
    for name in names:
        (tmp_path / name).write_text("# x\n")
    (tmp_path / "_generated").mkdir()
    assert guide.guide_pages(tmp_path) == ["model", "optimisation", "reflex"]


def test_notebooks_are_copied_listed_and_pruned(tmp_path):
    repository, src = tmp_path / "repo", tmp_path / "repo" / "docs"
    (repository / "notebooks").mkdir(parents=True)
    for name in ("02_b.ipynb", "01_a.ipynb"):
        (repository / "notebooks" / name).write_text(f'{{"name": "{name}"}}')
    (repository / "notebooks" / "01_a.py").write_text("# the jupytext pair: not a page")
    (src / "notebooks").mkdir(parents=True)
    (src / "notebooks" / "00_removed.ipynb").write_text("{}")

    pages = notebooks.copy_notebooks(notebooks.sources(repository), src, write_if_changed)

    assert pages == ["notebooks/01_a", "notebooks/02_b"]
    assert sorted(p.name for p in (src / "notebooks").iterdir()) == ["01_a.ipynb", "02_b.ipynb"]
    assert (src / "notebooks" / "02_b.ipynb").read_text() == '{"name": "02_b.ipynb"}'
    assert notebooks.toctree_markdown(pages).splitlines()[-3:] == ["notebooks/01_a", "notebooks/02_b", "```"]


def test_the_notebooks_page_is_a_guide_page_with_their_toctree():
    docs = Path(__file__).resolve().parents[2] / "docs"
    assert "notebooks" in guide.guide_pages(docs)
    assert "```{include} _generated/notebooks-toctree.md" in (docs / "notebooks.md").read_text()


def test_reproduction_tables_list_every_landmark_and_free_parameter():
    """docs/reproduction.md's tables: one row per landmark (with its verdict) and per free parameter
    (with its bounds and the preset's value, read from the preset file)."""
    from spinectl.paper import calibration, landmarks, verdicts

    table = reproduction.landmark_table()
    for mark in landmarks.LANDMARKS:
        row = next(line for line in table.splitlines() if line.startswith(f"| `{mark.name}` |"))
        assert verdicts.VERDICTS[mark.name].verdict in row
    params = reproduction.parameter_table()
    assert all(f"| `{p.name}` | {p.unit} | {p.lower:g} | {p.upper:g} |" in params for p in calibration.FREE_PARAMETERS)


def test_the_decay_rate_table_is_what_design_answers():
    """docs/reflex.md's --decay-rate table is generated: each row's co-contraction, total local stiffness and
    rightmost root are those of spinectl.reflex.design.answer at that decay rate (the command's own numbers,
    never typed), the rightmost root at or left of -sigma, and the stiffness grows with sigma; a rate the rule
    cannot reach says so."""
    import numpy as np

    from spinectl.model.config import load_preset
    from spinectl.reflex.design import answer

    rows = [line.split(" | ") for line in design.decay_table().splitlines()[2:]]
    assert len(rows) == len(design.DECAY_RATES)
    totals = []
    for sigma, row in zip(design.DECAY_RATES, rows, strict=True):
        chain = answer(load_preset("wagner2012"), *design.POINT, decay=sigma).chain
        result = answer(load_preset("wagner2012"), *design.POINT, decay=sigma)
        assert row[1] == (f"{result.activation:.4f}" if np.isfinite(result.activation) else "none in [0, 1]")
        if not np.isfinite(chain.fraction):
            assert row[2] == "none up to k*"
            continue
        assert row[2] == f"{np.sum(chain.local_stiffness):.1f}" and float(row[4]) <= -sigma + 1e-6
        totals.append(float(row[2]))
    assert totals == sorted(totals) and len(totals) >= 3


def test_the_study_estimate_line_is_the_estimate_of_the_pages_example(monkeypatch):
    """docs/studies.md's estimate line (studies.py) is the one `spinectl study` states before a long run: for
    the page's example (1000 x 1000 points x 100 values of K) it counts 100,000,000 points, and it follows the
    benchmark's cost a point (here doubled: the line's CPU time doubles), not a typed figure."""
    from spinectl_docs import studies

    from spinectl.landscape import budget

    line = studies.estimate_line()
    assert line.startswith("study: 100,000,000 points, about ") and line.endswith(" of CPU (estimated)")
    hours = float(line.split(", ")[-1].split(" h ")[0])
    monkeypatch.setattr(budget, "STUDY_SECONDS_PER_POINT", 2 * budget.STUDY_SECONDS_PER_POINT)
    assert float(studies.estimate_line().split(", ")[-1].split(" h ")[0]) == pytest.approx(2 * hours, rel=0.05)
