"""Benchmark: the fast path against the per-point reference, on the same grid in the same run.

    python benchmarks/bench_sweep.py                 # 81 x 81, then scaling, then reproduce
    python benchmarks/bench_sweep.py --points 41 --skip-scaling --skip-reproduce

Prints the wall time of both paths, their ratio and the largest difference
between their answers (relative to each point's total PCSA or ||CT||, at least
1 N m); then the fast path's time and working memory per grid point for growing
grids (linear cost, flat memory); then the wall time of ``spinectl reproduce``
end to end in a fresh interpreter. Timings on a shared machine are noisy: the
ratio and the differences are what matter.
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
from spinectl.model import config  # noqa: E402


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
    print(f"== fast path vs per-point reference, {points} x {points} grid (LP + least-||CT|| + tie-break)")
    fast_time, fast = timed(lambda: sweep.sweep(model, axis, axis, method="fast", progress=False), repeats)
    print(f"fast path:  {fast_time:8.2f} s  (median of {repeats}; {fast.attrs['points_solved_per_point']} fell back)")
    ref_time, ref = timed(lambda: sweep.sweep(model, axis, axis, method="per-point", progress=None))
    print(f"per-point:  {ref_time:8.2f} s")
    print(f"ratio:      {ref_time / fast_time:8.1f} x faster")
    for name, value in largest_differences(fast, ref).items():
        print(f"largest difference, {name:18}: {value:.2e}")


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
    parser.add_argument("--skip-scaling", action="store_true")
    parser.add_argument("--skip-reproduce", action="store_true")
    args = parser.parse_args()
    model = config.load_preset(args.preset)
    compare(model, args.points, args.repeats)
    if not args.skip_scaling:
        scaling(model, (21, 41, 81, 161))
    if not args.skip_reproduce:
        reproduce()


if __name__ == "__main__":
    main()
