"""Sweeps over the (E, Lambda) grid: the paper's landscapes as an xarray Dataset.

The grid is solved in chunks of points (working memory stays flat however
fine the grid), each chunk by the fast path (:mod:`spinectl.batch`) or the
per-point reference (:mod:`spinectl.optimise`). The Dataset carries the
answers, the per-segment coefficients that define every problem (so that
later analyses, e.g. delay margins, need not recompute them) and the
resolved configuration; docs/optimisation.md lists the schema with units.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import xarray as xr
from tqdm import tqdm

from . import __version__, batch, config, reflex
from .errors import ParameterError
from .io import atomic_path
from .optimise import problem_data
from .params import Model
from .stability import arithmetic_guard, checked_coefficients
from .units import M2_PER_CM2, m2_to_cm2

METHODS = ("fast", "per-point")
"""'fast': stacked blocks (:func:`spinectl.batch.solve_stacked`); 'per-point': the cvxpy reference."""

DEFAULT_CHUNK = 1024
"""Grid points per stacked problem: large enough that Python overheads vanish, small enough to keep memory flat."""

MAX_GRID_POINTS = 1_000_000
"""Largest grid of one sweep: the answer alone takes about 1.2 kB a point (1.2 GB here),
and at about 0.2 ms a point the fast path needs some minutes. A larger request is more
likely a typo (a step count in place of a point count) than a plan."""

REQUIRED = ("min_pcsa_cm2", "counter_torque_norm_Nm", "status", "K")
"""What :func:`load` insists on finding: the variables the figures and landmarks read."""

PAPER_REFERENCE = (
    "Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012) Spinal lordosis optimizes "
    "the requirements for a stable erect posture. Theor Biol Med Model 9:13"
)


def parse_grid(spec: str, name: str) -> np.ndarray:
    """A grid axis from ``"start:stop:num"`` (inclusive, metres) or a single value.

    Parameters
    ----------
    spec : str
        E.g. ``"0:0.08:81"`` or ``"0.03"``.
    name : str
        The option, for the error message.

    Raises
    ------
    ParameterError
        Naming ``name`` (e.g. ``"--E"``) and the allowed form.
    """
    parts = spec.split(":")
    try:
        if len(parts) == 1:
            return np.array([float(parts[0])])
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except (ValueError, IndexError):
        raise ParameterError(name, f"must be START:STOP:NUM in metres, e.g. 0:0.08:81 (got {spec!r})") from None
    if len(parts) != 3 or not 1 <= num <= MAX_GRID_POINTS or not start <= stop or not np.isfinite([start, stop]).all():
        raise ParameterError(
            name, f"must be START:STOP:NUM with START <= STOP and 1 <= NUM <= {MAX_GRID_POINTS:,} (got {spec!r})"
        )
    return np.linspace(start, stop, num)


def sweep(
    model: Model,
    eccentricity,
    lordosis,
    *,
    method: str = "fast",
    chunk_size: int = DEFAULT_CHUNK,
    progress: bool | None = None,
) -> xr.Dataset:
    """Minimum PCSA and counter torques on the grid E x Lambda (Figures 3 and 4).

    Parameters
    ----------
    model : Model
        Its ``passive.stiffness`` is the K of this landscape.
    eccentricity, lordosis : array_like, 1-D
        Grid axes E and Lambda [m].
    method : {'fast', 'per-point'}
    chunk_size : int
        Grid points per chunk.
    progress : bool or None
        Show a progress bar on stderr; None: only on a terminal.

    Returns
    -------
    xarray.Dataset
        Dimensions ``E``, ``Lambda``, ``segment``, ``muscle``; schema in docs/optimisation.md.
    """
    if method not in METHODS:
        raise ParameterError("method", f"must be one of {', '.join(map(repr, METHODS))} (got {method!r})")
    if int(chunk_size) < 1:
        raise ParameterError("chunk_size", f"must be >= 1 (got {chunk_size})")
    e_axis = np.atleast_1d(np.asarray(eccentricity, float))
    l_axis = np.atleast_1d(np.asarray(lordosis, float))
    if e_axis.ndim != 1 or l_axis.ndim != 1 or e_axis.size * l_axis.size > MAX_GRID_POINTS:
        raise ParameterError("grid", f"must be two 1-D axes with at most {MAX_GRID_POINTS:,} points in all")
    e_grid, l_grid = (a.ravel() for a in np.meshgrid(e_axis, l_axis, indexing="ij"))
    disable = None if progress is None else not progress  # None: tqdm shows it on a terminal only
    with tqdm(total=e_grid.size, disable=disable, unit="pt", desc="sweep") as bar:
        options = {"method": method, "chunk_size": chunk_size, "update": bar.update}
        arrays, per_point = point_columns(model, e_grid, l_grid, **options)
    shape = (e_axis.size, l_axis.size)
    arrays = {name: values.reshape(shape + values.shape[1:]) for name, values in arrays.items()}
    return _dataset(model, e_axis, l_axis, arrays, method, per_point)


def point_columns(
    model: Model, eccentricity, lordosis, *, method: str = "fast", chunk_size: int = DEFAULT_CHUNK, update=None
) -> tuple[dict[str, np.ndarray], int]:
    """Every variable of :data:`VARIABLES` at the points (E_i, Lambda_i), solved chunk by chunk.

    The fast path solves each chunk of ``chunk_size`` consecutive points as one
    stacked problem, so the answer depends on the chunking only through the
    solver's tolerance; the same points in the same chunks give the same bits.

    Parameters
    ----------
    model : Model
        The parameters; ``passive.stiffness`` is K.
    eccentricity, lordosis : array_like, shape (P,)
        E and Lambda of each point [m].
    method : {'fast', 'per-point'}
    chunk_size : int
        Points per chunk.
    update : callable, optional
        Called with the number of points solved, after each chunk (fast) or point (per-point).

    Returns
    -------
    columns : dict of str to numpy.ndarray
        Each variable with leading dimension P, in the units of its name.
    per_point : int
        Points that the per-point reference solved (all of them with ``method='per-point'``).
    """
    e_grid, l_grid = np.asarray(eccentricity, float), np.asarray(lordosis, float)
    update = update or (lambda n: None)
    arrays: dict[str, np.ndarray] = {}  # filled chunk by chunk: no copies of the answer beyond the answer
    per_point = 0
    for start in range(0, e_grid.size, int(chunk_size)):
        part = slice(start, start + int(chunk_size))
        coeffs = checked_coefficients(model, e_grid[part], l_grid[part])  # raises for bad input
        data = problem_data(model, coeffs)
        tol = model.optimisation.ct_tolerance
        if method == "fast":
            result = batch.solve_stacked(data, tol)
            update(len(data.stability))
        else:
            result = batch.solve_points(data, tol, progress=update)
        per_point += result.per_point
        with arithmetic_guard(e_grid[part], l_grid[part]):  # e.g. K = 1e154 overflows S^2 in the reflex roots
            columns = _chunk_columns(result, coeffs, model)
        for name, values in columns.items():
            if name not in arrays:
                arrays[name] = np.empty((e_grid.size,) + values.shape[1:], values.dtype)
            arrays[name][part] = values
    return arrays, per_point


def _chunk_columns(result: batch.BlockOptimum, coeffs, model: Model) -> dict[str, np.ndarray]:
    """The Dataset's variables for one chunk, in the units of their names."""
    return _reflex_columns(model, coeffs, result.pcsa) | {
        "min_pcsa_cm2": m2_to_cm2(result.min_pcsa),
        "pcsa_cm2": m2_to_cm2(result.pcsa),
        "counter_torque_Nm": result.counter_torque,
        "counter_torque_norm_Nm": np.linalg.norm(result.counter_torque, axis=-1),
        "status": result.status.astype(object),
        "stiffness_per_cm2": coeffs.stiffness_per_pcsa * M2_PER_CM2,
        "damping_per_cm2": coeffs.damping_per_pcsa * M2_PER_CM2,
        "torque_per_cm2": coeffs.torque_per_pcsa * M2_PER_CM2,
        "gravity_stiffness_Nm_per_rad": coeffs.gravity_stiffness,
        "gravity_torque_Nm": coeffs.gravity_torque,
        "passive_stiffness_Nm_per_rad": coeffs.passive_stiffness,
        "inertia_kgm2": coeffs.inertia,
    }


