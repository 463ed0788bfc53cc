"""README.md's examples run: every ```python block, the spinectl commands of its ```bash blocks, and the code
named inline in its prose (```spinectl.paper.reproduce("results")```, ```spinectl config show```), as written.

A command that takes minutes, or a local Dask cluster, is listed in SLOW with the test that runs it
instead; a new command in the README must be either run here or listed there.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from spinectl.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"
ROOT = README.parent

SLOW = {
    "reproduce": "the paper's 81 x 81 study; tests/cli/test_reproduce_cmd.py and test_consistency.py run it coarse",
    "study": "starts a local Dask cluster; tests/suites/test_examples.py runs examples/study.toml in-process",
    "calibrate": "about a minute; tests/paper/test_calibration.py runs a short fit",
    "explore": "serves until interrupted; tests/explore/test_browser.py serves it and drives it in Chromium",
    "design": "tens of seconds for the chain's certified design; tests/cli/test_design_cmd.py runs it",
    "atlas": "thousands of model evaluations; tests/cli/test_atlas_cmd.py runs a small prior file",
}
"""README commands not run here (too long, or a server), and where they are tested."""

COARSE = ("0:0.08:81", "0:0.08:5")
"""Sweeps run on 5 x 5 points instead of the paper's 81 x 81: the same command, seconds instead of a minute."""


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def _commands() -> list[list[str]]:
    """The ``spinectl ...`` lines of the bash blocks, comments removed, as argument lists."""
    commands = []
    for block in _blocks("bash"):
        for line in block.splitlines():
            for part in line.split("&&"):
                words = shlex.split(part, comments=True)
                if words[:1] == ["spinectl"]:
                    commands.append(words[1:])
    return commands


def test_the_readme_has_examples():
    assert len(_blocks("python")) >= 2 and len(_commands()) >= 10


def test_every_python_block_runs(tmp_path, monkeypatch):
    """The blocks run in order in one namespace (the second uses the first's ``model``), in an empty folder."""
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in _blocks("python"):
        exec(compile(block, str(README), "exec"), namespace)
    assert namespace["result"].all_self_stable in (True, False)
    assert namespace["landscape"].sizes["E"] == 81


def _is_slow(argv: list[str]) -> bool:
    return argv[0] in SLOW or "study.zarr" in argv  # plotting the study's store needs the study


@pytest.mark.parametrize("argv", [a for a in _commands() if not _is_slow(a)], ids=shlex.join)
def test_every_quick_command_runs(argv, tmp_path, monkeypatch, capsys):
    """Each quick command exits 0, in a folder holding the files the earlier commands wrote (and examples/)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    for earlier in _commands():  # the inputs a command reads: the sweeps before it
        if earlier == argv:
            break
        if earlier[0] == "sweep":
            assert main([w.replace(*COARSE) for w in earlier]) == 0
    assert main([w.replace(*COARSE) for w in argv]) == 0, capsys.readouterr().err


def test_every_slow_command_is_known():
    """A README command is either run above or listed in SLOW with the test that covers it."""
    assert {a[0] for a in _commands() if _is_slow(a)} <= set(SLOW) | {"plot"}


def _inline() -> list[str]:
    """The inline code spans of the prose (outside fenced blocks), in order, each once."""
    prose = re.sub(r"```.*?```", "", README.read_text(encoding="utf-8"), flags=re.S)
    return list(dict.fromkeys(re.findall(r"`([^`\n]+)`", prose)))


def _inline_api() -> list[str]:
    """The inline Python expressions of the API: ``spinectl.NAME...``, with or without a call."""
    return [span for span in _inline() if re.fullmatch(r"spinectl(\.\w+)+(\(.*\))?", span)]


def test_the_readme_names_the_api_inline():
    assert {"spinectl.DEFAULT_PRESET", 'spinectl.paper.reproduce("results")'} <= set(_inline_api())


def test_every_inline_api_name_runs_after_import_spinectl(tmp_path):
    """Each inline ``spinectl.x.y(...)`` of the prose is evaluated as written after a bare ``import spinectl``, in a
    fresh interpreter (this one has imported every subpackage already, which would hide a missing lazy import),
    in an empty folder; a call returns what it says (``reproduce`` the files it wrote, which exist)."""
    probe = (
        "import json, sys, spinectl\n"
        "out = {}\n"
        "for span in json.loads(sys.argv[1]):\n"
        "    value = eval(span, {'spinectl': spinectl})\n"
        "    out[span] = [str(v) for v in value] if isinstance(value, list) else repr(value)\n"
        "print(json.dumps(out))\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    done = subprocess.run(
        [sys.executable, "-c", probe, json.dumps(_inline_api())], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    values = json.loads(done.stdout)
    written = values['spinectl.paper.reproduce("results")']
    assert "results/report.md" in written and all((tmp_path / path).is_file() for path in written)


def _inline_commands() -> list[list[str]]:
    """The inline ``spinectl ...`` commands of the prose that take arguments (a bare name like ``spinectl margins``
    names the command and is run by the blocks above)."""
    commands = [shlex.split(span)[1:] for span in _inline() if span.startswith("spinectl ")]
    return [argv for argv in commands if len(argv) > 1]


def test_the_readme_has_inline_commands():
    assert ["config", "show"] in _inline_commands()


@pytest.mark.parametrize("argv", [a for a in _inline_commands() if not _is_slow(a)], ids=shlex.join)
def test_every_quick_inline_command_runs(argv, tmp_path, monkeypatch, capsys):
    """Each quick inline command of the prose exits 0 (the slow ones are covered as :data:`SLOW` says)."""
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 0, capsys.readouterr().err


def test_every_slow_inline_command_is_known():
    assert {a[0] for a in _inline_commands() if _is_slow(a)} <= set(SLOW)
