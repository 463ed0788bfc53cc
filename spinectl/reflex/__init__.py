"""Delayed reflexes: the PD reflex loop of each segment, its delay margins, simulation and plots (docs/reflex.md).

The vectorised functions are re-exported here (``reflex.delay_margin(S, D, theta, kp, kd)``);
python-control and matplotlib are imported only by the modules that need them. The modules:
CONTRIBUTING.md's map; symbols and units: docs/glossary.md.
"""

from .delay import (
    DELAY_INDEPENDENT,
    FINITE,
    STATUS,
    UNDEFINED,
    UNSTABLE_WITHOUT_DELAY,
    Crossings,
    DelayMargin,
    WithoutDelay,
    critical_gains,
    crossings,
    delay_margin,
    phase_margin,
    right_half_plane_roots,
    stable_at_delay,
    stable_without_delay,
    without_delay,
)
from .gains import default_gains, resolve_gains
from .maps import ReflexLandscape, landscape
from .pade import pade_coefficients, pade_convergence, pade_delay_margin, pade_inverse_lag, pade_phase_lag

__all__ = [
    "DELAY_INDEPENDENT",
    "FINITE",
    "STATUS",
    "UNDEFINED",
    "UNSTABLE_WITHOUT_DELAY",
    "Crossings",
    "DelayMargin",
    "WithoutDelay",
    "ReflexLandscape",
    "critical_gains",
    "crossings",
    "default_gains",
    "delay_margin",
    "landscape",
    "pade_coefficients",
    "pade_convergence",
    "pade_delay_margin",
    "pade_inverse_lag",
    "pade_phase_lag",
    "phase_margin",
    "resolve_gains",
    "right_half_plane_roots",
    "stable_at_delay",
    "stable_without_delay",
    "without_delay",
]
