"""The paper's model and its solution as a MuJoCo model (MJCF), built with MuJoCo's own spec API (docs/interchange.md).

The chain of docs/chain.md becomes a tree of hinge joints at the CoRs (the pelvis is a
body ``ground`` fixed to the world), each body holding the mass it carries: the body above the top CoR the upper
body's point mass, every other one the lumbar level above its joint (:func:`spinectl.model.chain.mass_matrix`).
Every fibre is a spatial tendon between two sites (its upper attachment on the thorax, its
lower one on the pelvis) driven by a ``general`` actuator whose affine gain reproduces, at
the exported upright posture, spinectl's tension, its slope in length and its slope in
velocity (:func:`fibre_gains`); the control of a fibre's actuator is its muscle's PCSA [cm^2].
The per-segment model's counter torques (docs/chain.md: tau_0 is the per-segment torque)
are motors on the joints, so that the posture is an equilibrium. The intervertebral stiffness
(``passive``, and with ``with_local_stiffness`` the chain's least local stiffness) is the
joints' ``stiffness``, and the local muscles' damping (docs/chain.md) the joints' ``damping``.
Keyframe 0 holds the solution: the posture and every control.

The XML is MuJoCo's own (:meth:`mujoco.MjSpec.to_xml`), with its numbers, which MuJoCo writes to
six significant digits, rewritten from the spec to the last bit (:func:`exact_xml`); written atomically.

References
----------
Todorov E, Erez T, Tassa Y (2012). MuJoCo: a physics engine for model-based control.
IROS 2012, 5026-5033. doi:10.1109/IROS.2012.6386109.

Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
doi:10.1186/1742-4682-9-13.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import atomic_write_text, check_distinct
from ..model import chain, geometry, laws
from ..model.mechanics import gravity_sign, inertia, passive_stiffness
from ..model.params import Model
from ..model.source import header
from ..quoting import xml_comment
from ..units import M2_PER_CM2
from .engine import CONTROL_UNIT, require_mujoco

HINGE_AXIS = (0.0, -1.0, 0.0)
"""The joints' axis in MuJoCo's frame: spinectl's (x, y) is MuJoCo's (x, z), and a rotation about -y
turns x towards z, counter-clockwise in spinectl's plane (docs/model.md, "Frame and units")."""

GROUND = "ground"
"""Name of the pelvis's body, fixed to MuJoCo's world (OpenSim's name of the ground)."""

KEYFRAME = "solution"
"""Name of keyframe 0: the exported posture and the controls of the solution."""


@dataclass(frozen=True)
class PaperSolution:
    """The paper's model at one (E, Lambda) with the solution to export.

    Attributes
    ----------
    model : Model
        The parameters.
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        PCSA of every muscle [m^2]: the per-segment optimum unless given.
    local_stiffness : numpy.ndarray, shape (n_cor,)
        Local stiffness added as joint springs [N m/rad] (0 without ``with_local_stiffness``).
    joint_stiffness : numpy.ndarray, shape (n_cor,)
        The joints' stiffness in the file: passive plus local [N m/rad].
    joint_damping : numpy.ndarray, shape (n_cor,)
        The joints' damping in the file: the local muscles' c_loc k
        (:func:`spinectl.model.chain.local_damping`) [N m s/rad].
    counter_torque : numpy.ndarray, shape (n_cor,)
        -tau_0, the constant torque that makes the posture an equilibrium [N m].
    eigenvalues : numpy.ndarray, shape (2 n_cor,)
        The chain's eigenvalues at this solution (``stability --coupled``), with the exported
        joint stiffness [1/s], largest real part first.
    stiffness, damping, mass : numpy.ndarray, shape (n_cor, n_cor)
        The chain's K (with the joint stiffness), D (with the joint damping) and M [N m/rad, N m s/rad, kg m^2].
    """

    model: Model
    eccentricity: float
    lordosis: float
    pcsa: np.ndarray
    local_stiffness: np.ndarray
    joint_stiffness: np.ndarray
    joint_damping: np.ndarray
    counter_torque: np.ndarray
    eigenvalues: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    mass: np.ndarray

    @property
    def cor(self) -> np.ndarray:
        """Upright CoR positions [m], top to bottom, shape (n_cor, 2)."""
        return geometry.cor_positions(self.eccentricity, self.lordosis, self.model.geometry)


