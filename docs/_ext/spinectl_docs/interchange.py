"""The table of ``docs/interchange.md`` that the exports produce, measured at the build.

The paper's model (``wagner2012``) at E = 3 cm, Lambda = 4 cm exported as MJCF and as OpenSim files with each
muscle model, without and with spinectl's least local stiffness: spinectl's verdict on its chain beside
OpenSim's own linearisation of the file written (:func:`spinectl.anatomy.interchange.export_verdicts`), so
that the page's numbers are those the commands print, never typed; and the page's recipe for Millard's
muscles (the least local stiffness of OpenSim's own K added to the file's springs, and OpenSim's
linearisation of that file).
"""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np

from spinectl.model.config import load_preset

from .chain import coupled
from .values import value

POINT = (0.03, 0.04)
"""E and Lambda [m] of the exports the table measures (docs/chain.md's table, "Dynamic stability")."""

EXPORTS = (
    ("mjcf", "millard", False),
    ("osim", "paper", False),
    ("osim", "paper", True),
    ("osim", "millard", False),
    ("osim", "millard", True),
)
"""(format, OpenSim muscle model, with the least local stiffness) of each row."""


def _cells(eigenvalues) -> str:
    """The largest real part [1/s], the real part nearest 0 with its sign (the slowest mode, growing if > 0), and
    the count of growing modes."""
    real = np.real(eigenvalues)
    slowest = real[np.argmin(np.abs(real))]
    return f"{real.max():.4g} | {slowest:+.3g} | {int(np.sum(real >= 0))} of {real.size}"


@cache
def _folder() -> str:
    """A folder for the build's exports, removed when the build's process ends."""
    folder = tempfile.TemporaryDirectory(prefix="spinectl-docs-")
    _KEEP.append(folder)  # alive as long as the process: the exports are read by several tables and values
    return folder.name


_KEEP: list = []


@cache
def exported(fmt: str, muscle: str, local: bool):
    """``spinectl export`` of the paper's model at :data:`POINT`, once per build: (the file, the solution)."""
    from spinectl.anatomy.interchange import export_model

    out = Path(_folder()) / f"{fmt}_{muscle}_{int(local)}.{'xml' if fmt == 'mjcf' else 'osim'}"
    solution = export_model(load_preset("wagner2012"), *POINT, out, fmt, with_local_stiffness=local, osim_muscle=muscle)
    return out, solution


@cache
def opensim_linearised(muscle: str, local: bool) -> tuple:
    """OpenSim's own linearisation of the ``.osim`` export: (f0 [N m], K [N m/rad], D [N m s/rad], M [kg m^2])."""
    from spinectl.anatomy.export_osim import opensim_linearisation

    path, solution = exported("osim", muscle, local)
    return opensim_linearisation(path, solution.model.geometry.cor_names)


def opensim_k(muscle: str, local: bool) -> np.ndarray:
    """K [N m/rad] of OpenSim's own linearisation of the ``.osim`` export."""
    return opensim_linearised(muscle, local)[1]


