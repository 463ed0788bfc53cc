"""``spinectl margins``: delayed-reflex margins of every segment."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ..model.config import set_parameter
from ..reflex.margins import MarginsReport, SegmentMargins, analyse
from ..units import m2_to_cm2
from ._common import add_model_options, emit_json, finite_float, load_model
from .stability_cmd import add_position_options


def register(sub) -> None:
    """Add the ``margins`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "margins",
        help="delay, gain and phase margins of a delayed PD reflex at each segment",
        description="Close each segment's loop with a delayed PD reflex u = -(kp alpha + kd omega)(t - tau) "
        "and report the exact delay margin (quasi-polynomial), its Pade estimate, gain and phase margins, "
        "the stabilising range of kp and whether the loop is stable at the delay. See docs/reflex.md.",
    )
    add_position_options(parser)
    parser.add_argument("--delay", type=finite_float("--delay"), help="reflex delay tau [s] (default: config, 0.1)")
    parser.add_argument("--kp", type=finite_float("--kp"), help="proportional gain [N m/rad] (default: the rule)")
    parser.add_argument("--kd", type=finite_float("--kd"), help="derivative gain [N m s/rad] (default: the rule)")
    parser.add_argument(
        "--activation",
        type=finite_float("--activation"),
        help="fraction of the minimum stabilising PCSA: 0 reflex only, 1 self-stable (default: config, 0.5)",
    )
    parser.add_argument("--pade-order", type=int, help="order of the Pade delay in the python-control models")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--plot", metavar="DIR", help="write bode.png, nyquist.png and response.png into DIR")
    add_model_options(parser)
    parser.set_defaults(func=run)


OVERRIDES = (("delay", "reflex.delay"), ("activation", "reflex.activation"), ("pade_order", "reflex.pade_order"))
"""Command-line options that replace a parameter of the ``reflex`` section."""


def model_with_overrides(args):
    """The model of ``--preset``/``--config`` with the reflex options applied (validated there).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments; ``delay`` [s], ``activation``, ``pade_order``, ``kp``, ``kd`` are optional.
    """
    model = load_model(args)
    for option, dotted in OVERRIDES:
        value = getattr(args, option)
        if value is not None:
            model = set_parameter(model, dotted, value)
    for option in ("kp", "kd"):
        value = getattr(args, option)
        if value is not None:
            set_parameter(model, f"reflex.{option}", value)  # validates: a gain must be >= 0
    return model


def run(args) -> int:
    """Run ``spinectl margins``: print the table, or JSON with ``--json``; plots with ``--plot``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], the reflex options, ``json``, ``plot``
        and the model options.

    Returns
    -------
    int
        Exit code 0 (also for an infeasible optimum, reported as a status).
    """
    model = model_with_overrides(args)
    report = analyse(model, args.E, args.Lambda, kp=args.kp, kd=args.kd)
    if args.plot:
        write_plots(model, report, Path(args.plot))
    if args.json:
        emit_json(report_to_json(model, report))
    else:
        print(format_table(model, report))
    return 0


def write_plots(model, report: MarginsReport, folder: Path) -> list[Path]:
    """response.png of every defined segment; bode.png and nyquist.png of every non-zero reflex loop.

    A segment without reflex (kp = kd = 0, e.g. self-stable under the default rule)
    has no loop to draw; if no segment has one, only response.png is written.

    Parameters
    ----------
    model : Model
        The model of the report (simulation settings, geometry).
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.analyse`.
    folder : Path
        Folder for the PNGs (created if missing).
    """
    from ..reflex import loops, plots, simulate  # matplotlib only when plotting

    point, settings = report.point, model.reflex
    usable = [(k, s) for k, s in enumerate(report.segments) if np.isfinite(s.stiffness)]  # NaN: infeasible
    where = (
        f"E = {point.eccentricity * 100:g} cm, Lambda = {point.lordosis * 100:g} cm, activation {point.activation:g}"
    )
    loops = {  # python_control None: python-control cannot evaluate its Pade model (microsecond delays, high orders)
        s.name: loops.loop_transfer(s.stiffness, s.damping, s.inertia, s.kp, s.kd, report.delay, report.pade_order)
        for _, s in usable
        if (s.kp > 0 or s.kd > 0) and s.python_control is not None
    }
    responses = {  # simulated before anything is written: a failure leaves no partial set of plots
        s.name: simulate.simulate(
            simulate.segment_plant(model, point.eccentricity, point.lordosis, k, point.pcsa),
            [s.kp, 0.0],
            [s.kd, 0.0],
            report.delay,
            settings,
        )
        for k, s in usable
    }
    written = []
    if loops:
        title = f"Reflex loops, Pade {report.pade_order}; {where}"
        written.append(plots.bode(loops, folder / "bode.png", frequency_range(report), title))
        title = f"Nyquist, tau = {report.delay:g} s; {where}"
        written.append(plots.nyquist(loops, folder / "nyquist.png", title))
    if responses:
        title = f"Response to a perturbation; {where}"
        written.append(plots.time_response(responses, folder / "response.png", title))
    skipped = sorted({"bode.png", "nyquist.png", "response.png"} - {p.name for p in written})
    if skipped:
        print(f"spinectl: note: not written (nothing to draw): {', '.join(skipped)}", file=sys.stderr)
    return written


def frequency_range(report: MarginsReport) -> tuple[float, float]:
    """A decade below the slowest and above the fastest rate of the loops [rad/s].

    The rates: each segment's sqrt(abs(S)/theta), abs(D)/theta and crossover, and
    order/tau, beyond which the Padé phase saturates.

    Parameters
    ----------
    report : MarginsReport
    """
    rates = [report.pade_order / report.delay] if report.delay > 0 else []
    for s in report.segments:
        rates += [np.sqrt(abs(s.stiffness) / s.inertia), abs(s.damping) / s.inertia, s.crossover_rad_s]
    rates = [r for r in rates if np.isfinite(r) and r > 0] or [1.0]
    return min(rates) / 10, max(rates) * 10


def _segment_json(s: SegmentMargins) -> dict:
    pc = s.python_control
    return {
        "name": s.name,
        "stiffness_Nm_per_rad": s.stiffness,
        "damping_Nms_per_rad": s.damping,
        "inertia_kgm2": s.inertia,
        "self_stable": s.self_stable,
        "kp_Nm_per_rad": s.kp,
        "kd_Nms_per_rad": s.kd,
        "gain_margin": s.gain_margin,
        "gain_margin_lower": s.gain_margin_lower,
        "phase_margin_deg": s.phase_margin_deg,
        "crossover_rad_s": s.crossover_rad_s,
        "delay_margin_s": s.delay_margin,
        "delay_margin_status": s.delay_margin_status,
        "delay_margin_pade_s": s.delay_margin_pade,
        "kp_min_Nm_per_rad": s.kp_min,
        "kp_max_Nm_per_rad": s.kp_max,
        "stable_at_delay": s.stable_at_delay,
        "python_control": None
        if pc is None
        else {
            "gain_margin": pc.gain_margin,
            "phase_margin_deg": pc.phase_margin_deg,
            "crossover_rad_s": pc.crossover_rad_s,
            "phase_crossover_rad_s": pc.phase_crossover_rad_s,
        },
    }


def report_to_json(model, report: MarginsReport) -> dict:
    """The JSON document of ``spinectl margins --json`` (units in the key names).

    Parameters
    ----------
    model : Model
        The model of the report (muscle names, gain mode).
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.analyse`.
    """
    point = report.point
    return {
        "E_m": point.eccentricity,
        "Lambda_m": point.lordosis,
        "delay_s": report.delay,
        "pade_order": report.pade_order,
        "activation": point.activation,
        "optimum_status": point.status,
        "gains": model.reflex.gains,
        "pcsa_cm2": dict(zip(model.muscle_names, m2_to_cm2(point.pcsa).tolist(), strict=True)),
        "segments": [_segment_json(s) for s in report.segments],
        "all_stable_at_delay": all(s.stable_at_delay for s in report.segments),
    }


def _num(value: float, width: int, digits: int) -> str:
    return f"{value:{width}.{digits}f}" if value == value and abs(value) != float("inf") else f"{value!s:>{width}}"


def format_table(model, report: MarginsReport) -> str:
    """A readable per-segment table.

    Parameters
    ----------
    model : Model
        The model of the report (gain mode).
    report : MarginsReport
        Output of :func:`spinectl.reflex.margins.analyse`.
    """
    point = report.point
    lines = [
        f"E = {point.eccentricity * 100:.2f} cm, Lambda = {point.lordosis * 100:.2f} cm, "
        f"activation {point.activation:g} x minimum PCSA (optimum: {point.status}), "
        f"delay {report.delay:g} s, Pade order {report.pade_order}, gains: {model.reflex.gains}",
        "",
        f"{'segment':8} {'S':>8} {'D':>8} {'theta':>6} {'kp':>8} {'kd':>7} {'GM low':>7} {'GM up':>7} "
        f"{'PM[deg]':>8} {'w_c':>7} {'tau_m[s]':>9} {'Pade[s]':>9} {'kp range at tau':>19} {'stable':>6}",
    ]
    for s in report.segments:
        lines.append(
            f"{s.name:8} {_num(s.stiffness, 8, 2)} {_num(s.damping, 8, 2)} {_num(s.inertia, 6, 3)} "
            f"{_num(s.kp, 8, 2)} {_num(s.kd, 7, 2)} {_num(s.gain_margin_lower, 7, 3)} {_num(s.gain_margin, 7, 3)} "
            f"{_num(s.phase_margin_deg, 8, 2)} {_num(s.crossover_rad_s, 7, 3)} {_num(s.delay_margin, 9, 4)} "
            f"{_num(s.delay_margin_pade, 9, 4)} [{_num(s.kp_min, 8, 1)},{_num(s.kp_max, 8, 1)}] "
            f"{'yes' if s.stable_at_delay else 'NO':>6}"
        )
    lines += [
        "",
        "S, kp in N m/rad; D, kd in N m s/rad; theta in kg m^2; w_c in rad/s. GM: stable range of a common",
        "factor on kp and kd. tau_m: exact delay margin (inf: any delay; 0: unstable without delay).",
    ]
    return "\n".join(lines)
