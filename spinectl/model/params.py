"""Model parameters as frozen dataclasses.

Every number the model uses lives here, with its unit and source in the field
metadata (``unit``, ``doc``); there are no magic numbers in the physics
modules. All values are SI (m, kg, N, s, rad) except where the field says
otherwise. Instances validate themselves on construction and raise
:class:`~spinectl.errors.ParameterError` naming the field.

Reading and writing TOML lives in :mod:`spinectl.model.config`; this module does no
I/O. docs/model.md sets out the reading of the paper [1]_ ("the paper") that
these defaults encode; docs/parameters.md lists every field with its unit,
default and source, and docs/glossary.md the symbols.

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from .. import _validate as v
from ..errors import ParameterError
from ..units import CM_PER_M, centimetre_slip

SIDES = ("ventral", "dorsal")
"""Sides of an antagonistic pair: ``ventral`` is +x, ``dorsal`` its mirror at -x.

In the coronal plane read them as right (+x) and left (-x).
"""


MAX_FIBRES = 1000
"""Most fibres per muscle. Fibres only discretise the attachment surface (the paper
uses 5); the bound keeps the per-fibre arrays of a sweep within memory."""


MAX_MUSCLE_PAIRS = 20
"""Most antagonistic pairs of a model. The fast path's active sets grow combinatorially with the
muscles: a 3 x 3 sweep took about 1.7 s a point with 20 pairs and 25 CoRs and 13 s a point with 100
pairs (the paper's 3 pairs: well under 1 ms); the trunk models of the literature have a few dozen muscles."""

MAX_CORS = 24
"""Most centres of rotation: the joints of the whole vertebral column, C1 to S1 (the paper models the
five lumbar ones). Every analysis is per segment or a chain of this many degrees of freedom."""

MAX_FIBRE_TERMS = 30_000
"""Most fibre-CoR terms of a model (fibres of every muscle times the CoRs): the per-fibre arrays of a
sweep hold this many per point and chunk point (240 MB a chunk of 1024 points here), the bound that
:data:`MAX_FIBRES` sets for the paper's 6 muscles and 5 CoRs."""

MAX_PADE_ORDER = 10
"""Highest Padé order of the reflex delay. Order 6 is already exact to rounding for the
spine's loops (docs/reflex.md); from order 9 python-control's polynomial margins overflow
for delays of a few microseconds, its coefficients growing like (1/tau)^n."""

MAX_MASS = 1000.0
"""Largest upper-body mass [kg]: the upper body above L3 is about 55 % of the body (Dempster 1955,
Winter 2009, table 4.1), and the heaviest bodies recorded are about 600 kg, so no human upper
body comes near 1000 kg. A mass of 1e6 kg (grams typed as kilograms) made every point
``infeasible`` without a reason: the solvers fail on constraints scaled that far, although the
answer scales linearly with the mass."""

MAX_DELAY = 10.0
"""Longest reflex delay [s]: fifty times the slowest loop the paper names (100 ms plus
50-100 ms of force generation). A delay of 1e62 s, a unit typo, made the Padé
coefficients (tau^n) overflow and python-control's Nyquist plot warn; the exact delay
margin does not depend on tau, so nothing of interest lies beyond."""

MAX_ACTIVATION_TIME_CONSTANT = 1.0
"""Longest force-generation time constant of the reflex [s]: ten times the 100 ms the paper names as
the upper end of force generation; a value beyond it is more likely milliseconds typed as seconds."""

MAX_ACTIVATION = 10.0
"""Largest activation of the reflex section, a sanity bound: ten times the co-contraction that
self-stability needs (a larger value is more likely a PCSA typed in place of a fraction)."""


MAX_BODY_LENGTH = 1.0
"""Largest length of the modelled trunk [m]: every height, coordinate, lever arm and radius of gyration of
the model lies within the trunk between the pelvis and the head, which spans about half of body height
above the hip joint (Winter 2009, Biomechanics and Motor Control of Human Movement, fig. 4.1), some 0.9 m
for a body 1.8 m tall; the paper's largest length is the mass height, 0.326 m. A length typed in cm
(``mass_height = 32.6``) is 30 times beyond."""

SPECIFIC_TENSION_RANGE = (1e4, 1e7)
"""Allowed ``fibre.specific_tension`` [N/m^2]: human values reported in vivo range from 2 to 73 N/cm^2
(2e4 to 7.3e5 N/m^2; Persad LS et al. 2024, J Appl Physiol 137:945-962, doi:10.1152/japplphysiol.00296.2024,
who recommend 26.8 N/cm^2), older estimates up to 137 N/cm^2 (Buchanan TS 1995, Med Eng Phys 17:529-536,
doi:10.1016/1350-4533(95)00005-8); the paper takes 25 N/cm^2 = 2.5e5 N/m^2. The range is wider than all
of them and still excludes N/cm^2 (25, a factor 1e4) and kPa (250, a factor 1e3) typed for N/m^2. Near
its lower end with the heaviest, tallest bodies the optimiser's statuses are not reliable
(docs/robustness.md, "Optimisation": large models)."""

MAX_GRAVITY = 30.0
"""Largest gravitational acceleration [m/s^2]: above Jupiter's 24.8; cm/s^2 (981) typed for m/s^2 is far beyond."""


def _length(name: str, value, *, allow_zero: bool = False, signed: bool = False) -> float:
    """A length of the trunk [m], at most :data:`MAX_BODY_LENGTH` in size, with the cm-for-m hint."""
    if signed:
        value = v.real(name, value)
    else:
        value = v.non_negative(name, value) if allow_zero else v.positive(name, value)
    if abs(value) > MAX_BODY_LENGTH:
        low = -MAX_BODY_LENGTH if signed else 0.0
        hint = centimetre_slip(value, low, MAX_BODY_LENGTH, f"{value:g}", f"{value / CM_PER_M:g}")
        raise ParameterError(
            name,
            f"must be at most {MAX_BODY_LENGTH:g} m{' in size' if signed else ''}, the modelled trunk's scale "
            f"(got {value:g}){hint}",
        )
    return value


def _specific_tension(value) -> float:
    value = v.positive("specific_tension", value)
    low, high = SPECIFIC_TENSION_RANGE
    if low <= value <= high:
        return value
    # the likely slip: the unit that brings the value nearest the paper's 2.5e5 N/m^2 (in decades)
    slips = [(f, u) for f, u in ((1e4, "N/cm^2"), (1e3, "kPa"), (1e6, "MPa")) if low <= value * f <= high]
    hint = ""
    if slips:
        factor, unit = min(slips, key=lambda slip: abs(math.log10(value * slip[0] / 2.5e5)))
        hint = f"; if you meant {value:g} {unit}, give {value * factor:g}"
    raise ParameterError(
        "specific_tension",
        f"must be in [{low:g}, {high:g}] N/m^2, around reported human values (2-137 N/cm^2) (got {value:g}){hint}",
    )


def _gravity(value) -> float:
    value = v.positive("gravity", value)
    if value > MAX_GRAVITY:
        hint = f"; if you meant {value:g} cm/s^2, give {value / CM_PER_M:g}" if value / CM_PER_M <= MAX_GRAVITY else ""
        raise ParameterError("gravity", f"must be at most {MAX_GRAVITY:g} m/s^2 (got {value:g}){hint}")
    return value


def _seconds(name: str, value, high: float) -> float:
    """A time in [0, high] s, with the hint for milliseconds typed as seconds."""
    value = v.real(name, value)
    if not 0.0 <= value <= high:
        hint = f"; if you meant {value:g} ms, give {value / 1e3:g}" if 0.0 < value / 1e3 <= high else ""
        raise ParameterError(name, f"must be in [0, {high:g}] s (got {value:g}){hint}")
    return value


def param(default, unit: str, doc: str):
    """A dataclass field carrying its unit and documentation.

    Parameters
    ----------
    default : object
        Default value, in ``unit``; a list or dict becomes a default factory.
    unit : str
        Unit of the value, e.g. ``"N m/rad"``; ``"1"`` for a ratio, ``""`` for text.
    doc : str
        What the parameter is and where its value comes from.

    Returns
    -------
    dataclasses.Field
        A field with ``metadata = {"unit": unit, "doc": doc}`` and the default (or
        default factory).
    """
    kwargs = {"default_factory": lambda: default} if isinstance(default, (list, dict)) else {"default": default}
    return field(metadata={"unit": unit, "doc": doc}, **kwargs)


SOLVER_TOLERANCE_RANGE = (1e-12, 1e-6)
"""Allowed ``optimisation.solver_tolerance`` [1]: interior-point solvers stall below 1e-12 in double
precision; above 1e-6 the two solution paths need not agree to the 1e-6 the fast path promises."""


def _store(obj, **values) -> None:
    """Store validated, normalised values (plain floats, tuples) on a frozen dataclass."""
    for name, value in values.items():
        object.__setattr__(obj, name, value)


def _mass(mass) -> float:
    mass = v.positive("mass", mass)
    if mass > MAX_MASS:
        raise ParameterError("mass", f"must be at most {MAX_MASS:g} kg, more than any human upper body (got {mass:g})")
    return mass


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


@dataclass(frozen=True)
class Fibre:
    """Force-length and Hill force-velocity properties of every global muscle fibre."""

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


@dataclass(frozen=True)
class Passive:
    """Passive stiffness K of the ligamentous sheath (paper, Elastic elements, eq. 2)."""

    stiffness: float = param(0.0, "N m/rad", "K; the paper's value is 15 N m/rad (its ref. 26). 0 = Figure 3.")
    convention: str = param(
        "physical",
        "",
        "'physical': K adds -K to dM/dalpha (i.e. -K/theta to d(omega')/dalpha). 'paper': eq. 2 as "
        "printed, -K subtracted from d(omega')/dalpha itself (K then read in 1/s^2). docs/model.md, Units of eq. 2.",
    )

    def __post_init__(self):
        _store(self, stiffness=v.non_negative("stiffness", self.stiffness))
        v.choice("convention", self.convention, ("physical", "paper"))


@dataclass(frozen=True)
class Local:
    """Local (intersegmental) muscles as a joint stiffness of the coupled chain (docs/chain.md).

    A local muscle of PCSA A at full activation pulls with F = specific_tension * A at the
    lever arm r of one joint; its short-range stiffness q F / l (Bergmark 1989,
    doi:10.3109/17453678909154177) gives the joint the rotational stiffness q F r^2 / l.
    """

    stiffness_gain: float = param(
        10.0,
        "1",
        "Dimensionless q of the muscle stiffness k = q F / l (Bergmark 1989, doi:10.3109/17453678909154177; "
        "used for spine stability by Cholewicki & McGill 1996, doi:10.1016/0268-0033(95)00035-6). 10 is "
        "spinectl's assumption, not a measurement: Brown et al. 2010 (doi:10.1080/10255841003630652) find "
        "q falling with activation. Local PCSAs scale with 1/q.",
    )
    lever_arm: float = param(
        0.07,
        "m",
        "Lever arm r of a local muscle about its joint (paper, Discussion: a conservative 7.0 cm, so that "
        "its +-30 N m limit is a PCSA of 17 cm^2).",
    )
    length: float = param(
        0.035,
        "m",
        "Length l of a local muscle in k = q F / l: one motion segment, the mean spacing of the paper's "
        "centres of rotation, (145 - 5 mm) / 4 = 35 mm.",
    )
    cost_weight: float = param(
        1.0,
        "1",
        "Weight w of the local PCSA against the global PCSA in the joint optimum of the coupled chain "
        "(docs/chain.md): 1 counts a cm^2 of local muscle like a cm^2 of global muscle.",
    )

    def __post_init__(self):
        _store(
            self,
            stiffness_gain=v.positive("stiffness_gain", self.stiffness_gain),
            lever_arm=_length("lever_arm", self.lever_arm),
            length=_length("length", self.length),
            cost_weight=v.non_negative("cost_weight", self.cost_weight),
        )


@dataclass(frozen=True)
class Levels:
    """The lumbar levels as bodies of the coupled chain: their inertia and weight (docs/chain.md).

    One body per vertebral level between two neighbouring centres of rotation (L2 to L5
    for the paper's five CoRs), a slice of the trunk with its centre of mass on the line
    of gravity (x = 0, like the upper body's point mass) halfway up between its CoRs. The
    per-segment analysis (eq. 1) has no such bodies; they make the chain's mass matrix
    regular (the point mass alone gives it rank 2).
    """

    mass: float = param(
        1.8,
        "kg",
        "Mass of each lumbar level (a slice of the trunk between two CoRs). The default, 1.8 kg, is 2.5 % of "
        "a 73 kg body, within "
        "the per-vertebral-level masses measured by CT (1.1 % at T1 rising to 2.6 % at L5; Pearsall, Reid "
        "and Livingston 1996, doi:10.1007/BF02667349). 0 removes the levels (the paper's point mass alone).",
    )
    radius_of_gyration: float = param(
        0.06,
        "m",
        "Radius of gyration of a level about its centre of mass for sagittal rotation. The default, 0.06 m, "
        "is spinectl's estimate: a uniform slab of the abdomen's sagittal depth d of about 0.2 m, "
        "sqrt(d^2 / 12) = 0.058 m.",
    )
    weight_in_gravity: float = param(
        0.0,
        "1",
        "Fraction of the levels' weight that enters the chain's gravity stiffness K_g (docs/chain.md, "
        "'The weight of the levels'). 0 (default): the levels carry inertia only, so the diagonal of K stays "
        "the paper's S_k; 1: their full weight, each level an inverted pendulum on the joints below it.",
    )

    def __post_init__(self):
        _store(
            self,
            mass=v.non_negative("mass", self.mass),
            radius_of_gyration=_length("radius_of_gyration", self.radius_of_gyration, allow_zero=True),
            weight_in_gravity=v.in_range("weight_in_gravity", self.weight_in_gravity, 0.0, 1.0),
        )


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
            stability_margin=v.non_negative("stability_margin", self.stability_margin),
            relative_margin=v.in_range("relative_margin", self.relative_margin, 0.0, 1.0),
            damping_margin=v.non_negative("damping_margin", self.damping_margin),
            pcsa_max=pmax,
            ct_tolerance=v.non_negative("ct_tolerance", self.ct_tolerance),
            solver_tolerance=v.in_range("solver_tolerance", self.solver_tolerance, *SOLVER_TOLERANCE_RANGE),
        )


