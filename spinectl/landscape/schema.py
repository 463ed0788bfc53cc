"""The landscape Dataset: its variables with units and long names, dimensions, coordinates and attributes.

The schema is listed in docs/optimisation.md; sweeps (:mod:`spinectl.landscape.sweep`) and studies
(:mod:`spinectl.landscape.study`) write the same variables, and the atlas (:mod:`spinectl.landscape.atlas`)
those of its draws. Every output name has one entry here (:data:`VARIABLES` or :data:`DRAW_VARIABLES`, never
both) and one function that computes it, in :mod:`spinectl.landscape.columns`, whichever command asks for it.
"""

from __future__ import annotations

import xarray as xr

from .._version import __version__
from ..model import config, source
from ..model.params import Model

PAPER_REFERENCE = (
    "Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012) Spinal lordosis optimizes "
    "the requirements for a stable erect posture. Theor Biol Med Model 9:13"
)


VARIABLES = {
    "min_pcsa_cm2": ("cm2", "minimum total PCSA of the global muscles for self-stability of all segments (Fig. 3)"),
    "pcsa_cm2": ("cm2", "chosen activation: PCSA of each muscle (least ||CT|| within ct_tolerance of the minimum)"),
    "counter_torque_Nm": ("N m", "local counter torque CT_k at the chosen activation"),
    "counter_torque_norm_Nm": ("N m", "Euclidean norm ||CT|| of the local counter torques (Fig. 4)"),
    "status": ("", "solver status: optimal, optimal_inaccurate, infeasible, infeasible_inaccurate, solver_error"),
    "stiffness_per_cm2": ("N m rad-1 cm-2", "dM_k/dalpha of each muscle per cm2 of its PCSA"),
    "damping_per_cm2": ("N m s rad-1 cm-2", "dM_k/domega of each muscle per cm2 of its PCSA"),
    "torque_per_cm2": ("N m cm-2", "torque of each muscle about CoR k per cm2 of its PCSA, upright"),
    "gravity_stiffness_Nm_per_rad": ("N m rad-1", "dM_ext/dalpha of the point mass (destabilising if > 0)"),
    "gravity_torque_Nm": ("N m", "torque M_ext of the point mass about CoR k, upright"),
    "passive_stiffness_Nm_per_rad": ("N m rad-1", "passive stiffness K as a torque stiffness (enters dM/dalpha as -K)"),
    "inertia_kgm2": ("kg m2", "moment of inertia theta_k of the upper body about CoR k"),
    "reflex_kp_Nm_per_rad": ("N m rad-1", "proportional gain kp of the delayed reflex (reflex settings)"),
    "reflex_kd_Nms_per_rad": ("N m s rad-1", "derivative gain kd of the delayed reflex (reflex settings)"),
    "delay_margin_s": (
        "s",
        "exact delay margin of the reflex loop (with the activation lag reflex.activation_time_constant) "
        "at reflex.activation x chosen PCSA",
    ),
    "delay_margin_pade_s": ("s", "Pade estimate of the delay margin at reflex.pade_order"),
    "delay_margin_status": ("", "finite, delay_independent (inf), unstable_without_delay (0) or undefined (NaN)"),
    "stable_at_delay": ("", "closed loop stable with the delay reflex.delay and the activation lag (exact)"),
    "spine_delay_margin_s": ("s", "smallest delay margin over the segments: the delay the whole spine tolerates"),
    "slowest_time_constant_s": (
        "s",
        "slowest time constant of the segments at the chosen activation, -1/max Re(lambda) (eq. 1; inf if not stable)",
    ),
    "coupled_margin_Nm_per_rad": (
        "N m rad-1",
        "static margin of the coupled chain at the chosen activation: smallest eigenvalue of -K (> 0 stable)",
    ),
    "local_stiffness_Nm_per_rad": (
        "N m rad-1",
        "least local-muscle stiffness k_j that makes the coupled chain stable at the chosen activation, the whole "
        "minimum PCSA (SDP, problem (a))",
    ),
    "local_stiffness_total_Nm_per_rad": ("N m rad-1", "sum over the joints of local_stiffness_Nm_per_rad"),
    "joint_global_pcsa_cm2": ("cm2", "joint optimum of global and local muscle (coupled chain): total global PCSA"),
    "joint_local_pcsa_cm2": ("cm2", "joint optimum of global and local muscle (coupled chain): total local PCSA"),
}
"""Every data variable of a landscape (sweep, study): units (UDUNITS) and long name."""

