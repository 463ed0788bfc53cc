"""Model parameters as frozen dataclasses, one module per section (CONTRIBUTING.md's map), re-exported here.

Every number the model uses lives here, with its unit and source in the field metadata (``unit``,
``doc``); SI unless the field says otherwise. Instances validate themselves on construction and
raise :class:`~spinectl.errors.ParameterError` naming the field. No I/O (TOML:
:mod:`spinectl.model.config`). docs/model.md sets out the reading of the paper [1]_ that the
defaults encode, docs/parameters.md lists every field.

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
"""

from __future__ import annotations

from .body import (
    Body,
    Geometry,
)
from .bounds import (
    MAX_ACTIVATION,
    MAX_ACTIVATION_TIME_CONSTANT,
    MAX_BODY_LENGTH,
    MAX_CORS,
    MAX_DELAY,
    MAX_FIBRE_TERMS,
    MAX_FIBRES,
    MAX_GRAVITY,
    MAX_LOCAL_DAMPING,
    MAX_MASS,
    MAX_MUSCLE_PAIRS,
    MAX_PADE_ORDER,
    SIDES,
    SOLVER_TOLERANCE_RANGE,
    SPECIFIC_TENSION_RANGE,
    param,
)
from .model import (
    Model,
)
from .muscles import (
    Fibre,
    MusclePair,
)
from .reflex import (
    Reflex,
)
from .segments import (
    Levels,
    Local,
    Passive,
)
from .solving import (
    Errata,
    Optimisation,
)

__all__ = [
    "Body",
    "Errata",
    "Fibre",
    "Geometry",
    "Levels",
    "Local",
    "MAX_ACTIVATION",
    "MAX_ACTIVATION_TIME_CONSTANT",
    "MAX_BODY_LENGTH",
    "MAX_CORS",
    "MAX_DELAY",
    "MAX_FIBRES",
    "MAX_FIBRE_TERMS",
    "MAX_GRAVITY",
    "MAX_LOCAL_DAMPING",
    "MAX_MASS",
    "MAX_MUSCLE_PAIRS",
    "MAX_PADE_ORDER",
    "Model",
    "MusclePair",
    "Optimisation",
    "Passive",
    "Reflex",
    "SIDES",
    "SOLVER_TOLERANCE_RANGE",
    "SPECIFIC_TENSION_RANGE",
    "param",
]
