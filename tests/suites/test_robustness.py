"""Bad input always gets a clean answer: invalid parameters, odd geometries, failing solvers, interrupted writes.

The classes of bad input tried here are listed in ``docs/robustness.md``.
"""

from __future__ import annotations

import dataclasses
import datetime
import importlib
import math
import os
import re
import warnings

import cvxpy as cp
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spinectl.atomic import atomic_path, atomic_write_text, check_folder, check_writable
from spinectl.cli import main
from spinectl.errors import ConfigError, ModelError, OutputError, ParameterError, SpinectlError
from spinectl.model import config, geometry, muscle
from spinectl.model.checks import validate_position
from spinectl.model.params import MAX_FIBRES, Model, MusclePair
from spinectl.model.stability import segment_stability
from spinectl.optimise.problem import OK_STATUSES
from spinectl.optimise.reference import solve_point

TMP = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
PCSA = np.array([10.0, 10.0, 10.0]) * 1e-4
"""A moderate PCSA per pair [m^2] (10 cm^2) for evaluating random models."""


# --- writing test values as TOML ----------------------------------------------------------


def toml_value(value) -> str:
    """``value`` as a TOML value (inline tables and mixed arrays included)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, str):
        return '"' + "".join(_toml_char(c) for c in value) + '"'
    if isinstance(value, (datetime.date, datetime.datetime)):
        return value.isoformat()
    if isinstance(value, list):
        return "[" + ", ".join(map(toml_value, value)) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {toml_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(value)


def _toml_char(c: str) -> str:
    if c in '"\\':
        return "\\" + c
    if c.isprintable() and c != "\x7f":
        return c
    return f"\\u{ord(c):04x}" if ord(c) <= 0xFFFF else f"\\U{ord(c):08x}"


def toml_document(dotted: str, value) -> str:
    """A configuration file setting one field; ``muscles.KEY`` sets it in the preset's pair ``straight``
    (a new pair must give its attachments)."""
    section, key = dotted.split(".")
    if section == "muscles":
        name = "" if key == "name" else 'name = "straight"\n'
        return f"[[muscles]]\n{name}{key} = {toml_value(value)}\n"
    return f"[{section}]\n{key} = {toml_value(value)}\n"


def load_text(tmp_path, text: str | bytes) -> Model:
    path = tmp_path / "model.toml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    return config.load_config(path)


# --- invalid values, one field at a time ---------------------------------------------------

REAL, REAL_OR_INF, INT, CHOICE, LABEL, LABELS, REALS, PAIR = (
    "real",
    "real or inf",
    "int",
    "choice",
    "label",
    "labels",
    "reals",
    "pair",
)
KINDS = {
    "body.mass": REAL,
    "body.mass_height": REAL,
    "body.gravity": REAL,
    "body.radius_of_gyration": REAL,
    "geometry.cor_names": LABELS,
    "geometry.side_names": LABELS,
    "geometry.cor_heights": REALS,
    "geometry.spine_length": REAL,
    "geometry.spline_bc": CHOICE,
    "geometry.eccentricity_range": PAIR,
    "geometry.lordosis_range": PAIR,
    **{f"fibre.{f.name}": REAL for f in dataclasses.fields(Model().fibre) if f.name != "law"},
    "fibre.law": CHOICE,
    "muscles.name": LABEL,
    "muscles.upper": PAIR,
    "muscles.lower": PAIR,
    "muscles.spread": REAL,
    "muscles.fibres": INT,
    "passive.stiffness": REAL,
    "passive.convention": CHOICE,
    **{f"local.{f.name}": REAL for f in dataclasses.fields(Model().local)},
    **{f"levels.{f.name}": REAL for f in dataclasses.fields(Model().levels)},
    "errata.gravity_sign": CHOICE,
    "errata.eccentric_constant": CHOICE,
    "optimisation.activation": CHOICE,
    "optimisation.stability_margin": REAL,
    "optimisation.relative_margin": REAL,
    "optimisation.damping_margin": REAL,
    "optimisation.pcsa_max": REAL_OR_INF,
    "optimisation.ct_tolerance": REAL,
    "optimisation.solver_tolerance": REAL,
    "reflex.delay": REAL,
    "reflex.activation_time_constant": REAL,
    "reflex.pade_order": INT,
    "reflex.activation": REAL,
    "reflex.gains": CHOICE,
    **{f"reflex.{name}": REAL for name in ("gain_factor", "damping_ratio", "kp", "kd")},
    **{f"reflex.sim_{name}": REAL for name in ("duration", "time_step", "perturbation", "divergence")},
}
"""The kind of every parameter: which wrong types to try on it."""

OUT_OF_RANGE = {
    "body.mass": [0, -0.0, -1.0, -1e300, 1000.5, 1e6],  # 1e6 kg: every point "infeasible", no reason given
    "body.mass_height": [0.0, -0.326, 0.1],  # 0.1: below the top CoR L1L2 (0.145 m)
    "body.gravity": [0.0, -9.81],
    "body.radius_of_gyration": [-1e-3],
    "geometry.cor_heights": [
        [0.005, 0.035, 0.072, 0.106, 0.145],  # increasing
        [0.145, 0.145, 0.072, 0.035, 0.005],  # repeated
        [0.145, 0.106, 0.072, 0.035, -0.005],  # below P2
        [0.2, 0.106, 0.072, 0.035, 0.005],  # above P1 (spine length 0.176 m)
        [],
    ],
    "geometry.cor_names": [["a", "b", "c", "d"], ["a", "b", "c", "d", "a"], ["a", "b", "", "d", "e"]],
    "geometry.side_names": [["right"], ["left", "left"], ["right", ""], ["a", "b", "c"]],
    "geometry.spine_length": [0.0, -0.176],
    "geometry.eccentricity_range": [[0.1, -0.1], [0.05, 0.05], [0.0]],
    "geometry.lordosis_range": [[0.1, -0.1], [0.0, 0.0, 0.1]],
    "fibre.specific_tension": [0.0, -2.5e5],
    "fibre.optimal_length_ratio": [1.0, 0.9, 0.0],
    "fibre.k1": [0.0, -0.96],
    "fibre.k2": [0.0],
    "fibre.fast_twitch": [-0.01, 1.01],
    "fibre.vmax_slow": [0.0],
    "fibre.vmax_fast_gain": [-1.0],
    "fibre.hill_a": [0.0],
    "fibre.hill_b": [-0.25],
    "fibre.eccentric_enhancement": [1.0, 0.5],
    "muscles.name": ["", "   ", "a\nb", "tab\there"],
    "muscles.upper": [[0.12, -0.1], [0.12, 0.0], [0.1]],  # (0.12, 0.0) is the default lower
    "muscles.lower": [[0.1, 0.2, 0.3]],
    "muscles.spread": [-0.01, 0.24, 1.0],  # the default straight fibre is 0.24 m long
    "muscles.fibres": [0, -1, MAX_FIBRES + 1, 10**30],
    "passive.stiffness": [-1.0],
    "local.stiffness_gain": [0.0, -10.0],
    "local.lever_arm": [0.0, -0.07],
    "local.length": [0.0, -0.035],
    "local.cost_weight": [-1.0],
    "levels.mass": [-1.8],
    "levels.radius_of_gyration": [-0.06],
    "levels.weight_in_gravity": [-0.5, 1.5],
    "optimisation.stability_margin": [-0.1, 3.1e4, 1e308],  # above m g r = 1000 kg x 30 m/s^2 x 1 m
    "optimisation.relative_margin": [-0.1, 1.5],
    "optimisation.damping_margin": [-0.1, 1.1e4, 1e308],  # above 2 sqrt(1000 kg m^2 x 3e4 N m/rad) = 10954
    "optimisation.pcsa_max": [0.0, -1.0, -math.inf],
    "optimisation.ct_tolerance": [-1e-3, 1.5, 1e308],  # above 1: a slack beyond twice the minimum
    "optimisation.solver_tolerance": [0.0, 1e-13, 1e-3],
    "reflex.delay": [-0.1, 10.5],
    "reflex.activation_time_constant": [-0.05, 50.0],  # 50: milliseconds typed as seconds
    "reflex.pade_order": [0, 11],
    "reflex.activation": [-0.1, 10.5],
    "reflex.gain_factor": [1.0, 0.5],
    "reflex.damping_ratio": [0.0],
    "reflex.kp": [-1.0],
    "reflex.kd": [-1.0],
    "reflex.sim_duration": [0.0],
    "reflex.sim_time_step": [0.0, 20.0],  # 20 s: not below the 12 s duration
    "reflex.sim_perturbation": [0.0, 0.3],  # 0.3 rad: not below the 0.2 rad divergence angle
    "reflex.sim_divergence": [-0.1, 2.0],
}
"""Values of the right type that the physics forbids, each blamed on the field itself."""

texts = st.text(st.characters(exclude_categories=("Cs",)), max_size=12)
tables = st.dictionaries(st.sampled_from(["a", "mass", "x"]), st.integers(0, 3), min_size=1, max_size=2)
not_numbers = st.one_of(st.booleans(), texts, st.dates(), tables, st.lists(st.floats(-1, 1), max_size=3), st.just([]))
non_finite = st.sampled_from([math.nan, math.inf, -math.inf])
numbers = st.one_of(st.integers(-(10**30), 10**30), st.floats())


def invalid_values(dotted: str):
    """A strategy of values that ``dotted`` must reject, by its kind."""
    kind = KINDS[dotted]
    by_kind = {
        REAL: st.one_of(not_numbers, non_finite),
        REAL_OR_INF: st.one_of(not_numbers, st.sampled_from([math.nan, -math.inf])),
        INT: st.one_of(not_numbers, st.floats(), st.integers(max_value=0), st.integers(min_value=MAX_FIBRES + 1)),
        CHOICE: st.one_of(st.booleans(), numbers, st.dates(), tables, st.lists(texts, max_size=2), texts),
        LABEL: st.one_of(st.booleans(), numbers, st.dates(), tables, st.lists(texts, max_size=2)),
        LABELS: st.one_of(
            st.booleans(), numbers, texts, tables, st.lists(st.one_of(numbers, st.booleans()), min_size=5, max_size=5)
        ),
        REALS: st.one_of(
            st.booleans(), numbers, texts, tables, st.lists(st.one_of(not_numbers, non_finite), min_size=1, max_size=5)
        ),
        PAIR: st.one_of(
            st.booleans(),
            numbers,
            texts,
            tables,
            st.lists(st.floats(-1, 1), min_size=3, max_size=4),
            st.lists(st.one_of(not_numbers, non_finite), min_size=2, max_size=2),
        ),
    }[kind]
    if kind == CHOICE:
        allowed = {"natural", "clamped", "not-a-knot", "physical", "paper", "destabilising", "printed"}
        allowed |= {"corrected", "paired", "independent", "rule", "explicit", "wagner2012"}
        by_kind = by_kind.filter(lambda x: not (isinstance(x, str) and x in allowed))
    return st.one_of(by_kind, st.sampled_from(OUT_OF_RANGE[dotted])) if dotted in OUT_OF_RANGE else by_kind


def _all_fields() -> set[str]:
    model = Model()
    out = set()
    for section in dataclasses.fields(Model):
        value = getattr(model, section.name)
        cls = type(value[0]) if isinstance(value, tuple) else type(value)
        out |= {f"{section.name}.{f.name}" for f in dataclasses.fields(cls)}
    return out


def test_every_parameter_has_its_bad_values_listed():
    """A new parameter must be added to KINDS (and OUT_OF_RANGE), so that its validation is tried."""
    assert set(KINDS) == _all_fields()
    assert set(OUT_OF_RANGE) <= set(KINDS)


@TMP
@given(st.sampled_from(sorted(KINDS)).flatmap(lambda f: st.tuples(st.just(f), invalid_values(f))))
def test_an_invalid_value_is_a_parameter_error_naming_the_field(tmp_path, case):
    dotted, value = case
    with pytest.raises(ParameterError) as info:
        load_text(tmp_path, toml_document(dotted, value))
    expected = dotted.replace("muscles.", "muscles.0.")
    field = info.value.field
    assert field == expected or field.startswith(expected + "["), (field, str(info.value))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("text", "field", "needle"),
    [
        ('[[muscles]]\nname = "straight"\n[[muscles]]\nname = "straight"\n', "muscles.1.name", "unique"),
        ("[geometry]\ncor_heights = [0.145, 0.072]\n", "geometry.cor_names", "one name per entry of cor_heights"),
        ("[geometry]\nspine_length = 0.1\n", "geometry.cor_heights", "spine_length=0.1"),
        ('[[muscles]]\nname = "straight"\nlower = [0.12, 0.3]\n', "muscles.0.upper", "must lie above lower"),
        (
            '[[muscles]]\nname = "straight"\nupper = [1e308, 1.0]\nlower = [-1e308, 0.0]\n',
            "muscles.0.upper",
            "modelled trunk's scale",  # was "finite distance"; lengths above 1 m are refused first
        ),
        ("[body]\nmass_height = 0.145\n", "body.mass_height", "above the top centre of rotation L1L2"),
        ("[geometry]\ncor_heights = [0.3, 0.1]\ncor_names = ['a', 'b']\n", "geometry.cor_heights", "on the spine"),
        ("body = 3\n", "body", "must be a table"),
        ("muscles = 3\n", "muscles", "array of tables"),
        ("muscles = []\n", "muscles", "at least one"),
        ("muscles = [1]\n", "muscles.0", "must be a table"),
        ('[[muscles]]\nname = "straight"\nupper = { x = 1 }\n', "muscles.0.upper", "must be a list"),
        ('preset = "nope"\n', "preset", "must be one of"),
        ("preset = 3\n", "preset", "must be one of"),
        ('preset = ""\n', "preset", "must be one of"),
    ],
)
def test_cross_field_and_shape_errors_name_a_field(tmp_path, text, field, needle):
    with pytest.raises(ParameterError) as info:
        load_text(tmp_path, text)
    assert info.value.field == field and needle in str(info.value)


@TMP
@given(st.sampled_from(sorted(KINDS)), st.sampled_from("abcdefghijklmnopqrstuvwxyz_"))
def test_a_misspelt_key_is_a_config_error_naming_it(tmp_path, dotted, extra):
    """One extra letter keeps difflib's similarity above its 0.6 cutoff: 2n / (2n + 1) >= 2/3."""
    section, key = dotted.split(".")
    typo = key + extra
    with pytest.raises(ConfigError) as info:
        load_text(tmp_path, toml_document(f"{section}.{typo}", 1.0))
    assert info.value.field == (f"muscles.0.{typo}" if section == "muscles" else f"{section}.{typo}")
    assert "did you mean" in str(info.value)


