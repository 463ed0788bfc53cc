"""The operating point: the single input of every analysis of the paper's chain (docs/chain.md, "The operating point").

An :class:`OperatingPoint` is the model, the posture (E, Lambda), the global PCSA of each muscle, the
local stiffness added at each joint and the external loads held (:mod:`spinectl.model.loads`), validated once
on construction. :func:`chain_at` builds from it the one
:class:`~spinectl.model.linear_chain.LinearChain` that every analysis takes (the chain's modes, its verdict
under the reflex, its least local stiffness, its delay margins, the designs): M, K and D at that point, on
:func:`spinectl.model.chain.linear_chain`. A new analysis is a function of that chain (CONTRIBUTING.md,
"Extension points").

An activation (a fraction of the minimum stabilising PCSA) needs the optimiser, a later layer: it becomes
the point's PCSA there (:func:`spinectl.optimise.stabilising.minimum_stabilising_pcsa`,
:func:`spinectl.reflex.margins.operating_point`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._validate import real, show
from ..errors import ParameterError
from . import geometry
from .chain import chain_coefficients, linear_chain
from .checks import arithmetic_guard, expand_pcsa, validate_position
from .linear_chain import LinearChain
from .loads import load_stiffness, loads_text, point_loads, upright_load_torque
from .params import Model


@dataclass(frozen=True, eq=False)  # eq=False: arrays have no single truth value; a point is compared by its chain
class OperatingPoint:
    """The paper's model at one posture and one global activation, with local stiffness added.

    Validated on construction: a bad field raises one :class:`~spinectl.errors.ParameterError` naming it.

    Attributes
    ----------
    model : Model
        The model (its identity: :func:`spinectl.model.source.header`).
    eccentricity, lordosis : float
        E and Lambda [m], inside ``geometry.eccentricity_range`` and ``geometry.lordosis_range``.
    pcsa : numpy.ndarray, shape (n_muscles,)
        Global PCSA of each muscle [m^2]; given per pair (n values, both sides) or per muscle
        (:func:`~spinectl.model.checks.expand_pcsa`), kept per muscle, read-only.
    local_stiffness : numpy.ndarray, shape (n_cor,)
        Stiffness k_j >= 0 added at each joint by the local muscles [N m/rad], with the damping of
        their force-velocity slope (:func:`spinectl.model.chain.local_damping_per_stiffness`); a
        number is the same at every joint. Default 0.
    slip_check : bool
        True (the default): a PCSA above :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA` is refused
        as cm^2 typed where m^2 are meant. False: spinectl computed it, or the caller checked its unit.
    loads : tuple of PointLoad
        External forces held at the point mass (:class:`spinectl.model.loads.PointLoad`, or (F_x, F_y) [N]
        pairs, fixed in the ground); default none. They enter the chain's K (:func:`chain_at`) and the
        torque to be held (:func:`load_torque_at`).
    """

    model: Model
    eccentricity: float
    lordosis: float
    pcsa: np.ndarray
    local_stiffness: np.ndarray = 0.0
    slip_check: bool = True
    loads: tuple = ()

    def __post_init__(self):
        if not isinstance(self.model, Model):
            raise ParameterError("model", f"must be a spinectl Model (got {show(self.model)})")
        e, lam = real("E", self.eccentricity), real("Lambda", self.lordosis)
        validate_position(self.model, e, lam)
        pcsa = expand_pcsa(self.model, self.pcsa, given=self.slip_check)
        if pcsa.ndim != 1:
            raise ParameterError("pcsa", f"must be one vector (got shape {pcsa.shape})")
        object.__setattr__(self, "eccentricity", e)
        object.__setattr__(self, "lordosis", lam)
        object.__setattr__(self, "pcsa", _frozen(pcsa))
        object.__setattr__(self, "local_stiffness", _frozen(_local_stiffness(self.model, self.local_stiffness)))
        object.__setattr__(self, "loads", point_loads(self.loads))


def _local_stiffness(model: Model, value) -> np.ndarray:
    """k [N m/rad] per joint: a number or one value per joint, each finite and >= 0."""
    n = len(model.geometry.cor_names)
    try:
        k = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("local_stiffness", f"must be numbers [N m/rad] (got {show(value)})") from None
    if k.ndim > 1 or (k.ndim == 1 and k.shape != (n,)):
        raise ParameterError("local_stiffness", f"must be one number or {n} (one per joint) (got shape {k.shape})")
    if not np.all(np.isfinite(k)) or np.any(k < 0):
        raise ParameterError("local_stiffness", f"must be finite and >= 0 [N m/rad] (got {show(value)})")
    return np.broadcast_to(k, (n,)) + 0.0  # a copy; + 0.0: no signed zero


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.array(array, float)
    array.setflags(write=False)
    return array


def chain_at(point: OperatingPoint) -> LinearChain:
    """The chain at an operating point: the one :class:`~spinectl.model.linear_chain.LinearChain` every analysis takes.

    :func:`spinectl.model.chain.linear_chain` (its joints, M, c_loc and source) with every control fixed at the
    point's PCSA and its local stiffness: no controls, K_0 = K(A) - diag(k) and D_0 = D(A) - c_loc diag(k);
    with loads, K_0 + K_load (:func:`spinectl.model.loads.load_stiffness`; docs/chain.md, "External loads").
    K(A) and D(A) sum the muscles per m^2 of each (:meth:`spinectl.model.chain.ChainCoefficients.stiffness`),
    as every analysis did before this function: equal to ``linear_chain(...).at(x, k)`` (x the decision
    variables in cm^2) to rounding, and to what they printed bit for bit.

    Parameters
    ----------
    point : OperatingPoint

    Returns
    -------
    LinearChain
        Without controls: ``stiffness_offset`` K [N m/rad], ``damping_offset`` D [N m s/rad], ``mass_matrix``
        M [kg m^2], ``local_damping_per_stiffness`` c_loc [s] (for local stiffness added later:
        :meth:`~spinectl.model.linear_chain.LinearChain.at`).

    Raises
    ------
    ModelError
        The arithmetic overflows at this point (:func:`~spinectl.model.checks.arithmetic_guard`).

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13.

    Examples
    --------
    At the paper's optimum every segment is stable alone, the chain with every CoR free is not
    (-sym(K) has a negative eigenvalue); 100 N m/rad of local stiffness at each joint makes it so:

    >>> import numpy as np
    >>> from spinectl import load_preset
    >>> from spinectl.model.operating_point import OperatingPoint, chain_at
    >>> from spinectl.optimise.active_set import solve_point
    >>> model = load_preset("wagner2012")
    >>> pcsa = solve_point(model, 0.03, 0.04).pcsa
    >>> def static_margin(chain):  # [N m/rad]
    ...     k = chain.stiffness_offset
    ...     return round(float(np.linalg.eigvalsh(-(k + k.T) / 2)[0]), 1)
    >>> static_margin(chain_at(OperatingPoint(model, 0.03, 0.04, pcsa, slip_check=False)))
    -56.2
    >>> static_margin(chain_at(OperatingPoint(model, 0.03, 0.04, pcsa, local_stiffness=100.0, slip_check=False)))
    43.8
    """
    model, e, lam = point.model, point.eccentricity, point.lordosis
    with arithmetic_guard(e, lam):
        coefficients = chain_coefficients(model, e, lam)
        free = linear_chain(model, e, lam, coefficients)
        stiffness = coefficients.stiffness(point.pcsa)
        if point.loads:  # without loads K stays bit for bit what it was
            stiffness = stiffness + load_stiffness(model, geometry.cor_positions(e, lam, model.geometry), point.loads)
        fixed = dataclasses.replace(
            free.at(np.zeros(free.n_controls)),
            stiffness_offset=stiffness,
            damping_offset=coefficients.damping(point.pcsa),
            source=free.source + loads_text(point.loads),
        )
        # k = 0 leaves K and D as they are (LinearChain.at would add zeros, turning a -0.0 into 0.0)
        return fixed.at((), point.local_stiffness) if np.any(point.local_stiffness) else fixed


def load_torque_at(point: OperatingPoint) -> np.ndarray:
    """The torque of the point's loads on every joint at its posture [N m], which the muscles must hold too.

    tau_j = (P - c_j) x F summed over the loads (:func:`spinectl.model.loads.upright_load_torque`): the
    load's part of the equilibrium, as gravity's is the counter torque's.

    Parameters
    ----------
    point : OperatingPoint

    Returns
    -------
    numpy.ndarray, shape (n_cor,)
        [N m], top to bottom; zeros without loads.
    """
    model = point.model
    cor = geometry.cor_positions(point.eccentricity, point.lordosis, model.geometry)
    return upright_load_torque(model, cor, point.loads)
