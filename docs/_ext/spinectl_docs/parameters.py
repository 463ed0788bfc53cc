"""The parameter tables of ``docs/parameters.md``, from the metadata of :mod:`spinectl.model.params`."""

from __future__ import annotations

import dataclasses
import inspect

from spinectl.model.params import Model

from .markup import first_paragraph, literal, md_escape, rst_to_myst

HEADER = ["| parameter | unit | default | description and source |", "| --- | --- | --- | --- |"]


def _code(value) -> str:
    text = literal(value)
    return md_escape(text) if "`" in text else f"`{text}`"


def _row(name: str, f, value) -> str:
    unit = md_escape(f.metadata.get("unit", "")) or "–"
    return f"| `{name}` | {unit} | {_code(value)} | {md_escape(f.metadata.get('doc', ''))} |"


def _heading(title: str, doc: str, cls) -> list[str]:
    """Section title, then the first paragraph of the class docstring (or the field's doc)."""
    qualname = f"{cls.__module__}.{cls.__qualname__}"
    summary = rst_to_myst(first_paragraph(inspect.getdoc(cls))) or md_escape(doc)
    return [f"## `{title}`", "", f"{summary} ({{py:class}}`~{qualname}`)", ""]


def section_table(name: str, value) -> list[str]:
    """One table for a section of the model such as ``body``: one row per field."""
    return HEADER + [_row(f"{name}.{f.name}", f, getattr(value, f.name)) for f in dataclasses.fields(value)]


def list_table(name: str, items: tuple) -> list[str]:
    """One table for a list of sections such as ``muscles``: one default column per item."""
    heads = [f"`{name}.{i}`" for i in range(len(items))]
    lines = [
        "| parameter | unit | " + " | ".join(heads) + " | description and source |",
        "| --- | --- | " + " | ".join("---" for _ in items) + " | --- |",
    ]
    for f in dataclasses.fields(items[0]):
        unit = md_escape(f.metadata.get("unit", "")) or "–"
        defaults = " | ".join(_code(getattr(item, f.name)) for item in items)
        lines.append(f"| `{f.name}` | {unit} | {defaults} | {md_escape(f.metadata.get('doc', ''))} |")
    return lines


def markdown(model: Model | None = None) -> str:
    """Every parameter of ``model`` (default: the dataclass defaults) as MyST Markdown."""
    model = model if model is not None else Model()
    lines, loose = [], []
    for f in dataclasses.fields(model):
        value = getattr(model, f.name)
        doc = f.metadata.get("doc", "")
        if dataclasses.is_dataclass(value):
            lines += [*_heading(f"[{f.name}]", doc, type(value)), *section_table(f.name, value), ""]
        elif isinstance(value, tuple) and value and dataclasses.is_dataclass(value[0]):
            lines += _heading(f"[[{f.name}]]", doc, type(value[0]))
            lines += [f"The default list has {len(value)} entries, one column each.", ""]
            lines += [*list_table(f.name, value), ""]
        else:
            loose.append(_row(f.name, f, value))
    if loose:
        lines += ["## Top level", "", *HEADER, *loose, ""]
    return "\n".join(lines)
