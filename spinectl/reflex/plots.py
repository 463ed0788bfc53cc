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

import textwrap
from collections.abc import Mapping
from pathlib import Path

import control as ct
import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MultipleLocator

from ..canvas import new_figure, save_figures, save_file
from ..model.params import Model
from ..model.stability import criterion
from .delay import delay_text
from .loops import ignoring_underflow
from .margins import MarginsReport, ReportResponses, report_responses
from .simulate import Simulation

DPI = 110
"""Resolution of the PNG files [dots per inch]."""

PLOT_FILES = ("bode.png", "nyquist.png", "response.png")
"""The files :func:`write_plots` may write, in this order."""

RESPONSE_NOTE = "each panel its own time: 5 slowest time constants, at most reflex.sim_duration"
"""The response figure's note on its time axes, which differ between segments."""
BODE_SIZE = (7.0, 8.0)
"""Inches: the Bode plot with its legend below the phase axes."""
PHASE_TICKS = 180.0
"""[deg] Phase tick spacing (twice that over more than :data:`PHASE_TICKS_MAX` ticks)."""
PHASE_TICKS_MAX = 8
"""Most phase ticks at :data:`PHASE_TICKS` spacing."""


NYQUIST_KEYS = (
    ({"ls": "-"}, "solid: L(jw), w > 0, arrows in the direction of increasing w"),
    ({"ls": "--"}, "dashed: w < 0, the mirror image"),
    ({"ls": "", "marker": "+", "ms": 7, "color": "tab:red"}, "-1, the critical point: the closed loop is stable if\n"
     "the curve circles it counter-clockwise once per unstable pole of L\n(none; one for a self-unstable segment)"),
)  # fmt: skip
"""The Nyquist legend's keys, beside the segments: the line styles and the critical point."""


def _control_figure(rows: int, **subplots):
    """A figure with ``rows`` x 1 axes styled as python-control styles its own (its rcParams, tight layout)."""
    fig = new_figure()
    with matplotlib.rc_context(ct.rcParams):
        axes = fig.subplots(rows, 1, squeeze=False, **subplots)
    fig.set_layout_engine("tight")
    return fig, axes


def bode_figure(
    loops: Mapping[str, ct.TransferFunction], omega_limits=None, title: str = "", margins: Mapping | None = None
) -> Figure:
    """Bode plot of the loop transfer functions L(s) = C(s) Pade(s) A(s) G(s), one curve per segment.

    With ``margins`` each curve carries its margins: a dot where abs(L) = 1 (the crossover that
    limits the delay margin) and, below it, the phase margin as a bar from the phase curve to
    -180 deg; a triangle at abs(L) = 1/GM on the phase crossover of the upper gain margin, a thin
    line from it up to 1; and the exact delay margin tau_m, the phase margin and the upper gain
    margin in the legend, which lies below the phase axes and names the markers.

    Parameters
    ----------
    loops : mapping of str to TransferFunction
        Segment name -> loop (:func:`spinectl.reflex.loops.loop_transfer`).
    omega_limits : (float, float), optional
        Frequency range [rad/s]; python-control's default otherwise.
    title : str, optional
        Figure title.
    margins : mapping of str to SegmentMargins, optional
        Segment name -> its margins (:class:`spinectl.reflex.margins.SegmentMargins`).

    Returns
    -------
    matplotlib.figure.Figure
        Magnitude above phase; nothing is written.
    """
    margins = margins or {}
    labels = [_margin_label(name, margins.get(name)) for name in loops]
    fig, axes = _control_figure(2, sharex=True)
    with ignoring_underflow():
        plot = ct.bode_plot(list(loops.values()), omega_limits=omega_limits, label=labels, ax=axes)
    for i, name in enumerate(loops):
        if name in margins:
            _mark_margins(axes[0, 0], axes[1, 0], i, margins[name])
    _phase_ticks(axes[1, 0])
    if margins:  # the legend below the axes: on the magnitude axes it covered the curves
        fig.set_size_inches(*BODE_SIZE)
        handles, texts = axes[0, 0].get_legend_handles_labels()
        if axes[0, 0].get_legend() is not None:  # python-control's, on the magnitude axes
            axes[0, 0].get_legend().remove()
        keys = [
            Line2D([], [], ls="", marker="o", ms=4, color="0.3", label="abs(L) = 1; below it the phase margin"),
            Line2D([], [], ls="", marker="v", ms=5, color="0.3", label="phase -180 deg: abs(L) = 1/GM (gain margin)"),
        ]
        axes[1, 0].legend(
            [*handles, *keys],
            [*texts, *(k.get_label() for k in keys)],
            loc="upper center",
            bbox_to_anchor=(0.5, -0.25),
            fontsize=7,
        )
    plot.set_plot_title(title or "Reflex loop L(jw)", frame="figure")
    fig.align_labels()
    return fig


