"""The paper's question and the chain's on an anatomical model, at one activation (docs/anatomy.md).

Verdicts, each with its criterion:

- **joint by joint** (the paper's): each joint alone, the others fixed, is self-stable when
  its diagonal entry of -K is positive;
- **the chain**: every chain joint free at once, stable when -K is positive definite (its
  least eigenvalue, the static margin, > 0), and its dynamics x' = [[0, I], [M^-1 K, M^-1 D]] x;
- both for the **free** chain (the model's equality constraints off) and the chain
  **constrained by the model's rhythm** (its independent coordinates only).

The global muscles' certificate: their moment arms over the chain's joints have rank r;
the n - r directions of their null space are modes whose stiffness they can give only
through their lengths' curvature (docs/chain.md), left to the local muscles, passive
tissue and reflexes.

All on the :class:`~spinectl.model.linear_chain.LinearChain` of the model, through the chain's
own functions: its state matrix and dynamic eigenvalues (:mod:`spinectl.model.chain`), its
programmes (:mod:`spinectl.optimise.coupled.sdp`) and its exact delay margin
(:func:`spinectl.reflex.mimo.linear_chain_delay_margin`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..model.chain import dynamic_eigenvalues
from ..model.chain import state_matrix as chain_state_matrix
from ..model.linear_chain import CONTROL_CLASSES, LinearChain
from ..model.stability import MARGINAL_TIME_CONSTANT, slowest_time_constant
from .certificate import GlobalCertificate, global_certificate
from .contract import AnatomyEngine
from .identity import identity_text, model_identity
from .loads import analysed_loads
from .naming import joint_labels
from .net_torque import NetTorque, net_torque
from .referee import mujoco_eigenvalues, mujoco_growth_rate

REFERENCE_POSTURE = "the model's reference posture"
"""The posture analysed when none is given, as the table and the JSON's ``posture_source`` say it."""


def activations(anatomy: AnatomyEngine, activation) -> np.ndarray:
    """The activation vector: one value for every muscle, a vector, or a dict by muscle name (others 0).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    activation : float, array_like, dict or None
        Activations in [0, 1] (MuJoCo's muscles; other muscles' controls within
        :meth:`~spinectl.anatomy.contract.AnatomyEngine.control_bounds`, e.g. a PCSA [cm^2] of spinectl's
        export); None: the model's keyframe 0 (:meth:`~spinectl.anatomy.contract.AnatomyEngine.default_controls`).

    Returns
    -------
    numpy.ndarray, shape (m,)
    """
    m = len(anatomy.muscles)
    lower, upper = anatomy.control_bounds()
    unit = anatomy.control_unit
    allowed = "[0, 1]" if unit == "1" else f"[{lower.min():g}, {upper.max():g}] {unit}"
    if unit == "1" and np.any(lower > 0):  # a law's activation floor (OpenSim's Millard and Thelen muscles)
        allowed = f"[floor, 1], each muscle's floor its law's minimum activation ({lower.min():g} ... {lower.max():g})"
    if activation is None:
        a = anatomy.default_controls()
    elif m == 0 and np.size(activation) > 0:  # before: analysed as given, its mean NaN
        raise ParameterError(
            "activation", f"{anatomy.name} has no muscles: its passive chain has no activation to give"
        )
    elif isinstance(activation, dict):
        unknown = sorted(set(activation) - set(anatomy.muscles))
        if unknown:
            raise ParameterError("activation", f"names muscles that {anatomy.name} lacks: {unknown[:5]}")
        a = np.array([float(activation.get(name, 0.0)) for name in anatomy.muscles])
    else:
        try:
            a = np.broadcast_to(np.asarray(activation, float), (m,)).copy()
        except (TypeError, ValueError):
            raise ParameterError("activation", f"must be one number or {m} numbers in {allowed}") from None
    if not np.all(np.isfinite(a)) or np.any(a < lower) or np.any(a > upper):
        raise ParameterError("activation", f"must be in {allowed} (got {a.min():g} ... {a.max():g})")
    return a


def state_matrix(chain: LinearChain, a) -> np.ndarray:
    """x' = A x with x = (q, q'): [[0, I], [M^-1 K(a), M^-1 D(a)]] [1/s^2, 1/s].

    :func:`spinectl.model.chain.state_matrix` at K(a), D(a).

    Parameters
    ----------
    chain : LinearChain
        The chain.
    a : array_like, shape (m,)
        Activations.

    Returns
    -------
    numpy.ndarray, shape (2n, 2n)
    """
    return chain_state_matrix(chain.mass_matrix, chain.stiffness(a), chain.damping(a))


