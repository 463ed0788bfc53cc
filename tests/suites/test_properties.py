"""Properties of the model over random valid geometries (hypothesis).

Random models vary the muscle pairs (attachments, spread, fibre count), the
mass, its height and radius of gyration, and the position (E, Lambda) within
the paper's range. Attachments are drawn above the top CoR and below the
bottom one, with the spread too small to cross them, so that no attachment
can lie on a CoR (that case is tested in test_robustness.py).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from spinectl.model import geometry, mechanics
from spinectl.model.checks import checked_coefficients
from spinectl.model.params import Body, Model, MusclePair, Optimisation, Passive
from spinectl.model.stability import segment_stability
from spinectl.optimise.problem import OK_STATUSES
from spinectl.optimise.reference import solve_point

STEP = 1e-6
"""Central-difference step in alpha [rad] and omega [rad/s]; truncation error ~ STEP^2."""

FAST = settings(max_examples=40, deadline=None)
SOLVER = settings(max_examples=15, deadline=None)  # two LP/SOCP solves per example


def _between(low, high):
    return st.floats(low, high, allow_nan=False, allow_infinity=False)


@st.composite
def muscle_pairs(draw, index: int) -> MusclePair:
    """A pair whose fibres all start above y = 0.155 m and end below y = -0.005 m.

    The default CoRs lie in [0.005, 0.145] m and the spread shifts a fibre by at
    most spread / 2 <= 0.01 m, so no fibre end can reach a CoR.
    """
    upper = (draw(_between(0.02, 0.20)), draw(_between(0.165, 0.30)))
    lower = (draw(_between(0.02, 0.20)), draw(_between(-0.05, -0.015)))
    return MusclePair(f"pair{index}", upper, lower, draw(_between(0.0, 0.02)), draw(st.integers(1, 5)))


PASSIVE_STIFFNESS = _between(0.0, 30.0)
"""K [N m/rad], up to twice the paper's 15 N m/rad."""

positions = st.tuples(_between(-0.08, 0.08), _between(-0.08, 0.08))
"""(E, Lambda) [m] within the paper's 0 to 8 cm and its mirror image."""


@st.composite
def models(draw, stiffness=PASSIVE_STIFFNESS) -> Model:
    """A random valid model: 1 to 3 pairs, mass 10-100 kg at 0.2-0.5 m, default fibres."""
    n_pairs = draw(st.integers(1, 3))
    body = Body(
        mass=draw(_between(10.0, 100.0)),
        mass_height=draw(_between(0.2, 0.5)),
        radius_of_gyration=draw(_between(0.0, 0.2)),
    )
    return Model(
        body=body,
        muscles=tuple(draw(muscle_pairs(i)) for i in range(n_pairs)),
        passive=Passive(stiffness=draw(stiffness)),
        optimisation=Optimisation(activation=draw(st.sampled_from(["paired", "independent"]))),
    )


def _swap_sides(n_muscles: int) -> np.ndarray:
    """Column permutation exchanging the ventral and dorsal muscle of every pair."""
    return np.arange(n_muscles).reshape(-1, 2)[:, ::-1].ravel()


@FAST
@given(models(), positions)
def test_mirror_symmetry(model, position):
    """E, Lambda -> -E, -Lambda mirrors x -> -x: CoR x_k = -E + Lambda phi_k changes sign,
    and the dorsal muscle is the mirror image of the ventral one. A mirror reverses the
    sense of rotation, so torques change sign and the sides swap, while stiffness and
    damping (torque per angle, both reversed) keep theirs (docs/model.md, "The muscles": the
    dorsal muscle is the mirror image x -> -x of the ventral one)."""
    E, L = position
    a = checked_coefficients(model, E, L)
    b = checked_coefficients(model, -E, -L)
    swap = _swap_sides(a.torque_per_pcsa.shape[-1])
    scale = np.abs(a.torque_per_pcsa).max() + np.abs(a.stiffness_per_pcsa).max()
    np.testing.assert_allclose(b.torque_per_pcsa, -a.torque_per_pcsa[..., swap], atol=1e-12 * scale)
    np.testing.assert_allclose(b.stiffness_per_pcsa, a.stiffness_per_pcsa[..., swap], atol=1e-12 * scale)
    np.testing.assert_allclose(b.damping_per_pcsa, a.damping_per_pcsa[..., swap], atol=1e-12 * scale)
    np.testing.assert_allclose(b.gravity_torque, -a.gravity_torque, atol=1e-12 * np.abs(a.gravity_stiffness).max())
    np.testing.assert_allclose(b.gravity_stiffness, a.gravity_stiffness, rtol=1e-12)
    np.testing.assert_allclose(b.inertia, a.inertia, rtol=1e-12)


def _central_difference(model, cor, variable: str):
    args = {"alpha": 0.0, "omega": 0.0}
    plus = mechanics.muscle_torque_per_pcsa(model, cor, **{**args, variable: STEP})
    minus = mechanics.muscle_torque_per_pcsa(model, cor, **{**args, variable: -STEP})
    return (plus - minus) / (2 * STEP)


