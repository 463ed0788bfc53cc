"""The command line starts at once: the parser and the light commands import no heavy stack.

Each check runs in a fresh interpreter (this one has imported everything already) and
reads ``sys.modules`` after the command, so it fails on any import of a listed package,
however indirect. The times themselves are measured in ``benchmarks/bench_startup.py``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

HEAVY = ("matplotlib", "xarray", "cvxpy", "control", "dask", "distributed", "zarr")
"""Packages that take from a quarter of a second to seconds to import (``python -X importtime``)."""

PROBE = """
import contextlib, io, json, sys
from spinectl.cli import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    code = main(sys.argv[1:]) if len(sys.argv) > 1 else 0
print(json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""


def imported(*argv: str, packages: bool = True) -> tuple[int, set[str]]:
    """Exit code of ``spinectl *argv`` in a fresh interpreter, and the top-level packages it imported (or, without
    ``packages``, every module)."""
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], cwd=ROOT, capture_output=True, text=True, check=True)
    answer = json.loads(done.stdout)
    return answer["code"], {name.partition(".")[0] if packages else name for name in answer["modules"]}


@pytest.mark.parametrize(
    "argv",
    [(), ("--help",), ("stability", "--help"), ("config", "presets")],
    ids=["import", "help", "stability-help", "config"],
)
def test_the_parser_imports_nothing_heavy(argv):
    """``import spinectl.cli``, ``spinectl --help`` and a light command load none of :data:`HEAVY`."""
    code, modules = imported(*argv)
    assert code == 0
    assert modules.isdisjoint(HEAVY), sorted(modules & set(HEAVY))


def test_stability_imports_nothing_heavy():
    """``spinectl stability`` solves one point by the batched active-set path: none of :data:`HEAVY`, no cvxpy
    (the per-point reference is only the fallback) and no python-control (only ``--coupled`` needs it)."""
    code, modules = imported("stability", "--E", "0.03", "--Lambda", "0.04")
    assert code == 0
    assert modules.isdisjoint(HEAVY), sorted(modules & set(HEAVY))


def test_a_deferred_command_still_has_its_options_and_defaults(capsys):
    """The options that a lazy parser defers appear when their command is used, with the library's defaults."""
    from spinectl.cli import build_parser, main
    from spinectl.landscape.sweep import DEFAULT_CHUNK, METHODS

    args = build_parser(lazy=True).parse_args(["sweep", "--out", "a.nc"])
    assert args.chunk_size == DEFAULT_CHUNK and args.method == METHODS[0]
    assert main(["sweep", "--help"]) == 0
    out = capsys.readouterr().out
    assert "--chunk-size" in out and all(method in out for method in METHODS)


def test_reproduce_imports_no_solver_stack(tmp_path):
    """``spinectl reproduce`` solves its landscapes by the batched active-set path and measures the presets
    without fitting: no cvxpy (before: 1.4 s, through optimise.coupled), no python-control, no scipy.stats or
    scipy.optimize (before: 0.5 s, through paper.calibration.fit)."""
    code, modules = imported("reproduce", "--points", "3", "--out", str(tmp_path / "r"), packages=False)
    assert code == 0
    assert not {"cvxpy", "control", "scipy.stats", "scipy.optimize"} & modules
