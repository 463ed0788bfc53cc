"""Document the fields of the parameter dataclasses from their ``unit`` and ``doc`` metadata."""

from __future__ import annotations

import dataclasses

from .markup import literal, rst_escape


def field_entries(cls) -> list[str]:
    """numpydoc "Parameters" entries for the fields of ``cls`` that carry ``doc`` metadata."""
    lines = []
    for f in dataclasses.fields(cls):
        doc = f.metadata.get("doc")
        if not doc:
            continue
        kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
        if f.default is not dataclasses.MISSING:
            kind += f", default {literal(f.default)}"
        unit = f.metadata.get("unit")
        lines += [f"{f.name} : {kind}", "    " + (f"[{rst_escape(unit)}] " if unit else "") + rst_escape(doc)]
    return lines


def add_parameters_section(app, what, name, obj, options, lines) -> None:
    """``autodoc-process-docstring`` handler: a "Parameters" section for metadata-documented dataclasses."""
    if what != "class" or not dataclasses.is_dataclass(obj):
        return
    if any(line.strip() == "Parameters" for line in lines):
        return  # the docstring documents its parameters itself
    entries = field_entries(obj)
    if entries:
        lines += ["", "Parameters", "----------", *entries]
