"""The bounds of the parameters and the helpers every section validates with.

Each bound says why it is where it is (a human body, a solver's precision, a sweep's
memory); :func:`param` gives a field its unit and doc, the metadata docs/parameters.md shows.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import field

from ... import _validate as v
from ...errors import ParameterError
from ...units import CM_PER_M, centimetre_slip

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

MAX_LOCAL_DAMPING = 10.0
"""Largest factor on the local muscles' force-velocity damping (``local.damping``): slow-twitch fibres alone
(``fibre.fast_twitch`` = 0, v_max = 6 instead of 11 l_opt/s, docs/model.md) have 1.8 times the default slope,
so 10 is beyond any fibre mix; a larger value is a typo, not a muscle."""

MAX_DELAY = 10.0
"""Longest reflex delay [s]: fifty times the slowest loop the paper names (100 ms plus
50-100 ms of force generation). A delay of 1e62 s, a unit typo, made the Padé
coefficients (tau^n) overflow and python-control's Nyquist plot warn; the exact delay
margin does not depend on tau, so nothing of interest lies beyond."""

MAX_ACTIVATION_TIME_CONSTANT = 1.0
"""Longest force-generation time constant of the reflex [s]: ten times the 100 ms the paper names as
the upper end of force generation; a value beyond it is more likely milliseconds typed as seconds."""

MAX_CURVE_POINTS = 1000
"""Most points of one curve of ``spinectl design`` (``--delays``, ``--passive``): a figure a thousand pixels wide
shows no more, and the table has a row each."""

MAX_DESIGNS = 10_000
"""Most designs of a design curve, delays times lags: each takes about 50 ms
(:data:`spinectl.landscape.budget.DESIGN_SECONDS`), so some 8 minutes here; more (1000 delays for 200 lags
took 200,000 designs, some 3 hours) is likelier a list typed wrong than a plan."""

MAX_PASSIVE_STIFFNESS = 1e4
"""Largest passive stiffness of ``design --passive`` [N m/rad]: some 650 times the paper's 15 N m/rad and far
beyond the stiffness from which the chain needs no muscle at all, where the curve is flat."""

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

MAX_STABILITY_MARGIN = MAX_MASS * MAX_GRAVITY * MAX_BODY_LENGTH
"""Largest required stiffness margin ``optimisation.stability_margin`` [N m/rad]: the gravity stiffness m g r of
the heaviest, tallest body the bounds allow (1000 kg, 30 m/s^2, 1 m: 3e4 N m/rad), more than any segment must
overcome. A margin of 1e308 overflowed the problem's equilibration (numpy's overflow warnings, then a false
"no activation stabilises")."""

MAX_DAMPING_MARGIN = 2.0 * math.sqrt(MAX_MASS * MAX_BODY_LENGTH**2 * MAX_STABILITY_MARGIN)
"""Largest required damping ``optimisation.damping_margin`` [N m s/rad]: the critical damping 2 sqrt(theta S) of
the same body (theta = m r^2 = 1000 kg m^2, S = 3e4 N m/rad: 1.1e4 N m s/rad). The paper's segments need about
0.4 N m s/rad per cm^2 of PCSA (a margin of 100 took 247 cm^2 at E = Lambda = 0), so the bound already asks for
some 27,000 cm^2; a margin of 1e308 overflowed the arithmetic (four warning lines before the error)."""

MAX_CT_TOLERANCE = 1.0
"""Largest ``optimisation.ct_tolerance`` [1]: a slack of 100 % lets the counter-torque problem take twice the
minimum PCSA, which no longer minimises it; 1e308 overflowed the slackened bound (numpy's warnings)."""


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


def seconds(name: str, value, high: float) -> float:
    """A time in [0, high] s, with the hint for milliseconds typed as seconds.

    The one check of a delay or an activation lag, whether a parameter (``reflex.delay``) or a
    design curve's axis (``design --delays``, ``--lags``), so the same quantity has the same bound.

    Parameters
    ----------
    name : str
        The field or option, as named in the error.
    value : object
        The time [s].
    high : float
        The bound [s], e.g. :data:`MAX_ACTIVATION_TIME_CONSTANT`.

    Returns
    -------
    float
        The time [s].

    Raises
    ------
    ParameterError
        Not a finite number, or outside [0, high], with ``if you meant ... ms`` where that fits.
    """
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


def _curve(name: str, values, check) -> tuple[float, ...]:
    """A design curve's axis: each value checked by ``check``, at least one, none repeated."""
    items = tuple(check(name, x) for x in values)
    if not items:
        raise ParameterError(name, "must name at least one value")
    repeated = sorted(x for x, n in Counter(items).items() if n > 1)
    if repeated:
        raise ParameterError(name, f"must not repeat a value (repeated: {', '.join(f'{x:g}' for x in repeated)})")
    return items


def design_axes(delays, lags) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The delays and lags of a design curve, checked as ``reflex.delay`` and ``reflex.activation_time_constant``.

    Parameters
    ----------
    delays : iterable of float
        tau [s], each in [0, :data:`MAX_DELAY`].
    lags : iterable of float
        T_a [s], each in [0, :data:`MAX_ACTIVATION_TIME_CONSTANT`], the bound of ``--activation-lag``.

    Returns
    -------
    (tuple of float, tuple of float)
        The delays and the lags [s], as given.

    Raises
    ------
    ParameterError
        Named ``--delays`` or ``--lags``: a value out of its bound, none, a repeated value, or more than
        :data:`MAX_DESIGNS` designs (delays times lags) in all.
    """
    delays = _curve("--delays", delays, lambda name, x: seconds(name, x, MAX_DELAY))
    lags = _curve("--lags", lags, lambda name, x: seconds(name, x, MAX_ACTIVATION_TIME_CONSTANT))
    if len(delays) > MAX_CURVE_POINTS:
        raise ParameterError("--delays", f"must have at most {MAX_CURVE_POINTS:,} values (got {len(delays):,})")
    if len(delays) * len(lags) > MAX_DESIGNS:
        raise ParameterError(
            "--lags" if len(lags) > 1 else "--delays",
            f"must give at most {MAX_DESIGNS:,} designs, delays times lags, about 50 ms each "
            f"(got {len(delays):,} x {len(lags):,} = {len(delays) * len(lags):,})",
        )
    return delays, lags


def passive_axis(stiffnesses) -> tuple[float, ...]:
    """The passive stiffnesses of ``design --passive`` [N m/rad], each in [0, :data:`MAX_PASSIVE_STIFFNESS`].

    Parameters
    ----------
    stiffnesses : iterable of float
        K per joint [N m/rad].

    Returns
    -------
    tuple of float
        The stiffnesses [N m/rad].

    Raises
    ------
    ParameterError
        Named ``--passive``: a value out of range, none, repeated, or more than :data:`MAX_CURVE_POINTS`.
    """

    def check(name: str, value) -> float:
        value = v.non_negative(name, value)
        if value > MAX_PASSIVE_STIFFNESS:
            raise ParameterError(name, f"must be at most {MAX_PASSIVE_STIFFNESS:g} N m/rad per joint (got {value:g})")
        return value

    values = _curve("--passive", stiffnesses, check)
    if len(values) > MAX_CURVE_POINTS:
        raise ParameterError("--passive", f"must have at most {MAX_CURVE_POINTS:,} values (got {len(values):,})")
    return values