@FAST
@given(models(), positions)
def test_stiffness_and_damping_are_central_differences_of_the_torque(model, position):
    """Analytic dM/dalpha and dM/domega per unit PCSA against central differences of the
    nonlinear torque M = h f_l f_H (paper, Methods). Error budget: truncation STEP^2 times
    the third derivative, rounding eps |M| / STEP ~ 1e-10 |M|; both far below 1e-6 of the
    largest entry. The Hill curve with erratum C is C^1 at v = 0, so the omega difference
    across the branch change is as accurate as elsewhere."""
    E, L = position
    coeffs = checked_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    for analytic, variable in ((coeffs.stiffness_per_pcsa, "alpha"), (coeffs.damping_per_pcsa, "omega")):
        fd = _central_difference(model, cor, variable)
        np.testing.assert_allclose(analytic, fd, atol=1e-6 * np.abs(fd).max(), err_msg=variable)
    assert np.all(coeffs.damping_per_pcsa <= 0)  # the Hill slope is negative


@FAST
@given(models(), positions, _between(0.1, 10.0))
def test_gravity_scales_with_mass_and_nothing_else_does(model, position, factor):
    """Gravity stiffness m g r_y, gravity torque -m g r_x and inertia m (r^2 + rho^2) are
    linear in m (docs/model.md, "Gravity"); the muscular coefficients do not involve m."""
    E, L = position
    heavy = model.replace(body=dataclasses.replace(model.body, mass=model.body.mass * factor))
    a, b = checked_coefficients(model, E, L), checked_coefficients(heavy, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    r_y = model.body.mass_height - cor[:, 1]
    np.testing.assert_allclose(a.gravity_stiffness, model.body.mass * model.body.gravity * r_y, rtol=1e-12)
    np.testing.assert_allclose(b.gravity_stiffness, factor * a.gravity_stiffness, rtol=1e-12)
    np.testing.assert_allclose(b.gravity_torque, factor * a.gravity_torque, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(b.inertia, factor * a.inertia, rtol=1e-12)
    np.testing.assert_array_equal(b.stiffness_per_pcsa, a.stiffness_per_pcsa)


@SOLVER
@given(models(stiffness=st.just(0.0)), positions, _between(1.5, 4.0))
def test_min_pcsa_is_proportional_to_mass_without_passive_stiffness(model, position, factor):
    """min PCSA(c m) = c min PCSA(m) at K = 0, with no margin and no upper bound.

    Why: the LP is  min w.x  s.t.  A x <= -(m g r_y - K) - margin,  0 <= x <= pcsa_max,
    every constraint linear in the PCSA x (docs/model.md, "Force-velocity": everything
    muscular is linear in PCSA). With K = 0, margin = 0 and pcsa_max = inf the constant term is
    -m g r_y (and the damping rows' bound is -damping_margin = 0), so x is feasible for m iff c x
    is feasible for c m, and the optimum scales
    by c. The counter torque CT = -(T x + M_ext) is then c times as large as well.
    """
    E, L = position
    light = model.replace(
        optimisation=dataclasses.replace(model.optimisation, stability_margin=0.0, damping_margin=0.0)
    )
    heavy = light.replace(body=dataclasses.replace(model.body, mass=model.body.mass * factor))
    a, b = solve_point(light, E, L), solve_point(heavy, E, L)
    assert a.ok == b.ok, (a.status, b.status)
    if a.ok:
        # Clarabel's default tolerances are 1e-8 relative; 1e-5 leaves room for conditioning.
        np.testing.assert_allclose(b.min_pcsa, factor * a.min_pcsa, rtol=1e-5)
        weight = model.body.mass * model.body.gravity * model.body.mass_height  # scale of CT [N m]
        np.testing.assert_allclose(
            b.counter_torque_norm, factor * a.counter_torque_norm, rtol=1e-4, atol=1e-6 * factor * weight
        )


@SOLVER
@given(models(), positions)
def test_the_optimum_is_self_stable(model, position):
    """The optimum satisfies dM_k/dalpha <= -margin < 0 at every CoR and has D < 0, so both
    eigenvalues of every segment have negative real part (paper, eq. 1): check it with the
    independent eigenvalue computation of segment_stability, or the point has no answer (NaN).

    'optimal_inaccurate' (Clarabel's AlmostSolved, e.g. two identical pairs) is an answer too:
    its reduced tolerance (~1e-4 of N m/rad-sized rows) is far inside the margins of 0.1 N m/rad
    and 0.01 N m s/rad, so it must be self-stable as well.
    """
    E, L = position
    optimum = solve_point(model, E, L)
    if optimum.status in OK_STATUSES:
        assert np.all(np.isfinite(optimum.pcsa)) and optimum.min_pcsa >= -1e-9
        result = segment_stability(model, E, L, optimum.pcsa)
        assert result.self_stable.all(), (optimum.status, result.stiffness, result.eigenvalues)
    else:
        assert np.isnan(optimum.min_pcsa) and np.isnan(optimum.pcsa).all()
