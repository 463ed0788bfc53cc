"""Deprecated aliases of names that moved between modules of the package (CHANGELOG).

The package's modules of 0.1 are aliased by ``spinectl.MOVED``; a name that moved out of a
module that stays gets a module ``__getattr__`` (PEP 562) from :func:`moved_names`, which
imports the new module only when the old name is read, so the old module imports nothing of it.
"""

from __future__ import annotations

import importlib
import warnings


def moved_names(module: str, moved: dict[str, str]):
    """A module ``__getattr__`` that finds each moved name in its new module, with a warning.

    Parameters
    ----------
    module : str
        Dotted name of the module the names left (its ``__name__``).
    moved : dict of str to str
        Each old name, and the dotted name of the module that holds it now.

    Returns
    -------
    callable
        ``__getattr__(name)``: the object, after a :class:`DeprecationWarning` naming the new
        module; :class:`AttributeError` for any other name.
    """

    def __getattr__(name: str):
        if name not in moved:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        warnings.warn(
            f"{module}.{name} has moved to {moved[name]}.{name}; the old name goes in the next release",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(importlib.import_module(moved[name]), name)

    return __getattr__
