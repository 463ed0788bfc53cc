"""The choices the paper does not make, and what each landmark's verdict is under each of them.

The paper states neither the upper-body mass, nor whether its minimum PCSA
counts both sides of a pair, nor how K enters eq. 2, nor whether the two
muscles of a pair share one PCSA, and it places position C in more than one
way (docs/reproduction.md, "Verdicts as functions of the assumptions"). A
landmark that agrees under one choice and not under another is decided by that
choice; its verdict is "not reproduced with" the choice that binds, never
"cannot be reproduced" unless a proof covers every choice.

:func:`measure_choices` measures one model's landmarks under every alternative
that needs no new calibration: the other K convention (the K = 15 landscapes of
both conventions are part of every measurement), the PCSA of one side of a
pair, and the other activation mode at the same geometry. The mass is a bound
of the calibration, so its alternative is the second calibrated preset
(:data:`MASS_FREE_PRESET`); :func:`documented_rows` puts the two together and
:func:`markdown` writes the table of docs/reproduction.md.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache

from ..model.config import load_preset, set_parameter
from ..model.params import Model
from . import landmarks
from .calibration.landscapes import coarse_landmarks
from .landmarks import Landmarks, Measurement
from .verdicts import ASSUMPTION_WORDS, PRESET, RELATION, format_number

TABLE_POINTS = 41
"""Grid points per axis of the assumption table (2 mm steps; A-D and E = 3, Lambda = 4 cm are grid points).
A test checks that every agreement on it is the one on the paper's 81-point grid."""

MASS_FREE_PRESET = "wagner2012_mass_free"
"""The preset calibrated with the mass free within 10-55 kg: what the paper's numbers imply."""


ALTERNATIVES = {
    "mass": "mass free in 10-55 kg (recalibrated)",
    "side": "the PCSA of one side",
    "convention": "the other K convention",
    "activation": "independent activation (same geometry)",
    "reading_C": "another reading of C (the rows of the same ratio)",
}
"""Each assumption of :data:`spinectl.paper.verdicts.ASSUMPTION_WORDS` (the choice of ``wagner2012``),
by name, to its alternative as the table's column header says it."""

C_READINGS = {"": "corner", "_text": "interior", "_ridge": "ridge line"}
"""Suffix of a C-ratio landmark's name to its reading of position C (:mod:`spinectl.paper.landmarks`)."""

PCSA_LANDMARKS = ("min_pcsa_A", "min_pcsa_B", "min_pcsa_ridge", "min_pcsa_ridge_K15")
"""The landmarks that are an absolute PCSA, which counting one side of a pair halves (ratios do not change)."""


def one_side(measurements: Sequence[Measurement]) -> list[Measurement]:
    """The measurements with every absolute PCSA counted for one side of each pair: half of it.

    Under paired activation both muscles of a pair carry the same PCSA (docs/model.md, "The
    optimisation"), so one side is half of the total; ratios of PCSAs do not change.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure`.

    Returns
    -------
    list of Measurement
        The same, with the values of :data:`PCSA_LANDMARKS` halved and their agreement redone.
    """
    out = []
    for m in measurements:
        if m.landmark.name in PCSA_LANDMARKS:
            half = m.value / 2.0
            m = Measurement(m.landmark, half, m.landmark.agrees(half), m.off_grid, m.uncertainty / 2.0)
        out.append(m)
    return out


def measure_choices(model: Model, points: int = TABLE_POINTS) -> dict[str, list[Measurement]]:
    """The landmarks of ``model`` under its own choices and under each alternative that needs no recalibration.

    Parameters
    ----------
    model : Model
        A calibrated model (its passive stiffness is replaced by 0 and 15 N m/rad).
    points : int
        Grid points per axis (fast path, :func:`spinectl.paper.calibration.coarse_landmarks`).

    Returns
    -------
    dict
        ``"chosen"``, ``"convention"``, ``"side"`` and ``"activation"`` to a list of
        :class:`~spinectl.paper.landmarks.Measurement`, one per landmark of
        :data:`spinectl.paper.landmarks.LANDMARKS`.
    """
    own = coarse_landmarks(model, points, other=True)
    other_mode = "independent" if model.optimisation.activation == "paired" else "paired"
    alternative = coarse_landmarks(set_parameter(model, "optimisation.activation", other_mode), points, other=True)
    chosen = landmarks.measure(own)
    return {
        "chosen": chosen,
        "convention": landmarks.measure(Landmarks(own.k0, own.k15_other, own.k15)),
        "side": one_side(chosen),
        "activation": landmarks.measure(alternative),
    }


def deciders(name: str, agree: Mapping[str, bool], by_reading: Mapping[str, bool] | None = None) -> tuple[str, ...]:
    """The assumptions under whose alternative the landmark's agreement differs from the chosen one.

    Parameters
    ----------
    name : str
        Landmark name.
    agree : mapping
        Assumption name (or ``"chosen"``) to whether the landmark agrees under it.
    by_reading : mapping, optional
        For a C-ratio landmark: the reading of C to whether that reading's landmark agrees.

    Returns
    -------
    tuple of str
        Names of :data:`ALTERNATIVES`, in their order.
    """
    flips = {key for key, value in agree.items() if key != "chosen" and value != agree["chosen"]}
    if by_reading and len(set(by_reading.values())) > 1:
        flips.add("reading_C")
    return tuple(key for key in ALTERNATIVES if key in flips)