def _reflex_columns(model: Model, coeffs, pcsa) -> dict[str, np.ndarray]:
    """Delayed PD reflex at every point and segment (docs/reflex.md), vectorised.

    The global muscles are active at ``reflex.activation`` times the chosen
    activation (1: self-stable, no reflex needed; 0: reflex only); the gains
    follow ``reflex``. The delay margin does not depend on the delay, so
    ``delay_margin_s > tau`` answers "stable at delay tau" for any tau.
    Infeasible points (NaN PCSA) get NaN and status 'undefined'.
    """
    active = model.reflex.activation * pcsa
    maps = reflex.landscape(coeffs.stiffness(active), coeffs.damping(active), coeffs.inertia, model.reflex)
    return {
        "reflex_kp_Nm_per_rad": maps.kp,
        "reflex_kd_Nms_per_rad": maps.kd,
        "delay_margin_s": maps.delay_margin,
        "delay_margin_pade_s": maps.delay_margin_pade,
        "delay_margin_status": np.asarray(reflex.STATUS, dtype=object)[maps.delay_margin_status],
        "stable_at_delay": maps.stable_at_delay,
        "spine_delay_margin_s": np.min(maps.delay_margin, axis=-1),
    }


VARIABLES = {
    "min_pcsa_cm2": ("cm2", "minimum total PCSA of the global muscles for self-stability of all segments (Fig. 3)"),
    "pcsa_cm2": ("cm2", "chosen activation: PCSA of each muscle (least ||CT|| within ct_tolerance of the minimum)"),
    "counter_torque_Nm": ("N m", "local counter torque CT_k at the chosen activation"),
    "counter_torque_norm_Nm": ("N m", "Euclidean norm ||CT|| of the local counter torques (Fig. 4)"),
    "status": ("", "solver status: optimal, optimal_inaccurate, infeasible, infeasible_inaccurate, solver_error"),
    "stiffness_per_cm2": ("N m rad-1 cm-2", "dM_k/dalpha of each muscle per cm2 of its PCSA"),
    "damping_per_cm2": ("N m s rad-1 cm-2", "dM_k/domega of each muscle per cm2 of its PCSA"),
    "torque_per_cm2": ("N m cm-2", "torque of each muscle about CoR k per cm2 of its PCSA, upright"),
    "gravity_stiffness_Nm_per_rad": ("N m rad-1", "dM_ext/dalpha of the point mass (destabilising if > 0)"),
    "gravity_torque_Nm": ("N m", "torque M_ext of the point mass about CoR k, upright"),
    "passive_stiffness_Nm_per_rad": ("N m rad-1", "passive stiffness K as a torque stiffness (enters dM/dalpha as -K)"),
    "inertia_kgm2": ("kg m2", "moment of inertia theta_k of the upper body about CoR k"),
    "reflex_kp_Nm_per_rad": ("N m rad-1", "proportional gain kp of the delayed reflex (reflex settings)"),
    "reflex_kd_Nms_per_rad": ("N m s rad-1", "derivative gain kd of the delayed reflex (reflex settings)"),
    "delay_margin_s": ("s", "exact delay margin of the reflex loop at reflex.activation x chosen PCSA"),
    "delay_margin_pade_s": ("s", "Pade estimate of the delay margin at reflex.pade_order"),
    "delay_margin_status": ("", "finite, delay_independent (inf), unstable_without_delay (0) or undefined (NaN)"),
    "stable_at_delay": ("", "closed loop stable with the delay reflex.delay (exact)"),
    "spine_delay_margin_s": ("s", "smallest delay margin over the segments: the delay the whole spine tolerates"),
}
"""Every data variable: units (UDUNITS) and long name."""


