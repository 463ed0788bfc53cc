"""Benchmark: a study of motions (``spinectl study`` on a file of ``[[trials]]``) on 1 and on 2 local Dask workers.

    python benchmarks/bench_motion_study.py                  # 1,000 MyoTorso frames, activations given
    python benchmarks/bench_motion_study.py --frames 200 --repeats 2

MyoTorso's lumbar flexion and return over ``--frames`` frames at 50 Hz and random activations in [0, 0.3],
written through OpenSim's API as ``bench_motion.py`` writes them, split into ``--trials`` trials of equal length
(default 4, as a study of several trials; the frames are the same), ``--chunk-frames`` frames per chunk. Each
configuration runs the command line in a fresh process (cluster start, model loads and writes included), in
turns; each keeps its fastest run of ``--repeats``. Reported: wall time, the run's own time (the command's
closing line: from the store's lock to the last trial's file, without the command's imports and the study
file's reading), frames per second, and the ratio of 2 workers to 1, of each. The local workers write the
chunk and trial files themselves (docs/motion.md, "Many trials on Dask"), so both times hold every file
written. The target: at least 1.6x on 2 workers for 1,000 frames. The machine is shared: the load average at
each start is printed, and the ratio cannot exceed what the free cores allow. Every store's trials are
checked equal bit for bit.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_motion import files  # noqa: E402 (benchmarks/bench_motion.py: the same flexion and activations)

from spinectl import anatomy  # noqa: E402
from spinectl.landscape.study import load_motion_study, load_motions  # noqa: E402


def study_file(folder: Path, frames: int, trials: int, chunk: int) -> Path:
    """The motion's files (bench_motion's flexion and activations) and a study of ``trials`` trials over
    consecutive ranges of its frames."""
    files(anatomy.load("myotorso"), folder, frames)
    bounds = np.linspace(0, frames, trials + 1).astype(int)
    text = f"[study]\nchunk_frames = {chunk}\n"
    for i, (first, end) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
        text += (
            f'\n[[trials]]\nname = "trial{i}"\nmodel = "myotorso"\ncoordinates = "flexion.mot"\n'
            f'activations = "so.sto"\nframes = "{first}:{end - 1}"\n'
        )
    path = folder / "study.toml"
    path.write_text(text, encoding="utf-8")
    return path


def run(command: list[str]) -> dict:
    """Wall time [s], the run's own time [s] (its closing line), the load average at the start."""
    load, start = os.getloadavg()[0], time.perf_counter()
    proc = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if proc.returncode:
        raise SystemExit(f"{' '.join(command)} failed ({proc.returncode}):\n{proc.stderr}")
    own, where = re.search(r"in ([0-9.]+) s, ([^;]+);", proc.stdout).groups()
    return {"wall": wall, "run": float(own), "load": load, "where": where}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=1000, help="frames in all (default 1000)")
    parser.add_argument("--trials", type=int, default=4, help="trials the frames are split into (default 4)")
    parser.add_argument("--chunk-frames", type=int, default=50, help="frames per chunk (default 50)")
    parser.add_argument("--repeats", type=int, default=1, help="runs per configuration, taking turns; fastest counts")
    args = parser.parse_args()
    runs = {"1 worker": ["--workers", "1"], "2 workers": ["--workers", "2"]}
    print(
        f"== study of motions: {args.frames} MyoTorso frames in {args.trials} trials, chunks of "
        f"{args.chunk_frames} frames, activations given; {os.cpu_count()} cores"
    )
    with tempfile.TemporaryDirectory() as folder:
        path = study_file(Path(folder), args.frames, args.trials, args.chunk_frames)
        print(f"{load_motion_study(path).n_chunks} chunks")
        best: dict[str, dict] = {}
        for repeat in range(args.repeats):
            for name, options in runs.items():
                store = Path(folder) / f"{name.replace(' ', '-')}-{repeat}"
                command = [sys.executable, "-m", "spinectl", "study", str(path), "--out", str(store), *options]
                r = run(command) | {"store": store}
                print(
                    f"{name:>10}: {r['wall']:7.1f} s wall, {r['run']:7.1f} s run, "
                    f"{args.frames / r['wall']:6.1f} frames/s (wall), {args.frames / r['run']:6.1f} frames/s (run), "
                    f"load average {r['load']:.2f} at start ({r['where']})"
                )
                if name not in best or r["wall"] < best[name]["wall"]:
                    best[name] = r
        one, two = best["1 worker"], best["2 workers"]
        print(
            f"speed-up 1 -> 2 workers: {one['wall'] / two['wall']:.2f}x (wall), {one['run'] / two['run']:.2f}x (run)"
            f"; target: 1.6x"
        )
        trials = {name: load_motions(r["store"]) for name, r in best.items()}
        first, *others = trials.values()
        for other in others:
            for key in first:
                xr.testing.assert_identical(first[key], other[key])
        print(f"stores identical bit for bit: {', '.join(trials)}")


if __name__ == "__main__":
    main()