def c_ratio_family(name: str) -> tuple[str, dict[str, str]] | None:
    """For a C-ratio landmark (``ct_D_over_C_text`` ...): its reading and the names of its family by reading.

    Parameters
    ----------
    name : str
        Landmark name.

    Returns
    -------
    tuple or None
        (reading, {reading: landmark name}) or None for a landmark that does not read C.
    """
    for suffix, reading in sorted(C_READINGS.items(), key=lambda item: -len(item[0])):
        stem = name.removesuffix(suffix)
        if stem.endswith("_over_C") and name == stem + suffix:
            return reading, {r: stem + s for s, r in C_READINGS.items()}
    return None


@dataclass(frozen=True)
class Row:
    """One landmark under every choice.

    Attributes
    ----------
    name : str
        Landmark name.
    values : dict
        Column ("chosen", "convention", "side", "activation", "mass") to (value, agrees).
    deciders : tuple of str
        The assumptions whose alternative changes the agreement (:func:`deciders`).
    """

    name: str
    values: dict
    deciders: tuple[str, ...]


def assumption_rows(
    choices: Mapping[str, Sequence[Measurement]], mass_free: Sequence[Measurement] | None = None
) -> list[Row]:
    """Every landmark with its value and agreement under each choice, and the choices that decide it.

    Parameters
    ----------
    choices : mapping
        From :func:`measure_choices` of the anatomical preset.
    mass_free : sequence of Measurement, optional
        The landmarks of the preset calibrated with the mass free (column ``"mass"``).

    Returns
    -------
    list of Row
        One per landmark of :data:`spinectl.paper.landmarks.LANDMARKS`, in order.
    """
    columns = dict(choices) | ({"mass": mass_free} if mass_free is not None else {})
    by_name = {key: {m.landmark.name: m for m in found} for key, found in columns.items()}
    rows = []
    for mark in landmarks.LANDMARKS:
        values = {key: (found[mark.name].value, found[mark.name].agrees) for key, found in by_name.items()}
        family = c_ratio_family(mark.name)
        by_reading = None if family is None else {r: by_name["chosen"][n].agrees for r, n in family[1].items()}
        rows.append(Row(mark.name, values, deciders(mark.name, {k: v[1] for k, v in values.items()}, by_reading)))
    return rows


def markdown(rows: Sequence[Row], points: int = TABLE_POINTS) -> str:
    """The assumption table as Markdown, for docs/reproduction.md (generated at each docs build).

    Parameters
    ----------
    rows : sequence of Row
        From :func:`assumption_rows`.
    points : int
        The grid the rows were measured on, for the caption.

    Returns
    -------
    str
        A caption line and a table: landmark, paper, then value and agreement under each
        choice, then the choices that decide it; ending in a newline.
    """
    keys = [k for k in ("chosen", "convention", "side", "activation", "mass") if k in rows[0].values]
    heads = {"chosen": "`wagner2012` as calibrated"} | ALTERNATIVES
    lines = [
        f"Measured at docs build on a {points} × {points} grid ({80 / (points - 1):g} mm steps; every agreement "
        "is the one on the paper's 81 × 81 grid, `tests/paper/test_assumptions.py`). ✓ agrees, ✗ does not.",
        "",
        "| landmark | paper | " + " | ".join(heads[k] for k in keys) + " | decided by |",
        "| --- | --- | " + " | ".join("---" for _ in keys) + " | --- |",
    ]
    marks = {m.name: m for m in landmarks.LANDMARKS}
    for row in rows:
        mark = marks[row.name]
        cells = [f"{format_number(row.values[k][0])} {'✓' if row.values[k][1] else '✗'}" for k in keys]
        decided = ", ".join(ASSUMPTION_WORDS[d] for d in row.deciders) or "none of these"
        paper = f"{RELATION[mark.relation]} {format_number(mark.paper)}"
        lines.append(f"| `{row.name}` | {paper} | " + " | ".join(cells) + f" | {decided} |")
    counts = [sum(row.values[k][1] for row in rows) for k in keys]
    lines.append("| **agree** | | " + " | ".join(f"**{c} of {len(rows)}**" for c in counts) + " | |")
    return "\n".join(lines) + "\n"


CALIBRATED_PRESETS = (PRESET, MASS_FREE_PRESET)
"""The calibrated presets: the anatomical bounds, and the mass free (docs/reproduction.md)."""


@cache
def calibrated_measurements(points: int = TABLE_POINTS) -> tuple[tuple[str, float, tuple[Measurement, ...]], ...]:
    """Every landmark of each calibrated preset, measured afresh (fast path).

    Cached per process: the presets are files of the package.

    Parameters
    ----------
    points : int
        Grid points per axis.

    Returns
    -------
    tuple of (str, float, tuple of Measurement)
        (preset, its mass [kg], its landmarks) for each of :data:`CALIBRATED_PRESETS`.
    """
    out = []
    for name in CALIBRATED_PRESETS:
        model = load_preset(name)
        out.append((name, model.body.mass, tuple(landmarks.measure(coarse_landmarks(model, points, other=True)))))
    return tuple(out)


def documented_rows(points: int = TABLE_POINTS) -> list[Row]:
    """The assumption table of docs/reproduction.md: ``wagner2012`` under every choice, and the mass-free preset.

    Parameters
    ----------
    points : int
        Grid points per axis.

    Returns
    -------
    list of Row
        :func:`assumption_rows` of :func:`measure_choices` of ``wagner2012`` and the landmarks of
        :data:`MASS_FREE_PRESET`.
    """
    mass_free = dict((name, found) for name, _, found in calibrated_measurements(points))[MASS_FREE_PRESET]
    return assumption_rows(measure_choices(load_preset(PRESET), points), mass_free)
