"""Benchmark: how long ``spinectl`` takes to start, against importing numpy (and scipy), in the same run.

    python benchmarks/bench_startup.py               # best of 7 runs each, interleaved
    python benchmarks/bench_startup.py --repeats 15  # on a busy machine

Each command runs in a fresh interpreter, as a user types it (``python -m spinectl``
from this checkout). Printed: the fastest wall time of each and the ratios the
targets are stated in: ``spinectl --help`` against ``python -c "import numpy"``
(target: within 3x) and ``spinectl stability --E 0.03 --Lambda 0.04`` against
``python -c "import numpy, scipy"`` (target: within 2x). Then the packages that
``spinectl stability`` imports beyond numpy and scipy, biggest first, from
``python -X importtime``. Other users' load only ever adds time, so the fastest
run is the one that measures the program.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON = [sys.executable]
SPINECTL = [*PYTHON, "-m", "spinectl"]

COMMANDS = {
    "import numpy": [*PYTHON, "-c", "import numpy"],
    "import numpy, scipy": [*PYTHON, "-c", "import numpy, scipy"],
    "spinectl --help": [*SPINECTL, "--help"],
    "spinectl stability": [*SPINECTL, "stability", "--E", "0.03", "--Lambda", "0.04"],
}

RATIOS = (
    ("spinectl --help", "import numpy", 3.0),
    ("spinectl stability", "import numpy, scipy", 2.0),
)
"""(command, reference, target ratio): the start-up targets of the 0.2 performance work."""


def wall(command: list[str]) -> float:
    """Wall time of one run [s]; the command must succeed."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    subprocess.run(command, cwd=ROOT, env=env, check=True, capture_output=True)
    return time.perf_counter() - start


def heaviest_imports(command: list[str], top: int = 10) -> list[tuple[str, float]]:
    """The packages that ``command`` imports, with the cumulative import time of each [s], biggest first.

    A package's time includes what it imports in turn (cvxpy's includes scipy.sparse's).
    """
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    traced = [command[0], "-X", "importtime", *command[1:]]
    done = subprocess.run(traced, cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    totals: dict[str, float] = {}
    for line in done.stderr.splitlines():
        parts = line.split("|")
        name = parts[-1].strip()
        if len(parts) == 3 and parts[1].strip().isdigit() and "." not in name and not name.startswith("_"):
            totals[name] = max(totals.get(name, 0.0), int(parts[1]) / 1e6)
    return sorted(totals.items(), key=lambda item: -item[1])[:top]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7, help="runs per command, taking turns; fastest counts")
    args = parser.parse_args()
    print(f"== start-up, fastest of {args.repeats} runs each, interleaved; load average {os.getloadavg()[0]:.2f}")
    best = {name: float("inf") for name in COMMANDS}
    for _ in range(args.repeats):
        for name, command in COMMANDS.items():
            best[name] = min(best[name], wall(command))
    for name, seconds in best.items():
        print(f"{name:>22}: {seconds:6.3f} s")
    for command, reference, target in RATIOS:
        ratio = best[command] / best[reference]
        verdict = "meets" if ratio <= target else "misses"
        print(f"{command} / {reference}: {ratio:5.2f}x ({verdict} the target of {target:g}x)")
    print("== packages that spinectl stability imports (cumulative import time, one run)")
    for name, seconds in heaviest_imports(COMMANDS["spinectl stability"]):
        print(f"{name:>22}: {seconds:6.3f} s")


if __name__ == "__main__":
    main()
