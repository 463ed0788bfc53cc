"""The atlas's draws: Saltelli's design on the priors, and every draw solved (the sweep's outputs on its coefficients).

Draws of the priors (:mod:`spinectl.landscape.priors`) on a scrambled Sobol' sequence in Saltelli's
design (SALib), and for each draw the joint-by-joint optimum (the fast path of
:mod:`spinectl.optimise.active_set`), the exact delay margin at the draw's co-contraction and, with
``chain``, the chain's least local stiffness at that co-contraction, every output computed by
:mod:`spinectl.landscape.columns`. The fast path solves a chunk of draws as one stacked problem, the
body's terms mixed exactly from four models (:data:`FAST`); the per-draw path, one model per draw, is
its reference. What is made of the outputs (verdicts, Sobol' indices, the files) is
:mod:`spinectl.landscape.atlas`.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from .._optional import require_module
from ..errors import SpinectlError
from ..model import chain
from ..model.checks import arithmetic_guard, checked_coefficients
from ..model.clinical import lordosis_angle, lordosis_from_angle
from ..model.config import set_parameters
from ..model.params import Model
from ..optimise import active_set
from ..optimise.problem import problem_data
from . import columns
from .priors import AtlasSpec

INSTALL_HINT = "pip install 'spinectl[atlas]' (SALib)"

FAST = (
    "body.mass",
    "body.mass_height",
    "passive.stiffness",
    "reflex.delay",
    "reflex.activation_time_constant",
    "reflex.activation",
)
"""Fields that the fast path varies within one stacked problem (docs/atlas.md, "What each draw solves").

