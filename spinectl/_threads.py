"""One BLAS thread for spinectl's small matrices, unless the user chose a number.

spinectl's kernels solve many small problems (10 x 10 state matrices, Louisell's matrix of the
chain's delay margin): a multi-threaded BLAS only adds synchronisation to each call, and on a busy
machine its threads wait for cores. Measured on the project's 2-core machine at a load of about 5:
the design curve of 41 delays took 42.7 s with OpenBLAS's two threads and 2.9 s with one
(docs/reflex.md, "The design question"). The limit is set through threadpoolctl, a well-kept
library that finds the BLAS loaded in the process; a user who sets ``OPENBLAS_NUM_THREADS``,
``OMP_NUM_THREADS`` or ``MKL_NUM_THREADS`` keeps their choice.
"""

from __future__ import annotations

import contextlib
import functools
import os

CHOICE_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
"""Environment variables by which a user sets the BLAS's threads; any one set leaves them as set."""


def user_chose_threads() -> bool:
    """Whether the environment sets the BLAS's number of threads (:data:`CHOICE_VARIABLES`)."""
    return any(os.environ.get(name) for name in CHOICE_VARIABLES)


@contextlib.contextmanager
def one_blas_thread():
    """Within the block, the loaded BLAS libraries use one thread (threadpoolctl), unless the user chose.

    Yields
    ------
    None
    """
    if user_chose_threads():
        yield
        return
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield


def with_one_blas_thread(function):
    """Decorate a library entry point of many small matrix problems: it runs under :func:`one_blas_thread`.

    Parameters
    ----------
    function : callable
        The entry point.

    Returns
    -------
    callable
        ``function`` with the limit around each call (its name and docstring kept).
    """

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with one_blas_thread():
            return function(*args, **kwargs)

    return wrapper
