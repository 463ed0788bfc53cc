"""``spinectl atlas``: JSON keys, one-line errors with exit code 2."""

from __future__ import annotations

import json

import pytest

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
    assert set(doc["probabilities"]["stabilisable_joint_by_joint"]) == {"p", "low", "high"}
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


def test_json_names_the_default_preset(tmp_path, capsys):
    """No --preset, --config or model key: the atlas starts from DEFAULT_PRESET, named as every command names it."""
    from spinectl import DEFAULT_PRESET

    assert main(["atlas", str(_file(tmp_path)), "--out", str(tmp_path / "out"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["preset"] == DEFAULT_PRESET and doc["config"] is None and doc["overridden"] == []
    saved = json.loads((tmp_path / "out" / "atlas.json").read_text())
    assert saved["preset"] == DEFAULT_PRESET
    assert f"preset {DEFAULT_PRESET}" in (tmp_path / "out" / "report.md").read_text()


def test_preset_and_set_reach_the_atlas(tmp_path, capsys):
    """--preset default and --set are named in the JSON and the table's first line."""
    args = ["atlas", str(_file(tmp_path)), "--out", str(tmp_path / "out"), "--preset", "default"]
    assert main([*args, "--set", "passive.stiffness=15"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("preset default, K = 15 N m/rad") and "overridden: passive.stiffness" in first


def test_preset_default_and_the_default_differ_as_stability_says(tmp_path, capsys):
    """--preset default vs the default preset: the atlas's min PCSA at a drawn point equals `spinectl stability` there.

    Second reading: `spinectl stability --E --Lambda --mass` with the same preset at the first draw; the two
    presets (40 kg and 24 kg upper body, different muscle geometry) give different minima.
    """
    import numpy as np

    found = {}
    for preset in ("default", None):
        out = tmp_path / f"out-{preset}"
        extra = ["--preset", preset] if preset else []
        assert main(["atlas", str(_file(tmp_path)), "--out", str(out), "--json", *extra]) == 0
        capsys.readouterr()
        with np.load(out / "draws.npz") as draws:
            e, lam, mass, pcsa = (
                float(draws[k][0]) for k in ("eccentricity_m", "lordosis_m", "body.mass", "min_pcsa_cm2")
            )
        point = ["stability", "--E", str(e), "--Lambda", str(lam), "--set", f"body.mass={mass!r}", "--json", *extra]
        assert main(point) == 0
        reading = json.loads(capsys.readouterr().out)
        found[preset] = pcsa
        assert pcsa == pytest.approx(reading["min_pcsa_cm2"], rel=1e-6)
    assert found["default"] != pytest.approx(found[None], rel=1e-3)


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (["--scheduler", "ftp://127.0.0.1:8786"], "scheduler: must be 'synchronous' or a dask.distributed address"),
        (["--scheduler", "synchronous", "--workers", "2"], "workers: sets the size of the local cluster"),
        (["--scheduler", "tcp://127.0.0.1:0"], "scheduler: must be tcp://HOST:PORT with a host and a port"),
        (["--workers", "0"], "--workers must be >= 1"),
    ],
)
def test_bad_scheduler_options_are_one_line_exit_2(tmp_path, capsys, options, words):
    """--scheduler and --workers as `spinectl study` checks them: one line, exit 2, before --out is made."""
    code = main(["atlas", str(_file(tmp_path)), "--out", str(tmp_path / "out"), *options])
    err = capsys.readouterr().err
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_two_local_workers_give_the_synchronous_json(tmp_path, capsys):
    """`--workers 2` (a local Dask cluster; two chunks of 3 draws) prints the JSON of `--scheduler synchronous`."""
    path = _file(tmp_path)
    path.write_text(path.read_text().replace("chain = false", "chain = false\nchunk_size = 3"))
    docs = []
    for options in (["--scheduler", "synchronous"], ["--workers", "2"]):
        assert main(["atlas", str(path), "--out", str(tmp_path / options[0]), "--json", *options]) == 0
        docs.append(json.loads(capsys.readouterr().out))
    assert docs[0] == docs[1] and len(list((tmp_path / "--workers" / "chunks").iterdir())) == 2


@pytest.mark.parametrize("where", ["priors", "config", "chunk"])
def test_an_out_that_would_overwrite_an_input_is_refused(tmp_path, capsys, where):
    """The atlas file saved as DIR/report.md, a --config saved as DIR/atlas.json, or either as a chunk of DIR:
    exit 2, one line naming the input, the input unchanged (it was overwritten, exit 0)."""
    out = tmp_path / "d"
    (out / "chunks").mkdir(parents=True)
    priors = _file(tmp_path).read_text()
    config = 'preset = "default"\n'
    victim = {"priors": out / "report.md", "config": out / "atlas.json", "chunk": out / "chunks" / "c.npz"}[where]
    victim.write_text(config if where == "config" else priors)
    argv = ["atlas", str(victim if where != "config" else _file(tmp_path)), "--out", str(out)]
    argv += ["--config", str(victim)] if where == "config" else []
    before = victim.read_text()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "is the same file as" in err and "\n" not in err
    assert victim.read_text() == before


def test_a_cut_chunk_is_one_line_on_stderr_and_solved_again(tmp_path, capsys):
    """A chunk file cut short after a run: the next run says so in one line on stderr, solves it again and
    prints the first run's JSON, exit 0 (it was a BadZipFile traceback)."""
    argv = ["atlas", str(_file(tmp_path)), "--out", str(tmp_path / "out"), "--json"]
    assert main(argv) == 0
    first = json.loads(capsys.readouterr().out)
    (chunk,) = (tmp_path / "out" / "chunks").iterdir()
    chunk.write_bytes(chunk.read_bytes()[:-40])
    assert main(argv) == 0
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.startswith("atlas:")]
    assert len(lines) == 1 and "cannot be read (cut short" in lines[0] and "computing them again" in lines[0]
    assert json.loads(captured.out) == first


def test_the_help_says_the_atlas_runs_in_process_without_workers(capsys):
    """The atlas's --help said "--workers N ... (default: cores)", a local cluster, while the atlas runs in this
    process without --workers (run_atlas: no scheduler and no workers is 'synchronous'); study's is one per core."""
    import re

    for command, default in (("atlas", "none: the draws run in this process"), ("study", "one per core")):
        assert main([command, "--help"]) == 0
        text = re.sub(r"\s+", " ", capsys.readouterr().out)
        assert f"--workers N local worker processes (default: {default}" in text and "(default: cores)" not in text
