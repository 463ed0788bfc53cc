"""``docs/chain.md``'s "Local muscles can" and "Together they need less" and ``docs/figures.md``'s coupled ratio at
A, measured at the build.

At the four points of chain.md's first table (:data:`.chain.POINTS`: ``default`` and ``wagner2012`` at A and at
E = 3, Lambda = 4 cm): the least local stiffness of ``spinectl stability --coupled`` (:func:`.chain.coupled`, the
table's own computation) and the joint optimum (c) of global and local muscle with ``w_local = 1``
(:func:`spinectl.optimise.coupled.joint.joint_optimum`, about a second each), against the per-segment minimum
PCSA. The words the page sets around them ("about half", "less muscle in total") are checked here: a build
whose numbers contradict them fails.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .chain import coupled
from .values import value

POSITIONS = ((0.0, 0.0), (0.03, 0.04))
"""A and E = 3, Lambda = 4 cm [m]."""

PRESETS = ("default", "wagner2012")


@cache
def joint_at(preset: str, e: float, lam: float):
    """The joint optimum (c) of the preset at (E, Lambda) [m], its own ``local.cost_weight`` (1)."""
    from spinectl.model.config import load_preset
    from spinectl.optimise.coupled.joint import joint_optimum

    return joint_optimum(load_preset(preset), e, lam)


def _kappa(preset: str) -> float:
    """The local muscles' stiffness per PCSA of the preset [N m/rad per m^2]."""
    from spinectl.model.config import load_preset
    from spinectl.model.local_muscles import local_stiffness_per_pcsa

    return local_stiffness_per_pcsa(load_preset(preset))


def _local(preset: str) -> list[np.ndarray]:
    """The least local stiffness [N m/rad] per joint at each of :data:`POSITIONS`."""
    return [np.asarray(coupled(preset, *at).local.local_stiffness, float) for at in POSITIONS]


def _segment_total(preset: str, at) -> float:
    """The per-segment minimum PCSA's total [m^2] at ``at``."""
    return float(np.sum(coupled(preset, *at).pcsa))


def _pair(values, fmt: str) -> str:
    """The values at both positions, 'a and b', or one where both round alike."""
    texts = [format(v, fmt) for v in values]
    return texts[0] if len(set(texts)) == 1 else " and ".join(texts)


def _span(values, fmt: str) -> str:
    lo, hi = (format(v, fmt) for v in (min(values), max(values)))
    return lo if lo == hi else f"{lo}–{hi}"


def joint_words() -> str:
    """'about half' where every joint optimum's global PCSA is 35-65 % of the per-segment one (the page's words);
    a joint optimum needing in total no less than the per-segment global PCSA fails the build ("less muscle in
    total")."""
    shares = []
    for preset in PRESETS:
        for at in POSITIONS:
            c, alone = joint_at(preset, *at), _segment_total(preset, at)
            if not c.total_pcsa + c.total_local_pcsa < alone:
                raise RuntimeError(f"docs/chain.md: the joint optimum of {preset} at {at} needs no less in total")
            shares.append(c.total_pcsa / alone)
    return "about half" if 0.35 <= min(shares) and max(shares) <= 0.65 else f"{_span(100 * np.array(shares), '.0f')} %"


def ratio(preset: str) -> float:
    """The coupled ratio at A: the joint optimum's global PCSA over the per-segment minimum PCSA [1]."""
    return joint_at(preset, 0.0, 0.0).total_pcsa / _segment_total(preset, (0.0, 0.0))


for _preset in PRESETS:
    value(f"chain.local_totals_{_preset}")(lambda p=_preset: " and ".join(f"{np.sum(k):.0f}" for k in _local(p)))
    value(f"chain.local_pcsa_{_preset}")(
        lambda p=_preset: _span([1e4 * np.sum(k) / _kappa(p) for k in _local(p)], ".1f")
    )
    value(f"chain.joint_global_{_preset}")(
        lambda p=_preset: _pair([1e4 * joint_at(p, *at).total_pcsa for at in POSITIONS], ".1f")
    )
    value(f"chain.joint_local_{_preset}")(
        lambda p=_preset: _pair([1e4 * joint_at(p, *at).total_local_pcsa for at in POSITIONS], ".1f")
    )
    value(f"figures.ratio_{_preset}")(lambda p=_preset: f"{ratio(p):.2f}")
    value(f"figures.joint_global_{_preset}")(lambda p=_preset: f"{1e4 * joint_at(p, 0.0, 0.0).total_pcsa:.1f}")
    value(f"figures.segment_{_preset}")(lambda p=_preset: f"{1e4 * _segment_total(p, (0.0, 0.0)):.1f}")

value("chain.local_most_joint")(lambda: f"{max(np.max(k) for p in PRESETS for k in _local(p)):.0f}")
value("chain.local_most_joint_pcsa")(
    lambda: f"{max(1e4 * np.max(k) / _kappa(p) for p in PRESETS for k in _local(p)):.1f}"
)
value("chain.joint_words")(joint_words)
