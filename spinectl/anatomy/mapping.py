"""The mapping of an anatomical model onto the chain, and the muscles' classes (docs/anatomy.md).

A small TOML file says which joints form the chain in each plane, which bodies are the
pelvis, the vertebrae and the thorax, and the intervertebral stiffness that may be added;
``mappings/myotorso.toml`` is MyoTorso's. Muscles are classified by the bodies their
tendon's path points (MuJoCo sites) are fixed to:

- **global**: thorax and pelvis only (the paper's muscles, spanning the whole chain);
- **local**: any vertebra of the chain;
- **between**: any other body, e.g. MyoTorso's ``Abdomen``, a body of its own hanging on
  lumbar5 and moved by the lumbar rhythm.

Wrapping surfaces do not count: a tendon slides over them. A body that is not listed
belongs to the group of the listed ancestor it is rigidly fixed to (no joint between),
so the thorax's head and arm attachments count as thorax.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..errors import ConfigError, ParameterError
from .engine import Engine, require_mujoco

MAPPINGS = Path(__file__).resolve().parent / "mappings"
"""Folder of the built-in mappings, one ``<model>.toml`` each."""

PLANES = ("sagittal", "coronal", "3d")
GROUPS = ("pelvis", "vertebrae", "thorax")


@dataclass(frozen=True)
class Mapping:
    """Which joints and bodies of a MuJoCo model form the chain.

    Attributes
    ----------
    bodies : dict
        ``{"pelvis": (...), "vertebrae": (...), "thorax": (...)}``, body names.
    planes : dict
        Plane name -> the chain's joint names, in the order of q.
    joint_stiffness : float
        Stiffness that ``joint_stiffness="mapped"`` adds at every chain joint [N m/rad].
    stiffness_source : str
        The published source of :attr:`joint_stiffness`.
    path : str
        The file it was read from.
    """

    bodies: dict
    planes: dict
    joint_stiffness: float
    stiffness_source: str
    path: str


def read_mapping(path: str | Path) -> Mapping:
    """Read and check a mapping file (its keys; the names are checked against a model by :func:`check_mapping`).

    Parameters
    ----------
    path : str or pathlib.Path
        The TOML file.

    Returns
    -------
    Mapping
    """
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError("mapping", f"cannot read {path}: {exc}") from None
    bodies, planes, stiff = doc.get("bodies", {}), doc.get("planes", {}), doc.get("joint_stiffness", {})
    for group in GROUPS:
        if not (isinstance(bodies.get(group), list) and bodies[group]):
            raise ConfigError(f"mapping.bodies.{group}", "must be a non-empty list of body names")
    if not planes or not set(planes) <= set(PLANES):
        raise ConfigError("mapping.planes", f"must give joint lists for some of {PLANES} (got {sorted(planes)})")
    value = stiff.get("Nm_per_rad", 0.0)
    if not isinstance(value, int | float) or value < 0:
        raise ConfigError("mapping.joint_stiffness.Nm_per_rad", f"must be a number >= 0 (got {value!r})")
    return Mapping(
        bodies={g: tuple(bodies[g]) for g in GROUPS},
        planes={p: tuple(v) for p, v in planes.items()},
        joint_stiffness=float(value),
        stiffness_source=str(stiff.get("source", "")),
        path=str(path),
    )


def default_mapping(name: str, *aliases: str) -> Mapping:
    """The built-in mapping of a model, ``mappings/<name>.toml``: the first of its names that has one.

    Parameters
    ----------
    name : str
        The model's name (``"myotorso"``).
    *aliases : str
        Other names of the same model, tried in turn (an MJCF file's own model name, e.g.
        ``"wagner2012_chain"`` for spinectl's export, whatever the file is called).

    Returns
    -------
    Mapping
    """
    for candidate in (name, *aliases):
        path = MAPPINGS / f"{candidate}.toml"
        if candidate and "/" not in candidate and path.is_file():
            return read_mapping(path)
    known = sorted(p.stem for p in MAPPINGS.glob("*.toml"))
    raise ParameterError("mapping", f"a model other than {known} needs a mapping file (--mapping FILE)")


def check_mapping(engine: Engine, mapping: Mapping) -> None:
    """Check that every body and joint the mapping names exists, and that the model has muscles.

    Parameters
    ----------
    engine : Engine
        The compiled model.
    mapping : Mapping
        Its mapping.
    """
    mujoco = require_mujoco()
    model = engine.model
    for group, names in mapping.bodies.items():
        missing = [n for n in names if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) < 0]
        if missing:
            raise ParameterError(f"mapping.bodies.{group}", f"names bodies that {engine.name} lacks: {missing}")
    for plane, names in mapping.planes.items():
        missing = [n for n in names if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) < 0]
        if missing:
            raise ParameterError(f"mapping.planes.{plane}", f"names joints that {engine.name} lacks: {missing}")
    if not engine.muscle_ids().size:
        raise ParameterError(
            "model", f"{engine.name} has no muscles (no tendon actuator with muscle or no activation dynamics)"
        )


def body_groups(engine: Engine, mapping: Mapping) -> dict:
    """Each body's group: ``"pelvis"``, ``"vertebrae"``, ``"thorax"`` or ``"between"``.

    A listed body has its group; an unlisted one that is rigidly fixed to its parent (no
    joint) takes its parent's group; any other body is ``"between"``.

    Parameters
    ----------
    engine : Engine
        The compiled model.
    mapping : Mapping
        Its mapping.

    Returns
    -------
    dict
        Body id -> group.
    """
    model = engine.model
    listed = {name: group for group, names in mapping.bodies.items() for name in names}
    names = engine.names("body")
    groups = {}
    for b in range(model.nbody):  # parents come before children in MuJoCo's body order
        if names[b] in listed:
            groups[b] = listed[names[b]]
        elif b > 0 and model.body_jntnum[b] == 0 and groups.get(int(model.body_parentid[b])) in GROUPS:
            groups[b] = groups[int(model.body_parentid[b])]
        else:
            groups[b] = "between"
    return groups


def muscle_bodies(engine: Engine) -> list:
    """The bodies each muscle's tendon sites are fixed to (:meth:`~spinectl.anatomy.engine.Engine.muscle_ids`).

    Parameters
    ----------
    engine : Engine
        The compiled model.

    Returns
    -------
    list of set of int
    """
    mujoco = require_mujoco()
    model = engine.model
    out = []
    for i in engine.muscle_ids():
        bodies = set()
        t = model.actuator_trnid[i, 0]
        for w in range(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t]):
            if model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_SITE:
                bodies.add(int(model.site_bodyid[model.wrap_objid[w]]))
        out.append(bodies)
    return out


def classify(engine: Engine, mapping: Mapping) -> tuple:
    """Each muscle's class by the bodies it attaches to: ``"local"``, ``"global"`` or ``"between"``.

    Local if any attachment is on a vertebra; else global if all are on the pelvis or the
    thorax; else between (module docstring).

    Parameters
    ----------
    engine : Engine
        The compiled model.
    mapping : Mapping
        Its mapping.

    Returns
    -------
    tuple of str
        One class per muscle (:meth:`~spinectl.anatomy.engine.Engine.muscle_ids`).
    """
    groups = body_groups(engine, mapping)
    out = []
    for bodies in muscle_bodies(engine):
        attached = {groups[b] for b in bodies}
        if "vertebrae" in attached:
            out.append("local")
        elif attached and attached <= {"pelvis", "thorax"}:
            out.append("global")
        else:
            out.append("between")
    return tuple(out)
