"""The verdicts of docs/reproduction.md: how close the ``wagner2012`` preset comes to each landmark, and why.

One :class:`Verdict` per landmark of :mod:`spinectl.paper.landmarks`: the value the
calibrated preset gives on the paper's 81 x 81 grid (as documented), a verdict
and its reason. The documentation's table and the reproduction report are
rendered from here; the test suite measures the preset afresh and checks
every documented value to :data:`RELATIVE` and every verdict against the
landmark's tolerance, so that the page cannot drift from the code.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import landmarks
from .grid import PAPER_POINTS
from .landmarks import Measurement

PRESET = "wagner2012"
"""The calibrated preset whose values are documented."""

RELATIVE = 0.02
"""Documented values hold to +-2 % of a fresh measurement (they are rounded to 3 digits)."""

REPRODUCED = "reproduced"
"""Within the landmark's tolerance (:mod:`spinectl.paper.landmarks`: 'about' is +-20 %)."""

COMPROMISE = "not reproduced"
"""Outside the tolerance with the calibrated parameters and the choices they were calibrated with; the
verdict names the choices whose alternative changes it (:attr:`Verdict.assumptions`)."""

STRUCTURAL = "cannot be reproduced"
"""Outside the tolerance for every parameter and every choice, shown by a proof (a bound in closed form)
or a certificate (a certified optimum): :attr:`Verdict.proof` links it. A search is neither."""

VERDICTS_ALLOWED = (REPRODUCED, COMPROMISE, STRUCTURAL)

ASSUMPTION_WORDS = {
    "mass": "the mass ≥ 24 kg",
    "side": "the PCSA of both sides of a pair",
    "convention": "the K convention `physical`",
    "activation": "paired activation",
    "reading_C": "this reading of C",
}
"""How a verdict names each assumption it depends on (:data:`spinectl.paper.assumptions.ALTERNATIVES`, whose
table measures which ones decide each landmark)."""


@dataclass(frozen=True)
class Verdict:
    """The documented outcome of one landmark with the ``wagner2012`` preset.

    Attributes
    ----------
    name : str
        Landmark name (:data:`spinectl.paper.landmarks.LANDMARKS`).
    value : float
        spinectl's value on the paper's grid, in the landmark's unit.
    verdict : str
        One of :data:`VERDICTS_ALLOWED`.
    reason : str
        Why, in one sentence; docs/reproduction.md gives the derivation.
    assumptions : tuple of str
        The choices the verdict depends on: names of :data:`ASSUMPTION_WORDS` whose alternative
        changes whether the landmark agrees (measured: docs/reproduction.md's assumption table).
    proof : str
        For :data:`STRUCTURAL`: the docs/reproduction.md section with the proof or certificate.
    """

    name: str
    value: float
    verdict: str
    reason: str
    assumptions: tuple[str, ...] = ()
    proof: str = ""

    @property
    def label(self) -> str:
        """The verdict with what it depends on, e.g. "not reproduced with paired activation"."""
        words = " and ".join(ASSUMPTION_WORDS[a] for a in self.assumptions)
        if self.verdict == STRUCTURAL:
            return f"{STRUCTURAL} (proof: docs/reproduction.md, {self.proof})"
        if self.verdict == COMPROMISE:
            return f"{COMPROMISE} with {words}" if words else f"{COMPROMISE} under any choice measured"
        return f"{REPRODUCED} with {words}" if words else REPRODUCED

    def holds(self, value: float) -> bool:
        """Whether a fresh measurement ``value`` matches the documented one (to :data:`RELATIVE`).

        Parameters
        ----------
        value : float
            A fresh measurement, in the landmark's unit.

        Returns
        -------
        bool
            True if finite and within :data:`RELATIVE` of the documented value (within
            :data:`spinectl.paper.landmarks.ZERO_TORQUE` of a documented 0).
        """
        if self.value == 0.0:
            return bool(np.isfinite(value) and abs(value) <= landmarks.ZERO_TORQUE)
        return bool(np.isfinite(value) and abs(value - self.value) <= RELATIVE * abs(self.value))


def _v(name: str, value: float, verdict: str, reason: str = "", *assumptions: str) -> Verdict:
    return Verdict(name, value, verdict, reason, tuple(assumptions))


_FALL = "paired activation co-contracts both sides at every E; a deeper fall needs more PCSA per kg at A"
_SPLINE = "‖CT‖ = F ‖x‖, x the CoRs' offsets from the mass, fixed by the spline"