def plane_text(plane: str) -> str:
    """A mapping's plane as a table's first line names it.

    Parameters
    ----------
    plane : str
        One of the mapping's planes (:data:`spinectl.anatomy.mapping.PLANES`).

    Returns
    -------
    str
        ``'sagittal plane'``, ``'coronal plane'``, and for ``'3d'`` (every chain joint of every plane at
        once) ``'all three planes (3-D)'``.
    """
    return "all three planes (3-D)" if plane == "3d" else f"{plane} plane"


@dataclass(frozen=True)
class ChainVerdict:
    """One chain at one activation: its matrices, joint-by-joint and chain verdicts.

    Attributes
    ----------
    joints : tuple of str
        Its coordinates.
    stiffness, damping, mass : numpy.ndarray, shape (n, n)
        K(a) [N m/rad], D(a) [N m s/rad], M [kg m^2].
    joint_stiffness : numpy.ndarray, shape (n,)
        Diagonal of -K: each joint alone, the others fixed [N m/rad].
    eigenvalues : numpy.ndarray, shape (n,)
        Of -K, ascending [N m/rad].
    modes : numpy.ndarray, shape (n, n)
        Unit eigenvectors of -K, one per column, in the order of ``eigenvalues``.
    dynamic_eigenvalues : numpy.ndarray, shape (2n,)
        Of the state matrix [1/s], by descending real part.
    """

    joints: tuple
    stiffness: np.ndarray
    damping: np.ndarray
    mass: np.ndarray
    joint_stiffness: np.ndarray
    eigenvalues: np.ndarray
    modes: np.ndarray
    dynamic_eigenvalues: np.ndarray

    @property
    def joint_self_stable(self) -> tuple:
        """Each joint self-stable, joint by joint (the paper's criterion)."""
        return tuple(bool(s > 0) for s in self.joint_stiffness)

    @property
    def joint_time_constants(self) -> np.ndarray:
        """Each joint's slowest time constant alone, the others fixed (K_jj, D_jj, M_jj) [s]; inf where unstable.

        :func:`spinectl.model.stability.slowest_time_constant`, the rule of ``spinectl stability``.
        """
        diag = [np.diag(x) for x in (self.stiffness, self.damping, self.mass)]
        return slowest_time_constant(diag[0][:, None], diag[1][:, None], diag[2][:, None])

    @property
    def joint_marginal(self) -> tuple:
        """Each joint self-stable but slower than :data:`~spinectl.model.stability.MARGINAL_TIME_CONSTANT`
        (stable in name only), as ``spinectl stability`` reports it."""
        slow = self.joint_time_constants > MARGINAL_TIME_CONSTANT
        return tuple(bool(ok and s) for ok, s in zip(self.joint_self_stable, slow, strict=True))

    @property
    def chain_stable(self) -> bool:
        """The chain stable, every joint free at once: -K positive definite."""
        return bool(self.eigenvalues[0] > 0)


def verdict(chain: LinearChain, a) -> ChainVerdict:
    """The joint-by-joint and chain verdicts of one chain at activations a.

    Parameters
    ----------
    chain : LinearChain
        The chain.
    a : array_like, shape (m,)
        Activations.

    Returns
    -------
    ChainVerdict
    """
    k = chain.stiffness(a)
    values, vectors = np.linalg.eigh(-0.5 * (k + k.T))
    dyn = dynamic_eigenvalues(chain.mass_matrix, k, chain.damping(a))
    return ChainVerdict(
        joints=chain.joints,
        stiffness=k,
        damping=chain.damping(a),
        mass=chain.mass_matrix,
        joint_stiffness=-np.diag(k),
        eigenvalues=values,
        modes=vectors,
        dynamic_eigenvalues=dyn,
    )