@dataclass(frozen=True)
class Reflex:
    """Delayed PD reflex per segment and its time-domain simulation (docs/reflex.md, "The loop").

    Beyond the paper, which discusses reflexes in words only (Discussion: "reflexes are
    delayed by up to 100 ms ... the force generation of the muscles takes another
    50-100 ms"). The reflex command -(kp alpha + kd omega)(t - delay) becomes the torque u
    through the force-generation lag T_a u' + u = command (``activation_time_constant``); see
    ``docs/reflex.md`` for the default gain rule and the margins.
    """

    delay: float = param(
        0.1,
        "s",
        "Reflex delay tau. The paper's Discussion: reflexes follow a perturbation by up to 100 ms "
        f"(force generation adds another 50-100 ms). 0 to {MAX_DELAY:g} s.",
    )
    activation_time_constant: float = param(
        0.05,
        "s",
        "Force generation (excitation-contraction dynamics) of the reflex torque as a first-order lag "
        "1/(T_a s + 1) after the delay. The paper's Discussion: force generation takes another 50-100 ms. "
        "Default 50 ms: the contraction time constants (tau1 = tau2 = 50 ms) of active human muscle at "
        "about 20 % of maximum effort (Zahalak GI, Heyman SJ 1979, J Biomech Eng 101:28-37, "
        "doi:10.1115/1.3426220); spinectl keeps one of the two. 0 is the pure delay; at most "
        f'{MAX_ACTIVATION_TIME_CONSTANT:g} s (docs/reflex.md, "Force generation: the activation lag").',
    )
    pade_order: int = param(
        5, "1", f"Order of the Pade approximant of exp(-s tau) in the python-control models, 1 to {MAX_PADE_ORDER}."
    )
    activation: float = param(
        0.5,
        "1",
        "Global-muscle activation as a fraction of the minimum stabilising PCSA (optimise.solve_point): "
        f"0 = no co-contraction, reflex only; 1 = self-stable, no reflex needed; at most {MAX_ACTIVATION:g}.",
    )
    gains: str = param(
        "rule",
        "",
        "'rule': kp and kd from the default rule (gain_factor, damping_ratio); 'explicit': the kp and kd below.",
    )
    gain_factor: float = param(
        1.5,
        "1",
        "Default rule: kp = gain_factor * max(S, 0), the stiffness deficit below self-stability times this "
        "factor (> 1, so that the net stiffness kp - S is positive). 1.5 leaves half the deficit as net "
        "stiffness and, with damping_ratio 1, gives the reflex-only spine about the largest delay margin "
        "the rule can (docs/reflex.md).",
    )
    damping_ratio: float = param(
        1.0,
        "1",
        "Default rule: kd = max(0, 2 zeta sqrt(theta (kp - S)) + D), the derivative gain that gives the "
        "delay-free closed loop this damping ratio zeta (1: critical damping), after the muscles' own "
        "damping D <= 0.",
    )
    kp: float = param(0.0, "N m/rad", "Proportional reflex gain, used when gains = 'explicit'.")
    kd: float = param(0.0, "N m s/rad", "Derivative reflex gain, used when gains = 'explicit'.")
    sim_duration: float = param(
        12.0, "s", "Length of a nonlinear simulation; should span several periods of the slowest oscillation."
    )
    sim_time_step: float = param(
        0.004, "s", "Fixed RK4 step of the simulation (reduced to the delay when the delay is shorter)."
    )
    sim_perturbation: float = param(
        1e-3, "rad", "Initial angle: the segment is held at this angle (omega = 0) and released at t = 0."
    )
    sim_divergence: float = param(
        0.2,
        "rad",
        "A simulation stops as unstable once |alpha| exceeds this angle (the linear verdict no longer holds).",
    )

    def __post_init__(self):
        factor = v.real("gain_factor", self.gain_factor)
        if factor <= 1.0:
            raise ParameterError("gain_factor", f"must be > 1, or the reflex cannot stabilise (got {factor:g})")
        v.choice("gains", self.gains, ("rule", "explicit"))
        duration = v.positive("sim_duration", self.sim_duration)
        step = v.positive("sim_time_step", self.sim_time_step)
        if step >= duration:
            raise ParameterError("sim_time_step", f"must be < sim_duration = {duration:g} s (got {step:g})")
        limit = v.positive("sim_divergence", self.sim_divergence)
        if limit > math.pi / 2:
            raise ParameterError("sim_divergence", f"must be <= pi/2 rad, a quarter turn (got {limit:g})")
        kick = v.positive("sim_perturbation", self.sim_perturbation)
        if kick >= limit:
            raise ParameterError("sim_perturbation", f"must be < sim_divergence = {limit:g} rad (got {kick:g})")
        _store(
            self,
            delay=_seconds("delay", self.delay, MAX_DELAY),
            activation_time_constant=_seconds(
                "activation_time_constant", self.activation_time_constant, MAX_ACTIVATION_TIME_CONSTANT
            ),
            pade_order=v.integer("pade_order", self.pade_order, 1, MAX_PADE_ORDER),
            activation=v.in_range("activation", self.activation, 0.0, MAX_ACTIVATION),
            gain_factor=factor,
            damping_ratio=v.positive("damping_ratio", self.damping_ratio),
            kp=v.non_negative("kp", self.kp),
            kd=v.non_negative("kd", self.kd),
            sim_duration=duration,
            sim_time_step=step,
            sim_perturbation=kick,
            sim_divergence=limit,
        )