VERDICTS: dict[str, Verdict] = {
    v.name: v
    for v in (
        _v(
            "min_pcsa_A",
            36.3,
            REPRODUCED,
            "the mass sets the scale (every constraint is linear in PCSA and mass)",
            "side",
        ),
        _v("min_pcsa_D_over_A", 0.817, REPRODUCED, "the binding CoR moves off the mass's vertical"),
        _v("min_pcsa_B", 19.3, COMPROMISE, _FALL, "side", "activation"),
        _v(
            "min_pcsa_ridge",
            36.3,
            REPRODUCED,
            "only because A's value agrees: the ridge is a plateau at A's 36.3",
            "side",
        ),
        _v(
            "ridge_rise",
            0.0,
            COMPROMISE,
            "along Λ = E/φ the binding CoR sits where it sits at A, so one binding CoR gives A's value exactly",
        ),
        _v("ridge_slope", 1.97, REPRODUCED, "where the binding CoR, L1L2, lies under the mass: Λ = E/φ = 1.97 E"),
        _v("ridge_over_B", 1.88, COMPROMISE, _FALL + " (the mass-free preset: 2.28; a search: 2.85 at 12 kg)"),
        _v("ct_A", 0.0, REPRODUCED, "symmetric pairs cancel and the mass is above every CoR"),
        _v("ct_valley_slope", 1.24, COMPROMISE, f"{_SPLINE}: least ‖x‖ at Λ = 1.28 E; F moves it", "mass"),
        _v("ct_B", 107.0, REPRODUCED, "every CoR is 8 cm behind the mass"),
        _v("ct_D_over_C", 1.31, COMPROMISE, f"{_SPLINE}; ‖x(D)‖/‖x(C)‖ = 1.37 and F(D) < F(C)", "reading_C"),
        _v("ct_B_over_C", 1.44, COMPROMISE, f"{_SPLINE}; ‖x(B)‖/‖x(C)‖ = 1.98 and F(B) < F(C)"),
        _v(
            "ct_D_over_C_text",
            3.43,
            COMPROMISE,
            f"{_SPLINE}; ‖x(D)‖/‖x(C)‖ = 3.94 and F(D) < F(C)",
            "activation",
            "reading_C",
        ),
        _v(
            "ct_B_over_C_text",
            3.77,
            COMPROMISE,
            "‖x(B)‖/‖x(C)‖ = 5.71 needs F(B)/F(C) = 0.53: the threefold fall (the mass-free preset: 2.9)",
            "mass",
        ),
        _v("ct_D_over_C_ridge", 1.86, REPRODUCED, "‖x(D)‖/‖x(C)‖ = 2.14 on this reading of C", "reading_C"),
        _v("ct_B_over_C_ridge", 2.04, COMPROMISE, "‖x(B)‖/‖x(C)‖ = 3.11 needs F(B) = F(C), but the PCSA falls with E"),
        _v(
            "optimum_lordosis",
            3.8,
            REPRODUCED,
            "the valley Λ = 1.24 E passes through E = 3 cm at Λ = 3.8 cm",
            "activation",
        ),
        _v("ct_optimum", 28.4, REPRODUCED, "‖x‖ = 3.1 cm there, times F = 905 N", "activation"),
        _v("min_pcsa_ridge_K15", 23.6, REPRODUCED, "the ridge falls to 0.65 of 36.3 cm²", "side"),
        _v(
            "halving_K15",
            0.650,
            COMPROMISE,
            "a physical spring removes K/(m g r): halving at L1L2 needs 17 kg",
            "mass",
        ),
        _v(
            "halving_K15_other",
            0.724,
            COMPROMISE,
            "eq. 2 as printed removes K r/g: 0.28 at the binding L1L2, 0.45-0.49 below",
            "mass",
        ),
        _v("ridge_slope_K15", 1.97, REPRODUCED, "L1L2 still binds along the ridge"),
    )
}
"""Landmark name to its documented :class:`Verdict`: the ``wagner2012`` preset on the paper's 81 x 81 grid."""


def format_number(value: float) -> str:
    """A value as the reports print it: 3 significant digits, exponent form when tiny or huge, 'n/a' if NaN.

    Parameters
    ----------
    value : float

    Returns
    -------
    str
        E.g. ``"36.3"``, ``"1.20e-05"`` or ``"n/a"``.
    """
    if not np.isfinite(value):
        return "n/a"
    if value != 0 and (abs(value) < 1e-3 or abs(value) >= 1e4):
        return f"{value:.2e}"
    return f"{value:.3g}"


RELATION = {"~": "≈", "=": "=", "<": "<", ">": ">"}
"""How each relation of :class:`spinectl.paper.landmarks.Landmark` is printed."""


def documented_table() -> str:
    """The documented table as Markdown: landmark, paper, spinectl (documented), verdict, reason.

    For docs/reproduction.md (generated at each docs build).

    Returns
    -------
    str
        A Markdown table, one row per landmark of :data:`spinectl.paper.landmarks.LANDMARKS`,
        ending in a newline.
    """
    lines = [
        "| landmark | what | paper | spinectl | unit | verdict | why |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for mark in landmarks.LANDMARKS:
        v = VERDICTS[mark.name]
        paper, value = format_number(mark.paper), format_number(v.value)
        lines.append(
            f"| `{mark.name}` | {mark.how} | {RELATION[mark.relation]} {paper} | {value} "
            f"| {mark.unit} | {v.label} | {v.reason} |"
        )
    return "\n".join(lines) + "\n"


def verdict_cell(measurement: Measurement) -> str:
    """The verdict for a fresh measurement, for the report's table: never one that its own value contradicts.

    The verdict of docs/reproduction.md, with its reason, where the fresh value matches the
    documented one and agrees (or not) with the paper as the documented verdict says. Otherwise
    (another preset, a coarse grid, a changed model) the verdict is this run's own, from its
    agreement, and the documented one follows as what holds under its condition: the
    ``wagner2012`` preset on the paper's grid.

    Parameters
    ----------
    measurement : Measurement
        From :func:`spinectl.paper.landmarks.measure`.

    Returns
    -------
    str
        "verdict: reason", or "this run: verdict (value); documented for `wagner2012` on the
        paper's 81 x 81 grid: value, verdict: reason"; "n/a" for a landmark without a documented verdict.
    """
    v = VERDICTS.get(measurement.landmark.name)
    if v is None:
        return "n/a"
    text = f"{v.label}: {v.reason}" if v.reason else v.label
    if v.holds(measurement.value) and measurement.agrees == (v.verdict == REPRODUCED):
        return text
    if measurement.agrees:
        own = REPRODUCED
    elif np.isfinite(measurement.value):
        own = COMPROMISE
    else:
        own = f"{COMPROMISE}, not measurable here"
    points = f"{PAPER_POINTS} x {PAPER_POINTS}"
    return (
        f"this run: {own} ({format_number(measurement.value)}); documented for `{PRESET}` on the paper's "
        f"{points} grid: {format_number(v.value)}, {text}"
    )