@TMP
@given(st.one_of(st.text(max_size=200), st.binary(max_size=200)))
def test_any_file_gives_a_model_or_a_clean_error(tmp_path, text):
    """Random text and bytes: not TOML, not UTF-8, unknown keys, or (rarely) a valid file."""
    if isinstance(text, str):
        text = text.encode("utf-8", "surrogatepass")
    try:
        assert isinstance(load_text(tmp_path, text), Model)
    except SpinectlError as exc:
        assert "\n" not in str(exc)


scalars = st.one_of(st.booleans(), numbers, texts, st.dates())
documents = st.dictionaries(
    st.sampled_from(["body", "geometry", "fibre", "muscles", "passive", "errata", "optimisation", "preset", "bodyy"]),
    st.one_of(
        scalars,
        st.dictionaries(st.sampled_from(["mass", "name", "upper", "stiffness", "k1", "spread", "x"]), scalars),
        st.lists(st.dictionaries(st.sampled_from(["name", "upper", "lower", "fibres"]), scalars), max_size=2),
    ),
    max_size=3,
)


@TMP
@given(documents)
def test_random_documents_give_a_model_or_a_clean_error(tmp_path, document):
    text = "\n".join(f"{key} = {toml_value(value)}" for key, value in document.items())
    try:
        load_text(tmp_path, text)
    except SpinectlError as exc:
        assert "\n" not in str(exc)


