"""The muscles' classes, by one rule for every engine: where a muscle attaches and which chain joints it crosses.

Each engine describes its model as a :class:`Skeleton` (a tree of bodies: each body's parent, whether
it is rigidly fixed to it, and whether one of the mapping's chain joints moves it) and each muscle by
the bodies its path points are fixed to; :func:`classify_muscles` then gives the class (docs/anatomy.md,
"Muscle classes"):

- a body rigidly fixed to another (MuJoCo: no joint between them, or a weld taken into the tree;
  OpenSim: a ``WeldJoint`` or a joint whose every coordinate is locked) is one rigid piece with it,
  and the piece counts as its mapped group: thorax before pelvis before vertebrae, so that a
  vertebra with no joint to the thorax (MyoTorso's ``lumbar1`` under ``torso``) is thorax;
- **non-lumbar**: the muscle crosses no chain joint (none of the mapping's joints lies between two
  of its attachments): a leg or arm muscle, or one within a rigid piece; it has no moment arm on the
  chain, so it adds nothing to K or to the lumbar equilibrium;
- **local**: an attachment on a vertebra's piece;
- **global**: every attachment on the pelvis's or the thorax's piece (the paper's muscles);
- **between**: any other muscle that crosses a chain joint (e.g. one routed over MyoTorso's ``Abdomen``).

Wrapping surfaces do not count: a tendon slides over them.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model.linear_chain import CONTROL_CLASSES

CLASSES = CONTROL_CLASSES
"""The classes (:data:`spinectl.model.linear_chain.CONTROL_CLASSES`, where the chain checks its controls')."""

ORDER = ("thorax", "pelvis", "vertebrae")
"""The group of a rigid piece holding bodies of several groups: the first of these it holds."""


@dataclass(frozen=True)
class Skeleton:
    """A model's bodies as a tree, what :func:`classify_muscles` needs of an engine.

    Attributes
    ----------
    names : tuple of str
        Body names, a parent before its children; the first is the root (MuJoCo's world, OpenSim's ground).
    parent : tuple of int
        Each body's parent index (-1 for the root).
    rigid : tuple of bool
        Each body fixed to its parent (no free joint or coordinate between them).
    chain : tuple of bool
        Each body moved relative to its parent by one of the mapping's chain joints.
    """

    names: tuple
    parent: tuple
    rigid: tuple
    chain: tuple

    def pieces(self) -> list:
        """Each body's rigid piece: the index of the piece's top body (its ancestor through rigid links).

        Returns
        -------
        list of int
        """
        top = []
        for b, p in enumerate(self.parent):
            top.append(top[p] if p >= 0 and self.rigid[b] else b)
        return top

    def crossed(self, bodies) -> set:
        """The chain-moved bodies whose joint lies between some of ``bodies`` (the chain joints a path crosses).

        A joint of body c lies between two bodies if one is c or below it and the other is not.

        Parameters
        ----------
        bodies : iterable of int
            Body indices.

        Returns
        -------
        set of int
            The chain-moved bodies c whose subtree holds some but not all of ``bodies``.
        """
        inside: dict = {}
        for b in set(bodies):
            node = b
            while node >= 0:  # every chain-moved ancestor (or b itself) holds b in its subtree
                if self.chain[node]:
                    inside[node] = inside.get(node, 0) + 1
                node = self.parent[node]
        total = len(set(bodies))
        return {c for c, count in inside.items() if count < total}


def piece_groups(skeleton: Skeleton, mapping_bodies: dict) -> list:
    """Each body's group: that of its rigid piece (:data:`ORDER`), or None off the mapped bodies.

    Parameters
    ----------
    skeleton : Skeleton
    mapping_bodies : dict
        Group -> body names (:attr:`spinectl.anatomy.mapping.Mapping.bodies`).

    Returns
    -------
    list of str or None
    """
    listed = {name: group for group, names in mapping_bodies.items() for name in names}
    top = skeleton.pieces()
    held: dict = {}
    for b, name in enumerate(skeleton.names):
        if name in listed:
            held.setdefault(top[b], set()).add(listed[name])
    group_of = {piece: next(g for g in ORDER if g in groups) for piece, groups in held.items()}
    return [group_of.get(top[b]) for b in range(len(skeleton.names))]


def classify_muscles(skeleton: Skeleton, mapping_bodies: dict, attachments) -> tuple:
    """Each muscle's class (module docstring): non-lumbar, local, global or between.

    Parameters
    ----------
    skeleton : Skeleton
    mapping_bodies : dict
        Group -> body names.
    attachments : iterable of set of int
        The bodies each muscle's path points are fixed to.

    Returns
    -------
    tuple of str
        One of :data:`CLASSES` per muscle.
    """
    groups = piece_groups(skeleton, mapping_bodies)
    out = []
    for bodies in attachments:
        attached = {groups[b] for b in bodies}
        if not skeleton.crossed(bodies):
            out.append("non-lumbar")
        elif "vertebrae" in attached:
            out.append("local")
        elif attached <= {"pelvis", "thorax"}:
            out.append("global")
        else:
            out.append("between")
    return tuple(out)