def _phase_ticks(ax) -> None:
    """Phase ticks every :data:`PHASE_TICKS` deg (twice that where too many): python-control's 90 deg ran to -990."""
    low, high = ax.get_ylim()
    step = PHASE_TICKS if (high - low) / PHASE_TICKS <= PHASE_TICKS_MAX else 2 * PHASE_TICKS
    ax.yaxis.set_major_locator(MultipleLocator(step))


def _margin_label(name: str, seg) -> str:
    """The legend entry of a segment: its name and, if known, its delay, phase and upper gain margins."""
    if seg is None or np.isnan(seg.delay_margin):
        return name
    parts = [f"tau_m {delay_text(seg.delay_margin, 3)}"]
    if np.isfinite(seg.phase_margin_deg):
        parts.append(f"PM {seg.phase_margin_deg:.0f} deg")
    if np.isfinite(seg.gain_margin):
        parts.append(f"GM {seg.gain_margin:.2f}")
    return f"{name}: " + ", ".join(parts)


def _mark_margins(magnitude_ax, phase_ax, index: int, seg) -> None:
    """Mark one curve's margins: the phase margin as a bar from the phase at the crossover (a dot on
    abs(L) = 1) to -180 deg, the upper gain margin as a bar from abs(L) to 1 at its phase crossover."""
    w, mag = magnitude_ax.get_lines()[index].get_data()
    phase = phase_ax.get_lines()[index].get_ydata()
    colour = magnitude_ax.get_lines()[index].get_color()
    w_c, pm = seg.crossover_rad_s, seg.phase_margin_deg
    if np.isfinite(w_c) and np.isfinite(pm) and w.min() <= w_c <= w.max():
        at = float(np.interp(np.log(w_c), np.log(w), phase))  # python-control's branch of the phase
        magnitude_ax.plot([w_c], [1.0], "o", color=colour, ms=4)
        phase_ax.plot([w_c, w_c], [at, at - pm], "-", color=colour, lw=3, alpha=0.6)
    if np.isfinite(seg.gain_margin):
        # the phase crossovers of the drawn curve (phase = -180 deg mod 360); the one with abs(L) = 1/GM
        wrapped = np.mod(np.asarray(phase) + 180.0, 360.0)
        jumps = np.flatnonzero(np.abs(np.diff(wrapped)) > 180.0)
        if jumps.size:
            i = jumps[np.argmin(np.abs(np.log(mag[jumps] * seg.gain_margin)))]
            # thin: the loops' phase crossovers lie close together (the delay sets them), thick bars merged
            magnitude_ax.plot([w[i], w[i]], [mag[i], 1.0], "-", color=colour, lw=0.8, gid="gain margin")
            magnitude_ax.plot([w[i]], [mag[i]], "v", color=colour, ms=5, gid="gain margin")


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
    ax = axes[0, 0]
    handles, texts = ax.get_legend_handles_labels()
    if ax.get_legend() is not None:  # python-control's names the segments alone: the line styles unexplained
        ax.get_legend().remove()
    keys = [Line2D([], [], label=text, **({"color": "0.3"} | style)) for style, text in NYQUIST_KEYS]
    fig.set_size_inches(*BODE_SIZE)
    ax.legend(
        [*handles, *keys],
        [*texts, *(k.get_label() for k in keys)],
        loc="upper center",
        bbox_to_anchor=(0.5, -0.12),
        fontsize=7,
    )
    plot.set_plot_title(title or "Nyquist plot of L(jw)", frame="figure")
    return fig


