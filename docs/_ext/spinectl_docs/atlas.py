"""The lordosis angle conversions that ``docs/atlas.md`` quotes, from :mod:`spinectl.model.clinical` at the build.

The default preset's spine (L = 176 mm, natural end conditions): the paper's optimum Lambda = 4 cm as an angle,
Yukawa et al.'s (2019) mean standing angle (49.8 deg, a citation) as a Lambda, and the model's Lambda range as the
angles ``--lordosis-angle`` accepts. The atlas's probabilities and Sobol' indices are
:mod:`.atlas_run`'s (the page's run of ``spinectl atlas examples/atlas.toml``, repeated at the build).
"""

from __future__ import annotations

from .values import value

OPTIMUM_LORDOSIS = 0.04
"""The paper's optimum Lambda [m]."""

YUKAWA_ANGLE = 49.8
"""The mean T12-S1 lordosis of the 627 adults of Yukawa et al. (2019) [deg] (a citation: an input)."""


def _model():
    from spinectl.model.config import load_preset

    return load_preset()


def optimum_angle() -> str:
    """'68.6°': the angle of Lambda = 4 cm."""
    from spinectl.model.clinical import lordosis_angle

    return f"{float(lordosis_angle(OPTIMUM_LORDOSIS, _model())):.1f}°"


def yukawa_lordosis() -> str:
    """'2.7 cm': the Lambda of :data:`YUKAWA_ANGLE`."""
    from spinectl.model.clinical import lordosis_from_angle

    return f"{100 * float(lordosis_from_angle(YUKAWA_ANGLE, _model())):.1f} cm"


def range_angles() -> str:
    """'±10 cm is ±119.2°': the model's Lambda range and its angles (symmetric)."""
    from spinectl.model.clinical import lordosis_angle

    low, high = _model().geometry.lordosis_range
    if low != -high:
        raise RuntimeError(f"docs/atlas.md says the Lambda range is symmetric; it is {(low, high)}")
    return f"±{100 * high:g} cm is ±{float(lordosis_angle(high, _model())):.1f}°"


value("atlas.optimum_angle")(optimum_angle)
value("atlas.yukawa_lordosis")(yukawa_lordosis)
value("atlas.range_angles")(range_angles)
