"""How the paper's problems are posed and solved: the errata chosen and the optimisation settings.

docs/model.md, "Errata" and "The optimisation".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ... import _validate as v
from ...errors import ParameterError
from .bounds import (
    MAX_CT_TOLERANCE,
    MAX_DAMPING_MARGIN,
    MAX_STABILITY_MARGIN,
    SOLVER_TOLERANCE_RANGE,
    _store,
    param,
)

MARGIN_REASONS = {
    "stability_margin": ("N m/rad", "the gravity stiffness m g r of the heaviest, tallest body the bounds allow"),
    "damping_margin": (
        "N m s/rad",
        "the critical damping 2 sqrt(theta S) of the heaviest, tallest body the bounds allow",
    ),
    "ct_tolerance": ("", "a slack of 100 %: twice the minimum PCSA"),
}
"""The unit and the reason of each bounded setting, for its message (``params.bounds.MAX_DAMPING_MARGIN`` etc.)."""


def _bounded(name: str, value, high: float) -> float:
    """A number in [0, high], the bound's unit and reason in the message (:data:`MARGIN_REASONS`)."""
    value = v.non_negative(name, value)
    if value > high:
        unit, why = MARGIN_REASONS[name]
        raise ParameterError(name, f"must be at most {high:.3g}{' ' + unit if unit else ''}, {why} (got {value:g})")
    return value


@dataclass(frozen=True)
class Errata:
    """Choices between the paper's printed formulas and their corrections (docs/model.md, "Errata")."""

    gravity_sign: str = param(
        "destabilising",
        "",
        "'destabilising': dM_ext/dalpha = +m g r cos(alpha), an inverted pendulum (erratum). "
        "'printed': M_ext = -m g r sin(alpha) as printed, which makes gravity stabilising.",
    )
    eccentric_constant: str = param(
        "corrected",
        "",
        "'corrected': C = (A - f_iso) B, continuous in value and slope at v = 0 (erratum C). "
        "'printed': C = (A - f_iso) b as printed; the Hill curve then jumps at v = 0.",
    )

    def __post_init__(self):
        v.choice("gravity_sign", self.gravity_sign, ("destabilising", "printed"))
        v.choice("eccentric_constant", self.eccentric_constant, ("corrected", "printed"))


@dataclass(frozen=True)
class Optimisation:
    """Settings of the minimum-PCSA and counter-torque problems (docs/model.md, "The optimisation")."""

    activation: str = param(
        "paired", "", "'paired': one PCSA per antagonistic pair (both sides equal); 'independent': one per muscle."
    )
    stability_margin: float = param(
        0.1,
        "N m/rad",
        "Required margin: dM_k/dalpha <= -stability_margin at every CoR. A small positive default makes "
        "the optimum strictly self-stable rather than marginal (a zero eigenvalue); it costs well under "
        "0.1 cm^2 of PCSA.",
    )
    relative_margin: float = param(
        0.0,
        "1",
        "Relative stability margin: dM_k/dalpha <= -relative_margin * m g r_y,k at every CoR, a fraction of "
        "the segment's gravity stiffness (the larger of this and stability_margin binds). 0 (the paper): "
        "an optimum only just beats gravity, with time constants of minutes; 0.1 asks the muscles for 10 % "
        "more stiffness than gravity takes away (docs/reproduction.md, 'A relative stability margin'); 0 to 1.",
    )
    damping_margin: float = param(
        0.01,
        "N m s/rad",
        "Required damping: dM_k/domega <= -damping_margin at every CoR. Self-stability needs both "
        "eigenvalues in the left half-plane (paper, eq. 1), so D_k < 0 as well as S_k < 0; where passive "
        "stiffness alone makes S_k < 0, a zero PCSA would leave an undamped centre. Costs about 0.05 cm^2.",
    )
    pcsa_max: float = param(math.inf, "m^2", "Upper bound on the PCSA of each decision variable (inf = none).")
    ct_tolerance: float = param(
        1e-3, "1", "Relative slack on the minimum total PCSA within which ||CT||_2 is minimised."
    )
    solver_tolerance: float = param(
        1e-9,
        "1",
        "Feasibility and relative-gap tolerance of the conic solver (Clarabel; SCS as fallback) and of the "
        "KKT check that polishes its answers. Tight, so that the per-point reference and the fast path "
        f"agree to 1e-6 (docs/optimisation.md); {SOLVER_TOLERANCE_RANGE[0]:g} to {SOLVER_TOLERANCE_RANGE[1]:g}.",
    )

    def __post_init__(self):
        v.choice("activation", self.activation, ("paired", "independent"))
        pmax = v.non_negative("pcsa_max", self.pcsa_max, allow_inf=True)
        if pmax == 0:
            raise ParameterError("pcsa_max", "must be > 0 (got 0)")
        _store(
            self,
            stability_margin=_bounded("stability_margin", self.stability_margin, MAX_STABILITY_MARGIN),
            relative_margin=v.in_range("relative_margin", self.relative_margin, 0.0, 1.0),
            damping_margin=_bounded("damping_margin", self.damping_margin, MAX_DAMPING_MARGIN),
            pcsa_max=pmax,
            ct_tolerance=_bounded("ct_tolerance", self.ct_tolerance, MAX_CT_TOLERANCE),
            solver_tolerance=v.in_range("solver_tolerance", self.solver_tolerance, *SOLVER_TOLERANCE_RANGE),
        )
