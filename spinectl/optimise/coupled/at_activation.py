"""The paper's chain at one (E, Lambda) and one global activation: ``spinectl stability --coupled`` (docs/chain.md).

Its matrices K, D and M, the static margin (the smallest eigenvalue of -K), the dynamic
eigenvalues with the global muscles alone and with the least local stiffness of problem (a)
(:func:`~spinectl.optimise.coupled.local.least_local_stiffness`) added.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..._validate import non_negative
from ...model import chain
from ...model.checks import arithmetic_guard, expand_pcsa
from ...model.linear_chain import LinearChain
from ...model.operating_point import OperatingPoint, chain_at, load_torque_at
from ...model.params import Model
from ...model.source import header, provenance
from ...model.stability import criterion, eigenvalue_text, self_stable
from ...units import m2_to_cm2
from ..stabilising import minimum_stabilising_pcsa
from .data import CoupledOptimum, coupled_data
from .local import least_local_stiffness


@dataclass(frozen=True)
class CoupledStability:
    """The coupled chain at one (E, Lambda) and one global activation: ``spinectl stability --coupled``.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    variable_names : tuple of str
        The decision variables: the pairs (paired activation) or the muscles (independent).
    pcsa : numpy.ndarray, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    chain : LinearChain
        The chain at this operating point (:func:`spinectl.model.operating_point.chain_at`): its joints
        (:attr:`segment_names`), K (:attr:`stiffness`), D (:attr:`damping`) and M (:attr:`mass`).
    gravity_stiffness : numpy.ndarray, shape (n_cor, n_cor)
        K_g [N m/rad].
    stiffness_per_variable : numpy.ndarray, shape (n_var, n_cor, n_cor)
        dK/dx of each decision variable [N m/rad per cm^2].
    local : CoupledOptimum
        The least local stiffness that makes the chain statically stable at this activation
        (:func:`least_local_stiffness`, problem (a)).
    margin : float
        Smallest eigenvalue of -K, global muscles only [N m/rad]; > 0 statically stable.
    eigenvalues : numpy.ndarray, shape (2 n_cor,), complex
        Of the state matrix [[0, I], [M^-1 K, M^-1 D]], global muscles only [1/s].
    local_eigenvalues : numpy.ndarray, shape (2 n_cor,), complex
        The same with the least local stiffness added, K - diag(k) [1/s]; NaN if (a) failed.
    loads : tuple of PointLoad
        The loads held at the point mass (:mod:`spinectl.model.loads`), in K; () none.
    load_torque : numpy.ndarray, shape (n_cor,), optional
        Their torque on each joint at the posture [N m] (:func:`~spinectl.model.operating_point.load_torque_at`).
    """

    eccentricity: float
    lordosis: float
    variable_names: tuple[str, ...]
    pcsa: np.ndarray
    chain: LinearChain
    gravity_stiffness: np.ndarray
    stiffness_per_variable: np.ndarray
    local: CoupledOptimum
    margin: float
    eigenvalues: np.ndarray
    local_eigenvalues: np.ndarray
    loads: tuple = ()
    load_torque: np.ndarray | None = None

    @property
    def linear_chain(self) -> LinearChain:
        """The chain at this activation (:attr:`chain`): the linear system the reflex analyses take.

        :func:`spinectl.reflex.chain_margins.chain_reflex_margins`,
        :func:`spinectl.reflex.gain_search.search_chain_gains`.
        """
        return self.chain

    @property
    def segment_names(self) -> tuple[str, ...]:
        """The joints, top to bottom."""
        return self.chain.joints

    @property
    def stiffness(self) -> np.ndarray:
        """K: global muscles, gravity and passive stiffness [N m/rad], shape (n_cor, n_cor)."""
        return self.chain.stiffness_offset

    @property
    def damping(self) -> np.ndarray:
        """D [N m s/rad], shape (n_cor, n_cor)."""
        return self.chain.damping_offset

    @property
    def mass(self) -> np.ndarray:
        """M [kg m^2] (:func:`spinectl.model.chain.mass_matrix`), shape (n_cor, n_cor)."""
        return self.chain.mass_matrix

    @property
    def self_stable(self) -> bool:
        """True if the chain is dynamically stable with the global muscles alone (every eigenvalue Re < 0)."""
        return bool(self_stable(self.eigenvalues))

    @property
    def stable_with_local(self) -> bool:
        """True if the chain is dynamically stable with the least local stiffness added."""
        return bool(self_stable(self.local_eigenvalues))

    def to_dict(self, model: Model, pcsa_source: str = "min_pcsa") -> dict:
        """The result as a JSON-ready dict: the document of ``spinectl stability --coupled --json``.

        Parameters
        ----------
        model : Model
            The model the result was computed with (muscle names, K and its convention).
        pcsa_source : {'given', 'min_pcsa', 'activation'}
            Where the PCSA came from (as in :meth:`spinectl.model.stability.StabilityResult.to_dict`);
            'activation': the reflex's activation times the minimum stabilising PCSA (:meth:`table`).

        Returns
        -------
        dict
            The model's :func:`~spinectl.model.source.provenance` (``preset``, ``config``, ``config_sha256``,
            ``overridden``, ``K_Nm_per_rad`` or ``K_per_s2``, ``K_convention``), ``E_m``, ``Lambda_m``,
            ``pcsa_source`` and
            ``coupled``: ``criterion`` (of its verdicts: the chain, all CoRs free,
            :func:`spinectl.model.stability.criterion`), ``segments``, ``decision_variables``,
            ``pcsa_cm2`` (muscle -> cm^2),
            ``stiffness_matrix_Nm_per_rad``, ``gravity_stiffness_matrix_Nm_per_rad``,
            ``stiffness_matrix_per_cm2`` (n_var x n_cor x n_cor, N m/rad per cm^2),
            ``damping_matrix_Nms_per_rad``, ``mass_matrix_kgm2``, ``local_stiffness_Nm_per_rad``
            (the least, per joint), ``local_stiffness_total_Nm_per_rad``, ``local_pcsa_cm2``,
            ``local_status``, ``margin_Nm_per_rad`` (global muscles only), ``eigenvalues`` as
            [real, imaginary] pairs [1/s] and ``self_stable`` (global muscles only), and
            ``eigenvalues_with_local`` and ``stable_with_local`` (with the least local stiffness).
        """
        local = self.local
        return provenance(model) | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "pcsa_source": pcsa_source,
            "coupled": {
                "criterion": criterion("chain", len(self.segment_names)),
                "segments": list(self.segment_names),
                "decision_variables": list(self.variable_names),
                "pcsa_cm2": dict(zip(model.muscle_names, m2_to_cm2(self.pcsa).tolist(), strict=True)),
                "stiffness_matrix_Nm_per_rad": self.stiffness.tolist(),
                "gravity_stiffness_matrix_Nm_per_rad": self.gravity_stiffness.tolist(),
                "stiffness_matrix_per_cm2": self.stiffness_per_variable.tolist(),
                "damping_matrix_Nms_per_rad": self.damping.tolist(),
                "mass_matrix_kgm2": self.mass.tolist(),
                "local_stiffness_Nm_per_rad": local.local_stiffness.tolist(),
                "local_stiffness_total_Nm_per_rad": float(np.sum(local.local_stiffness)),
                "local_pcsa_cm2": m2_to_cm2(local.local_pcsa).tolist(),
                "local_status": local.status,
                "margin_Nm_per_rad": self.margin,
                "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues],
                "self_stable": self.self_stable,
                "eigenvalues_with_local": [[float(z.real), float(z.imag)] for z in self.local_eigenvalues],
                "stable_with_local": self.stable_with_local,
                **self._loads_dict(),
            },
        }

    def _loads_dict(self) -> dict:
        """The loads applied and their torque [N m] (in K): the operating point's identity; empty without."""
        if not self.loads:
            return {}
        return {
            "loads": [load.to_dict() for load in self.loads],
            "load_torque_Nm": dict(zip(self.segment_names, np.asarray(self.load_torque).tolist(), strict=True)),
        }

    def table(self, model: Model, pcsa_source: str = "min_pcsa", activation: float = 1.0) -> str:
        """The result as readable text: the matrices row by row, then the verdicts.

        Parameters
        ----------
        model : Model
            The model the result was computed with.
        pcsa_source : {'given', 'min_pcsa', 'activation'}
            Where the PCSA came from: given, the minimum stabilising PCSA per segment, or
            ``activation`` times it (the reflex's operating point, ``spinectl margins --coupled``).
        activation : float
            The fraction of the minimum stabilising PCSA [1] the PCSA line names with 'activation'.

        Returns
        -------
        str
            The text ``spinectl stability --coupled`` prints (no final newline); each verdict line
            starts with its criterion, the chain's (:func:`spinectl.model.stability.criterion`).
        """
        pcsa = m2_to_cm2(self.pcsa)
        names = self.segment_names
        source = {
            "given": "",
            "min_pcsa": " (minimum stabilising per segment)",
            "activation": f" ({activation:g} x the minimum stabilising per segment, the reflex's activation)",
        }[pcsa_source]
        lines = [
            header(model),
            f"Coupled chain at E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            f"PCSA [cm^2]{source}: "
            + ", ".join(f"{n} {p:.2f}" for n, p in zip(model.muscle_names, pcsa, strict=True))
            + f"  (total {pcsa.sum():.2f})",
        ]
        for load in self.loads:  # the operating point's identity: K below includes them
            lines.append(f"load (in K): {load.text()}")
        if self.loads:
            lines.append(
                "load torque on each joint [N m]: "
                + ", ".join(f"{n} {t:.2f}" for n, t in zip(self.segment_names, self.load_torque, strict=True))
            )
        for title, matrix, fmt in (
            (
                "stiffness matrix K_chain = dtau/dq [N m/rad]: global muscles, gravity and the passive stiffness "
                "(the header's K, per joint, on the diagonal); eq. 1's sign: -K_chain > 0 restores",
                self.stiffness,
                "10.3f",
            ),
            ("damping D [N m s/rad]: eq. 1's sign: D < 0 damps (theta phi'' = S phi + D phi')", self.damping, "10.4f"),
            ("mass M [kg m^2]", self.mass, "10.4f"),
        ):
            lines += ["", title, " " * 8 + "".join(f"{n:>10}" for n in names)]
            lines += [f"{n:8}" + "".join(f"{v:{fmt}}" for v in row) for n, row in zip(names, matrix, strict=True)]
        local = self.local.local_stiffness
        name = criterion("chain", len(names))
        lines += [
            "",
            f"{name}: static margin (smallest eigenvalue of -K_chain) = {self.margin:.3f} N m/rad "
            f"({'stable' if self.margin > 0 else 'UNSTABLE'})",
            "eigenvalues [1/s]: " + ", ".join(eigenvalue_text(z) for z in self.eigenvalues),
            f"{name}: global muscles alone, no reflex: "
            + (
                "eigenvalues undefined, the mass matrix is singular (levels.mass = 0)"
                if np.isnan(self.eigenvalues).any()
                else f"{'dynamically stable' if self.self_stable else 'NOT stable'} "
                f"({int(np.sum(self.eigenvalues.real >= 0))} of {self.eigenvalues.size} eigenvalues with Re >= 0)"
            ),
            f"{name}: least local stiffness added to the diagonal of -K_chain [N m/rad] (beside the passive K): "
            + ", ".join(f"{n} {k:.2f}" for n, k in zip(names, local, strict=True))
            + f"  (total {np.sum(local):.2f}; local PCSA {m2_to_cm2(self.local.total_local_pcsa):.2f} cm^2; "
            f"{self.local.status}); with it: {'dynamically stable' if self.stable_with_local else 'NOT stable'}, "
            f"slowest eigenvalue {eigenvalue_text(self.local_eigenvalues[0])} 1/s",
        ]
        return "\n".join(lines)


