"""The mapping of an anatomical model onto the chain, and the muscles' classes (docs/anatomy.md).

A small TOML file says which joints form the chain in each plane, which bodies are the
pelvis, the vertebrae and the thorax, and the intervertebral stiffness that may be added;
``mappings/myotorso.toml`` is MyoTorso's. Muscles are classified by the bodies their
tendon's path points (MuJoCo sites) are fixed to and the chain joints between them, by the
rule of :mod:`spinectl.anatomy.classes` (the same for OpenSim): global, local, between or
non-lumbar. A body with no joint to its parent is one rigid piece with it, and the piece
counts as its mapped group (thorax first): MyoTorso's ``lumbar1`` has no joint to ``torso``,
so a muscle from the sacrum to ``lumbar1`` is global.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .. import _validate as v
from .._validate import SHOWN_CHARS, printable
from ..errors import ConfigError, ParameterError
from ..model import _toml
from .classes import Skeleton, classify_muscles, piece_groups
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
    stiffness_mapped : bool
        Whether the file gives ``[joint_stiffness] Nm_per_rad``: without it ``joint_stiffness="mapped"`` is
        refused (:meth:`~spinectl.anatomy.contract.MappedModel.added_stiffness`), not 0 added without a word.
    """

    bodies: dict
    planes: dict
    joint_stiffness: float
    stiffness_source: str
    path: str
    stiffness_mapped: bool = True


MAX_STIFFNESS = 1e6
"""Largest stiffness [N m/rad] added at a joint, by a mapping or ``--joint-stiffness``, and the bound of the
other stiffnesses of ``spinectl anatomy`` (``--margin``, ``--kp``): about 2000 times the stiffest lumbar
motion segment (6-11 N m/deg, 340-630 N m/rad, Miller et al. 1986, the built-in mapping's source), and a
hundred times below where the arithmetic stops holding. Measured on MyoTorso: the optimum with the
stability criterion (a conic programme, relative tolerance about 1e-8 against muscle torques of
1-100 N m) is exact with 1e8 N m/rad added at each joint (its cost that of the classic optimum, as it must
be), ``optimal_inaccurate`` from 1e9 and a wrong optimum (cost 1.9e-39) at 1e77; the chain's delay margin
scales as 1/kp up to kp = 1e8 (5e-5, 5e-7, 5e-9 s at 1e4, 1e6, 1e8) and is ``delay_independent`` at 1e12;
at 1e308 the eigenvalues of -K were NaN."""

KEYS = {"bodies": GROUPS, "planes": PLANES, "joint_stiffness": ("Nm_per_rad", "source")}
"""The sections of a mapping file and the keys of each."""


def located(path, key: str) -> str:
    """The field of a mapping's key in a message: the file as given, then the key as written in it.

    Parameters
    ----------
    path : str or pathlib.Path
        The mapping file.
    key : str
        A dotted key of the file, e.g. ``"joint_stiffness.Nm_per_rad"``.

    Returns
    -------
    str
        E.g. ``"m.toml: joint_stiffness.Nm_per_rad"``; a path beyond
        :data:`~spinectl._validate.SHOWN_CHARS` characters is shortened at its start.
    """
    text = printable(str(path))
    if len(text) > SHOWN_CHARS:  # the end names the file: shortened at the start
        text = "..." + text[3 - SHOWN_CHARS :]
    return f"{text}: {key}"


def read_mapping(path: str | Path) -> Mapping:
    """Read and check a mapping file (its keys; the names are checked against a model by :func:`check_mapping`).

    The file is read and parsed as every TOML file of the project (:mod:`spinectl.model._toml`): a
    regular UTF-8 file, unknown sections and keys refused with a "did you mean", each value of its
    type, every name once.

    Parameters
    ----------
    path : str or pathlib.Path
        The TOML file.

    Returns
    -------
    Mapping

    Raises
    ------
    ConfigError
        The file cannot be read (field ``mapping``), is not TOML, or has an unknown key.
    ParameterError
        A value of the wrong type or range, a name given twice; the field names the file and the key.
    """
    path = Path(path)
    try:
        doc = _toml.parse(_toml.read_text(path), str(path))
    except ConfigError as exc:
        raise ConfigError("mapping", exc.message) from None
    try:
        return _mapping(doc, str(path))
    except ParameterError as exc:
        raise type(exc)(located(path, exc.field), exc.message) from None


