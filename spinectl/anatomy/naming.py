"""How the anatomy outputs name a chain joint: the model's own name and its level, e.g. ``flex_extension (L5S1)``.

A model names its joints as its authors chose (MyoTorso: ``flex_extension`` for L5S1, then ``L4_L5_FE`` ...), so a
name alone does not say where a joint is. The mapping lists each plane's joints from L5S1 up (docs/anatomy.md,
"The mapping"), the ``3d`` plane the sagittal, coronal and axial chains one after the other; so the k-th joint of a
chain is the k-th intervertebral level from L5S1 up (L5S1, L4L5, ..., L1L2, T12L1, ...). Tables and figures
print :func:`joint_labels`; the JSON keeps the model's names (``joints``), which scripts match.
"""

from __future__ import annotations

VERTEBRAE = (
    "S1",
    "L5",
    "L4",
    "L3",
    "L2",
    "L1",
    *(f"T{i}" for i in range(12, 0, -1)),
    *(f"C{i}" for i in range(7, 1, -1)),
)
"""The vertebrae from the sacrum up: level k lies between VERTEBRAE[k + 1] and VERTEBRAE[k]."""

PLANES_3D = 3
"""The chains the ``3d`` plane lists one after the other: sagittal, coronal and axial."""


def level(k: int) -> str:
    """The k-th intervertebral level from L5S1 up (0: ``L5S1``), or ``level k+1`` beyond C2C3.

    Parameters
    ----------
    k : int
        The joint's position in its chain, from L5S1 up.

    Returns
    -------
    str
    """
    return f"{VERTEBRAE[k + 1]}{VERTEBRAE[k]}" if k + 1 < len(VERTEBRAE) else f"level {k + 1}"


def joint_label(name: str, k: int) -> str:
    """``name (level)``; the name alone where it is the level itself (spinectl's export names its joints so).

    Parameters
    ----------
    name : str
        The model's joint name.
    k : int
        Its position in its chain, from L5S1 up.

    Returns
    -------
    str
    """
    at = level(k)
    return name if name.replace("_", "").upper() == at else f"{name} ({at})"


def joint_labels(joints, plane: str) -> tuple:
    """Each chain joint's label, by its position in the mapping's list (see the module).

    Parameters
    ----------
    joints : sequence of str
        The chain's joints in ``plane``, in the mapping's order.
    plane : str
        ``sagittal``, ``coronal`` or ``3d`` (three chains of equal length, one after the other).

    Returns
    -------
    tuple of str
    """
    joints = list(joints)
    per_chain = len(joints) // PLANES_3D if plane == "3d" and len(joints) % PLANES_3D == 0 else len(joints)
    return tuple(joint_label(name, i % max(per_chain, 1)) for i, name in enumerate(joints))
