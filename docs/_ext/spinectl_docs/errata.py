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


# --- "The printed eccentric constant" and "The units of eq. 2" (docs/errata.md) ---


def eccentric_difference() -> str:
    """The largest difference of the minimum PCSA over the paper's 81 x 81 grid between the printed and the
    corrected eccentric constant C [cm^2] (two fast sweeps of ``wagner2012``, under a second)."""
    from spinectl.model.config import load_preset, set_parameter
    from spinectl.paper import calibration, grid

    model, axis = load_preset("wagner2012"), grid.paper_axis(grid.PAPER_POINTS)
    printed = set_parameter(model, "errata.eccentric_constant", "printed")
    a, b = (
        calibration.coarse_landscape(m, axis, counter_torque=False)["min_pcsa_cm2"].values for m in (model, printed)
    )
    return f"{float(np.nanmax(np.abs(a - b))):.1f} cm²"


def removed_fractions() -> dict:
    """The fraction of each CoR's gravity stiffness at A that K = 15 N m/rad removes (L1L2 to L5S1):
    ``paper`` K r_k / g (any mass), ``physical`` K / (m g r_k) at ``wagner2012``'s mass, and the mass [kg] at which
    ``physical`` removes half, r_k the height of the mass above CoR k [m]."""
    from spinectl.model.config import load_preset
    from spinectl.paper.grid import PAPER_STIFFNESS

    model = load_preset("wagner2012")
    g, m, k = model.body.gravity, model.body.mass, PAPER_STIFFNESS
    r = model.body.mass_height - np.asarray(model.geometry.cor_heights, float)
    return {"paper": k * r / g, "physical": k / (m * g * r), "half": k / (0.5 * g * r), "mass": m}


def _k15(name: str, column: str) -> str:
    """A K = 15 landmark of ``wagner2012`` in its own convention (``chosen``) or the other (``convention``),
    from :func:`.reproduction.assumption_rows` (the table's 41 x 41 grid, shared with reproduction.md)."""
    from spinectl.paper.verdicts import format_number

    from .reproduction import assumption_rows

    return format_number(assumption_rows()[name].values[column][0])


value("errata.eccentric_difference")(eccentric_difference)
for _kind, _fmt in (("paper", ".2f"), ("physical", ".2f"), ("half", ".1f")):  # one table cell each, L1L2 = 0
    for _k in range(5):
        value(f"errata.{_kind}_{_k}")(lambda kind=_kind, k=_k, fmt=_fmt: f"{removed_fractions()[kind][k]:{fmt}}")
value("errata.fraction_mass")(lambda: f"{removed_fractions()['mass']:.1f} kg")
value("errata.left_l5s1")(
    lambda: f"1 − {removed_fractions()['paper'][-1]:.2f} = {1 - removed_fractions()['paper'][-1]:.2f}"
)
value("errata.left_l4l5")(lambda: f"{1 - removed_fractions()['paper'][-2]:.2f}")
value("errata.halving_mass_range")(
    lambda: f"{np.min(removed_fractions()['half']):.0f}–{np.max(removed_fractions()['half']):.0f} kg"
)
value("errata.l1l2_pair")(
    lambda: f"{removed_fractions()['paper'][0]:.2f} against {removed_fractions()['physical'][0]:.2f}"
)
value("errata.ridge_k15")(lambda: _k15("min_pcsa_ridge_K15", "chosen"))
value("errata.ridge_k15_other")(lambda: _k15("min_pcsa_ridge_K15", "convention"))
value("errata.halving")(lambda: _k15("halving_K15", "chosen"))
value("errata.halving_other")(lambda: _k15("halving_K15", "convention"))
value("errata.low_cors_range")(
    lambda: f"{removed_fractions()['paper'][-2]:.2f}–{removed_fractions()['paper'][-1]:.2f}"
)  # L4L5 and L5S1 under `paper`: docs/reproduction.md's "which would halve it"