@dataclass(frozen=True)
class AnatomyResult:
    """The analysis of one model, plane, posture and activation (:func:`analyse`).

    Attributes
    ----------
    model : dict
        The model's identity (:func:`~spinectl.anatomy.identity.model_identity`): ``name``, ``source``,
        ``sha256``, ``sha256_short``, ``engine``, ``versions``.
    plane : str
        The plane.
    muscles : dict
        ``global``, ``local``, ``between``, ``non-lumbar``: muscle names by class (docs/anatomy.md).
    activations : numpy.ndarray, shape (m,)
        [1].
    joint_stiffness_added : numpy.ndarray, shape (n,)
        Added at each chain joint [N m/rad].
    stiffness_source : str
        The source of the added stiffness ('' when none is added).
    free, constrained : ChainVerdict
        The free chain and the chain constrained by the model's rhythm.
    certificate : GlobalCertificate
        The global muscles' rank and null space.
    mujoco_eigenvalues : numpy.ndarray or None
        The referee's eigenvalues of the free chain (``check=True``) [1/s].
    reflex : dict or None
        With a reflex: ``kp``, ``kd`` [N m/rad, N m s/rad], ``lag`` [s] and the free chain's exact
        delay margin (:func:`reflex_margin`).
    simulated_rate : float
        With ``check``: the rate fitted to MuJoCo's simulation started along the free chain's
        mode of largest real eigenvalue (``referee.mujoco_growth_rate``; NaN if that is complex) [1/s].
    control_unit : str
        The unit of ``activations``: ``"1"``, or e.g. ``"cm^2"`` (a PCSA, spinectl's export).
    activation_source : str
        Where ``activations`` come from: ``"given"``, or the model's defaults
        (:meth:`~spinectl.anatomy.model.Anatomy.default_controls_source`).
    rhythm_size : int
        How many coordinates the model's rhythm ties to the chain; 0: no rhythm (no joint
        equality or coupler), the constrained chain is the free one.
    joint_slopes : numpy.ndarray or None
        Where the chain's coordinates are not its joints' angles: each joint's rotation per unit of
        its own coordinate [rad per coordinate rad] (the stiffnesses are per joint radian,
        :mod:`spinectl.anatomy.joint_angles`); None where they are (a MuJoCo hinge).
    rhythm_left_out : tuple of str
        The model's couplings of a chain coordinate to one off the chain (a routing body's), named:
        not in the rhythm (:attr:`~spinectl.anatomy.linearise.Rhythm.left_out`).
    devices : tuple of str
        What the model holds besides muscles and how it enters the chain (welds, a free root fixed,
        passive tendons), one phrase each (:attr:`~spinectl.anatomy.engine.Engine.devices`).
    posture_source : str
        Where the posture comes from: the model's reference posture, ``"given"``, or a file and the time of
        its frame (:mod:`spinectl.anatomy.recordings`).
    net_torque : NetTorque or None
        The net torque at each chain joint at the posture and activations, and whether it is far from
        equilibrium (:mod:`spinectl.anatomy.net_torque`).
    rhythm_turns : tuple of float
        Per independent coordinate of the rhythm, the chain's joints' rotation summed per its radian [rad/rad]:
        the constrained chain's stiffness is per radian of that coordinate, which turns the chain this much.
    """

    model: dict
    plane: str
    muscles: dict
    activations: np.ndarray
    joint_stiffness_added: np.ndarray
    stiffness_source: str
    free: ChainVerdict
    constrained: ChainVerdict
    certificate: GlobalCertificate
    mujoco_eigenvalues: np.ndarray | None = field(default=None)
    simulated_rate: float = float("nan")
    reflex: dict | None = None
    control_unit: str = "1"
    activation_source: str = "given"
    rhythm_size: int = 1
    joint_slopes: np.ndarray | None = None
    rhythm_left_out: tuple = ()
    devices: tuple = ()
    posture_source: str = REFERENCE_POSTURE
    loads: tuple = field(default=(), metadata={"doc": "the external loads in the chains (spinectl.anatomy.loads)"})
    net_torque: NetTorque | None = None
    rhythm_turns: tuple = ()

    @property
    def activation_mean(self) -> float:
        """The mean of :attr:`activations`; NaN for a model without muscles (its passive chain)."""
        return float(self.activations.mean()) if self.activations.size else float("nan")

    def referee_error(self) -> float:
        """Largest relative difference between spinectl's and MuJoCo's eigenvalues, matched one to one.

        Returns
        -------
        float
            max over the modes of abs(lambda - mu) / abs(mu); NaN without ``check``.
        """
        if self.mujoco_eigenvalues is None:
            return float("nan")
        from scipy.optimize import linear_sum_assignment

        ours, theirs = self.free.dynamic_eigenvalues, self.mujoco_eigenvalues
        cost = np.abs(ours[:, None] - theirs[None, :]) / np.abs(theirs)[None, :]
        rows, cols = linear_sum_assignment(cost)
        return float(cost[rows, cols].max())

    def to_dict(self) -> dict:
        """JSON-ready: the keys of docs/anatomy.md ("JSON").

        Returns
        -------
        dict
        """

        def cplx(values):
            return [{"real": float(v.real), "imag": float(v.imag)} for v in values]

        free, con, cert = self.free, self.constrained, self.certificate
        out = {
            "model": self.model,
            "plane": self.plane,
            "joints": list(free.joints),
            "muscles": {k: list(v) for k, v in self.muscles.items()},
            "global_rank": cert.rank,
            "global_singular_values_m_per_rad": cert.singular_values.tolist(),
            "global_null_space": cert.null_space.T.tolist(),
            "null_space_stiffness_Nm_per_rad": cert.null_space_stiffness.tolist(),
            "activation_mean": self.activation_mean,
            "control_unit": self.control_unit,
            "activation_source": self.activation_source,
            "posture_source": self.posture_source,
            "stiffness_matrix_Nm_per_rad": free.stiffness.tolist(),
            "damping_matrix_Nms_per_rad": free.damping.tolist(),
            "mass_matrix_kgm2": free.mass.tolist(),
            "joint_stiffness_Nm_per_rad": self.joint_stiffness_added.tolist(),
            "joint_stiffness_source": self.stiffness_source,
            "restoring_stiffness_Nm_per_rad": free.joint_stiffness.tolist(),
            "eigenvalues": free.eigenvalues.tolist(),
            "modes": free.modes.T.tolist(),
            "dynamic_eigenvalues": cplx(free.dynamic_eigenvalues),
            "joint_self_stable": list(free.joint_self_stable),
            "joint_self_stable_criterion": "joint by joint: each joint alone, the others fixed (free chain)",
            "joint_marginal": list(free.joint_marginal),
            "slowest_time_constant_s": free.joint_time_constants.tolist(),
            "chain_stable": free.chain_stable,
            "chain_stable_criterion": "the chain: every chain joint free at once, equality constraints off",
            "constrained": {
                "joints": list(con.joints),
                "stiffness_matrix_Nm_per_rad": con.stiffness.tolist(),
                "mass_matrix_kgm2": con.mass.tolist(),
                "eigenvalues": con.eigenvalues.tolist(),
                "dynamic_eigenvalues": cplx(con.dynamic_eigenvalues),
                "chain_stable": con.chain_stable,
                "chain_stable_criterion": (
                    "the chain constrained by the model's lumbar rhythm"
                    if self.rhythm_size
                    else "no rhythm (no joint equality or coupler): the same as the free chain"
                ),
                "rhythm": bool(self.rhythm_size),
                "modes_removed": free.stiffness.shape[0] - con.stiffness.shape[0],
                "rhythm_left_out": list(self.rhythm_left_out),
                "chain_turn_rad_per_coordinate_rad": list(self.rhythm_turns),
            },
            "devices": list(self.devices),
            **({"loads": [load.to_dict() for load in self.loads]} if self.loads else {}),
        }
        if self.joint_slopes is not None:  # only where the units differ: a hinge's output stays as it was
            out["joint_rad_per_coordinate_rad"] = self.joint_slopes.tolist()
        if self.mujoco_eigenvalues is not None:
            out["mujoco_eigenvalues"] = cplx(self.mujoco_eigenvalues)
            out["mujoco_relative_difference"] = self.referee_error()
            out["predicted_rate_per_s"] = float(self.free.dynamic_eigenvalues[0].real)
            out["mujoco_simulated_rate_per_s"] = self.simulated_rate
        if self.reflex is not None:
            out["reflex"] = self.reflex
        if self.net_torque is not None:
            out.update(self.net_torque.to_dict())
        return out

    def _per_coordinate(self) -> str:
        """What the constrained chain's stiffness is per: a radian of the rhythm's coordinate, which turns the chain."""
        if not self.rhythm_turns:
            return ""
        turns = "; ".join(
            f"one radian of {j} turns the chain's joints {t:.3g} rad in all"
            for j, t in zip(self.constrained.joints, self.rhythm_turns, strict=True)
        )
        return f" per radian of the rhythm's coordinate, not of one joint ({turns})"

    def _activation_text(self) -> str:
        """The first line's activations: their mean and source, or that the model has none."""
        if not self.activations.size:
            return "no muscles (the passive chain)"
        if self.control_unit != "1":
            return f"mean control {self.activation_mean:.4g} {self.control_unit} ({self.activation_source})"
        return f"mean activation {self.activation_mean:.3g} ({self.activation_source})"

    def _angle_note(self) -> list:
        """One line where the coordinates are not the joints' angles: the slopes, and what the table is per."""
        if self.joint_slopes is None:
            return []
        turns = ", ".join(f"{j} {s:.4g}" for j, s in zip(self.free.joints, self.joint_slopes, strict=True))
        return [
            f"per radian of each joint's rotation, not of its coordinate (stiffness, added stiffness, "
            f"eigenvalues of -K): the joints turn {turns} rad per coordinate rad"
        ]

    def table(self) -> str:
        """A plain-text table; every verdict names its criterion.

        Returns
        -------
        str
        """
        free, con, cert = self.free, self.constrained, self.certificate
        word = {True: "stable", False: "unstable"}
        counts = ", ".join(f"{len(v)} {k}" for k, v in self.muscles.items())
        lines = [
            f"{identity_text(self.model)}, {plane_text(self.plane)}, posture: {self.posture_source}, "
            + self._activation_text(),
            f"source: {self.model['source']}",
            f"muscles: {counts}; global muscles' moment-arm rank {cert.rank} of {len(free.joints)} "
            f"(singular values {', '.join(f'{s:.3g}' for s in cert.singular_values)} m/rad)",
            f"joint stiffness added: {self.joint_stiffness_added[0]:.4g} N m/rad per joint",
            *self._angle_note(),
            *(["devices: " + "; ".join(self.devices)] if self.devices else []),
            *(f"load (in the equilibrium and K): {load.text()}" for load in self.loads),
            *(self.net_torque.lines() if self.net_torque is not None else []),
            "",
            f"{'joint (level)':<24}{'-K_jj [N m/rad]':>16}  joint by joint (others fixed)",
            f"{'':<24}{'(> 0 restores)':>16}",
        ]
        labels = joint_labels(free.joints, self.plane)  # the model's name and the level: flex_extension (L5S1)
        verdicts = zip(labels, free.joint_stiffness, free.joint_self_stable, free.joint_marginal, strict=True)
        for (name, s, ok, slow), tau in zip(verdicts, free.joint_time_constants, strict=True):
            marginal = f", marginal: slowest time constant {tau:.4g} s > {MARGINAL_TIME_CONSTANT:g} s" if slow else ""
            if slow and np.isinf(tau):  # a real part of 0: no damping at all, not a slow decay
                marginal = ", marginal: undamped (no damping at this joint: it oscillates without decay)"
            lines.append(f"{name:<24}{s:>16.4g}  {'self-' + word[ok]}{marginal}")
        eig = ", ".join(f"{v:.4g}" for v in free.eigenvalues)
        lines += [
            "",
            f"the chain, free (every joint free, equality constraints off): eigenvalues of -K {eig} N m/rad: "
            f"{word[free.chain_stable]} ({int(np.sum(free.eigenvalues <= 0))} of {len(free.eigenvalues)} modes "
            "unstable)",
        ]
        if not self.rhythm_size:
            lines.append(
                "the model has no rhythm (no joint equality or coupler ties the chain): the free chain's verdict "
                "is the only one"
            )
        else:
            lines.append(
                f"the chain constrained by the model's rhythm ({len(con.joints)} coordinate(s): "
                f"{', '.join(con.joints)}): "
                f"eigenvalues of -K {', '.join(f'{v:.4g}' for v in con.eigenvalues)} N m/rad{self._per_coordinate()}: "
                f"{word[con.chain_stable]}; the rhythm removes {len(free.joints) - len(con.joints)} modes"
            )
        if self.rhythm_left_out:
            lines.append(
                "left out of the rhythm (they tie a coordinate off the chain, e.g. a routing body, to the chain): "
                + "; ".join(self.rhythm_left_out)
            )
        if cert.null_space.size:
            lines.append(
                f"global muscles' null space ({cert.null_space.shape[1]} modes): -K there "
                f"{', '.join(f'{v:.4g}' for v in cert.null_space_stiffness)} N m/rad (left to local muscles, "
                "passive tissue and reflexes)"
            )
        if self.mujoco_eigenvalues is not None:
            lines.append(
                f"MuJoCo's own linearisation (mjd_transitionFD, free chain): largest relative difference "
                f"{self.referee_error():.2e} over {len(self.mujoco_eigenvalues)} eigenvalues; its simulation (mj_step) "
                f"along the leading mode (largest real part): rate {self.simulated_rate:.4g} 1/s, predicted "
                f"{self.free.dynamic_eigenvalues[0].real:.4g} 1/s"
            )
        if self.reflex is not None:
            r = self.reflex
            lines.append(
                f"the chain (free) under a delayed PD reflex kp = {r['kp_Nm_per_rad']:g} N m/rad, kd = "
                f"{r['kd_Nms_per_rad']:g} N m s/rad at every joint, activation lag {r['activation_lag_s']:g} s: "
                f"exact delay margin {r['delay_margin_s']:.4g} s ({r['delay_margin_status']})"
            )
        return "\n".join(lines)


