"""Delayed reflexes: the PD reflex loop of each segment, its delay margins, simulation and plots.

docs/reflex.md. Pure vectorised numpy functions for the exact delay margin
(:mod:`~spinectl.reflex.delay`), its Padé estimates (:mod:`~spinectl.reflex.pade`),
the gains (:mod:`~spinectl.reflex.gains`) and their maps over a landscape
(:mod:`~spinectl.reflex.maps`); above them the python-control objects
(:mod:`~spinectl.reflex.loops`), the exact delay margin of any SISO loop
(:mod:`~spinectl.reflex.siso`, also ``spinectl.loop_delay_margin``), the exact delay margin of the
coupled chain under a diagonal reflex (:mod:`~spinectl.reflex.mimo`; the chain's loop and disk
margins in :mod:`~spinectl.reflex.chain_system`, its report in :mod:`~spinectl.reflex.chain_margins`),
the nonlinear simulation
(:mod:`~spinectl.reflex.simulate`),
the report of one configuration (:mod:`~spinectl.reflex.margins`) and its plots
(:mod:`~spinectl.reflex.plots`).

The vectorised functions are re-exported here (``reflex.delay_margin(S, D, theta, kp, kd)``);
python-control and matplotlib are imported only by the modules that need them.

Symbols and units: docs/glossary.md.
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
