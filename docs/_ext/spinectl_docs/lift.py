"""The worked example of ``docs/motion.md``: a lift analysed along its frames, measured at the build.

A flexion of the lumbar joints and its return over :data:`DURATION` seconds is written as an OpenSim ``.mot`` by
:func:`spinectl.anatomy.motion.write_motion` (OpenSim's own ``STOFileAdapter``) into a temporary folder, then
analysed by :func:`spinectl.anatomy.motion.motion_response` with a load, the contributions and the joint-by-joint
optimum per frame, on MyoTorso and, where a copy of the published Pose2Sim model is present (docs/anatomy.md,
"Published models"), on it. The figure is written into ``_generated/`` at ``builder-inited`` (:func:`write_figure`),
the numbers that the page's sentences quote are ``{measured}`motion.*``` values. Each motion is computed once per
build.
"""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np

from .values import NotAtBuild, value

DURATION = 2.0
"""The lift's duration [s]."""

FRAMES = 11
"""Frames analysed: every 0.2 s."""

FLEXION = 6.0
"""Each sagittal chain joint's largest flexion [deg] (30 degrees over MyoTorso's five lumbar joints)."""

STIFFNESS = 50.0
"""Joint stiffness added at each chain joint [N m/rad], as in docs/anatomy.md's optima."""

OPTIMISE = "joints"
"""The activations per frame: the least-effort optimum with the joint-by-joint criterion."""

MYOTORSO_LOAD = ({"body": "torso", "force": (0.0, 0.0, -100.0), "point": (0.0, 0.0, 0.0), "frame": "ground"},)
"""100 N down at MyoTorso's thorax (the ``torso`` body's origin), fixed in the ground."""

POSE2SIM_LOAD = tuple(
    {"body": hand, "force": (0.0, -50.0, 0.0), "point": (0.0, 0.0, 0.0), "frame": "ground"}
    for hand in ("hand_r", "hand_l")
)
"""100 N down in the Pose2Sim model's hands, 50 N at each (OpenSim's y is up)."""

ROUNDING = 1e-9
"""A class's sum below this times the largest is shown as 0 (the eigensolver's rounding)."""

SOLVER_ROUNDING = 1e-3
"""A removal's change of the index below this [%] is shown as 0: a set whose removal leaves the optimum as it was
(no lumbar torque) is re-solved to the solver's tolerance, not to the bit."""

FIGURE = "motion-lift.png"
"""The figure in ``_generated/``."""

GROUPS = {"back": "IL|LTp", "abs": "rect_abd|EO|IO"}
"""The named groups removed (``--group back='IL|LTp' --group abs='rect_abd|EO|IO'``): MyoTorso's erector spinae
(iliocostalis, longissimus) and abdominal muscles, beside each class."""

REMOVAL_FIGURE = "motion-lift-removal.png"
"""The removal's figure in ``_generated/``."""


def _lift(model, path: Path) -> Path:
    """The lift as a .mot of every coordinate: the model's defaults, the chain's joints flexed and returned."""
    from spinectl.anatomy.motion import write_motion

    names = list(model.posture_columns().required)
    times = np.linspace(0.0, DURATION, FRAMES)
    rows = np.tile(_defaults(model, names), (times.size, 1))
    # exactly 0 at both ends: sin(pi) is 1.2e-16, a posture 1e-16 rad off the default that OpenSim's
    # path-length differences of the Pose2Sim model turn into 0/0 (a NaN damping)
    flexion = np.round(np.sin(np.pi * times / DURATION), 12) * FLEXION
    for joint in model.plane_joints("sagittal"):  # a flexion on both (MyoTorso's flex_extension > 0 extends)
        rows[:, names.index(joint)] -= flexion
    return write_motion(path, names, times, rows)


def _defaults(model, names) -> np.ndarray:
    """Each coordinate's default [deg or m]: an .osim's own defaults, else 0."""
    coordinate = getattr(model.engine, "coordinate", None)
    if coordinate is None:
        return np.zeros(len(names))
    rotational = model.posture_columns().rotational
    values = [coordinate(n).getDefaultValue() for n in names]
    return np.array([np.degrees(v) if n in rotational else v for n, v in zip(names, values, strict=True)])


@cache
def myotorso_lift():
    """MyoTorso's lift with 100 N at the thorax: the MotionResult."""
    from spinectl import anatomy
    from spinectl.anatomy.motion import motion_response
    from spinectl.anatomy.recordings import read_recording

    model = anatomy.load("myotorso")
    with tempfile.TemporaryDirectory() as folder:
        path = _lift(model, Path(folder) / "lift.mot")
        recording = read_recording(path, "posture")
        return motion_response(
            model,
            recording,
            optimise=OPTIMISE,
            joint_stiffness=STIFFNESS,
            loads=MYOTORSO_LOAD,
            contributions=True,
            removal="groups",
            groups=GROUPS,
            progress=False,
        )