def reflex_margin(chain: LinearChain, a, kp: float, kd: float, lag: float) -> dict:
    """The free chain's exact delay margin under a diagonal delayed PD reflex (:mod:`spinectl.reflex.mimo`).

    Parameters
    ----------
    chain : LinearChain
        The free chain.
    a : array_like, shape (m,)
        Activations.
    kp, kd : float
        The reflex gains at every joint [N m/rad], [N m s/rad], >= 0.
    lag : float
        The force generation's time constant T_a [s], >= 0.

    Returns
    -------
    dict
        ``kp_Nm_per_rad``, ``kd_Nms_per_rad``, ``activation_lag_s``, ``delay_margin_s`` (inf:
        any delay; 0: unstable without delay), ``delay_margin_status``, ``delay_margin_frequency_rad_s``.
    """
    from ..reflex.mimo import linear_chain_delay_margin

    for name, value in (("kp", kp), ("kd", kd), ("activation_lag", lag)):
        if not (np.isfinite(value) and value >= 0):
            raise ParameterError(name, f"must be a finite number >= 0 (got {value!r})")
    n = chain.n_joints
    margin = linear_chain_delay_margin(chain, np.full(n, kp), np.full(n, kd), lag, u=a)
    return {
        "kp_Nm_per_rad": float(kp),
        "kd_Nms_per_rad": float(kd),
        "activation_lag_s": float(lag),
        "delay_margin_s": float(margin.margin),
        "delay_margin_status": margin.status,
        "delay_margin_frequency_rad_s": float(margin.frequency),
    }


