"""Benchmark: the stability index along a motion (spinectl.anatomy.motion) against analyse called frame by frame.

    python benchmarks/bench_motion.py                # 100 MyoTorso frames: activations given, the optimum per frame
    python benchmarks/bench_motion.py --frames 300 --skip-optimum

MyoTorso's lumbar flexion and return (-8 sin(pi t / T) deg at each sagittal joint) over ``--frames`` frames at
50 Hz, and random activations in [0, 0.3] per frame, written through OpenSim's API (``write_motion``:
TimeSeriesTable, STOFileAdapter) into a temporary folder. Timed, wall clock, after one warm-up frame:

1. ``motion_response(activations=...)`` against ``analyse(posture=FILE, activation=FILE, time=t)`` per frame (the
   present API, which reads both files at every call); the indices must be equal (asserted);
2. ``motion_response(optimise="chain", joint_stiffness=50)`` against ``optimise(posture=...)`` then ``analyse``
   per frame at that posture and those activations.

The targets: 100 frames with activations given in at most 10 s, with the optimum per frame in
at most 60 s. Needs the anatomy and opensim extras. Timings on a shared machine are noisy.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.motion import motion_response, write_motion  # noqa: E402
from spinectl.anatomy.optimum import optimise  # noqa: E402
from spinectl.anatomy.recordings import read_recording  # noqa: E402

RATE = 50.0
"""Frames per second of the motion written [Hz]."""

STIFFNESS = 50.0
"""Joint stiffness added for the optimum [N m/rad]: without it MyoTorso's stable optimum is infeasible."""


def files(model, folder: Path, n: int):
    """The flexion's coordinates (.mot, degrees) and random activations (.sto) of ``n`` frames."""
    names = list(model.posture_columns().required)
    times = np.arange(n) / RATE
    rows = np.zeros((n, len(names)))
    for joint in model.plane_joints("sagittal"):
        rows[:, names.index(joint)] = -8.0 * np.sin(np.pi * times / times[-1])
    a = np.random.default_rng(0).uniform(0.0, 0.3, (n, len(model.muscles)))
    return (
        write_motion(folder / "flexion.mot", names, times, rows),
        write_motion(folder / "so.sto", model.muscles, times, a, in_degrees=None),
        times,
    )


def timed(run):
    start = time.perf_counter()
    out = run()
    return time.perf_counter() - start, out


def given(model, mot, sto, times) -> tuple:
    """(motion's time, frame-by-frame time) with activations from the file; the indices asserted equal."""
    rec, act = read_recording(mot, "posture"), read_recording(sto, "activations")
    ours, ds = timed(lambda: motion_response(model, rec, act, progress=False).dataset)
    theirs, old = timed(lambda: [analyse(model, posture=mot, activation=sto, time=float(t)) for t in times])
    assert np.array_equal(ds["free_index"].values, [r.free.eigenvalues[0] for r in old])
    return ours, theirs


def optimum(model, mot, times) -> tuple:
    """(motion's time, frame-by-frame time) with the optimum (chain criterion) per frame; how many were solved."""
    rec = read_recording(mot, "posture")
    ours, ds = timed(
        lambda: motion_response(model, rec, optimise="chain", joint_stiffness=STIFFNESS, progress=False).dataset
    )

    def frame_by_frame():
        columns = model.posture_columns()
        for t in times:
            posture = model.named_posture(rec.frame(columns, float(t)).values)
            opt = optimise(model, stability="chain", posture=posture, joint_stiffness=STIFFNESS)
            if opt.ok:
                analyse(model, posture=posture, activation=opt.activations, joint_stiffness=STIFFNESS)

    theirs, _ = timed(frame_by_frame)
    return ours, theirs, int(np.isfinite(ds["free_index"].values).sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--skip-optimum", action="store_true")
    args = parser.parse_args()
    model = anatomy.load("myotorso")
    with tempfile.TemporaryDirectory() as folder:
        mot, sto, times = files(model, Path(folder), args.frames)
        analyse(model, posture=mot, activation=sto, time=float(times[0]))  # warm-up: imports, OpenSim's reader
        motion_response(model, read_recording(mot, "posture"), frames=(0, 0, 1), progress=False)  # xarray, tqdm
        ours, theirs = given(model, mot, sto, times)
        print(
            f"MyoTorso, {args.frames} frames, activations given: motion_response {ours:.2f} s "
            f"({ours / args.frames * 1e3:.1f} ms/frame; target <= 10 s for 100), analyse frame by frame "
            f"{theirs:.2f} s: ratio {theirs / ours:.2f}x"
        )
        if not args.skip_optimum:
            ours, theirs, solved = optimum(model, mot, times)
            print(
                f"MyoTorso, {args.frames} frames, optimum per frame (chain, {STIFFNESS:g} N m/rad added, {solved} "
                f"solved): motion_response {ours:.2f} s (target <= 60 s for 100), optimise + analyse frame by "
                f"frame {theirs:.2f} s: ratio {theirs / ours:.2f}x"
            )


if __name__ == "__main__":
    main()
