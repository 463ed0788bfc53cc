"""Parameter studies: the sweep of :mod:`spinectl.landscape.sweep` over more axes, chunked, on Dask, into Zarr.

A study file (``docs/studies.md``) names a base model, the E x Lambda grid, any
number of parameter axes and Monte-Carlo draws, and the outputs.
:func:`load_study` validates it into a :class:`Study`; :func:`run_study` solves
it chunk by chunk (in-process, on a local Dask cluster or on an existing one)
into a Zarr store that it can resume; :func:`load` reads the store back.

- :mod:`spinectl.landscape.study.spec`: the study, its validation and the plan of chunks;
- :mod:`spinectl.landscape.study.files`: the study file, read and checked against its schema;
- :mod:`spinectl.landscape.study.store`: the Zarr store's layout, creation, resume check and writes;
- :mod:`spinectl.landscape.study.executor`: where chunks run (in-process, a local or an existing Dask
  cluster), a picklable function mapped over them; shared with the atlas;
- :mod:`spinectl.landscape.study.run`: the study's chunks on the executor, written as they finish.
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
