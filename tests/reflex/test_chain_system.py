"""The coupled chain as a python-control system (docs/chain.md, "Dynamic stability")."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import load_preset, optimise
from spinectl.errors import ModelError
from spinectl.model import chain, geometry
from spinectl.model.params import Levels, Model
from spinectl.reflex.chain_system import chain_system
from spinectl.reflex.loops import segment_system


def _matrices(model, E, L):
    opt = optimise.solve_point(model, E, L)
    coefficients = chain.chain_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    return chain.mass_matrix(model, cor), coefficients.stiffness(opt.pcsa), coefficients.damping(opt.pcsa)


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_chain_system_poles_and_static_gain(preset):
    """10 states, 5 torques in, 5 angles out; poles are the dynamic eigenvalues (numpy on the state
    matrix), and the static gain solves 0 = K q + u: q = -K^-1 u."""
    model = load_preset(preset)
    mass, stiffness, damping = _matrices(model, 0.03, 0.04)
    system = chain_system(mass, stiffness, damping, model.geometry.cor_names)
    assert (system.nstates, system.ninputs, system.noutputs) == (10, 5, 5)
    assert system.input_labels == [f"torque_{k}" for k in model.geometry.cor_names]
    assert system.output_labels[0] == "alpha_L1L2" and system.state_labels[5] == "omega_L1L2"
    np.testing.assert_allclose(
        np.sort_complex(system.poles()),
        np.sort_complex(chain.dynamic_eigenvalues(mass, stiffness, damping)),
        rtol=1e-8,
    )
    np.testing.assert_allclose(system.dcgain(), -np.linalg.inv(stiffness), rtol=1e-8)
    # independent of the state matrix: each pole s solves det(M s^2 - D s - K) = 0 (the chain's
    # characteristic equation, tau = K q + D q' = M q''), checked as the smallest singular value
    for s in system.poles():
        singular = np.linalg.svd(mass * s**2 - damping * s - stiffness, compute_uv=False)
        assert singular[-1] <= 1e-7 * singular[0]


def test_one_joint_is_the_segment_system():
    """n = 1: the chain's system is reflex.loops.segment_system with theta = M."""
    one = chain_system([[2.0]], [[-30.0]], [[-1.5]], ["L3L4"])
    segment = segment_system(-30.0, -1.5, 2.0)
    for ours, theirs in zip(ct_matrices(one), ct_matrices(segment), strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=1e-14)


def ct_matrices(system):
    return system.A, system.B, system.C, system.D


def test_singular_mass_matrix_is_a_model_error():
    """Massless levels and the point mass: M has rank 2, no state-space model."""
    model = Model(levels=Levels(mass=0.0))
    cor = geometry.cor_positions(0.0, 0.0, model.geometry)
    mass = chain.mass_matrix(model, cor)
    with pytest.raises(ModelError, match="singular"):
        chain_system(mass, -np.eye(5), -np.eye(5), model.geometry.cor_names)
    with pytest.raises(ModelError, match="5 x 5"):
        chain_system(mass[:4, :4], -np.eye(4), -np.eye(4), model.geometry.cor_names)
