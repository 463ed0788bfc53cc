"""spinectl: control-theoretic analysis of spinal stability.

Implements the lumbar spine model of Wagner, Liebetrau, Schinowski, Wulf and
de Lussanet (2012), *Spinal lordosis optimizes the requirements for a stable
erect posture*, Theor Biol Med Model 9:13 (doi:10.1186/1742-4682-9-13), with
the reading and errata of ``docs/model.md``. The map of the package, one idea
per subpackage, is in CONTRIBUTING.md ("Architecture"):

- :mod:`spinectl.model`: parameters, configuration, the physics and eq. 1;
- :mod:`spinectl.optimise`: minimum PCSA and counter torques at every point;
- :mod:`spinectl.reflex`: delayed reflexes and their margins; :func:`delay_margin`, the exact
  delay margin of any SISO python-control loop, is here at the top;
- :mod:`spinectl.landscape`: sweeps, NetCDF and parameter studies;
- :mod:`spinectl.paper`: the paper's study, its landmarks and verdicts;
- :mod:`spinectl.cli`: the ``spinectl`` command.

The subpackages are imported when first used (PEP 562), not by ``import spinectl``
(cvxpy, matplotlib and xarray take a second to import): ``spinectl.paper.reproduce(...)``
and ``from spinectl import optimise`` both work, and ``spinectl --help`` stays quick.
"""

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

from ._version import __version__ as __version__  # re-exported: the version has its home in the basics
from .errors import ConfigError, ModelError, ParameterError, SpinectlError
from .model.config import DEFAULT_PRESET, apply_overrides, dump_toml, list_presets, load_config, load_preset
from .model.mechanics import SegmentCoefficients, segment_coefficients
from .model.params import Model
from .model.stability import StabilityResult, segment_stability
from .reflex.siso import LoopDelayMargin, delay_margin

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
    "delay_margin",
    "dump_toml",
    "list_presets",
    "load_config",
    "load_preset",
    "segment_coefficients",
    "segment_stability",
]

SUBPACKAGES = ("model", "optimise", "reflex", "landscape", "paper", "explore", "cli")
"""The layers, reachable as ``spinectl.<name>`` after ``import spinectl``, each imported on first use."""

MOVED = {
    "params": "spinectl.model.params",
    "config": "spinectl.model.config",
    "geometry": "spinectl.model.geometry",
    "muscle": "spinectl.model.muscle",
    "mechanics": "spinectl.model.mechanics",
    "stability": "spinectl.model.stability",
    "batch": "spinectl.optimise.stacked",
    "polish": "spinectl.optimise.polish",
    "systems": "spinectl.reflex.loops",
    "simulate": "spinectl.reflex.simulate",
    "margins": "spinectl.reflex.margins",
    "control_plots": "spinectl.reflex.plots",
    "sweep": "spinectl.landscape.sweep",
    "study": "spinectl.landscape.study",
    "landmarks": "spinectl.paper.landmarks",
    "reproduction": "spinectl.paper.verdicts",
    "plotting": "spinectl.paper.figures",
    "report": "spinectl.paper.report",
    "calibration": "spinectl.paper.calibration",
    "io": "spinectl.atomic",
}
"""Modules of spinectl 0.1's flat layout and where they live now (CHANGELOG, 0.2).

``from spinectl import sweep``, ``import spinectl.sweep`` and
``from spinectl.config import load_preset`` still work for one release, with a
:class:`DeprecationWarning` naming the new module. Names that moved between
modules when one was split (e.g. ``sweep.save``, now
:func:`spinectl.landscape.netcdf.save`) are found in the new module only.
"""


def _moved(old: str, stacklevel: int):
    """The module that the 0.1 name ``spinectl.<old>`` (or a module inside it) now is, with a warning."""
    head, _, rest = old.partition(".")
    new = MOVED[head] + (f".{rest}" if rest else "")
    warnings.warn(
        f"spinectl.{old} has moved to {new}; the old name goes in the next release",
        DeprecationWarning,
        stacklevel=stacklevel,
    )
    return importlib.import_module(new)


def __getattr__(name: str):
    """The subpackages of :data:`SUBPACKAGES`, imported on first use, and the moved modules of :data:`MOVED`,
    with a :class:`DeprecationWarning` (PEP 562).

    Parameters
    ----------
    name : str
        An attribute of the package, e.g. ``"sweep"``.

    Returns
    -------
    module
        The subpackage ``spinectl.<name>``, or the module that ``spinectl.<name>`` now is.

    Raises
    ------
    AttributeError
        ``name`` is neither an attribute, a subpackage nor a moved module.
    """
    if name in SUBPACKAGES:
        return importlib.import_module(f"{__name__}.{name}")  # the import sets it as an attribute too
    if name not in MOVED:
        raise AttributeError(f"module 'spinectl' has no attribute {name!r}")
    return _moved(name, stacklevel=3)


def __dir__() -> list[str]:
    """The package's names with the subpackages that :func:`__getattr__` imports on first use (tab completion).

    Returns
    -------
    list of str
        The sorted names.
    """
    return sorted(set(globals()) | set(SUBPACKAGES))


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """``import spinectl.sweep`` and ``from spinectl.config import ...`` of 0.1: the new module, with a warning."""

    def find_spec(self, fullname, path=None, target=None):
        old = fullname.removeprefix(f"{__name__}.")
        if old != fullname and old.partition(".")[0] in MOVED:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        return _moved(spec.name.removeprefix(f"{__name__}."), stacklevel=8)

    def exec_module(self, module):
        pass  # the new module is imported already


if not any(isinstance(finder, _MovedModules) for finder in sys.meta_path):
    sys.meta_path.insert(0, _MovedModules())  # before the path finder, which would load old paths twice
