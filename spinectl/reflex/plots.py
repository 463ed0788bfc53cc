"""Bode and Nyquist plots of the reflex loops and the simulated time responses.

python-control draws the frequency plots (``bode_plot``, ``nyquist_plot``); every
file is written atomically (:func:`spinectl.atomic.atomic_path`) with matplotlib's Agg
backend, so nothing needs a display.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import control as ct
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 - after selecting the backend

from ..atomic import atomic_path  # noqa: E402
from .loops import ignoring_underflow  # noqa: E402
from .simulate import Simulation  # noqa: E402


def _save(figure, path: Path) -> Path:
    with atomic_path(path) as tmp:
        figure.savefig(tmp, format="png", dpi=110)
    plt.close(figure)
    return Path(path)


def bode(loops: Mapping[str, ct.TransferFunction], path, omega_limits=None, title: str = "") -> Path:
    """Bode plot of the loop transfer functions L(s) = C(s) Pade(s) G(s), one curve per segment.

    Parameters
    ----------
    loops : mapping of str to TransferFunction
        Segment name -> loop (:func:`spinectl.reflex.loops.loop_transfer`).
    path : str or Path
        PNG to write.
    omega_limits : (float, float), optional
        Frequency range [rad/s]; python-control's default otherwise.
    title : str, optional
        Figure title.
    """
    with ignoring_underflow():
        plot = ct.bode_plot(
            list(loops.values()), omega_limits=omega_limits, label=list(loops), title=title or "Reflex loop L(jw)"
        )
    return _save(plot.figure, path)


def nyquist(loops: Mapping[str, ct.TransferFunction], path, title: str = "") -> Path:
    """Nyquist plot of the loops; an open-loop unstable segment must circle -1 once counter-clockwise.

    Parameters
    ----------
    loops : mapping of str to TransferFunction
        Segment name -> loop.
    path : str or Path
        PNG to write.
    title : str, optional
        Figure title.
    """
    with ignoring_underflow():
        plot = ct.nyquist_plot(list(loops.values()), label=list(loops), title=title or "Nyquist plot of L(jw)")
    return _save(plot.figure, path)


def time_response(responses: Mapping[str, Simulation], path, title: str = "") -> Path:
    """Angle after the perturbation, with the reflex (run 0) and without it (run 1), per segment.

    Each panel is scaled to the response with the reflex; a response without it that
    diverges leaves the panel (the simulation stops at ``sim_divergence``).

    Parameters
    ----------
    responses : mapping of str to Simulation
        Segment name -> a batch of two runs (:func:`spinectl.reflex.simulate.simulate`).
    path : str or Path
        PNG to write.
    title : str, optional
        Figure title.
    """
    fig, axes = plt.subplots(len(responses), 1, sharex=True, figsize=(7, 1.6 * len(responses) + 1), squeeze=False)
    for ax, (name, sim) in zip(axes[:, 0], responses.items(), strict=True):
        scale = 1e3  # mrad
        verdict = ["stable" if s else "unstable" for s in sim.stable]
        ax.plot(sim.time, sim.alpha[0] * scale, label=f"reflex, tau = {sim.delay[0]:g} s ({verdict[0]})")
        ax.plot(sim.time, sim.alpha[1] * scale, "--", label=f"no reflex ({verdict[1]})")
        top = 1.3 * abs(sim.alpha[0]).max() * scale
        ax.set_ylim(-top, top)
        ax.set_ylabel(f"{name}\nalpha [mrad]")
        ax.legend(loc="upper right", fontsize="small")
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(title or "Response to a perturbation (nonlinear segment, true delay)")
    fig.tight_layout()
    return _save(fig, path)
