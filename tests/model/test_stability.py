"""Self-stability of segments: known-stable and known-unstable configurations."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import optimise
from spinectl.errors import ParameterError
from spinectl.model import mechanics, muscle, source
from spinectl.model.checks import MAX_PLAUSIBLE_PCSA
from spinectl.model.config import set_parameter
from spinectl.model.params import Errata, Passive
from spinectl.model.stability import (
    eigenvalues,
    hurwitz_stable,
    jacobian,
    segment_stability,
    self_stable,
    slowest_time_constant,
)

ZERO = np.zeros(3)


def test_closed_form_eigenvalues_equal_numerical_eigenvalues(rng):
    s = rng.normal(0, 50, 20)
    d = -rng.uniform(0, 20, 20)
    theta = rng.uniform(0.5, 5, 20)
    closed = np.sort_complex(eigenvalues(s, d, theta))
    numeric = np.sort_complex(np.linalg.eigvals(jacobian(s, d, theta)))
    np.testing.assert_allclose(closed, numeric, atol=1e-9)


def test_eigenvalues_keep_the_small_root_when_theta_is_tiny():
    """theta -> 0: the roots of theta s^2 - D s - S are about D/theta and -S/D.

    From Vieta: lambda_1 lambda_2 = -S/theta and lambda_1 + lambda_2 = D/theta, so
    for theta S << D^2 the small root is -S/D (1 + O(theta S / D^2)); with
    S = -17.7, D = -5.78 (the segment of docs/robustness.md, mass 1 nm above L1L2) it is
    -3.062. The textbook form D/(2 theta) + sqrt(...) cancels to 0.
    """
    s, d, theta = -17.7, -5.78, 1e-20
    eigs = eigenvalues(s, d, theta)
    np.testing.assert_allclose(eigs[0].real, -s / d, rtol=1e-12)
    np.testing.assert_allclose(eigs[1].real, d / theta, rtol=1e-12)
    assert self_stable(eigs) and hurwitz_stable(s, d)


def test_hurwitz_verdict_agrees_with_numerical_eigenvalues(rng):
    """Routh-Hurwitz (S < 0 and D < 0) against numpy's eigenvalues of the Jacobian, both signs of S and D."""
    s = rng.normal(0, 50, 200)
    d = rng.normal(0, 10, 200)
    theta = rng.uniform(0.01, 5, 200)
    numeric = np.all(np.linalg.eigvals(jacobian(s, d, theta)).real < 0, axis=-1)
    np.testing.assert_array_equal(hurwitz_stable(s, d), numeric)


def test_mass_just_above_the_top_joint_is_judged_by_eq_1(model):
    """Mass 1 nm above L1L2: theta_1 ~ 1e-18 kg m^2, yet the verdict follows the signs of S and D.

    The segment's S and D do not depend on theta; where both are negative it is
    self-stable by eq. 1 (Routh-Hurwitz), and its slow eigenvalue is -S/D (see above).
    """
    top = model.geometry.cor_heights[0]
    near = set_parameter(model, "body.mass_height", top + 1e-9)
    pcsa = np.array([0.13, 0.0, 9.96]) * 1e-4  # the minimum stabilising PCSA of this model [m^2]
    result = segment_stability(near, 0.0, 0.0, pcsa)
    s, d = result.stiffness[0], result.damping[0]
    assert s < 0 and d < 0 and result.inertia[0] < 1e-12
    assert result.self_stable[0]
    np.testing.assert_allclose(result.eigenvalues[0, 0].real, -s / d, rtol=1e-6)


def test_gravity_alone_destabilises_every_segment(model):
    """No muscle, K = 0: an inverted pendulum at every CoR, lambda = +-sqrt(g / r).

    At E = Lambda = 0 the mass is straight above CoR k at r_k = 0.326 - y_k, and
    theta_k = m r_k^2, so S/theta = g / r_k (docs/model.md, "Gravity sign").
    """
    result = segment_stability(model, 0.0, 0.0, ZERO)
    assert not result.self_stable.any()
    r = model.body.mass_height - np.asarray(model.geometry.cor_heights)
    np.testing.assert_allclose(result.eigenvalues[:, 0].real, np.sqrt(model.body.gravity / r), rtol=1e-12)


