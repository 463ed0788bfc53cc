"""The model: parameters, TOML configuration, the physics of eq. 1 and its guarded evaluation.

docs/model.md. Parameters are frozen dataclasses (:mod:`~spinectl.model.params`) read
from TOML with presets (:mod:`~spinectl.model.config`, on the schema engine
:mod:`~spinectl.model._toml`); the physics are pure array functions in SI units:
the spine's geometry (:mod:`~spinectl.model.geometry`), the muscle laws by name
(:mod:`~spinectl.model.laws`; the paper's Hill-type relations in :mod:`~spinectl.model.muscle`),
the torques and their derivatives per unit PCSA (:mod:`~spinectl.model.mechanics`);
:mod:`~spinectl.model.checks` guards their evaluation and :mod:`~spinectl.model.stability`
applies the paper's eq. 1 [1]_.

Symbols and units: docs/glossary.md.

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
"""
