"""The removal method along a motion: the index at every frame with each class and group removed (docs/motion.md).

Cholewicki & VanVliet (2002) judge what a muscle group gives the spine's stability by the index with that group
removed. Each frame's removal here is the one-posture removal of ``spinectl anatomy --contributions`` at that
frame, by the same code: :func:`spinectl.model.contributions.contributions` on the frame's free and constrained
chain with the same :data:`~spinectl.model.contributions.Resolver`. With activations given (a file, or the model's
own controls) the removed muscles are set to 0 and the others keep their activations: the equilibrium is not
re-solved. With the optimum per frame (``optimise``), the optimum is re-solved without them
(:func:`spinectl.anatomy.contributions.optimum_resolver`), once per removed set and frame, shared by both chains:
the cost is one re-solve per class and group per frame, so every single muscle is removed only on request and
never with the optimum (one re-solve per muscle per frame).

References
----------
Cholewicki J, VanVliet JJ (2002). Relative contribution of trunk muscles to the stability of the lumbar spine
during isometric exertions. Clin Biomech 17(2):99-105. doi:10.1016/S0268-0033(01)00118-8.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from .._validate import show
from ..errors import ParameterError

REMOVAL_REFERENCE = "Cholewicki J, VanVliet JJ (2002) Clin Biomech 17:99-105, doi:10.1016/S0268-0033(01)00118-8"
"""The removal method's source, in the Dataset's ``references``."""

REMOVAL = ("groups", "muscles")
"""``removal``: each class and named group removed in turn, or also each muscle (not with the optimum per frame)."""

KEPT = "the removed muscles at 0, the others' activations kept (the equilibrium not re-solved)"
RESOLVED = "the removed muscles at 0, the optimum re-solved without them at each frame"
"""The two methods, as the variables' ``method`` attribute says."""


@dataclass(frozen=True)
class RemovalSpec:
    """What is removed at every frame.

    Attributes
    ----------
    classes : dict of str to tuple of str
        The model's muscle classes and their members, each removed as ``class:<name>``.
    groups : dict of str to tuple of str
        The named groups and their members, each removed as ``group:<name>``.
    muscles : tuple of str
        The muscles removed one by one (empty unless asked for).
    """

    classes: dict
    groups: dict = field(default_factory=dict)
    muscles: tuple = ()

    @property
    def keys(self) -> tuple:
        """Each removed set's name, as the one-posture removal names it (``class:...``, ``group:...``, a muscle)."""
        return tuple(f"class:{c}" for c in self.classes) + tuple(f"group:{g}" for g in self.groups) + self.muscles


def check_removal(removal, groups, optimise: str, fields=("removal", "groups")) -> None:
    """Refuse a removal the motion cannot do, before any model is loaded.

    Parameters
    ----------
    removal : {None, "groups", "muscles"}
        What is removed (:data:`REMOVAL`); None: nothing.
    groups : dict or None
        Named groups: they go with ``removal``.
    optimise : str
        The motion's ``optimise``: with the optimum per frame, ``"muscles"`` is refused (its cost).
    fields : tuple of str
        The names of ``removal`` and ``groups`` in messages (the command line's ``--removal``, ``--group``).

    Returns
    -------
    None

    Raises
    ------
    ParameterError
        An unknown removal, groups without a removal, every muscle removed with the optimum re-solved.
    """
    if removal is not None and removal not in REMOVAL:
        raise ParameterError(fields[0], f"must be one of {REMOVAL} (got {show(removal)})")
    if groups and removal is None:
        raise ParameterError(fields[1], f"goes with {fields[0]} (got {fields[1]} alone)")
    if removal == "muscles" and optimise != "none":
        raise ParameterError(
            fields[0],
            "'muscles' cannot go with the optimum per frame: it would re-solve the optimum once per muscle at "
            "every frame; remove the classes and groups ('groups'), or give the activations",
        )


def removal_spec(anatomy, removal, groups, optimise: str, classes: tuple) -> RemovalSpec | None:
    """The sets removed at every frame, the groups matched against the model's muscles.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    removal : {None, "groups", "muscles"}
        :data:`REMOVAL`; None: no removal.
    groups : dict or None
        Group name -> a regular expression or the members' names
        (:func:`spinectl.model.contributions.resolve_groups`).
    optimise : str
        The motion's ``optimise``.
    classes : tuple of str
        The model's muscle classes, in the order of the class variables.

    Returns
    -------
    RemovalSpec or None

    Raises
    ------
    ParameterError
        As :func:`check_removal`; a group that matches no muscle or is no regular expression.
    """
    from ..model.contributions import resolve_groups

    check_removal(removal, groups, optimise)
    if removal is None:
        return None
    named = resolve_groups(anatomy.muscles, dict(groups or {}))
    members = {c: tuple(m for m, k in zip(anatomy.muscles, anatomy.classes, strict=True) if k == c) for c in classes}
    return RemovalSpec(members, named, tuple(anatomy.muscles) if removal == "muscles" else ())