DRAW_VARIABLES = {
    "counter_torque_max_Nm": ("N m", "largest |CT_k| over the segments at the chosen activation"),
    "cocontraction_local_stiffness_total_Nm_per_rad": (
        "N m rad-1",
        "least total local-muscle stiffness sum k_j that makes the coupled chain stable with the global muscles at "
        "reflex.activation x chosen PCSA, the draw's co-contraction (SDP, problem (a)); at reflex.activation = 1 "
        "local_stiffness_total_Nm_per_rad",
    ),
    "cocontraction_local_stiffness_max_Nm_per_rad": (
        "N m rad-1",
        "largest k_j of the joints in cocontraction_local_stiffness_total_Nm_per_rad's optimum",
    ),
    "local_stiffness_limit_Nm_per_rad": (
        "N m rad-1",
        "the local muscles' stiffness at the atlas's local_pcsa_limit_cm2 per joint (kappa x the limit)",
    ),
    "delay_s": ("s", "the reflex delay of the draw (reflex.delay): stable_at_delay compares the margin with it"),
}
"""The atlas's outputs at each draw beyond :data:`VARIABLES` (``draws.npz``): units and long name.

Before 0.1.0 was released, the atlas called ``cocontraction_local_stiffness_total_Nm_per_rad``
``local_stiffness_total_Nm_per_rad``, the name of the landscape's variable at the whole minimum PCSA; the two differ
wherever ``reflex.activation`` < 1 (docs/atlas.md, "The answer")."""

ON_REQUEST = (
    "local_stiffness_Nm_per_rad",
    "local_stiffness_total_Nm_per_rad",
    "joint_global_pcsa_cm2",
    "joint_local_pcsa_cm2",
)
"""Variables computed only when asked for (``sweep --coupled``, a study's ``outputs``): semidefinite
programmes of the coupled chain, about 2.7 ms a point, seven times the rest of a landscape (docs/chain.md)."""


def dims_of(name: str, ndim: int) -> tuple[str, ...]:
    """Dimensions of the variable ``name`` on the grid, from the number of its dimensions.

    Parameters
    ----------
    name : str
        A key of :data:`VARIABLES`.
    ndim : int
        2 (E, Lambda), 3 (plus segment, or muscle for ``pcsa_cm2``) or 4 (plus segment and muscle).

    Returns
    -------
    tuple of str
        Dimension names, ``("E", "Lambda", ...)``.
    """
    extra = {3: ("muscle",) if name == "pcsa_cm2" else ("segment",), 4: ("segment", "muscle")}
    return ("E", "Lambda") + extra.get(ndim, ())


K_UNITS = {"physical": "N m rad-1", "paper": "s-2"}
"""UDUNITS of the coordinate ``K`` under each ``passive.convention`` (``spinectl.model.source.STIFFNESS_UNITS``):
under eq. 2 as printed K is an angular acceleration per radian (docs/model.md, "Passive stiffness: two conventions")."""


def grid_coordinates(model: Model, e_axis, l_axis) -> dict:
    """The coordinates ``E``, ``Lambda``, ``segment`` and ``muscle`` of a landscape, with units and names.

    Parameters
    ----------
    model : Model
        Supplies the names of the segments and muscles.
    e_axis, l_axis : array_like, 1-D
        Grid axes E and Lambda [m].

    Returns
    -------
    dict
        ``{name: (dimension, values, attributes)}`` for ``E`` [m], ``Lambda`` [m],
        ``segment`` and ``muscle``, as xarray takes coordinates.
    """
    return {
        "E": ("E", e_axis, {"units": "m", "long_name": "eccentricity of the spine"}),
        "Lambda": ("Lambda", l_axis, {"units": "m", "long_name": "lordosis: horizontal offset of P3"}),
        "segment": ("segment", list(model.geometry.cor_names), {"long_name": "centre of rotation"}),
        "muscle": ("muscle", list(model.muscle_names), {"long_name": "global muscle"}),
    }


def landscape_dataset(model: Model, e_axis, l_axis, arrays: dict, method: str, per_point: int) -> xr.Dataset:
    """The landscape Dataset of a sweep: variables with units, coordinates and the model as attributes.

    Parameters
    ----------
    model : Model
        The resolved model, written into the ``config_toml`` attribute.
    e_axis, l_axis : array_like, 1-D
        Grid axes E and Lambda [m].
    arrays : dict of str to numpy.ndarray
        Keys of :data:`VARIABLES`, each of shape (len(e_axis), len(l_axis), ...).
    method : str
        How the grid was solved ('fast' or 'per-point').
    per_point : int
        Points that the per-point reference solved.

    Returns
    -------
    xarray.Dataset
        Dimensions ``E``, ``Lambda``, ``segment``, ``muscle``; a scalar coordinate ``K``.
    """
    data_vars = {
        name: xr.Variable(dims_of(name, arr.ndim), arr, {"units": VARIABLES[name][0], "long_name": VARIABLES[name][1]})
        for name, arr in arrays.items()
    }
    coords = grid_coordinates(model, e_axis, l_axis) | {
        "K": (
            (),
            model.passive.stiffness,
            {"units": K_UNITS[model.passive.convention], "long_name": "passive stiffness K"},
        ),
    }
    attrs = {
        "title": "spinectl landscapes of minimum PCSA and counter torques",
        "source": f"spinectl {__version__}",
        "references": PAPER_REFERENCE,
        "method": method,
        "points_solved_per_point": per_point,
        "passive_convention": model.passive.convention,
        "activation": model.optimisation.activation,
        "reflex_delay_s": model.reflex.delay,
        "reflex_activation_time_constant_s": model.reflex.activation_time_constant,
        "reflex_activation": model.reflex.activation,
        "config_toml": config.dump_toml(model),
    } | source.attributes(model)
    return xr.Dataset(data_vars, coords, attrs)
