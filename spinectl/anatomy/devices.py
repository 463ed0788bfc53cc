"""MJCF as published: weld equalities (devices, exosuit straps) and a free root taken into the chain (docs/anatomy.md).

The chain's analyses hold every joint off the chain and linearise MuJoCo's own kinematics, so a
model's devices enter through its tree. :func:`as_published` edits the spec (MuJoCo's
:class:`mujoco.MjSpec`, never the XML) before it is compiled:

- a **weld** equality between two bodies makes them one rigid piece: the device is the body whose
  own joints alone join it to their common ancestor (an exosuit strap with its free joint, not the
  torso, which the lumbar chain's joints carry), else the one with fewer degrees of freedom to it.
  It loses its own joints and hangs on the other body at their relative pose in the reference
  posture (``qpos0``), its subtree, sites and the tendons routed over it with it (its bodies and
  sites named ``device/...``); the weld is then met by construction and removed. A weld to the world
  (a body fixed in space) is the same with the world as the other body.
- a **free root** joint (a full-body model's pelvis floating in the world) is removed, its body
  fixed at its reference pose, the analysis's operating point anyway; said in one line.

Each edit is one phrase of :attr:`spinectl.anatomy.engine.Engine.devices`, with every passive
tendon that no actuator pulls (a strap: a spring, no muscle), whose spring MuJoCo's passive forces
carry into K_0 (:mod:`spinectl.anatomy.linearise`).
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError

PREFIX = "device/"
"""The names of a moved device's bodies, sites and geoms (copies: MuJoCo's attach); its tendons and actuators keep
their own."""


def as_published(spec) -> tuple:
    """The spec with its welds taken into the tree and a free root fixed (module docstring), and what was done.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model's spec, edited in place.

    Returns
    -------
    tuple
        (the spec, tuple of str: one phrase per weld and free root).
    """
    mujoco = _mujoco()
    # each weld with its index in the compiled model (MuJoCo compiles the equalities in the spec's order)
    welds = [(k, e) for k, e in enumerate(spec.equalities) if e.type == mujoco.mjtEq.mjEQ_WELD and e.active]
    roots = [j for j in spec.joints if j.type == mujoco.mjtJoint.mjJNT_FREE]
    if not welds and not roots:
        return spec, ()
    before = spec.compile()  # the reference posture's poses, the keyframes' values by name
    notes = [_attach(spec, before, k, weld) for k, weld in welds]
    for joint in [j for j in spec.joints if j.type == mujoco.mjtJoint.mjJNT_FREE]:
        body = joint.parent
        if body.parent.name == spec.worldbody.name:
            spec.delete(joint)
            notes.append(f"free root joint of {body.name!r} fixed at its reference pose (qpos0)")
    _keep_keyframes(spec, before)
    return spec, tuple(notes)


def _mujoco():
    """:mod:`mujoco`: the engine (:func:`spinectl.anatomy.engine.require_mujoco`) has imported it before it calls."""
    import mujoco

    return mujoco


def _bodies_of(model, weld: int) -> tuple:
    """The two bodies a compiled weld ties (its objects bodies, or the bodies of its sites)."""
    mujoco = _mujoco()
    ids = (int(model.eq_obj1id[weld]), int(model.eq_obj2id[weld]))
    if model.eq_objtype[weld] == mujoco.mjtObj.mjOBJ_SITE:
        return tuple(int(model.site_bodyid[i]) for i in ids)
    return ids


def _path_dofs(model, body: int, ancestor: int) -> int:
    """Degrees of freedom between a body and an ancestor of it."""
    count = 0
    while body != ancestor:
        count += int(model.body_dofnum[body])
        body = int(model.body_parentid[body])
    return count


def _device_rank(model, body: int, common: int) -> tuple:
    """How little a body looks like the weld's device (lower first): a body whose own joints alone join it to the
    common ancestor (a strap's free joint), then the fewer degrees of freedom between; never the world."""
    dofs = _path_dofs(model, body, common)
    own = body != common and int(model.body_dofnum[body]) == dofs > 0
    return (body == 0, not own, dofs)


def _ancestors(model, body: int) -> list:
    out = [body]
    while body:
        body = int(model.body_parentid[body])
        out.append(body)
    return out


def _attach(spec, model, e: int, weld) -> str:
    """Hang weld ``e``'s device body on the other body at their reference pose; the phrase that says so."""
    mujoco = _mujoco()
    label = weld.name or str(e)
    b1, b2 = _bodies_of(model, e)
    up1, up2 = _ancestors(model, b1), _ancestors(model, b2)
    common = next(b for b in up1 if b in up2)
    device, other = (b1, b2) if _device_rank(model, b1, common) <= _device_rank(model, b2, common) else (b2, b1)
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or "the world" for b in (device, other)]
    if _path_dofs(model, device, common) > int(model.body_dofnum[device]):
        raise ParameterError(
            "model",
            f"{spec.modelname or 'the model'}: weld {label} ties {names[0]!r} to {names[1]!r} across joints "
            "of other bodies: a weld that locks the model's joints is not supported (a device's weld ties a body "
            "that only its own joints move)",
        )
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    pos, quat = _relative_pose(data, other, device)
    if model.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE:  # MuJoCo welds the two sites' frames onto each other
        sites = dict(zip((b1, b2), (int(model.eq_obj1id[e]), int(model.eq_obj2id[e])), strict=True))
        pos, quat = _site_on_site(model, sites[other], sites[device])
    spec.delete(weld)
    moved = spec.body(names[0])
    for joint in list(moved.joints):
        spec.delete(joint)
    moved.pos, moved.quat = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]  # its pose is the frame's
    moved.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT
    # the subtree, with the tendons and actuators routed over it, copied from a copy of the spec once the
    # original is gone (MuJoCo's attach copies what refers to the subtree, under a prefix)
    source = spec.copy()
    spec.delete(moved)
    target = spec.worldbody if other == 0 else spec.body(names[1])
    keys = len(spec.keys)
    target.add_frame(pos=pos, quat=quat).attach_body(source.body(names[0]), PREFIX, "")
    for key in list(spec.keys)[keys:]:  # the copy's keyframes come along: the model's own stay
        spec.delete(key)
    _restore_names(spec)
    return f"weld {label}: {names[0]!r} rigid on {names[1]!r} at the reference pose (a device)"


