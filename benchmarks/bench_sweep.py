"""Benchmark: the fast path against the per-point reference, on the same grid in the same run.

    python benchmarks/bench_sweep.py                 # 81 x 81, coefficients, scaling, reproduce, 401 x 401 study
    python benchmarks/bench_sweep.py --points 41 --skip-scaling --skip-reproduce --skip-study
    python benchmarks/bench_sweep.py --variant independent --skip-scaling --skip-reproduce --skip-study

Prints the wall time of both paths (all three stages, the reflex columns and the coupled
margin: what a sweep computes), their ratio and the largest difference between their
answers (relative to each point's total PCSA or ||CT||, at least 1 N m); then the time to
build the coefficients of the grid against the floor of one fused numpy pass over its
fibre-CoR terms and against the per-fibre sums it replaced, and the coupled chain's matrices in the monomial
form against their per-fibre sums (interleaved, best of N); then the fast path's time and
working memory per grid point for growing grids (linear cost, flat memory); then the wall
time of ``spinectl reproduce`` end to end and of the 401 x 401 study on 2 local workers
(``benchmarks/bench_study.py``), each in a fresh interpreter. Timings on a shared machine
are noisy: the ratios and the differences are what matter.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from spinectl.landscape import sweep  # noqa: E402
from spinectl.landscape.columns import DEFAULT_CHUNK  # noqa: E402
from spinectl.model import chain, config, geometry, mechanics  # noqa: E402
from spinectl.model.params import Passive  # noqa: E402


def timed(function, repeats: int = 1):
    """Median wall time [s] over ``repeats`` calls, and the last result."""
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def largest_differences(fast, ref) -> dict[str, float]:
    """Largest relative differences between two sweeps, per quantity."""
    total = ref["min_pcsa_cm2"]
    norm = np.maximum(ref["counter_torque_norm_Nm"], 1.0)
    return {
        "min_pcsa": float(np.nanmax(abs(fast["min_pcsa_cm2"] - total) / total)),
        "pcsa (per muscle)": float(np.nanmax(abs(fast["pcsa_cm2"] - ref["pcsa_cm2"]).max("muscle") / total)),
        "||CT||": float(np.nanmax(abs(fast["counter_torque_norm_Nm"] - ref["counter_torque_norm_Nm"]) / norm)),
        "CT (per segment)": float(
            np.nanmax(abs(fast["counter_torque_Nm"] - ref["counter_torque_Nm"]).max("segment") / norm)
        ),
        "status mismatches": float((fast["status"] != ref["status"]).sum()),
    }


def compare(model, points: int, repeats: int) -> None:
    axis = np.linspace(0.0, 0.08, points)
    print(f"== fast path vs per-point reference, {points} x {points} grid (3 stages, reflex columns, coupled margin)")
    fast_time, fast = timed(lambda: sweep.sweep(model, axis, axis, method="fast", progress=False), repeats)
    print(f"fast path:  {fast_time:8.2f} s  (median of {repeats}; {fast.attrs['points_solved_per_point']} fell back)")
    ref_time, ref = timed(lambda: sweep.sweep(model, axis, axis, method="per-point", progress=None))
    print(f"per-point:  {ref_time:8.2f} s")
    print(f"ratio:      {ref_time / fast_time:8.1f} x faster")
    for name, value in largest_differences(fast, ref).items():
        print(f"largest difference, {name:18}: {value:.2e}")


def fused_pass_floor(model, eccentricity, lordosis) -> float:
    """Seconds of one fused numpy pass over the grid's fibre-CoR terms: the lever arm h = a + b cx + d cy of
    every fibre about every CoR (two multiply-adds per term) into a preallocated array; the least work
    any per-term method does."""
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)
    upper, lower, _ = geometry.all_fibres(model)
    e = lower - upper
    length = np.hypot(e[:, 0], e[:, 1])
    a, b, d = mechanics.cross2(upper, e) / length, -e[:, 1] / length, e[:, 0] / length
    out = np.empty(cor.shape[:-1] + a.shape)
    scratch = np.empty_like(out)
    start = time.perf_counter()
    np.multiply(cor[..., 0, None], b, out=out)
    np.multiply(cor[..., 1, None], d, out=scratch)
    np.add(out, scratch, out=out)
    np.add(out, a, out=out)
    return time.perf_counter() - start


def coefficients(model, points: int, repeats: int) -> None:
    axis = np.linspace(0.0, 0.08, points)
    e, lam = np.meshgrid(axis, axis, indexing="ij")
    terms = e.size * len(model.geometry.cor_heights) * len(geometry.all_fibres(model)[0])
    print(f"== coefficients of the {points} x {points} grid ({terms:,} fibre-CoR terms)")
    kernel, _ = timed(lambda: mechanics.segment_coefficients(model, e, lam), repeats)
    before, _ = timed(lambda: mechanics.per_fibre_sums(model, e, lam), repeats)
    floor = min(fused_pass_floor(model, e, lam) for _ in range(repeats))
    print(f"segment_coefficients (monomial form): {1e3 * kernel:8.1f} ms")
    print(f"per-fibre sums (before):              {1e3 * before:8.1f} ms")
    print(f"floor, one fused pass over the terms: {1e3 * floor:8.1f} ms")
    print(f"kernel / floor: {kernel / floor:.2f}x (target <= 3x); per-fibre sums / kernel: {before / kernel:.1f}x")
    chain_coefficients(model, e.ravel(), lam.ravel(), repeats)


def chain_coefficients(model, eccentricity, lordosis, repeats: int) -> None:
    """The coupled chain's matrices in the sweep's chunks: monomial form against per-fibre sums, interleaved.

    Best of ``repeats`` for each, alternating, so that both see the same load. The per-fibre sums
    build the muscle matrices only (no gravity, no passive term), so the ratio understates the gain.
    """
    forms = {"monomial form": chain.chain_coefficients, "per-fibre sums": chain.chain_per_fibre_sums}
    best = dict.fromkeys(forms, np.inf)
    for _ in range(repeats):
        for name, function in forms.items():
            start = time.perf_counter()
            for first in range(0, eccentricity.size, DEFAULT_CHUNK):
                part = slice(first, first + DEFAULT_CHUNK)
                function(model, eccentricity[part], lordosis[part])
            best[name] = min(best[name], time.perf_counter() - start)
    chunks = -(-eccentricity.size // DEFAULT_CHUNK)
    print(f"chain_coefficients (monomial form), {chunks} chunks: {1e3 * best['monomial form']:8.1f} ms")
    print(f"chain per-fibre sums (before), same chunks: {1e3 * best['per-fibre sums']:8.1f} ms")
    print(f"per-fibre sums / monomial form: {best['per-fibre sums'] / best['monomial form']:.1f}x (best of {repeats})")


def scaling(model, sizes) -> None:
    """Time untraced; then the peak of traced allocations beyond the answer's own size."""
    print("== fast path: cost and working memory against grid size")
    print(f"{'grid':>9} {'points':>7} {'time [s]':>9} {'us/point':>9} {'working memory [MB]':>20}")
    for n in sizes:
        axis = np.linspace(0.0, 0.08, n)
        seconds, _ = timed(lambda axis=axis: sweep.sweep(model, axis, axis, progress=False))
        tracemalloc.start()
        result = sweep.sweep(model, axis, axis, progress=False)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        working = (peak - result.nbytes) / 1e6  # the answer itself must grow with the grid
        print(f"{n:>4} x{n:>4} {n * n:>7} {seconds:>9.2f} {1e6 * seconds / n**2:>9.0f} {working:>20.1f}")


