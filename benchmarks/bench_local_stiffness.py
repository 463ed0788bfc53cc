"""Benchmark: the coupled chain's SDPs over the 81 x 81 landscape, stacked against per point.

    python benchmarks/bench_local_stiffness.py                # 81 x 81, per-point reference on 200 points
    python benchmarks/bench_local_stiffness.py --points 41 --sample 100

The least local stiffness of docs/chain.md, problem (a), at the per-segment optimum of every
grid point: the fast path (one stacked Clarabel problem per chunk of 1024 points,
:func:`spinectl.optimise.coupled.stacked_sdp.least_local_stiffness_stacked`) on the whole grid, and the
per-point cvxpy reference (:func:`~spinectl.optimise.coupled.sdp.least_local_stiffness_at`) on a
random sample of its points, its time extrapolated to the grid. Prints both times, their
ratio and the largest relative difference of the totals on the sample. The per-segment
optimum the SDPs start from is solved first and not timed. Target: <= 30 s for 81 x 81 on the
project's 2-core machine. Then the same for the joint optimum of global and local muscle,
problem (c) (:func:`~spinectl.optimise.coupled.stacked_sdp.joint_optimum_stacked` against
:func:`~spinectl.optimise.coupled.joint.joint_optimum_sdp`), compared by its objective.
Timings on a shared machine are noisy: the ratio is what matters.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from spinectl.landscape.columns import DEFAULT_CHUNK  # noqa: E402
from spinectl.model import chain, config  # noqa: E402
from spinectl.model.checks import checked_coefficients  # noqa: E402
from spinectl.optimise import coupled, stacked  # noqa: E402
from spinectl.optimise.problem import problem_data  # noqa: E402
from spinectl.units import M2_PER_CM2  # noqa: E402


def chain_stiffness(model, e, lam):
    """K at the per-segment optimum of every point (NaN where infeasible), chunk by chunk."""
    out = []
    for start in range(0, e.size, DEFAULT_CHUNK):
        part = slice(start, start + DEFAULT_CHUNK)
        data = problem_data(model, checked_coefficients(model, e[part], lam[part]))
        pcsa = stacked.solve_stacked(data, model.optimisation.ct_tolerance).pcsa
        k = chain.chain_coefficients(model, e[part], lam[part]).stiffness(np.nan_to_num(pcsa))
        out.append(np.where(np.isnan(pcsa).any(axis=-1)[:, None, None], np.nan, k))
    return np.concatenate(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=81, help="grid points per axis")
    parser.add_argument("--sample", type=int, default=200, help="points solved by the per-point reference")
    parser.add_argument("--preset", default="default")
    args = parser.parse_args()
    model = config.load_preset(args.preset)
    opt = model.optimisation
    e, lam = (g.ravel() for g in np.meshgrid(*[np.linspace(0.0, 0.08, args.points)] * 2, indexing="ij"))
    stiffness = chain_stiffness(model, e, lam)

    start = time.perf_counter()
    totals = []
    for first in range(0, e.size, DEFAULT_CHUNK):
        status, k = coupled.least_local_stiffness_stacked(
            stiffness[first : first + DEFAULT_CHUNK], opt.stability_margin, opt.solver_tolerance
        )
        totals.append(k.sum(axis=-1))
    fast = time.perf_counter() - start
    totals = np.concatenate(totals)

    sample = np.random.default_rng(0).choice(e.size, min(args.sample, e.size), replace=False)
    start = time.perf_counter()
    reference = np.array(
        [
            np.sum(coupled.least_local_stiffness_at(stiffness[i], opt.stability_margin, opt.solver_tolerance)[1])
            for i in sample
        ]
    )
    per_point = (time.perf_counter() - start) / sample.size * e.size
    difference = np.nanmax(np.abs(totals[sample] - reference) / reference)
    print(f"least local stiffness, {args.points} x {args.points} = {e.size} points ({args.preset})")
    print(f"  stacked (chunks of {DEFAULT_CHUNK}):  {fast:8.2f} s")
    print(f"  per point (cvxpy, {sample.size} points, extrapolated): {per_point:8.2f} s")
    print(f"  ratio per point / stacked:   {per_point / fast:8.1f}")
    print(f"  largest relative difference of the totals on the sample: {difference:.2e}")
    joint(model, e, lam, sample)


def joint(model, e, lam, sample) -> None:
    """Problem (c): the stacked chunks on the whole grid, per point on the sample; the objectives compared."""
    kappa = chain.local_stiffness_per_pcsa(model) * M2_PER_CM2
    mu, weight = model.optimisation.stability_margin, model.local.cost_weight
    start = time.perf_counter()
    objective = []
    for first in range(0, e.size, DEFAULT_CHUNK):
        part = slice(first, first + DEFAULT_CHUNK)
        data = problem_data(model, checked_coefficients(model, e[part], lam[part]))
        coefficients = chain.chain_coefficients(model, e[part], lam[part])
        _, x, k = coupled.joint_optimum_stacked(data, coefficients, mu, kappa, weight)
        objective.append(x @ data.weights + weight * k.sum(axis=-1) / kappa)
    fast = time.perf_counter() - start
    objective = np.concatenate(objective)
    start = time.perf_counter()
    reference = []
    for i in sample:
        data = coupled.coupled_data(model, e[i], lam[i])
        _, x, k = coupled.joint_optimum_sdp(data)
        reference.append(data.problem.weights @ x + weight * k.sum() / kappa)
    per_point = (time.perf_counter() - start) / sample.size * e.size
    difference = np.nanmax(np.abs(objective[sample] - np.array(reference)) / np.array(reference))
    print("joint optimum of global and local muscle")
    print(f"  stacked (chunks of {DEFAULT_CHUNK}):  {fast:8.2f} s")
    print(f"  per point (cvxpy, {sample.size} points, extrapolated): {per_point:8.2f} s")
    print(f"  ratio per point / stacked:   {per_point / fast:8.1f}")
    print(f"  largest relative difference of the objectives on the sample: {difference:.2e}")


if __name__ == "__main__":
    main()
