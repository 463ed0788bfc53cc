"""Benchmark: the cost of OpenSim's forward simulation (Manager.integrate) of the exported paper chain.

    python benchmarks/bench_osim_replay.py                   # 10 s stable, 0.1 s and 1 s unstable, accuracy 1e-8
    python benchmarks/bench_osim_replay.py --accuracy 1e-6 --seconds 20

The wagner2012 preset at E = 3 cm, Lambda = 4 cm exported as ``.osim`` (docs/interchange.md), replayed
from a small perturbation with the controls held, as tests/anatomy/test_osim_replay.py does:

1. ``paper`` muscles with the chain's least local stiffness (stable): every mode excited by 1e-6,
   ``--seconds`` of simulated time; the wall time per simulated second, and the slowest mode's
   amplitude at the end against its eigenvalue's prediction (OpenSim's own linearisation);
2. ``paper`` muscles without local stiffness: 1e-7 rad along the fastest mode, 0.1 s (growth by e^6.8);
   the fitted rate against OpenSim's largest eigenvalue;
3. ``millard`` muscles with spinectl's least local stiffness (unstable in OpenSim): 1 s along its
   growing mode; the fitted rate against OpenSim's largest eigenvalue.

Needs the opensim extra (``pip install 'spinectl[opensim]'``). Timings on a shared machine are noisy.
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

from spinectl.anatomy.export_osim import export_osim, opensim_linearisation, require_opensim  # noqa: E402
from spinectl.model import chain  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402

E, LAMBDA = 0.03, 0.04


def replay(path, names, x0, times, accuracy):
    """Manager.integrate of the file from x0 = (q, q'): the states at ``times`` and the wall time [s]."""
    osim = require_opensim()
    model = osim.Model(str(path))
    state = model.initSystem()
    coordinates = model.getCoordinateSet()
    n = len(names)
    for k, name in enumerate(names):
        coordinates.get(name).setValue(state, float(x0[k]), False)
        coordinates.get(name).setSpeedValue(state, float(x0[n + k]))
    manager = osim.Manager(model)
    manager.setIntegratorAccuracy(accuracy)
    manager.initialize(state)
    out = []
    start = time.perf_counter()
    for t in times:
        state = manager.integrate(float(t))
        out.append(
            [coordinates.get(c).getValue(state) for c in names]
            + [coordinates.get(c).getSpeedValue(state) for c in names]
        )
    return np.array(out), time.perf_counter() - start


def modes(linearisation):
    """Eigenvalues and eigenvectors of OpenSim's state matrix."""
    _, stiffness, damping, mass = linearisation
    return np.linalg.eig(chain.state_matrix(mass, stiffness, damping))


def growth(path, names, duration, accuracy) -> str:
    """Replay along the fastest growing mode of OpenSim's linearisation; fitted and predicted rates, cost."""
    values, vectors = modes(opensim_linearisation(path, names))
    top = np.argmax(values.real)
    rate, mode = values[top].real, np.real(vectors[:, top])
    mode = mode / np.linalg.norm(mode[: len(names)])
    times = duration * np.arange(1, 101) / 100
    states, wall = replay(path, names, 1e-7 * mode, times, accuracy)
    fitted = np.polyfit(times, np.log(np.abs(states[:, : len(names)] @ mode[: len(names)])), 1)[0]
    return (
        f"{duration:g} s simulated in {wall:.2f} s ({wall / duration:.2f} s per simulated second); "
        f"rate {fitted:.5g} 1/s fitted, {rate:.5g} 1/s predicted ({fitted / rate - 1:+.1e})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated time of the stable replay [s]")
    parser.add_argument("--accuracy", type=float, default=1e-8, help="the integrator's accuracy")
    args = parser.parse_args()
    model = load_preset("wagner2012")
    names = model.geometry.cor_names
    with tempfile.TemporaryDirectory() as folder:
        files = {}
        for muscle, local in (("paper", True), ("paper", False), ("millard", True)):
            files[muscle, local] = Path(folder) / f"{muscle}_{int(local)}.osim"
            export_osim(model, E, LAMBDA, files[muscle, local], with_local_stiffness=local, muscle=muscle)
        path = files["paper", True]
        values, vectors = modes(opensim_linearisation(path, names))
        x0 = 1e-6 * np.real(vectors @ np.ones(len(values)))
        times = np.linspace(args.seconds / 20, args.seconds, 20)
        states, wall = replay(path, names, x0, times, args.accuracy)
        start, end = np.linalg.solve(vectors, x0), np.linalg.solve(vectors, states[-1])
        slow = np.argmax(values.real)
        predicted = abs(start[slow]) * np.exp(args.seconds * values[slow].real)
        print(f"OpenSim Manager.integrate, accuracy {args.accuracy:g}, wagner2012 at E = {E} m, Lambda = {LAMBDA} m")
        print(
            f"  paper muscles + least local stiffness (stable): {args.seconds:g} s simulated in {wall:.2f} s "
            f"({wall / args.seconds:.3f} s per simulated second); every mode smaller: "
            f"{bool(np.all(np.abs(end) < np.abs(start)))}; slowest ({values[slow].real:.4g} 1/s) "
            f"{abs(end[slow]) / predicted - 1:+.1e} from its prediction"
        )
        print(f"  paper muscles, no local stiffness: {growth(files['paper', False], names, 0.1, args.accuracy)}")
        print(f"  millard + spinectl's local stiffness: {growth(files['millard', True], names, 1.0, args.accuracy)}")


if __name__ == "__main__":
    main()
