"""The command line's aliases of ``--set`` (``--K``, ``--mass``) and its hints for options misplaced or mistyped."""

from __future__ import annotations

import argparse
import json

import pytest

from spinectl.cli import build_parser, main


def _json(argv, capsys) -> dict:
    assert main([*argv, "--json"]) == 0, capsys.readouterr().err
    document = json.loads(capsys.readouterr().out)
    document["overridden"] = sorted(document["overridden"])  # the order the fields were set in
    return document


@pytest.mark.parametrize("command", ["stability", "margins"])
def test_K_and_mass_are_the_set_of_their_fields(command, capsys):
    """``--K 15 --mass 35`` answers as ``--set passive.stiffness=15 --set body.mass=35`` does, in full (margins
    had no ``--K`` before, and no command a ``--mass``); the mass changes the answer (checked against 24 kg)."""
    where = ["--E", "0.03", "--Lambda", "0.04"]
    aliased = _json([command, *where, "--K", "15", "--mass", "35"], capsys)
    assert aliased == _json([command, *where, "--set", "passive.stiffness=15", "--set", "body.mass=35"], capsys)
    assert aliased != _json([command, *where, "--K", "15"], capsys)


def test_margins_takes_K_as_the_readme_shows(capsys):
    assert main(["margins", "--K", "15"]) == 0
    assert "passive.stiffness" in capsys.readouterr().out


def _commands() -> dict:
    action = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def test_every_command_with_K_has_mass_and_the_model_options():
    """Wherever ``--K`` is (an alias, or sweep's axis), ``--mass`` is too, beside ``--set``."""
    with_k = {name for name, parser in _commands().items() if "--K" in parser._option_string_actions}
    assert with_k >= {"stability", "margins", "sweep"}
    for name in with_k:
        assert {"--mass", "--set"} <= set(_commands()[name]._option_string_actions), name


def test_K_and_mass_refuse_a_set_of_the_same_field(capsys):
    assert main(["margins", "--mass", "35", "--set", "body.mass=30"]) == 2
    assert "--mass: sets body.mass, as does --set body.mass" in capsys.readouterr().err


def test_preset_help_says_which_preset_to_use(capsys):
    """``--preset``'s help names both presets' masses and which one is for one's own subject."""
    assert main(["stability", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "24 kg" in text and "40 kg" in text and "one's own subject" in text


@pytest.mark.parametrize(("typed", "meant"), [("--e", "--E"), ("--lambda", "--Lambda"), ("--k", "--K")])
def test_did_you_mean_prefers_the_option_that_differs_in_case(typed, meant, capsys):
    """``--e`` is ``--E`` mistyped (difflib's closest was ``--set``, one letter from ``--e`` too)."""
    assert main(["stability", typed, "0.03"]) == 2
    assert capsys.readouterr().err.strip().endswith(f"did you mean {meant}?")


def test_options_before_the_command_get_the_command_line_reordered(capsys):
    """``spinectl --set body.mass=35 stability`` read ``body.mass=35`` as the command ("invalid choice")."""
    assert main(["--set", "body.mass=35", "stability", "--E", "0.03"]) == 2
    err = capsys.readouterr().err
    assert err == "spinectl: error: options go after the command: spinectl stability --set body.mass=35 --E 0.03\n"
    assert main(["--set", "body.mass=35"]) == 2
    assert "options go after the command" in capsys.readouterr().err


def test_a_mistyped_command_still_gets_its_did_you_mean(capsys):
    assert main(["stabilty"]) == 2
    assert "did you mean stability?" in capsys.readouterr().err