def response_figure(
    responses: Mapping[str, Simulation],
    title: str = "",
    chain: tuple | None = None,
    chain_label: str = "",
    joints=(),
    divergence: float = float("nan"),
) -> Figure:
    """Angle after the perturbation, with the reflex (run 0) and without it (run 1), per segment.

    Each panel is scaled to the response with the reflex; a response without it that
    diverges leaves the panel (the simulation stops at ``sim_divergence``). Each panel has its
    own time axis, the length of its simulation (five slowest time constants of its segment,
    :func:`spinectl.reflex.margins.response_duration`): on one shared axis the fast segments'
    curves stopped early.

    Parameters
    ----------
    responses : mapping of str to Simulation
        Segment name -> a batch of two runs (:func:`spinectl.reflex.simulate.simulate`).
    title : str, optional
        Figure title.
    chain : tuple of Simulation, optional
        The chain with its reflex and without (:attr:`spinectl.reflex.margins.ReportResponses.chain`): a last
        panel, every joint's angle, under its own criterion.
    chain_label : str, optional
        The chain's verdict at the delay, as its panel's title says it (the exact one, not the simulation's).
    joints : sequence of str, optional
        The chain's joints, in the order of its runs: the chain panel's legend names each colour.
    divergence : float, optional
        ``reflex.sim_divergence`` [rad]: where a chain run diverged, the panel says its traces stop there (the
        angles are frozen after, not a new posture).

    Returns
    -------
    matplotlib.figure.Figure
        One panel per segment, each simulated alone (joint by joint), and one for the chain; nothing is written.
    """
    rows = len(responses) + (chain is not None)
    fig = new_figure(figsize=(7, 1.6 * rows + 1.2))
    axes = fig.subplots(rows, 1, squeeze=False)
    for ax, (name, sim) in zip(axes[:, 0], responses.items(), strict=False):
        scale = 1e3  # mrad
        verdict = ["stable" if s else "unstable" for s in sim.stable]
        ax.plot(sim.time, sim.alpha[0] * scale, label=f"reflex, tau = {sim.delay[0]:g} s ({verdict[0]})")
        ax.plot(sim.time, sim.alpha[1] * scale, "--", label=f"no reflex ({verdict[1]})")
        top = 1.3 * abs(sim.alpha[0]).max() * scale
        ax.set_ylim(-top, top)
        ax.set_ylabel(f"{name}\nalpha [mrad]")
        ax.set_xlim(sim.time[0], sim.time[-1])
        ax.legend(loc="best", fontsize="small")
    if chain is not None:
        _chain_panel(axes[-1, 0], chain, chain_label, joints, divergence)
    axes[-1, 0].set_xlabel("time [s]")
    default = "Response to a perturbation (nonlinear, true delay)"
    joint = f"segments: {criterion('joint')}"
    notes = [joint] + ([RESPONSE_NOTE] if len(responses) > 1 else [])
    fig.suptitle("\n".join([title or default, *notes]), fontsize="medium")
    fig.tight_layout()
    return fig


def _chain_panel(ax, chain: tuple, label: str, joints=(), divergence: float = float("nan")) -> None:
    """The chain's joints with the reflex (solid) and without (dashed), scaled to the response with the reflex;
    a legend names the joints' colours, and a diverged run's stop at ``divergence`` is said, not left to look
    like a new resting posture."""
    scale = 1e3  # mrad
    with_reflex, without = chain
    for j, alpha in enumerate(with_reflex.alpha):
        ax.plot(with_reflex.time, alpha * scale, color=f"C{j}", lw=1.0)
        ax.plot(without.time, without.alpha[j] * scale, color=f"C{j}", lw=0.8, ls="--")
    top = 1.3 * max(abs(with_reflex.alpha).max(), 1e-12) * scale
    ax.set_ylim(-top, top)
    ax.set_xlim(with_reflex.time[0], _shown_until(with_reflex))
    ax.set_ylabel("chain\nalpha [mrad]")
    title = textwrap.fill(label, 90)
    note = divergence_note(chain, divergence)
    if note:
        title += "\n" + textwrap.fill(note, 90)
        for sign in (-1, 1):  # the limit the traces stop at
            ax.axhline(sign * divergence * scale, color="0.6", lw=0.6, ls=":")
    ax.set_title(title, fontsize="small")
    names = list(joints) if len(joints) == with_reflex.alpha.shape[0] else []
    handles = [Line2D([], [], color=f"C{j}", lw=1.0, label=name) for j, name in enumerate(names)]
    if handles:
        ax.legend(handles=handles, loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="x-small")


def divergence_note(chain: tuple, divergence: float) -> str:
    """What the chain panel says where a run diverged: its traces stop at the divergence limit.

    Parameters
    ----------
    chain : tuple of Simulation
        The chain's runs, with the reflex and without.
    divergence : float
        ``reflex.sim_divergence`` [rad].

    Returns
    -------
    str
        '' if no run diverged or the limit is not known.
    """
    if not np.isfinite(divergence) or not any(np.any(sim.diverged) for sim in chain):
        return ""
    return (
        f"diverged: each trace is held flat from its last step before |alpha| passes {divergence * 1e3:g} mrad "
        "(reflex.sim_divergence); the flat part is where it stopped, not a posture"
    )


