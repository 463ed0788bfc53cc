"""The muscle-law seam (spinectl.model.laws; docs/model.md, "The muscle-law seam").

The registered law is the paper's relations, to the last bit of what the code computed before the
seam; a made-up law registered here, with nothing else edited, reaches the model, the chain, the
local muscles and the MJCF gains, each as its derivative says; the OpenSim export refuses a law
without OpenSim expressions in one line; an unknown name is one line with a "did you mean".
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl import load_preset
from spinectl.anatomy.export_mjcf import fibre_gains
from spinectl.errors import ParameterError
from spinectl.model import chain, config, geometry, laws, mechanics, muscle
from spinectl.model.params import Errata, Fibre, Model

STEP = 1e-6
SPEED = 10.0
"""The made-up law's v_0 / l_opt [1/s]: f_V(v) = 1 - v / (SPEED l_opt)."""


def _linear_law(name: str, passive: bool = False) -> laws.MuscleLaw:
    """A made-up law: f_L(x) = x, f_V(v) = 1 - v / (SPEED l_opt), and with ``passive`` f_P(x) = (x - 1/2)^2 / 2."""
    return laws.MuscleLaw(
        name=name,
        active_force_length=lambda x, fibre: np.asarray(x, float),
        active_force_length_slope=lambda x, fibre: np.ones_like(np.asarray(x, float)),
        force_velocity=lambda v, l_opt, fibre, errata: 1.0 - np.asarray(v) / (SPEED * np.asarray(l_opt)),
        force_velocity_slope=lambda v, l_opt, fibre, errata: (
            np.zeros_like(np.asarray(v, float)) - 1.0 / (SPEED * np.asarray(l_opt))
        ),
        passive_force_length=(lambda x, fibre: 0.5 * (np.asarray(x) - 0.5) ** 2) if passive else None,
        passive_force_length_slope=(lambda x, fibre: np.asarray(x) - 0.5) if passive else None,
    )


@pytest.fixture
def made_up():
    """The made-up laws registered as ``linear`` and ``linear_passive`` for one test, then removed."""
    registered = [laws.register_law(_linear_law("linear")), laws.register_law(_linear_law("linear_passive", True))]
    yield registered
    for law in registered:
        del laws.LAWS[law.name]


def _before_the_seam(model: Model):
    """mechanics._fibre_laws as it read before the seam: the paper's relations called directly."""
    upper, lower, share = geometry.all_fibres(model)
    l0 = np.linalg.norm(lower - upper, axis=-1)
    l_opt = model.fibre.optimal_length_ratio * l0
    f_l = muscle.force_length(l0, l_opt, model.fibre)
    f_l_slope = muscle.force_length_slope(l0, l_opt, model.fibre)
    f_h_slope = muscle.force_velocity_slope(np.zeros_like(l0), muscle.hill_constants(l_opt, model.fibre, model.errata))
    return upper, lower, model.fibre.specific_tension * share, l0, f_l, f_l_slope, f_h_slope


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_the_registered_law_gives_the_numbers_before_the_seam_bit_for_bit(preset):
    """The default law is the paper's: _fibre_laws (what K, D and the torques of the model and the chain are made
    of), the MJCF gains, c_loc and the nonlinear torques of the chain and of one segment (fibre_torque) equal, bit
    for bit, the paper's relations composed as the code composed them before the seam."""
    model = load_preset(preset)
    assert model.fibre.law == "wagner2012" and laws.get_law(model.fibre.law) is laws.LAWS["wagner2012"]
    before = _before_the_seam(model)
    for now, then in zip(mechanics._fibre_laws(model), before, strict=True):
        np.testing.assert_array_equal(now, then)
    _, _, _, l0, f_l, f_l_slope, f_h_slope = before
    f_iso = model.fibre.specific_tension * geometry.all_fibres(model)[2].sum(axis=1)
    gains = fibre_gains(model)
    np.testing.assert_array_equal(gains.force, f_iso * f_l)
    np.testing.assert_array_equal(gains.length_slope, f_iso * f_l_slope)
    np.testing.assert_array_equal(gains.velocity_slope, f_iso * f_l * f_h_slope)
    local = model.local
    hill = muscle.hill_constants(model.fibre.optimal_length_ratio * local.length, model.fibre, model.errata)
    c_loc = local.damping * local.length * -float(muscle.force_velocity_slope(0.0, hill)) / local.stiffness_gain
    assert chain.local_damping_per_stiffness(model) == c_loc
    rng = np.random.default_rng(0)
    cor = geometry.cor_positions(0.03, 0.04, model.geometry)
    q, qdot = rng.uniform(-0.1, 0.1, 5), rng.uniform(-1.0, 1.0, 5)
    upper, lower, to_muscle, _, l_opt, _ = chain._fibre_constants(model)
    moved, _ = chain.chain_positions(q, cor)
    tops = chain.carried_points(upper, q, cor)
    length, h = mechanics.fibre_length_and_lever_arm(tops[..., None, :, :], lower, moved[..., :, None, :])
    velocity = np.einsum("...jf,...j->...f", h, qdot)
    hill = muscle.hill_constants(l_opt, model.fibre, model.errata)
    tension = muscle.force_length(length[..., 0, :], l_opt, model.fibre) * muscle.force_velocity(velocity, hill)
    expected = (h * tension[..., None, :]) @ to_muscle
    np.testing.assert_array_equal(chain.chain_muscle_torque_per_pcsa(model, cor, q, qdot), expected)
    alpha, omega = rng.uniform(-0.2, 0.2, (7, 1, 1)), rng.uniform(-1.0, 1.0, (7, 1, 1))
    length, h = mechanics.fibre_length_and_lever_arm(upper, lower, cor[:, None, :], alpha)
    expected = h * muscle.force_length(length, l_opt, model.fibre) * muscle.force_velocity(h * omega, hill)
    torque = mechanics.fibre_torque(alpha, omega, upper, lower, cor[:, None, :], model.fibre, model.errata)
    np.testing.assert_array_equal(torque, expected)


