"""Delayed, lagged PD reflex of one segment: exact delay margins, root counting, critical gains.

Pure vectorised numpy functions of the segment's S [N m/rad], D [N m s/rad], theta [kg m^2], the
gains kp [N m/rad], kd [N m s/rad] and the activation lag T_a [s] (``lag``, 0: the pure delay), of
any broadcastable shapes. The characteristic quasi-polynomial is

    Delta(s, tau) = P(s) + Q(s) exp(-s tau),  P(s) = (T_a s + 1)(theta s^2 - D s - S),  Q(s) = kp + kd s;

a root crosses the imaginary axis at s = j w only where abs(Q(jw)) = abs(P(jw)), at the delays
tau = (phi + 2 pi k) / w, in the direction of the sign of F'(w^2) (Cooke and Grossman 1982 [1]_;
Cooke and van den Driessche 1986 [2]_). The derivation and the boundary cases are docs/reflex.md,
"The loop", "Crossing frequencies and the exact delay margin" and "Boundary cases". One module per
method (CONTRIBUTING.md's map), every name re-exported here.

References
----------
.. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
   switches. J Math Anal Appl 86:592-627.
.. [2] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
   equations. Funkcialaj Ekvacioj 29:77-90.
"""

from __future__ import annotations

from .counting import (
    phase_margin,
    right_half_plane_roots,
    stable_at_delay,
    stable_at_delay_of,
)
from .critical import (
    BISECTIONS,
    critical_gains,
)
from .free import (
    WithoutDelay,
    as_arrays,
    check_retarded,
    stable_without_delay,
    without_delay,
    without_delay_coefficients,
)
from .frequencies import (
    SLOTS,
    Crossings,
    crossing_polynomial,
    crossings,
    crossings_of,
)

# The fast root finder and its reference, which the tests compare and switch between.
from .frequencies import _cubic_candidates as _cubic_candidates
from .frequencies import _cubic_roots as _cubic_roots
from .frequencies import _cubic_roots_companion as _cubic_roots_companion
from .frequencies import _positive_roots as _positive_roots
from .margin import (
    DELAY_INDEPENDENT,
    FINITE,
    STATUS,
    UNDEFINED,
    UNSTABLE_WITHOUT_DELAY,
    DelayMargin,
    delay_margin,
    delay_margin_of,
    delay_text,
    margin_from_delays,
    pure_gain,
    undefined_inputs,
)

__all__ = [
    "BISECTIONS",
    "Crossings",
    "DELAY_INDEPENDENT",
    "DelayMargin",
    "FINITE",
    "SLOTS",
    "STATUS",
    "UNDEFINED",
    "UNSTABLE_WITHOUT_DELAY",
    "WithoutDelay",
    "as_arrays",
    "check_retarded",
    "critical_gains",
    "crossing_polynomial",
    "crossings",
    "crossings_of",
    "delay_margin",
    "delay_margin_of",
    "delay_text",
    "margin_from_delays",
    "phase_margin",
    "pure_gain",
    "right_half_plane_roots",
    "stable_at_delay",
    "stable_at_delay_of",
    "stable_without_delay",
    "undefined_inputs",
    "without_delay",
    "without_delay_coefficients",
]
