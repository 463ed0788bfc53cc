"""Parameter studies: the sweep of :mod:`spinectl.landscape.sweep` over more axes, chunked, on Dask, into Zarr.

A study file (``docs/studies.md``) names a base model, the E x Lambda grid, any number of
parameter axes and Monte-Carlo draws, and the outputs. :func:`load_study` validates it into a
:class:`Study`; :func:`run_study` solves it chunk by chunk (in-process, on a local Dask cluster or
on an existing one) into a Zarr store that it can resume; :func:`load` reads the store back. The
modules: CONTRIBUTING.md's map.
"""

from __future__ import annotations

from .files import load_study, parse_study
from .run import StudyResult, describe, run_study
from .spec import Axis, Chunk, Sampled, Samples, Study
from .store import load, open_store

__all__ = [
    "Axis",
    "Chunk",
    "Sampled",
    "Samples",
    "Study",
    "StudyResult",
    "describe",
    "load",
    "load_study",
    "open_store",
    "parse_study",
    "run_study",
]
