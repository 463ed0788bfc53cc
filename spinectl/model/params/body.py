"""The upper body and the spine's geometry (paper, Methods; docs/model.md, "Geometry")."""

from __future__ import annotations

from dataclasses import dataclass

from ... import _validate as v
from ...errors import ParameterError
from .bounds import SIDES, _gravity, _length, _mass, _store, param


@dataclass(frozen=True)
class Body:
    """The upper body, a point mass above the lumbar spine (paper, Methods)."""

    mass: float = param(
        40.0,
        "kg",
        "Point mass m of the upper body. Not stated in the paper; spinectl's default, 40 kg, is head, arms "
        "and trunk above L3, about 55 % of a 73 kg body (Dempster 1955 segment fractions, as tabulated by "
        "Winter 2009, Biomechanics and Motor Control of Human Movement, table 4.1). At most 1000 kg "
        "(spinectl.model.params.MAX_MASS): more than any human upper body.",
    )
    mass_height: float = param(0.326, "m", "Height y of the point mass above P2 (paper: 326 mm).")
    gravity: float = param(9.81, "m/s^2", "Gravitational acceleration g.")
    radius_of_gyration: float = param(
        0.0,
        "m",
        "Radius of gyration of the upper body about the point mass; the inertia about CoR k "
        "is m (r_k^2 + rho^2). 0 reproduces the paper's point mass (docs/model.md, Gravity).",
    )

    def __post_init__(self):
        _store(
            self,
            mass=_mass(self.mass),
            mass_height=_length("mass_height", self.mass_height),
            gravity=_gravity(self.gravity),
            radius_of_gyration=_length("radius_of_gyration", self.radius_of_gyration, allow_zero=True),
        )


@dataclass(frozen=True)
class Geometry:
    """Spine line and centres of rotation (paper, Methods; docs/model.md, "Geometry")."""

    cor_names: tuple[str, ...] = param(
        ("L1L2", "L2L3", "L3L4", "L4L5", "L5S1"), "", "Names of the centres of rotation, top to bottom."
    )
    cor_heights: tuple[float, ...] = param(
        (0.145, 0.106, 0.072, 0.035, 0.005),
        "m",
        "Heights y of the centres of rotation above P2 (paper, from its ref. 16).",
    )
    spine_length: float = param(0.176, "m", "Height of P1 (thoracic joint) above P2 (pelvic joint); paper: 176 mm.")
    spline_bc: str = param(
        "natural",
        "",
        "End conditions of the cubic spline through P2, P3, P1: 'natural' (the default), "
        "'clamped' (zero slope at both ends) or 'not-a-knot' (a parabola for three points).",
    )
    eccentricity_range: tuple[float, ...] = param(
        (-0.10, 0.10), "m", "Modelled range of the eccentricity E; the paper studies 0 to 0.08 m."
    )
    lordosis_range: tuple[float, ...] = param(
        (-0.10, 0.10), "m", "Modelled range of the lordosis Lambda; the paper studies 0 to 0.08 m."
    )
    side_names: tuple[str, ...] = param(
        SIDES,
        "",
        "Names of the two sides of every pair, the +x muscle first: ventral and dorsal in the sagittal plane, "
        "right and left in the coronal plane (docs/model.md, 'Frame and units'); each muscle is <pair>_<side>.",
    )

    def __post_init__(self):
        heights = v.real_vector("cor_heights", self.cor_heights)
        if not heights:
            raise ParameterError("cor_heights", "must name at least one centre of rotation")

        names = v.labels("cor_names", self.cor_names)
        if len(names) != len(heights):
            raise ParameterError(
                "cor_names", f"must have one name per entry of cor_heights ({len(heights)}; got {len(names)})"
            )
        _store(self, cor_heights=heights, cor_names=names)
        length = _length("spine_length", self.spine_length)
        _store(self, spine_length=length)
        if any(b >= a for a, b in zip(heights, heights[1:], strict=False)):
            raise ParameterError("cor_heights", f"must be strictly decreasing, top to bottom (got {list(heights)})")
        if not all(0 <= h <= length for h in heights):
            raise ParameterError("cor_heights", f"must lie on the spine, in [0, spine_length={length:g}] m")
        v.choice("spline_bc", self.spline_bc, ("natural", "clamped", "not-a-knot"))
        for name in ("eccentricity_range", "lordosis_range"):
            lo, hi = (_length(name, x, signed=True) for x in v.real_vector(name, getattr(self, name), 2))
            if lo >= hi:
                raise ParameterError(name, f"must be [low, high] with low < high (got [{lo:g}, {hi:g}])")
            _store(self, **{name: (lo, hi)})
        sides = v.labels("side_names", self.side_names)
        if len(sides) != len(SIDES):  # distinct already (labels)
            raise ParameterError("side_names", f"must name 2 sides, the +x side first (got {len(sides)})")
        _store(self, side_names=sides)