@dataclass(frozen=True)
class Model:
    """The whole parameter set of one spinectl model."""

    body: Body = field(default_factory=Body, metadata={"doc": "Upper-body mass and inertia."})
    geometry: Geometry = field(default_factory=Geometry, metadata={"doc": "Spine line and CoRs."})
    fibre: Fibre = field(default_factory=Fibre, metadata={"doc": "Muscle fibre properties."})
    muscles: tuple[MusclePair, ...] = field(
        default_factory=_default_muscles, metadata={"doc": "The antagonistic pairs of global muscles."}
    )
    passive: Passive = field(default_factory=Passive, metadata={"doc": "Passive stiffness K."})
    local: Local = field(default_factory=Local, metadata={"doc": "Local muscles of the coupled chain."})
    levels: Levels = field(default_factory=Levels, metadata={"doc": "Lumbar levels of the coupled chain."})
    errata: Errata = field(default_factory=Errata, metadata={"doc": "Printed formula or correction."})
    optimisation: Optimisation = field(default_factory=Optimisation, metadata={"doc": "Optimiser settings."})
    reflex: Reflex = field(default_factory=Reflex, metadata={"doc": "Delayed reflex and its simulation."})

    def __post_init__(self):
        for f in dataclasses.fields(self):  # each section's default factory is its class
            section = getattr(self, f.name)
            if f.name != "muscles" and not isinstance(section, f.default_factory):
                raise ParameterError(f.name, f"must be a {f.default_factory.__name__} (got {v.show(section)})")
        muscles = self.muscles
        if isinstance(muscles, MusclePair) or not isinstance(muscles, (tuple, list)):
            raise ParameterError("muscles", f"must be a list of MusclePair (got {v.show(muscles)})")
        if not muscles:
            raise ParameterError("muscles", "must list at least one muscle pair")
        n_cors = len(self.geometry.cor_heights)  # the model's bound: a bare Geometry may sample a line finely
        if n_cors > MAX_CORS:
            raise ParameterError(
                "geometry.cor_heights",
                f"must have at most {MAX_CORS} centres of rotation, the joints of the whole spine (got {n_cors})",
            )
        if len(muscles) > MAX_MUSCLE_PAIRS:  # before the pairwise checks: their cost grows with the square
            raise ParameterError(
                "muscles",
                f"must list at most {MAX_MUSCLE_PAIRS} pairs: the optimisation's cost grows combinatorially "
                f"with the muscles (got {len(muscles)})",
            )
        for i, pair in enumerate(muscles):
            if not isinstance(pair, MusclePair):
                raise ParameterError(f"muscles.{i}", f"must be a MusclePair (got {v.show(pair)})")
            if pair.name in [m.name for m in muscles[:i]]:
                raise ParameterError(f"muscles.{i}.name", f"must be unique among the pairs (repeated: {pair.name!r})")
        _store(self, muscles=tuple(muscles))
        terms = len(SIDES) * sum(pair.fibres for pair in muscles) * n_cors
        if terms > MAX_FIBRE_TERMS:
            raise ParameterError(
                "muscles",
                f"must have at most {MAX_FIBRE_TERMS:,} fibre-CoR terms (fibres of every muscle x the "
                f"{n_cors} CoRs; got {terms:,}): use fewer fibres",
            )
        top = self.geometry.cor_heights[0]
        if self.body.mass_height <= top:
            # every segment is an inverted pendulum: the mass above the joint (docs/model.md, Gravity)
            raise ParameterError(
                "body.mass_height",
                f"must lie above the top centre of rotation {self.geometry.cor_names[0]} at {top:g} m "
                f"(got {self.body.mass_height:g})",
            )

    @property
    def muscle_names(self) -> tuple[str, ...]:
        """Names of the individual muscles, ``<pair>_<side>``, in column order."""
        return tuple(f"{m.name}_{side}" for m in self.muscles for side in SIDES)

    @property
    def pair_names(self) -> tuple[str, ...]:
        """Names of the antagonistic pairs."""
        return tuple(m.name for m in self.muscles)

    def replace(self, **changes) -> Model:
        """Return a copy with top-level sections replaced (see :func:`dataclasses.replace`).

        Returns
        -------
        Model
            A new, validated model; ``self`` is unchanged.
        """
        return dataclasses.replace(self, **changes)