def dims_of(name: str, ndim: int) -> tuple[str, ...]:
    """Dimensions of the variable ``name`` on the grid, from the number of its dimensions.

    Parameters
    ----------
    name : str
        A key of :data:`VARIABLES`.
    ndim : int
        2 (E, Lambda), 3 (plus segment, or muscle for ``pcsa_cm2``) or 4 (plus segment and muscle).
    """
    extra = {3: ("muscle",) if name == "pcsa_cm2" else ("segment",), 4: ("segment", "muscle")}
    return ("E", "Lambda") + extra.get(ndim, ())


def grid_coordinates(model: Model, e_axis, l_axis) -> dict:
    """The coordinates ``E``, ``Lambda``, ``segment`` and ``muscle`` of a landscape, with units and names.

    Parameters
    ----------
    model : Model
        Supplies the names of the segments and muscles.
    e_axis, l_axis : array_like, 1-D
        Grid axes E and Lambda [m].
    """
    return {
        "E": ("E", e_axis, {"units": "m", "long_name": "eccentricity of the spine"}),
        "Lambda": ("Lambda", l_axis, {"units": "m", "long_name": "lordosis: horizontal offset of P3"}),
        "segment": ("segment", list(model.geometry.cor_names), {"long_name": "centre of rotation"}),
        "muscle": ("muscle", list(model.muscle_names), {"long_name": "global muscle"}),
    }


