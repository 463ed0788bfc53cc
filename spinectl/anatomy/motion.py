"""The Cholewicki-McGill stability index along a recorded motion (docs/motion.md).

Cholewicki & McGill (1996, Clin Biomech 11:1-15, doi:10.1016/0268-0033(95)00035-6) judge the lumbar spine's
stability through a task by the least eigenvalue of the Hessian of its potential energy, evaluated frame by
frame with the muscles' forces of that frame. Here that Hessian is -K of the chain linearised at each frame's
operating point, the index is the least eigenvalue of -K [N m/rad per joint radian], on the free chain (every
chain joint free at once, equality constraints off) and on the chain constrained by the model's lumbar rhythm.

:func:`motion_response` computes (no file written, no figure drawn), :func:`motion_plot` draws
(:mod:`spinectl.anatomy.motion_figures`), as python-control separates a response from its plot. Each frame is
the operating point :func:`spinectl.anatomy.analyses.analyse` would analyse: the posture from the coordinates
file (:func:`spinectl.anatomy.recordings.read_recording`, read once), the activations from an activations file
at the same time, the optimum at that posture (:func:`spinectl.anatomy.optimum.optimise`) or the model's own
controls; the chains are the engine's (:meth:`~spinectl.anatomy.contract.AnatomyEngine.chains`) and the
verdicts :func:`spinectl.anatomy.analyses.verdict`'s, so a frame's index is ``analyse``'s at that posture.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validate import show
from ..errors import ParameterError
from .analyses import activations as activation_vector
from .analyses import reflex_margin, verdict
from .identity import model_identity
from .loads import analysed_loads
from .motion_removal import REMOVAL_REFERENCE, frame_removal, removal_data, removal_spec, removal_summary

OPTIMISE = ("none", "joints", "chain")
"""``--optimise``: none (the activations file, or the model's own controls), or the anatomy optimum per frame
with the stability criterion joint by joint or of the free chain (:func:`spinectl.anatomy.optimum.optimise`)."""

FREE = "the chain, free: every chain joint free at once, equality constraints off"
CONSTRAINED = "the chain constrained by the model's lumbar rhythm"
"""The criteria that every stable/unstable of the output names."""

RATE_TOLERANCE = 1e-9
"""Relative slack of ``rate`` against the file's own rate: a file's times are written to 8 decimals."""


@dataclass(frozen=True)
class MotionResult:
    """The index along a motion (:func:`motion_response`).

    Attributes
    ----------
    dataset : xarray.Dataset
        Dims ``time``, ``joint`` (the free chain's), ``mode`` (of the free chain), ``coordinate`` and
        ``constrained_mode`` (the constrained chain's), ``muscle`` (and ``muscle_class`` with the contributions,
        ``group`` with the removal); every variable's ``units`` and ``description`` in its attributes, the
        model's identity in the Dataset's.
    """

    dataset: object

    @property
    def times(self) -> np.ndarray:
        """The frames' times [s]."""
        return self.dataset["time"].values

    def summary(self) -> str:
        """A few lines: the model, the frames, the least index of each chain and where; each criterion named.

        Returns
        -------
        str
        """
        ds = self.dataset
        lines = [
            f"{ds.attrs['model_identity_text']}, {ds.attrs['plane']} plane, {ds.sizes['time']} frames of "
            f"{ds.attrs['coordinates_file']} ({ds.attrs['activation_source']})"
        ]
        lines += [
            f"load (in the equilibrium and K, every frame): {text}"
            for text in json.loads(ds.attrs.get("loads_text", "[]"))
        ]
        for name, criterion in (("free", FREE), ("constrained", CONSTRAINED)):
            index = ds[f"{name}_index"].values
            unstable = ds[f"{name}_unstable_modes"].values
            if np.all(np.isnan(index)):
                lines.append(f"{criterion}: no frame solved")
                continue
            at = int(np.nanargmin(index))
            lines.append(
                f"{criterion}: least index {index[at]:.4g} N m/rad at t = {self.times[at]:g} s; "
                f"unstable in {int(np.sum(unstable > 0))} of {index.size} frames"
            )
        return "\n".join(lines + removal_summary(ds))


def select_frames(times, frames=None, rate=None, fields=("frames", "rate")) -> np.ndarray:
    """The indices of the frames analysed: all, a range of them, or one every 1/rate seconds.

    Parameters
    ----------
    times : array_like, shape (t,)
        The file's times [s], increasing.
    frames : tuple of int, optional
        ``(first, last, step)``: frame indices from 0, ``last`` included.
    rate : float, optional
        Frames per second [Hz], > 0 and at most the file's own rate ((t - 1) / duration); the frame nearest
        each time ``times[0] + k / rate``.
    fields : tuple of str
        The names of ``frames`` and ``rate`` in messages (the command line's ``--frames``, ``--rate``).

    Returns
    -------
    numpy.ndarray of int

    Raises
    ------
    ParameterError
        Both given, a range outside the file's frames, a step < 1, a rate <= 0 or above the file's.
    """
    times = np.asarray(times, float)
    n = times.size
    if frames is not None and rate is not None:
        raise ParameterError(fields[1], f"cannot go with {fields[0]}: choose the frames one way")
    if n == 0:
        raise ParameterError("coordinates", "the file has no frames")
    if frames is not None:
        first, last, step = frames
        if not (0 <= first <= last < n) or step < 1:
            raise ParameterError(
                fields[0],
                f"must be FIRST:LAST[:STEP] with 0 <= FIRST <= LAST <= {n - 1} (the file's {n} frames) "
                f"and STEP >= 1 (got {first}:{last}:{step})",
            )
        return np.arange(first, last + 1, step)
    if rate is None:
        return np.arange(n)
    own = (n - 1) / (times[-1] - times[0]) if n > 1 else 0.0
    if not (np.isfinite(rate) and 0 < rate <= own * (1 + RATE_TOLERANCE)):
        raise ParameterError(fields[1], f"must be > 0 and at most the file's own rate, {own:.6g} Hz (got {show(rate)})")
    targets = times[0] + np.arange(int(np.floor((times[-1] - times[0]) * rate * (1 + RATE_TOLERANCE))) + 1) / rate
    right = np.clip(np.searchsorted(times, targets), 1, n - 1)
    nearer_left = targets - times[right - 1] <= times[right] - targets
    return np.unique(np.where(nearer_left, right - 1, right))


def motion_response(
    anatomy,
    recording,
    activations=None,
    optimise="none",
    frames=None,
    rate=None,
    plane="sagittal",
    joint_stiffness="none",
    least_stiffness=None,
    progress=None,
    loads=(),
    contributions=False,
    reflex=None,
    removal=None,
    groups=None,
) -> MotionResult:
    """The stability index, free and constrained, at each frame of a recorded motion.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (:func:`spinectl.anatomy.load`).
    recording : Recording
        The coordinates (:func:`spinectl.anatomy.recordings.read_recording` with field ``"posture"``).
    activations : Recording, optional
        The activations (field ``"activations"``), read at each frame's time.
    optimise : {"none", "joints", "chain"}
        ``"none"``: ``activations``, else the model's own controls; else the optimum at each frame's posture
        with that stability criterion (margin 1 N m/rad, :func:`spinectl.anatomy.optimum.optimise`).
    frames, rate : optional
        The frames analysed (:func:`select_frames`).
    plane : str
        One of the mapping's planes.
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    least_stiffness : float, optional
        Also the least added joint stiffness with -K + diag(k) >= margin I on the free chain, at this margin
        [N m/rad] (the SDP :func:`spinectl.optimise.coupled.sdp.least_local_stiffness_at`).
    progress : bool or None
        A progress bar on stderr; None: on a terminal only (as the study and the atlas).
    loads : sequence of BodyLoad or dict, optional
        External loads (:mod:`spinectl.anatomy.loads`), the same at every frame: in the equilibrium, in K and in
        the optimum, as ``analyse(..., loads=)``.
    contributions : bool
        Also each muscle's and each class's d lambda_min / d a_i on both chains
        (:func:`spinectl.model.contributions.contributions`; NaN where lambda_min is repeated).
    reflex : tuple, optional
        ``(kp, kd, lag)``: also the free chain's exact delay margin under that reflex at each frame
        (:func:`spinectl.anatomy.analyses.reflex_margin`).
    removal : {None, "groups", "muscles"}
        Also the removal method at each frame (:mod:`spinectl.anatomy.motion_removal`): the index of both chains
        with each muscle class and each of ``groups`` removed (``"muscles"``: each muscle too, not with
        ``optimise``); the others' activations kept, or with ``optimise`` the optimum re-solved without them
        (one re-solve per class and group per frame).
    groups : dict, optional
        Named groups removed (:func:`spinectl.model.contributions.resolve_groups`); they go with ``removal``.

    Returns
    -------
    MotionResult

    Raises
    ------
    ParameterError
        One line: ``optimise`` and ``activations`` both given, a frame selection outside the file, a frame
        that the model cannot read (a missing coordinate, NaN), activations missing at a frame's time; a removal
        refused (:func:`spinectl.anatomy.motion_removal.check_removal`), a group that matches no muscle.
    """
    from tqdm import tqdm  # plain: tqdm.auto warns in kernels without ipywidgets (as the study)

    if optimise not in OPTIMISE:
        raise ParameterError("optimise", f"must be one of {OPTIMISE} (got {show(optimise)})")
    if optimise != "none" and activations is not None:
        raise ParameterError("activations", "cannot go with optimise, which finds the activations itself")
    loads = analysed_loads(loads, False)
    extras = {"loads": loads, "contributions": bool(contributions), "reflex": reflex}
    extras["removal"] = removal_spec(anatomy, removal, groups, optimise, _classes(anatomy))  # before any frame
    chosen = select_frames(recording.times, frames, rate)
    points = [_read_point(anatomy, recording, activations, float(recording.times[i])) for i in chosen]  # every
    # frame's columns, NaNs and activation times checked before the first is solved: a bad last frame costs no run
    rows = []
    with tqdm(
        total=chosen.size, unit="frame", desc="motion", disable=None if progress is None else not progress
    ) as bar:
        for time, (values, a) in zip(recording.times[chosen], points, strict=True):
            try:
                rows.append(
                    _frame(anatomy, float(time), values, a, optimise, plane, joint_stiffness, least_stiffness, extras)
                )
            except ParameterError as exc:  # a frame the engine cannot linearise: say which
                raise type(exc)(exc.field, f"at t = {float(time):g} s of the motion: {exc.message}") from None
            bar.update(1)
    return MotionResult(
        _dataset(anatomy, recording, activations, optimise, plane, joint_stiffness, least_stiffness, rows, extras)
    )


def _read_point(anatomy, recording, activations, time) -> tuple:
    """One frame's coordinates (name -> value [rad or m]) and activations (None: not from a file), checked."""
    values = recording.frame(anatomy.posture_columns(), time).values
    if activations is None:
        return values, None
    frame = activations.frame(anatomy.activation_columns(), time)
    return values, activation_vector(anatomy, np.array([frame.values[name] for name in anatomy.muscles]))


def _activations_at(anatomy, posture, a, optimise, plane, joint_stiffness, loads=()) -> tuple:
    """The frame's activations (the file's, the optimum's or the model's own) and the optimum (or None)."""
    if a is not None or optimise == "none":
        return (activation_vector(anatomy, None) if a is None else a), None
    from .optimum import optimise as optimum

    loaded = {"loads": loads} if loads else {}  # without: the optimum's call as it was
    opt = optimum(anatomy, plane, stability=optimise, posture=posture, joint_stiffness=joint_stiffness, **loaded)
    return opt.activations, opt


def _frame(anatomy, time, values, a, optimise, plane, joint_stiffness, least_stiffness, extras) -> dict:
    """Everything the Dataset holds of one frame: its coordinates ``values`` and activations ``a`` (or None)."""
    posture = anatomy.named_posture(values)
    loads = extras["loads"]
    a, opt = _activations_at(anatomy, posture, a, optimise, plane, joint_stiffness, loads)
    row = {"time": time, "activation": a, "optimum_status": "" if opt is None else opt.status}
    free_chain = anatomy.plane_joints(plane)
    row["posture"] = np.array([values.get(j, np.nan) for j in free_chain])
    if not np.all(np.isfinite(a)):  # an optimum not found: no operating point, no index
        return row
    loaded = {"loads": loads} if loads else {}  # without: the engines' calls as they were
    free, con, lin = anatomy.chains(plane, posture, joint_stiffness, activations=a, **loaded)
    eq_rows, tau_per, tau_0 = anatomy.equilibrium_rows(lin, plane, posture, "rhythm")
    dofs = list(lin.dofs[: lin.n])
    row["net_torque"] = lin.torque_per_muscle[dofs] @ a + lin.torque_offset[dofs]
    row["residual"] = float(np.linalg.norm(tau_per @ a + tau_0))
    row["joints"], row["coordinates"] = free.joints, con.joints
    for name, chain in (("free", free), ("constrained", con)):
        v = verdict(chain, a)
        shape = v.modes[:, 0] * np.sign(v.modes[np.argmax(np.abs(v.modes[:, 0])), 0])  # largest entry positive
        row[name] = (v.eigenvalues, shape, int(np.sum(v.eigenvalues <= 0)))
    if least_stiffness is not None:
        from ..optimise.coupled.sdp import least_local_stiffness_at

        status, k = least_local_stiffness_at(free.stiffness(a), least_stiffness)
        row["least"] = np.full(free.n_joints, np.nan) if k is None else k
    if extras["contributions"]:
        row.update(_contributions(anatomy, free, con, a))
    if extras["removal"] is not None:
        at = (posture, plane, joint_stiffness, optimise, loads, extras["removal"])
        row.update(frame_removal(anatomy, (free, con), a, *at))
    if extras["reflex"] is not None:
        margin = reflex_margin(free, a, *extras["reflex"])
        row["delay_margin"] = (margin["delay_margin_s"], margin["delay_margin_frequency_rad_s"])
        row["delay_margin_status"] = margin["delay_margin_status"]
    return row


def _contributions(anatomy, free, con, a) -> dict:
    """d lambda_min / d a_i per muscle (in the model's muscle order) and per class, on both chains."""
    from ..model.contributions import contributions

    out = {}
    for name, chain in (("free", free), ("constrained", con)):
        c = contributions(chain, a)
        by_name = dict(zip(c.controls, c.derivative, strict=True))
        per_class = c.classes()
        out[f"{name}_contribution"] = np.array([by_name.get(m, np.nan) for m in anatomy.muscles])
        out[f"{name}_class_contribution"] = np.array(
            [c.sums(per_class[k])[0] if k in per_class else np.nan for k in _classes(anatomy)]
        )
    return out


def _classes(anatomy) -> tuple:
    """The control classes of the model's muscles, in :data:`~spinectl.model.linear_chain.CONTROL_CLASSES` order."""
    from ..model.linear_chain import CONTROL_CLASSES

    return tuple(c for c in CONTROL_CLASSES if c in set(anatomy.classes))


def _stack(rows, key, width, part=None) -> np.ndarray:
    """One variable over the frames: NaN where a frame has none (an optimum not found)."""
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        if key in row:
            out[i] = row[key] if part is None else row[key][part]
    return out


VARIABLES = {
    "free_index": (("time",), "N m/rad", f"least eigenvalue of -K, {FREE} (per joint radian); > 0 stable"),
    "constrained_index": (("time",), "N m/rad", f"least eigenvalue of -K, {CONSTRAINED}; > 0 stable"),
    "free_eigenvalues": (("time", "mode"), "N m/rad", f"eigenvalues of -K, ascending, {FREE}"),
    "constrained_eigenvalues": (
        ("time", "constrained_mode"),
        "N m/rad",
        f"eigenvalues of -K, ascending, {CONSTRAINED}",
    ),
    "free_mode_shape": (("time", "joint"), "1", f"unit eigenvector of the least eigenvalue, largest entry > 0, {FREE}"),
    "constrained_mode_shape": (
        ("time", "coordinate"),
        "1",
        f"unit eigenvector of the least eigenvalue, largest entry > 0, {CONSTRAINED}",
    ),
    "free_unstable_modes": (("time",), "1", f"eigenvalues of -K <= 0 (NaN: no operating point), {FREE}"),
    "constrained_unstable_modes": (("time",), "1", f"eigenvalues of -K <= 0 (NaN: no operating point), {CONSTRAINED}"),
    "net_torque": (
        ("time", "joint"),
        "N m",
        "net generalised force of muscles, gravity and passive tissue on each free-chain joint",
    ),
    "equilibrium_residual": (
        ("time",),
        "N m",
        "norm of the net torque on the rhythm's coordinates (0: in equilibrium)",
    ),
    "posture": (("time", "joint"), "rad", "the chain's coordinates as the file gives them (converted from degrees)"),
    "activation": (("time", "muscle"), "", "each muscle's control at the frame (units: the model's control unit)"),
    "least_joint_stiffness": (
        ("time", "joint"),
        "N m/rad",
        f"least added stiffness per joint with -K + diag(k) >= margin I (attribute margin), {FREE}",
    ),
    "free_contribution": (
        ("time", "muscle"),
        "N m/rad per control unit",
        f"d lambda_min / d a_i = v^T (-K_i) v at the least mode v (NaN: lambda_min repeated), {FREE}",
    ),
    "constrained_contribution": (
        ("time", "muscle"),
        "N m/rad per control unit",
        f"d lambda_min / d a_i = v^T (-K_i) v at the least mode v (NaN: lambda_min repeated), {CONSTRAINED}",
    ),
    "free_class_contribution": (
        ("time", "muscle_class"),
        "N m/rad per control unit",
        f"d lambda_min / d a_i summed over the class's muscles, {FREE}",
    ),
    "constrained_class_contribution": (
        ("time", "muscle_class"),
        "N m/rad per control unit",
        f"d lambda_min / d a_i summed over the class's muscles, {CONSTRAINED}",
    ),
    "delay_margin": (
        ("time",),
        "s",
        f"exact delay margin of the reflex (attributes kp, kd, activation_lag; inf: any delay), {FREE}",
    ),
    "delay_margin_frequency": (("time",), "rad/s", f"the crossing frequency at the delay margin, {FREE}"),
}
"""Every variable of the Dataset: dims, units, description (the criterion named where it is a verdict)."""


def _values(rows, n: int, c: int, m: int) -> dict:
    """The variables' values over the frames, NaN where a frame has none (an optimum not found)."""
    return {
        "free_index": _stack(rows, "free", n, 0)[:, 0],
        "constrained_index": _stack(rows, "constrained", max(c, 1), 0)[:, 0],
        "free_eigenvalues": _stack(rows, "free", n, 0),
        "constrained_eigenvalues": _stack(rows, "constrained", c, 0),
        "free_mode_shape": _stack(rows, "free", n, 1),
        "constrained_mode_shape": _stack(rows, "constrained", c, 1),
        "free_unstable_modes": _stack(rows, "free", 1, 2)[:, 0],
        "constrained_unstable_modes": _stack(rows, "constrained", 1, 2)[:, 0],
        "net_torque": _stack(rows, "net_torque", n),
        "equilibrium_residual": _stack(rows, "residual", 1)[:, 0],
        "posture": _stack(rows, "posture", n),
        "activation": _stack(rows, "activation", m),
    }


def _dataset(anatomy, recording, activations, optimise, plane, joint_stiffness, least_stiffness, rows, extras):
    """The frames as an xarray Dataset, units and descriptions on every variable, the model's identity."""
    import xarray as xr

    from .identity import identity_text

    solved = [r for r in rows if "free" in r]
    joints = tuple(solved[0]["joints"]) if solved else tuple(anatomy.plane_joints(plane))
    coordinates = tuple(solved[0]["coordinates"]) if solved else ()
    n, c = len(joints), len(coordinates)
    values = _values(rows, n, c, len(anatomy.muscles))
    if least_stiffness is not None:
        values["least_joint_stiffness"] = _stack(rows, "least", n)
    values |= _extra_values(anatomy, rows, extras)
    data = {}
    for name, value in values.items():
        dims, units, description = VARIABLES[name]
        data[name] = (dims, value, {"units": units or anatomy.control_unit, "description": description})
    if least_stiffness is not None:
        data["least_joint_stiffness"][2]["margin"] = float(least_stiffness)
    _extra_attributes(data, extras)
    status = np.array([r["optimum_status"] for r in rows], dtype=object)
    data["optimum_status"] = (("time",), status, {"description": "the optimum's solver status ('' without one)"})
    if extras["reflex"] is not None:
        margin = np.array([r.get("delay_margin_status", "") for r in rows], dtype=object)
        data["delay_margin_status"] = (("time",), margin, {"description": "the delay margin's status ('' unsolved)"})
    coords = {
        "time": ("time", np.array([r["time"] for r in rows]), {"units": "s"}),
        "joint": ("joint", list(joints)),
        "mode": ("mode", np.arange(n)),
        "coordinate": ("coordinate", list(coordinates)),
        "constrained_mode": ("constrained_mode", np.arange(c)),
        "muscle": ("muscle", list(anatomy.muscles)),
    }
    if extras["contributions"]:
        coords["muscle_class"] = ("muscle_class", list(_classes(anatomy)))
    if extras["removal"] is not None:
        removed, group = removal_data(rows, extras["removal"], optimise, {"free": FREE, "constrained": CONSTRAINED})
        data |= removed
        coords |= group
    identity = model_identity(anatomy)
    attrs = {
        "title": "Cholewicki-McGill stability index along a motion (spinectl motion)",
        "references": "Cholewicki J, McGill SM (1996) Clin Biomech 11:1-15, doi:10.1016/0268-0033(95)00035-6",
        "model_name": identity["name"],
        "model_source": str(identity["source"]),
        "model_sha256": identity["sha256"],
        "model_engine": identity["engine"],
        "model_identity": json.dumps(identity),
        "model_identity_text": identity_text(identity),
        "plane": plane,
        "coordinates_file": str(recording.path.name),
        "activation_source": _activation_source(anatomy, activations, optimise),
        "joint_stiffness_added": str(joint_stiffness),
        "free_criterion": FREE,
        "constrained_criterion": CONSTRAINED,
        "loads": json.dumps([load.to_dict() for load in extras["loads"]]),
        "loads_text": json.dumps([load.text() for load in extras["loads"]]),
    }
    if extras["removal"] is not None:
        attrs["references"] += f"; {REMOVAL_REFERENCE}"
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _extra_values(anatomy, rows, extras) -> dict:
    """The contributions' and the delay margin's variables, where asked for."""
    out = {}
    if extras["contributions"]:
        for name in ("free", "constrained"):
            out[f"{name}_contribution"] = _stack(rows, f"{name}_contribution", len(anatomy.muscles))
            out[f"{name}_class_contribution"] = _stack(rows, f"{name}_class_contribution", len(_classes(anatomy)))
    if extras["reflex"] is not None:
        out["delay_margin"] = _stack(rows, "delay_margin", 2)[:, 0]
        out["delay_margin_frequency"] = _stack(rows, "delay_margin", 2)[:, 1]
    return out


def _extra_attributes(data, extras) -> None:
    """The reflex's gains on its variables, and the margin's status per frame."""
    if extras["reflex"] is None:
        return
    gains = dict(zip(("kp", "kd", "activation_lag"), (float(x) for x in extras["reflex"]), strict=True))
    data["delay_margin"][2].update(gains)
    data["delay_margin_frequency"][2].update(gains)


def _activation_source(anatomy, activations, optimise) -> str:
    if activations is not None:
        return f"activations from {activations.path.name}"
    if optimise != "none":
        return f"the optimum per frame, stability criterion: {optimise}"
    return f"the model's own controls: {anatomy.default_controls_source()}"


def write_motion(path, labels, times, values, in_degrees: bool = True):
    """A motion written as an OpenSim ``.mot``/``.sto`` by OpenSim's own API, atomically (a lab's IK output's form).

    ``opensim.TimeSeriesTable`` with the header's ``inDegrees``, written by ``opensim.STOFileAdapter`` to a
    temporary name, then renamed (:func:`spinectl.atomic.atomic_path`): a worked example or a synthetic motion
    is a file that :func:`~spinectl.anatomy.recordings.read_recording` and every OpenSim tool read.

    Parameters
    ----------
    path : str or pathlib.Path
        The file written.
    labels : sequence of str
        The column labels (coordinate or muscle names, or OpenSim paths).
    times : array_like, shape (t,)
        Strictly increasing [s].
    values : array_like, shape (t, len(labels))
        One row per time [deg or rad, m; or activations 1].
    in_degrees : bool or None
        The header's ``inDegrees`` (``yes``/``no``); None: none written (an activations file).

    Returns
    -------
    pathlib.Path
    """
    from ..atomic import atomic_path
    from .export_osim import require_opensim

    osim = require_opensim()
    values = np.asarray(values, float)
    table = osim.TimeSeriesTable()
    table.setColumnLabels(osim.StdVectorString([str(label) for label in labels]))
    for t, row in zip(np.asarray(times, float), values, strict=True):
        table.appendRow(float(t), osim.RowVector(row))
    if in_degrees is not None:
        table.addTableMetaDataString("inDegrees", "yes" if in_degrees else "no")
    with atomic_path(path) as tmp:
        osim.STOFileAdapter.write(table, str(tmp))
    return Path(path)


def motion_plot(result: MotionResult):
    """The index and the unstable modes against time, the chain's posture below (:mod:`.motion_figures`).

    Parameters
    ----------
    result : MotionResult

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .motion_figures import motion_figure

    return motion_figure(result.dataset)


def removal_plot(result: MotionResult):
    """The relative change of the index per class and group removed, against time (:mod:`.motion_figures`).

    Parameters
    ----------
    result : MotionResult
        With ``removal``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .motion_figures import removal_figure

    return removal_figure(result.dataset)