def point_at_activation(
    model: Model, eccentricity: float, lordosis: float, activation: float = 1.0, local_stiffness=0.0
) -> OperatingPoint:
    """The operating point at a fraction of the minimum stabilising PCSA: activation x A* (docs/chain.md).

    The activation becomes the point's PCSA here, in the optimiser's layer: A* is
    :func:`~spinectl.optimise.stabilising.minimum_stabilising_pcsa` (the fast path), computed, so of any size.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    activation : float
        The fraction of A* [1], >= 0; 1 (the default): A* itself.
    local_stiffness : float or array_like, shape (n_cor,)
        k_j >= 0 added at each joint [N m/rad]; 0 (the default): none.

    Returns
    -------
    OperatingPoint
        PCSA activation x A* [m^2].

    Raises
    ------
    ParameterError
        ``activation`` negative or not a number; a field of the point out of range.
    ModelError
        No activation within the bounds stabilises every segment (no A*), or the model cannot be evaluated there.
    """
    activation = non_negative("activation", activation)
    pcsa = minimum_stabilising_pcsa(model, eccentricity, lordosis)
    return OperatingPoint(model, eccentricity, lordosis, activation * pcsa, local_stiffness, slip_check=False)


def coupled_stability_at(
    model: Model, eccentricity: float, lordosis: float, pcsa=None, *, slip_check: bool = True, loads=()
) -> CoupledStability:
    """The coupled chain at a global activation, by default the per-segment optimum.

    The chain at that operating point (:func:`spinectl.model.operating_point.chain_at`), the static margin
    (:func:`spinectl.model.chain.coupled_margin`), the dynamic eigenvalues
    (:func:`spinectl.model.chain.dynamic_eigenvalues`) and the least local stiffness
    (:func:`least_local_stiffness`); docs/chain.md.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, optional
        Global PCSA [m^2], per pair or per muscle; default the minimum stabilising PCSA of
        :func:`spinectl.optimise.reference.solve_point`
        (:func:`~spinectl.optimise.stabilising.minimum_stabilising_pcsa`).
    slip_check : bool
        True (the default): a ``pcsa`` above :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA` is refused
        as cm^2 typed where m^2 are meant. False: the caller has checked its unit (``--pcsa``, in cm^2), and
        it is analysed whatever its size, as a computed optimum is (docs/robustness.md, "Model evaluation").
    loads : sequence of PointLoad or of (F_x, F_y) [N], optional
        Ground-fixed loads held at the point mass (:mod:`spinectl.model.loads`): in K, in the least local
        stiffness's programme and in the torque reported; the default PCSA stays the unloaded optimum's.

    Returns
    -------
    CoupledStability

    Raises
    ------
    ModelError
        ``pcsa`` not given and no activation stabilises every segment; or the model cannot be
        evaluated there.
    ParameterError
        E, Lambda or ``pcsa`` out of range.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    e, lam = float(eccentricity), float(lordosis)
    given = pcsa is not None and slip_check  # a computed optimum, or a checked unit: any size is an answer
    point = (
        point_at_activation(model, e, lam)
        if pcsa is None  # the PCSA's errors before the position's, as ever:
        else OperatingPoint(model, e, lam, expand_pcsa(model, pcsa, given=given), slip_check=given)
    )
    if loads:
        point = dataclasses.replace(point, loads=loads)  # validated again, the loads with the rest
    pcsa, at_point, data = point.pcsa, chain_at(point), coupled_data(model, e, lam, point.loads)
    local = least_local_stiffness(model, e, lam, pcsa, given=given, loads=point.loads)  # the SDP, outside numpy's guard
    with arithmetic_guard(e, lam):
        mass, stiffness, damping = at_point.mass_matrix, at_point.stiffness_offset, at_point.damping_offset
        eigenvalues = chain.dynamic_eigenvalues(mass, stiffness, damping)
        k = local.local_stiffness  # its stiffness and the damping of its force-velocity slope; NaN if (a) failed
        with_local = chain.dynamic_eigenvalues(mass, at_point.stiffness((), k), at_point.damping((), k))
    return CoupledStability(
        eccentricity=e,
        lordosis=lam,
        variable_names=data.chain.controls,
        pcsa=pcsa,
        chain=at_point,
        gravity_stiffness=data.coefficients.gravity_stiffness,
        stiffness_per_variable=np.moveaxis(data.chain.stiffness_per_control, -1, 0),
        local=local,
        margin=float(chain.coupled_margin(stiffness)),
        eigenvalues=eigenvalues,
        local_eigenvalues=with_local,
        loads=point.loads,
        load_torque=load_torque_at(point),
    )
