"""``spinectl anatomy --optimise``: the remedy's command names the model analysed; ``mapped`` needs a mapped value."""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest

from spinectl.cli import main

pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

BUILT_IN = Path(__file__).resolve().parents[2] / "spinectl" / "anatomy" / "mappings" / "myotorso.toml"


def _remedy(out: str) -> str:
    return next(line for line in out.splitlines() if line.startswith("remedy: "))


def test_the_remedys_command_names_the_model_and_mapping_and_runs_feasible(tmp_path, capsys):
    """MyoTorso from a mapping file of its own (the built-in one, copied into tmp_path) at mu = 2: the remedy's
    command names the model, ``--mapping`` and ``--margin 2`` (before: ``spinectl anatomy --optimise
    --joint-stiffness 41.3``, which would analyse the built-in model at mu = 1); run as suggested, the optimum
    is feasible (its row says no 'infeasible')."""
    mapping = tmp_path / "my torso.toml"  # a space: the command is quoted for a shell
    mapping.write_text(BUILT_IN.read_text())
    assert main(["anatomy", "myotorso", "--mapping", str(mapping), "--optimise", "--margin", "2"]) == 0
    line = _remedy(capsys.readouterr().out)
    command = shlex.split(line.split("at each chain joint: ", 1)[1])
    assert command[:5] == ["spinectl", "anatomy", "myotorso", "--mapping", str(mapping)]
    assert command[5:9] == ["--margin", "2", "--optimise", "--joint-stiffness"]
    assert main(command[1:]) == 0
    optimum = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("optimum ("))
    assert "infeasible" not in optimum


def test_the_python_api_says_where_the_model_goes():
    """Without a command line the remedy's command has the placeholders MODEL and MAPPING, not a bare command that
    would run on MyoTorso."""
    from spinectl.anatomy.remedy import remedy_text

    assert "spinectl anatomy MODEL --mapping MAPPING --optimise --joint-stiffness 40" in remedy_text(39.95)


@pytest.mark.parametrize("section", ["", '[joint_stiffness]\nsource = "a paper"\n'])
def test_mapped_stiffness_without_a_mapped_value_is_refused(tmp_path, capsys, section):
    """A mapping without [joint_stiffness] (and, the variant, one whose section gives only its source):
    ``--joint-stiffness mapped`` is refused in one line naming the file and the key (before: 0 N m/rad added
    without a word)."""
    text = "".join(line + "\n" for line in BUILT_IN.read_text().splitlines() if not _stiffness_line(line))
    mapping = tmp_path / "bare.toml"
    mapping.write_text(text + section)
    assert main(["anatomy", "myotorso", "--mapping", str(mapping), "--joint-stiffness", "mapped"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("spinectl: error: ")
    assert "bare.toml: joint_stiffness.Nm_per_rad: is missing" in err  # the path shortened at its start
    assert main(["anatomy", "myotorso", "--mapping", str(mapping), "--joint-stiffness", "5"]) == 0  # a number is fine


def _stiffness_line(line: str) -> bool:
    """The built-in mapping's [joint_stiffness] section and its keys."""
    return line.startswith("[joint_stiffness]") or line.split("=")[0].strip() in ("Nm_per_rad", "source")
