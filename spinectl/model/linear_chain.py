"""One description of a linearised chain of joints, whatever model produced it (docs/chain.md).

The chain analyses (the semidefinite programmes of :mod:`spinectl.optimise`, the
multivariable delay margins and python-control systems of :mod:`spinectl.reflex`) need
only the chain linearised about an equilibrium,

    M q'' = tau(q, q'),   tau ~ tau_0 + K(u) q + D(u) q',
    K(u) = K_0 + sum_i u_i K_i,   D(u) = D_0 + sum_i u_i D_i,

with q the joint angles [rad], u the controls (the muscles' PCSA of the paper's model
[cm^2], or the activations in [0, 1] of an anatomical model [1]), and the matrices per unit
of each control. The paper's model produces it with
:func:`spinectl.model.chain.chain_coefficients`; an anatomical model through its engine.
Sign convention of :mod:`spinectl.model.chain`: K = dtau/dq, so the chain is statically
stable when -K is positive definite (Bergmark 1989).

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError

CONTROL_CLASSES = ("global", "local", "between", "non-lumbar")
"""Muscle classes by the bodies a muscle attaches to (docs/chain.md): thorax and pelvis only;
any vertebra of the chain; a body in between that is neither (e.g. MyoTorso's abdomen); and a
muscle that crosses no chain joint (a leg or arm muscle: no moment arm on the chain)."""


@dataclass(frozen=True)
class LinearChain:
    """A chain of n joints and m controls, linearised about an equilibrium.

    Attributes
    ----------
    joints : tuple of str, length n
        Joint names, in the order of q (the paper's: top to bottom, ``L1L2`` ... ``L5S1``).
    controls : tuple of str, length m
        Control (muscle) names, in the order of u.
    control_class : tuple of str, length m
        Each control's class, one of :data:`CONTROL_CLASSES`.
    stiffness_per_control : numpy.ndarray, shape (n, n, m)
        K_i = dtau/dq per unit of control i [N m/rad per control unit]; symmetric in (n, n).
    damping_per_control : numpy.ndarray, shape (n, n, m)
        D_i = dtau/dq' per unit of control i [N m s/rad per control unit].
    stiffness_offset : numpy.ndarray, shape (n, n)
        K_0: gravity, passive tissue and joint springs [N m/rad].
    damping_offset : numpy.ndarray, shape (n, n)
        D_0 [N m s/rad].
    mass_matrix : numpy.ndarray, shape (n, n)
        M [kg m^2], symmetric positive definite.
    lower, upper : numpy.ndarray, shape (m,)
        Bounds of each control (``upper`` may be inf) [control unit].
    control_unit : str
        The unit of u: ``"cm^2"`` (PCSA) or ``"1"`` (activation).
    source : str
        What produced it (a preset and posture, a model file), for outputs.
    local_damping_per_stiffness : float
        c_loc [s]: the damping c_loc k_j that local joint stiffness k_j brings with it (the paper's
        local muscles, :func:`spinectl.model.chain.local_damping_per_stiffness`); 0: stiffness only.
    """

    joints: tuple
    controls: tuple
    control_class: tuple
    stiffness_per_control: np.ndarray
    damping_per_control: np.ndarray
    stiffness_offset: np.ndarray
    damping_offset: np.ndarray
    mass_matrix: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    control_unit: str = "1"
    source: str = field(default="", compare=False)
    local_damping_per_stiffness: float = 0.0

    def __post_init__(self):
        n, m = len(self.joints), len(self.controls)
        shapes = {
            "stiffness_per_control": (n, n, m),
            "damping_per_control": (n, n, m),
            "stiffness_offset": (n, n),
            "damping_offset": (n, n),
            "mass_matrix": (n, n),
            "lower": (m,),
            "upper": (m,),
        }
        for name, shape in shapes.items():
            value = np.asarray(getattr(self, name), float)
            if value.shape != shape:
                raise ParameterError(f"LinearChain.{name}", f"must have shape {shape} (got {value.shape})")
            if name != "upper" and not np.all(np.isfinite(value)):
                raise ParameterError(f"LinearChain.{name}", "must be finite")
            object.__setattr__(self, name, value)
        if len(self.control_class) != m or not set(self.control_class) <= set(CONTROL_CLASSES):
            raise ParameterError("LinearChain.control_class", f"must give one of {CONTROL_CLASSES} per control")
        c = float(self.local_damping_per_stiffness)
        if not (np.isfinite(c) and c >= 0):
            raise ParameterError("LinearChain.local_damping_per_stiffness", f"must be finite and >= 0 (got {c:g})")
        object.__setattr__(self, "local_damping_per_stiffness", c)
        if np.any(self.lower > self.upper):
            raise ParameterError("LinearChain.lower", "must not exceed upper")
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "controls", tuple(self.controls))
        object.__setattr__(self, "control_class", tuple(self.control_class))

    @property
    def n_joints(self) -> int:
        """n, the number of joints."""
        return len(self.joints)

    @property
    def n_controls(self) -> int:
        """m, the number of controls."""
        return len(self.controls)

    def stiffness(self, u, local_stiffness=0.0) -> np.ndarray:
        """K(u) - diag(k) [N m/rad]: K_0 + sum_i u_i K_i, less local joint stiffness k.

        Parameters
        ----------
        u : array_like, shape (m,)
            The controls [control unit].
        local_stiffness : array_like, shape (n,)
            k_j >= 0 added at each joint [N m/rad]; 0: none.

        Returns
        -------
        numpy.ndarray, shape (n, n)
            [N m/rad].
        """
        k = np.broadcast_to(np.asarray(local_stiffness, float), (self.n_joints,))
        return self.stiffness_offset + self.stiffness_per_control @ np.asarray(u, float) - np.diag(k)

    def damping(self, u, local_stiffness=0.0) -> np.ndarray:
        """D(u) - c_loc diag(k) [N m s/rad]: D_0 + sum_i u_i D_i, and the damping of local joint stiffness k.

        Parameters
        ----------
        u : array_like, shape (m,)
            The controls [control unit].
        local_stiffness : array_like, shape (n,)
            k_j >= 0 added at each joint [N m/rad], damped by c_loc k_j
            (``local_damping_per_stiffness``); 0: none.

        Returns
        -------
        numpy.ndarray, shape (n, n)
            [N m s/rad].
        """
        k = np.broadcast_to(np.asarray(local_stiffness, float), (self.n_joints,))
        d = self.damping_offset + self.damping_per_control @ np.asarray(u, float)
        return d - np.diag(self.local_damping_per_stiffness * k)

    def at(self, u, local_stiffness=0.0) -> LinearChain:
        """The chain with its controls fixed at ``u``: no controls, K_0 = K(u) - diag(k), D_0 = D(u) - c_loc diag(k).

        The linear system at one activation, which the reflex analyses take
        (:mod:`spinectl.reflex.mimo`, :mod:`spinectl.reflex.chain_system`).

        Parameters
        ----------
        u : array_like, shape (m,)
            The controls [control unit].
        local_stiffness : array_like, shape (n,)
            k_j >= 0 added at each joint [N m/rad], with its damping c_loc k_j; 0: none.

        Returns
        -------
        LinearChain
            With zero controls; ``stiffness(())`` and ``damping(())`` are the matrices at ``u``.
        """
        n = self.n_joints
        return LinearChain(
            joints=self.joints,
            controls=(),
            control_class=(),
            stiffness_per_control=np.zeros((n, n, 0)),
            damping_per_control=np.zeros((n, n, 0)),
            stiffness_offset=self.stiffness(u, local_stiffness),
            damping_offset=self.damping(u, local_stiffness),
            mass_matrix=self.mass_matrix,
            lower=np.zeros(0),
            upper=np.zeros(0),
            control_unit=self.control_unit,
            source=self.source,
            local_damping_per_stiffness=self.local_damping_per_stiffness,
        )

    def fix(self, values: dict) -> LinearChain:
        """The chain with some controls fixed: their u_i K_i and u_i D_i moved into K_0 and D_0.

        E.g. the global muscles held at an activation, the local ones left to a programme
        (:mod:`spinectl.optimise.coupled.sdp`); :meth:`at` fixes them all.

        Parameters
        ----------
        values : dict of str to float
            Control name -> its value [control unit].

        Returns
        -------
        LinearChain
            The other controls, in their order, with their bounds.

        Raises
        ------
        ParameterError
            A name that is no control of the chain.
        """
        unknown = sorted(set(values) - set(self.controls))
        if unknown:
            raise ParameterError("LinearChain.fix", f"names no control of the chain: {', '.join(unknown)}")
        fixed = np.array([c in values for c in self.controls], bool)
        u = np.array([float(values.get(c, 0.0)) for c in self.controls])
        keep = ~fixed
        return LinearChain(
            joints=self.joints,
            controls=tuple(np.array(self.controls, object)[keep]),
            control_class=tuple(np.array(self.control_class, object)[keep]),
            stiffness_per_control=self.stiffness_per_control[..., keep],
            damping_per_control=self.damping_per_control[..., keep],
            stiffness_offset=self.stiffness_offset + self.stiffness_per_control[..., fixed] @ u[fixed],
            damping_offset=self.damping_offset + self.damping_per_control[..., fixed] @ u[fixed],
            mass_matrix=self.mass_matrix,
            lower=self.lower[keep],
            upper=self.upper[keep],
            control_unit=self.control_unit,
            source=self.source,
            local_damping_per_stiffness=self.local_damping_per_stiffness,
        )

    def bound_rows(self) -> tuple[np.ndarray, np.ndarray]:
        """The bounds lower <= u <= upper as rows G u <= h (an infinite upper bound gives no row).

        Returns
        -------
        lhs : numpy.ndarray, shape (r, m)
            G [1].
        rhs : numpy.ndarray, shape (r,)
            h [control unit].
        """
        eye = np.eye(self.n_controls)
        finite = np.isfinite(self.upper)
        return np.concatenate([-eye, eye[finite]]), np.concatenate([-self.lower, self.upper[finite]])

    def select(self, classes) -> LinearChain:
        """The same chain with only the controls of ``classes``; the others held at 0.

        Parameters
        ----------
        classes : iterable of str
            Classes of :data:`CONTROL_CLASSES` to keep.

        Returns
        -------
        LinearChain
        """
        keep = np.array([c in set(classes) for c in self.control_class], bool)
        return LinearChain(
            joints=self.joints,
            controls=tuple(np.array(self.controls, object)[keep]),
            control_class=tuple(np.array(self.control_class, object)[keep]),
            stiffness_per_control=self.stiffness_per_control[..., keep],
            damping_per_control=self.damping_per_control[..., keep],
            stiffness_offset=self.stiffness_offset,
            damping_offset=self.damping_offset,
            mass_matrix=self.mass_matrix,
            lower=self.lower[keep],
            upper=self.upper[keep],
            control_unit=self.control_unit,
            source=self.source,
            local_damping_per_stiffness=self.local_damping_per_stiffness,
        )
