"""Benchmark: ``spinectl study`` on a fine E x Lambda grid, in-process, on 1 and on 2 local Dask workers.

    python benchmarks/bench_study.py                      # 401 x 401 (0.2 mm), all outputs
    python benchmarks/bench_study.py --repeats 3          # best of three, interleaved, on a busy machine
    python benchmarks/bench_study.py --points 161 --skip-in-process

Each run is the command a user types, in a fresh interpreter, into a fresh
store: ``spinectl study STUDY.toml --out STORE`` with ``--scheduler
synchronous`` (the reference: the same chunks solved one after another in one
process, no Dask), ``--workers 1`` and ``--workers 2`` (a LocalCluster on
127.0.0.1). Every run solves all three stages at every point (the LP of the
minimum PCSA, the least-counter-torque problem, the tie-break) and the delay
margins. Printed per run: wall time of the command (imports, cluster start-up
and shutdown included), the run's own time from its summary line, the CPU
time of the command and every process it started (sampled every 0.1 s, so a
process's last tenth of a second may be missed; the local workers are children
of a fork server, which the kernel's count of a command's children misses),
the peak of their summed
resident memory (shared pages count once per process: an upper bound) and
the load average of the machine at the start. Then the 1 -> 2 worker speed-up,
the cost of the cluster against the in-process reference, and whether the
stores are identical bit for bit.

Timings on a shared machine are noisy: the ratios matter. With ``--repeats``
the configurations take turns and each keeps its fastest run (other users'
load only ever adds time).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from spinectl.landscape import study  # noqa: E402

STUDY = """[study]
description = "benchmark: {n} x {n} grid, 0 to 8 cm"

[axes]
E = {{ start = 0.0, stop = 0.08, num = {n} }}
Lambda = {{ start = 0.0, stop = 0.08, num = {n} }}
"""


def tree_sample(process: psutil.Process, cpu: dict[int, float]) -> int:
    """Resident memory of ``process`` and all its descendants [bytes]; their CPU times [s] into ``cpu`` by pid."""
    total = 0
    for p in [process, *process.children(recursive=True)]:
        try:
            with p.oneshot():
                total += p.memory_info().rss
                times = p.cpu_times()
                cpu[p.pid] = times.user + times.system
        except psutil.Error:  # ended between the listing and the reading
            pass
    return total


def run(command: list[str]) -> dict:
    """Wall time [s], the run's own time [s], CPU time [s], peak memory of the process tree [bytes], load, where."""
    load, start = os.getloadavg()[0], time.perf_counter()
    proc = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    peak, watched, cpu = 0, psutil.Process(proc.pid), {}

    def sample():
        nonlocal peak
        while proc.poll() is None:
            peak = max(peak, tree_sample(watched, cpu))
            time.sleep(0.1)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    out, err = proc.communicate()
    wall = time.perf_counter() - start
    sampler.join()
    if proc.returncode:
        raise SystemExit(f"{' '.join(command)} failed ({proc.returncode}):\n{err}")
    own, where = re.search(r"in ([0-9.]+) s, ([^;]+);", out).groups()
    return {"wall": wall, "run": float(own), "cpu": sum(cpu.values()), "peak": peak, "load": load, "where": where}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=401, help="grid points per axis (default 401: 0.2 mm)")
    parser.add_argument("--skip-in-process", action="store_true", help="skip the in-process reference run")
    parser.add_argument("--repeats", type=int, default=1, help="runs per configuration, taking turns; fastest counts")
    args = parser.parse_args()
    n = args.points
    runs = {"1 worker": ["--workers", "1"], "2 workers": ["--workers", "2"]}
    if not args.skip_in_process:
        runs = {"in-process": ["--scheduler", "synchronous"]} | runs
    print(f"== spinectl study, {n} x {n} grid ({n * n:,} points), all outputs; {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "study.toml"
        path.write_text(STUDY.format(n=n))
        spec = study.load_study(path)
        print(f"{spec.n_chunks} chunks of {spec.tile[0]} x {spec.tile[1]} points")
        best: dict[str, dict] = {}
        for repeat in range(args.repeats):
            for name, options in runs.items():
                store = Path(folder) / f"{name.replace(' ', '-')}-{repeat}.zarr"
                command = [sys.executable, "-m", "spinectl", "study", str(path), "--out", str(store), *options]
                r = run(command) | {"store": store}
                print(
                    f"{name:>10}: {r['wall']:7.1f} s wall, {r['run']:7.1f} s run, {r['cpu']:7.1f} s CPU, "
                    f"peak memory {r['peak'] / 2**30:5.2f} GiB, load average {r['load']:.2f} at start ({r['where']})"
                )
                if name not in best or r["wall"] < best[name]["wall"]:
                    best[name] = r
        one, two = best["1 worker"], best["2 workers"]
        fastest = ", ".join(f"{name} {r['wall']:.1f} s" for name, r in best.items())
        print(f"fastest: {fastest}")
        print(f"speed-up 1 -> 2 workers: {one['wall'] / two['wall']:.2f}x (wall), {one['run'] / two['run']:.2f}x (run)")
        if "in-process" in best:
            print(f"1 worker against in-process: {one['wall'] / best['in-process']['wall']:.2f}x the wall time")
        print(f"peak memory: {max(r['peak'] for r in best.values()) / 2**30:.2f} GiB")
        datasets = {name: study.load(r["store"]) for name, r in best.items()}
        first, *others = datasets.values()
        for other in others:
            xr.testing.assert_identical(first, other)
        print(f"stores identical bit for bit: {', '.join(datasets)}")


if __name__ == "__main__":
    main()