def test_printed_gravity_sign_makes_a_centre_not_self_stable(model):
    """With the printed sign and no muscle, S = -m g r, D = 0: eigenvalues +-j sqrt(g/r).

    Real parts are 0, so the segments are not (asymptotically) self-stable; yet
    the paper needs 35 cm^2 at A, which is why the sign must be an erratum.
    """
    printed = model.replace(errata=Errata(gravity_sign="printed"))
    result = segment_stability(printed, 0.0, 0.0, ZERO)
    np.testing.assert_allclose(result.eigenvalues.real, 0.0, atol=1e-12)
    assert not result.self_stable.any()


def test_stiff_ligaments_stabilise_without_much_muscle(model):
    """K = 1000 N m/rad exceeds gravity (m g r <= 40 * 9.81 * 0.321 = 126 N m/rad)
    plus any muscle term at 1 cm^2 per muscle (|dM/dalpha| < 10 N m/rad per cm^2
    for lever arms below 0.2 m), and 1 cm^2 gives D < 0: stable at every CoR."""
    stiff = model.replace(passive=Passive(stiffness=1000.0))
    result = segment_stability(stiff, 0.04, 0.02, np.full(3, 1e-4))
    assert result.self_stable.all()


def _vertical_threshold(m):
    """PCSA per muscle [m^2] at which S_k = 0 for the single-vertical-fibre pair, by hand.

    S_k = m g r_k + 2 p sigma (f_l a b/(a+b) - d^2 f_l'), see test_mechanics.
    """
    d, top = 0.12, 0.24
    y = np.asarray(m.geometry.cor_heights)
    a, b, l0 = top - y, y, top
    f_l = muscle.force_length(l0, 1.2 * l0, m.fibre)
    f_l_slope = muscle.force_length_slope(l0, 1.2 * l0, m.fibre)
    per_pcsa = 2 * m.fibre.specific_tension * (f_l * a * b / (a + b) - d**2 * f_l_slope)
    gravity = m.body.mass * m.body.gravity * (m.body.mass_height - y)
    return np.where(per_pcsa < 0, -gravity / per_pcsa, np.inf)


def test_vertical_pair_is_stable_just_above_its_hand_threshold(vertical_model):
    threshold = _vertical_threshold(vertical_model)
    k = int(np.argmin(threshold))  # most favourable CoR with a finite threshold
    assert np.isfinite(threshold[k])
    above = segment_stability(vertical_model, 0.0, 0.0, [1.01 * threshold[k]])
    below = segment_stability(vertical_model, 0.0, 0.0, [0.99 * threshold[k]])
    assert above.self_stable[k] and not below.self_stable[k]
    # CoRs whose hand threshold is infinite (buckling term wins) are never stable.
    hopeless = ~np.isfinite(threshold)
    assert not segment_stability(vertical_model, 0.0, 0.0, [MAX_PLAUSIBLE_PCSA]).self_stable[hopeless].any()


def test_passive_stiffness_conventions(model):
    """'physical' subtracts K from dM/dalpha; 'paper' subtracts K theta_k (eq. 2 as printed)."""
    base = mechanics.segment_coefficients(model, 0.02, 0.03)
    phys = mechanics.segment_coefficients(model.replace(passive=Passive(15.0, "physical")), 0.02, 0.03)
    paper = mechanics.segment_coefficients(model.replace(passive=Passive(15.0, "paper")), 0.02, 0.03)
    np.testing.assert_allclose(base.stiffness(np.zeros(6)) - phys.stiffness(np.zeros(6)), 15.0)
    np.testing.assert_allclose(base.stiffness(np.zeros(6)) - paper.stiffness(np.zeros(6)), 15.0 * base.inertia)


def test_self_stable_margin():
    eigs = np.array([[-0.5 + 1j, -0.5 - 1j]])
    assert self_stable(eigs)[0] and not self_stable(eigs, margin=1.0)[0]


@pytest.mark.parametrize(
    ("E", "L", "pcsa", "field"),
    [
        (0.5, 0.0, ZERO, "E"),
        (0.0, -0.2, ZERO, "Lambda"),
        (np.nan, 0.0, ZERO, "E"),
        (0.0, 0.0, [1, 2], "pcsa"),
        (0.0, 0.0, [-1, 0, 0], "pcsa"),
    ],
)
def test_bad_input_names_the_field(model, E, L, pcsa, field):
    with pytest.raises(ParameterError) as info:
        segment_stability(model, E, L, pcsa)
    assert info.value.field == field


SEGMENT_KEYS = (
    "name",
    "stiffness_Nm_per_rad",
    "damping_Nms_per_rad",
    "inertia_kgm2",
    "eigenvalues",
    "self_stable",
    "slowest_time_constant_s",
    "marginal",
    "counter_torque_Nm",
)
"""Every key of a segment in ``spinectl stability --json``: the unit in the name."""


