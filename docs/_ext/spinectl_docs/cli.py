"""The command-line reference of ``docs/cli.md``, from the argparse parser of :mod:`spinectl.cli`."""

from __future__ import annotations

import argparse

from spinectl.cli import build_parser

from .markup import md_escape

WIDTH = 80
"""Width of the usage lines, fixed so that the page does not depend on the terminal."""

NO_DEFAULT = (argparse._HelpAction, argparse._VersionAction, argparse._StoreTrueAction, argparse._StoreFalseAction)


def _formatter(parser: argparse.ArgumentParser) -> argparse.HelpFormatter:
    return argparse.HelpFormatter(parser.prog, width=WIDTH)


def usage(parser: argparse.ArgumentParser) -> str:
    """The usage line(s) of ``parser``, as ``spinectl ... --help`` prints them."""
    formatter = _formatter(parser)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups)
    return formatter.format_help().strip()


def _default(action: argparse.Action) -> str:
    if action.required:
        return "required"
    if isinstance(action, NO_DEFAULT) or action.default in (None, argparse.SUPPRESS):
        return ""
    return md_escape(action.default)


def _subcommands(parser: argparse.ArgumentParser):
    """(name, help, parser) of each sub-command, aliases once."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help for choice in action._choices_actions}
            seen = set()
            for name, sub in action.choices.items():
                if id(sub) not in seen:
                    seen.add(id(sub))
                    yield name, helps.get(name), sub


def option_tables(parser: argparse.ArgumentParser) -> list[str]:
    """One table per argument group ("options", "model", ...), without ``-h`` and sub-commands."""
    formatter = _formatter(parser)
    lines = []
    for group in parser._action_groups:
        actions = [
            a
            for a in group._group_actions
            if a.help != argparse.SUPPRESS and not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))
        ]
        if not actions:
            continue
        lines += [f"*{md_escape(group.title)}*", "", "| argument | default | description |", "| --- | --- | --- |"]
        for a in actions:
            invocation = formatter._format_action_invocation(a)
            help_text = md_escape(formatter._expand_help(a)) if a.help else ""
            lines.append(f"| `{invocation}` | {_default(a)} | {help_text} |")
        lines.append("")
    return lines


def command(parser: argparse.ArgumentParser, summary: str | None, depth: int) -> list[str]:
    """The section of one (sub-)command and, below it, of each of its sub-commands."""
    lines = [f"{'#' * min(depth, 6)} `{parser.prog}`", ""]
    text = parser.description or summary
    if text:
        lines += [md_escape(text), ""]
    lines += ["```text", usage(parser), "```", ""]
    lines += option_tables(parser)
    subs = list(_subcommands(parser))
    if subs:
        lines += ["| command | summary |", "| --- | --- |"]
        lines += [f"| `{sub.prog}` | {md_escape(help_text or '')} |" for _, help_text, sub in subs]
        lines.append("")
    if parser.epilog:
        lines += [md_escape(parser.epilog), ""]
    for _, help_text, sub in subs:
        lines += command(sub, help_text, depth + 1)
    return lines


def markdown(parser: argparse.ArgumentParser | None = None) -> str:
    """The whole command tree of ``parser`` (default: :func:`spinectl.cli.build_parser`) as MyST Markdown."""
    return "\n".join(command(parser or build_parser(), None, 2))