def test_unreadable_files_are_config_errors(tmp_path):
    bad_utf8 = tmp_path / "latin1.toml"
    bad_utf8.write_bytes("# Lordose \xe9\n".encode("latin-1"))
    deep = tmp_path / "deep.toml"
    deep.write_text("[body]\nmass = " + "[" * 5000 + "]" * 5000 + "\n")
    cases = {
        bad_utf8: "not UTF-8",
        deep: "too deeply",
        tmp_path: "not a regular file",
        tmp_path / "missing.toml": "file not found",
        "a\x00b.toml": "file not found|cannot read",  # which one depends on the Python version
        "x" * 5000: "cannot read",
    }
    if os.path.exists("/dev/zero"):
        cases["/dev/zero"] = "not a regular file"  # would never end if read
    for path, needle in cases.items():
        with pytest.raises(ConfigError, match=needle) as info:
            config.load_config(path)
        assert info.value.field == "config"


def test_set_parameter_rejects_odd_paths(model):
    for dotted in ("muscles.²", "muscles.-1", "muscles.9", "body.mass.x", "nope"):
        with pytest.raises(ConfigError):
            config.set_parameter(model, dotted, 1.0)


def test_python_api_rejects_wrong_sections_and_normalises_numbers():
    with pytest.raises(ParameterError, match="must be a Body"):
        Model(body=3)
    with pytest.raises(ParameterError) as info:
        Model(muscles=(Model().muscles[0], "x"))
    assert info.value.field == "muscles.1"
    pair = MusclePair(upper=np.array([0.12, 0.24]), lower=[np.float32(0.12), np.int64(0)], fibres=np.int64(3))
    assert pair.upper == (0.12, 0.24) and type(pair.lower[1]) is float and type(pair.fibres) is int
    assert math.copysign(1.0, MusclePair(spread=-0.0).spread) == 1.0  # -0.0 stored as 0.0


