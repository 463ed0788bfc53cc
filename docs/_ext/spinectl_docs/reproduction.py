"""The tables of ``docs/reproduction.md``, from :mod:`spinectl.paper.calibration` and :mod:`spinectl.paper.verdicts`.

The free parameters with their bounds, sources and calibrated values (read
from the ``wagner2012`` preset), and the documented verdict of every landmark.
The assumption table is measured at each build (:mod:`spinectl.paper.assumptions`,
on a coarse grid); the test suite checks the documented values against a fresh
measurement of the preset (tests/paper/test_verdicts.py) and the documented
assumptions against that table (tests/paper/test_assumptions.py).
"""

from __future__ import annotations

from spinectl.model.config import load_preset
from spinectl.paper import assumptions, calibration, verdicts

from .markup import md_escape
from .values import value


def parameter_table() -> str:
    """The free parameters: name, unit, bounds, both presets' values, what it is and where the bounds come from."""
    fitted, free = load_preset(verdicts.PRESET), load_preset(assumptions.MASS_FREE_PRESET)
    lines = [
        f"| parameter | unit | lower | upper | `{verdicts.PRESET}` | `{assumptions.MASS_FREE_PRESET}` "
        "| what it is | source of the bounds |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for p in calibration.FREE_PARAMETERS:
        lines.append(
            f"| `{p.name}` | {p.unit} | {p.lower:g} | {p.upper:g} | {p.value(fitted):.4g} | {p.value(free):.4g} "
            f"| {md_escape(p.doc)} | {md_escape(p.source)} |"
        )
    lines.append(
        f"\n`{assumptions.MASS_FREE_PRESET}` is calibrated with the mass within "
        f"{calibration.MASS_FREE[0]:g}-{calibration.MASS_FREE[1]:g} kg (`--bounds mass=10,55`), "
        "its other bounds as above."
    )
    return "\n".join(lines) + "\n"


def assumption_table() -> str:
    """Every landmark under each choice the paper does not make, measured now (a coarse grid, about half a minute)."""
    return assumptions.markdown(assumptions.documented_rows())


def landmark_table() -> str:
    """The documented verdict of every landmark (:func:`spinectl.paper.verdicts.documented_table`)."""
    return verdicts.documented_table()


def _documented(name: str) -> str:
    """A landmark's documented value for ``wagner2012``, as the landmark table prints it (the tests check it
    against a fresh measurement: tests/paper/test_verdicts.py)."""
    return verdicts.format_number(verdicts.VERDICTS[name].value)


def claim() -> str:
    """'reproduced' or 'not reproduced': the paper's main claim, from its two landmarks' documented verdicts."""
    both = all(verdicts.VERDICTS[n].verdict == verdicts.REPRODUCED for n in ("optimum_lordosis", "ct_optimum"))
    return "reproduced" if both else "not reproduced"


def agreeing() -> str:
    """'11 of 22': how many landmarks the documented verdicts call reproduced, of all."""
    marks = verdicts.VERDICTS.values()
    return f"{sum(v.verdict == verdicts.REPRODUCED for v in marks)} of {len(marks)}"


value("reproduction.claim")(claim)
value("reproduction.optimum_lordosis")(lambda: _documented("optimum_lordosis"))
value("reproduction.ct_optimum")(lambda: _documented("ct_optimum"))
value("reproduction.agreeing")(agreeing)
