"""Benchmark: the atlas's draws on the fast path against one model per draw, over eight parameters.

    python benchmarks/bench_atlas.py                                  # the speed target: 8 priors, 73 728 draws
    python benchmarks/bench_atlas.py --only-file --samples 1024 --evaluations 0   # the shipped atlas as it is
    python benchmarks/bench_atlas.py --sample 20 --chain-draws 1024   # quicker

The speed target: 4096 Saltelli base samples over 8 parameters, 73 728 model evaluations (N (2D + 2),
the count with second-order terms; the atlas's own design without them is N (D + 2) = 40 960), for
the joint-by-joint outputs (min PCSA, counter torques, exact delay margin) in <= 60 s on the project's
2-core machine. The eight priors are the shipped five of examples/atlas.toml and, where that file
does not vary them, the three of :data:`EXTRA` (the mass's height, T_a and the activation), so that
every field of :data:`spinectl.landscape.atlas.FAST` varies. ``--evaluations`` takes that many of the
first rows of the smallest power-of-2 design that has them (0: the whole design of ``--samples``).

Timed: the fast path (:func:`spinectl.landscape.atlas.evaluate` with ``method='fast'``, one stacked
problem per chunk) on every draw, and the per-draw reference (``method='per-draw'``: one validated
model per draw) on the first ``--sample`` draws, its time extrapolated; the largest relative
difference of each output on the sample. Then the chain's least local stiffness on the first
``--chain-draws`` draws: the stacked SDP's cost per draw (the atlas with the chain less without),
against the per-point reference, one cvxpy SDP per draw
(:func:`spinectl.optimise.coupled.sdp.least_local_stiffness_at`) at the same K, on ``--sample``
draws. Timings on a shared machine are noisy (wall-clock and CPU time are printed): the ratio is what matters.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from spinectl.landscape import atlas  # noqa: E402
from spinectl.landscape.priors import load_atlas, parse_atlas  # noqa: E402
from spinectl.model import chain  # noqa: E402
from spinectl.model.checks import checked_coefficients  # noqa: E402
from spinectl.model.config import set_parameters  # noqa: E402
from spinectl.optimise import active_set, coupled  # noqa: E402
from spinectl.optimise.problem import problem_data  # noqa: E402

EXTRA = {
    "body.mass_height": (0.28, 0.38, "benchmark: +-5 cm about the paper's 326 mm"),
    "reflex.activation_time_constant": (0.05, 0.1, "benchmark: the paper's Discussion, force generation 50-100 ms"),
    "reflex.activation": (0.3, 1.0, "benchmark: 30 % to all of the minimum PCSA"),
}
"""Uniform priors (low, high, source) of the three fields beyond the shipped five; not the shipped file's."""

OUTPUTS = ("min_pcsa_cm2", "counter_torque_norm_Nm", "spine_delay_margin_s")


def eight_priors(path: Path):
    """The atlas file at ``path`` with the priors of :data:`EXTRA` it lacks appended."""
    text = path.read_text(encoding="utf-8")
    have = set(load_atlas(path).names)
    for name, (low, high, source) in EXTRA.items():
        if name not in have:
            text += f'\n[[prior]]\nparameter = "{name}"\ndistribution = "uniform"\n'
            text += f'bounds = [{low}, {high}]\nsource = "{source}"\n'
    return parse_atlas(text, source=str(path), base_dir=path.parent)


def timed(spec, values, method):
    """The outputs, the wall-clock time [s] and the process's CPU time [s] (the load of a shared machine aside)."""
    start, cpu = time.perf_counter(), time.process_time()
    out = atlas.evaluate(spec, values, method=method)
    return out, time.perf_counter() - start, time.process_time() - cpu


def relative(a, b):
    """Largest |a - b| / |b| over the entries where b is finite and a equals b where it is not."""
    finite = np.isfinite(b)
    assert np.array_equal(a[~finite], b[~finite], equal_nan=True), "the paths disagree where an output is not finite"
    return float(np.max(np.abs(a[finite] - b[finite]) / np.maximum(np.abs(b[finite]), 1e-300), initial=0.0))


