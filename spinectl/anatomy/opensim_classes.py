"""An ``.osim`` model's mapping checked and its muscles classed: OpenSim's joint tree as the classes' skeleton.

The rule is :mod:`spinectl.anatomy.classes`' (one for every engine); this module reads what it needs
from OpenSim's joints and path points (docs/anatomy.md, "The muscles' classes").
"""

from __future__ import annotations

from ..errors import ParameterError
from .classes import Skeleton, classify_muscles
from .mapping import Mapping, located


def _base_body(frame) -> str:
    """The body (or ground) a frame is fixed to."""
    return frame.findBaseFrame().getName()


def check_mapping(engine, mapping: Mapping) -> None:
    """Every mapped body and coordinate exists: else one line (a model without muscles is its passive chain).

    Parameters
    ----------
    engine : spinectl.anatomy.opensim_engine.OsimEngine
        The model built by OpenSim.
    mapping : Mapping
        Its chain joints and body groups.

    Raises
    ------
    spinectl.errors.ParameterError
        A body or coordinate the model lacks, named with the mapping's key.
    """
    bodies = {engine.model.getGround().getName()} | {
        engine.model.getBodySet().get(i).getName() for i in range(engine.model.getBodySet().getSize())
    }
    for group, names in mapping.bodies.items():
        missing = [n for n in names if n not in bodies]
        if missing:
            lacks = f"names bodies that {engine.name} lacks: {missing}"
            raise ParameterError(located(mapping.path, f"bodies.{group}"), lacks)
    coords = engine.model.getCoordinateSet()
    for plane, names in mapping.planes.items():
        missing = [n for n in names if not coords.contains(n)]
        if missing:
            lacks = f"names coordinates that {engine.name} lacks: {missing}"
            raise ParameterError(located(mapping.path, f"planes.{plane}"), lacks)


def classify(engine, mapping: Mapping) -> tuple:
    """Each muscle's class by the bodies its path points are fixed to (:mod:`spinectl.anatomy.classes`' rule).

    Parameters
    ----------
    engine : spinectl.anatomy.opensim_engine.OsimEngine
        The model built by OpenSim.
    mapping : Mapping
        Its chain joints and body groups.

    Returns
    -------
    tuple of str
        Each muscle's class, in the model's muscle order.
    """
    tree = _skeleton(engine, mapping)
    index = {name: b for b, name in enumerate(tree.names)}
    muscles = engine.model.getMuscles()
    attachments = []
    for i in range(muscles.getSize()):
        points = muscles.get(i).getGeometryPath().getPathPointSet()
        attachments.append({index[_base_body(points.get(k).getParentFrame())] for k in range(points.getSize())})
    return classify_muscles(tree, mapping.bodies, attachments)


def _skeleton(engine, mapping: Mapping) -> Skeleton:
    """OpenSim's joint tree as a :class:`~spinectl.anatomy.classes.Skeleton`, ground first, parents first.

    A body is rigid on its parent where its joint has no coordinate (a ``WeldJoint``) or every
    one is locked (``Coordinate.getDefaultLocked``); a chain body where a mapped coordinate moves it.
    """
    model = engine.model
    mapped = {n for names in mapping.planes.values() for n in names}
    joints = model.getJointSet()
    below: dict = {}
    for i in range(joints.getSize()):
        joint = joints.get(i)
        coords = [joint.get_coordinates(k) for k in range(joint.numCoordinates())]
        rigid = all(c.getDefaultLocked() for c in coords)  # True without coordinates: a weld
        chain = any(c.getName() in mapped for c in coords)
        child = _base_body(joint.getChildFrame())
        below.setdefault(_base_body(joint.getParentFrame()), []).append((child, rigid, chain))
    names, parent, rigid, chain = [model.getGround().getName()], [-1], [False], [False]
    for b, name in enumerate(names):  # breadth first: the list grows as it is read
        for child, fixed, moved in below.get(name, ()):
            names.append(child)
            parent.append(b)
            rigid.append(fixed)
            chain.append(moved)
    return Skeleton(tuple(names), tuple(parent), tuple(rigid), tuple(chain))
