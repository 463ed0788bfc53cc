"""Cohort priors for the atlas: the file's schema, its distributions and their draws (docs/atlas.md).

An atlas file has one ``[atlas]`` table (the sampling and the verdicts' limits) and one
``[[prior]]`` table per varied parameter: its distribution family, the family's parameters,
its bounds and its published source. Read with the project's TOML schema engine
(:mod:`spinectl.model._toml`), so unknown keys, parameters and families are one line that names
the field, with a "did you mean".
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from ..errors import ConfigError, ParameterError
from ..model import _toml
from ..model.config import DEFAULT_PRESET, apply_overrides, load_model_spec, load_preset
from ..model.params import Model
from ..model.source import header

FAMILIES = ("normal", "lognormal", "uniform", "truncated normal")
"""Distribution families of a prior; every draw is truncated to the prior's bounds."""

GEOMETRY = ("lordosis_angle_deg", "lordosis_m", "eccentricity_m")
"""Parameters of a prior that are no field of the model: the position (E, Lambda), Lambda also as an angle."""

PRIOR_KEYS = ("parameter", "distribution", "mean", "sd", "bounds", "source")
ATLAS_KEYS = (
    "samples",
    "seed",
    "model",
    "eccentricity_m",
    "lordosis_m",
    "counter_torque_limit_Nm",
    "local_pcsa_limit_cm2",
    "chain",
    "chunk_size",
    "bootstrap",
    "confidence",
)

PAPER_OPTIMUM = (0.03, 0.04)
"""(E, Lambda) of the paper's optimum C [m] (paper, Discussion: E ~ 3 cm, Lambda ~ 4 cm; Figure 4, position C)."""

VERDICTS = {
    "stabilisable_joint_by_joint": "some global activation within optimisation.pcsa_max makes every segment "
    "self-stable (a feasible minimum PCSA; joint by joint)",
    "counter_torque_within_limit": "every counter torque CT_k within +-counter_torque_limit_Nm (joint by joint)",
    "chain_stabilisable_locally": "the chain (all CoRs free) stabilised by local muscle within local_pcsa_limit_cm2",
    "spine_stable_at_delay": "the reflex loop of every segment stable at the reflex delay (joint by joint)",
}
"""The verdicts and the criterion each names."""


def model_line(model: Model, varied) -> str:
    """The atlas's base model as its outputs name it: its header, K only where no prior draws it.

    Parameters
    ----------
    model : Model
        The base model (the parameters no prior varies).
    varied : iterable of str
        The parameters the priors vary (:attr:`AtlasSpec.names`).

    Returns
    -------
    str
        :func:`~spinectl.model.source.header` of the base model, with "K drawn from its prior" in place of its K
        where ``passive.stiffness`` has a prior (the base model's K is no draw's: it printed K = 0).
    """
    if "passive.stiffness" not in set(varied):
        return header(model)
    return header(model, stiffness=f"K drawn from its prior, convention {model.passive.convention}")


LEAST_MASS = 1e-9
"""Smallest share of a distribution's mass that its bounds may hold: less is 'no mass' (a typo)."""


