"""Benchmark: ``spinectl motion`` on an .osim model of about 320 muscles, per frame, against analyse frame by frame.

    python benchmarks/bench_osim_motion.py                   # 20 frames: activations given, then the optimum
    python benchmarks/bench_osim_motion.py --frames 30 --skip-optimum --profile

The issue's target: a 324-muscle ``.osim`` at most 2 s per frame after the model's load. Two models, each
loaded once with the cache of linearisations off (``cache=False``: every frame is a new posture, linearised
in the run, as a first analysis of a recording is):

1. the 324-muscle model of ``bench_osim_anatomy.py`` (spinectl's export of the paper's chain with
   rigid-tendon Millard muscles added and couplers tying its joints to L5S1), built through OpenSim's API;
2. where a copy of the published models is present (``$SPINECTL_SHARED_MODELS``;
   tests/anatomy/shared_models.py), the Pose2Sim model as published (318 DeGrooteFregly muscles,
   44 wrap objects, 18 lumbar couplers) with docs/mappings/pose2sim.toml; else a line says it is skipped.

On each, a flexion and return of the mapped sagittal joints (-8 sin(pi t / T) deg added to the model's default
posture, every other coordinate at its default) over ``--frames`` frames at 10 Hz, and random activations in
[0.05, 0.3] per frame, both written through OpenSim's API (``write_motion``: TimeSeriesTable, STOFileAdapter).
Timed, wall clock, after a warm-up at another posture (imports, OpenSim's reader, xarray), with the
engine's in-memory linearisations emptied before each timed call (a call would otherwise read the frames the
previous one linearised), each the least of ``--repeat`` alternated runs:

1. ``motion_response(activations=...)`` (the library call of ``spinectl motion --activations``) against
   ``analyse(posture=FILE, activation=FILE, time=t)`` per frame (the present API, which reads both files at
   every call, in the same run); the indices must be equal bit for bit (asserted);
2. unless ``--skip-optimum``, ``motion_response(optimise="joints")`` over ``--optimum-frames`` frames against
   ``optimise(posture=..., stability="joints")`` then ``analyse`` at its activations, per frame.

Each line gives seconds per frame, the ratio to the 2 s target, the ratio frame-by-frame / motion, and the
load average (1 min) before and after: the machine is shared, the ratios of one run are what matters.
``--profile`` prints cProfile's heaviest functions of one motion run (activations given). Needs the
anatomy and opensim extras (``pip install 'spinectl[anatomy,opensim]'``).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))  # bench_osim_anatomy: the built 324-muscle model
sys.path.insert(0, str(ROOT / "tests" / "anatomy"))  # shared_models: where the published models are read from

from bench_motion import timed  # noqa: E402
from bench_osim_anatomy import built_model  # noqa: E402
from shared_models import ABSENT, DOCUMENTED_MAPPINGS, POSE2SIM  # noqa: E402

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.engine import engine_output_to_stderr  # noqa: E402
from spinectl.anatomy.motion import motion_response, write_motion  # noqa: E402
from spinectl.anatomy.optimum import optimise  # noqa: E402
from spinectl.anatomy.recordings import read_recording  # noqa: E402

RATE = 10.0
"""Frames per second of the motion written [Hz]."""

TARGET = 2.0
"""The issue's target: seconds per frame after the model's load [s]."""

FLEXION = 8.0
"""The flexion's amplitude at each sagittal joint [deg]."""


def load_average() -> str:
    """The 1-minute load average, as printed beside each timing."""
    return f"{os.getloadavg()[0]:.1f}"


def flexion(model, times) -> tuple:
    """The coordinates' names and rows [deg or m]: the default posture, the sagittal joints flexed by
    FLEXION sin(pi t / T)."""
    columns = model.posture_columns()
    names = list(columns.required)
    default = [model.engine.coordinate(name).getDefaultValue() for name in names]
    upright = [np.degrees(v) if name in columns.rotational else v for name, v in zip(names, default, strict=True)]
    rows = np.tile(upright, (len(times), 1))
    for joint in model.plane_joints("sagittal"):
        rows[:, names.index(joint)] -= FLEXION * np.sin(np.pi * times / times[-1])
    return names, rows


def files(model, folder: Path, n: int) -> tuple:
    """The flexion's coordinates (.mot, degrees) and random activations (.sto) of ``n`` frames, and their times."""
    times = np.arange(n) / RATE
    names, rows = flexion(model, times)
    a = np.random.default_rng(0).uniform(0.05, 0.3, (n, len(model.muscles)))
    return (
        write_motion(folder / "flexion.mot", names, times, rows),
        write_motion(folder / "so.sto", model.muscles, times, a, in_degrees=None),
        times,
    )


def warm_up(model, folder: Path) -> None:
    """Imports, OpenSim's reader and xarray, at an extension the motion does not visit; then no linearisation kept."""
    names, rows = flexion(model, np.array([0.0, 1.0, 2.0]))
    extended = 2 * rows[0] - rows[1]  # the deepest flexion mirrored about upright
    mot = write_motion(folder / "warm.mot", names, [0.0], [extended])
    analyse(model, posture=mot)
    motion_response(model, read_recording(mot, "posture"), progress=False)
    model.engine.linearisations.clear()


