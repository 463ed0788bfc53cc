"""Delayed, lagged PD reflex of one segment: exact delay margins, root counting, critical gains.

Pure vectorised numpy functions of arrays (any broadcastable shapes) of the
segment's stiffness S = dM/dalpha [N m/rad], damping D = dM/domega
[N m s/rad], inertia theta [kg m^2] and the reflex gains kp [N m/rad],
kd [N m s/rad], and the activation time constant T_a [s] of the force generation
(``lag``, 0 by default: the pure delay); no python-control object per point (the loop
and the derivations are in docs/reflex.md, "The loop", "Force generation: the
activation lag" and "Crossing frequencies and the exact delay margin"). The reflex
is beyond the paper, which discusses it in words only.

The linearised segment theta alpha'' = S alpha + D alpha' + u with the delayed reflex
command -(kp alpha + kd alpha')(t - tau), turned into the torque u by the lag
T_a u' + u = command, has the characteristic quasi-polynomial

    Delta(s, tau) = P(s) + Q(s) exp(-s tau),  P(s) = (T_a s + 1)(theta s^2 - D s - S),  Q(s) = kp + kd s.

A root crosses the imaginary axis at s = j w only where abs(Q(jw)) = abs(P(jw)), i.e.
F(w^2) = 0 with F(x) = (1 + T_a^2 x)(theta^2 x^2 + (2 S theta + D^2) x + S^2) - kp^2 - kd^2 x
(quadratic in x for T_a = 0, cubic otherwise), and then only at the delays
tau = (phi + 2 pi k) / w, phi = arg(-Q/P) mod 2 pi. The sign of F'(w^2) is the direction
of the crossing (Cooke and Grossman 1982 [1]_; Cooke and van den Driessche 1986 [2]_):
+ destabilising, - stabilising. With T_a = 0 every function returns what it did before
the lag existed, bit for bit.

Boundary cases (docs/reflex.md, "Boundary cases"): the delay-free loop is classified from
the signs of its coefficients after making the leading one positive, so a first-order
loop (theta = 0) does not depend on the sign convention; a pair on the imaginary axis at
tau = 0 (kd = D) is followed to the side it leaves to; the pure gain (theta = D = T_a =
kd = 0) has a closed form; loops of neutral type (kd != 0 with deg P <= 1) are refused.

References
----------
.. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
   switches. J Math Anal Appl 86:592-627.
.. [2] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
   equations. Funkcialaj Ekvacioj 29:77-90.

One module per method, on the delay-free loop below them:

- :mod:`~spinectl.reflex.delay.free`: the loop without delay (coefficients, Routh-Hurwitz, neutral loops refused);
- :mod:`~spinectl.reflex.delay.frequencies`: the crossing frequencies, roots of the quadratic or cubic F;
- :mod:`~spinectl.reflex.delay.margin`: the exact delay margin and its status codes;
- :mod:`~spinectl.reflex.delay.counting`: roots in the right half-plane, stability and phase margin at a delay;
- :mod:`~spinectl.reflex.delay.critical`: the critical gains at a delay.

Every name of these modules is also here: ``spinectl.reflex.delay.delay_margin``
as before the split.
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