def test_to_dict_schema_and_values(model):
    """Units in the key names; PCSA in cm^2 by muscle; ||CT|| the norm of the listed torques."""
    stiff = model.replace(passive=Passive(15.0, "paper"))
    result = segment_stability(stiff, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    doc = result.to_dict(stiff)
    assert doc["E_m"] == 0.03 and doc["Lambda_m"] == 0.04
    assert doc["K_per_s2"] == 15 and "K_Nm_per_rad" not in doc  # eq. 2 as printed: K in 1/s^2
    assert doc["K_convention"] == "paper" and doc["pcsa_source"] == "given"
    assert doc["pcsa_cm2"] == dict.fromkeys(model.muscle_names, pytest.approx(10.0))
    assert doc["total_pcsa_cm2"] == pytest.approx(60)
    assert [s["name"] for s in doc["segments"]] == list(result.segment_names)
    for k, seg in enumerate(doc["segments"]):
        assert tuple(seg) == SEGMENT_KEYS
        assert seg["eigenvalues"] == [[z.real, z.imag] for z in result.eigenvalues[k]]
        assert seg["self_stable"] == all(re < 0 for re, _ in seg["eigenvalues"])
    norm = sum(s["counter_torque_Nm"] ** 2 for s in doc["segments"]) ** 0.5
    assert doc["counter_torque_norm_Nm"] == pytest.approx(norm)
    assert doc["all_self_stable"] == all(s["self_stable"] for s in doc["segments"])
    assert result.to_dict(stiff, pcsa_source="min_pcsa")["pcsa_source"] == "min_pcsa"


def test_table(model):
    result = segment_stability(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    lines = result.table(model).splitlines()
    assert lines[0] == source.header(model)
    assert lines[1] == "E = 3.00 cm, Lambda = 4.00 cm"
    assert lines[2].startswith("PCSA [cm^2]: ") and lines[2].endswith("(total 60.00)")  # 6 x 10 cm^2, given
    rows = lines[5 : 5 + len(result.segment_names)]
    assert [row.split()[0] for row in rows] == list(result.segment_names)
    assert [float(row.split()[-1]) for row in rows] == pytest.approx(result.counter_torque, abs=5e-4)
    assert lines[-3].startswith(f"||CT|| = {result.counter_torque_norm:.3f} N m; slowest time constant ")
    assert lines[-2].startswith(
        "joint by joint (each CoR alone, the others fixed; the paper's criterion): self-stable: "
    )
    assert lines[-1].startswith("chain (all 5 CoRs free): ")
    assert "(minimum stabilising, chosen activation)" in result.table(model, pcsa_source="min_pcsa")


def test_table_prints_real_eigenvalues_as_real_numbers():
    """A real root (discriminant D^2 + 4 theta S >= 0, imaginary part exactly 0) is printed as a real number,
    not ``0.608 +0.000j``; a complex pair keeps its imaginary parts. Which is which: from the eigenvalues
    (the README's point in the preset wagner2012 has both kinds)."""
    from spinectl.model.config import load_preset

    model = load_preset("wagner2012")
    result = segment_stability(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    rows = result.table(model).splitlines()[5 : 5 + len(result.segment_names)]
    for row, eig in zip(rows, result.eigenvalues, strict=True):
        complex_pair = bool(np.any(eig.imag))
        assert row.count("j") == (2 if complex_pair else 0), row
        if not complex_pair:
            assert [float(w) for w in row.split()[4:6]] == pytest.approx(eig.real, abs=5e-4)
    assert {bool(np.any(e.imag)) for e in result.eigenvalues} == {True, False}  # both kinds are checked here


def test_a_result_has_no_truth_value(model):
    """``if result:`` is ambiguous (every segment or any?): a TypeError naming all_self_stable."""
    result = segment_stability(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    with pytest.raises(TypeError, match="use result.all_self_stable"):
        bool(result)
    assert result.all_self_stable == bool(np.all(result.self_stable))


def test_a_pcsa_in_cm2_given_as_m2_is_refused(model):
    """pcsa=[10, 10, 10] (cm^2 out of habit) is 10 m^2 per muscle: refused, naming the cm^2 slip and the fix."""
    with pytest.raises(ParameterError, match=r"if you meant 10 cm\^2, pass 0.001"):
        segment_stability(model, 0.03, 0.04, [10, 10, 10])
    segment_stability(model, 0.03, 0.04, [MAX_PLAUSIBLE_PCSA] * 3)  # the bound itself is allowed


def test_slowest_time_constant_against_the_roots_of_the_characteristic_polynomial():
    """-1 / max Re(lambda) over the segments, lambda the roots of theta s^2 - D s - S (numpy.roots, a second
    method); a segment that only just beats gravity (S = -0.1 N m/rad, D = -15 N m s/rad) recovers in about
    |D|/|S| = 150 s; inf for a segment that is not stable, NaN for NaN input."""
    s, d, theta = np.array([-0.1, -40.0, -5.0]), np.array([-15.0, -20.0, -2.0]), np.array([2.0, 1.5, 1.0])
    roots = [np.roots([t, -dk, -sk]) for sk, dk, t in zip(s, d, theta, strict=True)]
    expected = -1.0 / max(r.real.max() for r in roots)
    assert slowest_time_constant(s, d, theta) == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(15.0 / 0.1, rel=0.01)
    assert slowest_time_constant([-1.0, 0.5], [-1.0, -1.0], [1.0, 1.0]) == np.inf
    assert np.isnan(slowest_time_constant([np.nan, -1.0], [-1.0, -1.0], [1.0, 1.0]))
    rows = slowest_time_constant(np.stack([s, s * 2]), np.stack([d, d]), np.stack([theta, theta]))
    assert rows.shape == (2,) and rows[1] < rows[0]  # stiffer: faster


def test_the_result_reports_its_slowest_time_constant(model):
    """StabilityResult: the property, the JSON key and the table line agree with the function."""
    point = optimise.solve_point(model, 0.03, 0.04)
    result = segment_stability(model, 0.03, 0.04, point.pcsa)
    tau = float(slowest_time_constant(result.stiffness, result.damping, result.inertia))
    assert result.slowest_time_constant == tau and result.to_dict(model)["slowest_time_constant_s"] == tau
    assert f"slowest time constant {tau:.4g} s" in result.table(model)


def test_a_segment_that_does_not_return_has_no_time_constant_in_the_table(model):
    """10 cm^2 per muscle at (3, 4) cm leaves a segment unstable (S > 0): the time constant is inf, and the
    table says "none", as spinectl margins does, not "inf s"."""
    result = segment_stability(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    assert not result.all_self_stable and result.slowest_time_constant == np.inf
    assert "slowest time constant none (not every segment returns)\n" in result.table(model)


def test_the_header_names_k_in_the_unit_its_convention_gives_and_what_it_adds():
    """Under eq. 2 as printed (``wagner2012_mass_free``) K = 15 is 15 1/s^2 and adds K theta_k [N m/rad] at each
    CoR; the header printed "K = 15 N m/rad" where 5.0 N m/rad was added at L1L2. The values it names now are
    the drop of S from K = 0 to K = 15 in the same table (a second reading: S itself, at a given PCSA);
    'physical' K stays N m/rad and adds K."""
    from spinectl.model.config import load_preset

    pcsa = [10e-4, 10e-4, 10e-4]
    paper = load_preset("wagner2012_mass_free")
    assert paper.passive.convention == "paper"
    k0, k15 = (segment_stability(paper.replace(passive=Passive(k, "paper")), 0.03, 0.04, pcsa) for k in (0.0, 15.0))
    line = k15.table(paper.replace(passive=Passive(15.0, "paper"))).splitlines()[0]
    assert "K = 15 1/s^2, convention paper: K theta_k = " in line and "N m/rad, convention" not in line
    named = [float(x) for x in line.split("K theta_k = ")[1].split(" N m/rad")[0].split(", ")]
    np.testing.assert_allclose(named, k0.stiffness - k15.stiffness, rtol=1e-3)
    assert 4.9 < named[0] < 5.1  # L1L2: 5.0 N m/rad
    physical = paper.replace(passive=Passive(15.0, "physical"))
    assert "K = 15 N m/rad, convention physical" in source.header(physical)
    assert "theta" not in source.header(physical)
    assert source.header(paper.replace(passive=Passive(15.0, "paper"))).endswith(  # Model.replace keeps the source
        "K = 15 1/s^2, convention paper (K theta_k [N m/rad] at each CoR); overridden: passive.stiffness"
    )


def test_eigenvalues_of_a_stiffness_whose_discriminant_overflows():
    """S = -+1e308 N m/rad (``--K 1e308``): D^2 + 4 theta S overflows, the roots do not. Closed forms with theta = 0.79,
    D = -0.01: S < 0 gives D / (2 theta) +- j sqrt(-S / theta - D^2 / (4 theta^2)) (the D^2 term below rounding);
    S > 0 gives real roots of product -S / theta and sum D / theta, about +-sqrt(S / theta)."""
    theta, d = 0.79, -0.01
    with np.errstate(over="raise"):
        stable, unstable = eigenvalues(np.array([-1e308, 1e308]), d, theta)
    assert stable[0].real == pytest.approx(d / (2 * theta), rel=1e-12)
    assert stable[0].imag == pytest.approx(np.sqrt(1e308 / theta), rel=1e-12) and stable[1] == np.conj(stable[0])
    assert unstable.imag.tolist() == [0.0, 0.0]
    assert unstable[0].real == pytest.approx(np.sqrt(1e308 / theta), rel=1e-12)
    assert unstable[0].real * unstable[1].real == pytest.approx(-1e308 / theta, rel=1e-12)
    ordinary = eigenvalues(np.array([-50.0, 20.0]), d, theta)  # the unscaled path, as before
    np.testing.assert_allclose(ordinary.prod(axis=-1), [50.0 / theta, -20.0 / theta], rtol=1e-14)


def test_every_verdict_names_its_criterion_and_the_chain_stands_beside_it(model):
    """The JSON names the criterion of the segments' verdicts and carries the chain's own, whose eigenvalues
    are those of the state matrix [[0, I], [M^-1 K, M^-1 D]] built here from chain.py's matrices (a second
    assembly); the table prints both verdicts with their criteria."""
    from spinectl.model import chain, geometry

    point = optimise.solve_point(model, 0.03, 0.04)
    result = segment_stability(model, 0.03, 0.04, point.pcsa)
    doc = result.to_dict(model)
    assert doc["criterion"] == "joint by joint (each CoR alone, the others fixed; the paper's criterion)"
    assert doc["chain"]["criterion"] == "chain (all 5 CoRs free)"
    coefficients = chain.chain_coefficients(model, 0.03, 0.04)
    mass = chain.mass_matrix(model, geometry.cor_positions(0.03, 0.04, model.geometry))
    n = mass.shape[0]
    a = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [
                np.linalg.solve(mass, coefficients.stiffness(point.pcsa)),
                np.linalg.solve(mass, coefficients.damping(point.pcsa)),
            ],
        ]
    )
    expected = np.linalg.eigvals(a)
    got = np.array([complex(*z) for z in doc["chain"]["eigenvalues"]])
    assert np.sort_complex(got) == pytest.approx(np.sort_complex(expected), rel=1e-9, abs=1e-9)
    growing = expected.real[expected.real >= 0]
    assert doc["chain"]["stable"] == (growing.size == 0) and doc["chain"]["growing_modes"] == growing.size
    assert doc["chain"]["growth_time_constants_s"] == pytest.approx(sorted(1 / growing))
    table = result.table(model)
    assert "joint by joint (each CoR alone" in table and "chain (all 5 CoRs free): " in table


def test_a_segment_that_returns_only_slowly_is_flagged_marginal():
    """At the minimum PCSA of the wagner2012 preset at (0, 0) L1L2 has S = -0.10, D = -14.67 N m s/rad: its
    slow root is about S / D, a time constant of |D / S| = 147 s (eq. 1), above the 10 s threshold, so it is
    'marginal' in the table and the JSON, and the verdict line says so; the stiffer segments are not."""
    from spinectl.model.config import load_preset
    from spinectl.model.stability import MARGINAL_TIME_CONSTANT

    model = load_preset("wagner2012")
    point = optimise.solve_point(model, 0.0, 0.0)
    result = segment_stability(model, 0.0, 0.0, point.pcsa)
    approx = np.abs(result.damping / result.stiffness)  # the slow root's closed form for |S| << D^2 / theta
    expected = result.self_stable & (approx > MARGINAL_TIME_CONSTANT)
    assert result.marginal.tolist() == expected.tolist() and expected[0] and not expected[-1]
    doc = result.to_dict(model)
    assert doc["marginal_segments"] == [n for n, f in zip(result.segment_names, expected, strict=True) if f]
    assert result.time_constants[0] == pytest.approx(approx[0], rel=0.01)
    assert f"{result.segment_names[0]} marginal: slowest time constant" in result.verdict()