def export_table() -> str:
    """The exports' eigenvalues: spinectl's chain and, for OpenSim files, OpenSim's linearisation of the file."""
    try:
        import opensim  # noqa: F401  (the engine that referees the OpenSim rows)
    except ImportError:
        return "*(This table needs the opensim extra at the docs' build: `pip install 'spinectl[opensim]'`.)*\n"
    from spinectl.anatomy.interchange import opensim_eigenvalues

    model = load_preset("wagner2012")
    lines = [
        "| export | local stiffness | whose linearisation | largest Re [1/s] "
        "| Re nearest 0 [1/s] (the slowest mode; > 0 grows) | growing modes |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for fmt, muscle, local in EXPORTS:
        out, solution = exported(fmt, muscle, local)
        name = "MJCF" if fmt == "mjcf" else f"`.osim`, `--osim-muscle {muscle}`"
        springs = "the least (spinectl's)" if local else "none"
        lines.append(f"| {name} | {springs} | spinectl's chain | {_cells(solution.eigenvalues)} |")
        if fmt == "osim":
            found = opensim_eigenvalues(out, model.geometry.cor_names)
            lines.append(f"| {name} | {springs} | OpenSim's, of the file | {_cells(found)} |")
    return "\n".join(lines) + "\n"


def _minus(v: float, fmt: str) -> str:
    return (f"{v:+{fmt}}" if v > 0 else f"{v:{fmt}}").replace("-", "\u2212")


def _and(values, fmt: str = ".0f") -> str:
    texts = [f"{v:{fmt}}" for v in values]
    return ", ".join(texts[:-1]) + " and " + texts[-1]


def _mujoco_check():
    """``spinectl anatomy chain.xml --check`` on the MJCF export (no local stiffness), at its solution."""
    from spinectl import anatomy
    from spinectl.anatomy.analyses import analyse

    return analyse(anatomy.load(str(exported("mjcf", "millard", False)[0])), activation=None, check=True)


value("interchange.fastest")(lambda: f"{exported('mjcf', 'millard', False)[1].eigenvalues.real.max():.2f}")
value("interchange.mujoco_rate")(lambda: f"{_mujoco_check().simulated_rate:.2f}")
value("interchange.slowest_local")(lambda: _minus(exported("mjcf", "millard", True)[1].eigenvalues.real.max(), ".3g"))
value("interchange.local_stiffness")(lambda: _and(exported("mjcf", "millard", True)[1].local_stiffness))
value("interchange.local_total")(lambda: f"{np.sum(exported('mjcf', 'millard', True)[1].local_stiffness):.0f}")
value("interchange.millard_diagonal")(
    lambda: _and([_minus(v, ".1f") for v in np.diag(opensim_k("millard", False))], "")
)
value("interchange.paper_diagonal")(  # spinectl's own chain at the exported solution (chain.md's first table)
    lambda: _and([_minus(v, ".1f") for v in np.diag(coupled("wagner2012", *POINT).chain.stiffness_offset)], "")
)
value("interchange.millard_least")(
    lambda: _minus(np.linalg.eigvalsh(-(opensim_k("millard", True) + opensim_k("millard", True).T) / 2)[0], ".1f")
)


def _growing(eigenvalues) -> list:
    real = np.sort(np.real(eigenvalues[np.real(eigenvalues) >= 0]))[::-1]
    return real


@cache
def _millard_opensim():
    from spinectl.anatomy.interchange import opensim_eigenvalues

    path, solution = exported("osim", "millard", False)
    return opensim_eigenvalues(path, solution.model.geometry.cor_names)


value("interchange.millard_growing")(
    lambda: (
        f"{len(_growing(_millard_opensim()))} growing modes ("
        + _and([f"{v:.3g}" for v in _growing(_millard_opensim())], "")
        + " 1/s"
    )
)
value("interchange.spinectl_growing")(
    lambda: "{}, {} to {}".format(
        len(_growing(exported("osim", "millard", False)[1].eigenvalues)),
        *(f"{v:.1f}" for v in _growing(exported("osim", "millard", False)[1].eigenvalues)[[0, -1]]),
    )
)
value("interchange.millard_fastest")(lambda: f"{_growing(_millard_opensim())[0]:.2f}")
value("interchange.fastest_6")(lambda: f"{exported('mjcf', 'millard', False)[1].eigenvalues.real.max():.6g}")


@cache
def _millard_local_opensim():
    """OpenSim's own linearisation of the Millard export with spinectl's least local stiffness (and damping)."""
    from spinectl.anatomy.interchange import opensim_eigenvalues

    path, solution = exported("osim", "millard", True)
    return opensim_eigenvalues(path, solution.model.geometry.cor_names)


value("interchange.millard_local_fastest")(lambda: f"{_growing(_millard_local_opensim())[0]:.2f}")


# --- Millard's chain made stable: the least local stiffness computed on OpenSim's own K ---


@cache
def own_local() -> np.ndarray:
    """``least_local_stiffness_at(K, mu)`` on K of OpenSim's linearisation of the plain Millard export [N m/rad]."""
    from spinectl.optimise.coupled.sdp import least_local_stiffness_at

    margin = load_preset("wagner2012").optimisation.stability_margin
    status, local = least_local_stiffness_at(opensim_k("millard", False), margin)
    if status != "optimal":
        raise RuntimeError(f"docs/interchange.md: the least local stiffness of OpenSim's K is {status}")
    return np.asarray(local, float)


@cache
def _own_local_opensim() -> np.ndarray:
    """OpenSim's own linearisation of the plain Millard export with :func:`own_local` added to its springs."""
    import opensim as osim

    from spinectl.anatomy.interchange import opensim_eigenvalues

    path, solution = exported("osim", "millard", False)
    names = solution.model.geometry.cor_names
    built = osim.Model(str(path))
    for k, name in enumerate(names):  # the export's joint springs, one per coordinate (docs/interchange.md)
        spring = osim.SpringGeneralizedForce.safeDownCast(built.getForceSet().get(f"{name}_stiffness"))
        spring.setStiffness(spring.getStiffness() + float(own_local()[k]))
    stable = Path(_folder()) / "millard_own_local.osim"
    built.printToXML(str(stable))
    return opensim_eigenvalues(stable, names)


def _slowest(eigenvalues) -> str:
    """'decays at -0.0008 1/s' (one significant figure), or 'grows at ...' where a mode does not decay."""
    top = float(np.max(np.real(eigenvalues)))
    return f"{'decays' if top < 0 else 'grows'} at {_minus(top, '.1g')} 1/s"


value("interchange.own_local")(lambda: _and(own_local()))
value("interchange.own_local_total")(lambda: f"{np.sum(own_local()):.0f}")
value("interchange.own_local_ratio")(
    lambda: f"{np.sum(own_local()) / np.sum(exported('mjcf', 'millard', True)[1].local_stiffness):.1f}"
)
value("interchange.own_local_slowest")(lambda: _slowest(_own_local_opensim()))