@dataclasses.dataclass(frozen=True)
class Prior:
    """One varied parameter: a distribution truncated to bounds, with its source.

    Attributes
    ----------
    parameter : str
        A name of :data:`GEOMETRY` or a dotted field of the model (``config show``), in its unit.
    distribution : str
        One of :data:`FAMILIES`. 'lognormal' takes the mean and sd of the quantity itself.
    mean, sd : float
        Of the untruncated distribution (not used by 'uniform').
    bounds : tuple of float
        (low, high); the range of 'uniform'; +-inf where unbounded (normal, lognormal only).
    source : str
        The published source (author, year, journal, doi), or 'unverified: ...'.
    """

    parameter: str
    distribution: str
    mean: float = math.nan
    sd: float = math.nan
    bounds: tuple[float, float] = (-math.inf, math.inf)
    source: str = ""

    def _frozen(self):
        """The untruncated scipy.stats distribution."""
        from scipy import stats

        if self.distribution == "uniform":
            return stats.uniform(self.bounds[0], self.bounds[1] - self.bounds[0])
        if self.distribution == "lognormal":  # mean m, sd s of X: log X ~ N(mu, sigma^2)
            sigma2 = _log_variance(self.mean, self.sd)
            return stats.lognorm(math.sqrt(sigma2), scale=math.exp(math.log(self.mean) - sigma2 / 2))
        return stats.norm(self.mean, self.sd)

    def mass(self) -> float:
        """The share of the distribution's mass within the bounds [1].

        Returns
        -------
        float
            F(high) - F(low).
        """
        dist = self._frozen()
        with np.errstate(all="ignore"):  # a spread near the smallest double: the answer is checked, not warned of
            return float(dist.cdf(self.bounds[1]) - dist.cdf(self.bounds[0]))

    def ppf(self, u) -> np.ndarray:
        """The truncated distribution's quantiles: F^-1(F(low) + u (F(high) - F(low))).

        Parameters
        ----------
        u : array_like
            Probabilities in (0, 1).

        Returns
        -------
        numpy.ndarray
            Values of the parameter in its unit, the shape of ``u``, within the bounds.
        """
        dist = self._frozen()
        with np.errstate(all="ignore"):  # numpy's overflow warnings at sd ~ 1e-320: the quantiles are checked
            low, high = dist.cdf(self.bounds[0]), dist.cdf(self.bounds[1])
            return np.clip(dist.ppf(low + np.asarray(u, float) * (high - low)), *self.bounds)


def _log_variance(mean: float, sd: float) -> float:
    """sigma^2 = log(1 + (sd / mean)^2) of a lognormal of that mean and sd, without overflow or underflow.

    In logarithms: the ratio of 1e300 to 40 squared overflows, and that of 1e-300 to 40 squared
    underflows to 0, a lognormal of no spread whose quantiles scipy gives as NaN.
    """
    log_ratio = math.log(sd) - math.log(mean)
    if log_ratio > 300:  # (sd/mean)^2 would overflow: log(1 + r^2) = 2 log r + log(1 + r^-2), the last below 1e-260
        return 2 * log_ratio
    if log_ratio < -20:  # log(1 + r^2) = r^2 to double precision (r^2 < 1e-17); r^2 may underflow, kept as sigma^2
        return math.exp(2 * log_ratio) or math.ulp(0.0)
    return math.log1p(math.exp(2 * log_ratio))


@dataclasses.dataclass(frozen=True)
class AtlasSpec:
    """An atlas file, validated: the base model, the priors and the settings of ``[atlas]``.

    Attributes
    ----------
    model : Model
        The parameters that no prior varies; its source names its preset, file and overridden fields
        (:mod:`spinectl.model.source`).
    priors : tuple of Prior
        One per varied parameter, in the file's order.
    samples : int
        Saltelli base samples N, a power of 2; N (D + 2) evaluations for D priors.
    seed : int
        Seeds the scrambled Sobol' sequence and SALib's bootstrap.
    eccentricity, lordosis : float
        E and Lambda [m] where no prior varies them (default: the paper's optimum, 3 and 4 cm).
    counter_torque_limit : float
        ``abs(CT_k)`` limit of the local muscles [N m] (paper, Discussion: +-30 N m).
    local_pcsa_limit : float
        The local muscles' PCSA limit per joint [cm^2] (paper, Discussion: 17 cm^2).
    chain : bool
        Also the chain's least local stiffness (one stacked SDP per chunk).
    chunk_size : int
        Draws per chunk.
    bootstrap : int
        SALib's bootstrap resamples for the confidence intervals.
    confidence : float
        Level of every confidence interval (Wilson and bootstrap).
    """

    model: Model
    priors: tuple[Prior, ...]
    samples: int = 4096
    seed: int = 0
    eccentricity: float = PAPER_OPTIMUM[0]
    lordosis: float = PAPER_OPTIMUM[1]
    counter_torque_limit: float = 30.0
    local_pcsa_limit: float = 17.0
    chain: bool = True
    chunk_size: int = 1024
    bootstrap: int = 100
    confidence: float = 0.95

    @property
    def names(self) -> list[str]:
        """The varied parameters, in order."""
        return [p.parameter for p in self.priors]


