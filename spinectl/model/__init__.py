"""The model: parameters, TOML configuration, the physics of eq. 1 [1]_ and its guarded evaluation.

docs/model.md; the modules: CONTRIBUTING.md's map; symbols and units: docs/glossary.md. The
physics are pure array functions in SI units.

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
"""
