"""The model: parameters, TOML configuration, the physics of eq. 1 and its guarded evaluation.

docs/model.md. Parameters are frozen dataclasses (:mod:`~spinectl.model.params`) read
from TOML with presets (:mod:`~spinectl.model.config`, on the schema engine
:mod:`~spinectl.model._toml`); the physics are pure array functions in SI units:
the spine's geometry (:mod:`~spinectl.model.geometry`), the Hill-type muscles
(:mod:`~spinectl.model.muscle`), the torques and their derivatives per unit PCSA
(:mod:`~spinectl.model.mechanics`); :mod:`~spinectl.model.checks` guards their
evaluation and :mod:`~spinectl.model.stability` applies the paper's eq. 1.
"""