def paper_solution(model: Model, eccentricity: float, lordosis: float, pcsa=None, with_local_stiffness=False):
    """The solution to export: the per-segment optimum (or ``pcsa``) and the chain there.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, optional
        PCSA [m^2], per pair or per muscle; default the per-segment optimum
        (:func:`spinectl.optimise.stabilising.minimum_stabilising_pcsa`).
    with_local_stiffness : bool
        Add the chain's least local stiffness
        (:func:`spinectl.optimise.coupled.least_local_stiffness`) as joint springs, with the local
        muscles' damping (:func:`spinectl.model.chain.local_damping`) as joint dampers.

    Returns
    -------
    PaperSolution

    Raises
    ------
    ModelError
        No activation stabilises every segment (``pcsa`` not given).
    """
    from ..optimise.coupled import coupled_stability_at

    result = coupled_stability_at(model, eccentricity, lordosis, pcsa, slip_check=pcsa is not None)
    e, lam = float(eccentricity), float(lordosis)
    cor = geometry.cor_positions(e, lam, model.geometry)
    n = cor.shape[0]
    local = np.asarray(result.local.local_stiffness, float) if with_local_stiffness else np.zeros(n)
    if not np.all(np.isfinite(local)):
        from ..errors import ModelError

        raise ModelError(f"with_local_stiffness: no least local stiffness at E = {e:g} m, Lambda = {lam:g} m")
    passive = passive_stiffness(model, inertia(cor, model))
    zero = np.zeros(n)
    tau0 = chain.chain_muscle_torque_per_pcsa(model, cor, zero, zero) @ result.pcsa
    tau0 = tau0 + chain.chain_gravity_torque(model, cor, zero)
    stiffness = result.stiffness - np.diag(local)
    joint_damping = chain.local_damping(local, model)  # the local muscles damp what they stiffen
    damping = result.damping - np.diag(joint_damping)
    return PaperSolution(
        model=model,
        eccentricity=e,
        lordosis=lam,
        pcsa=np.asarray(result.pcsa, float),
        local_stiffness=local,
        joint_stiffness=passive + local,
        joint_damping=joint_damping,
        counter_torque=-tau0,
        eigenvalues=chain.dynamic_eigenvalues(result.mass, stiffness, damping),
        stiffness=stiffness,
        damping=damping,
        mass=result.mass,
    )


@dataclass(frozen=True)
class Fibres:
    """Every fibre of the paper's model with its linearised tension law (:func:`fibre_gains`).

    Attributes
    ----------
    names : tuple of str
        ``<muscle>_<k>``, k the fibre's index within its muscle.
    muscle : numpy.ndarray of int, shape (F,)
        Index of each fibre's muscle in ``model.muscle_names``.
    upper, lower : numpy.ndarray, shape (F, 2)
        Upright attachments [m] (upper on the thorax, lower on the pelvis).
    length : numpy.ndarray, shape (F,)
        Upright length l0 [m].
    force, length_slope, velocity_slope : numpy.ndarray, shape (F,)
        Per unit PCSA of the fibre's muscle: tension T0 = sigma s f_l(l0) [N/m^2], dT/dl =
        sigma s f_l'(l0) [N/m^3] and dT/dv = sigma s f_l(l0) f_H'(0) [N s/m^3] with the paper's
        law (:func:`spinectl.model.laws.at_rest` with another), s the fibre's share of its muscle
        and v the shortening velocity.
    """

    names: tuple
    muscle: np.ndarray
    upper: np.ndarray
    lower: np.ndarray
    length: np.ndarray
    force: np.ndarray
    length_slope: np.ndarray
    velocity_slope: np.ndarray