def analyse(
    anatomy: AnatomyEngine,
    plane: str = "sagittal",
    activation=None,
    posture=None,
    joint_stiffness="none",
    check=False,
    reflex=None,
    time=None,
    loads=(),
) -> AnatomyResult:
    """Joint-by-joint and chain verdicts of a model at an activation, free and constrained.

    Parameters
    ----------
    anatomy : AnatomyEngine
        From :func:`spinectl.anatomy.load`.
    plane : str
        One of the mapping's planes.
    activation : float, array_like, dict, str, pathlib.Path or None
        Activations in [0, 1] (:func:`activations`); None (default): the model's own controls
        (:meth:`~spinectl.anatomy.contract.AnatomyEngine.default_controls`: an MJCF's keyframe 0, else 0;
        an ``.osim``'s controllers at t = 0, else each muscle's activation floor); a file: an
        OpenSim ``.sto`` with one column per muscle (:func:`spinectl.anatomy.recordings.anatomy_point`).
    posture : array_like, dict, str, pathlib.Path, optional
        The engine's form (MuJoCo: the full qpos; OpenSim: coordinate name -> value [rad]), or an OpenSim
        ``.mot``/``.sto`` file of every coordinate (:func:`spinectl.anatomy.recordings.anatomy_point`);
        default the model's reference posture.
    joint_stiffness : {"none", "mapped"} or float
        Intervertebral stiffness added at each chain joint [N m/rad].
    check : bool
        Also MuJoCo's own eigenvalues (:func:`~spinectl.anatomy.referee.mujoco_eigenvalues`) and its
        simulation along the leading mode (:func:`~spinectl.anatomy.referee.mujoco_growth_rate`); reference
        posture only.
    reflex : tuple, optional
        ``(kp, kd, lag)``: also the free chain's exact delay margin under that reflex (:func:`reflex_margin`).
    time : float, optional
        The frame read from the posture and activation files [s]; default each file's first.
    loads : sequence of BodyLoad, optional
        External loads in K and the torque offset (not with ``check``).

    Returns
    -------
    AnatomyResult
    """
    from .recordings import recorded_point

    point = recorded_point(anatomy, posture, activation, time)
    posture, activation = point.posture, point.activation
    a = activations(anatomy, activation)
    loads = analysed_loads(loads, check)
    free, con, lin = anatomy.chains(plane, posture, joint_stiffness, activations=a, loads=loads)
    added = anatomy.added_stiffness(joint_stiffness, free.n_joints)
    arms = lin.moment_arms[:, list(lin.dofs[: lin.n])]
    referee, rate = None, float("nan")
    if check:
        anatomy.require_referee()
        if posture is not None and not np.allclose(anatomy.posture(posture), anatomy.engine.model.qpos0):
            raise ParameterError("check", "compares at the model's reference posture only")
        referee = mujoco_eigenvalues(anatomy, free, a, added)
        values, vectors = np.linalg.eig(state_matrix(free, a))
        lead = int(np.argmax(values.real))
        if abs(values[lead].imag) == 0:
            rate = mujoco_growth_rate(anatomy, free, a, added, values[lead].real, vectors[: free.n_joints, lead].real)
    classes = anatomy.classes
    return AnatomyResult(
        model=model_identity(anatomy),
        plane=plane,
        muscles={c: tuple(m for m, k in zip(anatomy.muscles, classes, strict=True) if k == c) for c in CONTROL_CLASSES},
        activations=a,
        joint_stiffness_added=added,
        stiffness_source=anatomy.mapping.stiffness_source if np.any(added > 0) else "",
        free=verdict(free, a),
        constrained=verdict(con, a),
        certificate=global_certificate(anatomy, free, arms, a),
        mujoco_eigenvalues=referee,
        simulated_rate=rate,
        reflex=None if reflex is None else reflex_margin(free, a, *reflex),
        control_unit=anatomy.control_unit,
        activation_source=point.activation_source or _activation_source(anatomy, activation),
        rhythm_size=anatomy.rhythm_size(plane, posture),
        joint_slopes=_slopes_shown(anatomy, plane, posture),
        rhythm_left_out=anatomy.rhythm(plane, posture)[0].left_out,
        devices=tuple(getattr(anatomy.engine, "devices", ())),
        posture_source=point.posture_source or REFERENCE_POSTURE,
        loads=loads,
        net_torque=_net_torque(anatomy, lin, a, plane, posture, free.joints),
        rhythm_turns=_rhythm_turns(anatomy, plane, posture) if anatomy.rhythm_size(plane, posture) else (),
    )