def study(points: int) -> None:
    from bench_study import STUDY, run

    print(f"== spinectl study, {points} x {points} grid, 2 local workers, fresh interpreter")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "study.toml"
        path.write_text(STUDY.format(n=points))
        command = [sys.executable, "-m", "spinectl", "study", str(path), "--out", str(Path(folder) / "s.zarr")]
        r = run([*command, "--workers", "2"])
    print(f"wall time:  {r['wall']:8.2f} s ({r['run']:.2f} s the run's own; load average {r['load']:.2f} at start)")


def reproduce() -> None:
    print("== spinectl reproduce, end to end in a fresh interpreter (imports, K = 0 and 15, figures, report)")
    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "spinectl", "reproduce", "--out", out]
        seconds, proc = timed(lambda: subprocess.run(command, cwd=ROOT, capture_output=True, text=True, check=False))
    print(f"wall time:  {seconds:8.2f} s (exit code {proc.returncode})")
    if proc.returncode:
        print(proc.stderr)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=81, help="grid points per axis (default 81: 1 mm)")
    parser.add_argument("--repeats", type=int, default=3, help="fast-path repeats (median)")
    parser.add_argument("--preset", default="default")
    parser.add_argument(
        "--variant", choices=("paired", "independent", "K15"), default="paired", help="activation or K = 15 N m/rad"
    )
    parser.add_argument("--study-points", type=int, default=401, help="grid points per axis of the study (401)")
    parser.add_argument("--skip-scaling", action="store_true")
    parser.add_argument("--skip-reproduce", action="store_true")
    parser.add_argument("--skip-study", action="store_true")
    args = parser.parse_args()
    model = config.load_preset(args.preset)
    if args.variant == "independent":
        model = config.set_parameter(model, "optimisation.activation", "independent")
    elif args.variant == "K15":
        model = model.replace(passive=Passive(15.0, model.passive.convention))
    compare(model, args.points, args.repeats)
    coefficients(model, args.points, max(args.repeats, 5))
    if not args.skip_scaling:
        scaling(model, (21, 41, 81, 161))
    if not args.skip_reproduce:
        reproduce()
    if not args.skip_study:
        study(args.study_points)


if __name__ == "__main__":
    main()
