"""The optional extras' modules (MuJoCo, myo-sim, OpenSim, SALib), imported where first needed.

A missing extra is one line naming what to install (a :class:`~spinectl.errors.SpinectlError` of the
caller's kind), not a traceback; every extra is imported through :func:`require_module`.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from .errors import SpinectlError


def require_module(name: str, error: type[SpinectlError], message: str) -> ModuleType:
    """Import and return the module ``name`` of an optional extra, or raise ``error(message)``.

    Parameters
    ----------
    name : str
        The module, e.g. ``"mujoco"``.
    error : type
        The :class:`~spinectl.errors.SpinectlError` subclass to raise where it cannot be imported.
    message : str
        Its one line: what needs the module and how to install it.

    Returns
    -------
    module
        The module.

    Raises
    ------
    SpinectlError
        ``error(message)``, where ``name`` cannot be imported (not installed, or blocked by ``sys.modules``).
    """
    try:
        return importlib.import_module(name)
    except ImportError:
        raise error(message) from None
