"""The tables of ``docs/reproduction.md``, from :mod:`spinectl.calibration` and :mod:`spinectl.reproduction`.

The free parameters with their bounds, sources and calibrated values (read
from the ``wagner2012`` preset), and the documented verdict of every landmark.
Nothing is computed here: the test suite checks the documented values against
a fresh measurement of the preset (tests/test_reproduction.py).
"""

from __future__ import annotations

from spinectl import calibration, reproduction
from spinectl.config import load_preset

from .markup import md_escape


def parameter_table() -> str:
    """The free parameters: name, unit, bounds, the calibrated value, what it is and where the bounds come from."""
    fitted = load_preset(reproduction.PRESET)
    lines = [
        f"| parameter | unit | lower | upper | `{reproduction.PRESET}` | what it is | source of the bounds |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for p in calibration.FREE_PARAMETERS:
        lines.append(
            f"| `{p.name}` | {p.unit} | {p.lower:g} | {p.upper:g} | {p.value(fitted):.4g} "
            f"| {md_escape(p.doc)} | {md_escape(p.source)} |"
        )
    return "\n".join(lines) + "\n"


def landmark_table() -> str:
    """The documented verdict of every landmark (:func:`spinectl.reproduction.documented_table`)."""
    return reproduction.documented_table()
