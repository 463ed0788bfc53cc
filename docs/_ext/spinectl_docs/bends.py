"""``docs/reflex.md``'s design against the passive stiffness K and the design curve's readings, measured at the build.

- Against K: the chain's rule design of ``spinectl design --delay 0.12 --E 0.03 --Lambda 0.04 --K k`` on
  ``wagner2012`` for each K of :data:`STIFFNESSES` (:func:`spinectl.reflex.design.chain.chain_design` at the
  global PCSA the command uses, ``reflex.activation`` times the minimum stabilising PCSA at that K: the chain's
  part of the command alone, 3-5 s of CPU each, one BLAS thread), and ``design --passive 30:40:11``'s least K
  from which global muscles alone suffice (:func:`spinectl.reflex.design.passive_curve`, under a second).
- The curve: ``spinectl design --delays 0:0.2:41 --lags 0,0.05,0.1 --E 0.03 --Lambda 0.04 --mass 35 --K 10``
  (:func:`spinectl.reflex.design.delay_curve` on the page's subject, :data:`.reflex.SUBJECT`), about 7 s of CPU.

Each is computed once per build (module-level memos); about 30 s of CPU in all.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .reflex import SUBJECT
from .values import value

POSITION = (0.03, 0.04)
"""E and Lambda [m]."""

K_DELAY = 0.12
"""The delay of the designs against K [s]."""

STIFFNESSES = (0.0, 40.0, 80.0, 120.0, 160.0, 200.0)
"""The passive stiffnesses K of the designs against K [N m/rad]."""

PASSIVE_AXIS = np.linspace(30.0, 40.0, 11)
"""``design --passive 30:40:11``: the K scanned before the bisection of the threshold [N m/rad]."""

CURVE_DELAYS = np.linspace(0.0, 0.2, 41)
"""``--delays 0:0.2:41`` [s]."""

CURVE_LAGS = (0.0, 0.05, 0.1)
"""``--lags 0,0.05,0.1``: T_a [s]."""


def _and(texts) -> str:
    texts = list(texts)
    return ", ".join(texts[:-1]) + " and " + texts[-1]


@cache
def against_k(k: float):
    """The chain's rule design at K = k [N m/rad] (``design --delay 0.12 --K k``): (global PCSA [m^2], ChainDesign)."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design.chain import chain_design

    model = set_parameters(load_preset("wagner2012"), {"reflex.delay": K_DELAY, "passive.stiffness": float(k)})
    with one_blas_thread():
        pcsa = model.reflex.activation * np.asarray(solve_point(model, *POSITION).pcsa, float)
        return float(np.sum(pcsa)), chain_design(model, *POSITION, pcsa, model.reflex.activation)


@cache
def springs_only():
    """The chain's rule design of ``design --delay 0.12 --E 0.03 --Lambda 0.04 --mass 35 --K 10 --set
    local.damping=0``: the page's subject with its local muscles as springs only (a ChainDesign)."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design.chain import chain_design

    changes = SUBJECT | {"reflex.delay": K_DELAY, "local.damping": 0.0}
    model = set_parameters(load_preset("wagner2012"), changes)
    with one_blas_thread():
        pcsa = model.reflex.activation * np.asarray(solve_point(model, *POSITION).pcsa, float)
        return chain_design(model, *POSITION, pcsa, model.reflex.activation)


def springs_share() -> str:
    """What the delayed reflex carries of k* with springs-only local muscles, in words."""
    share = 100 * (1 - springs_only().fraction)
    return "almost none of it" if share < 1 else f"{share:.0f} % of it"


@cache
def passive():
    """``spinectl design --passive 30:40:11 --E 0.03 --Lambda 0.04`` on ``wagner2012``."""
    from spinectl.model.config import load_preset
    from spinectl.reflex.design import passive_curve

    return passive_curve(load_preset("wagner2012"), *POSITION, PASSIVE_AXIS)


@cache
def curve():
    """``spinectl design --delays 0:0.2:41 --lags 0,0.05,0.1 --E 0.03 --Lambda 0.04 --mass 35 --K 10``."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.reflex.design import delay_curve

    with one_blas_thread():
        return delay_curve(set_parameters(load_preset("wagner2012"), SUBJECT), *POSITION, CURVE_DELAYS, CURVE_LAGS)


