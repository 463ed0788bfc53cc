"""Benchmark: an anatomical model (MyoTorso) loaded, linearised and optimised; the lordosis curve; K per muscle.

    python benchmarks/bench_anatomy.py                  # MyoTorso, 50 N m/rad added, 41 postures
    python benchmarks/bench_anatomy.py --postures 21 --joint-stiffness 0

Three timings in one run, each against its target or its reference (docs/anatomy.md, "Speed"):

1. after import, each in a fresh process: ``spinectl.anatomy.load("myotorso")``, the free and
   constrained sagittal chains at the reference posture (K_0 + sum a_i K_i, D, M) and the
   stability-constrained optimum (the chain criterion); target <= 1 s in all. Twice, with a
   cache folder of its own (``$SPINECTL_CACHE_DIR``, a temporary one): cold (myo-sim composes
   the model, MuJoCo compiles it, the compiled model is written to the cache), then warm
   (the compiled model read from the cache, spinectl.anatomy.cache);
2. the lordosis curve (:func:`spinectl.anatomy.optimum.lordosis_curve`): the three optima at each of
   41 postures over -20 ... +20 deg; target <= 20 s;
3. spinectl's per-muscle stiffness K_i over the five FE joints (one linearisation for all 210
   muscles) against the reference, central differences of MuJoCo's own generalised forces
   (``qfrc_actuator + qfrc_passive - qfrc_bias``) at a = e_i less a = 0, muscle by muscle: the
   ratio of the times and the largest difference relative to the largest entry of any K_i.

Needs the anatomy extra (``pip install 'spinectl[anatomy]'``). Timings on a shared machine
are noisy: the ratios are what matters.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

STEP = 1e-6
"""The reference's central-difference step [rad] (as tests/anatomy/test_linearise.py)."""


def per_muscle_reference(anatomy, dofs):
    """K_i by central differences of MuJoCo's forces, muscle by muscle: (m, n, n) [N m/rad per unit activation]."""
    engine, q0 = anatomy.engine, anatomy.posture()
    m, n = len(anatomy.muscles), len(dofs)

    def stiffness(act):
        out = np.zeros((n, n))
        for k, dof in enumerate(dofs):
            sides = []
            for sign in (1.0, -1.0):
                q = q0.copy()
                q[engine.model.jnt_qposadr[engine.model.dof_jntid[dof]]] += sign * STEP
                sides.append(engine.generalised_force(q, act)[list(dofs)])
            out[:, k] = (sides[0] - sides[1]) / (2 * STEP)
        return out

    base = stiffness(np.zeros(m))
    return np.array([stiffness(np.eye(m)[i]) - base for i in range(m)])


def first_load(joint_stiffness: float) -> dict:
    """In this (fresh) process: the import, then load + K + optimum, timed [s]."""
    start = time.perf_counter()
    # imported by load and the optimum: their imports are no part of the timing
    import cvxpy  # noqa: F401
    import mujoco  # noqa: F401
    import myo_sim  # noqa: F401

    from spinectl import anatomy
    from spinectl.anatomy.optimum import optimise

    imported = time.perf_counter() - start
    start = time.perf_counter()
    torso = anatomy.load("myotorso")
    loaded = time.perf_counter()
    torso.chains("sagittal", joint_stiffness=joint_stiffness)
    linearised = time.perf_counter()
    opt = optimise(torso, stability="chain", joint_stiffness=joint_stiffness)
    solved = time.perf_counter()
    return {
        "import": imported,
        "load": loaded - start,
        "chains": linearised - loaded,
        "optimum": solved - linearised,
        "total": solved - start,
        "status": opt.status,
        "cost": opt.cost,
        "source": torso.engine.source,
        "muscles": len(torso.muscles),
    }


def in_fresh_process(joint_stiffness: float, cache: str) -> dict:
    """:func:`first_load` in a new Python process with ``cache`` as the cache folder."""
    env = {**os.environ, "SPINECTL_CACHE_DIR": cache}
    command = [sys.executable, __file__, "--first-load", "--joint-stiffness", str(joint_stiffness)]
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--postures", type=int, default=41, help="postures of the lordosis curve")
    parser.add_argument("--joint-stiffness", type=float, default=50.0, help="added at each joint [N m/rad]")
    parser.add_argument("--first-load", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.first_load:
        print(json.dumps(first_load(args.joint_stiffness)))
        return

    with tempfile.TemporaryDirectory(prefix="spinectl-bench-cache-") as cache:
        runs = {"cold": in_fresh_process(args.joint_stiffness, cache)}
        runs["warm"] = in_fresh_process(args.joint_stiffness, cache)
    cold = runs["cold"]
    print(f"MyoTorso ({cold['source']}), {cold['muscles']} muscles, {args.joint_stiffness:g} N m/rad added")
    print(f"  import of spinectl.anatomy, mujoco, myo-sim, cvxpy (not counted): {cold['import']:8.3f} s")
    for name, run in runs.items():
        what = "compiled, cache written" if name == "cold" else "read from the cache"
        print(f"  {name} process, the model {what}:")
        print(f"    load:                                                 {run['load']:8.3f} s")
        print(f"    the chains (K_0 + sum a_i K_i, D, M; free and constrained): {run['chains']:8.3f} s")
        print(f"    the optimum, chain criterion ({run['status']}, cost {run['cost']:.4g}): {run['optimum']:8.3f} s")
        print(f"    load + K + optimum: {run['total']:.3f} s (target <= 1 s: ratio {run['total'] / 1.0:.2f})")

    from spinectl import anatomy
    from spinectl.anatomy.optimum import lordosis_curve

    torso = anatomy.load("myotorso", cache=False)
    lin = torso.chains("sagittal", joint_stiffness=args.joint_stiffness)[2]

    degrees = np.linspace(-20.0, 20.0, args.postures)
    start = time.perf_counter()
    curve = lordosis_curve(torso, degrees, joint_stiffness=args.joint_stiffness)
    swept = time.perf_counter() - start
    statuses = [s for key in ("none", "joints", "chain") for s in curve[key]["status"]]
    solved = sum(s in ("optimal", "optimal_inaccurate") for s in statuses)
    print(f"lordosis curve, {args.postures} postures x 3 optima ({solved} solved)")
    print(f"  {swept:.2f} s (target <= 20 s: ratio {swept / 20.0:.2f}); {swept / args.postures:.3f} s per posture")

    dofs = list(lin.dofs[: lin.n])
    start = time.perf_counter()
    ours_lin = torso.linearise("sagittal")[0]
    ours_time = time.perf_counter() - start
    ours = np.moveaxis(ours_lin.stiffness_per_muscle[: lin.n, : lin.n], -1, 0)
    start = time.perf_counter()
    reference = per_muscle_reference(torso, dofs)
    reference_time = time.perf_counter() - start
    scale = np.abs(reference).max()
    error = np.abs(ours - reference).max() / scale
    print(f"K per muscle over the {lin.n} FE joints, {len(torso.muscles)} muscles")
    print(f"  spinectl (one linearisation, every K_i):                 {ours_time:8.3f} s")
    print(f"  reference (central differences of MuJoCo's forces, per muscle): {reference_time:8.3f} s")
    print(f"  ratio reference / spinectl: {reference_time / ours_time:.1f}")
    print(f"  largest difference over the largest entry of any K_i: {error:.2e}")


if __name__ == "__main__":
    main()
