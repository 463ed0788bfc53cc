"""Export the paper's model and its solution to another engine's file format (docs/interchange.md).

One entry point for the command line: :func:`export_model` picks the writer by format,
MJCF (:mod:`spinectl.anatomy.export_mjcf`) or OpenSim (:mod:`spinectl.anatomy.export_osim`).
"""

from __future__ import annotations

from pathlib import Path

from .._validate import printable
from ..errors import ParameterError
from ..model.params import Model

FORMATS = {"mjcf": (".xml", ".mjcf"), "osim": (".osim",)}
"""The export formats and the file suffixes that name them."""


def format_of(out, fmt: str | None = None) -> str:
    """The export format: ``fmt`` if given, else the one that ``out``'s suffix names.

    Parameters
    ----------
    out : str or pathlib.Path
        The file to write.
    fmt : str, optional
        ``"mjcf"`` or ``"osim"``.

    Returns
    -------
    str
    """
    if fmt is not None:
        if fmt not in FORMATS:
            raise ParameterError("format", f"must be one of {sorted(FORMATS)} (got {printable(fmt)})")
        return fmt
    suffix = Path(out).suffix.lower()
    for name, suffixes in FORMATS.items():
        if suffix in suffixes:
            return name
    raise ParameterError(
        "format", f"not given, and the suffix of {printable(str(out))} names none of {sorted(FORMATS)}"
    )


def export_model(
    model: Model,
    eccentricity: float,
    lordosis: float,
    out,
    fmt: str | None = None,
    *,
    pcsa=None,
    with_local_stiffness: bool = False,
    inputs: dict | None = None,
    osim_muscle: str = "millard",
):
    """Write the paper's model at (E, Lambda) with its solution as MJCF or OpenSim.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    out : str or pathlib.Path
        The file to write (atomically).
    fmt : {"mjcf", "osim"}, optional
        Default: from ``out``'s suffix (:data:`FORMATS`).
    pcsa : array_like, optional
        PCSA [m^2]; default the per-segment optimum.
    with_local_stiffness : bool
        The chain's least local stiffness as joint springs.
    inputs : dict, optional
        Option name -> every file read; ``out`` must be none of them.
    osim_muscle : {"millard", "paper"}
        OpenSim only: the fibres' muscle model (:data:`spinectl.anatomy.export_osim.MUSCLES`).

    Returns
    -------
    spinectl.anatomy.export_mjcf.PaperSolution
        What was exported.
    """
    kind = format_of(out, fmt)
    options = {"pcsa": pcsa, "with_local_stiffness": with_local_stiffness, "inputs": inputs}
    if kind == "mjcf":
        if osim_muscle != "millard":
            raise ParameterError("osim_muscle", f"applies to the osim format only (got {printable(osim_muscle)})")
        from .export_mjcf import export_mjcf

        return export_mjcf(model, eccentricity, lordosis, out, **options)
    from .export_osim import export_osim

    return export_osim(model, eccentricity, lordosis, out, muscle=osim_muscle, **options)
