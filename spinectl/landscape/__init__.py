"""Landscapes: the model's answers over grids of (E, Lambda) and over any parameter, as xarray Datasets.

docs/optimisation.md (the schema) and docs/studies.md. The variables and their units
(:mod:`~spinectl.landscape.schema`), the chunked solve of a list of points
(:mod:`~spinectl.landscape.columns`), the sweep over a grid
(:mod:`~spinectl.landscape.sweep`), NetCDF files (:mod:`~spinectl.landscape.netcdf`)
and parameter studies on Dask in a Zarr store (:mod:`~spinectl.landscape.study`).

Symbols and units: docs/glossary.md.
"""
