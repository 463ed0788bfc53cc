"""The figures of a landscape as a set: which are drawn, and saved all or none.

:func:`figure_set` draws Figures 3 and 4 for every K of a sweep (Figure S1 for K > 0), the coupled
ratio where the sweep has it and, on request, the ratio S1 / 3 (:class:`FigureOptions` says how);
:func:`draw_figures` saves the set into one folder as a whole (:func:`spinectl.canvas.save_figures`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ...canvas import save_figures
from ...errors import ParameterError
from ...landscape import netcdf
from .counter_torque import counter_torque_figure
from .files import DPI, FORMATS, check_dpi, coupled_ratio_name, figure_names, ratio_name
from .landscape import LAMBDA_LABEL
from .min_pcsa import min_pcsa_figure
from .ratios import COUPLED_VARIABLE, coupled_ratio_figure, ratio_figure
from .style import cm_text

LORDOSIS_AXES = ("lambda", "angle")
"""The lordosis axis of the landscapes: Lambda [cm], or the lordosis angle [deg] (:class:`FigureOptions`)."""


@dataclass(frozen=True)
class FigureOptions:
    """How :func:`~spinectl.paper.figures.sets.draw_figures` draws and saves.

    Attributes
    ----------
    format : str
        One of :data:`~spinectl.paper.figures.files.FORMATS`.
    dpi : float
        Resolution of PNG files [dots per inch].
    vmin, vmax : float, optional
        Colour range of the minimum-PCSA figures [cm²]; default each figure's own.
    shared_scale : bool
        Figures 3 and S1 on one colour scale, the range over every K.
    ratio : bool
        Also the map of minimum PCSA at K > 0 over K = 0 (the paper's "halving").
    insets : bool
        The model drawn at the grid's four corners around Figure 3 and S1.
    lordosis_axis : {'lambda', 'angle'}
        The lordosis axis in cm of Lambda, or ticked in degrees of the lordosis angle
        (:func:`spinectl.model.clinical.lordosis_angle`, with the dataset's model; docs/atlas.md).
    """

    format: str = "png"
    dpi: float = DPI
    vmin: float | None = None
    vmax: float | None = None
    shared_scale: bool = False
    ratio: bool = False
    insets: bool = False
    lordosis_axis: str = "lambda"

    def __post_init__(self):
        if self.lordosis_axis not in LORDOSIS_AXES:
            raise ParameterError(
                "--lordosis-axis", f"must be one of {', '.join(LORDOSIS_AXES)} (got {self.lordosis_axis!r})"
            )
        if self.format not in FORMATS:
            raise ParameterError("--format", f"must be one of {', '.join(FORMATS)} (got {self.format!r})")
        check_dpi(self.dpi)


def _pcsa_range(dataset: xr.Dataset, options: FigureOptions) -> tuple[float | None, float | None]:
    """The colour range of the minimum-PCSA figures: the options', else with shared_scale that over every K."""
    vmin, vmax = options.vmin, options.vmax
    if options.shared_scale:
        values = dataset["min_pcsa_cm2"].values
        if np.isfinite(values).any():
            vmin = float(np.nanmin(values)) if vmin is None else vmin
            vmax = float(np.nanmax(values)) if vmax is None else vmax
    return vmin, vmax


def _ratio_stiffnesses(dataset: xr.Dataset) -> list[float]:
    """The K > 0 of a dataset that also holds K = 0; checked before anything is drawn."""
    stiffnesses = [float(k) for k in np.atleast_1d(dataset["K"].values)]
    if "K" not in dataset.dims or 0.0 not in stiffnesses or max(stiffnesses) <= 0:
        raise ParameterError("--ratio", "needs a landscape with K = 0 and a K > 0 (spinectl sweep --K 0,15)")
    return [k for k in stiffnesses if k > 0]


def figure_set(
    dataset: xr.Dataset, specific_tension: float | None = None, options: FigureOptions | None = None
) -> dict[str, Figure]:
    """Figures 3 and 4 for every K of ``dataset`` (Figure S1 for K > 0), by file name; nothing written.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`~spinectl.landscape.sweep.sweep` (scalar K) or
        :func:`~spinectl.landscape.sweep.stiffness_sweep` (a K dimension).
    specific_tension : float, optional
        f_iso per PCSA [N/m^2], for the local-PCSA scale of Figure 4; default: that of
        the model the dataset was computed with (:func:`spinectl.landscape.netcdf.model_of`).
    options : FigureOptions, optional
        Format, resolution, colour range, ratio map, insets; default PNG at :data:`~spinectl.paper.figures.files.DPI`.

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        :func:`~spinectl.paper.figures.files.figure_names` of each K -> its figure, K in the dataset's order.

    Raises
    ------
    ConfigError, ParameterError
        ``specific_tension`` not given and the dataset's ``config_toml`` is not a valid model.
    """
    options = options or FigureOptions()
    if specific_tension is None:
        specific_tension = netcdf.model_of(dataset).fibre.specific_tension
    parts = [dataset.sel(K=k) for k in dataset["K"].values] if "K" in dataset.dims else [dataset]
    vmin, vmax = _pcsa_range(dataset, options)
    stiffnesses = _ratio_stiffnesses(dataset) if options.ratio else []
    drawn = {}
    for part in parts:
        pcsa_name, ct_name = figure_names(float(part["K"]), options.format)
        drawn[pcsa_name] = min_pcsa_figure(part, vmin, vmax, options.insets)
        drawn[ct_name] = counter_torque_figure(part, specific_tension)
        if COUPLED_VARIABLE in part:
            drawn[coupled_ratio_name(float(part["K"]), options.format)] = coupled_ratio_figure(part)
    for k in stiffnesses:
        drawn[ratio_name(k, options.format)] = ratio_figure(dataset, k)
    if options.lordosis_axis == "angle":
        model = netcdf.model_of(dataset)
        for fig in drawn.values():
            angle_ticks(fig, model)
    return drawn


def angle_ticks(fig: Figure, model, step: float = 10.0) -> None:
    """Tick the lordosis axes of ``fig`` (y label :data:`LAMBDA_LABEL`) in degrees of the lordosis angle.

    The data stay in cm of Lambda; the ticks sit at the Lambda of whole multiples of ``step`` degrees,
    Lambda = L tan(theta / 2) / (2 phi'(0)) (:func:`spinectl.model.clinical.lordosis_from_angle`).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        Changed in place; axes with another y label are left alone.
    model : Model
        Its spine length and end conditions convert.
    step : float
        Degrees between ticks.

    Raises
    ------
    ParameterError
        Clamped end conditions, which have no angle (field ``geometry.spline_bc``).
    """
    from ...model.clinical import lordosis_angle, lordosis_from_angle

    for ax in fig.axes:
        if ax.get_ylabel() != LAMBDA_LABEL:
            continue
        low, high = sorted(ax.get_ylim())
        theta = lordosis_angle(np.array([low, high]) / 100.0, model)  # cm -> m
        ticks = np.arange(np.ceil(theta[0] / step), np.floor(theta[1] / step) + 1) * step
        ax.set_yticks(100.0 * lordosis_from_angle(ticks, model), [f"{t:g}" for t in ticks])
        ax.set_ylim(low, high)
        ax.set_ylabel("lordosis angle θ [deg]")
        for label in ax.texts:  # a corner's "0, 4.92 cm" read as a Λ on a θ axis
            if (label.get_gid() or "").startswith("label ") and len(label.get_text()) > 1:
                label.set_text(corner_text(*label.xy, model))


def corner_text(e_cm: float, lambda_cm: float, model) -> str:
    """A grid corner's label on an angle axis: ``E 0 cm, Λ 4.92 cm (θ 80°)``, each coordinate named.

    Parameters
    ----------
    e_cm, lambda_cm : float
        The corner [cm].
    model : Model
        Its spine length and end conditions convert Λ to θ (:func:`spinectl.model.clinical.lordosis_angle`).

    Returns
    -------
    str
    """
    from ...model.clinical import lordosis_angle

    theta = float(lordosis_angle(np.array([lambda_cm / 100.0]), model)[0])
    return f"E {cm_text(e_cm / 100.0)} cm, Λ {cm_text(lambda_cm / 100.0)} cm (θ {theta:.0f}°)"


def draw_figures(
    dataset: xr.Dataset,
    out_dir: str | Path,
    specific_tension: float | None = None,
    options: FigureOptions | None = None,
) -> list[Path]:
    """Draw :func:`~spinectl.paper.figures.sets.figure_set` and save it into ``out_dir``: all or none
    (:func:`spinectl.canvas.save_figures`).

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`figure_set`.
    out_dir : str or Path
        Folder for the files (created if missing), named by :func:`~spinectl.paper.figures.files.figure_names` (and
        :func:`~spinectl.paper.figures.files.ratio_name`); its other files are kept.
    specific_tension : float, optional
        As for :func:`figure_set`.
    options : FigureOptions, optional
        As for :func:`figure_set`; its ``dpi`` is the resolution of PNG files.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    ConfigError, ParameterError
        ``specific_tension`` not given and the dataset's ``config_toml`` is not a valid model;
        a bad colour range, or the ratio map without K = 0 and a K > 0; fewer than 2 values
        of E or of Lambda (field ``grid``), before any file is written.
    OutputError
        ``out_dir`` cannot take the files; nothing is written.
    """
    options = options or FigureOptions()
    return save_figures(figure_set(dataset, specific_tension, options), out_dir, options.dpi)