@cache
def pose2sim_lift():
    """The Pose2Sim model's lift with 100 N in the hands, the model's own controls (its activation floor)."""
    from spinectl import anatomy
    from spinectl.anatomy.motion import motion_response
    from spinectl.anatomy.recordings import read_recording

    from .published import shared_models

    source = shared_models() / "pose2sim-beaucage-gauvreau" / "Model_Pose2Sim_muscles_flex.osim"
    if not source.is_file():
        raise NotAtBuild(f"the Pose2Sim model is not at this build ({source} is absent)")
    mapping = Path(__file__).resolve().parents[2] / "mappings" / "pose2sim.toml"
    model = anatomy.load(source, mapping)
    with tempfile.TemporaryDirectory() as folder:
        path = _lift(model, Path(folder) / "lift.mot")
        return motion_response(
            model,
            read_recording(path, "posture"),
            frames=(0, FRAMES - 1, 2),
            loads=POSE2SIM_LOAD,
            contributions=True,
            progress=False,
        )


def write_figure(folder: Path) -> None:
    """MyoTorso's lift figures (:func:`spinectl.anatomy.motion.motion_plot`, ``removal_plot``) into ``folder``;
    without the extras, nothing (the page's values say what is missing)."""
    try:
        result = myotorso_lift()
    except ImportError:
        return
    from spinectl.anatomy.motion import motion_plot, removal_plot
    from spinectl.canvas import save_figures

    save_figures({FIGURE: motion_plot(result), REMOVAL_FIGURE: removal_plot(result)}, folder, 100.0)


def _least(result, name: str = "free") -> str:
    ds = result.dataset
    index = ds[f"{name}_index"].values
    at = int(np.nanargmin(index))
    return f"{index[at]:.3g} N m/rad at t = {ds['time'].values[at]:.1f} s"


def _unstable(result, name: str = "free") -> str:
    modes = result.dataset[f"{name}_unstable_modes"].values
    most = int(np.nanmax(modes))
    return f"{int(np.sum(modes > 0))} of {modes.size} frames (at most {most} unstable mode{'' if most == 1 else 's'})"


def _classes(result) -> str:
    """Each class's d lambda_min / d a at the frame of the least free index, largest first."""
    ds = result.dataset
    at = int(np.nanargmin(ds["free_index"].values))
    sums = ds["free_class_contribution"].values[at]
    sums = np.where(np.abs(sums) < ROUNDING * np.nanmax(np.abs(sums)), 0.0, sums)  # a class without lumbar rows
    order = np.argsort(-np.abs(np.nan_to_num(sums)))
    return ", ".join(f"{ds['muscle_class'].values[k]} {sums[k]:+.3g}" for k in order)


def _top_muscle(result) -> str:
    ds = result.dataset
    at = int(np.nanargmin(ds["free_index"].values))
    d = ds["free_contribution"].values[at]
    k = int(np.nanargmax(d))
    return f"{ds['muscle'].values[k]} ({d[k]:+.3g} N m/rad per unit activation)"


@value("motion.lift_free_least")
def _myotorso_free_least() -> str:
    return _least(myotorso_lift())


@value("motion.lift_free_unstable")
def _myotorso_free_unstable() -> str:
    return _unstable(myotorso_lift())


@value("motion.lift_constrained_least")
def _myotorso_constrained_least() -> str:
    return _least(myotorso_lift(), "constrained")


@value("motion.lift_classes")
def _myotorso_classes() -> str:
    return _classes(myotorso_lift())


@value("motion.lift_top_muscle")
def _myotorso_top_muscle() -> str:
    return _top_muscle(myotorso_lift())


def _removed(result, name: str = "free") -> str:
    """Each removed set's change of the index [%] at the frame of the least free index, largest first; the sets
    whose re-solved optimum is infeasible named apart."""
    ds = result.dataset
    at = int(np.nanargmin(ds["free_index"].values))
    change = ds[f"{name}_removed_change"].values[at]
    groups = [str(g) for g in ds["group"].values]
    order = [k for k in np.argsort(-np.abs(np.nan_to_num(change))) if np.isfinite(change[k])]
    change = np.where(np.abs(change) < SOLVER_ROUNDING, 0.0, change)
    text = ", ".join(f"{groups[k]} {change[k]:+.3g} %" for k in order)
    failed = [groups[k] for k in range(len(groups)) if ds["removal_status"].values[at, k] == "re-solved: infeasible"]
    return text + (f"; without {' or '.join(failed)} the re-solved optimum is infeasible" if failed else "")


def _removal_extremes(result) -> str:
    """The lowest change of either chain's index on a removal over the lift, and how many re-solves failed."""
    ds = result.dataset
    parts = []
    for name in ("free", "constrained"):
        change = ds[f"{name}_removed_change"].values
        t, k = np.unravel_index(int(np.nanargmin(change)), change.shape)
        parts.append(
            f"{change[t, k]:+.3g} % on the {name} chain ({ds['group'].values[k]} removed at t = "
            f"{ds['time'].values[t]:.1f} s)"
        )
    status = ds["removal_status"].values
    failed = int(np.sum(status == "re-solved: infeasible"))
    return f"{' and '.join(parts)}; the re-solved optimum is infeasible in {failed} of {status.size} removals"


@value("motion.lift_removal_free")
def _myotorso_removal_free() -> str:
    return _removed(myotorso_lift())


@value("motion.lift_removal_extremes")
def _myotorso_removal_extremes() -> str:
    return _removal_extremes(myotorso_lift())


@value("motion.pose2sim")
def _pose2sim() -> str:
    result = pose2sim_lift()
    return (
        f"the free chain's least index is {_least(result)}, unstable in "
        f"{_unstable(result)}; per class at that frame: {_classes(result)}"
    )
