"""The reproduction report: the paper's landmarks beside spinectl's, as Markdown.

Pure text from measurements and a few facts about the run; writing the file
is the caller's job (:func:`spinectl.paper.reproduce`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..model.source import stiffness_unit
from ..quoting import markdown_text
from ..units import m2_to_cm2
from . import grid, landmarks, verdicts
from .landmarks import Measurement
from .verdicts import RELATION
from .verdicts import format_number as _number


@dataclass(frozen=True)
class Run:
    """Facts about a reproduction run that the report states.

    Attributes
    ----------
    preset : str
        Where the parameters came from (preset name or config file; :func:`spinectl.model.source.origin`,
        without a K: the run covers K = 0 and 15).
    convention : str
        ``passive.convention`` of the K = 15 landscape.
    other_convention : str
    points : int
        Grid points per axis (E and Lambda from 0 to 8 cm).
    seconds : float
        Wall time of the sweeps, figures and report [s].
    files : tuple of str
        Files written, relative to the output folder.
    specific_tension : float
        f_iso per PCSA [N/m^2], for the local-muscle equivalent of CT.
    calibrated : bool
        Whether the parameters are the calibrated preset of docs/reproduction.md.
    presets : tuple of (str, float, tuple of Measurement)
        (preset, mass [kg], landmarks) of each calibrated preset
        (:func:`spinectl.paper.assumptions.calibrated_measurements`).
    preset_points : int
        Grid points per axis on which ``presets`` were measured.
    """

    preset: str
    convention: str
    other_convention: str
    points: int
    seconds: float
    files: tuple[str, ...]
    specific_tension: float
    calibrated: bool = False
    presets: tuple = ()
    preset_points: int = 0


def landmark_table(measurements: Sequence[Measurement], points: int | None = None) -> str:
    """The landmark table as Markdown: name, paper, spinectl, unit, agrees, verdict, how measured, where.

    The verdict is that of docs/reproduction.md for the calibrated preset
    (:func:`spinectl.paper.verdicts.verdict_cell`), flagged where this run's value differs.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure`.
    points : int, optional
        Grid points per axis of the run measured: the column names its grid (the summary's preset
        table comes from another grid).

    Returns
    -------
    str
        A Markdown table, one row per measurement, without a trailing newline.
    """
    measured = "spinectl" if points is None else f"spinectl ({points} × {points} grid)"
    lines = [
        f"| landmark | paper | {measured} | unit | agrees | verdict for `{verdicts.PRESET}` "
        "(docs/reproduction.md) | how spinectl measures it | where the paper says it |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for m in measurements:
        mark = m.landmark
        lines.append(
            f"| `{mark.name}` | {RELATION[mark.relation]} {_number(mark.paper)} | {value_cell(m)} | {mark.unit} "
            f"| {'yes' if m.agrees else '**no**'} | {verdicts.verdict_cell(m)} | {m.how} | {mark.where} |"
        )
    return "\n".join(lines)


def value_cell(measurement: Measurement) -> str:
    """A measured value as the report prints it, with ``± standard error`` where it has one.

    Parameters
    ----------
    measurement : Measurement

    Returns
    -------
    str
        E.g. ``"1.97"`` or ``"1.24 ± 0.0023"``.
    """
    spread = measurement.uncertainty
    return _number(measurement.value) + (f" ± {spread:.2g}" if np.isfinite(spread) else "")


def _find(measurements: Sequence[Measurement], name: str) -> Measurement:
    return next(m for m in measurements if m.landmark.name == name)


def _value(measurements: Sequence[Measurement], name: str) -> float:
    return _find(measurements, name).value


def _local_pcsa(measurements: Sequence[Measurement], specific_tension: float) -> str:
    parts = []
    for name, label in (("ct_B", "B"), ("ct_optimum", landmarks.label(landmarks.OPTIMUM))):
        m = _find(measurements, name)
        torque = m.value
        if m.off_grid:  # the point actually read, not the one named
            label = f"{landmarks.label(m.off_grid[0][1])} (nearest grid point to {label})"
        pcsa = m2_to_cm2(landmarks.local_pcsa_equivalent(torque, specific_tension))
        parts.append(f"{label}: {_number(torque)} N m ≙ {_number(float(pcsa))} cm²")
    limit = m2_to_cm2(landmarks.local_pcsa_equivalent(landmarks.CT_LIMIT, specific_tension))
    return (
        f"Counter torques as the PCSA of a local muscle with the paper's "
        f"{landmarks.LOCAL_LEVER_ARM * 100:g} cm lever arm (the paper: 30 N m ≙ 17 cm²; "
        f"spinectl: {landmarks.CT_LIMIT:g} N m ≙ {_number(float(limit))} cm²): " + "; ".join(parts) + "."
    )


QUESTION = (
    "The paper asks whether the lumbar lordosis makes the erect posture easier to hold: at the eccentricity "
    "E ≈ 3 cm of the physiological posture, does a lordosis of Λ ≈ 4 cm minimise the counter torque the "
    "local muscles must add, and keep it within what they can give (±30 N m)?"
)
"""The paper's question, in the words of its Discussion (Wagner et al. 2012), as the report opens with it."""


