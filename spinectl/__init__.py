"""spinectl: control-theoretic analysis of spinal stability.

Implements the lumbar spine model of Wagner, Liebetrau, Schinowski, Wulf and
de Lussanet (2012), *Spinal lordosis optimizes the requirements for a stable
erect posture*, Theor Biol Med Model 9:13 (doi:10.1186/1742-4682-9-13), with
the reading and errata of ``docs/model.md``. The map of the package, one idea
per subpackage, is in CONTRIBUTING.md ("Architecture"):

- :mod:`spinectl.model`: parameters, configuration, the physics and eq. 1;
- :mod:`spinectl.optimise`: minimum PCSA and counter torques at every point;
- :mod:`spinectl.reflex`: delayed reflexes and their margins; :func:`loop_delay_margin`, the exact
  delay margin of any SISO python-control loop, is here at the top;
- :mod:`spinectl.landscape`: sweeps, NetCDF and parameter studies;
- :mod:`spinectl.paper`: the paper's study, its landmarks and verdicts;
- :mod:`spinectl.cli`: the ``spinectl`` command.

The subpackages are imported when first used (PEP 562), not by ``import spinectl``
(cvxpy, matplotlib and xarray take a second to import): ``spinectl.paper.reproduce(...)``
and ``from spinectl import optimise`` both work, and ``spinectl --help`` stays quick.
"""

import importlib

from ._version import __version__ as __version__  # re-exported: the version has its home in the basics
from .errors import ConfigError, ModelError, ParameterError, SpinectlError
from .model.config import DEFAULT_PRESET, apply_overrides, dump_toml, list_presets, load_config, load_preset
from .model.mechanics import SegmentCoefficients, segment_coefficients
from .model.params import Model
from .model.stability import StabilityResult, segment_stability
from .reflex.siso import LoopDelayMargin, loop_delay_margin

__all__ = [
    "DEFAULT_PRESET",
    "ConfigError",
    "LoopDelayMargin",
    "Model",
    "ModelError",
    "ParameterError",
    "SegmentCoefficients",
    "SpinectlError",
    "StabilityResult",
    "apply_overrides",
    "loop_delay_margin",
    "dump_toml",
    "list_presets",
    "load_config",
    "load_preset",
    "segment_coefficients",
    "segment_stability",
]

SUBPACKAGES = ("model", "optimise", "reflex", "landscape", "paper", "explore", "cli")
"""The layers, reachable as ``spinectl.<name>`` after ``import spinectl``, each imported on first use."""


def __getattr__(name: str):
    """The subpackages of :data:`SUBPACKAGES`, imported on first use (PEP 562).

    Parameters
    ----------
    name : str
        An attribute of the package, e.g. ``"landscape"``.

    Returns
    -------
    module
        The subpackage ``spinectl.<name>``.

    Raises
    ------
    AttributeError
        ``name`` is neither an attribute nor a subpackage.
    """
    if name in SUBPACKAGES:
        return importlib.import_module(f"{__name__}.{name}")  # the import sets it as an attribute too
    raise AttributeError(f"module 'spinectl' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The package's names with the subpackages that :func:`__getattr__` imports on first use (tab completion).

    Returns
    -------
    list of str
        The sorted names.
    """
    return sorted(set(globals()) | set(SUBPACKAGES))
