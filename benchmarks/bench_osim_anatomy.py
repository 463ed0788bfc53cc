"""Benchmark: an .osim model of about 320 muscles through OpenSim: one table, 41 postures, against the present path.

    python benchmarks/bench_osim_anatomy.py             # the built model; the Pose2Sim model too where present
    python benchmarks/bench_osim_anatomy.py --postures 11 --muscles 200

The present path is the one spinectl took before (docs/anatomy.md, "Speed"): every muscle's
``computeMomentArm`` about every coordinate at the posture and at q +- STEP e_k for the
Hessians, the inverse dynamics each time, no cache. It is written out in
tests/anatomy/osim_reference.py (``present_geometry``, shared with the tests) and timed
against :func:`spinectl.anatomy.osim_geometry.geometry` on the same coordinates, with the
largest difference. Then, each in a fresh process with a cache folder of its own,
``spinectl anatomy MODEL --mapping MAP`` (one table; target <= 5 s of wall time after the
first load, i.e. with the linearisation cached) and ``--lordosis -20:20:41`` (41
postures, three optima each; target <= 60 s), cold (the cache empty: the first load) and warm.
The present path's wall times are estimated from the same runs: the present path linearised
once per table and three times per posture (once per optimum), each at the measured cost of
``present_geometry`` instead of the new one.

Models, each built in a temporary folder through OpenSim's API:

1. spinectl's export of the paper's chain (``export_osim``, 30 Millard muscles) with muscles added
   to reach ``--muscles`` (rigid-tendon Millard, two or three path points on random chain bodies)
   and couplers tying L4L5 ... L1L2 to L5S1 (a lumbar rhythm, as the Christophy family's);
2. where a copy of the published models is present (tests/anatomy/shared_models.py), the Pose2Sim model
   (Beaucage-Gauvreau's lumbar spine,
   318 muscles, 44 wrap objects, 18 lumbar couplers) with its muscles made rigid-tendon Millard
   (the present path's reference reads Millard muscles only), its lumbar flexion chain mapped.

Needs the opensim extra (``pip install 'spinectl[opensim]'``). Timings on a shared machine are
noisy: the ratios are what matters.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "anatomy"))  # osim_reference: the previous path, shared with the tests

from shared_models import POSE2SIM as SHARED  # noqa: E402 (tests/anatomy/shared_models.py)

POSE2SIM_MAPPING = """[bodies]
pelvis = ["pelvis", "sacrum"]
vertebrae = ["lumbar5", "lumbar4", "lumbar3", "lumbar2", "lumbar1"]
thorax = ["torso"]
[planes]
sagittal = ["L5_S1_Flex_Ext", "L4_L5_Flex_Ext", "L3_L4_Flex_Ext", "L2_L3_Flex_Ext", "L1_L2_Flex_Ext"]
"""
CHAIN_BODIES = ["ground", "vertebra_above_L5S1", "vertebra_above_L4L5", "vertebra_above_L3L4"]
CHAIN_BODIES += ["vertebra_above_L2L3", "thorax"]


def built_model(folder: Path, muscles: int, seed: int = 0) -> tuple:
    """The export of the paper's chain with muscles added up to ``muscles`` and four couplers: (path, mapping)."""
    import opensim as osim

    from spinectl.anatomy.export_osim import export_osim
    from spinectl.model.config import load_preset

    export_osim(load_preset("wagner2012"), 0.03, 0.04, folder / "chain.osim")
    model = osim.Model(str(folder / "chain.osim"))
    model.initSystem()
    rng = np.random.default_rng(seed)
    frames = {"ground": model.getGround()} | {b: model.getBodySet().get(b) for b in CHAIN_BODIES[1:]}
    for k in range(muscles - model.getMuscles().getSize()):
        low, high = sorted(rng.choice(len(CHAIN_BODIES), 2, replace=False))
        chosen = [low, high] if high - low < 2 or rng.random() < 0.5 else [low, int(rng.integers(low + 1, high)), high]
        muscle = osim.Millard2012EquilibriumMuscle(f"added_{k}", 200.0, 0.1, 0.01, 0.0)
        side = rng.choice([-1.0, 1.0])  # ventral or dorsal
        for j, body in enumerate(chosen):
            where = osim.Vec3(side * rng.uniform(0.03, 0.1), rng.uniform(-0.01, 0.01), rng.uniform(-0.06, 0.06))
            muscle.addNewPathPoint(f"added_{k}_p{j}", frames[CHAIN_BODIES[body]], where)
        muscle.set_ignore_tendon_compliance(True)
        model.addForce(muscle)
    for name, slope in (("L4L5", 0.9), ("L3L4", 0.8), ("L2L3", 0.7), ("L1L2", 0.6)):
        coupler = osim.CoordinateCouplerConstraint()
        coupler.setName(f"rhythm_{name}")
        independent = osim.ArrayStr()
        independent.append("L5S1")
        coupler.setIndependentCoordinateNames(independent)
        coupler.setDependentCoordinateName(name)
        coupler.setFunction(osim.LinearFunction(slope, 0.0))
        model.addConstraint(coupler)
    model.finalizeConnections()
    state = model.initSystem()
    for i in range(model.getMuscles().getSize()):  # fibres at their optimal length upright, tendons 10 % of the path
        muscle = osim.Millard2012EquilibriumMuscle.safeDownCast(model.getMuscles().get(i))
        if muscle.getName().startswith("added_"):
            length = muscle.getLength(state)
            muscle.setOptimalFiberLength(0.9 * length)
            muscle.setTendonSlackLength(0.1 * length)
    model.printToXML(str(folder / "built.osim"))
    return folder / "built.osim", None


