"""Calibration of the parameters the paper does not state, against the paper's landmarks.

The paper (Wagner et al. 2012) gives neither the upper-body mass, nor the muscle attachment
coordinates, nor the fibre spread. This package fits them, within anatomically plausible bounds,
to the landmarks of :mod:`spinectl.paper.landmarks`, and reports the residual of every landmark
(docs/reproduction.md, "The calibration"; the modules: CONTRIBUTING.md's map).
"""

from .fit import (
    BUDGET_RANGES,
    GENERATIONS,
    POPSIZE,
    REFINE_EVALUATIONS,
    REFINE_RANGE,
    REFINE_STEP,
    CalibrationResult,
    Fit,
    calibrate,
    convention_losses,
)
from .landscapes import (
    FIT_POINTS,
    coarse_landmarks,
    coarse_landscape,
    measure_model,
)
from .output import history_csv, preset_toml, summary
from .parameters import (
    FREE_PARAMETERS,
    MASS_FREE,
    FreeParameter,
    bounds,
    from_model,
    parameter_set,
    to_model,
    with_bounds,
)
from .sensitivity import STEP_LANDMARKS, Sensitivity, sensitivity
from .targets import (
    C_READINGS,
    MISSING_PENALTY,
    STRICT_MARGIN,
    WEIGHTS,
    Residual,
    Target,
    loss,
    paper_targets,
    penalty,
    residuals,
    synthetic_targets,
)

__all__ = [
    "BUDGET_RANGES",
    "C_READINGS",
    "FIT_POINTS",
    "FREE_PARAMETERS",
    "GENERATIONS",
    "MASS_FREE",
    "MISSING_PENALTY",
    "POPSIZE",
    "REFINE_EVALUATIONS",
    "REFINE_RANGE",
    "REFINE_STEP",
    "STEP_LANDMARKS",
    "STRICT_MARGIN",
    "WEIGHTS",
    "CalibrationResult",
    "Fit",
    "FreeParameter",
    "Residual",
    "Sensitivity",
    "Target",
    "bounds",
    "calibrate",
    "coarse_landmarks",
    "coarse_landscape",
    "convention_losses",
    "from_model",
    "history_csv",
    "loss",
    "measure_model",
    "paper_targets",
    "parameter_set",
    "penalty",
    "preset_toml",
    "residuals",
    "sensitivity",
    "summary",
    "synthetic_targets",
    "to_model",
    "with_bounds",
]