def test_the_registered_law_is_the_closed_forms_of_docs_model():
    """wagner2012 through the seam against docs/model.md written out here: f_l = exp(-(((l/l_opt)^k1 - 1)/k2)^2),
    its slope f_l (-2u/k2) (k1/l_opt) (l/l_opt)^(k1 - 1), Hill's c/(v + b) - a (v >= 0) and C/(v - B) + A (v < 0)
    with a = 1/4, b = v_max/4, v_max = 11 l_opt/s, c = 1.25 b, A = 1.5, B = 0.4 b, C = 0.2 b, and the slope at
    rest -(1 + a)/b; to 1e-14 (the order of the operations differs)."""
    fibre, errata, law = Fibre(), Errata(), laws.get_law("wagner2012")
    l_opt = 0.3
    length = np.linspace(0.5, 1.4, 10) * l_opt
    x = length / l_opt
    u = (x**0.96 - 1) / 0.35
    f_l = np.exp(-(u**2))
    b = 11 * l_opt / 4
    v = np.array([-2.0, -0.5, -1e-3, 0.0, 1e-3, 0.5, 2.0])
    f_h = np.where(v >= 0, 1.25 * b / (v + b) - 0.25, 0.2 * b / (v - 0.4 * b) + 1.5)
    tension = laws.tension(law, length[:, None], v[None, :], l_opt, fibre, errata)
    np.testing.assert_allclose(tension, f_l[:, None] * f_h[None, :], rtol=1e-14)
    rest = laws.at_rest(law, length, l_opt, fibre, errata)
    np.testing.assert_allclose(rest.tension, f_l, rtol=1e-14)
    np.testing.assert_allclose(rest.length_slope, f_l * (-2 * u / 0.35) * 0.96 / l_opt * x ** (0.96 - 1), rtol=1e-13)
    np.testing.assert_allclose(rest.relative_velocity_slope, -(1 + 0.25) / b, rtol=1e-14)


def _central(func, step=STEP):
    return (func(step) - func(-step)) / (2 * step)


def test_a_made_up_law_changes_k_and_d_as_its_derivatives_say(made_up):
    """A linear force-length and force-velocity law, registered here and selected by fibre.law alone: the
    model's stiffness and damping per PCSA are the central differences in alpha and omega of the fibre torque
    (mechanics.muscle_torque_per_pcsa, which calls fibre_torque), and differ from the paper's law's; the chain's
    K and D likewise of chain_muscle_torque_per_pcsa; tolerances as tests/model/test_chain.py's (1e-6 of the
    largest entry)."""
    paper = load_preset("wagner2012")
    model = dataclasses.replace(paper, fibre=dataclasses.replace(paper.fibre, law="linear"))
    E, L = 0.03, 0.04
    cor = geometry.cor_positions(E, L, model.geometry)
    coeffs = mechanics.segment_coefficients(model, E, L)
    for k in range(cor.shape[0]):
        stiffness = _central(lambda a, k=k: mechanics.muscle_torque_per_pcsa(model, cor[k], a, 0.0))
        np.testing.assert_allclose(coeffs.stiffness_per_pcsa[k], stiffness, atol=1e-6 * np.abs(stiffness).max())
        damping = _central(lambda w, k=k: mechanics.muscle_torque_per_pcsa(model, cor[k], 0.0, w))
        np.testing.assert_allclose(coeffs.damping_per_pcsa[k], damping, atol=1e-6 * np.abs(damping).max())
    ours = mechanics.segment_coefficients(paper, E, L)
    assert (
        np.abs(coeffs.stiffness_per_pcsa - ours.stiffness_per_pcsa).max() > 0.1 * np.abs(ours.stiffness_per_pcsa).max()
    )
    coupled, zero, eye = chain.chain_coefficients(model, E, L), np.zeros(5), np.eye(5)
    for j in range(5):
        by_q = _central(lambda s, j=j: chain.chain_muscle_torque_per_pcsa(model, cor, s * eye[j], zero))
        np.testing.assert_allclose(coupled.stiffness_per_pcsa[:, j], by_q, atol=1e-6 * np.abs(by_q).max())
        by_qdot = _central(lambda s, j=j: chain.chain_muscle_torque_per_pcsa(model, cor, zero, s * eye[j]))
        np.testing.assert_allclose(coupled.damping_per_pcsa[:, j], by_qdot, atol=1e-6 * np.abs(by_qdot).max())


