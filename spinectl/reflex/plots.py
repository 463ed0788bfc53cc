"""Bode and Nyquist plots of the reflex loops and the simulated time responses.

Compute, draw and save are separate steps, as python-control's ``*_response`` and
``*_plot``: :func:`spinectl.reflex.margins.report_responses` computes the loops and
the simulations of a report, the figure functions (:func:`bode_figure`,
:func:`nyquist_figure`, :func:`response_figure`, :func:`report_figures`) draw them on
new figures with the Agg canvas (:func:`spinectl.canvas.new_figure`; python-control's
``bode_plot`` and ``nyquist_plot`` draw on their axes) and return them, writing
nothing, and :func:`save_figure` writes one atomically. :func:`write_plots` does all
three for ``spinectl margins --plot``. No backend is selected and pyplot keeps no
figure: nothing needs a display.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import control as ct
import matplotlib
import numpy as np
from matplotlib.figure import Figure

from ..canvas import new_figure, save_png, save_pngs
from ..model.params import Model
from .loops import ignoring_underflow
from .margins import MarginsReport, ReportResponses, report_responses
from .simulate import Simulation

DPI = 110
"""Resolution of the PNG files [dots per inch]."""

PLOT_FILES = ("bode.png", "nyquist.png", "response.png")
"""The files :func:`write_plots` may write, in this order."""


def _control_figure(rows: int, **subplots):
    """A figure with ``rows`` x 1 axes styled as python-control styles its own (its rcParams, tight layout)."""
    fig = new_figure()
    with matplotlib.rc_context(ct.rcParams):
        axes = fig.subplots(rows, 1, squeeze=False, **subplots)
    fig.set_layout_engine("tight")
    return fig, axes


def bode_figure(loops: Mapping[str, ct.TransferFunction], omega_limits=None, title: str = "") -> Figure:
    """Bode plot of the loop transfer functions L(s) = C(s) Pade(s) G(s), one curve per segment.

    Parameters
    ----------
    loops : mapping of str to TransferFunction
        Segment name -> loop (:func:`spinectl.reflex.loops.loop_transfer`).
    omega_limits : (float, float), optional
        Frequency range [rad/s]; python-control's default otherwise.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Magnitude above phase; nothing is written.
    """
    fig, axes = _control_figure(2, sharex=True)
    with ignoring_underflow():
        plot = ct.bode_plot(list(loops.values()), omega_limits=omega_limits, label=list(loops), ax=axes)
    plot.set_plot_title(title or "Reflex loop L(jw)", frame="figure")
    fig.align_labels()
    return fig


def nyquist_figure(loops: Mapping[str, ct.TransferFunction], title: str = "") -> Figure:
    """Nyquist plot of the loops; an open-loop unstable segment must circle -1 once counter-clockwise.

    Parameters
    ----------
    loops : mapping of str to TransferFunction
        Segment name -> loop.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        One axes with every loop; nothing is written.
    """
    fig, axes = _control_figure(1)
    with ignoring_underflow():
        plot = ct.nyquist_plot(list(loops.values()), label=list(loops), ax=axes)
    plot.set_plot_title(title or "Nyquist plot of L(jw)", frame="figure")
    return fig


def response_figure(responses: Mapping[str, Simulation], title: str = "") -> Figure:
    """Angle after the perturbation, with the reflex (run 0) and without it (run 1), per segment.

    Each panel is scaled to the response with the reflex; a response without it that
    diverges leaves the panel (the simulation stops at ``sim_divergence``).

    Parameters
    ----------
    responses : mapping of str to Simulation
        Segment name -> a batch of two runs (:func:`spinectl.reflex.simulate.simulate`).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per segment; nothing is written.
    """
    fig = new_figure(figsize=(7, 1.6 * len(responses) + 1))
    axes = fig.subplots(len(responses), 1, sharex=True, squeeze=False)
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
    return fig


def frequency_range(report: MarginsReport) -> tuple[float, float]:
    """A decade below the slowest and above the fastest rate of the loops [rad/s].

    The rates: each segment's sqrt(abs(S)/theta), abs(D)/theta and crossover, and
    order/tau, beyond which the Padé phase saturates.

    Parameters
    ----------
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.analyse`.

    Returns
    -------
    (float, float)
        Lowest and highest frequency [rad/s]; (0.1, 10) if no rate is finite and positive.
    """
    rates = [report.pade_order / report.delay] if report.delay > 0 else []
    for s in report.segments:
        rates += [np.sqrt(abs(s.stiffness) / s.inertia), abs(s.damping) / s.inertia, s.crossover_rad_s]
    rates = [r for r in rates if np.isfinite(r) and r > 0] or [1.0]
    return min(rates) / 10, max(rates) * 10


def report_figures(report: MarginsReport, responses: ReportResponses) -> dict[str, Figure]:
    """The Bode, Nyquist and time-response figures of a report, by file name; nothing is written.

    Bode and Nyquist only if some segment has a loop, the time response only if some
    segment was simulated (see :func:`spinectl.reflex.margins.report_responses`).

    Parameters
    ----------
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.analyse` (titles, frequency range).
    responses : ReportResponses
        Its loops and simulations.

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        A subset of :data:`PLOT_FILES` -> figure, in that order.
    """
    point = report.point
    where = (
        f"E = {point.eccentricity * 100:g} cm, Lambda = {point.lordosis * 100:g} cm, activation {point.activation:g}"
    )
    figures = {}
    if responses.loops:
        title = f"Reflex loops, Pade {report.pade_order}; {where}"
        figures["bode.png"] = bode_figure(responses.loops, frequency_range(report), title)
        figures["nyquist.png"] = nyquist_figure(responses.loops, f"Nyquist, tau = {report.delay:g} s; {where}")
    if responses.simulations:
        figures["response.png"] = response_figure(responses.simulations, f"Response to a perturbation; {where}")
    return figures


def save_figure(fig: Figure, path: str | Path) -> Path:
    """The save step: :func:`spinectl.canvas.save_png` at this module's :data:`DPI`.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure of this module.
    path : str or Path
        The PNG file, written atomically.

    Returns
    -------
    Path
        ``path``.
    """
    return save_png(fig, path, DPI)


def write_plots(report: MarginsReport, folder: str | Path, model: Model) -> list[Path]:
    """Compute, draw and save the plots of a report: ``spinectl margins --plot``.

    response.png of every segment with a finite stiffness; bode.png and nyquist.png of
    every non-zero reflex loop. Everything is computed and drawn before the first file
    is written, so a failure (e.g. a delay too short to simulate) writes nothing; the
    files then replace the old ones together (:func:`spinectl.canvas.save_pngs`), and a
    plot of an earlier run that this one does not draw goes with them: the folder never
    shows a Bode plot of one configuration beside the response of another.

    Parameters
    ----------
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.analyse` for ``model``.
    folder : str or Path
        Folder for the PNG files (created if missing).
    model : Model
        The model of the report (geometry and simulation settings).

    Returns
    -------
    list of Path
        The files written, in the order of :data:`PLOT_FILES`; those with nothing to draw are left out.

    Raises
    ------
    ParameterError
        The simulation cannot run at the report's delay.
    OutputError
        A file cannot be written (nothing is written then).
    """
    return save_pngs(report_figures(report, report_responses(model, report)), folder, DPI, replaces=PLOT_FILES)
