"""One autodoc page per module of :mod:`spinectl`, found by walking the package."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import spinectl

from .markup import first_paragraph, rst_to_myst

FOLDER = "api"
"""Folder of the generated module pages, relative to the docs sources."""

NOT_IMPORTED = {"spinectl.__main__"}  # importing it runs the CLI


def module_names() -> list[str]:
    """Every module of the package, packages first within their folder."""
    walked = pkgutil.walk_packages(spinectl.__path__, prefix="spinectl.")
    return ["spinectl", *sorted(m.name for m in walked if m.name not in NOT_IMPORTED)]


def internal(name: str) -> bool:
    """A module whose dotted name has a part with a leading underscore."""
    return any(part.startswith("_") for part in name.split("."))


def reexports(module) -> list[str]:
    """Canonical dotted names of what ``module`` lists in ``__all__`` but defines elsewhere."""
    out = []
    for name in getattr(module, "__all__", ()):
        obj = getattr(module, name, None)
        home = getattr(obj, "__module__", None)
        if home and home != module.__name__ and hasattr(obj, "__qualname__"):
            out.append(f"{home}.{obj.__qualname__}")
    return out


def stub(name: str) -> str:
    """The reST page of module ``name``: its docstring and members, via autodoc and numpydoc."""
    title = f"``{name}``"
    lines = [title, "=" * len(title), ""]
    if internal(name):
        lines += [".. note:: Internal module: used inside spinectl, not a stable interface.", ""]
    lines += [
        f".. automodule:: {name}",
        "   :members:",
        "   :ignore-module-all:",
        "   :show-inheritance:",
        "   :member-order: bysource",
        "",
    ]
    exported = reexports(importlib.import_module(name))
    if exported:
        lines += [".. rubric:: Re-exported here", ""]
        lines += [f"- :py:obj:`~{target}`" for target in exported]
        lines.append("")
    return "\n".join(lines)


def index_markdown(names: list[str], folder: str) -> str:
    """A table of every module with the first paragraph of its docstring, linking to its page."""
    lines = ["| module | summary |", "| --- | --- |"]
    for name in names:
        summary = rst_to_myst(first_paragraph(inspect.getdoc(importlib.import_module(name)))).replace("|", "\\|")
        tag = " (internal)" if internal(name) else ""
        lines.append(f"| {{doc}}`{name} <{folder}/{name}>`{tag} | {summary} |")
    return "\n".join(lines) + "\n"
