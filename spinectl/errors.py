"""Exceptions of spinectl.

Every error a user can cause derives from :class:`SpinectlError`; the CLI maps
it to one line on stderr and exit code 2. Subclasses also derive from the
builtin that fits (python-control's convention), so ``except ValueError`` in
user code keeps working.
"""

from __future__ import annotations


class SpinectlError(Exception):
    """Base class of every error that spinectl raises on purpose."""


class ParameterError(SpinectlError, ValueError):
    """A parameter has a wrong type, is not finite or is out of range.

    Parameters
    ----------
    field : str
        Dotted name of the offending parameter, e.g. ``"body.mass"``.
    message : str
        What is allowed, e.g. ``"must be > 0 (got -3.0)"``.
    """

    def __init__(self, field: str, message: str):
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")

    def __reduce__(self):
        """Pickled by its field and message (an error of a worker process comes back as itself)."""
        return type(self), (self.field, self.message)

    def under(self, prefix: str) -> ParameterError:
        """Return the same error with ``prefix`` prepended to the field name.

        Parameters
        ----------
        prefix : str
            Dotted path of the section, e.g. ``"body"``; empty leaves the name unchanged.

        Returns
        -------
        ParameterError
            A new error of the same class, its field ``prefix.field``.
        """
        return type(self)(f"{prefix}.{self.field}" if prefix else self.field, self.message)


class ConfigError(ParameterError):
    """A configuration file cannot be read: missing, not TOML, unknown key."""


class ModelError(SpinectlError, ValueError):
    """A configuration is valid parameter by parameter but not as a whole.

    Raised where E and Lambda are known (:func:`spinectl.model.checks.validate_position`):
    a fibre attachment on a centre of rotation, or parameters so far off that
    the arithmetic overflows.
    """


class OutputError(SpinectlError, OSError):
    """An output cannot be written (folder not writable, a folder in the way, ...).

    Raised before anything is renamed onto the target, so the previous output
    is left intact (see :func:`spinectl.atomic.atomic_path`).
    """
