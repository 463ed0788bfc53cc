"""Model parameters as frozen dataclasses.

Every number the model uses lives here, with its unit and source in the field
metadata (``unit``, ``doc``); there are no magic numbers in the physics
modules. All values are SI (m, kg, N, s, rad) except where the field says
otherwise. Instances validate themselves on construction and raise
:class:`~spinectl.errors.ParameterError` naming the field.

Reading and writing TOML lives in :mod:`spinectl.model.config`; this module does no
I/O. docs/model.md sets out the reading of the paper [1]_ ("the paper") that
these defaults encode; docs/parameters.md lists every field with its unit,
default and source, and docs/glossary.md the symbols.

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13

One module per parameter section, on the bounds below them:

- :mod:`~spinectl.model.params.bounds`: the bounds of the parameters and the validation helpers;
- :mod:`~spinectl.model.params.body`: the upper body and the spine's geometry;
- :mod:`~spinectl.model.params.muscles`: the global muscles' fibres and antagonistic pairs;
- :mod:`~spinectl.model.params.segments`: the passive stiffness, the local muscles, the levels' inertia;
- :mod:`~spinectl.model.params.solving`: the errata chosen and the optimisation settings;
- :mod:`~spinectl.model.params.reflex`: the delayed PD reflex and its simulation;
- :mod:`~spinectl.model.params.model`: the whole parameter set, :class:`Model`.

Every public name of these modules is also here: ``spinectl.model.params.Model``
as before the split.
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