def load_atlas(path: str | Path, model: Model | None = None, assignments=()) -> AtlasSpec:
    """Read and validate an atlas file (docs/atlas.md).

    Parameters
    ----------
    path : str or Path
        The TOML file.
    model : Model, optional
        The base model (``--preset``, ``--config``), instead of the file's ``[atlas] model``.
    assignments : sequence of str
        ``SECTION.FIELD=VALUE`` laid over the base model (``--set``).

    Returns
    -------
    AtlasSpec

    Raises
    ------
    ConfigError
        Unreadable, not TOML, or any field invalid: one line naming the field.
    """
    path = Path(path)
    text = _toml.read_text(path, "atlas")
    return parse_atlas(text, source=str(path), base_dir=path.parent, model=model, assignments=assignments)


def parse_atlas(
    text: str, source: str = "atlas", base_dir: str | Path = ".", model: Model | None = None, assignments=()
) -> AtlasSpec:
    """Validate the text of an atlas file into an :class:`AtlasSpec`.

    Parameters
    ----------
    text : str
        TOML with ``[atlas]`` and ``[[prior]]`` tables.
    source : str
        Named in a syntax error.
    base_dir : str or Path
        Where a relative ``model`` path is looked for.
    model : Model, optional
        The base model, instead of the file's ``[atlas] model`` (the command line's ``--preset`` or
        ``--config`` wins over the file). Neither: the preset :data:`~spinectl.model.config.DEFAULT_PRESET`,
        as for every command.
    assignments : sequence of str
        ``SECTION.FIELD=VALUE`` laid over the base model (``--set``), named in its source as overridden.

    Returns
    -------
    AtlasSpec

    Raises
    ------
    ConfigError
        An unknown key, family or parameter (with a "did you mean"), bounds that exclude all
        the mass, a value of the wrong type: one line naming the field.
    """
    data = _toml.parse(text, source)
    _toml.check_keys(data, ("atlas", "prior"))
    head = data.get("atlas", {})
    _toml.check_table(head, "atlas")
    _toml.check_keys(head, ATLAS_KEYS, "atlas")
    base = model if model is not None else _model(head.get("model"), Path(base_dir))
    model = apply_overrides(base, list(assignments))
    rows = data.get("prior", [])
    if not isinstance(rows, list) or not rows:
        raise ConfigError("prior", "must be one or more [[prior]] tables")
    priors = tuple(_prior(i, row, model) for i, row in enumerate(rows))
    _check_distinct(priors)
    settings = _settings(head)
    return AtlasSpec(model=model, priors=priors, **settings)


def _model(spec, base_dir: Path) -> Model:
    """The file's ``model`` key: a preset or a model file; none, the default preset, as every command starts from."""
    if spec is None:
        return load_preset(DEFAULT_PRESET)
    if not isinstance(spec, str):
        raise ConfigError("atlas.model", "must be a preset name or a path to a model file")
    candidate = base_dir / spec
    return load_model_spec(str(candidate) if candidate.is_file() else spec)


def _number(where: str, value, low=-math.inf, high=math.inf, integer=False):
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if integer:
        ok = ok and isinstance(value, int)
    if not ok or not low <= value <= high:
        kind = "an integer" if integer else "a finite number"
        raise ConfigError(where, f"must be {kind} in [{low:g}, {high:g}] (got {value!r})")
    return value