def chain_stiffness(spec, values, i):
    """K of the chain at the per-segment optimum of draw i, one model (as the per-draw path builds it)."""
    fields = [name for name in values if "." in name]
    model = set_parameters(spec.model, {f: float(values[f][i]) for f in fields})
    e, lam = values["eccentricity_m"][i : i + 1], values["lordosis_m"][i : i + 1]
    data = problem_data(model, checked_coefficients(model, e, lam))
    pcsa = active_set.solve_block(data, model.optimisation.ct_tolerance).pcsa
    return chain.chain_coefficients(model, e, lam).stiffness(pcsa)[0]


def per_point_chain(spec, values, sample):
    """The cvxpy SDP per draw on the first ``sample`` draws: its wall-clock and CPU time per draw [s], the totals."""
    opt = spec.model.optimisation
    matrices = [chain_stiffness(spec, values, i) for i in range(sample)]
    start, cpu = time.perf_counter(), time.process_time()
    totals = [
        np.sum(coupled.least_local_stiffness_at(k, opt.stability_margin, opt.solver_tolerance)[1]) for k in matrices
    ]
    return (time.perf_counter() - start) / sample, (time.process_time() - cpu) / sample, np.array(totals)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--priors", type=Path, default=ROOT / "examples" / "atlas.toml", help="atlas file")
    parser.add_argument("--only-file", action="store_true", help="the file's priors alone, without EXTRA")
    parser.add_argument("--samples", type=int, default=4096, help="Saltelli base samples (a power of 2)")
    parser.add_argument("--evaluations", type=int, default=73728, help="draws to time (0: the whole design)")
    parser.add_argument("--sample", type=int, default=50, help="draws solved by the per-draw references")
    parser.add_argument("--chain-draws", type=int, default=4096, help="draws with the chain (0: none)")
    args = parser.parse_args()
    spec = load_atlas(args.priors) if args.only_file else eight_priors(args.priors)
    spec = dataclasses.replace(spec, samples=args.samples, chain=False)
    if args.evaluations:  # the smallest power-of-2 N whose design has that many rows
        per = len(spec.priors) + 2
        spec = dataclasses.replace(spec, samples=max(args.samples, 1 << (-(-args.evaluations // per) - 1).bit_length()))
    start = time.perf_counter()
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    t_draw = time.perf_counter() - start
    if args.evaluations:
        values = {k: v[: args.evaluations] for k, v in values.items()}
    n = values["eccentricity_m"].size
    fast, t_fast, cpu_fast = timed(spec, values, "fast")
    head = {k: v[: args.sample] for k, v in values.items()}
    reference, t_ref, cpu_ref = timed(spec, head, "per-draw")
    per_draw = t_ref / args.sample
    print(f"{n} draws, {len(spec.priors)} parameters ({', '.join(spec.names)}), joint by joint")
    print(f"sampling and quantiles: {t_draw:.2f} s")
    print(f"fast path: {t_fast:.2f} s ({1e6 * t_fast / n:.0f} us per draw; CPU {cpu_fast:.2f} s)")
    print(f"per draw:  {per_draw * 1e3:.2f} ms per draw (CPU {cpu_ref / args.sample * 1e3:.2f} ms), ", end="")
    print(f"{per_draw * n:.0f} s extrapolated, {per_draw * n / t_fast:.0f}x")
    for name in OUTPUTS:
        print(f"  largest relative difference of {name}: {relative(fast[name][: args.sample], reference[name]):.1e}")
    if not args.chain_draws:
        return
    m = min(args.chain_draws, n)
    some = {k: v[:m] for k, v in values.items()}
    chained = dataclasses.replace(spec, chain=True)
    with_chain, t_with, cpu_with = timed(chained, some, "fast")
    _, t_without, cpu_without = timed(spec, some, "fast")
    stacked = (t_with - t_without) / m
    sdp, sdp_cpu, totals = per_point_chain(spec, values, min(args.sample, m))
    found = with_chain["cocontraction_local_stiffness_total_Nm_per_rad"][: totals.size]
    print(f"chain's least local stiffness on {m} draws: stacked SDP {stacked * 1e3:.2f} ms per draw ", end="")
    print(f"(CPU {(cpu_with - cpu_without) / m * 1e3:.2f} ms)")
    print(
        f"  per-point SDP (cvxpy): {sdp * 1e3:.1f} ms per draw (CPU {sdp_cpu * 1e3:.1f} ms), {sdp / stacked:.0f}x; ",
        end="",
    )
    print(f"largest relative difference of the total: {relative(found, totals):.1e}")


if __name__ == "__main__":
    main()
