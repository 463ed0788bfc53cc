"""Benchmark: the reflex columns of the 81 x 81 grid, closed-form cubic and Newton inverse lag against the
companion matrix and the bisection they replaced, in the same run.

    python benchmarks/bench_reflex.py               # 81 x 81, default preset, best of 7
    python benchmarks/bench_reflex.py --points 161 --repeats 5

Builds what the sweep's reflex columns see (S, D, theta of every segment at the reflex's activation of the
chosen optimum, chunk by chunk as ``spinectl.landscape.columns`` does), then times, interleaved and best of
N in CPU time (``time.process_time``; the machine is shared): the roots of the crossing cubics, the inverse
of the Padé lag at the crossings' phases, the whole ``reflex.landscape`` and the whole fast sweep with
both old forms switched in. Prints each pair, their ratio and the largest relative difference of the answers.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from spinectl.landscape import sweep  # noqa: E402
from spinectl.landscape.columns import DEFAULT_CHUNK  # noqa: E402
from spinectl.model import config  # noqa: E402
from spinectl.model.checks import checked_coefficients  # noqa: E402
from spinectl.optimise import active_set  # noqa: E402
from spinectl.optimise.problem import problem_data  # noqa: E402
from spinectl.reflex import crossings, delay, landscape, pade  # noqa: E402
from spinectl.reflex.gains import resolve_gains  # noqa: E402


def chunks(model, points: int):
    """(S, D, theta) of each chunk of the grid at the reflex's activation, as the sweep's columns build them."""
    axis = np.linspace(0.0, 0.08, points)
    e, lam = (x.ravel() for x in np.meshgrid(axis, axis, indexing="ij"))
    out = []
    for start in range(0, e.size, DEFAULT_CHUNK):
        part = slice(start, start + DEFAULT_CHUNK)
        coeffs = checked_coefficients(model, e[part], lam[part])
        optimum = active_set.solve_block(problem_data(model, coeffs), model.optimisation.ct_tolerance)
        active = model.reflex.activation * optimum.pcsa
        out.append(delay.as_arrays(coeffs.stiffness(active), coeffs.damping(active), coeffs.inertia))
    return out


@contextlib.contextmanager
def reference_forms():
    """The companion matrix and the bisection in place of the closed form and Newton's method."""
    cubic, inverse = delay.frequencies._cubic_roots, pade.pade_inverse_lag
    delay.frequencies._cubic_roots, pade.pade_inverse_lag = delay._cubic_roots_companion, pade._inverse_lag_bisection
    try:
        yield
    finally:
        delay.frequencies._cubic_roots, pade.pade_inverse_lag = cubic, inverse


def interleaved(new, old, repeats: int):
    """Best CPU time [s] of each over ``repeats`` alternating calls, and the last answers."""
    best_new = best_old = np.inf
    for _ in range(repeats):
        start = time.process_time()
        answer_new = new()
        best_new = min(best_new, time.process_time() - start)
        start = time.process_time()
        answer_old = old()
        best_old = min(best_old, time.process_time() - start)
    return best_new, best_old, answer_new, answer_old


def largest_relative_difference(new, old) -> float:
    """Over the entries finite in ``old``; the non-finite ones must match exactly (else inf)."""
    new, old = np.asarray(new, float), np.asarray(old, float)
    finite = np.isfinite(old)
    if not np.array_equal(np.isfinite(new), finite) or not np.array_equal(new[~finite], old[~finite], equal_nan=True):
        return np.inf
    with np.errstate(invalid="ignore", divide="ignore"):
        return float(np.nanmax(np.abs(new[finite] - old[finite]) / np.abs(old[finite]), initial=0.0))


def report(name: str, new: float, old: float, difference: float | None = None) -> None:
    tail = "" if difference is None else f"   {difference:.1e}"
    print(f"{name:34} {1e3 * new:8.1f} ms {1e3 * old:8.1f} ms {old / new:8.1f}x{tail}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=81, help="grid points per axis (default 81)")
    parser.add_argument("--repeats", type=int, default=7, help="interleaved repeats (best of)")
    parser.add_argument("--preset", default=config.DEFAULT_PRESET)
    args = parser.parse_args()
    model = config.load_preset(args.preset)
    reflex_settings = model.reflex
    parts = chunks(model, args.points)
    lag = reflex_settings.activation_time_constant
    gains = [resolve_gains(s, d, theta, reflex_settings) for s, d, theta in parts]
    cubics = [delay.crossing_polynomial(*p, *g, lag) for p, g in zip(parts, gains, strict=True)]
    phases = [crossings(*p, *g, lag).phase for p, g in zip(parts, gains, strict=True)]
    order = reflex_settings.pade_order
    segments = sum(p[0].size for p in parts)
    grid = f"{args.points} x {args.points} grid"
    print(f"== reflex columns, {grid} ({segments} segments, T_a = {lag} s, Padé order {order})")
    print(f"{'':34} {'new':>11} {'before':>11} {'ratio':>9}   largest relative difference")

    def roots(method):
        return np.concatenate([np.sort(np.nan_to_num(method(*f)[0], nan=np.inf), axis=-1) for f in cubics])

    t_new, t_old, a, b = interleaved(
        lambda: roots(delay._cubic_roots), lambda: roots(delay._cubic_roots_companion), args.repeats
    )
    report("crossing cubics (closed form)", t_new, t_old, largest_relative_difference(a, b))

    def inverse(method):
        return np.concatenate([method(phase, order).ravel() for phase in phases])

    t_new, t_old, a, b = interleaved(
        lambda: inverse(pade.pade_inverse_lag), lambda: inverse(pade._inverse_lag_bisection), args.repeats
    )
    report("Padé inverse lag (Newton)", t_new, t_old, largest_relative_difference(a, b))

    def columns():
        return [landscape(*p, reflex_settings) for p in parts]

    def columns_before():
        with reference_forms():
            return columns()

    t_new, t_old, a, b = interleaved(columns, columns_before, args.repeats)
    report("reflex.landscape (all columns)", t_new, t_old)
    for field in ("delay_margin", "delay_margin_pade", "crossing_frequency", "delay_margin_status", "stable_at_delay"):
        new, old = (np.concatenate([getattr(x, field).ravel() for x in answer]) for answer in (a, b))
        print(f"  largest relative difference, {field:20} {largest_relative_difference(new, old):.1e}")
    axis = np.linspace(0.0, 0.08, args.points)

    def whole_sweep():
        return sweep.sweep(model, axis, axis, method="fast", progress=False)

    def whole_sweep_before():
        with reference_forms():
            return whole_sweep()

    t_new, t_old, a, b = interleaved(whole_sweep, whole_sweep_before, args.repeats)
    report("whole fast sweep (3 stages, reflex)", t_new, t_old)
    names = ("delay_margin_s", "delay_margin_pade_s", "min_pcsa_cm2", "counter_torque_norm_Nm")
    for name in names:
        difference = largest_relative_difference(a[name].values, b[name].values)
        print(f"  largest relative difference, {name:22} {difference:.1e}")
    print("(best CPU time of interleaved runs)")


if __name__ == "__main__":
    main()