def answer(measurements: Sequence[Measurement]) -> str:
    """The paper's question and spinectl's answer, in two sentences, from the two landmarks that carry the claim.

    The claim is the Discussion's: at E ≈ 3 cm the least counter torque lies at Λ ≈ 4 cm
    (landmark ``optimum_lordosis``) and is inside the local muscles' ±30 N m (landmark ``ct_optimum``).

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure`.

    Returns
    -------
    str
        Markdown: the question, then whether this run reproduces it, with both numbers and their paper values.
    """
    lordosis, torque = _find(measurements, "optimum_lordosis"), _find(measurements, "ct_optimum")
    e_cm, lam_cm = (100 * v for v in landmarks.OPTIMUM)
    found = (
        f"at E = {e_cm:g} cm the least ‖CT‖ lies at Λ = {_number(lordosis.value)} cm "
        f"(paper: about {_number(lordosis.landmark.paper)} cm), and at E = {e_cm:g} cm, Λ = {lam_cm:g} cm "
        f"‖CT‖ is {_number(torque.value)} N m (paper: inside ±{_number(torque.landmark.paper)} N m)"
    )
    if lordosis.agrees and torque.agrees:
        verdict = f"**The paper's main claim is reproduced:** {found}."
    else:
        failed = " and ".join(f"`{m.landmark.name}`" for m in (lordosis, torque) if not m.agrees)
        verdict = f"**The paper's main claim is not reproduced with these parameters** ({failed} disagree): {found}."
    criterion = (
        "The criterion is the paper's, joint by joint (each CoR alone, the others fixed; minimum PCSA for "
        "self-stability and counter torques as in Figures 3 and 4); with every CoR free at once the chain is "
        "another question (`spinectl stability --coupled`, docs/chain.md)."
    )
    return f"{QUESTION}\n\n{verdict} {criterion}"


def _k_unit(convention: str) -> str:
    """K's unit under ``convention`` as the report writes it (docs/model.md, "Passive stiffness: two conventions")."""
    return stiffness_unit(convention).replace("^2", "²")


def _halving(measurements: Sequence[Measurement], run: Run) -> str:
    own, other = _value(measurements, "halving_K15"), _value(measurements, "halving_K15_other")
    closer = run.convention if abs(own - 0.5) <= abs(other - 0.5) else run.other_convention
    return (
        f"With K = {grid.PAPER_STIFFNESS:g} N m/rad the largest minimum PCSA falls to "
        f"{_number(own)} of its K = 0 value with the model's `{run.convention}` convention and to "
        f"{_number(other)} with the `{run.other_convention}` convention; the paper reports a halving (0.5). "
        f"With these parameters `{closer}` comes closer; docs/errata.md (eq. 2) compares the conventions "
        "after calibrating with each."
    )


def _provenance(run: Run) -> str:
    if run.calibrated and run.points == grid.PAPER_POINTS:
        return (
            "The parameters the paper does not state (upper-body mass, muscle attachment\n"
            "points, fibre spread) are **calibrated** against the landmarks below in this\n"
            "preset (`spinectl calibrate`; docs/reproduction.md gives the loss, the anatomical\n"
            "bounds and the reason for every verdict). The verdict column names the\n"
            "assumptions each verdict depends on (mass bound, PCSA of one side or both,\n"
            'K convention, activation mode, reading of C); "cannot be reproduced" only\n'
            "where a proof covers every parameter and every choice."
        )
    if run.calibrated:
        paper = f"{grid.PAPER_POINTS} × {grid.PAPER_POINTS}"
        return (
            "The parameters the paper does not state (upper-body mass, muscle attachment\n"
            "points, fibre spread) are **calibrated** against the landmarks below in this\n"
            "preset (`spinectl calibrate`; docs/reproduction.md gives the loss, the anatomical\n"
            f"bounds and the reason for every verdict), on the paper's {paper} grid.\n"
            f"This run's grid is {run.points} × {run.points}: a landmark may agree or not here because of\n"
            "the grid alone; where this run's verdict differs from the documented one, the\n"
            "verdict column gives this run's first, then the documented one and its reason."
        )
    return (
        "These parameters are **not** the calibrated preset: the landmarks below are\n"
        "reported as they are, not tuned, and the verdict column (which documents the\n"
        f"calibrated `{verdicts.PRESET}` preset) flags every value that differs from it.\n"
        f"`spinectl reproduce` without `--preset` or `--config` runs `{verdicts.PRESET}`."
    )


IMAGE_SUFFIXES = (".png", ".svg")
"""Files that the report shows as images, beside its link to them."""


def figures_section(files: Sequence[str]) -> str:
    """The figures of a run embedded as Markdown images, each under its file name.

    Parameters
    ----------
    files : sequence of str
        Files written, relative to the output folder (the report's own folder).

    Returns
    -------
    str
        One ``### name`` heading and ``![name](name)`` per image file, in the order given;
        an empty string without images.
    """
    images = [name for name in files if name.lower().endswith(IMAGE_SUFFIXES)]
    return "\n\n".join(f"### {name}\n\n![{name}]({name})" for name in images)