def fibre_gains(model: Model) -> Fibres:
    """Each fibre's tension, and its slopes in length and velocity, at the upright posture.

    The tension T = f_iso T_law(l, v) of the fibres' muscle law (``fibre.law``, the paper's f_l(l) f_H(v);
    :func:`spinectl.model.laws.at_rest`), with f_iso = sigma s PCSA, to first order about (l0, v = 0):
    T ~ T0 + T_l (l - l0) + T_v v, which is what the chain's K and D are made of (docs/chain.md).

    Parameters
    ----------
    model : Model

    Returns
    -------
    Fibres
    """
    upper, lower, share = geometry.all_fibres(model)
    l0 = np.linalg.norm(lower - upper, axis=-1)
    l_opt = model.fibre.optimal_length_ratio * l0
    rest = laws.at_rest(laws.get_law(model.fibre.law), l0, l_opt, model.fibre, model.errata)
    f_iso = model.fibre.specific_tension * share.sum(axis=1)  # per unit PCSA of the fibre's muscle
    owner = np.argmax(share, axis=1)
    counts: dict = {}
    names = []
    for m in owner:
        k = counts[m] = counts.get(m, -1) + 1
        names.append(f"{model.muscle_names[m]}_{k}")
    return Fibres(
        names=tuple(names),
        muscle=owner,
        upper=upper,
        lower=lower,
        length=l0,
        force=f_iso * rest.tension,
        length_slope=f_iso * rest.length_slope,
        velocity_slope=f_iso * rest.tension * rest.relative_velocity_slope,
    )


def affine_gain(fibres: Fibres) -> np.ndarray:
    """MuJoCo ``gainprm`` (g0, g1, g2) of each fibre's actuator, per cm^2 of its muscle's PCSA.

    MuJoCo's affine gain is g0 + g1 L + g2 V with L the tendon's length and V = dL/dt; the
    actuator's force is the gain times the control, and a tendon pulls with a negative force.
    With the shortening velocity v = -V, the tension to first order T0 + T_l (L - l0) - T_v V
    (:func:`fibre_gains`) gives g0 = -(T0 - T_l l0), g1 = -T_l, g2 = T_v, times 1e-4 m^2/cm^2.
    Its force's slopes in L and V at (l0, 0) are then spinectl's, so K and D are.

    Parameters
    ----------
    fibres : Fibres

    Returns
    -------
    numpy.ndarray, shape (F, 3)
        [N/cm^2, N/m/cm^2, N s/m/cm^2].
    """
    g = np.stack([-(fibres.force - fibres.length_slope * fibres.length), -fibres.length_slope, fibres.velocity_slope])
    return (g * M2_PER_CM2).T


def _xz(point) -> list:
    """spinectl's (x, y) as MuJoCo's (x, 0, z)."""
    return [float(point[0]), 0.0, float(point[1])]


def body_names(model: Model) -> tuple:
    """Names of the chain's bodies, from the top: ``thorax``, then the vertebra above each lower CoR.

    Parameters
    ----------
    model : Model

    Returns
    -------
    tuple of str
        Body k hangs on joint k (``model.geometry.cor_names[k]``).
    """
    return ("thorax",) + tuple(f"vertebra_above_{name}" for name in model.geometry.cor_names[1:])


