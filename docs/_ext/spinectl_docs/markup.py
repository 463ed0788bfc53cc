"""Small text helpers shared by the generators."""

from __future__ import annotations

import re

MARKDOWN_SPECIAL = re.compile(r"([\\`*_\[\]<>|$])")
RST_SPECIAL = re.compile(r"([\\`*_|])")
RST_LITERAL = re.compile(r"``([^`]+)``")
RST_ROLE = re.compile(r":(?:py:)?(\w+):`([^`]+)`")


def md_escape(text: str) -> str:
    """Plain text as MyST Markdown: backslash-escape what would be markup (tables, math, emphasis)."""
    return MARKDOWN_SPECIAL.sub(r"\\\1", " ".join(str(text).split()))


def rst_escape(text: str) -> str:
    """Plain text as reST: ``||CT||`` is not a substitution, ``f_iso_`` not a link."""
    return RST_SPECIAL.sub(r"\\\1", " ".join(str(text).split()))


def rst_to_myst(text: str) -> str:
    """The inline reST of a docstring (````x````, ``:class:`X```) as MyST, on one line."""
    text = " ".join(text.split())
    text = RST_LITERAL.sub(r"`\1`", text)
    return RST_ROLE.sub(r"{py:\1}`\2`", text)


def first_paragraph(doc: str | None) -> str:
    """The first paragraph of a docstring, on one line."""
    return " ".join((doc or "").strip().split("\n\n")[0].split())


def literal(value) -> str:
    """A default value as it is written in a TOML configuration file."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float) and value in (float("inf"), float("-inf")):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(literal(v) for v in value) + "]"
    return repr(value)
