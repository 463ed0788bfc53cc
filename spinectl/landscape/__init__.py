"""Landscapes: the model's answers over grids of (E, Lambda) and over any parameter, as xarray Datasets.

docs/optimisation.md (the schema), docs/studies.md and docs/atlas.md; the modules: CONTRIBUTING.md's
map; symbols and units: docs/glossary.md.
"""
