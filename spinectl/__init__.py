"""spinectl: control-theoretic analysis of spinal stability.

Implements the lumbar spine model of Wagner, Liebetrau, Schinowski, Wulf and
de Lussanet (2012), *Spinal lordosis optimizes the requirements for a stable
erect posture*, Theor Biol Med Model 9:13, with the reading and errata of
``docs/model.md``.

Layers (each depends only on those above it in this list):

- parameters: :mod:`spinectl.params`, :mod:`spinectl.config`
- physics: :mod:`spinectl.geometry`, :mod:`spinectl.muscle`, :mod:`spinectl.mechanics`
- analysis: :mod:`spinectl.stability`, :mod:`spinectl.optimise` (per-point
  reference), :mod:`spinectl.polish`, :mod:`spinectl.batch` (fast path),
  :mod:`spinectl.reflex`, :mod:`spinectl.systems`, :mod:`spinectl.simulate`,
  :mod:`spinectl.margins`
- edges: :mod:`spinectl.sweep`, :mod:`spinectl.landmarks`, :mod:`spinectl.plotting`,
  :mod:`spinectl.report`, :mod:`spinectl.io`, :mod:`spinectl.control_plots`,
  :mod:`spinectl.cli`

The optimiser and the edges are not imported here (cvxpy, matplotlib and
xarray take a second to import); ``from spinectl import optimise, sweep``.
"""

from .config import dump_toml, list_presets, load_config, load_preset
from .errors import ConfigError, ModelError, ParameterError, SpinectlError
from .mechanics import SegmentCoefficients, segment_coefficients
from .params import Model
from .stability import StabilityResult, segment_stability

__version__ = "0.1.0"

__all__ = [
    "ConfigError",
    "Model",
    "ModelError",
    "ParameterError",
    "SegmentCoefficients",
    "SpinectlError",
    "StabilityResult",
    "dump_toml",
    "list_presets",
    "load_config",
    "load_preset",
    "segment_coefficients",
    "segment_stability",
]
