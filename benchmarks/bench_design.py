"""Benchmark: the design curve of 41 delays (0 to 200 ms), both criteria, against a brute-force activation scan.

Run once: ``PYTHONPATH=. python benchmarks/bench_design.py``. The target: the curve in <= 10 s on the 2-core
machine. The brute force answers the joint-by-joint half alone by scanning the activation in steps of 1e-3
(1001 exact margins per delay, every segment) and checks that the curve's activations agree to that step.

The chain's half: at each delay the least local-stiffness fraction, by a safeguarded inverse interpolation of
the exact margins already computed (spinectl.reflex.design.chain._bracket_root), 3.5-3.9 exact margins per delay where
a bisection needed 13-14 (to the same width 2^-20, with the same certificate).

Measured with one BLAS thread, the curve alone (this script's calls without the brute force, at a load of 1.9):
default 5.7 s and the 35 kg subject with K = 10 N m/rad (wagner2012) 4.0 s at E = 3 cm, Lambda = 4 cm; at position A
(E = Lambda = 0) wagner2012 5.1 s and default 5.7 s; with the bisection 22.5-33 s (141-154 exact margins for the
curve against 517-573). The brute force, last run with the local muscles' stiffness only (the joint-by-joint half is
unchanged since): default 183.6 s (largest difference 9.5e-4), the subject 235.0 s (9.8e-4).

The curve makes thousands of small LAPACK calls (the chain's frequency sweep, the characteristic roots), and
OpenBLAS's threads, on a machine whose cores other jobs hold, wait for a core at each call: on a loaded machine
(load 6 to 10) one BLAS thread made the curve 7 to 25 times faster (stiffness only). The script prints the load
and the setting.
"""

from __future__ import annotations

import os
import time

import numpy as np

from spinectl.model import config
from spinectl.model.checks import checked_coefficients
from spinectl.optimise.reference import solve_point
from spinectl.reflex.design import delay_curve, segment_margins_at

POINT = (0.03, 0.04)
A = (0.0, 0.0)
"""Position A, the corner E = Lambda = 0 (:data:`spinectl.paper.grid.POSITIONS`)."""
DELAYS = np.linspace(0.0, 0.2, 41)


def brute_force(model, e, lam, delays):
    """The least common activation per delay on a 1e-3 grid, by evaluating every grid point at every delay."""
    coefficients = checked_coefficients(model, e, lam)
    p = solve_point(model, e, lam).pcsa
    grid = np.linspace(0.0, 1.0, 1001)
    out = []
    for d in delays:
        margins = np.stack([segment_margins_at(model, coefficients, p, [a])[0] for a in grid])
        ok = np.all(margins >= d, axis=1)
        out.append(grid[np.argmax(ok)] if ok.any() else np.nan)
    return np.array(out)


def main() -> None:
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "unset (delay_curve then uses one BLAS thread: spinectl._threads)")
    print(f"load average at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; OPENBLAS_NUM_THREADS {threads}")
    for preset in ("wagner2012", "default"):
        start = time.perf_counter()
        delay_curve(config.load_preset(preset), *A, DELAYS)
        print(f"{preset} at A: design curve, 41 delays, both criteria {time.perf_counter() - start:.2f} s (<= 10 s)")
    for preset, extra in (("default", {}), ("wagner2012", {"body.mass": 35.0, "passive.stiffness": 10.0})):
        model = config.set_parameters(config.load_preset(preset), extra)
        start = time.perf_counter()
        curve = delay_curve(model, *POINT, DELAYS)
        took = time.perf_counter() - start
        start = time.perf_counter()
        brute = brute_force(model, *POINT, DELAYS)
        brute_took = time.perf_counter() - start
        gap = np.nanmax(np.abs(curve.activation[0] - brute))
        print(
            f"{preset}: design curve, 41 delays, both criteria {took:.2f} s (target <= 10 s); brute-force activation "
            f"scan, joint by joint only {brute_took:.2f} s; largest activation difference {gap:.2e} (grid 1e-3)"
        )


if __name__ == "__main__":
    main()
