"""The files of examples/ load and run, and ``spinectl plot`` draws a study's slices or says why not."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from spinectl.cli import main
from spinectl.landscape import study
from spinectl.model import config

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_the_study_runs_and_plot_draws_its_slices(tmp_path, capsys):
    """2 masses x 2 stiffnesses: 4 slices, each drawn as minimum PCSA and ||CT|| (8 files)."""
    store = tmp_path / "study.zarr"
    argv = ["study", str(EXAMPLES / "study.toml"), "--out", str(store), "--scheduler", "synchronous"]
    assert main([*argv, "--set", "optimisation.ct_tolerance=0.002"]) == 0
    attrs = study.load(store).attrs  # the store names its model, --set included
    assert attrs["preset"] == "wagner2012" and attrs["overridden"] == "optimisation.ct_tolerance"
    assert main(["plot", str(store), "--out", str(tmp_path / "figures")]) == 0
    written = sorted(Path(line).name for line in capsys.readouterr().out.split() if line.endswith(".png"))
    assert len(written) == 8
    assert "min_pcsa_body.mass=24_K=15.png" in written and "counter_torque_body.mass=40_K=0.png" in written


def test_plot_of_a_folder_that_is_no_store_says_so(tmp_path, capsys):
    folder = tmp_path / "nothing.zarr"
    folder.mkdir()
    assert main(["plot", str(folder), "--out", str(tmp_path / "figures")]) == 2
    err = capsys.readouterr().err
    assert "is not a spinectl study store" in err and err.count("\n") == 1


def test_four_pairs_adds_a_pair_to_the_preset():
    model = config.load_config(EXAMPLES / "four_pairs.toml")
    preset = config.load_preset("wagner2012")
    assert model.pair_names == (*preset.pair_names, "deep_straight")
    assert model.muscles[:3] == preset.muscles


def test_four_pairs_runs(capsys):
    argv = ["stability", "--config", str(EXAMPLES / "four_pairs.toml"), "--E", "0.03", "--Lambda", "0.04"]
    assert main(argv) == 0
    assert "deep_straight_ventral" in capsys.readouterr().out


def test_the_coronal_plane_runs_at_e_0_and_refuses_a_sagittal_e(capsys):
    """The coronal file replaces the pairs (silently: its author's choice) and narrows E to 0."""
    path = str(EXAMPLES / "coronal.toml")
    assert main(["stability", "--config", path, "--E", "0", "--Lambda", "0.02"]) == 0
    out, err = capsys.readouterr()
    assert "lateral_straight_right" in out and "lateral_straight_left" in out and "all segments" in out
    assert "ventral" not in out and "dorsal" not in out  # geometry.side_names: right and left
    assert err == ""
    assert main(["stability", "--config", path, "--E", "0.03"]) == 2
    assert "E: must be in" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["four_pairs.toml", "coronal.toml"])
def test_config_show_of_an_example_reads_back(name, tmp_path, capsys):
    """config show's output (every pair named) loads back to the same model, without a warning (the coronal
    file replaces the preset's pairs: its author's choice, written in the file)."""
    assert main(["config", "show", "--config", str(EXAMPLES / name)]) == 0
    shown = tmp_path / "shown.toml"
    shown.write_text(capsys.readouterr().out)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert config.load_config(shown) == config.load_config(EXAMPLES / name)
    assert not caught, [str(w.message) for w in caught]
