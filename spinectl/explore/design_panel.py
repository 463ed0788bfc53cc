"""The explorer's design panel as HTML: the words of ``spinectl design``'s table, part by part (no Panel).

The lines are the library's (:meth:`spinectl.reflex.design.result.Design.readings` through
:func:`spinectl.explore.numbers.design_rows`), the same that ``spinectl design`` prints, so that the panel and
the command cannot say different things: each criterion headed by its name, joint by joint the segments'
table, then every answer with the reflex it assumes, that the least value is a stability boundary, the chain's
global PCSA and gains and what a margin costs. A line that names an option of ``spinectl design`` (``--margin
R``, ``--gains search``) is followed by the command that runs it on the explorer's state (:func:`design_command`).
"""

from __future__ import annotations

import html

from ..reflex.design import Design
from .numbers import design_rows
from .state import ExploreState

TOML_NAME = "spinectl-explore.toml"
"""The file name of the explorer's TOML export (the button *export TOML config*), which the command reads."""

PARTS = ("joint_title", "joint_table", "joint", "chain_title", "chain")
"""The parts of :func:`~spinectl.explore.numbers.design_rows` shown under the headline, in the command's order."""

SEARCH_WORDS = "and every diagonal PD reflex"
"""The explorer's choice under its design button that adds ``--gains search``, as the panel names it."""

NOTE_STYLE = "margin-left:1.5em"
"""A note on the line above it (two spaces in the command's table) is indented under it, as the command does."""


def design_command(state: ExploreState, search: bool = False) -> str:
    """The command that gives the same design on the command line, for the state's TOML export.

    Parameters
    ----------
    state : ExploreState
    search : bool
        With ``--gains search``, as the explorer's choice :data:`SEARCH_WORDS`.

    Returns
    -------
    str
        ``spinectl design --config spinectl-explore.toml --E ... --Lambda ...`` (E and Lambda [m], as
        ``--E`` and ``--Lambda`` take them; every other value of the state is in the file,
        :func:`spinectl.explore.state.state_toml`).
    """
    command = f"spinectl design --config {TOML_NAME} --E {state.eccentricity!r} --Lambda {state.lordosis!r}"
    return command + (" --gains search" if search else "")


def design_html(answer: Design, state: ExploreState, current: bool) -> str:
    """The design answer as HTML: each line of :func:`~spinectl.explore.numbers.design_rows` in its own element.

    Parameters
    ----------
    answer : Design
        An answer of :func:`spinectl.explore.numbers.design_numbers`.
    state : ExploreState
        The state the answer is for (its command line, :func:`design_command`).
    current : bool
        Whether the answer is for the sliders' state; if not, it says so.

    Returns
    -------
    str
        Each line in an element whose ``data-design`` is its part (``header``, ``headline``, ``joint_title``,
        ``joint_table``, ``joint``, ``chain_title``, ``chain``, ``command``); the segments' table in a ``<pre>``,
        whose text is its lines joined by newlines; every other line a ``<div>``, a note indented under the line
        above it.
    """
    rows = {key: [(html.escape(line), note) for line, note in lines] for key, lines in design_rows(answer).items()}
    stale = "" if current else " <b>(the sliders have moved since: press again)</b>"
    parts = [
        f'<p><b>design for this delay</b> (<span data-design="header">{rows["header"][0][0]}</span>): '
        f'<span data-design="headline">{rows["headline"][0][0]}</span>{stale}</p>'
    ]
    for key in PARTS:
        if key.endswith("_title"):
            parts += [f'<p><b data-design="{key}">{line}</b></p>' for line, _ in rows[key]]
        elif key == "joint_table":
            parts.append(f'<pre data-design="{key}">' + "\n".join(line for line, _ in rows[key]) + "</pre>")
        else:
            parts += [
                f'<div data-design="{key}"' + (f' style="{NOTE_STYLE}"' if note else "") + f">{line}</div>"
                for line, note in rows[key]
            ]
    command = html.escape(design_command(state, answer.searched is not None))
    parts.append(
        "<p>the options named above are those of spinectl design (--gains search is also the choice "
        f"<i>{html.escape(SEARCH_WORDS)}</i> under the button): <b>export TOML config</b>, then "
        f'<code data-design="command">{command}</code> prints this answer</p>'
    )
    return '<div class="spinectl-design">' + "".join(parts) + "</div>"