def _settings(head: dict) -> dict:
    out = {}
    samples = _number("atlas.samples", head.get("samples", 4096), 2, 2**24, integer=True)
    if samples & (samples - 1):
        raise ConfigError("atlas.samples", f"must be a power of 2, for the balance of Sobol' points (got {samples})")
    out["samples"] = samples
    out["seed"] = _number("atlas.seed", head.get("seed", 0), 0, 2**32 - 1, integer=True)
    out["eccentricity"] = _number("atlas.eccentricity_m", head.get("eccentricity_m", PAPER_OPTIMUM[0]), -0.1, 0.1)
    out["lordosis"] = _number("atlas.lordosis_m", head.get("lordosis_m", PAPER_OPTIMUM[1]), -0.1, 0.1)
    out["counter_torque_limit"] = _number("atlas.counter_torque_limit_Nm", head.get("counter_torque_limit_Nm", 30.0), 0)
    out["local_pcsa_limit"] = _number("atlas.local_pcsa_limit_cm2", head.get("local_pcsa_limit_cm2", 17.0), 0)
    chain = head.get("chain", True)
    if not isinstance(chain, bool):
        raise ConfigError("atlas.chain", f"must be true or false (got {chain!r})")
    out["chain"] = chain
    out["chunk_size"] = _number("atlas.chunk_size", head.get("chunk_size", 1024), 1, 2**20, integer=True)
    out["bootstrap"] = _number("atlas.bootstrap", head.get("bootstrap", 100), 2, 10**5, integer=True)
    out["confidence"] = _number("atlas.confidence", head.get("confidence", 0.95), 0.5, 0.999)
    return out


def _prior(index: int, row, model: Model) -> Prior:
    where = f"prior[{index}]"
    _toml.check_table(row, where)
    _toml.check_keys(row, PRIOR_KEYS, where)
    for key in ("parameter", "distribution", "source"):
        if not isinstance(row.get(key), str) or not row[key].strip():
            raise ConfigError(f"{where}.{key}", "is required, a non-empty string")
    parameter = _parameter(f"{where}.parameter", row["parameter"], model)
    family = row["distribution"]
    if family not in FAMILIES:
        raise ConfigError(f"{where}.distribution", _toml.unknown_message(family, FAMILIES).replace("key", "family"))
    prior = Prior(parameter, family, *_moments(where, row, family), _bounds(where, row, family), row["source"])
    _check_quantiles(where, prior)
    if prior.mass() < LEAST_MASS:
        raise ConfigError(
            f"{where}.bounds", f"{list(prior.bounds)} hold no mass of the {family} distribution (below {LEAST_MASS:g})"
        )
    _check_range(f"{where}.bounds", prior, model)
    return prior


def _check_quantiles(where: str, prior: Prior) -> None:
    """The prior's extreme quantiles must be finite numbers: moments or bounds beyond double precision are refused.

    A normal of sd 1e308 has its quantile at eps below -8e308 (infinite), a uniform over [-1e308, 1e308] a
    width of infinity, a lognormal of sd 1e300 about a mean of 1e-300 a scale below the smallest double:
    their draws would be infinite or NaN.
    """
    tiny = np.finfo(float).eps  # the atlas draws on (eps, 1 - eps), as in _check_range
    with np.errstate(all="ignore"):
        ends = prior.ppf([tiny, 1.0 - tiny])
    if np.all(np.isfinite(ends)):
        return
    if prior.distribution == "uniform":
        field, given = "bounds", f"bounds {list(prior.bounds)}"
    else:
        field, given = "sd", f"mean {prior.mean:g} and sd {prior.sd:g}"
    span = "" if np.isnan(ends).any() else f" (from {ends[0]:g} to {ends[1]:g})"  # NaN: no numbers at all
    raise ConfigError(
        f"{where}.{field}",
        f"{given} give a {prior.distribution} distribution whose draws are not finite in double precision{span}: "
        "give the moments or bounds of the quantity in its unit",
    )


