"""External loads on the paper's chain (model/loads.py, model/operating_point.py; docs/chain.md, "External loads").

Every expected number comes from a second method: central differences of the nonlinear torque
(P(q) - c_j(q)) x F(q) for the load stiffness, the closed form -F_y h of a vertical load on one joint,
gravity's own K_g and torque (model/chain.py) for a load equal to the weight.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl import load_preset
from spinectl.errors import ParameterError
from spinectl.model import chain, geometry
from spinectl.model.loads import PointLoad, load_stiffness, load_torque
from spinectl.model.operating_point import OperatingPoint, chain_at, load_torque_at

E, LAMBDA = 0.03, 0.04
PCSA = np.full(6, 10e-4)  # 10 cm^2 in each muscle [m^2]


@pytest.fixture(scope="module")
def model():
    return load_preset("wagner2012")


@pytest.fixture(scope="module")
def cor(model):
    return geometry.cor_positions(E, LAMBDA, model.geometry)


def _central_differences(model, cor, loads, step=1e-6):
    n = cor.shape[0]
    out = np.zeros((n, n))
    for k in range(n):
        dq = np.zeros(n)
        dq[k] = step
        out[:, k] = (load_torque(model, cor, dq, loads) - load_torque(model, cor, -dq, loads)) / (2 * step)
    return out


@pytest.mark.parametrize("frame", ["ground", "body"])
def test_load_stiffness_is_the_torques_derivative(model, cor, frame):
    """K_load equals central differences of the nonlinear load torque in q, both frames (a follower force too)."""
    loads = [PointLoad((30.0, -200.0), frame), PointLoad((-12.0, 5.0), frame)]
    k = load_stiffness(model, cor, loads)
    assert np.allclose(k, _central_differences(model, cor, loads), rtol=1e-8, atol=1e-7)


def test_ground_load_symmetric_follower_not(model, cor):
    """A ground-fixed load is conservative (K symmetric); a body-fixed one is not, and is zero on the diagonal."""
    ground = load_stiffness(model, cor, [PointLoad((30.0, -200.0))])
    body = load_stiffness(model, cor, [PointLoad((30.0, -200.0), "body")])
    assert np.array_equal(ground, ground.T)
    assert not np.allclose(body, body.T)
    assert np.allclose(np.triu(body), 0.0)  # a follower force on one joint alone: no load stiffness


def test_vertical_load_on_one_joint_is_minus_f_h(model, cor):
    """Each joint alone (the diagonal): a vertical load F_y at height h above CoR k gives K = -F_y h (closed form)."""
    f_y = -150.0
    heights = model.body.mass_height - cor[:, 1]  # h_k, P straight above the origin (x = 0)
    k = load_stiffness(model, cor, [PointLoad((0.0, f_y))])
    assert np.allclose(np.diag(k), -f_y * heights, rtol=1e-14)
    # a horizontal load F_x pulls on the lever P_x - c_x = -x_k: K = -F_x (0 - x_k)
    k_x = load_stiffness(model, cor, [PointLoad((40.0, 0.0))])
    assert np.allclose(np.diag(k_x), 40.0 * cor[:, 0], rtol=1e-14)


def test_weight_as_a_load_is_gravity(model, cor):
    """F = (0, -m g) at the point mass is gravity: K_g and the nonlinear torque of model/chain.py."""
    weight = model.body.mass * model.body.gravity
    loads = [PointLoad((0.0, -weight))]
    assert model.errata.gravity_sign == "destabilising" and model.levels.weight_in_gravity == 0
    assert np.allclose(load_stiffness(model, cor, loads), chain._gravity_stiffness(model, cor[:, 1]), rtol=1e-14)
    q = np.array([0.01, -0.02, 0.03, 0.0, 0.015])
    assert np.allclose(load_torque(model, cor, q, loads), chain.chain_gravity_torque(model, cor, q), rtol=1e-13)


def test_chain_at_adds_the_load_stiffness(model, cor):
    """chain_at's K with loads is K without plus K_load; without loads it is unchanged bit for bit."""
    loads = (PointLoad((0.0, -200.0)),)
    bare = chain_at(OperatingPoint(model, E, LAMBDA, PCSA))
    loaded = chain_at(OperatingPoint(model, E, LAMBDA, PCSA, loads=loads))
    assert np.allclose(loaded.stiffness_offset - bare.stiffness_offset, load_stiffness(model, cor, loads), rtol=1e-12)
    assert np.array_equal(loaded.damping_offset, bare.damping_offset)
    assert np.array_equal(loaded.mass_matrix, bare.mass_matrix)
    assert "load F = (0, -200) N" in loaded.source and "load" not in bare.source
    coefficients = chain.chain_coefficients(model, E, LAMBDA)
    assert np.array_equal(bare.stiffness_offset, coefficients.stiffness(PCSA))
    # a weight held lowers the static margin (the least eigenvalue of -K) by at least the least of K_load's
    margin = [np.linalg.eigvalsh(-c.stiffness_offset)[0] for c in (bare, loaded)]
    assert margin[1] < margin[0] - np.linalg.eigvalsh(load_stiffness(model, cor, loads))[0] + 1e-9


def test_load_torque_at_the_upright_posture(model, cor):
    """tau_j = (P - c_j) x F upright: for F = (F_x, F_y), (0 - x_j) F_y - (y_m - y_j) F_x."""
    point = OperatingPoint(model, E, LAMBDA, PCSA, loads=[(25.0, -100.0)])
    expected = -cor[:, 0] * -100.0 - (model.body.mass_height - cor[:, 1]) * 25.0
    assert np.allclose(load_torque_at(point), expected, rtol=1e-14)
    assert np.array_equal(load_torque_at(OperatingPoint(model, E, LAMBDA, PCSA)), np.zeros(len(cor)))


@pytest.mark.parametrize(
    "loads",
    [
        [(1.0,)],
        [(np.nan, 0.0)],
        [(2e5, 0.0)],  # beyond MAX_LOAD
        [("a", 1.0)],
        7.0,
    ],
)
def test_bad_loads_are_refused_in_one_line(model, loads):
    """A load that is not two finite forces within the bound: a ParameterError naming 'loads'."""
    with pytest.raises(ParameterError, match="loads"):
        OperatingPoint(model, E, LAMBDA, PCSA, loads=loads)


def test_bad_frame_refused_and_point_frozen(model):
    """A frame other than ground or body is refused; the point's loads cannot be changed after validation."""
    with pytest.raises(ParameterError, match="frame"):
        PointLoad((0.0, -1.0), "thorax")
    point = OperatingPoint(model, E, LAMBDA, PCSA, loads=[(0.0, -10.0)])
    assert isinstance(point.loads, tuple) and point.loads[0] == PointLoad((0.0, -10.0))
    with pytest.raises(dataclasses.FrozenInstanceError):
        point.loads = ()
