"""``spinectl atlas``: JSON keys, one-line errors with exit code 2."""

from __future__ import annotations

import json

from spinectl.cli import main

PRIOR = """
[[prior]]
parameter = "{parameter}"
distribution = "uniform"
bounds = [30.0, 50.0]
source = "s"
"""


def _file(tmp_path, parameter="body.mass"):
    path = tmp_path / "priors.toml"
    path.write_text("[atlas]\nsamples = 2\nchain = false\n" + PRIOR.format(parameter=parameter))
    return path


def test_json_has_the_issues_keys(tmp_path, capsys):
    """--json prints n_evaluations = N (D + 2), probabilities {p, low, high} and sobol {S1, S1_conf, ST, ST_conf}."""
    assert main(["atlas", str(_file(tmp_path)), "--out", str(tmp_path / "out"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["n_evaluations"] == 2 * (1 + 2)
    assert set(doc["probabilities"]["self_stable_joint_by_joint"]) == {"p", "low", "high"}
    assert set(doc["sobol"]["min_pcsa_cm2"]["body.mass"]) == {"S1", "S1_conf", "ST", "ST_conf"}


def test_unknown_parameter_is_one_line_exit_2(tmp_path, capsys):
    """A misspelt parameter: exit 2, one line with a 'did you mean', nothing written."""
    assert main(["atlas", str(_file(tmp_path, "body.mas")), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "did you mean 'mass'" in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_lordosis_angle_with_a_lordosis_prior_is_refused(tmp_path, capsys):
    """--lordosis-angle fixes the lordosis only where no prior varies it: else exit 2, one line."""
    path = _file(tmp_path, "lordosis_m")
    path.write_text(path.read_text().replace("[30.0, 50.0]", "[0.0, 0.05]"))
    assert main(["atlas", str(path), "--out", str(tmp_path / "o"), "--lordosis-angle", "50"]) == 2
    assert "--lordosis-angle" in capsys.readouterr().err


def test_an_out_that_is_a_file_is_one_line_exit_2(tmp_path, capsys):
    """--out naming a file: exit 2 and one line before any draw is solved (it was a traceback after them)."""
    out = tmp_path / "a_file"
    out.write_text("")
    assert main(["atlas", str(_file(tmp_path)), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "cannot write" in err and "\n" not in err