def best(model, runs: int, ours, theirs) -> tuple:
    """The least wall time of ``runs`` alternated calls of ``ours`` and of ``theirs`` [s], the load averages
    before and after, and each one's last result. The least: a shared machine's bursts of other work lengthen
    a timing, never shorten it. The engine's in-memory linearisations are emptied before every call."""
    before, spent, outs = load_average(), [[], []], [None, None]
    for _ in range(runs):
        for k, run in enumerate((ours, theirs)):
            model.engine.linearisations.clear()
            elapsed, outs[k] = timed(run)
            spent[k].append(elapsed)
    model.engine.linearisations.clear()
    return min(spent[0]), min(spent[1]), f"{before} -> {load_average()}", outs


def given(model, mot, sto, times, runs: int) -> tuple:
    """(motion's time, frame-by-frame time, load averages) with activations from the file; indices asserted equal."""
    rec, act = read_recording(mot, "posture"), read_recording(sto, "activations")
    ours, theirs, loads, (ds, old) = best(
        model,
        runs,
        lambda: motion_response(model, rec, act, progress=False).dataset,
        lambda: [analyse(model, posture=mot, activation=sto, time=float(t)) for t in times],
    )
    for name in ("free", "constrained"):
        assert np.array_equal(ds[f"{name}_index"].values, [getattr(r, name).eigenvalues[0] for r in old]), name
    return ours, theirs, loads


def optimum(model, mot, frames: int, runs: int) -> tuple:
    """(motion's time, frame-by-frame time, load averages, frames solved) with the optimum (joints) per frame."""
    rec = read_recording(mot, "posture")
    columns = model.posture_columns()

    def frame_by_frame():
        for t in rec.times[:frames]:
            posture = model.named_posture(rec.frame(columns, float(t)).values)
            opt = optimise(model, stability="joints", posture=posture)
            if opt.ok:
                analyse(model, posture=posture, activation=opt.activations)

    ours, theirs, loads, (ds, _) = best(
        model,
        runs,
        lambda: motion_response(model, rec, optimise="joints", frames=(0, frames - 1, 1), progress=False).dataset,
        frame_by_frame,
    )
    return ours, theirs, loads, int(np.isfinite(ds["free_index"].values).sum())


def report(label: str, what: str, frames: int, ours: float, theirs: float, loads: str, runs: int) -> None:
    """Seconds per frame, the ratio to the target and to the frame-by-frame calls, the load average."""
    per, previous = ours / frames, theirs / frames
    print(f"{label}, {frames} frames, {what}:")
    print(f"    motion {per:.2f} s/frame: ratio to the {TARGET:g} s target {per / TARGET:.2f}")
    print(f"    analyse frame by frame {previous:.2f} s/frame: ratio frame by frame / motion {theirs / ours:.2f}")
    print(f"    load average (1 min) {loads}; each the least of {runs} alternated run(s)")


def profile(model, mot, sto) -> None:
    """cProfile's heaviest functions (cumulative and own time) of one motion run with activations given."""
    rec, act = read_recording(mot, "posture"), read_recording(sto, "activations")
    profiler = cProfile.Profile()
    profiler.runcall(motion_response, model, rec, act, progress=False)
    model.engine.linearisations.clear()
    stats = pstats.Stats(profiler, stream=sys.stdout)
    stats.sort_stats("cumulative").print_stats(25)
    stats.sort_stats("tottime").print_stats(15)


def bench(label: str, path: Path, mapping, args) -> None:
    """Load once, write the motion, time the motion against analyse frame by frame (and the optimum)."""
    with engine_output_to_stderr():  # OpenSim's log lines (a missing mesh each) are not the benchmark's
        load, model = timed(lambda: anatomy.load(path, mapping, cache=False))
    print(f"{label}: {len(model.muscles)} muscles, loaded in {load:.1f} s (not counted), load average {load_average()}")
    with tempfile.TemporaryDirectory(prefix="spinectl-bench-osim-motion-") as folder:
        mot, sto, times = files(model, Path(folder), args.frames)
        warm_up(model, Path(folder))
        ours, theirs, loads = given(model, mot, sto, times, args.repeat)
        report(label, "activations given", args.frames, ours, theirs, loads, args.repeat)
        if not args.skip_optimum:
            frames = min(args.optimum_frames, args.frames)
            ours, theirs, loads, solved = optimum(model, mot, frames, args.repeat)
            report(label, f"the optimum per frame (joints; {solved} solved)", frames, ours, theirs, loads, args.repeat)
        if args.profile:
            profile(model, mot, sto)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20, help="frames of the motion (>= 2)")
    parser.add_argument("--optimum-frames", type=int, default=5, help="of them, solved with the optimum")
    parser.add_argument("--repeat", type=int, default=2, help="runs of each, alternated; the least time kept")
    parser.add_argument("--skip-optimum", action="store_true")
    parser.add_argument("--skip-built", action="store_true", help="the shared Pose2Sim model only")
    parser.add_argument("--profile", action="store_true", help="cProfile of one motion run per model")
    args = parser.parse_args()
    if args.frames < 2 or args.optimum_frames < 1 or args.repeat < 1:
        parser.error("--frames must be >= 2, --optimum-frames and --repeat >= 1")
    with tempfile.TemporaryDirectory(prefix="spinectl-bench-osim-") as folder:
        if not args.skip_built:
            with engine_output_to_stderr():
                path, mapping = built_model(Path(folder), 324)
            bench("the paper's chain with muscles added and couplers (built)", path, mapping, args)
    if POSE2SIM.is_file():
        bench("the Pose2Sim model as published", POSE2SIM, DOCUMENTED_MAPPINGS / "pose2sim.toml", args)
    else:
        print(f"the Pose2Sim model: skipped, {ABSENT} (set $SPINECTL_SHARED_MODELS to their folder)")


if __name__ == "__main__":
    main()