def paper_spec(solution: PaperSolution):
    """The MuJoCo spec (:class:`mujoco.MjSpec`) of the paper's model with the solution in keyframe 0.

    Parameters
    ----------
    solution : PaperSolution

    Returns
    -------
    mujoco.MjSpec
    """
    mujoco = require_mujoco()
    model, cor = solution.model, solution.cor
    n = cor.shape[0]
    spec = mujoco.MjSpec()
    spec.modelname = "wagner2012_chain"
    spec.comment = xml_comment(  # the header holds the user's --config path: never live XML (spinectl.quoting)
        f" spinectl export of {header(model)}; E = {solution.eccentricity:g} m, Lambda = {solution.lordosis:g} m. "
        "Fibre actuators: affine gain = spinectl's tension and its slopes at the upright posture, control = "
        "the muscle's PCSA [cm^2]; counter_* motors hold the per-segment counter torques [N m]. "
    )
    spec.compiler.degree = False
    spec.option.gravity = [0.0, 0.0, -gravity_sign(model) * model.body.gravity]
    spec.option.timestep = 5e-4
    masses = [model.body.mass] + [model.levels.mass] * (n - 1)
    gyration = [model.body.radius_of_gyration] + [model.levels.radius_of_gyration] * (n - 1)
    levels = chain.level_positions(np.zeros(n), cor)
    centres = [geometry.mass_position(model)] + list(levels)  # body k: level k - 1 lies between CoRs k - 1 and k
    names = body_names(model)
    # the pelvis: a body fixed to the world, named as OpenSim's ground, so that one mapping
    # (mappings/wagner2012_chain.toml) maps both exports
    ground = parent = spec.worldbody.add_body(name=GROUND)
    bodies = {}
    for k in range(n - 1, -1, -1):  # from the pelvis up: the bottom joint carries everything
        body = parent.add_body(name=names[k])
        body.explicitinertial = True
        body.mass = masses[k]
        body.ipos = _xz(centres[k])
        body.inertia = [max(masses[k] * gyration[k] ** 2, mujoco.mjMINVAL)] * 3  # only the hinge axis's counts
        if k > 0:  # a level's weight enters gravity by levels.weight_in_gravity (docs/chain.md)
            body.gravcomp = 1.0 - model.levels.weight_in_gravity
        body.add_joint(
            name=model.geometry.cor_names[k],
            type=mujoco.mjtJoint.mjJNT_HINGE,
            pos=_xz(cor[k]),
            axis=list(HINGE_AXIS),
            stiffness=float(solution.joint_stiffness[k]),
            damping=float(solution.joint_damping[k]),
        )
        bodies[k] = parent = body
    fibres = fibre_gains(model)
    gains = affine_gain(fibres)
    for f, name in enumerate(fibres.names):
        bodies[0].add_site(name=f"{name}_upper", pos=_xz(fibres.upper[f]))
        ground.add_site(name=f"{name}_lower", pos=_xz(fibres.lower[f]))
        tendon = spec.add_tendon(name=name)
        tendon.wrap_site(f"{name}_upper")
        tendon.wrap_site(f"{name}_lower")
    for f, name in enumerate(fibres.names):
        actuator = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_TENDON)
        actuator.gaintype = mujoco.mjtGain.mjGAIN_AFFINE
        actuator.biastype = mujoco.mjtBias.mjBIAS_NONE
        actuator.gainprm[:3] = gains[f]
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for joint in model.geometry.cor_names:
        motor = spec.add_actuator(name=f"counter_{joint}", target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.gainprm[0] = 1.0
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    spec.add_text(name=CONTROL_UNIT, data="cm^2")  # read back by spinectl.anatomy.model.Anatomy.control_unit
    controls = np.concatenate([solution.pcsa[fibres.muscle] / M2_PER_CM2, solution.counter_torque])
    spec.add_key(name=KEYFRAME, qpos=np.zeros(n), ctrl=controls)
    return spec


def export_mjcf(
    model: Model,
    eccentricity: float,
    lordosis: float,
    out,
    *,
    pcsa=None,
    with_local_stiffness: bool = False,
    inputs: dict | None = None,
) -> PaperSolution:
    """Write the paper's model and its solution as MJCF (:func:`paper_spec`), atomically.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    out : str or pathlib.Path
        The MJCF file to write.
    pcsa : array_like, optional
        PCSA [m^2]; default the per-segment optimum.
    with_local_stiffness : bool
        The chain's least local stiffness as joint springs.
    inputs : dict, optional
        Option name -> path of every file read (e.g. ``{"--config": path}``): ``out`` must be none of them.

    Returns
    -------
    PaperSolution
        What was exported.

    Raises
    ------
    ParameterError
        ``out`` is one of ``inputs``.
    """
    check_distinct({"--out": str(out)}, inputs)
    solution = paper_solution(model, eccentricity, lordosis, pcsa, with_local_stiffness)
    spec = paper_spec(solution)
    spec.compile()  # refuse to write what MuJoCo cannot load
    atomic_write_text(Path(out), exact_xml(spec))
    return solution


_INERTIAL = {"pos": "ipos", "mass": "mass", "diaginertia": "inertia"}
"""An ``<inertial>`` element's attributes and the attributes of its body in the spec."""


def _spec_object(spec, tag: str, name: str):
    """The spec's object that an MJCF element of ``tag`` named ``name`` stands for, or None."""
    kind = {"site": spec.site, "joint": spec.joint, "body": spec.body, "key": spec.key, "spatial": spec.tendon}.get(tag)
    if kind is None and tag in ("general", "motor"):
        kind = spec.actuator
    return None if kind is None else kind(name)


def _exact(values, count: int) -> str:
    """The first ``count`` of ``values`` as text that reads back to the same doubles."""
    return " ".join(repr(float(v)) for v in np.ravel(values)[:count])


def _numbers(text: str):
    """How many numbers the attribute's text holds, or None if it is not a list of numbers."""
    try:
        return len([float(word) for word in text.split()]) or None
    except ValueError:
        return None


def exact_xml(spec) -> str:
    """MuJoCo's MJCF of ``spec`` with every number of a named element as the spec holds it.

    :meth:`mujoco.MjSpec.to_xml` writes numbers to six significant digits, too few for a
    round trip at 1e-9; every numeric attribute that the spec's object of the element has
    (``pos``, ``stiffness``, ``gainprm``, a key's ``ctrl``, an ``<inertial>``'s mass ...) is
    rewritten to the last bit, the rest of MuJoCo's text kept.

    Parameters
    ----------
    spec : mujoco.MjSpec

    Returns
    -------
    str
        MJCF.
    """
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    root = ET.fromstring(spec.to_xml(), parser=parser)
    for element in root.iter():
        name = element.get("name")
        obj = None if name is None else _spec_object(spec, element.tag, name)
        if obj is None:
            continue
        pairs = [(attr, attr) for attr in element.keys()]
        if element.tag == "body":
            for child in element.findall("inertial"):
                for attr, field in _INERTIAL.items():
                    if attr in child.keys():
                        child.set(attr, _exact(getattr(obj, field), _numbers(child.get(attr))))
        for attr, field in pairs:
            numbers = _numbers(element.get(attr))
            value = getattr(obj, field, None)
            if numbers is None or isinstance(value, str | bool | int) or value is None:
                continue  # names, keywords, integers and flags are exact already
            value = np.ravel(np.asarray(value, float))
            if value.size >= numbers:
                element.set(attr, _exact(value, numbers))
    return ET.tostring(root, encoding="unicode") + "\n"


def mujoco_state_matrix(mj_model, data, joints) -> np.ndarray:
    """MuJoCo's own linearisation as a continuous state matrix over ``joints``, controls held.

    :func:`mujoco.mjd_transitionFD` of one semi-implicit Euler step v+ = v + h M^-1 f(q, v),
    q+ = q + h v+: its velocity rows are exact, A_vq = h M^-1 K and A_vv = I + h M^-1 D, so the
    continuous matrix is [[0, I], [A_vq / h, (A_vv - I) / h]] (Euler's implicit damping off).

    Parameters
    ----------
    mj_model : mujoco.MjModel
        With Euler integration.
    data : mujoco.MjData
        At the state and controls to linearise about.
    joints : sequence of str
        Joint names, in the order of the rows.

    Returns
    -------
    numpy.ndarray, shape (2 n, 2 n)
        [1/s^2, 1/s].
    """
    mujoco = require_mujoco()
    mj_model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_EULERDAMP
    nv, h = mj_model.nv, mj_model.opt.timestep
    size = 2 * nv + mj_model.na
    a = np.zeros((size, size))
    mujoco.mjd_transitionFD(mj_model, data, 1e-6, True, a, None, None, None)
    dofs = np.array([mj_model.jnt_dofadr[mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in joints])
    n = dofs.size
    a_vq = a[np.ix_(nv + dofs, dofs)]
    a_vv = a[np.ix_(nv + dofs, nv + dofs)]
    return np.block([[np.zeros((n, n)), np.eye(n)], [a_vq / h, (a_vv - np.eye(n)) / h]])
