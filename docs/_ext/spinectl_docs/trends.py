"""The numbers of docs/contributions.md's "Published trends" (MyoTorso, the paper's chain), measured at the build.

The same computations as ``tests/anatomy/test_published_trends.py`` and ``tests/model/test_chain_published_trends.py``
(:mod:`spinectl.anatomy.trends`, the removal method, the least local stiffness), each run once per build.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value

BODY_WEIGHT = 75.0 * 9.81
"""The nominal body weight [N] that scales the loads held (the tests' BODY_WEIGHT)."""

FRACTIONS = np.linspace(0.0, 0.6, 7)
"""The loads held, as fractions of :data:`BODY_WEIGHT`."""

FLOORS = np.linspace(0.0, 0.08, 5)
"""The abdominals' least activation along the co-contraction path [1]."""

STIFFNESS = 100.0
"""The joint stiffness added [N m/rad] where the price of stability is shown."""


@cache
def _torso():
    from spinectl import anatomy

    return anatomy.load("myotorso")


@cache
def co_contraction():
    """The co-contraction path at the mapped stiffness (Granata & Marras 2000)."""
    from spinectl.anatomy.trends import co_contraction_path

    return co_contraction_path(_torso(), FLOORS)


@cache
def price(joint_stiffness=STIFFNESS):
    """The price of stability against the load held (Cholewicki et al. 1997)."""
    from spinectl.anatomy.trends import stability_price

    return stability_price(_torso(), FRACTIONS * BODY_WEIGHT, joint_stiffness=joint_stiffness)


@cache
def removals() -> dict:
    """Each group's removal at the classic optimum, mapped stiffness, re-solved (Cholewicki & VanVliet 2002)."""
    from spinectl.anatomy.contributions import optimum_resolver
    from spinectl.anatomy.optimum import optimise
    from spinectl.anatomy.trends import GROUPS
    from spinectl.model.contributions import contributions

    torso = _torso()
    free, _, _ = torso.chains("sagittal", None, "mapped")
    opt = optimise(torso, stability="none", joint_stiffness="mapped")
    resolve = optimum_resolver(torso, "sagittal", None, "mapped", stability="none", margin=1.0, equilibrium="rhythm")
    kept = contributions(free, opt.activations, groups=GROUPS).removals
    return {"resolved": contributions(free, opt.activations, groups=GROUPS, resolve=resolve).removals, "kept": kept}


@cache
def chain_stiffness() -> list:
    """The paper's chain: the least total local stiffness against a weight at the point mass [N m/rad]."""
    from spinectl import load_preset
    from spinectl.model.loads import PointLoad
    from spinectl.optimise.coupled.at_activation import point_at_activation
    from spinectl.optimise.coupled.local import least_local_stiffness

    model = load_preset("wagner2012")
    point = point_at_activation(model, 0.03, 0.04)
    return [
        float(
            np.sum(
                least_local_stiffness(
                    model, 0.03, 0.04, point.pcsa, given=False, loads=(PointLoad((0.0, -float(w))),)
                ).local_stiffness
            )
        )
        for w in FRACTIONS * BODY_WEIGHT
    ]


def _percent(x: float) -> str:
    return f"{100 * x:.1f}"


def _largest_feasible_removal() -> str:
    resolved = removals()["resolved"]
    changes = [
        abs(r.percent_change) for k, r in resolved.items() if k.startswith("group:") and np.isfinite(r.percent_change)
    ]
    return f"{max(changes):.1f}"


value("trends.index_rise")(lambda: _percent(co_contraction().rise(co_contraction().index)))
value("trends.critical_rise")(lambda: _percent(co_contraction().rise(co_contraction().critical_load)))
value("trends.compression_rise")(lambda: _percent(co_contraction().rise(co_contraction().compression)))
value("trends.price_low")(lambda: f"{price().price[0]:.2g}")


def _last_feasible() -> int:
    """The index of the largest load at which the chain criterion is feasible (100 N m/rad)."""
    return int(np.flatnonzero(np.isfinite(price().stable_cost))[-1])


def _priced_from() -> str:
    """The least load at which stability costs anything at the mapping's stiffness [% of body weight]."""
    mapped = price("mapped")
    priced = np.flatnonzero(mapped.price > 1e-6 * mapped.classic_cost)
    return f"{100 * FRACTIONS[priced[0]]:.0f}" if priced.size else "(none: no price at any load)"


value("trends.price_high")(lambda: f"{price().price[_last_feasible()]:.3g}")
value("trends.price_high_at")(lambda: f"{100 * FRACTIONS[_last_feasible()]:.0f}")
value("trends.classic_fall")(lambda: _percent(1 - price().classic_cost[-1] / price().classic_cost[0]))
value("trends.mapped_priced_from")(_priced_from)


def _infeasible_from(joint_stiffness: float = 50.0) -> str:
    """The least fraction of body weight at which the chain criterion is infeasible [%]."""
    infeasible = np.flatnonzero(~np.isfinite(price(joint_stiffness).stable_cost))
    return f"{100 * FRACTIONS[infeasible[0]]:.0f}" if infeasible.size else "(none: feasible at every load)"


value("trends.infeasible_from_50")(_infeasible_from)
value("trends.infeasible_from_100")(lambda: _infeasible_from(STIFFNESS))
value("trends.removal_largest")(_largest_feasible_removal)
value("trends.erector_kept")(lambda: f"{removals()['kept']['group:erector_spinae'].percent_change:.1f}")
value("trends.chain_low")(lambda: f"{chain_stiffness()[0]:.0f}")
value("trends.chain_high")(lambda: f"{chain_stiffness()[-1]:.0f}")