# --- odd geometries and extreme magnitudes -------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(
    st.floats(-0.1, 0.1),
    st.floats(-0.1, 0.1),
    st.integers(0, 4),
    st.sampled_from(["upper", "lower"]),
)
def test_an_attachment_on_a_cor_is_a_model_error(E, L, k, end):
    """Place one attachment exactly where CoR k sits at (E, Lambda): a fibre with zero length
    on one side of the joint. Every entry point that knows E and Lambda says so."""
    base = Model()
    cor = tuple(geometry.cor_positions(E, L, base.geometry)[k])
    ends = {"upper": (0.1, 0.3), "lower": (0.1, -0.05), end: cor}
    model = base.replace(muscles=(MusclePair("p", ends["upper"], ends["lower"], 0.0, 1),))
    for call in (
        lambda: validate_position(model, E, L),
        lambda: segment_stability(model, E, L, [1e-3]),
        lambda: solve_point(model, E, L),
    ):
        with pytest.raises(ModelError, match=f"muscles.0.{end}.*{base.geometry.cor_names[k]}"):
            call()


def test_a_line_of_action_through_every_cor_is_allowed():
    """A vertical fibre at x = d with E = -d passes through every CoR: h = 0, so no torque,
    and (as in test_mechanics' closed form with d = 0) dM/dalpha = sigma f_l a b / (a + b),
    a and b the distances from the CoR to the two attachments: the buckling term alone."""
    d, top = 0.05, 0.24
    model = Model(muscles=(MusclePair("straight", (d, top), (d, 0.0), 0.0, 1),))
    coeffs = segment_stability(model, -d, 0.0, [1e-4]).coefficients
    np.testing.assert_allclose(coeffs.torque_per_pcsa[:, 0], 0.0, atol=1e-12)
    y = np.asarray(model.geometry.cor_heights)
    a, b = top - y, y
    f_l = muscle.force_length(top, model.fibre.optimal_length_ratio * top, model.fibre)
    expected = model.fibre.specific_tension * f_l * a * b / (a + b)
    np.testing.assert_allclose(coeffs.stiffness_per_pcsa[:, 0], expected, rtol=1e-9)