def _shown_until(sim: Simulation) -> float:
    """The end of a response's time axis [s]: twice the time of divergence where it diverged (the angles are
    frozen after it), else the whole simulation."""
    if not sim.diverged.any():
        return float(sim.time[-1])
    moving = np.flatnonzero(np.any(np.diff(sim.alpha, axis=1) != 0, axis=0))
    last = sim.time[moving[-1] + 1] if moving.size else sim.time[-1]
    return float(min(2.0 * last, sim.time[-1]))


def frequency_range(report: MarginsReport) -> tuple[float, float]:
    """A decade below the slowest and above the fastest rate of the loops [rad/s].

    The rates: each segment's sqrt(abs(S)/theta), abs(D)/theta and crossover, the corner
    1/T_a of the activation lag, and order/tau, beyond which the Padé phase saturates.

    Parameters
    ----------
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.margins_report`.

    Returns
    -------
    (float, float)
        Lowest and highest frequency [rad/s]; (0.1, 10) if no rate is finite and positive.
    """
    rates = [report.pade_order / report.delay] if report.delay > 0 else []
    rates += [1.0 / report.activation_time_constant] if report.activation_time_constant > 0 else []
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
        Output of :func:`spinectl.reflex.margins.margins_report` (titles, frequency range).
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
        criteria = _loop_criteria(report)
        title = f"Reflex loops L(jw), Pade {report.pade_order}; {where}\n{criteria}{_left_out(report, responses)}"
        by_name = {seg.name: seg for seg in report.segments}
        figures["bode.png"] = bode_figure(responses.loops, frequency_range(report), title, by_name)
        nyquist_title = f"Nyquist, tau = {report.delay:g} s; {where}\n{criteria}{_left_out(report, responses)}"
        figures["nyquist.png"] = nyquist_figure(responses.loops, nyquist_title)
    if responses.simulations:
        figures["response.png"] = response_figure(
            responses.simulations, f"Response to a perturbation; {where}", responses.chain, _chain_label(report),
            [seg.name for seg in report.segments], responses.divergence,
        )  # fmt: skip
    return figures


def _loop_criteria(report: MarginsReport) -> str:
    """What the loop figures judge: each segment alone (joint by joint), and the chain's verdict, not drawn."""
    lines = [f"each curve one segment's loop alone: {criterion('joint')}"]
    chain = report.chain
    if chain is not None:
        verdict = "stable" if chain.stable_at_delay else "NOT stable"
        lines.append(
            f"{chain.criterion}, same reflex: {verdict} at {delay_text(report.delay)} (exact delay margin "
            f"{delay_text(chain.exact.margin)}); a multi-input loop, not drawn here: its response in response.png"
        )
    return "\n".join(textwrap.fill(line, 80) for line in lines)


def _chain_label(report: MarginsReport) -> str:
    """The chain panel's title: its criterion and its exact verdict at the delay (solid: reflex, dashed: none)."""
    chain = report.chain
    if chain is None:
        return ""
    verdict = "stable" if chain.stable_at_delay else "NOT stable"
    return (
        f"{chain.criterion}, the same reflex at every joint: {verdict} at {delay_text(report.delay)} "
        f"(exact delay margin {delay_text(chain.exact.margin)}); solid: reflex, dashed: none"
    )


def _left_out(report: MarginsReport, responses: ReportResponses) -> str:
    """A title's note on the segments without a loop in the plot, and why ("" if every segment has one)."""
    reasons = []
    for seg in report.segments:
        if seg.name in responses.loops:
            continue
        if seg.kp == 0 and seg.kd == 0:
            why = "kp = kd = 0" + (", self-stable" if seg.self_stable else "")
        else:
            why = "margins not defined"
        reasons.append(f"{seg.name} ({why})")
    return f"\nno reflex loop drawn: {'; '.join(reasons)}" if reasons else ""


def save_figure(fig: Figure, path: str | Path) -> Path:
    """The save step: :func:`spinectl.canvas.save_file` at this module's :data:`DPI`.

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
    return save_file(fig, path, DPI)


def write_plots(report: MarginsReport, folder: str | Path, model: Model) -> list[Path]:
    """Compute, draw and save the plots of a report: ``spinectl margins --plot``.

    response.png of every segment with a finite stiffness; bode.png and nyquist.png of
    every non-zero reflex loop. Everything is computed and drawn before the first file
    is written, so a failure (e.g. a delay too short to simulate) writes nothing; the
    files then replace the old ones together (:func:`spinectl.canvas.save_figures`), and a
    plot of an earlier run that this one does not draw goes with them: the folder never
    shows a Bode plot of one configuration beside the response of another.

    Parameters
    ----------
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.margins_report` for ``model``.
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
    return save_figures(report_figures(report, report_responses(model, report)), folder, DPI, replaces=PLOT_FILES)
