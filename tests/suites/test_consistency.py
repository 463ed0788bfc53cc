"""One model behind every command: stability, margins, sweep and reproduce, each with no model option,
report the same preset and the same minimum PCSA and ||CT|| at the same point (docs/model.md,
"The default model").

The point (E, Lambda) = (4 cm, 4 cm) lies on reproduce's 5 x 5 grid (0 to 8 cm in 2 cm steps). The
sweep and reproduce solve it on the fast path, stability on the per-point reference; the two paths
agree to 1e-6 (docs/optimisation.md), so the numbers are compared to 1e-5.
"""

from __future__ import annotations

import json

import pytest

from spinectl.cli import main
from spinectl.landscape import netcdf
from spinectl.model import config

E, LAMBDA = 0.04, 0.04
POINT = ["--E", str(E), "--Lambda", str(LAMBDA)]


def _json(argv, capsys) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_every_command_reports_the_same_model_and_numbers(tmp_path, capsys):
    stability = _json(["stability", *POINT, "--json"], capsys)
    margins = _json(["margins", *POINT, "--json"], capsys)
    assert main(["sweep", "--E", str(E), "--Lambda", str(LAMBDA), "--out", str(tmp_path / "one.nc")]) == 0
    swept = netcdf.load(tmp_path / "one.nc").sel(E=E, Lambda=LAMBDA)
    assert main(["reproduce", "--points", "5", "--out", str(tmp_path / "results")]) == 0
    reproduced = netcdf.load(tmp_path / "results" / "landscapes.nc").sel(K=0.0, E=E, Lambda=LAMBDA)
    report = (tmp_path / "results" / "report.md").read_text(encoding="utf-8")
    capsys.readouterr()

    preset = config.DEFAULT_PRESET
    assert stability["preset"] == margins["preset"] == swept.attrs["preset"] == preset
    assert netcdf.load(tmp_path / "results" / "landscapes.nc").attrs["preset"] == preset
    assert f"Parameters: preset {preset}; K = 0 and K = 15 N m/rad" in report  # both stiffnesses of the run
    assert stability["K_Nm_per_rad"] == margins["K_Nm_per_rad"] == 0.0  # reproduce's K = 0 is the preset's K

    min_pcsa, torque = stability["min_pcsa_cm2"], stability["counter_torque_norm_Nm"]
    assert float(swept["min_pcsa_cm2"]) == pytest.approx(min_pcsa, rel=1e-5)
    assert float(reproduced["min_pcsa_cm2"]) == pytest.approx(min_pcsa, rel=1e-5)
    assert float(swept["counter_torque_norm_Nm"]) == pytest.approx(torque, rel=1e-5, abs=1e-6)
    assert float(reproduced["counter_torque_norm_Nm"]) == pytest.approx(torque, rel=1e-5, abs=1e-6)
    # margins runs at a fraction of the chosen activation (reflex.activation): its PCSA over that
    # fraction is the chosen activation, whose total stability reports
    activation = margins["activation"]
    assert sum(margins["pcsa_cm2"].values()) / activation == pytest.approx(stability["chosen_pcsa_total_cm2"], rel=1e-6)
