"""The generators of the reference pages in docs/_ext (the Sphinx build itself runs in .ci/run)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from spinectl.model.config import to_dict
from spinectl.model.params import Model

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "_ext"))
from spinectl_docs import api, cli, guide, notebooks, parameters, reproduction, write_if_changed  # noqa: E402


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


def test_cli_page_walks_sub_sub_commands_and_skips_aliases():
    parser = argparse.ArgumentParser(prog="tool")
    sub = parser.add_subparsers(dest="command")
    group = sub.add_parser("group", help="a group", aliases=["g"])
    inner = group.add_subparsers(dest="action")
    leaf = inner.add_parser("leaf", help="the leaf")
    leaf.add_argument("--width", type=float, default=2.5, help="width [m], default %(default)s")
    page = cli.markdown(parser)
    assert "## `tool`" in page and "### `tool group`" in page and "#### `tool group leaf`" in page
    assert page.count("### `tool group`") == 1  # the alias g is the same parser
    assert "| `--width WIDTH` | 2.5 | width \\[m\\], default 2.5 |" in page


def test_cli_page_has_every_spinectl_command():
    page = cli.markdown()
    for command in ("spinectl config show", "spinectl config presets", "spinectl stability"):
        assert f"`{command}`" in page


def test_api_stub_per_module_and_reexports():
    names = api.module_names()
    assert "spinectl.model.mechanics" in names and "spinectl.__main__" not in names
    assert ".. automodule:: spinectl.model.mechanics" in api.stub("spinectl.model.mechanics")
    assert ":py:obj:`~spinectl.model.params.Model`" in api.stub("spinectl")


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
