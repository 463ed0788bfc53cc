"""The remedy of an infeasible optimum: the least added joint stiffness from which it becomes feasible.

Where the muscles alone cannot meet the stability criterion (MyoTorso's chain, which has no joint
stiffness of its own), the optimum's table names how much ``--joint-stiffness`` makes it feasible,
found by a certified bracket (docs/anatomy.md, "The optimum").
"""

from __future__ import annotations

import numpy as np

INFEASIBLE_HINT = (
    "remedy: the stability criterion needs more stiffness than the muscles give (the classic optimum, without "
    "it, is solved); --joint-stiffness mapped or a value in N m/rad adds stiffness at each chain joint "
    "(docs/anatomy.md, 'The optimum')"
)
MAX_REMEDY = 1e5
"""The most stiffness per joint [N m/rad] the remedy searches (the paper's K is 15 N m/rad, Crisco and Panjabi's
passive lumbar segments tens): a model that needs more has no remedy in added joint stiffness, and says so."""
REMEDY_RERUN = "MODEL --mapping MAPPING"
"""The model's place in the remedy's command where it was not run from the command line (the Python API)."""
REMEDY_RTOL = 1e-3
"""Relative width of the bracket :func:`least_joint_stiffness` certifies (its upper end is feasible)."""


def least_joint_stiffness(feasible, start: float = 0.0, rtol: float = REMEDY_RTOL) -> float:
    """The least stiffness c [N m/rad] at each chain joint with ``feasible(c)``, by doubling then bisection.

    Adding c at each joint adds c A to -K, with A positive semidefinite (the identity on the free chain,
    T^T T on the chain constrained by the rhythm), so whatever meets the criterion at c meets it at every
    larger c: feasibility is monotone in c, and bisection brackets its least value.

    Parameters
    ----------
    feasible : callable
        ``feasible(c) -> bool``: the optimum solved with c [N m/rad] added at each chain joint.
    start : float, optional
        The stiffness already added, known infeasible [N m/rad].
    rtol : float, optional
        Relative width of the returned bracket.

    Returns
    -------
    float
        The bracket's upper end [N m/rad] (feasible, within ``rtol`` of the least); inf if even
        :data:`MAX_REMEDY` is not.
    """
    low, high = start, max(2.0 * start, 1.0)
    while not feasible(high):
        if high >= MAX_REMEDY:
            return float("inf")
        low, high = high, min(2.0 * high, MAX_REMEDY)
    while high - low > rtol * high:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if feasible(middle) else (middle, high)
    return high


def remedy(anatomy, optimise_at, opt, classic, joint_stiffness, kwargs: dict) -> float:
    """Where only the stability criterion fails, the least ``--joint-stiffness`` that makes the optimum feasible.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (its :meth:`added_stiffness` reads ``joint_stiffness``).
    optimise_at : callable
        The engine's ``optimise(anatomy, stability=..., **kwargs)``.
    opt, classic : Optimum
        The optimum with the criterion and without.
    joint_stiffness : {"none", "mapped"} or float
        What was added [N m/rad].
    kwargs : dict
        The optimum's other arguments (plane, margin, equilibrium).

    Returns
    -------
    float
        [N m/rad] per chain joint (:func:`least_joint_stiffness`); NaN unless only the criterion fails.
    """
    if opt.ok or not classic.ok:
        return float("nan")
    given = float(anatomy.added_stiffness(joint_stiffness, 1)[0])

    def feasible(c: float) -> bool:
        return optimise_at(anatomy, stability=opt.stability, **{**kwargs, "joint_stiffness": c}).ok

    return least_joint_stiffness(feasible, given)


def remedy_text(value: float, rerun: str = REMEDY_RERUN) -> str:
    """The remedy as the table's hint ends it.

    Parameters
    ----------
    value : float
        :attr:`OptimisedResult.remedy` [N m/rad].
    rerun : str, optional
        What follows ``spinectl anatomy`` to analyse the same model again: the model and ``--mapping`` as given
        (and the posture, plane and criterion where not the defaults), so that the suggested command runs on the
        model analysed, not on MyoTorso; default :data:`REMEDY_RERUN` (the Python API, which has no command line).

    Returns
    -------
    str
        ``"; feasible from 39.9 N m/rad at each chain joint: spinectl anatomy m.osim --mapping m.toml --optimise
        --joint-stiffness 40"`` (the value named rounded up to 3 digits, so still feasible); ``""`` for NaN.
    """
    if np.isnan(value):
        return ""
    if np.isinf(value):
        return f"; none up to {MAX_REMEDY:g} N m/rad at each chain joint makes it feasible"
    step = 10.0 ** (np.floor(np.log10(value)) - 2)  # three significant digits, rounded up: still feasible
    return (
        f"; feasible from {value:.3g} N m/rad at each chain joint: spinectl anatomy {rerun} --optimise "
        f"--joint-stiffness {np.ceil(value / step) * step:.3g}"
    )


"""What the table adds where only the stability criterion fails (the classic optimum solved): what would make it
feasible."""