@cache
def springs_curve():
    """``design --delays 0:0.2:41 --lags 0,0.05,0.1 --E 0.03 --Lambda 0.04 --mass 35 --K 10 --set
    local.damping=0``: the subject's curve with the local muscles as springs only (about 2 s of CPU)."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.reflex.design import delay_curve

    model = set_parameters(load_preset("wagner2012"), SUBJECT | {"local.damping": 0.0})
    with one_blas_thread():
        return delay_curve(model, *POSITION, CURVE_DELAYS, CURVE_LAGS)


def springs_least() -> str:
    """The least f of the springs-only curve from 10 ms, every lag, rounded down: ``at least 0.999``."""
    c = springs_curve()
    least = float(np.min(c.local_fraction[:, c.delays >= 0.01 - 1e-12]))
    return f"at least {np.floor(1e3 * least) / 1e3:.3f}"


def _at(array, lag: float, delay: float) -> float:
    """The curve's value at the lag and delay [s] (both on the curve's axes)."""
    c = curve()
    return float(array[int(np.argmin(np.abs(c.lags - lag))), int(np.argmin(np.abs(c.delays - delay)))])


def fraction(lag: float, delay: float) -> float:
    """The chain's f (of k*) at the lag and delay."""
    return _at(curve().local_fraction, lag, delay)


def activation(lag: float, delay: float) -> float:
    """The joint-by-joint activation (of the minimum PCSA) at the lag and delay."""
    return _at(curve().activation, lag, delay)


def free_until(lag: float) -> str:
    """The longest delay of the curve's grid up to which no co-contraction is needed joint by joint [ms]."""
    c = curve()
    row = c.activation[int(np.argmin(np.abs(c.lags - lag)))]
    needed = np.flatnonzero(row > 0)
    last = c.delays[needed[0] - 1] if needed.size else c.delays[-1]
    return f"{1e3 * last:.0f} ms"


def plateau(lag: float) -> str:
    """``0.83 at 5 ms to 0.84 from 30 ms``: f at the first nonzero delay and from where it stops changing."""
    c = curve()
    row = c.local_fraction[int(np.argmin(np.abs(c.lags - lag)))]
    first = int(np.flatnonzero(c.delays > 0)[0])
    flat = int(np.flatnonzero(np.isclose(row, row[-1], rtol=0, atol=1e-9))[0])
    return f"{row[first]:.2f} at {1e3 * c.delays[first]:.0f} ms to {row[-1]:.2f} from {1e3 * c.delays[flat]:.0f} ms"


value("reflex.k_pcsa")(lambda: _and(f"{1e4 * against_k(k)[0]:.2f}" for k in STIFFNESSES))
value("reflex.k_local")(lambda: _and(f"{np.sum(against_k(k)[1].local_stiffness):.0f}" for k in STIFFNESSES))
value("reflex.k_fraction")(lambda: ", ".join(f"{against_k(k)[1].fraction:.3f}" for k in STIFFNESSES))
value("reflex.k_static")(lambda: ", ".join(f"{np.sum(against_k(k)[1].least_static):.0f}" for k in STIFFNESSES))
value("reflex.passive_threshold")(lambda: f"{passive().threshold:.2f}")
value("reflex.curve_free")(
    lambda: (
        f"{free_until(0.0)} without lag, {free_until(0.05)} with T_a = 50 ms and {free_until(0.1)} with T_a = 100 ms"
    )
)
value("reflex.curve_free_50")(lambda: free_until(0.05))
value("reflex.curve_activation_120_slow")(lambda: f"{activation(0.1, 0.12):.3f}")
value("reflex.curve_activation_200_slow")(lambda: f"{activation(0.1, 0.2):.3f}")
value("reflex.curve_f_5")(lambda: f"{fraction(0.05, 0.005):.2f}")
value("reflex.curve_f_40")(lambda: f"{fraction(0.05, 0.04):.2f}")
value("reflex.curve_f_200")(lambda: f"{fraction(0.05, 0.2):.2f}")
value("reflex.curve_f_slow")(lambda: _and(f"{fraction(0.1, d):.2f}" for d in (0.005, 0.04, 0.12, 0.2)))
value("reflex.curve_f_no_lag")(lambda: plateau(0.0))
value("reflex.subject_f_120_springs")(lambda: f"{springs_only().fraction:.4f}")
value("reflex.subject_share_120_springs")(springs_share)
value("reflex.curve_springs_least")(springs_least)


@cache
def springs_only_wagner():
    """The chain's rule design of ``design --delay 0.12 --E 0.03 --Lambda 0.04 --set local.damping=0`` on
    ``wagner2012`` at its own K (a ChainDesign): the page's example of a margin the table writes in s."""
    from spinectl._threads import one_blas_thread
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design.chain import chain_design

    model = set_parameters(load_preset("wagner2012"), {"reflex.delay": K_DELAY, "local.damping": 0.0})
    with one_blas_thread():
        pcsa = model.reflex.activation * np.asarray(solve_point(model, *POSITION).pcsa, float)
        return chain_design(model, *POSITION, pcsa, model.reflex.activation)


def seconds_example() -> str:
    """'f = 0.998 is 329.8 s': the example of a delay the table writes in s (a margin of 1 s or more)."""
    design = springs_only_wagner()
    if not 1.0 <= design.delay_margin < np.inf:
        raise RuntimeError(f"docs/reflex.md's example of a margin in s has {design.delay_margin} s")
    return f"f = {design.fraction:.3f} is {design.delay_margin:.1f} s"


value("reflex.seconds_example")(seconds_example)
