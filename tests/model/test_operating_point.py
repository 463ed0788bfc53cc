"""The operating point and its chain (model/operating_point.py; docs/chain.md, "The operating point").

The expected matrices are recomputed here from model/chain.py's documented formulas, the way each of the four
former assemblies wrote them (stability.chain_modes, reflex.chain_verdict, reflex.design's chain_matrices,
optimise.coupled.coupled_stability_at): K = chain_coefficients(...).stiffness(A), D = .damping(A),
M = mass_matrix(model, cor_positions(E, Lambda)), with local stiffness K - diag(k) and D - c_loc diag(k).
The command outputs before and after the change were compared bit for bit outside the suite (the report).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl import load_preset
from spinectl.errors import ParameterError
from spinectl.model import chain, geometry
from spinectl.model.linear_chain import LinearChain
from spinectl.model.operating_point import OperatingPoint, chain_at
from spinectl.model.stability import chain_modes
from spinectl.optimise.coupled import coupled_stability_at, least_local_stiffness_stacked, point_at_activation
from spinectl.optimise.stabilising import minimum_stabilising_pcsa
from spinectl.reflex import design as dz
from spinectl.reflex.chain_verdict import chain_verdict
from spinectl.reflex.gains import resolve_chain_gains
from spinectl.reflex.margins import operating_point
from spinectl.reflex.mimo import chain_delay_margin

E, LAMBDA = 0.03, 0.04


@pytest.fixture(scope="module")
def model():
    return load_preset("wagner2012")


def _formula(model, pcsa):
    """M, K(A), D(A) as the four former paths assembled them (model/chain.py's formulas)."""
    coefficients = chain.chain_coefficients(model, E, LAMBDA)
    mass = chain.mass_matrix(model, geometry.cor_positions(E, LAMBDA, model.geometry))
    return mass, coefficients.stiffness(pcsa), coefficients.damping(pcsa)


# --- validation: one ParameterError naming the field --------------------------------------------


@pytest.mark.parametrize(
    ("fields", "field", "message"),
    [
        ({"pcsa": [1e-3] * 4}, "pcsa", "must have 3 values (one per pair) or 6 (one per muscle)"),
        ({"pcsa": [[1e-3] * 3] * 2}, "pcsa", "must be one vector"),
        ({"pcsa": [1e-3, -1e-3, 1e-3]}, "pcsa", "must be finite and >= 0"),
        ({"local_stiffness": -1.0}, "local_stiffness", "must be finite and >= 0"),
        ({"local_stiffness": [0.0, 1.0, np.nan, 0.0, 0.0]}, "local_stiffness", "must be finite and >= 0"),
        ({"local_stiffness": [1.0, 2.0]}, "local_stiffness", "must be one number or 5 (one per joint)"),
        ({"local_stiffness": "stiff"}, "local_stiffness", "must be numbers"),
        ({"eccentricity": 0.5}, "E", "the modelled range"),
        ({"lordosis": float("nan")}, "Lambda", "must be finite"),
        ({"eccentricity": "0.03"}, "E", "must be a number"),
        ({"model": "wagner2012"}, "model", "must be a spinectl Model"),
    ],
)
def test_a_bad_field_is_one_parameter_error_naming_it(model, fields, field, message):
    """Each bad field (shape, sign, range, type; the PCSA per pair or per muscle, the stiffness as a number or per
    joint) raises one ParameterError whose field is the one at fault and whose text is one line."""
    given = {"model": model, "eccentricity": E, "lordosis": LAMBDA, "pcsa": [1e-3] * 3} | fields
    with pytest.raises(ParameterError) as err:
        OperatingPoint(**given)
    assert err.value.field == field
    assert message in err.value.message and "\n" not in str(err.value)


def test_the_point_is_frozen_and_keeps_its_pcsa_per_muscle(model):
    """Per pair in, per muscle kept (both sides the pair's value), read-only; a number of local stiffness is
    the same at every joint; the point cannot be changed after its checks."""
    point = OperatingPoint(model, E, LAMBDA, [1e-3, 2e-3, 3e-3], local_stiffness=4.0)
    np.testing.assert_array_equal(point.pcsa, [1e-3, 1e-3, 2e-3, 2e-3, 3e-3, 3e-3])
    np.testing.assert_array_equal(point.local_stiffness, np.full(5, 4.0))
    with pytest.raises(ValueError, match="read-only"):
        point.pcsa[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        point.pcsa = np.zeros(6)


def test_a_pcsa_in_cm2_is_refused_unless_computed(model):
    """10 m^2 per muscle is cm^2 typed as m^2 (the unit-slip check of expand_pcsa) unless slip_check=False."""
    with pytest.raises(ParameterError, match="the Python API takes m\\^2"):
        OperatingPoint(model, E, LAMBDA, [10.0] * 3)
    assert OperatingPoint(model, E, LAMBDA, [10.0] * 3, slip_check=False).pcsa.max() == 10.0


# --- the chain: bit for bit what the four former assemblies built -------------------------------


def test_the_chain_is_the_formula_bit_for_bit(model):
    """chain_at without local stiffness: no controls, K, D and M of the formulas bit for bit, the joints, c_loc and
    the source of linear_chain; with local stiffness k, K - diag(k) and D - c_loc diag(k) bit for bit (the form
    of coupled_stability_at's and the design's), and linear_chain(...).at(x, k) to rounding (x the decision
    variables in cm^2: the same sums in another order)."""
    pcsa = minimum_stabilising_pcsa(model, E, LAMBDA)
    mass, stiffness, damping = _formula(model, pcsa)
    linear = chain_at(OperatingPoint(model, E, LAMBDA, pcsa))
    assert isinstance(linear, LinearChain) and linear.n_controls == 0
    np.testing.assert_array_equal(linear.stiffness_offset, stiffness)
    np.testing.assert_array_equal(linear.damping_offset, damping)
    np.testing.assert_array_equal(linear.mass_matrix, mass)
    free = chain.linear_chain(model, E, LAMBDA)
    assert linear.joints == free.joints and linear.source == free.source
    assert linear.local_damping_per_stiffness == chain.local_damping_per_stiffness(model) > 0
    k = np.array([60.0, 90.0, 95.0, 66.0, 19.0])
    with_local = chain_at(OperatingPoint(model, E, LAMBDA, pcsa, local_stiffness=k))
    np.testing.assert_array_equal(with_local.stiffness_offset, stiffness - np.diag(k))
    c_loc = chain.local_damping_per_stiffness(model)
    np.testing.assert_array_equal(with_local.damping_offset, damping - np.diag(c_loc * k))
    x = pcsa[::2] / 1e-4  # paired: one variable per pair [cm^2]
    np.testing.assert_allclose(with_local.stiffness_offset, free.stiffness(x, k), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(with_local.damping_offset, free.damping(x, k), rtol=1e-12, atol=1e-12)


def test_the_four_former_paths_take_the_same_chain(model):
    """Each former assembly's public answer at activation 0.5 equals the analysis applied to the formula's matrices
    bit for bit: the modes (stability.chain_modes), the stability --coupled matrices and eigenvalues with the
    least local stiffness (coupled_stability_at), the chain's reflex gains and exact margin (chain_verdict), and
    the design's loop at a fraction (chain_loop_at, K - f diag(k*), D - c_loc f diag(k*))."""
    point = operating_point(model, E, LAMBDA, 0.5)
    mass, stiffness, damping = _formula(model, point.pcsa)
    np.testing.assert_array_equal(
        chain_modes(model, E, LAMBDA, point.pcsa).eigenvalues, chain.dynamic_eigenvalues(mass, stiffness, damping)
    )
    coupled = coupled_stability_at(model, E, LAMBDA, point.pcsa)
    for got, want in ((coupled.stiffness, stiffness), (coupled.damping, damping), (coupled.mass, mass)):
        np.testing.assert_array_equal(got, want)
    k = coupled.local.local_stiffness
    c_loc = chain.local_damping_per_stiffness(model)
    with_local = chain.dynamic_eigenvalues(mass, stiffness - np.diag(k), damping - np.diag(c_loc * k))
    np.testing.assert_array_equal(coupled.local_eigenvalues, with_local)
    verdict = chain_verdict(model, point, model.reflex.delay, model.reflex.activation_time_constant)
    _, least = least_local_stiffness_stacked(stiffness[None], model.optimisation.stability_margin)
    kp, kd = resolve_chain_gains(model.reflex, mass, stiffness, damping, least[0])
    np.testing.assert_array_equal(verdict.kp, kp)
    np.testing.assert_array_equal(verdict.kd, kd)
    exact = chain_delay_margin(mass, stiffness, damping, kp, kd, model.reflex.activation_time_constant)
    assert verdict.exact.margin == exact.margin
    f = 0.3
    k_f, d_f, _, _ = dz.chain_loop_at(model, chain_at(OperatingPoint(model, E, LAMBDA, point.pcsa)), least[0], f)
    np.testing.assert_array_equal(k_f, stiffness - f * np.diag(least[0]))
    np.testing.assert_array_equal(d_f, damping - np.diag(chain.local_damping(f * least[0], model)))


# --- the extension point: a new analysis is a function of a LinearChain -------------------------


def static_margin(linear: LinearChain) -> float:
    """A made-up analysis, as CONTRIBUTING.md's "Extension points" writes one: the least eigenvalue of -sym(K)
    [N m/rad] of a chain at its operating point, > 0 statically stable (Bergmark 1989)."""
    k = linear.stiffness_offset
    return float(np.linalg.eigvalsh(-(k + k.T) / 2)[0])


def test_an_analysis_of_a_linear_chain_runs_on_the_points_chain(model):
    """static_margin needs nothing but the chain: at the segment optimum it is negative (the chain's unstable static
    modes, docs/chain.md "The finding"), and with the least local stiffness of problem (a) added (a second method:
    Clarabel's SDP, whose constraint diag(k) - K >= mu I is active at its optimum) it is the optimisation's margin
    mu, to the solver's tolerance (3e-14 N m/rad seen)."""
    pcsa = minimum_stabilising_pcsa(model, E, LAMBDA)
    bare = chain_at(OperatingPoint(model, E, LAMBDA, pcsa))
    assert static_margin(bare) < 0
    mu = model.optimisation.stability_margin
    _, least = least_local_stiffness_stacked(bare.stiffness_offset[None], mu)
    held = chain_at(OperatingPoint(model, E, LAMBDA, pcsa, local_stiffness=least[0]))
    assert static_margin(held) == pytest.approx(mu, abs=1e-6)  # Clarabel's tolerance [N m/rad]


def test_the_point_at_an_activation_is_that_fraction_of_the_optimum(model):
    """point_at_activation: the PCSA activation x the minimum stabilising PCSA (its own call here), bit for bit,
    of any size (computed); 1 is the optimum itself, what stability --coupled takes without --pcsa; a negative
    activation is one ParameterError naming it."""
    optimum = minimum_stabilising_pcsa(model, E, LAMBDA)
    np.testing.assert_array_equal(point_at_activation(model, E, LAMBDA, 0.5).pcsa, 0.5 * optimum)
    np.testing.assert_array_equal(point_at_activation(model, E, LAMBDA).pcsa, optimum)
    np.testing.assert_array_equal(coupled_stability_at(model, E, LAMBDA).pcsa, optimum)
    assert point_at_activation(model, E, LAMBDA, 1e4).pcsa.max() > 0.1  # beyond MAX_PLAUSIBLE_PCSA: computed
    with pytest.raises(ParameterError) as err:
        point_at_activation(model, E, LAMBDA, -0.5)
    assert err.value.field == "activation"