def frame_removal(anatomy, chains, a, posture, plane, joint_stiffness, optimise, loads, spec: RemovalSpec) -> dict:
    """One frame's removals on both chains: what ``spinectl anatomy --contributions`` gives at that posture.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    chains : tuple
        The frame's (free, constrained) LinearChain at its activations.
    a : numpy.ndarray, shape (m,)
        The frame's activations.
    posture : optional
        The frame's posture (the engine's form).
    plane, joint_stiffness, loads
        As the frame's chains.
    optimise : str
        ``"none"``: the others kept; else the frame's optimum criterion, re-solved without each set.
    spec : RemovalSpec
        What is removed.

    Returns
    -------
    dict
        ``free_removed_index``, ``constrained_removed_index`` [N m/rad], ``free_removed_change``,
        ``constrained_removed_change`` [%], each shape (sets,) in ``spec.keys`` order, and ``removal_status``.
    """
    from ..model.contributions import contributions
    from .contributions import optimum_resolver
    from .optimum import MARGIN

    resolve = None
    if optimise != "none":  # the optimum the frame solved: its criterion, margin and equilibrium (the defaults)
        loaded = {"loads": loads} if loads else {}
        resolve = optimum_resolver(anatomy, plane, posture, joint_stiffness, optimise, MARGIN, "rhythm", **loaded)
    out = {}
    for name, chain in zip(("free", "constrained"), chains, strict=True):
        removals = contributions(chain, a, groups=spec.groups, remove=spec.muscles, resolve=resolve).removals
        chosen = [removals[key] for key in spec.keys]
        out[f"{name}_removed_index"] = np.array([r.least_eigenvalue for r in chosen])
        out[f"{name}_removed_change"] = np.array([r.percent_change for r in chosen])
        if name == "free":  # one resolve(held) serves both chains: the constrained chain's statuses are these
            out["removal_status"] = np.array([r.status for r in chosen], dtype=object)
    return out


VARIABLES = {
    "{name}_removed_index": (
        "N m/rad",
        "least eigenvalue of -K with the group's muscles removed (attribute method); NaN: the re-solved optimum "
        "infeasible (removal_status) or no operating point, {criterion}",
    ),
    "{name}_removed_change": (
        "%",
        "100 (removed index - index) / abs(index): the relative change of the index when the group is removed, "
        "{criterion}",
    ),
}
"""The removal's variables (dims time, group), for each chain: units and description."""


def removal_data(rows, spec: RemovalSpec, optimise: str, criteria: dict) -> tuple:
    """The removal's variables over the frames and its ``group`` coordinate.

    Parameters
    ----------
    rows : list of dict
        The frames (a frame without an operating point has no removal: NaN, status '').
    spec : RemovalSpec
        What was removed.
    optimise : str
        The motion's ``optimise`` (the method's name).
    criteria : dict of str to str
        ``"free"`` and ``"constrained"`` -> the criterion each chain's description names.

    Returns
    -------
    tuple
        (data variables as ``{name: (dims, values, attrs)}``, coordinates as ``{"group": ...}``).
    """
    width = len(spec.keys)
    method = KEPT if optimise == "none" else f"{RESOLVED} (stability criterion: {optimise})"
    data = {}
    for name, criterion in criteria.items():
        for template, (units, description) in VARIABLES.items():
            key = template.format(name=name)
            values = np.full((len(rows), width), np.nan)
            for i, row in enumerate(rows):
                if key in row:
                    values[i] = row[key]
            attrs = {"units": units, "description": description.format(criterion=criterion), "method": method}
            data[key] = (("time", "group"), values, attrs)
    status = np.full((len(rows), width), "", dtype=object)
    for i, row in enumerate(rows):
        if "removal_status" in row:
            status[i] = row["removal_status"]
    data["removal_status"] = (
        ("time", "group"),
        status,
        {"description": "'removed' (the others kept), 're-solved: <the optimum's status>', '' no operating point"},
    )
    members = {f"class:{c}": list(m) for c, m in spec.classes.items()}
    members |= {f"group:{g}": list(m) for g, m in spec.groups.items()}
    group = (
        "group",
        list(spec.keys),
        {
            "description": "what is removed: a muscle class (class:NAME), a named group (group:NAME, its muscles in "
            "the attribute members) or one muscle (its name)",
            "members": json.dumps(members),
        },
    )
    return data, {"group": group}


def removal_summary(ds) -> list:
    """A line per chain: the least relative change of the index on a removal (the set removed, the frame).

    Parameters
    ----------
    ds : xarray.Dataset
        A motion's Dataset with the removal's variables.

    Returns
    -------
    list of str
        Empty without them.
    """
    if "removal_status" not in ds:
        return []
    lines = [f"removal: {ds['free_removed_change'].attrs['method']}"]
    infeasible = int(np.sum(np.char.startswith(ds["removal_status"].values.astype(str), "re-solved: infeasible")))
    for name in ("free", "constrained"):
        change = ds[f"{name}_removed_change"].values
        if np.all(np.isnan(change)):
            lines.append(f"  {ds.attrs[f'{name}_criterion']}: no removal solved")
            continue
        t, k = np.unravel_index(int(np.nanargmin(change)), change.shape)
        lines.append(
            f"  {ds.attrs[f'{name}_criterion']}: least change of the index {change[t, k]:+.3g} % "
            f"({ds['group'].values[k]} removed, t = {ds['time'].values[t]:g} s)"
        )
    if infeasible:
        lines.append(
            f"  the re-solved optimum infeasible in {infeasible} of {ds['removal_status'].size} removals (NaN)"
        )
    return lines