def pose2sim_model(folder: Path) -> tuple:
    """The Pose2Sim model with rigid-tendon Millard muscles on the same paths, and its mapping: (path, mapping)."""
    from osim_reference import rigid_millard_copy

    rigid_millard_copy(SHARED, folder / "pose2sim_millard.osim")
    (folder / "pose2sim.toml").write_text(POSE2SIM_MAPPING)
    return folder / "pose2sim_millard.osim", folder / "pose2sim.toml"


def geometry_times(path: Path, mapping) -> dict:
    """The present path's and the new geometry's times at the reference posture [s] and their difference."""
    from osim_reference import present_geometry

    from spinectl.anatomy.opensim_engine import _mobility_order, load_osim
    from spinectl.anatomy.osim_geometry import geometry

    anatomy = load_osim(path, mapping, cache=False)
    engine = anatomy.engine
    _, involved = anatomy.rhythm("sagittal")
    start = time.perf_counter()
    geo = geometry(engine, involved, {}, _mobility_order(engine))
    new = time.perf_counter() - start
    start = time.perf_counter()
    arms, hessian, _, _ = present_geometry(engine, involved, {})
    present = time.perf_counter() - start
    return {
        "muscles": len(anatomy.muscles),
        "coordinates": len(involved),
        "new": new,
        "present": present,
        "arms": np.abs(geo.arms - arms).max() / np.abs(arms).max(),
        "hessian": np.abs(geo.hessian - hessian).max() / np.abs(hessian).max(),
    }


def command_time(args: list, cache: str) -> float:
    """Wall time of ``python -m spinectl ARGS`` in a fresh process with ``cache`` as the cache folder [s]."""
    env = {**os.environ, "SPINECTL_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "spinectl", *args], env=env, capture_output=True, check=True)
    return time.perf_counter() - start


def bench(label: str, path: Path, mapping, postures: int) -> None:
    """Print the geometry's ratio, then the table's and the lordosis curve's times against their targets."""
    geo = geometry_times(path, mapping)
    print(f"{label}: {geo['muscles']} muscles, {geo['coordinates']} coordinates linearised over")
    print(f"  the geometry at a posture (arms, Hessians, passive torques): present path {geo['present']:.3f} s,")
    print(f"    now {geo['new']:.3f} s: ratio present / now {geo['present'] / geo['new']:.1f}")
    print(f"    largest difference: arms {geo['arms']:.1e}, Hessians {geo['hessian']:.1e} of the largest entry")
    extra = [] if mapping is None else ["--mapping", str(mapping)]
    runs = {  # (options, target [s], linearisations now, on the present path: the table's, then 3 per posture)
        "one table": ([], 5.0, 1, 1),
        f"{postures} postures (--lordosis, 3 optima each)": (
            ["--lordosis", f"-20:20:{postures}"],
            60.0,
            1 + postures,
            1 + 3 * postures,
        ),
    }
    for what, (options, target, computed, linearisations) in runs.items():
        with tempfile.TemporaryDirectory(prefix="spinectl-bench-cache-") as cache:
            cold = command_time(["anatomy", str(path), *extra, *options], cache)
            warm = command_time(["anatomy", str(path), *extra, *options], cache)
        present = cold - computed * geo["new"] + linearisations * geo["present"]
        print(f"  {what}: first load {cold:.2f} s, after it (cached) {warm:.2f} s: target <= {target:g} s,")
        print(f"    ratio {warm / target:.2f}; present path ~{present:.1f} s ({linearisations} linearisation(s)):")
        print(f"    ratio present / first load {present / cold:.1f}, present / cached {present / warm:.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--postures", type=int, default=41, help="postures of the lordosis curve")
    parser.add_argument("--muscles", type=int, default=324, help="muscles of the built model")
    args = parser.parse_args()
    from spinectl.anatomy.engine import engine_output_to_stderr

    with tempfile.TemporaryDirectory(prefix="spinectl-bench-osim-") as folder:
        folder = Path(folder)
        with engine_output_to_stderr():  # OpenSim's log lines (a missing mesh each) are not the benchmark's
            path, mapping = built_model(folder, args.muscles)
        bench("the paper's chain with added muscles and couplers (built)", path, mapping, args.postures)
        if SHARED.is_file():
            with engine_output_to_stderr():
                path, mapping = pose2sim_model(folder)
            bench("the Pose2Sim model, rigid-tendon Millard muscles", path, mapping, args.postures)
        else:
            print(f"(the Pose2Sim model: {SHARED} is absent)")


if __name__ == "__main__":
    main()