def test_a_made_up_law_reaches_the_mjcf_gains_and_the_local_muscles(made_up):
    """With the linear law by hand (l0 / l_opt = 1 / 1.2): T0 = f_iso / 1.2, dT/dl = f_iso / l_opt and dT/dv =
    T0 (-1 / (SPEED l_opt)); c_loc = damping l (1 / (SPEED 1.2 l)) / q = damping / (12 q). With a passive force
    f_P (the linear_passive law) the MJCF gains are the central differences of laws.tension in l and v (the
    velocity slope scales only the active part), and the model's damping that of the fibre torque in omega."""
    model = Model(fibre=Fibre(law="linear"))
    upper, lower, share = geometry.all_fibres(model)
    l0 = np.linalg.norm(lower - upper, axis=-1)
    l_opt, f_iso = 1.2 * l0, model.fibre.specific_tension * share.sum(axis=1)
    gains = fibre_gains(model)
    np.testing.assert_allclose(gains.force, f_iso / 1.2, rtol=1e-15)
    np.testing.assert_allclose(gains.length_slope, f_iso / l_opt, rtol=1e-15)
    np.testing.assert_allclose(gains.velocity_slope, -f_iso / 1.2 / (SPEED * l_opt), rtol=1e-15)
    local = model.local
    assert chain.local_damping_per_stiffness(model) == pytest.approx(local.damping / (12 * local.stiffness_gain))
    assert chain.local_damping_per_stiffness(model) != chain.local_damping_per_stiffness(Model())

    passive = Model(fibre=Fibre(law="linear_passive"))
    law, fibre, errata = laws.get_law("linear_passive"), passive.fibre, passive.errata
    gains = fibre_gains(passive)
    by_l = _central(lambda s: laws.tension(law, l0 + s, 0.0, l_opt, fibre, errata))
    by_v = _central(lambda s: laws.tension(law, l0, s, l_opt, fibre, errata))
    np.testing.assert_allclose(gains.force, f_iso * (1 / 1.2 + 0.5 * (1 / 1.2 - 0.5) ** 2), rtol=1e-15)
    np.testing.assert_allclose(gains.length_slope, f_iso * by_l, rtol=1e-8)
    np.testing.assert_allclose(gains.velocity_slope, f_iso * by_v, rtol=1e-8)
    cor = geometry.cor_positions(0.03, 0.04, passive.geometry)[2]
    damping = _central(lambda w: mechanics.muscle_torque_per_pcsa(passive, cor, 0.0, w))
    coeffs = mechanics.segment_coefficients(passive, 0.03, 0.04).damping_per_pcsa[2]
    np.testing.assert_allclose(coeffs, damping, atol=1e-6 * np.abs(damping).max())


def test_a_law_without_opensim_expressions_is_refused_in_one_line(made_up):
    """The made-up law has no OpenSim form: the export's curves are one ParameterError naming fibre.law (the paper's
    law gives its two expressions and no passive one)."""
    with pytest.raises(ParameterError) as info:
        laws.opensim_curves(Fibre(law="linear"), Errata())
    assert info.value.field == "fibre.law" and "'linear' has no OpenSim expressions" in str(info.value)
    assert "\n" not in str(info.value)
    curves = laws.opensim_curves(Fibre(), Errata())
    assert curves.active_force_length.startswith("exp(") and curves.passive_force_length is None


@pytest.mark.parametrize(
    ("value", "hint"),
    [("wagner2021", "; did you mean 'wagner2012'?"), ("Wagner2012", "; did you mean 'wagner2012'?"), ("hill", "")],
)
def test_an_unknown_law_is_one_line_with_a_did_you_mean(tmp_path, value, hint):
    """A misspelt name names the closest registered law; a name close to none lists them (difflib's cutoff 0.6)."""
    path = tmp_path / "model.toml"
    path.write_text(f'[fibre]\nlaw = "{value}"\n')
    with pytest.raises(ParameterError) as info:
        config.load_config(path)
    assert str(info.value) == f"fibre.law: must be one of 'wagner2012' (got {value!r}){hint}"
    with pytest.raises(ParameterError, match="did you mean" if hint else "must be one of"):
        laws.get_law(value)


def test_a_law_is_registered_once_under_its_name(made_up):
    """register_law refuses a second law under a taken name and a non-law; get_law takes a law itself."""
    with pytest.raises(ValueError, match="registered already"):
        laws.register_law(_linear_law("linear"))
    with pytest.raises(ValueError, match="takes a MuscleLaw"):
        laws.register_law(lambda x: x)
    assert laws.register_law(made_up[0]) is made_up[0]  # the same law again: no change
    assert laws.get_law(made_up[0]) is made_up[0]
    with pytest.raises(ValueError, match="together"):
        dataclasses.replace(made_up[1], passive_force_length_slope=None)
