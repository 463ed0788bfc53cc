"""The paper's muscle law, ``wagner2012``: its exponential force-length and Hill force-velocity relations.

The relations are those of :mod:`spinectl.model.muscle` (docs/model.md, "Force-length" and
"Force-velocity"), with the fibre's constants (``fibre.k1``, ``k2``, the Hill constants) and the
eccentric constant C of ``errata.eccentric_constant``; no passive force, a rigid tendon. Written
as OpenSim expressions by :func:`opensim_curves` for ``spinectl export --osim-muscle paper``.

References
----------
Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis optimizes the
requirements for a stable erect posture. Theor Biol Med Model 9:13. doi:10.1186/1742-4682-9-13.

Hill AV (1938). The heat of shortening and the dynamic constants of muscle. Proc R Soc Lond B
126:136-195. doi:10.1098/rspb.1938.0050.
"""

from __future__ import annotations

import numpy as np

from .. import muscle
from .law import MuscleLaw, OpenSimCurves

# The law's relations in the MuscleLaw's signatures (its attributes say what each takes and gives):
# muscle.py's with l_opt = 1 for the force-length (x / 1 and a slope over 1 keep every bit), and the
# Hill constants of the fibre's l_opt for the force-velocity.


def _active_force_length(ratio, fibre):
    """f_L(x) = exp(-((x^k1 - 1) / k2)^2) [1] at x = l / l_opt."""
    return muscle.force_length(ratio, 1.0, fibre)


def _active_force_length_slope(ratio, fibre):
    """df_L/dx [1] at x = l / l_opt."""
    return muscle.force_length_slope(ratio, 1.0, fibre)


def _force_velocity(velocity, optimal_length, fibre, errata):
    """Hill's f_H / f_iso [1] at the shortening velocity ``velocity`` [m/s] of fibres of optimal length [m]."""
    return muscle.force_velocity(velocity, muscle.hill_constants(optimal_length, fibre, errata))


def _force_velocity_slope(velocity, optimal_length, fibre, errata):
    """d(f_H / f_iso)/dv [s/m] at the shortening velocity ``velocity`` [m/s] of fibres of optimal length [m]."""
    return muscle.force_velocity_slope(velocity, muscle.hill_constants(optimal_length, fibre, errata))


def opensim_curves(fibre, errata) -> OpenSimCurves:
    """The paper's force-length and force-velocity factors as OpenSim expressions of the normalised fibre state.

    OpenSim's ``RigidTendonMuscle`` evaluates its active force-length curve at x = l / l_opt and its
    force-velocity curve at w = V / (l_opt v_hat), V the lengthening velocity and v_hat its
    ``max_contraction_velocity`` [l_opt/s]. With v_max = v_hat l_opt (:func:`~spinectl.model.muscle.max_velocity`)
    and the shortening velocity v = -w v_max, the paper's factors (:mod:`spinectl.model.muscle`) are
    f_l = exp(-((x^k1 - 1) / k2)^2), and f_H = c~ / (b~ - w) - a for w <= 0 (concentric, v >= 0),
    A - C~ / (w + B~) for w > 0, with b~, c~, B~, C~ the Hill constants over v_max (the same for every
    fibre, since b and B scale with l_opt). Numbers are written with ``repr``: the shortest decimal
    that reads back to the same double.

    Parameters
    ----------
    fibre : Fibre
    errata : Errata

    Returns
    -------
    OpenSimCurves
        The force-length expression in x and the force-velocity expression in w.

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis optimizes the
    requirements for a stable erect posture. Theor Biol Med Model 9:13. doi:10.1186/1742-4682-9-13.
    """
    unit = float(muscle.max_velocity(1.0, fibre))  # v_max of a fibre with l_opt = 1 m: the Hill constants over v_max
    hill = muscle.hill_constants(np.asarray(1.0), fibre, errata)
    a, b, c = float(hill.a), float(hill.b) / unit, float(hill.c) / unit
    big_a, big_b, big_c = float(hill.A), float(hill.B) / unit, float(hill.C) / unit
    length = f"exp(-((x^{float(fibre.k1)!r} - 1) / {float(fibre.k2)!r})^2)"
    # step(-w) is 1 at w = 0: the concentric branch there, as spinectl's; min/max keep each branch off its pole
    velocity = (
        f"step(-w) * ({c!r} / ({b!r} - min(w, 0)) - {a!r})"
        f" + (1 - step(-w)) * ({big_a!r} - {big_c!r} / (max(w, 0) + {big_b!r}))"
    )
    return OpenSimCurves(length, velocity)


LAW = MuscleLaw(
    name="wagner2012",
    active_force_length=_active_force_length,
    active_force_length_slope=_active_force_length_slope,
    force_velocity=_force_velocity,
    force_velocity_slope=_force_velocity_slope,
    opensim=opensim_curves,
    reference="Wagner et al. (2012), Theor Biol Med Model 9:13, doi:10.1186/1742-4682-9-13; Hill (1938)",
)
"""The paper's law, registered as ``wagner2012`` (the default of ``fibre.law``)."""
