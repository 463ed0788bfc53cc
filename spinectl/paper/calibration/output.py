"""A calibration as text: the summary ``spinectl calibrate`` prints, the preset TOML, the loss history."""

from __future__ import annotations

import time

import numpy as np

from ...model.config import dump_toml
from ...quoting import toml_comment
from ..verdicts import RELATION
from .fit import CalibrationResult


def _number(value: float) -> str:
    return f"{value:.4g}" if np.isfinite(value) else "n/a"


def summary(result: CalibrationResult) -> str:
    """The calibration as text: the parameters with their bounds, each convention's loss, every landmark.

    Parameters
    ----------
    result : CalibrationResult

    Returns
    -------
    str
        Lines of plain text without a trailing newline: time and evaluations, a table of
        the parameters, the loss of each convention and the residual of every landmark.
    """
    best = result.best
    lines = [f"calibrated in {result.seconds:.0f} s, {result.evaluations} evaluations; convention {best.convention}"]
    lines += ["", f"{'parameter':18} {'value':>9} {'lower':>8} {'upper':>8}  unit"]
    for p, v in zip(result.parameters, best.vector, strict=True):
        lines.append(f"{p.name:18} {v:9.4g} {p.lower:8.4g} {p.upper:8.4g}  {p.unit}")
    lines += ["", "convention   loss (fit grid)   loss (verification grid)   vector found with"]
    for fit in result.fits.values():
        lines.append(f"{fit.convention:12} {fit.fit_loss:15.4g}   {fit.loss:24.4g}   {fit.origin}")
    lines += ["", f"{'landmark':22} {'paper':>9} {'spinectl':>10} {'log-ratio':>10} {'penalty':>8}  agrees"]
    for r in best.residuals:
        paper = f"{RELATION[r.relation]} {r.paper:.3g}"
        lines.append(
            f"{r.name:22} {paper:>9} {_number(r.value):>10} {_number(r.log_ratio):>10} {r.penalty:8.3g}  "
            f"{'yes' if r.agrees else 'no'}"
        )
    return "\n".join(lines)


def preset_toml(result: CalibrationResult, command: str, date: str | None = None) -> str:
    """The calibrated model as a preset TOML, with a header saying how it was produced.

    Parameters
    ----------
    result : CalibrationResult
    command : str
        The command line that produced it.
    date : str, optional
        ISO date; default today.

    Returns
    -------
    str
        Comment lines (command, date, loss, convention, the free parameters with their
        bounds), then :func:`spinectl.model.config.dump_toml` of the calibrated model.
    """
    date = date or time.strftime("%Y-%m-%d")
    best = result.best
    losses = ", ".join(
        f"{f.convention} {f.loss:.4g} with the vector found with {f.origin}" for f in result.fits.values()
    )
    header = [
        "spinectl preset calibrated against the landmarks of Wagner et al. (2012); docs/reproduction.md.",
        f"Produced by: {command}",  # the user's paths: toml_comment keeps each line one comment whatever they hold
        f"Date: {date}; wall time {result.seconds:.0f} s, {result.evaluations} loss evaluations.",
        f"Loss: {best.loss:.4g} on the {result.settings['verify_points']}-point grid "
        f"({best.fit_loss:.4g} on the {result.settings['points']}-point fitting grid); "
        f"{sum(r.agrees for r in best.residuals)} of {len(best.residuals)} landmarks agree.",
        f"Passive-stiffness convention: {best.convention}, picked at the final vector (losses: {losses}).",
        "Free parameters (value; bounds):",
    ]
    for p, v in zip(result.parameters, best.vector, strict=True):
        header.append(f"  {p.name} = {v:.6g} {p.unit}; [{p.lower:g}, {p.upper:g}]")
    return "\n".join(map(toml_comment, header)) + "\n" + dump_toml(result.model, _fitted(result))


def _fitted(result: CalibrationResult) -> dict:
    """The note "fitted by this calibration" by dotted field of each free parameter and of the convention."""
    fields = {"passive.convention"}
    for p in result.parameters:
        for path in p.paths:  # "body.mass", "muscles.0.upper.1": a pair by index, a coordinate by index
            parts = path.split(".")
            if parts[0] == "muscles":
                parts[1] = result.model.muscles[int(parts[1])].name
            fields.add(".".join(part for part in parts[:3] if not part.isdigit()))
    return dict.fromkeys(sorted(fields), "fitted by this calibration: the free parameters above")


def history_csv(result: CalibrationResult) -> str:
    """Every loss evaluation as CSV: the parameter vector, then the loss with each convention.

    Parameters
    ----------
    result : CalibrationResult

    Returns
    -------
    str
        A header row and one row per evaluation, ending in a newline.
    """
    names = [f"{p.name}_{p.unit}" for p in result.parameters]
    header = ",".join(["evaluation", *names, *(f"loss_{c}" for c in result.settings["conventions"])])
    rows = [
        ",".join([str(i), *(f"{v:.10g}" for v in vector), *(f"{v:.10g}" for v in losses)])
        for i, (vector, losses) in enumerate(zip(result.vectors, result.history, strict=True))
    ]
    return "\n".join([header, *rows]) + "\n"
