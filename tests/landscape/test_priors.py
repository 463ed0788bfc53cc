"""The atlas file's schema: its priors, their truncated distributions and the one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from spinectl.errors import ConfigError
from spinectl.landscape.priors import parse_atlas

HEAD = "[atlas]\nsamples = 8\n"


def _prior(**fields) -> str:
    row = {"parameter": "body.mass", "distribution": "uniform", "bounds": [30.0, 50.0], "source": "s"} | fields
    lines = ["[[prior]]"]
    for key, value in row.items():
        if value is not None:
            lines.append(f"{key} = {value!r}".replace("'", '"'))
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        (HEAD + _prior(distribution="gamma"), "prior[0].distribution", "unknown family 'gamma'"),
        (HEAD + _prior(distribution="normal", mean=40.0, sd=1.0, bounds=[60.0, 70.0]), "prior[0].bounds", "no mass"),
        (HEAD + _prior(parameter="lordosis_angle"), "prior[0].parameter", "did you mean 'lordosis_angle_deg'"),
        (HEAD + _prior(parameter="body.mas"), "body.mas", "did you mean 'mass'"),
        (HEAD + _prior(parameter="geometry.spline_bc"), "prior[0].parameter", "not a number"),
        (HEAD + _prior(bounds=[50.0, 30.0]), "prior[0].bounds", "low < high"),
        (HEAD + _prior(source=None), "prior[0].source", "required"),
        (HEAD + _prior(colour=1), "prior[0].colour", "unknown key"),
        ("[atlas]\nsamples = 12\n" + _prior(), "atlas.samples", "power of 2"),
        (HEAD + _prior() + _prior(), "prior[1].parameter", "has a prior already"),
        (HEAD, "prior", "one or more"),
    ],
)
def test_bad_atlas_files_are_one_error_naming_the_field(text, field, words):
    """Each mistake is a ConfigError naming its field, with the words of the rule (and a 'did you mean')."""
    with pytest.raises(ConfigError) as raised:
        parse_atlas(text)
    assert raised.value.field == field and words in str(raised.value)
    assert "\n" not in str(raised.value)


def test_truncated_normal_quantiles_are_scipys_truncnorm():
    """Prior.ppf of a truncated normal equals scipy.stats.truncnorm's quantiles (a second implementation)."""
    text = HEAD + _prior(
        parameter="lordosis_angle_deg", distribution="truncated normal", mean=49.8, sd=11.2, bounds=[20.0, 90.0]
    )
    prior = parse_atlas(text).priors[0]
    u = np.linspace(0.01, 0.99, 25)
    reference = stats.truncnorm((20.0 - 49.8) / 11.2, (90.0 - 49.8) / 11.2, loc=49.8, scale=11.2).ppf(u)
    np.testing.assert_allclose(prior.ppf(u), reference, rtol=1e-9)


def test_lognormal_takes_the_quantitys_mean_and_sd():
    """'lognormal' with mean m and sd s: the untruncated draws have mean m and sd s (scipy's moments)."""
    prior = parse_atlas(HEAD + _prior(distribution="lognormal", mean=40.0, sd=8.0, bounds=None)).priors[0]
    mean, var = prior._frozen().stats("mv")
    assert float(mean) == pytest.approx(40.0) and math.sqrt(float(var)) == pytest.approx(8.0)


def test_the_shipped_priors_load_and_cite():
    """examples/atlas.toml parses; every row has a DOI or says 'unverified'."""
    from pathlib import Path

    from spinectl.landscape.priors import load_atlas

    spec = load_atlas(Path(__file__).parents[2] / "examples" / "atlas.toml")
    assert spec.names[0] == "lordosis_angle_deg" and spec.samples == 1024
    assert all("doi:" in p.source or p.source.startswith("unverified") for p in spec.priors)


@pytest.mark.parametrize(
    ("fields", "words"),
    [
        ({"parameter": "lordosis_angle_deg", "bounds": [20.0, 170.0]}, "geometry.lordosis_range"),
        ({"parameter": "eccentricity_m", "distribution": "normal", "mean": 0.03, "sd": 0.01, "bounds": None}, "range"),
        ({"parameter": "body.mass", "bounds": [-10.0, 50.0]}, "mass"),
    ],
)
def test_priors_whose_draws_leave_the_model_are_refused(fields, words):
    """Every draw must be a valid model: a prior reaching beyond a parameter's range is refused when read."""
    with pytest.raises(ConfigError) as raised:
        parse_atlas(HEAD + _prior(**fields))
    assert raised.value.field == "prior[0].bounds" and words in str(raised.value)


