"""The numbers of ``docs/errata.md`` (the sign of gravity) and ``docs/model.md`` (K under the paper's convention)
that the model computes, at the build.

The ``wagner2012`` preset at position A: the segments' gravity stiffness m g r_y (the diagonal of the chain's
K_g, :func:`spinectl.model.chain.chain_coefficients`) and, without muscles, each segment's inverted-pendulum
eigenvalues +-sqrt(g / r_y), with r_y = K_g / (m g).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import value


@cache
def gravity_stiffness() -> tuple:
    """(K_g's diagonal [N m/rad], L1L2 to L5S1; the preset's g [m/s^2] and mass [kg])."""
    from spinectl.model.chain import chain_coefficients
    from spinectl.model.config import load_preset

    model = load_preset("wagner2012")
    return np.diag(chain_coefficients(model, 0.0, 0.0).gravity_stiffness), model.body.gravity, model.body.mass


def pendulum_rates() -> np.ndarray:
    """sqrt(g / r_y) [1/s] of each segment, r_y = K_g / (m g)."""
    k, g, m = gravity_stiffness()
    return np.sqrt(g / (k / (m * g)))


value("errata.gravity_stiffness")(
    lambda: ", ".join(f"{v:.1f}" for v in gravity_stiffness()[0][:-1]) + f" and {gravity_stiffness()[0][-1]:.1f}"
)
value("errata.rates")(lambda: f"±{pendulum_rates()[0]:.2f} … ±{pendulum_rates()[-1]:.2f}")
value("errata.rate_l1l2")(lambda: f"{pendulum_rates()[0]:.2f}")


def paper_convention_line() -> str:
    """``K theta_k = ... N m/rad`` as ``spinectl stability --preset wagner2012_mass_free --K 15 --E 0.03 --Lambda
    0.04`` prints it in its header (``passive.convention = "paper"``: K in 1/s^2, what it adds at each CoR)."""
    from spinectl.model.config import load_preset, set_parameters
    from spinectl.model.source import stiffness_text
    from spinectl.optimise.stabilising import stability_at

    model = set_parameters(load_preset("wagner2012_mass_free"), {"passive.stiffness": 15.0})
    result = stability_at(model, 0.03, 0.04)
    text = stiffness_text(model.passive.stiffness, model.passive.convention, result.inertia)
    return text[text.index("K theta_k") :]


value("model.paper_convention_line", code=True)(paper_convention_line)