ANATOMICAL_MASS = 24.0
"""The lower bound of an adult upper body's mass [kg] (docs/reproduction.md, "What is fitted")."""


def presets_section(run: Run) -> str:
    """Both calibrated presets side by side: each landmark's value, agreement and documented verdict.

    Parameters
    ----------
    run : Run
        Its :attr:`Run.presets` (nothing without them).

    Returns
    -------
    str
        Markdown: the count of each preset, then one row per landmark; empty without presets.
    """
    if not run.presets:
        return ""
    counts = []
    for name, mass, found in run.presets:
        light = ", lighter than any adult upper body" if mass < ANATOMICAL_MASS else ""
        counts.append(f"`{name}` (m = {mass:.3g} kg{light}): **{sum(m.agrees for m in found)} of {len(found)}**")
    size = f"{run.preset_points} × {run.preset_points}"
    # their own grid, not this run's: the column says so
    head = " | ".join(f"`{name}` (separate {size} grid)" for name, _, _ in run.presets)
    lines = [
        "The calibrated presets, measured afresh on a separate "
        f"{size} grid (not this run's landscapes): " + "; ".join(counts) + ". The mass-free preset "
        "says what the paper's numbers imply; docs/reproduction.md gives every landmark under each assumption.",
        "",
        f"| landmark | paper | {head} | verdict for `{verdicts.PRESET}`, and what it depends on |",
        "| --- | --- | " + " | ".join("---" for _ in run.presets) + " | --- |",
    ]
    for i, mark in enumerate(landmarks.LANDMARKS):
        cells = [f"{_number(found[i].value)} {'✓' if found[i].agrees else '✗'}" for _, _, found in run.presets]
        verdict = verdicts.VERDICTS[mark.name].label
        paper = f"{RELATION[mark.relation]} {_number(mark.paper)}"
        lines.append(f"| `{mark.name}` | {paper} | " + " | ".join(cells) + f" | {verdict} |")
    return "\n".join(lines)


K_GLOSS = (
    "K is the passive stiffness of the ligaments at each joint (eq. 2): a torsional spring in N m/rad; eq. 2 as "
    "printed subtracts it from the slope of the angular acceleration, where it reads in 1/s² (docs/model.md, "
    '"Passive stiffness: two conventions").'
)
"""What K is, under the report's first lines that give it in two units."""


def _separately(run: Run) -> str:
    """Where the presets' counts come from, beside this run's count: another grid, measured afresh."""
    if not run.presets:
        return ""
    return (
        f"; the calibrated presets' counts that follow are measured afresh on a separate {run.preset_points} × "
        f"{run.preset_points} grid"
    )


def render(measurements: Sequence[Measurement], run: Run) -> str:
    """The Markdown report of a reproduction run.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure`.
    run : Run
        Facts about the run.

    Returns
    -------
    str
        The whole ``report.md``: the run's facts, the paper's question and this run's answer, the landmark
        table, the halving by K, the local-muscle equivalent of the counter torques, the figures (embedded) and
        the files written.
    """
    agree = sum(m.agrees for m in measurements)
    files = "\n".join(f"- [`{name}`]({name})" for name in run.files)
    k, own, other = f"K = {grid.PAPER_STIFFNESS:g}", _k_unit(run.convention), _k_unit(run.other_convention)
    return f"""# spinectl reproduction of Wagner et al. (2012)

Minimum PCSA for self-stability (Figure 3), local counter torques (Figure 4) and
the effect of passive stiffness (Figure S1) on the paper's grid: E and Λ from 0
to 8 cm, {run.points} × {run.points} points, K = 0 and K = {grid.PAPER_STIFFNESS:g} N m/rad.
Parameters: {markdown_text(run.preset)}; K = 0 and {k} {own} with the `{run.convention}` convention,
{k} {other} also with the `{run.other_convention}` convention. Wall time: {run.seconds:.1f} s.
{K_GLOSS}

## The paper's question and spinectl's answer

{answer(measurements)}

## Read this first

{_provenance(run)}

**{agree} of {len(measurements)} landmarks agree** with the paper, measured on this run's {run.points} × {run.points}
landscapes (the Landmarks table below{_separately(run)}).

{presets_section(run)}

## Landmarks

{landmark_table(measurements, run.points)}

"About" is read as ±20 % of the paper's value; A, B and D are corners of
Figures 3 and 4 (A: E = Λ = 0; B: E = 8 cm, Λ = 0; D: E = 0, Λ = 8 cm). C is
read as Figure 3's caption and the Discussion place it, the physiological
situation inside the grid (E ≈ 3 cm, Λ ≈ 4 cm: the `_text` rows); the
C-ratios are also given with C at the corner (E = Λ = 8 cm) and where the ridge
line Λ = 1.7 E leaves the grid (the `_ridge` rows).

{_local_pcsa(measurements, run.specific_tension)}

{_halving(measurements, run)}

## Figures

{figures_section(run.files) or "No figures were written."}

## Files

{files}
"""
