"""The inputs of the public reflex functions, checked once for all of them.

The CLI validates a reflex through :class:`spinectl.model.params.Reflex`; a
caller of the library passes arrays straight to :func:`~spinectl.reflex.delay_margin`
and its neighbours. :func:`validated` gives every public function the same
checks, by the names of its arguments, before any arithmetic: a bool, a text
or a complex number where a real number belongs (``kp=True``, ``kp='200'``), a negative or
zero inertia, magnitudes whose powers overflow, a negative or
absurd delay and a Padé order below 1 raise a
:class:`~spinectl.errors.ParameterError` naming the argument; NaN stays
allowed (an infeasible point: the answer is NaN with status ``undefined``).
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import inspect
import numbers

import numpy as np

from .. import _validate as v
from ..errors import ParameterError
from ..model.params import MAX_DELAY

MAX_MAGNITUDE = float(np.finfo(float).max) ** 0.25
"""Largest magnitude of S, D, theta, kp, kd (about 1.2e77, in their SI units).

The crossing polynomial F(w^2) = theta^2 w^4 + (2 S theta + D^2 - kd^2) w^2 + S^2 - kp^2
(docs/reflex.md, "Crossing frequencies and the exact delay margin") multiplies up to
four of them; below this bound no such product overflows a float."""

SIGNED = ("stiffness", "damping", "kp", "kd")
"""Arguments of any sign: S [N m/rad], D [N m s/rad] and the gains [N m/rad], [N m s/rad]
(:func:`~spinectl.reflex.critical_gains` finds stabilising intervals of negative kp too)."""

_INSIDE = contextvars.ContextVar("inside_reflex_api", default=False)
"""True while a validated function runs: its calls of other public functions, with
values of its own making (e.g. kp = inf as a probe), are not checked again."""


def validated(func=None, *, zero_inertia: bool = False):
    """Decorate a public reflex function so that its arguments are checked by name before it runs.

    Checked where present: ``stiffness``, ``damping``, ``inertia``, ``kp``, ``kd``
    (:func:`check_arrays`), ``delay`` and ``order``/``orders`` (:func:`check_delay`,
    :func:`check_order`).

    Parameters
    ----------
    func : callable
        The function.
    zero_inertia : bool
        Accept theta = 0, which the functions of :mod:`~spinectl.reflex.delay` and
        :mod:`~spinectl.reflex.pade` cover where the loop is retarded (their ``check_retarded``).

    Returns
    -------
    callable
        The function with the checks in front.
    """
    if func is None:
        return functools.partial(validated, zero_inertia=zero_inertia)
    signature = inspect.signature(func)
    arrays = (*SIGNED, "inertia", "delay")
    required = [p.name for p in signature.parameters.values() if p.default is p.empty and p.name in arrays]

    @functools.wraps(func)
    def checked(*args, **kwargs):
        if _INSIDE.get():
            return func(*args, **kwargs)
        given = signature.bind(*args, **kwargs).arguments
        for name in required:  # None where a value is required would read as NaN, an answer of "undefined"
            if name in given and given[name] is None:
                raise ParameterError(name, "must be real numbers (got None)")
        check_arrays(given, zero_inertia=zero_inertia)
        if given.get("delay") is not None:
            check_delay(given["delay"])
        if "order" in given:
            check_order(given["order"])
        for order in given.get("orders", ()):
            check_order(order, "orders")
        with guarded():
            return func(*args, **kwargs)

    return checked


@contextlib.contextmanager
def guarded():
    """Skip the checks of :func:`validated` inside the block: for library callers under their own guard.

    A sweep's reflex columns come from a validated model and run under
    :func:`spinectl.model.checks.arithmetic_guard`, which names the position and the
    likely unit typo when the arithmetic overflows; their S and D are not the user's
    to correct, so a bound on them would only blur that message.

    Yields
    ------
    None
        Inside the block the public reflex functions run unchecked.
    """
    token = _INSIDE.set(True)
    try:
        yield
    finally:
        _INSIDE.reset(token)


def check_arrays(given: dict, *, zero_inertia: bool = False) -> None:
    """Raise :class:`ParameterError` for a bad S, D, theta, kp or kd in ``given`` (by name).

    Parameters
    ----------
    given : dict
        Argument name -> value (array_like); names other than those checked are ignored.
    zero_inertia : bool
        Accept theta = 0.
    """
    arrays = {}
    for name in (*SIGNED, "inertia"):
        if given.get(name) is not None:
            arrays[name] = _floats(name, given[name])
            _bounded(name, arrays[name])
    if "inertia" in arrays:
        theta = arrays["inertia"]
        bad = theta < 0 if zero_inertia else theta <= 0
        _first("inertia", theta, bad, "must be >= 0" if zero_inertia else "must be > 0")
        # theta = 0 with kd != 0 is of neutral type unless the activation lag raises the degree of P:
        # spinectl.reflex.delay.check_retarded decides that, with the lag in view.


def check_delay(delay) -> None:
    """Raise :class:`ParameterError` unless every delay is in [0, ``MAX_DELAY``] s (or NaN).

    Parameters
    ----------
    delay : array_like
        tau [s].
    """
    tau = _floats("delay", delay)
    _first("delay", tau, np.isinf(tau) | (tau < 0) | (tau > MAX_DELAY), f"must be in [0, {MAX_DELAY:g}] s")


def check_order(order, name: str = "order") -> None:
    """Raise :class:`ParameterError` unless ``order`` is an integer >= 1.

    Parameters
    ----------
    order : int
        Padé order.
    name : str
        The argument's name, for the message.
    """
    v.integer(name, order.item() if isinstance(order, np.integer) else order, 1)


def _floats(name: str, value) -> np.ndarray:
    """``value`` as floats, if it holds real numbers only: not bools, strings (``'200'`` would convert) or complex."""
    try:
        raw = np.asarray(value)
        numeric = raw.dtype.kind in "iuf" or (
            raw.dtype.kind == "O"
            and all(isinstance(x, numbers.Real) and not isinstance(x, bool | np.bool_) for x in raw.flat)
        )
        if numeric:
            return np.asarray(raw, float)
    except (TypeError, ValueError, OverflowError):
        pass
    raise ParameterError(name, f"must be real numbers, not bools or text (got {v.show(value)})")


def _bounded(name: str, x: np.ndarray) -> None:
    _first(name, x, np.isinf(x) | (np.abs(x) > MAX_MAGNITUDE), f"must be finite, at most {MAX_MAGNITUDE:.3g}")


def _first(name: str, x: np.ndarray, bad, rule: str) -> None:
    bad = np.asarray(bad)
    if bad.any():
        raise ParameterError(name, f"{rule} (got {np.broadcast_to(x, bad.shape)[bad].flat[0]:g})")