def _net_torque(anatomy: AnatomyEngine, lin, a, plane: str, posture, joints) -> NetTorque:
    """The net torque per chain joint and, where the model has a rhythm, on its coordinates (the optimum's rows)."""
    rhythm = None
    if anatomy.rhythm_size(plane, posture):
        rhythm = anatomy.equilibrium_rows(lin, plane, posture, "rhythm")[1:]
    return net_torque(lin, a, anatomy.control_bounds(), joints, rhythm)


def _rhythm_turns(anatomy: AnatomyEngine, plane: str, posture) -> tuple:
    """Per independent coordinate of the rhythm, the chain's joints' rotation summed per its radian [rad/rad]."""
    rhy, _ = anatomy.joint_rhythm(plane, posture)
    n = len(anatomy.plane_joints(plane))
    return tuple(float(t) for t in np.asarray(rhy.transform)[:n].sum(axis=0))


def _slopes_shown(anatomy: AnatomyEngine, plane: str, posture) -> np.ndarray | None:
    """The chain joints' rotation per unit of their own coordinates, where that is not 1 (else None)."""
    slopes = anatomy.joint_slopes(plane, posture)
    return None if slopes.is_identity() else slopes.slopes


def _activation_source(anatomy: AnatomyEngine, activation) -> str:
    """Where the analysed activations come from: given, or the model's own default controls."""
    return "given" if activation is not None else anatomy.default_controls_source()
