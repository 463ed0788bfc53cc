"""The table of ``docs/interchange.md`` that the exports produce, measured at the build.

The paper's model (``wagner2012``) at E = 3 cm, Lambda = 4 cm exported as MJCF and as OpenSim files with each
muscle model, without and with spinectl's least local stiffness: spinectl's verdict on its chain beside
OpenSim's own linearisation of the file written (:func:`spinectl.anatomy.interchange.export_verdicts`), so
that the page's numbers are those the commands print, never typed.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from spinectl.model.config import load_preset

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
    """Largest and smallest real part [1/s] and the count of growing modes."""
    real = np.real(eigenvalues)
    return f"{real.max():.4g} | {np.abs(real).min():.3g} | {int(np.sum(real >= 0))} of {real.size}"


def export_table() -> str:
    """The exports' eigenvalues: spinectl's chain and, for OpenSim files, OpenSim's linearisation of the file."""
    try:
        import opensim  # noqa: F401  (the engine that referees the OpenSim rows)
    except ImportError:
        return "*(This table needs the opensim extra at the docs' build: `pip install 'spinectl[opensim]'`.)*\n"
    from spinectl.anatomy.interchange import export_model, opensim_eigenvalues

    model = load_preset("wagner2012")
    lines = [
        "| export | local stiffness | whose linearisation | largest Re [1/s] | least abs(Re) [1/s] | growing modes |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    with tempfile.TemporaryDirectory() as folder:
        for fmt, muscle, local in EXPORTS:
            out = Path(folder) / f"{fmt}_{muscle}_{int(local)}.{'xml' if fmt == 'mjcf' else 'osim'}"
            solution = export_model(model, *POINT, out, fmt, with_local_stiffness=local, osim_muscle=muscle)
            name = "MJCF" if fmt == "mjcf" else f"`.osim`, `--osim-muscle {muscle}`"
            springs = "the least (spinectl's)" if local else "none"
            lines.append(f"| {name} | {springs} | spinectl's chain | {_cells(solution.eigenvalues)} |")
            if fmt == "osim":
                found = opensim_eigenvalues(out, model.geometry.cor_names)
                lines.append(f"| {name} | {springs} | OpenSim's, of the file | {_cells(found)} |")
    return "\n".join(lines) + "\n"
