"""Ctrl-C during a study or an atlas: what is saved and how to continue, said where the interruption is reported.

The run knows how many chunks it has saved when the interruption reaches it; :func:`saved_on_interrupt`
turns the bare :class:`KeyboardInterrupt` into :class:`Interrupted`, a :class:`KeyboardInterrupt` whose text
says so, and the command line prints that text (:func:`spinectl.cli.main`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager


class Interrupted(KeyboardInterrupt):
    """A :class:`KeyboardInterrupt` that says what the run saved and how to continue; still exits 130."""


def interrupted_text(saved: int, total: int, where: str, again: str) -> str:
    """The line of an interrupted run: ``interrupted: 70 of 216 chunks saved in 'big.zarr'; continue with --resume``.

    Parameters
    ----------
    saved : int
        Chunks saved (this run's and any earlier run's).
    total : int
        Chunks of the whole run.
    where : str
        The store or folder that holds them.
    again : str
        How to continue.

    Returns
    -------
    str
        The line, without ``spinectl:`` and without a newline.
    """
    return f"interrupted: {saved} of {total} chunks saved in {where!r}; {again}"


@contextmanager
def saved_on_interrupt(saved: Callable[[], int], total: int, where: str, again: str) -> Iterator[None]:
    """Raise :class:`Interrupted` (with :func:`interrupted_text`) for a Ctrl-C inside the block.

    Parameters
    ----------
    saved : callable
        The chunks saved, counted when the interruption comes.
    total, where, again :
        As :func:`interrupted_text`.

    Returns
    -------
    contextlib.AbstractContextManager
        The block's guard; it re-raises any other exception as it came.
    """
    try:
        yield
    except Interrupted:
        raise
    except KeyboardInterrupt:
        raise Interrupted(interrupted_text(saved(), total, where, again)) from None