def _mapping(doc: dict, path: str) -> Mapping:
    """The Mapping of a parsed file; errors name the key only (:func:`read_mapping` adds the file)."""
    _toml.check_keys(doc, KEYS)
    for section, value in doc.items():  # every section a table before any of their keys is read
        _toml.check_table(value, section)
    for section, value in doc.items():
        _toml.check_keys(value, KEYS[section], section)
    bodies, planes, stiff = doc.get("bodies", {}), doc.get("planes", {}), doc.get("joint_stiffness", {})
    for group in GROUPS:
        if group not in bodies:
            raise ParameterError(f"bodies.{group}", "is required: a non-empty list of body names")
    if not planes:
        raise ParameterError("planes", f"must give the chain's joints in some of {', '.join(PLANES)}")
    mapped = {g: _names(f"bodies.{g}", bodies[g]) for g in GROUPS}
    _disjoint("bodies", mapped, "a body belongs to one group")
    chains = {p: _names(f"planes.{p}", v) for p, v in planes.items()}
    # a joint turns in one plane: 3d lists the planes' joints together, but sagittal and coronal share none
    _disjoint("planes", {p: chains[p] for p in ("sagittal", "coronal") if p in chains}, "a joint turns in one plane")
    value = stiff.get("Nm_per_rad", 0.0)
    value = v.non_negative("joint_stiffness.Nm_per_rad", value)
    if value > MAX_STIFFNESS:
        raise ParameterError(
            "joint_stiffness.Nm_per_rad",
            f"must be at most {MAX_STIFFNESS:g} N m/rad, beyond which the chain's arithmetic fails (got {value:g})",
        )
    source = stiff.get("source", "")
    if not isinstance(source, str):
        raise ParameterError("joint_stiffness.source", f"must be a string (got {v.show(source)})")
    given = "Nm_per_rad" in stiff
    return Mapping(mapped, chains, value, source, path, stiffness_mapped=given)


def _names(key: str, value) -> tuple:
    """A non-empty list of distinct printable names (:func:`spinectl._validate.labels`)."""
    if isinstance(value, list) and not value:
        raise ParameterError(key, "must be a non-empty list of names (got [])")
    return v.labels(key, value)


def _disjoint(section: str, lists: dict, why: str) -> None:
    """Refuse a name in two of the lists of ``section``."""
    seen: dict = {}
    for key, names in lists.items():
        for name in names:
            if name in seen:
                raise ParameterError(
                    f"{section}.{key}", f"lists {v.show(name)}, which {section}.{seen[name]} lists too: {why}"
                )
            seen[name] = key


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
    """Check that every body and joint the mapping names exists (a model without muscles is its passive chain).

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
            lacks = f"names bodies that {engine.name} lacks: {missing}"
            raise ParameterError(located(mapping.path, f"bodies.{group}"), lacks)
    for plane, names in mapping.planes.items():
        missing = [n for n in names if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) < 0]
        if missing:
            lacks = f"names joints that {engine.name} lacks: {missing}"
            raise ParameterError(located(mapping.path, f"planes.{plane}"), lacks)


def skeleton(engine: Engine, mapping: Mapping) -> Skeleton:
    """MuJoCo's body tree as the classes' :class:`~spinectl.anatomy.classes.Skeleton`.

    A body with no joint is rigid on its parent; a body that one of the mapping's joints (any
    plane) moves is a chain body.

    Parameters
    ----------
    engine : Engine
        The compiled model.
    mapping : Mapping
        Its mapping.

    Returns
    -------
    Skeleton
    """
    model = engine.model
    mapped = {n for names in mapping.planes.values() for n in names}
    moved = {int(model.jnt_bodyid[j]) for j, name in enumerate(engine.names("joint")) if name in mapped}
    return Skeleton(
        names=tuple(engine.names("body")),
        parent=tuple(int(p) if b else -1 for b, p in enumerate(model.body_parentid)),
        rigid=tuple(bool(b and model.body_jntnum[b] == 0) for b in range(model.nbody)),
        chain=tuple(b in moved for b in range(model.nbody)),
    )


def body_groups(engine: Engine, mapping: Mapping) -> dict:
    """Each body's group: ``"pelvis"``, ``"vertebrae"``, ``"thorax"`` or ``"between"``.

    A body has the group of its rigid piece (:func:`spinectl.anatomy.classes.piece_groups`:
    the bodies joined to it with no joint between, thorax before pelvis before vertebrae);
    a body of no mapped piece is ``"between"``.

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
    groups = piece_groups(skeleton(engine, mapping), mapping.bodies)
    return {b: group or "between" for b, group in enumerate(groups)}


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
    """Each muscle's class by its attachments: ``"global"``, ``"local"``, ``"between"`` or ``"non-lumbar"``.

    :func:`spinectl.anatomy.classes.classify_muscles` on MuJoCo's body tree (:func:`skeleton`)
    and the bodies of each muscle's sites (:func:`muscle_bodies`).

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
    return classify_muscles(skeleton(engine, mapping), mapping.bodies, muscle_bodies(engine))
