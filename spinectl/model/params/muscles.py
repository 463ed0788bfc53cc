"""The global muscles: their fibres' properties and the antagonistic pairs (paper, Methods)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ... import _validate as v
from ...errors import ParameterError
from ..laws import DEFAULT_LAW, LAWS
from .bounds import MAX_FIBRES, _length, _specific_tension, _store, param


@dataclass(frozen=True)
class Fibre:
    """Force-length and Hill force-velocity properties of every global muscle fibre, and its muscle law."""

    specific_tension: float = param(
        25.0e4, "N/m^2", "Isometric force per PCSA, f_iso / PCSA (paper: 25 N/cm^2 = 2.5e5 N/m^2)."
    )
    optimal_length_ratio: float = param(
        1.2, "1", "l_opt / l0, optimal length over equilibrium length (paper: l_opt = 1.2 l0, ascending limb)."
    )
    k1: float = param(0.96, "1", "Exponent k1 of the force-length relation (paper).")
    k2: float = param(0.35, "1", "Width k2 of the force-length relation (paper).")
    fast_twitch: float = param(0.5, "1", "Fraction FT of fast-twitch fibres (paper: 0.5).")
    vmax_slow: float = param(6.0, "l_opt/s", "v_max = (vmax_slow + vmax_fast_gain FT) l_opt (paper: 6).")
    vmax_fast_gain: float = param(10.0, "l_opt/s", "v_max = (vmax_slow + vmax_fast_gain FT) l_opt (paper: 10).")
    hill_a: float = param(0.25, "1", "a / f_iso of the Hill curve (paper: a = f_iso / 4).")
    hill_b: float = param(0.25, "1", "b / v_max of the Hill curve (paper: b = v_max / 4).")
    eccentric_enhancement: float = param(
        1.5, "1", "f_ecc: the eccentric force tends to A = f_ecc f_iso (paper, its ref. 24: 1.5)."
    )
    law: str = param(
        DEFAULT_LAW,
        "",
        "The muscle law: a registered name (spinectl.model.laws). 'wagner2012': the paper's force-length and "
        "Hill force-velocity relations with the constants above, no passive force, a rigid tendon "
        "(docs/model.md, The muscle-law seam).",
    )

    def __post_init__(self):
        ratio = v.positive("optimal_length_ratio", self.optimal_length_ratio)
        if ratio <= 1.0:
            raise ParameterError(
                "optimal_length_ratio", f"must be > 1 so that muscles act on the ascending limb (got {ratio:g})"
            )
        ecc = v.real("eccentric_enhancement", self.eccentric_enhancement)
        if ecc <= 1.0:
            raise ParameterError("eccentric_enhancement", f"must be > 1 (got {ecc:g})")
        _store(
            self,
            specific_tension=_specific_tension(self.specific_tension),
            optimal_length_ratio=ratio,
            k1=v.positive("k1", self.k1),
            k2=v.positive("k2", self.k2),
            fast_twitch=v.in_range("fast_twitch", self.fast_twitch, 0.0, 1.0),
            vmax_slow=v.positive("vmax_slow", self.vmax_slow),
            vmax_fast_gain=v.non_negative("vmax_fast_gain", self.vmax_fast_gain),
            hill_a=v.positive("hill_a", self.hill_a),
            hill_b=v.positive("hill_b", self.hill_b),
            eccentric_enhancement=ecc,
            law=v.choice("law", self.law, tuple(LAWS), suggest=True),
        )


@dataclass(frozen=True)
class MusclePair:
    """One antagonistic pair of global muscles, mirror-symmetric about x = 0.

    The coordinates are those of the ventral (+x) muscle; the dorsal one is its
    mirror image. Each muscle runs from the thoracic cage (``upper``, moves with
    the upper body) to the pelvis (``lower``, fixed) as ``fibres`` parallel
    fibres spread over ``spread`` across the line of action (paper, Methods).
    The paper gives no coordinates; the defaults are anatomical estimates
    (see ``docs/parameters.md``), which the calibration fits to the paper's landmarks
    (docs/reproduction.md, "The calibration").
    """

    name: str = param("straight", "", "Name of the pair.")
    upper: tuple[float, ...] = param((0.12, 0.24), "m", "(x, y) of the upper (thoracic) attachment, ventral side.")
    lower: tuple[float, ...] = param((0.12, 0.0), "m", "(x, y) of the lower (pelvic) attachment, ventral side.")
    spread: float = param(
        0.03, "m", "Width of the attachment surface across which the fibres are spread; less than the fibre length."
    )
    fibres: int = param(5, "1", f"Number of parallel fibres (paper: 5), at most {MAX_FIBRES}.")

    def __post_init__(self):
        name = v.label("name", self.name)
        upper = tuple(_length("upper", x, signed=True) for x in v.real_vector("upper", self.upper, 2))
        lower = tuple(_length("lower", x, signed=True) for x in v.real_vector("lower", self.lower, 2))
        if upper[1] <= lower[1]:
            raise ParameterError("upper", f"must lie above lower (got y {upper[1]:g} <= {lower[1]:g})")
        length = math.dist(upper, lower)
        if not math.isfinite(length):
            raise ParameterError("upper", f"must lie a finite distance from lower (got {upper} and {lower})")
        spread = v.non_negative("spread", self.spread)
        if spread >= length:
            # a muscle is longer than its attachment is wide; catches a spread typed in cm
            raise ParameterError("spread", f"must be smaller than the fibre length {length:g} m (got {spread:g})")
        _store(
            self,
            name=name,
            upper=upper,
            lower=lower,
            spread=spread,
            fibres=v.integer("fibres", self.fibres, 1, MAX_FIBRES),
        )


def _default_muscles() -> tuple[MusclePair, ...]:
    return (
        MusclePair("straight", (0.12, 0.24), (0.12, 0.0), 0.03, 5),
        MusclePair("oblique_outer", (0.16, 0.22), (0.07, 0.0), 0.03, 5),
        MusclePair("oblique_inner", (0.07, 0.22), (0.16, 0.0), 0.03, 5),
    )
