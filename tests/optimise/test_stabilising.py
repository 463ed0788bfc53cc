"""The stability at one point with its minimum stabilising PCSA, by the fast path (optimise/stabilising)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl import optimise
from spinectl.errors import ModelError
from spinectl.model.stability import segment_stability
from spinectl.optimise import stabilising


def _with(model, **settings):
    return model.replace(optimisation=dataclasses.replace(model.optimisation, **settings))


def test_minimum_stabilising_pcsa_is_the_chosen_activation(model):
    """The fast path's chosen activation (active_set.solve_point): the reference's to 1e-9 of the total PCSA
    (the agreement of tests/optimise/test_active_set.py), and self-stable."""
    pcsa = stabilising.minimum_stabilising_pcsa(model, 0.03, 0.04)
    opt = optimise.solve_point(model, 0.03, 0.04)
    np.testing.assert_allclose(pcsa, opt.pcsa, rtol=0, atol=1e-9 * opt.min_pcsa)
    assert segment_stability(model, 0.03, 0.04, pcsa).all_self_stable


def test_no_minimum_stabilising_pcsa_is_a_model_error(model):
    """At most 1 cm^2 per muscle: infeasible (as above), an error naming the status and the way out."""
    with pytest.raises(ModelError, match=r"no activation stabilises every segment at E = 0 m, Lambda = 0 m") as info:
        stabilising.minimum_stabilising_pcsa(_with(model, pcsa_max=1e-4), 0.0, 0.0)
    # the library speaks of its own argument, not of a command-line option (before: "give --pcsa")
    assert "argument pcsa" in str(info.value) and "--" not in str(info.value)


def test_stability_at_defaults_to_the_minimum_stabilising_pcsa(model):
    default = stabilising.stability_at(model, 0.03, 0.04)
    np.testing.assert_array_equal(default.pcsa, stabilising.minimum_stabilising_pcsa(model, 0.03, 0.04))
    given = stabilising.stability_at(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    expected = segment_stability(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    np.testing.assert_array_equal(given.eigenvalues, expected.eigenvalues)
    with pytest.raises(ModelError):
        stabilising.stability_at(_with(model, pcsa_max=1e-4), 0.0, 0.0)


def test_a_computed_optimum_beyond_any_muscle_is_an_answer_not_a_unit_slip():
    """A 1000 kg body on fibres of 5e4 N/m^2 (both inside the allowed ranges) needs more than the
    1000 cm^2 that a *given* PCSA may have: stability_at reports it, as a sweep does, instead of
    refusing its own optimum as m^2 typed for cm^2. With zero margins the problem is linear in m / sigma
    (gravity stiffness m g r, muscle stiffness sigma PCSA; paper, eq. 2), so the optimum is exactly
    (1000 / 24.06) x (2.5e5 / 5e4) = 208 times the preset's."""
    from spinectl.model import config
    from spinectl.model.checks import MAX_PLAUSIBLE_PCSA

    base = config.load_preset("wagner2012")
    base = base.replace(optimisation=dataclasses.replace(base.optimisation, stability_margin=0.0, damping_margin=0.0))
    heavy = base.replace(
        body=dataclasses.replace(base.body, mass=1000.0),
        fibre=dataclasses.replace(base.fibre, specific_tension=5e4),
    )
    scale = (1000.0 / base.body.mass) * (base.fibre.specific_tension / 5e4)
    result = stabilising.stability_at(heavy, 0.03, 0.04)
    assert result.pcsa.max() > MAX_PLAUSIBLE_PCSA  # (zero margins: marginally stable by construction)
    assert result.min_pcsa == pytest.approx(scale * stabilising.stability_at(base, 0.03, 0.04).min_pcsa, rel=1e-6)
