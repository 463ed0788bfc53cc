"""README.md's examples run: every ```python block, and the spinectl commands of its ```bash blocks.

A command that takes minutes, or a local Dask cluster, is listed in SLOW with the test that runs it
instead; a new command in the README must be either run here or listed there.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from spinectl.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"
ROOT = README.parent

SLOW = {
    "reproduce": "the paper's 81 x 81 study; tests/cli/test_reproduce_cmd.py and test_consistency.py run it coarse",
    "study": "starts a local Dask cluster; tests/suites/test_examples.py runs examples/study.toml in-process",
    "calibrate": "3-4 minutes; tests/paper/test_calibration.py runs a short fit",
    "explore": "serves until interrupted; tests/explore/test_browser.py serves it and drives it in Chromium",
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
