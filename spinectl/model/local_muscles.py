"""The local muscles as joint springs and dampers: their stiffness and damping per unit, their PCSA (docs/chain.md).

The local muscles (multifidus, rotatores) span one joint each, so the chain takes them as a
stiffness k_j and a damping c_loc k_j on the diagonal of K and D (``local``). These functions
convert between k, the muscle's PCSA and its damping, for the chain (:mod:`spinectl.model.chain`),
its optima, the landscape's columns and the exports.

References
----------
Cholewicki J, McGill SM (1996). Mechanical stability of the in vivo lumbar spine:
implications for injury and chronic low back pain. Clin Biomech 11(1):1-15.
doi:10.1016/0268-0033(95)00035-6.
"""

from __future__ import annotations

import numpy as np

from . import laws
from .params import Model


def local_stiffness_per_pcsa(model: Model) -> float:
    """Joint stiffness of a local muscle per unit PCSA at full activation [N m/rad / m^2].

    kappa = q sigma r^2 / l: the muscle's short-range stiffness q F / l (Bergmark 1989;
    Cholewicki & McGill 1996) with F = sigma A, acting at the lever arm r of its joint
    (``local``; docs/chain.md). The geometric stiffness of its tension is neglected.

    Parameters
    ----------
    model : Model
        Supplies ``local`` (q, r [m], l [m]) and ``fibre.specific_tension`` sigma [N/m^2].

    Returns
    -------
    float
        kappa [N m/rad / m^2].

    References
    ----------
    Cholewicki J, McGill SM (1996). Mechanical stability of the in vivo lumbar spine:
    implications for injury and chronic low back pain. Clin Biomech 11(1):1-15.
    doi:10.1016/0268-0033(95)00035-6.
    """
    local = model.local
    return local.stiffness_gain * model.fibre.specific_tension * local.lever_arm**2 / local.length


def local_damping_per_stiffness(model: Model) -> float:
    """c_loc [s]: the joint damping of a local muscle per unit of its joint stiffness, from its force-velocity slope.

    A local muscle at force F with the global fibres' muscle law (``fibre.law``, the force scaled by
    F/f_iso) has dF/dv = F s at rest, v its shortening velocity and s = (dT/dv) / T of the law at rest
    (:func:`spinectl.model.laws.at_rest`; the paper's Hill slope f_H'(0)). At the lever arm r, v = r omega,
    so the joint damping is r^2 F abs(s); its stiffness is k = q F r^2 / l (:func:`local_stiffness_per_pcsa`).
    Both are proportional to F r^2, so

        d = c_loc k,   c_loc = ``local.damping`` * l abs(s) / q,

    whatever the PCSA, activation or lever arm: s (with the paper's law f_H'(0) = -(1 + a) / b) is that of
    a fibre of length l and optimal length l_opt = ``fibre.optimal_length_ratio`` * l (the local muscle all
    fibre, on the ascending limb like the global ones). docs/chain.md, "Local muscles as joint stiffness
    and damping".

    Parameters
    ----------
    model : Model
        Supplies ``local`` (q, l [m], the factor ``damping``), ``fibre`` (the law and its constants) and
        ``errata`` (with the paper's law the eccentric constant, which does not change the slope at rest).

    Returns
    -------
    float
        c_loc [s]; 0 with ``local.damping`` = 0 (the stiffness-only model).

    References
    ----------
    Hill AV (1938). The heat of shortening and the dynamic constants of muscle. Proc R Soc Lond B
    126:136-195. doi:10.1098/rspb.1938.0050.

    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis optimizes
    the requirements for a stable erect posture. Theor Biol Med Model 9:13. doi:10.1186/1742-4682-9-13.
    """
    local = model.local
    l_opt = model.fibre.optimal_length_ratio * local.length
    rest = laws.at_rest(laws.get_law(model.fibre.law), local.length, l_opt, model.fibre, model.errata)
    slope = float(rest.relative_velocity_slope)  # (dT/dv) / T [s/m], < 0: the force falls as the muscle shortens
    # d / k = (r^2 F abs(s)) / (q F r^2 / l): F and r cancel, so c_loc holds at every activation and lever arm
    return local.damping * local.length * -slope / local.stiffness_gain


def local_damping(local_stiffness, model: Model):
    """The joint damping of local muscles of stiffness ``local_stiffness``: c_loc k [N m s/rad].

    Positive (it enters D as -c_loc diag(k)); :func:`local_damping_per_stiffness`.

    Parameters
    ----------
    local_stiffness : array_like
        k [N m/rad].
    model : Model

    Returns
    -------
    numpy.ndarray
        c_loc k [N m s/rad], the shape of ``local_stiffness``.
    """
    return local_damping_per_stiffness(model) * np.asarray(local_stiffness, float)


def local_pcsa(local_stiffness, model: Model):
    """The least local-muscle PCSA that gives a joint the stiffness ``local_stiffness`` [m^2].

    A = k / kappa (:func:`local_stiffness_per_pcsa`), at full activation; compare with the
    paper's 17 cm^2 (30 N m at 7 cm).

    Parameters
    ----------
    local_stiffness : array_like
        k [N m/rad].
    model : Model

    Returns
    -------
    numpy.ndarray
        A [m^2], the shape of ``local_stiffness``.
    """
    return np.asarray(local_stiffness, float) / local_stiffness_per_pcsa(model)
