"""Export the paper's model and its solution to another engine's file format (docs/interchange.md).

One entry point for the command line: :func:`export_model` picks the writer by format,
MJCF (:mod:`spinectl.anatomy.export_mjcf`) or OpenSim (:mod:`spinectl.anatomy.export_osim`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._validate import printable
from ..atomic import check_distinct, check_writable
from ..errors import ParameterError
from ..model.params import Model
from ..units import m2_to_cm2

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


def outputs_of(out, fmt: str | None = None) -> dict:
    """Every file an export to ``out`` writes, by the name a message gives it.

    Parameters
    ----------
    out : str or pathlib.Path
    fmt : {"mjcf", "osim"}, optional
        Default: from ``out``'s suffix.

    Returns
    -------
    dict
        ``{"--out": out}``, and for OpenSim ``"controls"``: the ``.sto`` beside it
        (:func:`spinectl.anatomy.export_osim.controls_path`).
    """
    from .export_osim import controls_path  # a light module: OpenSim itself is imported when it writes

    files = {"--out": str(out)}
    if format_of(out, fmt) == "osim":
        files["controls"] = str(controls_path(out))
    return files


def check_output(out, fmt: str | None = None, inputs: dict | None = None) -> str:
    """The export's format, once its outputs are known to be writable: called before any work.

    ``out``'s suffix must be one of the format's (:data:`FORMATS`: ``spinectl anatomy`` reads a model by
    its suffix), no output may be an input or the other output (:func:`spinectl.atomic.check_distinct`),
    and each must be writable (:func:`spinectl.atomic.check_writable`): a mistake in ``--out`` costs no solve.

    Parameters
    ----------
    out : str or pathlib.Path
    fmt : {"mjcf", "osim"}, optional
        Default: from ``out``'s suffix.
    inputs : dict, optional
        Option name -> every file read.

    Returns
    -------
    str
        The format.

    Raises
    ------
    ParameterError
        An unknown format, a suffix of another format, an output that is an input.
    OutputError
        An output that cannot be written (a folder in the way, a folder that cannot be written).
    """
    kind = format_of(out, fmt)
    suffix = Path(out).suffix.lower()
    if suffix not in FORMATS[kind]:
        raise ParameterError(
            "--out",
            f"an {kind} file ends in {' or '.join(FORMATS[kind])}, which is how spinectl anatomy reads it back "
            f"(got {printable(str(out))})",
        )
    outputs = outputs_of(out, kind)
    check_distinct(outputs, inputs)
    for path in outputs.values():
        check_writable(path)
    return kind


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
    kind = check_output(out, fmt, inputs)
    options = {"pcsa": pcsa, "with_local_stiffness": with_local_stiffness, "inputs": inputs}
    if kind == "mjcf":
        if osim_muscle != "millard":
            raise ParameterError("osim_muscle", f"applies to the osim format only (got {printable(osim_muscle)})")
        from .export_mjcf import export_mjcf

        return export_mjcf(model, eccentricity, lordosis, out, **options)
    from .export_osim import export_osim

    return export_osim(model, eccentricity, lordosis, out, muscle=osim_muscle, **options)


def export_verdicts(solution, out, fmt: str, osim_muscle: str = "millard") -> list[str]:
    """What the exported chain's stability is, each line naming whose model says it.

    spinectl's verdict is that of its own chain at the exported solution (:attr:`PaperSolution.eigenvalues`,
    all CoRs free). An OpenSim file with Millard muscles carries Millard's curves, not the paper's, so its
    dynamics differ (docs/interchange.md): its second line is OpenSim's own linearisation of the file
    written (:func:`~spinectl.anatomy.export_osim.opensim_linearisation`), the referee of what OpenSim will do.
    A file with the paper's curves gets that line too: there OpenSim's linearisation is the chain's, and the
    line shows it (a few dozen inverse-dynamics calls, well under a second).

    Parameters
    ----------
    solution : spinectl.anatomy.export_mjcf.PaperSolution
        What :func:`export_model` wrote.
    out : str or pathlib.Path
        The file written.
    fmt : {"mjcf", "osim"}
        Its format.
    osim_muscle : {"millard", "paper"}
        The OpenSim file's muscle model.

    Returns
    -------
    list of str
        What was exported (the global PCSA, the local stiffness as springs), then one line per verdict:
        ``"spinectl's chain with them (all CoRs free, the paper's muscle laws): stable, largest real part
        -0.0327 1/s"``, then for an OpenSim file OpenSim's, naming its muscle curves, with the remedy where a
        Millard file grows.
    """
    springs = float(np.sum(solution.local_stiffness))
    what = f"global PCSA {m2_to_cm2(np.sum(solution.pcsa)):.2f} cm^2 (the per-segment optimum unless given), " + (
        f"local stiffness {springs:.1f} N m/rad in all as joint springs" if springs else "no local stiffness"
    )
    lines = [
        f"exported: {what}",
        _verdict_line("spinectl's chain with them (all CoRs free, the paper's muscle laws)", solution.eigenvalues),
    ]
    if fmt == "osim":  # the engine as referee for both muscle models: for the paper's it confirms the chain's
        eigenvalues = opensim_eigenvalues(out, solution.model.geometry.cor_names)
        growing = int(np.sum(eigenvalues.real >= 0))
        millard = osim_muscle == "millard"
        curves = "Millard's muscle curves" if millard else "the paper's curves on a RigidTendonMuscle"
        lines.append(
            _verdict_line(f"OpenSim's own linearisation of the file ({curves})", eigenvalues)
            + f", {growing} of {eigenvalues.size} eigenvalues with Re >= 0"
            + ("; for a file whose dynamics are spinectl's chain: --osim-muscle paper" if growing and millard else "")
        )
    return lines


def opensim_eigenvalues(path, names) -> np.ndarray:
    """The eigenvalues of OpenSim's own linearisation of an exported file (the engine as referee).

    Parameters
    ----------
    path : str or pathlib.Path
        An ``.osim`` file written by :func:`export_model`.
    names : sequence of str
        Its chain's coordinates, top to bottom (the model's ``geometry.cor_names``).

    Returns
    -------
    numpy.ndarray, shape (2 n,)
        Of the state matrix [[0, I], [M^-1 K, M^-1 D]] of
        :func:`~spinectl.anatomy.export_osim.opensim_linearisation` [1/s] (docs/chain.md's convention).
    """
    from ..model.chain import state_matrix
    from .export_osim import opensim_linearisation

    _, stiffness, damping, mass = opensim_linearisation(path, names)
    return np.linalg.eigvals(state_matrix(mass, stiffness, damping))


def _verdict_line(whose: str, eigenvalues) -> str:
    """``whose: stable|unstable, largest real part x 1/s``, the criterion being every eigenvalue's Re < 0."""
    growth = float(np.max(np.real(eigenvalues)))
    return f"{whose}: {'stable' if growth < 0 else 'unstable'}, largest real part of its eigenvalues {growth:.6g} 1/s"