Every term of the segment and chain mechanics that holds the body's mass m or its height y_m is
A + m q(y_m), q a quadratic in y_m (gravity's torque m g x_k and stiffness m g (y_m - y_k), the
inertia m ((y_m - y_k)^2 + x_k^2 + rho^2), K_pas = K theta_k in the paper's convention; A the
levels' weight in the chain), so four models (two masses, three heights) give it exactly; K enters as
-K_pas, linear in K; the delay margin does not depend on the delay; the activation scales the
chosen PCSA and T_a enters the reflex loops, whose margins are computed per segment anyway, so
both are arrays over the stack."""


class AtlasUnavailable(SpinectlError, ImportError):
    """SALib, the atlas's sampling and sensitivity analysis, is not installed."""


def require_salib():
    """Import and return :mod:`SALib`, or raise one line saying what to install.

    Returns
    -------
    module
        :mod:`SALib`.
    """
    return require_module("SALib", AtlasUnavailable, f"the atlas needs SALib: {INSTALL_HINT}")


def saltelli_unit(spec: AtlasSpec) -> np.ndarray:
    """Saltelli's design on the unit cube from SALib's scrambled Sobol' sequence, seeded.

    Parameters
    ----------
    spec : AtlasSpec
        Supplies ``samples`` N, ``seed`` and the D priors.

    Returns
    -------
    numpy.ndarray, shape (N (D + 2), D)
        Probabilities in (0, 1), rows in SALib's order (A, AB_1 ... AB_D, B per base sample).
    """
    require_salib()
    from SALib.sample import sobol as sobol_sample

    problem = unit_problem(len(spec.priors))
    u = sobol_sample.sample(problem, spec.samples, calc_second_order=False, scramble=True, seed=spec.seed)
    tiny = np.finfo(float).eps  # an open cube: an unbounded normal has no quantile at 0 or 1
    return np.clip(u, tiny, 1.0 - tiny)


def unit_problem(n: int) -> dict:
    """SALib's problem of ``n`` variables on the unit cube (the priors' quantiles map them).

    Parameters
    ----------
    n : int
        D, the number of priors.

    Returns
    -------
    dict
    """
    return {"num_vars": n, "names": [f"x{i}" for i in range(n)], "bounds": [[0.0, 1.0]] * n}


def draw(spec: AtlasSpec, unit: np.ndarray) -> dict[str, np.ndarray]:
    """The parameters of every draw from probabilities, through each prior's truncated quantiles.

    Parameters
    ----------
    spec : AtlasSpec
    unit : numpy.ndarray, shape (n, D)
        Probabilities, one column per prior.

    Returns
    -------
    dict of str to numpy.ndarray
        Each prior's parameter (its unit), and ``eccentricity_m``, ``lordosis_m`` and
        ``lordosis_angle_deg`` of every draw, shape (n,).
    """
    values = {p.parameter: p.ppf(unit[:, i]) for i, p in enumerate(spec.priors)}
    n = unit.shape[0]
    values.setdefault("eccentricity_m", np.full(n, spec.eccentricity))
    if "lordosis_angle_deg" in values:
        values["lordosis_m"] = lordosis_from_angle(values["lordosis_angle_deg"], spec.model)
    values.setdefault("lordosis_m", np.full(n, spec.lordosis))
    values.setdefault("lordosis_angle_deg", lordosis_angle(values["lordosis_m"], spec.model))
    return values


def evaluate(spec: AtlasSpec, values: dict, *, method: str = "auto", update=None) -> dict[str, np.ndarray]:
    """The outputs at every draw, chunk by chunk.

    Parameters
    ----------
    spec : AtlasSpec
    values : dict of str to numpy.ndarray
        :func:`draw`'s answer for n draws.
    method : {'auto', 'fast', 'per-draw'}
        'fast': one stacked problem per chunk with the fields of :data:`FAST` varied inside it;
        'per-draw': one model per draw (:func:`spinectl.model.config.set_parameters`), the reference;
        'auto': 'fast' unless a prior varies another field.
    update : callable, optional
        Called with the number of draws solved after each chunk.

    Returns
    -------
    dict of str to numpy.ndarray
        ``min_pcsa_cm2``, ``counter_torque_norm_Nm``, ``status``, ``spine_delay_margin_s`` (the sweep's variables,
        :data:`SEGMENT_OUTPUTS`), ``counter_torque_max_Nm``, ``delay_s`` and with ``chain``
        ``cocontraction_local_stiffness_total_Nm_per_rad``, ``cocontraction_local_stiffness_max_Nm_per_rad`` and
        ``local_stiffness_limit_Nm_per_rad`` (:data:`spinectl.landscape.schema.DRAW_VARIABLES`), shape (n,); NaN
        where infeasible. Each computed by :mod:`spinectl.landscape.columns`.
    """
    fields = [name for name in values if "." in name]
    if method == "auto":
        method = "fast" if set(fields) <= set(FAST) else "per-draw"
    solve = _fast_chunk if method == "fast" else _per_draw_chunk
    n = values["eccentricity_m"].size
    parts = []
    for start in range(0, n, spec.chunk_size):
        part = {k: v[start : start + spec.chunk_size] for k, v in values.items()}
        parts.append(solve(spec, part))
        if update:
            update(len(part["eccentricity_m"]))
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _field(spec: AtlasSpec, part: dict, name: str) -> np.ndarray:
    """A dotted field's value at every draw of the chunk: the drawn one, else the base model's."""
    n = part["eccentricity_m"].size
    section, key = name.split(".")
    return np.asarray(part.get(name, np.full(n, getattr(getattr(spec.model, section), key))), float)


def _body_bases(spec: AtlasSpec, mass: np.ndarray, height: np.ndarray):
    """Models at which the body's terms are evaluated, and every draw's weights on them (exact for A + m q(y)).

    The bases are the base mass m0 at the heights y_j (:func:`_heights`), then m0 / 2 at y_0, each
    with K = 1 so that K_pas is per unit K. With t = m / m0 and L_j(y) the Lagrange polynomials of
    the heights, A + m q(y) = (1 - t) A + t sum_j L_j(y) (A + m0 q(y_j)) and
    A = 2 f(m0 / 2, y_0) - f(m0, y_0): the weights t L_j, with 1 - t taken off the first and
    2 (1 - t) on the last. Within the heights the L_j lie in [-1/8, 1], so the mix loses no precision.

    Returns
    -------
    bases : tuple of Model
    weights : numpy.ndarray, shape (n, len(bases))
        Sum to 1 in every row.
    """
    heights = _heights(spec, height)
    t = mass / spec.model.body.mass
    weights = []
    for j, node in enumerate(heights):
        # L_j(y): 1 at height j, 0 at the others; a quadratic q(y) is sum_j L_j(y) q(y_j) exactly (3 nodes)
        lagrange = np.ones_like(height)
        for i, other in enumerate(heights):
            if i != j:
                lagrange = lagrange * (height - other) / (node - other)
        weights.append(t * lagrange)
    # the mass-free part A, (1 - t) of it: A = 2 f(m0 / 2, y_0) - f(m0, y_0), on the last base and the first
    weights[0] = weights[0] - (1.0 - t)
    weights.append(2.0 * (1.0 - t))
    return _bases(spec.model, heights), np.stack(weights, axis=-1)


def _heights(spec: AtlasSpec, height: np.ndarray) -> tuple[float, ...]:
    """The bases' heights: the prior's extreme draws and their middle (one set for every chunk), else the chunk's."""
    prior = next((p for p in spec.priors if p.parameter == "body.mass_height"), None)
    tiny = np.finfo(float).eps  # saltelli_unit's open cube: these quantiles bound every draw (and are valid heights)
    low, high = (float(y) for y in prior.ppf([tiny, 1.0 - tiny])) if prior else (height.min(), height.max())
    return (float(low),) if low == high else (float(low), (low + high) / 2, float(high))


@functools.lru_cache(maxsize=4)
def _bases(model: Model, heights: tuple[float, ...]) -> tuple[Model, ...]:
    """The base models of :func:`_body_bases`, built once per atlas (set_parameters validates, which costs ms)."""
    m0, fixed = model.body.mass, {"passive.stiffness": 1.0}
    bases = [set_parameters(model, fixed | {"body.mass": m0, "body.mass_height": y}) for y in heights]
    return (*bases, set_parameters(model, fixed | {"body.mass": m0 / 2, "body.mass_height": heights[0]}))


def _mixed(found: list, weights: np.ndarray, k: np.ndarray):
    """The first of ``found`` with its body's terms the weighted sums over all, and K_pas times K."""

    def mix(name):
        arrays = [getattr(c, name) for c in found]
        # every term is affine in the bases' values (A + m q(y)), so the draw's term is their weighted sum
        w = weights.reshape(weights.shape[:1] + (1,) * (arrays[0].ndim - 1) + weights.shape[1:])
        return sum(w[..., j] * a for j, a in enumerate(arrays))

    mixed = {f.name: mix(f.name) for f in dataclasses.fields(found[0]) if f.name in _BODY_TERMS}
    mixed["passive_stiffness"] = mixed["passive_stiffness"] * k[:, None]  # (n, n_cor) in both kinds of coefficients
    return dataclasses.replace(found[0], **mixed)


_REFLEX_TERMS = ("delay", "activation", "activation_time_constant")
"""The fields of the reflex that the fast path takes per draw: tau, the activation and T_a."""

_BODY_TERMS = ("gravity_torque", "gravity_stiffness", "inertia", "passive_stiffness")
"""The fields of the segment and chain coefficients that hold the body's mass or height, or K."""


def _fast_chunk(spec: AtlasSpec, part: dict) -> dict[str, np.ndarray]:
    """One chunk in one stacked problem: the body's terms mixed from four models (:func:`_body_bases`), exactly."""
    model = spec.model
    e, lam = part["eccentricity_m"], part["lordosis_m"]
    bases, weights = _body_bases(spec, _field(spec, part, "body.mass"), _field(spec, part, "body.mass_height"))
    k = _field(spec, part, "passive.stiffness")
    coeffs = _mixed([checked_coefficients(b, e, lam) for b in bases], weights, k)
    result = active_set.solve_block(problem_data(model, coeffs), model.optimisation.ct_tolerance)
    delay, activation, lag = (_field(spec, part, f"reflex.{name}") for name in _REFLEX_TERMS)
    out = _segment_outputs(model, e, lam, coeffs, result, delay, activation, lag)
    if spec.chain:
        with arithmetic_guard(e, lam):
            found = [chain.chain_coefficients(b, e, lam) for b in bases]
        out |= _chain_outputs(spec, model, e, lam, _mixed(found, weights, k), result.pcsa, activation)
    return out


def _per_draw_chunk(spec: AtlasSpec, part: dict) -> dict[str, np.ndarray]:
    """One chunk, one model per draw: the reference for the fast path, and the path for any other field."""
    fields = [name for name in part if "." in name]
    rows = []
    for i in range(part["eccentricity_m"].size):
        model = set_parameters(spec.model, {f: float(part[f][i]) for f in fields})
        e, lam = part["eccentricity_m"][i : i + 1], part["lordosis_m"][i : i + 1]
        coeffs = checked_coefficients(model, e, lam)
        result = active_set.solve_block(problem_data(model, coeffs), model.optimisation.ct_tolerance)
        row = _segment_outputs(model, e, lam, coeffs, result, np.array([model.reflex.delay]))
        if spec.chain:
            with arithmetic_guard(e, lam):
                found = chain.chain_coefficients(model, e, lam)
            row |= _chain_outputs(spec, model, e, lam, found, result.pcsa)
        rows.append(row)
    return {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}


SEGMENT_OUTPUTS = ("min_pcsa_cm2", "counter_torque_norm_Nm", "status", "spine_delay_margin_s")
"""The landscape's variables (:data:`spinectl.landscape.schema.VARIABLES`) that each draw keeps."""


def _segment_outputs(model, e, lam, coeffs, result, delay, activation=None, lag=None) -> dict[str, np.ndarray]:
    """The joint-by-joint outputs of a block, as the sweep computes them (:mod:`spinectl.landscape.columns`).

    ``activation`` and ``lag`` (T_a [s]), one per row, in place of the model's reflex; None: the model's.
    """
    found = columns.segment_columns(model, e, lam, coeffs, result, activation, lag)
    out = {name: found[name] for name in SEGMENT_OUTPUTS}
    out["status"] = out["status"].astype(str)  # the chunk files hold no Python objects (np.load without pickle)
    return out | columns.counter_torque_max_columns(result) | columns.delay_columns(delay)


def _chain_outputs(spec: AtlasSpec, model, e, lam, coefficients, pcsa, activation=None) -> dict[str, np.ndarray]:
    """The chain's least local stiffness at the draw's co-contraction (problem (a), docs/chain.md); its limit.

    With the global muscles at ``reflex.activation`` (``activation`` per row, else the model's) times the minimum
    PCSA: the co-contraction the draw holds, which its delay margin also uses, so that the local muscles supply what
    that activation leaves (:func:`spinectl.landscape.columns.cocontraction_local_stiffness_columns`).
    """
    out = columns.cocontraction_local_stiffness_columns(model, e, lam, coefficients, pcsa, activation)
    return out | columns.local_stiffness_limit_columns(model, spec.local_pcsa_limit, pcsa.shape[0])
