"""spinectl.quoting: user text quoted for XML comments, TOML and Markdown reads back as the text, nothing else."""

from __future__ import annotations

import tomllib
import xml.etree.ElementTree as ET

import pytest
from hypothesis import given
from hypothesis import strategies as st

from spinectl.quoting import from_xml_comment, markdown_cell_code, markdown_text, toml_comment, toml_string, xml_comment

HOSTILE = (
    'a--><include file="x.xml"/><!--',  # the issue's: ends the comment, MuJoCo follows the include
    "runs/2026-12--a/model.toml",  # an ordinary double dash: a parse error before
    "ends-",  # a comment may not end with '-'
    "---",
    "<!-- -->",
    "100%2D",  # percent signs must survive the decoding
    "line\nbreak\r\ttab\x01\x7f",
    "undecodable \udcff byte",  # a path's byte that is not UTF-8, as Python holds it
    'quote" ]] | `tick` **x** <b>&amp;',
    "Λ ünïcode",
)
"""Texts that end or break a construct if written as they are; not all are in the issue."""


@pytest.mark.parametrize("text", HOSTILE)
def test_an_xml_comment_is_one_comment_and_reads_back_as_the_text(text):
    """The comment parses as XML holding exactly one comment and one element (nothing the text opened), on one
    line, without '--' or a last '-', and decodes to the text."""
    body = xml_comment(text)
    assert "--" not in body and not body.endswith("-") and "\n" not in body
    root = ET.fromstring(f"<r><!--{body}--><e/></r>", parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    assert [child.tag for child in root] == [ET.Comment, "e"]
    assert from_xml_comment(root[0].text) == text


@given(st.text())
def test_any_text_survives_an_xml_comment(text):
    """Any string (surrogates included) goes through the comment and back unchanged."""
    body = xml_comment(text)
    assert "--" not in body and not body.endswith("-")
    assert from_xml_comment(body) == text


@given(st.text(st.characters(exclude_categories=("Cs",))))
def test_a_toml_string_reads_back_as_the_text(text):
    """tomllib reads toml_string back to the text: quotes, backslashes, ']]', control characters, DEL."""
    assert tomllib.loads(f"v = {toml_string(text)}") == {"v": text}


def test_a_toml_string_refuses_a_lone_surrogate():
    """No TOML string holds a lone surrogate: refused, not written as something tomllib reads differently."""
    with pytest.raises(ValueError, match="surrogate"):
        toml_string("a\udcffb")


@pytest.mark.parametrize("text", HOSTILE + ("x\n[body]\nmass = 1\n", "a\rb = 2"))
def test_a_toml_comment_is_one_line_and_no_value(text):
    """A comment with a line break in the text stays one comment: the document has no key at all."""
    line = toml_comment(text)
    assert line.startswith("#") and "\n" not in line and "\r" not in line
    assert tomllib.loads(line + "\n") == {}


def _rendered(markdown: str) -> str:
    """Markdown with CommonMark's backslash escapes of ASCII punctuation undone: what a reader sees of plain text."""
    out, i = [], 0
    while i < len(markdown):
        if markdown[i] == "\\" and i + 1 < len(markdown) and markdown[i + 1] in "\\`*_[]<>|&~#!":
            i += 1
        out.append(markdown[i])
        i += 1
    return "".join(out)


@pytest.mark.parametrize("text", HOSTILE + ("| a | b |", "# heading", "[link](http://x)", "![img](x.png)"))
def test_markdown_text_has_no_live_markup_and_renders_as_the_text(text):
    """Every character Markdown reads as markup carries a backslash, the line breaks are escaped, and removing the
    escapes gives the text as repr shows its control characters."""
    from spinectl._validate import printable

    out = markdown_text(text)
    assert "\n" not in out and "\r" not in out
    for i, char in enumerate(out):
        if char in "`*_[]<>|&~#!":  # escaped: an odd number of backslashes before it
            assert (len(out[:i]) - len(out[:i].rstrip("\\"))) % 2 == 1, (out, i)
    assert _rendered(out) == printable(text)


@pytest.mark.parametrize("text", ["body.mass", "muscles.a`b.upper", "``x|y", "`"])
def test_a_markdown_cell_code_span_is_not_closed_by_the_text(text):
    """The fence is longer than any backtick run inside, and '|' cannot split the table's cell."""
    out = markdown_cell_code(text)
    fence = len(out) - len(out.lstrip("`"))
    inner = out[fence:-fence]
    assert "`" * fence not in inner and "|" not in inner.replace("\\|", "")
    assert inner.strip(" ").replace("\\|", "|") == text


def test_no_writer_formats_a_comment_itself():
    """Every comment spinectl formats goes through spinectl.quoting: no one-line f-string in the package outside it
    starts a TOML comment ('# ...{x}'), none holds an XML comment ('<!--'), and every MuJoCo spec's ``comment`` is
    assigned the result of xml_comment. A writer added later that formats user text into a comment fails here (the
    header's --config path made TOML lines and live XML that way)."""
    import ast
    import pathlib

    import spinectl

    offenders = []
    for path in pathlib.Path(spinectl.__file__).parent.rglob("*.py"):
        if path.name == "quoting.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.JoinedStr) and any(isinstance(v, ast.FormattedValue) for v in node.values):
                first = node.values[0]
                text = "".join(v.value for v in node.values if isinstance(v, ast.Constant))
                one_line = "\n" not in text.rstrip("\n")  # a Markdown document's f-string starts with '# ' too
                comment = isinstance(first, ast.Constant) and first.value.startswith("# ") and one_line
                if comment or "<!--" in text:
                    offenders.append(f"{path.name}:{node.lineno}")
            if isinstance(node, ast.Assign) and any(getattr(t, "attr", None) == "comment" for t in node.targets):
                call = node.value
                if not (isinstance(call, ast.Call) and getattr(call.func, "id", None) == "xml_comment"):
                    offenders.append(f"{path.name}:{node.lineno}")
    assert offenders == []