def _dataset(model: Model, e_axis, l_axis, arrays: dict, method: str, per_point: int) -> xr.Dataset:
    data_vars = {
        name: xr.Variable(dims_of(name, arr.ndim), arr, {"units": VARIABLES[name][0], "long_name": VARIABLES[name][1]})
        for name, arr in arrays.items()
    }
    coords = grid_coordinates(model, e_axis, l_axis) | {
        "K": ((), model.passive.stiffness, {"units": "N m rad-1", "long_name": "passive stiffness K"}),
    }
    attrs = {
        "title": "spinectl landscapes of minimum PCSA and counter torques",
        "source": f"spinectl {__version__}",
        "references": PAPER_REFERENCE,
        "method": method,
        "points_solved_per_point": per_point,
        "passive_convention": model.passive.convention,
        "activation": model.optimisation.activation,
        "reflex_delay_s": model.reflex.delay,
        "reflex_activation": model.reflex.activation,
        "config_toml": config.dump_toml(model),
    }
    return xr.Dataset(data_vars, coords, attrs)


def stiffness_sweep(model: Model, stiffnesses, eccentricity, lordosis, **options) -> xr.Dataset:
    """:func:`sweep` for several passive stiffnesses K [N m/rad], stacked along a ``K`` dimension.

    ``config_toml`` is then the model of the first K; the ``K`` coordinate gives each one's
    ``passive.stiffness`` (convention: ``passive_convention``).

    Parameters
    ----------
    model : Model
    stiffnesses : sequence of float
        K values [N m/rad].
    eccentricity, lordosis : array_like, 1-D
        Grid axes [m].
    **options
        Passed to :func:`sweep`.
    """
    parts = [
        sweep(config.set_parameter(model, "passive.stiffness", float(k)), eccentricity, lordosis, **options)
        for k in stiffnesses
    ]
    combined = xr.concat(parts, dim="K", data_vars="all", coords="minimal", compat="override", combine_attrs="override")
    combined.attrs["points_solved_per_point"] = sum(p.attrs["points_solved_per_point"] for p in parts)
    return combined


def model_of(dataset: xr.Dataset) -> Model:
    """The resolved model a Dataset was computed with (from its ``config_toml`` attribute).

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`sweep` or :func:`load`.
    """
    return config.from_dict(Model, tomllib.loads(dataset.attrs["config_toml"]))


def save(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write a Dataset to NetCDF atomically (:func:`spinectl.io.atomic_path`).

    Parameters
    ----------
    dataset : xarray.Dataset
    path : str or Path
    """
    with atomic_path(path) as tmp:
        dataset.to_netcdf(tmp, engine="netcdf4")
    return Path(path)


def load(path: str | Path) -> xr.Dataset:
    """Read a Dataset written by :func:`save` fully into memory (the file is closed again).

    Parameters
    ----------
    path : str or Path

    Raises
    ------
    ParameterError
        The file is missing, not NetCDF or not a sweep (field ``results``).
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError("results", f"file not found: {path}")
    try:
        dataset = xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError) as exc:
        raise ParameterError("results", f"{path} is not a spinectl NetCDF file ({exc.__class__.__name__})") from None
    missing = [name for name in (*REQUIRED, "E", "Lambda") if name not in dataset.variables]
    if missing or "config_toml" not in dataset.attrs:
        what = ", ".join(missing) or "attribute config_toml"
        raise ParameterError("results", f"{path} is not a spinectl sweep (missing {what})")
    return dataset
