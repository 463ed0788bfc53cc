"""User text quoted for the file formats spinectl writes: the one way such text enters XML, TOML and Markdown.

Paths, preset and pair names, titles, command lines and provenance strings are the user's. Written
into a file by string formatting, they can end the construct they stand in and become part of
the file: a path holding ``-->`` ends an XML comment (the ``<include file=...>`` after it is then
followed by MuJoCo), a line break ends a TOML comment (the next line is read as parameters), a
``|`` splits a Markdown table's cell. Every writer passes such text through one function here;
JSON needs none (:mod:`json` quotes every string, :mod:`spinectl.jsondoc`), nor XML attributes and
element text built with the XML library (MuJoCo's spec API, OpenSim's API, :mod:`xml.etree`), which
escape them.

- :func:`xml_comment`: an XML comment cannot escape anything (no ``--`` inside, no ``-`` last), so
  the text is percent-encoded where it must be; :func:`from_xml_comment` reads it back exactly.
- :func:`toml_comment`, :func:`toml_string`: a comment of one line; a basic string with every
  character TOML requires escaped.
- :func:`markdown_text`: text that renders as itself, in prose or in a table cell.
"""

from __future__ import annotations

import re
from urllib.parse import unquote

from ._validate import printable


def _percent(char: str) -> str:
    """``char`` as percent-encoded UTF-8 (a lone surrogate, e.g. an undecodable byte of a path, too)."""
    return "".join(f"%{byte:02X}" for byte in char.encode("utf-8", "surrogatepass"))


def xml_comment(text: str) -> str:
    """``text`` as the content of an XML comment, percent-encoded where it must be.

    XML has no escape inside a comment: ``--`` may not occur in it nor ``-`` end it (XML 1.0, production
    ``Comment``), and a character XML does not allow (a control character, a lone surrogate) may occur
    nowhere. Those and ``%`` itself are written as ``%XX`` (UTF-8 bytes), and so are line breaks and tabs,
    so that the comment stays one line; the rest of the text is kept as it reads.

    Parameters
    ----------
    text : str
        E.g. a model's header line with its ``--config`` path.

    Returns
    -------
    str
        Text without ``--``, not ending with ``-``, of characters XML allows only;
        :func:`from_xml_comment` gives ``text`` back.
    """
    out: list[str] = []
    for i, char in enumerate(text):
        dash_pair = char == "-" and ((out and out[-1].endswith("-")) or i == len(text) - 1)
        if char == "%" or dash_pair or not char.isprintable():  # every character XML forbids is one
            char = _percent(char)
        out.append(char)
    return "".join(out)


def from_xml_comment(comment: str) -> str:
    """The text that :func:`xml_comment` encoded into ``comment``.

    Parameters
    ----------
    comment : str

    Returns
    -------
    str
    """
    return unquote(comment, errors="surrogatepass")


def toml_comment(text: str) -> str:
    """``text`` as one TOML comment line: ``"# "`` and the text with line breaks and control characters escaped.

    A line break would end the comment and make the rest of the text TOML; TOML allows no control
    character but the tab in a comment either (TOML 1.0, "Comment").

    Parameters
    ----------
    text : str

    Returns
    -------
    str
        One line starting with ``#``.
    """
    return f"# {printable(text)}".rstrip()


_TOML_SHORT = {"\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r", '"': '\\"', "\\": "\\\\"}
_TOML_ESCAPED = re.compile('["\\\\\x00-\x1f\x7f]')


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string: in double quotes, ``"``, ``\\`` and control characters escaped.

    Parameters
    ----------
    text : str

    Returns
    -------
    str
        What :mod:`tomllib` reads back to ``text``.

    Raises
    ------
    ValueError
        ``text`` holds a lone surrogate, which no TOML string can hold.
    """
    if re.search("[\ud800-\udfff]", text):
        raise ValueError(f"a TOML string cannot hold a lone surrogate (got {printable(text)})")
    body = _TOML_ESCAPED.sub(lambda m: _TOML_SHORT.get(m.group(), f"\\u{ord(m.group()):04x}"), text)
    return f'"{body}"'


_MARKDOWN_SPECIAL = re.compile(r"([\\`*_\[\]<>|&~#!])")
"""ASCII punctuation that Markdown (CommonMark and GitHub's tables) may read as markup: code, emphasis,
links, images, HTML and entities, table cells, strike-through, headings. CommonMark lets a backslash
escape any ASCII punctuation, which then renders as itself."""


def markdown_text(text: str) -> str:
    """``text`` as Markdown that renders as the text itself, on one line, in prose or in a table's cell.

    Line breaks and control characters are escaped as in ``repr`` first (a line break would start a new
    block, a heading or a table row), then every character of :data:`_MARKDOWN_SPECIAL` gets a backslash.

    Parameters
    ----------
    text : str
        E.g. a path, a preset's name, a prior's source.

    Returns
    -------
    str
    """
    return _MARKDOWN_SPECIAL.sub(r"\\\1", printable(text))


def markdown_cell_code(text: str) -> str:
    """``text`` as a code span in a Markdown table's cell, rendering as the text itself.

    No escape works inside a code span, so its fence is one backtick longer than the longest run of
    backticks in the text (padded by a space where the text starts or ends with one, CommonMark,
    "Code spans"); GitHub's tables split cells at ``|`` before reading code spans, so ``|`` is written
    ``\\|`` there, which the table turns back into ``|``. Line breaks are escaped as in ``repr``.

    Parameters
    ----------
    text : str
        E.g. a parameter's dotted name that may hold a pair's name.

    Returns
    -------
    str
    """
    text = printable(text).replace("|", "\\|")
    fence = "`" * (max((len(run) for run in re.findall("`+", text)), default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"