def test_the_base_model_is_the_default_preset_or_the_files_or_the_callers():
    """No model key: spinectl.DEFAULT_PRESET as every command; the file's key; a given model wins; --set is named."""
    from spinectl import DEFAULT_PRESET
    from spinectl.model.config import load_preset
    from spinectl.model.source import source_of

    assert source_of(parse_atlas(HEAD + _prior()).model).preset == DEFAULT_PRESET
    from_file = parse_atlas('[atlas]\nsamples = 8\nmodel = "default"\n' + _prior()).model
    assert source_of(from_file).preset == "default" and from_file == load_preset("default")
    given = parse_atlas(
        '[atlas]\nsamples = 8\nmodel = "default"\n' + _prior(),
        model=load_preset(DEFAULT_PRESET),
        assignments=["passive.stiffness=15"],
    ).model
    assert source_of(given).preset == DEFAULT_PRESET and source_of(given).overridden == ("passive.stiffness",)
    assert given.passive.stiffness == 15.0


@pytest.mark.parametrize(
    ("fields", "field", "words"),
    [
        # sd / mean = 2.5e298: (sd / mean)^2 overflowed math's float power (an OverflowError traceback); in logarithms
        # the lognormal is valid, and so wide that every draw lies below 1e-166 kg, which body.mass refuses
        ({"distribution": "lognormal", "mean": 40.0, "sd": 1e300, "bounds": None}, "prior[0].bounds", "must be > 0"),
        # a median of 1e-600 kg: below the smallest double, its quantiles NaN (they were, with the same traceback)
        ({"distribution": "lognormal", "mean": 1e-300, "sd": 1e300, "bounds": None}, "prior[0].sd", "not finite"),
        ({"distribution": "lognormal", "mean": 1e-300, "sd": 1.0, "bounds": None}, "prior[0].sd", "not finite"),
        # the quantile at eps of N(40, 1e308) is -8.1e308, beyond the largest double
        ({"distribution": "normal", "mean": 40.0, "sd": 1e308, "bounds": None}, "prior[0].sd", "from -inf to inf"),
        # the uniform's width 2e308 overflows to infinity: scipy's quantiles NaN
        ({"bounds": [-1e308, 1e308]}, "prior[0].bounds", "not finite in double precision"),
        # a lognormal of mean 1e300 kg: its draws are 1e300 (it said 'draws from nan to nan', the spread lost)
        ({"distribution": "lognormal", "mean": 1e300, "sd": 1.0, "bounds": None}, "prior[0].bounds", "at most 1000 kg"),
    ],
)
def test_moments_beyond_double_precision_are_one_line(fields, field, words):
    """Huge or tiny moments of a prior: one ConfigError naming the field, never a traceback or 'nan'."""
    with pytest.raises(ConfigError) as raised:
        parse_atlas(HEAD + _prior(**fields))
    assert raised.value.field == field and words in str(raised.value) and "nan to nan" not in str(raised.value)


@pytest.mark.parametrize("sd", [1e-300, 1e-12])
def test_a_lognormal_of_tiny_sd_draws_its_mean(sd):
    """sd / mean below 1e-154: (sd / mean)^2 underflowed to 0, a lognormal of no spread whose quantiles were NaN
    (refused as 'must be finite (got nan)'); the draws are the mean to double precision (sigma = sd / mean)."""
    prior = parse_atlas(HEAD + _prior(distribution="lognormal", mean=40.0, sd=sd, bounds=None)).priors[0]
    np.testing.assert_allclose(prior.ppf([1e-9, 0.5, 1 - 1e-9]), 40.0, rtol=1e-9)


@pytest.mark.parametrize("sd", [1e-320, 1e-310])
def test_a_truncated_normal_of_a_subnormal_sd_is_quiet_and_draws_its_mean(sd):
    """sd in the subnormal range: numpy's overflow warning leaked onto stderr twice ("overflow encountered in
    divide", exit 0); the draws are the mean, and nothing is warned (warnings are errors here)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        text = HEAD + _prior(distribution="truncated normal", mean=40.0, sd=sd, bounds=[30.0, 50.0])
        prior = parse_atlas(text).priors[0]
        np.testing.assert_allclose(prior.ppf([1e-9, 0.5, 1 - 1e-9]), 40.0, rtol=1e-12)


@pytest.mark.parametrize("parameter", ["reflex.pade_order", "muscles.1.fibres"])
def test_a_prior_on_an_integer_field_says_it_is_a_count(parameter):
    """An integer field (a count): the reason is that priors draw real numbers (it was 'must be an integer
    (got 2.0000000000000004)' against the bounds, blaming the draws)."""
    with pytest.raises(ConfigError) as raised:
        parse_atlas(HEAD + _prior(parameter=parameter, bounds=[2.0, 4.0]))
    assert raised.value.field == "prior[0].parameter" and "is an integer" in str(raised.value)
    assert "real numbers" in str(raised.value)
