"""Parameter studies: the sweep of :mod:`spinectl.landscape.sweep` over more axes, chunked, on Dask, into Zarr.

A study file (``docs/studies.md``) names a base model, the E x Lambda grid, any number of
parameter axes and Monte-Carlo draws, and the outputs. :func:`load_study` validates it into a
:class:`Study`; :func:`run_study` solves it chunk by chunk (in-process, on a local Dask cluster or
on an existing one) into a Zarr store that it can resume; :func:`load` reads the store back.
A study of motions (``[[trials]]``, docs/motion.md) runs :func:`spinectl.anatomy.motion.motion_response`
on every trial, chunked by frames, on the same executor (:func:`run_motion_study`, :func:`load_motions`). The
modules: CONTRIBUTING.md's map.
"""

from __future__ import annotations

from .files import load_study, parse_study
from .motion_run import load_motions, run_motion_study
from .motion_spec import MotionStudy, Trial, load_motion_study, parse_motion_study
from .run import StudyResult, describe, run_study
from .spec import Axis, Chunk, Sampled, Samples, Study
from .store import load, open_store

__all__ = [
    "Axis",
    "Chunk",
    "MotionStudy",
    "Sampled",
    "Samples",
    "Study",
    "Trial",
    "StudyResult",
    "describe",
    "load",
    "load_motion_study",
    "load_motions",
    "load_study",
    "open_store",
    "parse_motion_study",
    "parse_study",
    "run_motion_study",
    "run_study",
]