HUGE_OR_TINY = st.sampled_from([1e300, 1e200, 1e150, 1e17, 5e-324, 1e-300])
FREE_REALS = sorted(
    f
    for f, kind in KINDS.items()
    if kind == REAL and f not in ("fibre.fast_twitch", "muscles.spread", "geometry.spine_length")
)


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(FREE_REALS), HUGE_OR_TINY)
def test_extreme_magnitudes_give_finite_answers_or_a_model_error(tmp_path_factory, dotted, value):
    """Parameters far outside any body's scale (unit typos): the load succeeds or names the
    field; evaluating then gives finite numbers or a ModelError, never a numpy warning,
    NaN or a raw exception; the optimiser gives a status."""
    try:
        model = load_text(tmp_path_factory.mktemp("m"), toml_document(dotted, value))
    except ParameterError:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            result = segment_stability(model, 0.03, 0.04, PCSA)
        except ModelError as exc:
            assert "orders of magnitude" in str(exc)
            return
        assert np.isfinite(result.eigenvalues).all() and np.isfinite(result.counter_torque).all()
        warnings.simplefilter("ignore", UserWarning)  # cvxpy's "solution may be inaccurate"
        optimum = solve_point(model, 0.03, 0.04)
    assert optimum.ok == np.isfinite(optimum.min_pcsa)


@pytest.mark.parametrize(
    ("dotted", "value"),
    [
        # (radius_of_gyration and specific_tension of 1e300 are refused at load now: MAX_BODY_LENGTH,
        # SPECIFIC_TENSION_RANGE; tests/model/test_params.py)
        ("body.mass", 5e-324),  # inertia underflows to 0: division by zero
        ("fibre.k2", 5e-324),
    ],
)
def test_overflow_is_a_model_error_or_a_solver_status(tmp_path, dotted, value):
    """Before: a raw OverflowError or ValueError, or numpy warnings and NaN results."""
    model = load_text(tmp_path, toml_document(dotted, value))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ModelError, match="orders of magnitude"):
            segment_stability(model, 0.03, 0.04, PCSA)
        try:
            optimum = solve_point(model, 0.03, 0.04)
        except ModelError as exc:
            assert "orders of magnitude" in str(exc)
        else:  # finite but extreme problem data: the solver's status says it
            assert not optimum.ok and np.isnan(optimum.min_pcsa)


def test_a_huge_spine_length_stays_finite(tmp_path):
    """spine_length = 1e300 m: scipy's spline raised ValueError; the closed-form spine line (docs/model.md)
    keeps every coefficient finite, without a numpy warning; the solver answers with a status. Validation
    refuses lengths above 1 m now, so the model is built around it (the spine line is still the defence)."""
    with pytest.raises(ParameterError, match="modelled trunk's scale"):
        load_text(tmp_path, toml_document("geometry.spine_length", 1e300))
    geometry = Model().geometry
    object.__setattr__(geometry, "spine_length", 1e300)
    model = Model(geometry=geometry)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = segment_stability(model, 0.03, 0.04, PCSA)
        optimum = solve_point(model, 0.03, 0.04)
    assert np.all(np.isfinite(result.stiffness)) and np.all(np.isfinite(result.damping))
    assert optimum.status and (optimum.ok == np.isfinite(optimum.min_pcsa))


def test_huge_pcsa_is_refused_before_any_arithmetic(model):
    """1e300 m^2 once overflowed to a ModelError; now a PCSA above checks.MAX_PCSA (1e100 m^2 per muscle, where
    the torques overflow) is refused up front, naming the bound (smaller ones, even beyond any muscle, are
    answers: a computed optimum can be fed back)."""
    with pytest.raises(ParameterError, match="at most 1e\\+100 m\\^2 per muscle"):
        segment_stability(model, 0.0, 0.0, np.full(3, 1e300))


# --- solver failures --------------------------------------------------------------------------


def _failing_solve(monkeypatch, failing=("CLARABEL", "SCS"), raises=None, status=None):
    """Make ``Problem.solve`` raise ``raises`` or report ``status`` for the ``failing`` solvers."""
    real = cp.Problem.solve

    def solve(self, *args, solver=None, **kwargs):
        if solver not in failing:
            return real(self, *args, solver=solver, **kwargs)
        if raises is not None:
            raise raises
        self._status = status  # a status without a solution, as a broken solver would leave it
        return None

    monkeypatch.setattr(cp.Problem, "solve", solve)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"raises": cp.error.SolverError("Solver 'CLARABEL' failed")},
        {"raises": ZeroDivisionError("numerical trouble")},
        {"raises": ValueError("Problem data contains NaN")},
        {"status": cp.UNBOUNDED},
        {"status": cp.USER_LIMIT},
        {"status": None},
    ],
)
def test_a_failing_solver_is_a_status_not_an_exception(monkeypatch, model, kwargs):
    _failing_solve(monkeypatch, **kwargs)
    optimum = solve_point(model, 0.03, 0.04)
    assert optimum.status == "solver_error"
    assert np.isnan(optimum.min_pcsa) and np.isnan(optimum.pcsa).all() and np.isnan(optimum.counter_torque).all()


