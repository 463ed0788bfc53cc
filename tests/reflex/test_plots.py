"""Bode, Nyquist and time-response plots: written atomically as PNG files."""

from __future__ import annotations

import warnings

import numpy as np

from spinectl.model.params import Reflex
from spinectl.reflex import loops, plots, simulate

PNG = b"\x89PNG\r\n\x1a\n"


def test_plots_are_pngs_and_leave_no_temporaries(tmp_path, model):
    transfer = {"L3L4": loops.loop_transfer(50.0, -15.0, 2.6, 75.0, 1.3, 0.1, 5)}
    plant = simulate.segment_plant(model, 0.03, 0.04, 2, np.array([15, 15, 0, 0, 0.2, 0.2]) * 1e-4)
    runs = {"L3L4": simulate.simulate(plant, [75.0, 0.0], [1.3, 0.0], 0.1, Reflex(sim_duration=0.3))}
    written = [
        plots.bode(transfer, tmp_path / "bode.png", omega_limits=(0.1, 100.0)),
        plots.nyquist(transfer, tmp_path / "nyquist.png"),
        plots.time_response(runs, tmp_path / "response.png"),
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bode.png", "nyquist.png", "response.png"]
    assert all(p.read_bytes()[:8] == PNG for p in written)


def test_frequency_plots_of_subnormal_coefficients_are_silent(tmp_path):
    """python-control evaluates L(jw) under np.errstate(all="warn"); a subnormal damping
    (activation 1e-308 in ``spinectl margins --plot``) printed underflow warnings."""
    transfer = {"L1L2": loops.loop_transfer(71.0, -1.1e-308, 1.31, 106.5, 13.6, 0.0, 5)}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plots.bode(transfer, tmp_path / "bode.png")
        plots.nyquist(transfer, tmp_path / "nyquist.png")
    assert (tmp_path / "bode.png").read_bytes()[:8] == PNG