def _check_range(where: str, prior: Prior, model: Model) -> None:
    """Every draw must be a valid parameter: the prior's extreme quantiles, those of the open cube's ends, are tried."""
    from ..model.clinical import lordosis_from_angle
    from ..model.config import set_parameter

    tiny = np.finfo(float).eps  # the atlas draws on (eps, 1 - eps): these quantiles bound every draw
    ends = [float(x) for x in prior.ppf([tiny, 1.0 - tiny])]
    try:
        if prior.parameter in GEOMETRY:
            values = lordosis_from_angle(ends, model) if prior.parameter == "lordosis_angle_deg" else ends
            name = "eccentricity_range" if prior.parameter == "eccentricity_m" else "lordosis_range"
            low, high = getattr(model.geometry, name)
            if not all(low <= v <= high for v in values):
                raise ConfigError(
                    where, f"draws from {ends[0]:g} to {ends[1]:g} leave geometry.{name} [{low:g}, {high:g}] m"
                )
        else:
            for value in ends:
                set_parameter(model, prior.parameter, value)
    except ConfigError:
        raise
    except ParameterError as exc:
        raise ConfigError(where, f"draws from {ends[0]:g} to {ends[1]:g}: {exc}") from None


def _parameter(where: str, name: str, model: Model) -> str:
    """The prior's parameter: a name of GEOMETRY or a numeric dotted field of the model."""
    if name in GEOMETRY:
        return name
    tree = _toml.to_dict(model)
    if "." not in name:
        raise ConfigError(where, _toml.unknown_message(name, (*GEOMETRY, *tree)).replace("key", "parameter"))
    holder, key = _toml.locate(tree, name)  # unknown parts: "did you mean"
    value = holder[key]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(where, f"{name!r} is not a number; a prior varies a numeric parameter")
    if isinstance(value, int):  # the model's real fields hold floats (validated), its counts ints
        raise ConfigError(
            where,
            f"{name!r} is an integer (a count, {value} in this model), and a prior draws real numbers from a "
            "continuous distribution: vary a real-valued parameter, or set this one with --set or the model file",
        )
    return name


def _moments(where: str, row: dict, family: str) -> tuple[float, float]:
    if family == "uniform":
        for key in ("mean", "sd"):
            if key in row:
                raise ConfigError(f"{where}.{key}", "is not a parameter of 'uniform' (its range is its bounds)")
        return math.nan, math.nan
    mean = _number(f"{where}.mean", row.get("mean"))
    sd = _number(f"{where}.sd", row.get("sd"), 0)
    if sd == 0:
        raise ConfigError(f"{where}.sd", "must be > 0")
    if family == "lognormal" and mean <= 0:
        raise ConfigError(f"{where}.mean", f"must be > 0 for 'lognormal' (got {mean!r})")
    return float(mean), float(sd)


def _bounds(where: str, row: dict, family: str) -> tuple[float, float]:
    if "bounds" not in row:
        if family in ("uniform", "truncated normal"):
            raise ConfigError(f"{where}.bounds", f"is required for '{family}'")
        return (0.0 if family == "lognormal" else -math.inf, math.inf)
    bounds = row["bounds"]
    if not isinstance(bounds, list) or len(bounds) != 2:
        raise ConfigError(f"{where}.bounds", "must be [low, high]")
    low, high = (float(_number(f"{where}.bounds", b)) for b in bounds)
    if not low < high:
        raise ConfigError(f"{where}.bounds", f"must have low < high (got {bounds})")
    return low, high


def _check_distinct(priors) -> None:
    names = [p.parameter for p in priors]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise ConfigError(f"prior[{i}].parameter", f"{name!r} has a prior already")
    if {"lordosis_angle_deg", "lordosis_m"} <= set(names):
        raise ConfigError("prior", "give the lordosis once: lordosis_angle_deg or lordosis_m, not both")