def test_the_fallback_solver_answers_when_clarabel_fails(monkeypatch, model):
    reference = solve_point(model, 0.03, 0.04)
    _failing_solve(monkeypatch, failing=("CLARABEL",), raises=cp.error.SolverError("Clarabel failed"))
    fallback = solve_point(model, 0.03, 0.04)
    assert fallback.status in OK_STATUSES
    # SCS is a first-order method: agreement to its default tolerance (about 1e-4), not Clarabel's.
    np.testing.assert_allclose(fallback.min_pcsa, reference.min_pcsa, rtol=1e-3)
    np.testing.assert_allclose(fallback.counter_torque_norm, reference.counter_torque_norm, rtol=1e-3)


def test_optimal_without_a_solution_is_not_reported_as_optimal(monkeypatch, model):
    _failing_solve(monkeypatch, status=cp.OPTIMAL)
    optimum = solve_point(model, 0.03, 0.04)
    assert optimum.status != cp.OPTIMAL or np.isfinite(optimum.min_pcsa)


# --- atomic outputs -----------------------------------------------------------------------


class Interrupted(Exception):
    """Stands for anything that stops a writer midway (error, Ctrl-C, full disk)."""


@TMP
@given(st.binary(max_size=64), st.binary(max_size=64), st.sampled_from([Interrupted, KeyboardInterrupt]))
def test_an_interrupted_write_leaves_the_previous_file(tmp_path, old, new, stop):
    target = tmp_path / "result.json"
    target.write_bytes(old)
    with pytest.raises(stop), atomic_path(target) as tmp:
        tmp.write_bytes(new[: len(new) // 2])  # half-written
        raise stop()
    assert target.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.json"]  # no temporary left


def test_an_interrupted_folder_write_leaves_the_previous_folder(tmp_path):
    target = tmp_path / "grid.zarr"
    target.mkdir()
    (target / "chunk").write_text("old")
    with pytest.raises(Interrupted), atomic_path(target, directory=True) as tmp:
        (tmp / "chunk").write_text("half")
        raise Interrupted
    assert (target / "chunk").read_text() == "old"
    with atomic_path(target, directory=True) as tmp:
        (tmp / "chunk").write_text("new")
    assert (target / "chunk").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grid.zarr"]


def test_outputs_get_ordinary_permissions(tmp_path):
    """mkstemp creates 0600 files; an output must be as readable as any file the user writes."""
    umask = os.umask(0o022)
    try:
        fresh = atomic_write_text(tmp_path / "new.json", "{}")
        assert fresh.stat().st_mode & 0o777 == 0o644
        (tmp_path / "old.json").write_text("{}")
        os.chmod(tmp_path / "old.json", 0o640)
        assert atomic_write_text(tmp_path / "old.json", "[]").stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(umask)


def test_an_unwritable_target_is_an_output_error(tmp_path):
    (tmp_path / "taken").mkdir()
    (tmp_path / "taken" / "inside").write_text("keep")
    (tmp_path / "a_file").write_text("keep")
    for target in (tmp_path / "taken", tmp_path / "a_file" / "below.json"):
        with pytest.raises(OutputError, match="cannot write"):
            atomic_write_text(target, "new")
    assert (tmp_path / "taken" / "inside").read_text() == "keep"
    assert (tmp_path / "a_file").read_text() == "keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "taken"]


def test_check_writable_fails_where_the_write_would_and_leaves_nothing(tmp_path):
    """The pre-flight of long jobs: the same OutputError as atomic_write_text above, before any work."""
    (tmp_path / "taken").mkdir()
    (tmp_path / "a_file").write_text("keep")
    for target in (tmp_path / "taken", tmp_path / "a_file" / "below.json"):
        with pytest.raises(OutputError, match="cannot write"):
            check_writable(target)
    assert check_writable(tmp_path / "new" / "out.nc") == tmp_path / "new" / "out.nc"
    assert check_writable(tmp_path / "a_file") == tmp_path / "a_file"
    assert (tmp_path / "a_file").read_text() == "keep"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a_file", "taken"]  # no file, and no folder, made


def test_a_failed_write_removes_the_folders_it_made(tmp_path):
    """A write into folders that do not exist yet makes them; if the writer fails (a full disk, Ctrl-C), they go
    too: nothing is left (before: ``export --out full/sub/d.xml`` onto a full disk left an empty ``sub``); a
    folder that held something before stays."""
    from spinectl.atomic import atomic_path, staged_directory

    (tmp_path / "kept").mkdir()
    for target in (tmp_path / "new" / "deeper" / "out.txt", tmp_path / "kept" / "new" / "out.txt"):
        with pytest.raises(OSError, match="No space"), atomic_path(target) as tmp:
            tmp.write_text("half")
            raise OSError(28, "No space left on device")
    with pytest.raises(KeyboardInterrupt), staged_directory(tmp_path / "made" / "figures") as stage:
        (stage / "a.png").write_bytes(b"x")
        raise KeyboardInterrupt
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["kept"]
    with atomic_path(tmp_path / "new" / "out.txt") as tmp:  # a write that succeeds keeps its folder
        tmp.write_text("whole")
    assert (tmp_path / "new" / "out.txt").read_text() == "whole"


def _links(folder) -> None:
    """Symbolic links of every kind that can stand in an output's way, in ``folder``."""
    (folder / "a_file").write_text("keep")
    links = {"loop.nc": "loop.nc", "l1": "l2", "l2": "l1", "dangling": "nowhere", "to_file": "a_file"}
    for name, to in links.items():
        (folder / name).symlink_to(to)


@pytest.mark.parametrize(
    ("out", "needle"),
    [
        ("loop.nc", "'loop.nc' is a symbolic link loop"),  # the case of the issue
        ("loop.nc/x.nc", "'loop.nc' is a symbolic link loop"),
        ("sub/../l1/deeper/x.nc", "'sub/../l1' is a symbolic link loop"),  # two links, further down
        ("dangling/x.nc", "'dangling' is a symbolic link to 'nowhere', which does not exist"),
        ("to_file/x.nc", "'to_file' is a symbolic link to a file ('a_file'), not a folder"),
        ("a_file/x.nc", "'a_file' is a file, not a folder"),
    ],
)
def test_a_path_that_cannot_lead_to_an_output_says_which_part_and_why(tmp_path, monkeypatch, capsys, out, needle):
    """A symbolic link loop, a link to nothing or to a file where a folder is wanted, anywhere on the
    output's path: one line naming that part, exit 2, before the job, nothing written (before: ``File
    exists``, or the loop's link silently replaced by the output)."""
    _links(tmp_path)
    (tmp_path / "sub").mkdir()
    monkeypatch.setattr(importlib.import_module("spinectl.landscape.sweep"), "sweep", lambda *a, **k: pytest.fail())
    monkeypatch.chdir(tmp_path)
    before = sorted((p.name, p.is_symlink()) for p in tmp_path.iterdir())
    assert main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", out]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"spinectl: error: cannot write {out!r}: {needle}") and err.count("\n") == 1
    for write in (check_writable, lambda p: atomic_write_text(p, "new"), check_folder):  # every writer's check
        with pytest.raises(OutputError, match=re.escape(needle)):
            write(out)
    assert sorted((p.name, p.is_symlink()) for p in tmp_path.iterdir()) == before


def test_an_output_that_is_a_symbolic_link_is_written_where_it_leads(tmp_path):
    """A link to a file, or to a file yet to be made: the output replaces the file it leads to and the
    link stays (as a link to a folder does for folder outputs) (before: the link itself was replaced)."""
    _links(tmp_path)
    (tmp_path / "later.json").symlink_to("made/later.json")
    for link, real in [("to_file", "a_file"), ("later.json", "made/later.json")]:
        atomic_write_text(tmp_path / link, "new")
        assert (tmp_path / link).is_symlink() and (tmp_path / real).read_text() == "new"


@pytest.mark.parametrize(
    ("argv", "job"),
    [
        (
            ["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", "taken.nc"],
            ("spinectl.landscape.sweep", "sweep"),
        ),
        (["calibrate", "--grid", "3", "--history", "a_file/h.csv"], ("spinectl.paper.calibration", "calibrate")),
    ],
)
def test_long_jobs_check_their_outputs_before_they_start(tmp_path, monkeypatch, capsys, argv, job):
    """A typo in --out costs a second, not the run: the job itself is never called."""
    (tmp_path / "taken.nc").mkdir()
    (tmp_path / "a_file").write_text("keep")
    monkeypatch.setattr(importlib.import_module(job[0]), job[1], lambda *a, **k: pytest.fail("the job ran"))
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("spinectl: error: cannot write") and err.count("\n") == 1


def test_every_text_file_is_opened_with_an_explicit_encoding():
    """Every ``open``, ``read_text``, ``write_text`` in spinectl names its encoding.

    docs/robustness.md, "a locale that is not UTF-8".

    Without one Python uses the locale's encoding, e.g. ISO-8859-1, which cannot
    write the report's Λ; binary modes ('rb', 'wb') need none.
    """
    import ast
    import pathlib

    import spinectl

    missing = []
    for path in pathlib.Path(spinectl.__file__).parent.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Call):
                continue
            name = getattr(node.func, "attr", getattr(node.func, "id", None))
            if name not in {"open", "read_text", "write_text"}:
                continue
            own = isinstance(node.func, ast.Attribute) and getattr(node.func.value, "id", None) == "_toml"
            if isinstance(node.func, ast.Name) and name != "open" or own:
                continue  # spinectl's own read_text (model/_toml.py), which names the encoding
            if isinstance(node.func, ast.Attribute) and getattr(node.func.value, "id", None) == "os":
                continue  # os.open: a file descriptor with flags, no text and no encoding
            modes = node.args[1:2] + [k.value for k in node.keywords if k.arg == "mode"]  # positional or mode=
            binary = any(isinstance(m, ast.Constant) and "b" in str(m.value) for m in modes)
            if not binary and not any(k.arg == "encoding" for k in node.keywords):
                missing.append(f"{path.name}:{node.lineno}")
    assert missing == []


def _full_disk(*args, **kwargs):
    import errno

    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.parametrize(
    ("command", "patched"),
    [
        (["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", "{out}/old.nc"], "xarray.Dataset.to_netcdf"),
        (["plot", "{out}/old.nc", "--out", "{out}"], "matplotlib.backends.backend_agg.FigureCanvasAgg.print_png"),
        (["reproduce", "--points", "3", "--out", "{out}"], "matplotlib.backends.backend_agg.FigureCanvasAgg.print_png"),
        (["margins", "--plot", "{out}"], "matplotlib.backends.backend_agg.FigureCanvasAgg.print_png"),
        (
            ["study", "{out}/study.toml", "--out", "{out}/s.zarr", "--scheduler", "synchronous"],
            "xarray.Dataset.to_zarr",
        ),
    ],
)
def test_a_full_disk_is_one_line_and_keeps_the_previous_files(tmp_path, monkeypatch, capsys, command, patched):
    """OSError(ENOSPC) from the writer (simulated: the disk cannot be filled in a test) is an OutputError:
    one line naming the file, exit 2, the previous output intact, no temporary left (docs/robustness.md)."""
    from spinectl.landscape import sweep

    sweep.write_sweep(Model(), [0.0, 0.08], [0.0, 0.08], tmp_path / "old.nc")  # a previous output, and plot's input
    (tmp_path / "study.toml").write_text("[axes]\nE = [0.0, 0.08]\nLambda = [0.0]\n", encoding="utf-8")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    argv = [a.format(out=tmp_path) for a in command]
    monkeypatch.setattr(patched, _full_disk)
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2 and "No space left on device" in err and err.count("\n") == 1 and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_full_disk_while_writing_text_is_an_output_error(tmp_path, monkeypatch):
    """atomic_write_text (calibrate's preset and history, JSON outputs) on a full disk: OutputError, old text kept."""
    target = tmp_path / "preset.toml"
    target.write_text("old", encoding="utf-8")
    monkeypatch.setattr("pathlib.Path.write_text", _full_disk)
    with pytest.raises(OutputError, match="preset.toml'.*No space left on device"):
        atomic_write_text(target, "new")
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["preset.toml"]


def test_other_errors_of_a_writer_are_not_called_output_errors(tmp_path):
    """Only the file system's refusals (atomic.DEVICE_ERRORS) become OutputError; a writer's own bug stays itself."""
    with pytest.raises(FileNotFoundError), atomic_path(tmp_path / "x") as tmp:
        tmp.write_text("x", encoding="utf-8")
        (tmp_path / "missing-input").read_text(encoding="utf-8")
    assert list(tmp_path.iterdir()) == []


def test_a_mass_beyond_any_human_upper_body_is_refused_with_the_reason(tmp_path, capsys):
    """body.mass = 1e6 kg (grams typed as kilograms): before, every point of a sweep came out
    'infeasible' without a word why; now the model names the limit (params.MAX_MASS) and its reason."""
    from spinectl.model.config import set_parameter
    from spinectl.model.params import MAX_MASS

    with pytest.raises(ParameterError, match=r"body\.mass: must be at most 1000 kg, more than any human upper body"):
        set_parameter(Model(), "body.mass", 1e6)
    assert set_parameter(Model(), "body.mass", MAX_MASS).body.mass == MAX_MASS  # the limit itself is allowed
    config = tmp_path / "heavy.toml"
    config.write_text("[body]\nmass = 1e6\n")
    code = main(
        ["sweep", "--config", str(config), "--E", "0:0:1", "--Lambda", "0:0:1", "--out", str(tmp_path / "x.nc")]
    )
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "body.mass: must be at most 1000 kg" in err


@pytest.mark.parametrize(
    ("assignment", "needle"),
    [
        (
            "optimisation.damping_margin=1e308",
            "damping_margin: must be at most 1.1e+04 N m s/rad, the critical damping",
        ),
        ("optimisation.damping_margin=2e4", "damping_margin: must be at most 1.1e+04 N m s/rad"),
        (
            "optimisation.stability_margin=1e308",
            "stability_margin: must be at most 3e+04 N m/rad, the gravity stiffness",
        ),
        ("optimisation.ct_tolerance=1e308", "ct_tolerance: must be at most 1, a slack of 100 %"),
    ],
)
def test_a_margin_beyond_any_body_is_one_line_at_the_validator(capsys, assignment, needle):
    """A required margin beyond any body the bounds allow is refused where it is read: one line, exit 2.

    The bounds follow from the other bounds (``params.bounds``): m g r = 1000 kg x 30 m/s^2 x 1 m = 3e4 N m/rad,
    its critical damping 2 sqrt(m r^2 x m g r) = 2 sqrt(1000 x 3e4) = 1.1e4 N m s/rad. Before, 1e308 gave four
    lines of numpy's overflow warnings and then a false "no activation stabilises".
    """
    assert main(["stability", "--set", assignment]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("spinectl: error: optimisation.") and needle in err