def _relative_pose(data, parent: int, child: int) -> tuple:
    """The child body's position and orientation in the parent body's frame [m, unit quaternion]."""
    mujoco = _mujoco()
    rot = data.xmat[parent].reshape(3, 3)
    pos = rot.T @ (data.xpos[child] - data.xpos[parent])
    inverse, quat = np.zeros(4), np.zeros(4)
    mujoco.mju_negQuat(inverse, data.xquat[parent])
    mujoco.mju_mulQuat(quat, inverse, data.xquat[child])
    return pos, quat


def _site_on_site(model, fixed: int, moved: int) -> tuple:
    """The pose in the fixed site's body that puts the moved site's body with the two sites' frames one [m, 1]."""
    mujoco = _mujoco()
    inverse_pos, inverse_quat = np.zeros(3), np.zeros(4)
    mujoco.mju_negPose(inverse_pos, inverse_quat, model.site_pos[moved], model.site_quat[moved])
    pos, quat = np.zeros(3), np.zeros(4)
    mujoco.mju_mulPose(pos, quat, model.site_pos[fixed], model.site_quat[fixed], inverse_pos, inverse_quat)
    return pos, quat


def _restore_names(spec) -> None:
    """The moved tendons' and actuators' own names back (the outputs name them), the actuators' targets with them.

    The bodies, sites and geoms keep :data:`PREFIX`: MuJoCo's tendon paths refer to them by the copied names.
    """
    renamed = {}
    for tendon in spec.tendons:
        if tendon.name.startswith(PREFIX) and not _named(spec.tendons, tendon.name[len(PREFIX) :]):
            renamed[tendon.name] = tendon.name = tendon.name[len(PREFIX) :]
    for actuator in spec.actuators:
        if actuator.target in renamed:
            actuator.target = renamed[actuator.target]
        if actuator.name.startswith(PREFIX) and not _named(spec.actuators, actuator.name[len(PREFIX) :]):
            actuator.name = actuator.name[len(PREFIX) :]


def _named(items, name: str) -> bool:
    return any(item.name == name for item in items)


def _keep_keyframes(spec, before) -> None:
    """Each keyframe's positions, controls and activations carried over by joint and actuator name."""
    mujoco = _mujoco()
    if not before.nkey:
        return
    saved = [(k.qpos, k.qvel, k.act, k.ctrl) for k in spec.keys]
    for key in spec.keys:
        key.qpos, key.qvel, key.act, key.ctrl = [], [], [], []
    after = spec.compile()
    for key, k in zip(spec.keys, range(before.nkey), strict=False):
        qpos, qvel = after.qpos0.copy(), np.zeros(after.nv)
        for j in range(after.njnt):
            name = mujoco.mj_id2name(after, mujoco.mjtObj.mjOBJ_JOINT, j)
            old = mujoco.mj_name2id(before, mujoco.mjtObj.mjOBJ_JOINT, name) if name else -1
            if old < 0:
                continue
            width = _width(after, j)
            qpos[after.jnt_qposadr[j] : after.jnt_qposadr[j] + width[0]] = before.key_qpos[k][
                before.jnt_qposadr[old] : before.jnt_qposadr[old] + width[0]
            ]
            qvel[after.jnt_dofadr[j] : after.jnt_dofadr[j] + width[1]] = before.key_qvel[k][
                before.jnt_dofadr[old] : before.jnt_dofadr[old] + width[1]
            ]
        ctrl = np.zeros(after.nu)
        for a in range(after.nu):
            name = mujoco.mj_id2name(after, mujoco.mjtObj.mjOBJ_ACTUATOR, a)
            old = mujoco.mj_name2id(before, mujoco.mjtObj.mjOBJ_ACTUATOR, name) if name else -1
            if old >= 0:
                ctrl[a] = before.key_ctrl[k][old]
        key.qpos, key.qvel, key.ctrl = qpos.tolist(), qvel.tolist(), ctrl.tolist()
        key.act = list(saved[k][2]) if after.na == before.na else []


def _width(model, joint: int) -> tuple:
    """(qpos, qvel) widths of a joint: free 7, 6; ball 4, 3; hinge and slide 1, 1."""
    kind = int(model.jnt_type[joint])
    return {0: (7, 6), 1: (4, 3)}.get(kind, (1, 1))


def passive_tendons(model) -> tuple:
    """Every tendon with a spring that no actuator pulls (a strap), one phrase each.

    Parameters
    ----------
    model : mujoco.MjModel

    Returns
    -------
    tuple of str
    """
    mujoco = _mujoco()
    tendon = mujoco.mjtTrn.mjTRN_TENDON
    pulled = {int(model.actuator_trnid[i, 0]) for i in range(model.nu) if model.actuator_trntype[i] == tendon}
    out = []
    for t in range(model.ntendon):
        if t in pulled or not model.tendon_stiffness[t] > 0:
            continue
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_TENDON, t) or f"tendon {t}"
        out.append(
            f"passive tendon {name!r} (a spring of {float(model.tendon_stiffness[t]):.4g} N/m, no actuator): a device, "
            "not a muscle; its spring is in the passive forces (K_0)"
        )
    return tuple(out)
