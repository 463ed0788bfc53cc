"""Benchmark: the atlas's draws on the fast path against one model per draw.

    python benchmarks/bench_atlas.py                      # 4096 base samples, examples/atlas.toml, 200 reference draws
    python benchmarks/bench_atlas.py --samples 1024 --sample 100
    python benchmarks/bench_atlas.py --evaluations 73728 --sample 50 --no-chain   # the speed target's count

The joint-by-joint outputs (min PCSA, counter torques, delay margin) of Saltelli's design over the
priors of examples/atlas.toml: the fast path (:func:`spinectl.landscape.atlas.evaluate` with
``method='fast'``: the body's mass, K and the delay varied inside one stacked problem per chunk) on
every draw, and the per-draw reference (``method='per-draw'``: one validated model per draw) on the
first ``--sample`` draws, its time extrapolated. Then the chain's least local stiffness (one stacked
SDP per chunk) on the fast path, its cost per draw. Prints the times, their ratio and the largest
difference of the min PCSA on the sample. Target: 4096 base samples over 8 parameters (73 728
evaluations, with second-order terms) in <= 60 s on the project's 2-core machine; without second
order, N (D + 2). The fast path's cost is per draw, whatever the number of parameters among the
position and :data:`spinectl.landscape.atlas.FAST` (a prior on any other field takes the per-draw path):
``--evaluations 73728`` times that many draws of the shipped priors' design, the target's count.
Timings on a shared machine are noisy: the ratio is what matters.
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
from spinectl.landscape.priors import load_atlas  # noqa: E402


def timed(spec, values, method):
    start = time.perf_counter()
    out = atlas.evaluate(spec, values, method=method)
    return out, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=4096, help="Saltelli base samples (a power of 2)")
    parser.add_argument("--sample", type=int, default=200, help="draws solved by the per-draw reference")
    parser.add_argument("--evaluations", type=int, help="time this many draws (the design's first rows)")
    parser.add_argument("--no-chain", action="store_true", help="skip the chain's stacked SDPs")
    args = parser.parse_args()
    spec = dataclasses.replace(load_atlas(ROOT / "examples" / "atlas.toml"), samples=args.samples, chain=False)
    if args.evaluations:  # the smallest power-of-2 N whose design has that many rows
        per = len(spec.priors) + 2
        samples = 1 << max(0, -(-args.evaluations // per) - 1).bit_length()
        spec = dataclasses.replace(spec, samples=samples)
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    if args.evaluations:
        values = {k: v[: args.evaluations] for k, v in values.items()}
    n = values["eccentricity_m"].size
    fast, t_fast = timed(spec, values, "fast")
    head = {k: v[: args.sample] for k, v in values.items()}
    reference, t_ref = timed(spec, head, "per-draw")
    diff = np.nanmax(np.abs(fast["min_pcsa_cm2"][: args.sample] - reference["min_pcsa_cm2"]))
    print(f"{n} draws, {len(spec.priors)} parameters, joint by joint")
    print(f"fast path: {t_fast:.2f} s ({1e6 * t_fast / n:.0f} us per draw)")
    print(f"per draw:  {t_ref / args.sample * 1e3:.2f} ms per draw, {t_ref / args.sample * n:.1f} s extrapolated")
    print(f"ratio: {t_ref / args.sample * n / t_fast:.0f}x; largest |difference| of min PCSA: {diff:.2e} cm^2")
    if args.no_chain:
        return
    chained = dataclasses.replace(spec, chain=True)
    _, t_chain = timed(chained, values, "fast")
    print(
        f"with the chain's least local stiffness (stacked SDP): {t_chain:.2f} s ({1e3 * t_chain / n:.2f} ms per draw)"
    )


if __name__ == "__main__":
    main()
