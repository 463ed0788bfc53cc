"""The toctree of the guide pages: every top-level page but the index and the reference pages.

A glob toctree cannot leave out the reference pages, which have their own
toctree; so the list is made here, at each build, from the files present.
"""

from __future__ import annotations

from pathlib import Path

NOT_GUIDE = ("index", "parameters", "glossary", "cli", "api")
"""Top-level pages that are not guide pages: the index and the reference pages (their toctree is in index.md)."""

FIRST = ("model",)
"""Guide pages listed first, in this order; the others follow alphabetically."""

SUFFIXES = (".md", ".ipynb", ".rst")


def guide_pages(src: Path) -> list[str]:
    """Docnames of the guide pages in ``src``, ``FIRST`` first."""
    names = {p.stem for p in src.iterdir() if p.suffix in SUFFIXES and not p.name.startswith((".", "_"))}
    names -= set(NOT_GUIDE)
    first = [n for n in FIRST if n in names]
    return first + sorted(names - set(first))


def toctree_markdown(src: Path) -> str:
    """A MyST toctree of the guide pages, to be included by ``index.md``."""
    entries = "\n".join(guide_pages(src))
    return f"```{{toctree}}\n:caption: Guide\n:maxdepth: 2\n\n{entries}\n```\n"
