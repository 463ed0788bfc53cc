"""Published trends of spinal stability, computed on an anatomical model (docs/contributions.md, "Published trends").

Three analyses of the literature, each on the model's free chain and its anatomy optimum
(:func:`spinectl.anatomy.optimum.optimise`), the index being lambda_min of -sym(K) (Cholewicki & McGill 1996):

- :func:`co_contraction_path`: antagonistic co-contraction at a fixed net moment, against the compression it
  adds (Granata & Marras 2000);
- :func:`stability_price`: the effort that stability costs above equilibrium alone, against a load held
  (Cholewicki, Panjabi & Khachatryan 1997);
- the removal of a muscle group (Cholewicki & VanVliet 2002) is :func:`spinectl.model.contributions.contributions`
  with :func:`spinectl.anatomy.contributions.optimum_resolver`; :data:`GROUPS` are their groups on MyoTorso.

The tests that hold the model to these papers, or say where it disagrees, are
``tests/anatomy/test_published_trends.py``.

References
----------
Cholewicki J, McGill SM (1996). Clin Biomech 11(1):1-15. doi:10.1016/0268-0033(95)00035-6.
Cholewicki J, Panjabi MM, Khachatryan A (1997). Stabilizing function of trunk flexor-extensor muscles around a
neutral spine posture. Spine 22(19):2207-2212. doi:10.1097/00007632-199710010-00003.
Cholewicki J, VanVliet JJ (2002). Clin Biomech 17(2):99-105. doi:10.1016/S0268-0033(01)00118-8.
Granata KP, Marras WS (2000). Cost-benefit of muscle cocontraction in protecting against spinal instability.
Spine 25(11):1398-1404. doi:10.1097/00007632-200006010-00012.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..model.contributions import least_mode
from .buckling import critical_load, load_stiffness_per_newton, weight_load
from .contract import AnatomyEngine
from .optimum import MARGIN, _lumbar_only, optimise, solve_on_chain

GROUPS = {
    "erector_spinae": "IL|LTp",
    "multifidus": "MF",
    "quadratus_lumborum": "QL",
    "psoas": "Ps",
    "obliques": "EO|IO",
    "rectus": "rect",
}
"""Cholewicki & VanVliet's (2002) muscle groups as MyoTorso's name prefixes (:func:`re.match`): iliocostalis
(IL) with longissimus thoracis pars thoracis and lumborum (LTpT, LTpL); multifidus; quadratus lumborum; psoas;
external and internal obliques; rectus abdominis."""

ABDOMINALS = "EO|IO|rect"
"""MyoTorso's abdominal flexors: the antagonists of an upright hold, whose net moment the extensors make."""

MAX_CRITICAL_LOAD = 1e5
"""The largest load searched for the critical load [N]: :data:`spinectl.model.loads.MAX_LOAD`."""


@dataclass(frozen=True)
class CoContraction:
    """A co-contraction path at a fixed net moment (:func:`co_contraction_path`).

    Attributes
    ----------
    floors : numpy.ndarray, shape (p,)
        The antagonists' least activation along the path [1].
    activations : numpy.ndarray, shape (p, m)
        The least-effort activations at each floor [1].
    index : numpy.ndarray, shape (p,)
        lambda_min of -sym(K) of the free chain [N m/rad].
    critical_load : numpy.ndarray, shape (p,)
        The least load along gravity at the thorax's centre of mass at which lambda_min reaches 0, the
        activations fixed [N] (:func:`spinectl.anatomy.buckling.critical_load`)
        (0 where already unstable, inf where none up to :data:`MAX_CRITICAL_LOAD` is).
    compression : numpy.ndarray, shape (p,)
        The sum of the forces of the muscles that cross the lumbar chain [N]: the compression they add if each
        ran along the spine (an upper bound; the model's tendons have no joint reaction).
    residual : numpy.ndarray, shape (p,)
        The largest equilibrium residual along the path [N m]: the net moment kept.
    """

    floors: np.ndarray
    activations: np.ndarray
    index: np.ndarray
    critical_load: np.ndarray
    compression: np.ndarray
    residual: np.ndarray

    def rise(self, values) -> float:
        """The relative rise of ``values`` from the first floor to the last.

        Parameters
        ----------
        values : array_like, shape (p,)
            One of the path's series (``index``, ``critical_load``, ``compression``).

        Returns
        -------
        float
            values[-1] / values[0] - 1 [1].
        """
        return float(values[-1] / values[0] - 1.0)


def co_contraction_path(
    anatomy: AnatomyEngine,
    floors,
    antagonists: str = ABDOMINALS,
    joint_stiffness="mapped",
    plane: str = "sagittal",
    posture=None,
) -> CoContraction:
    """Antagonistic co-contraction at a fixed net moment: stability and compression along it (Granata & Marras 2000).

    At each floor c, the least-effort activations (the anatomy optimum without a stability criterion, volume
    weights, the equilibrium on the rhythm's rows) with every antagonist at least at c: the agonists re-solved,
    the net moment of the hold kept.

    Parameters
    ----------
    anatomy : AnatomyEngine
        A MuJoCo model (the muscle forces are MuJoCo's).
    floors : array_like, shape (p,)
        The antagonists' least activation at each step [1], in [0, 1].
    antagonists : str
        A regular expression matched at the start of the muscles' names.
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    plane : str
        The chain.
    posture : optional
        The engine's posture; default the reference.

    Returns
    -------
    CoContraction

    Raises
    ------
    ParameterError
        A floor outside [0, 1], an expression matching no muscle, or a floor at which the hold is infeasible.

    References
    ----------
    Granata KP, Marras WS (2000). Spine 25(11):1398-1404. doi:10.1097/00007632-200006010-00012.
    """
    floors = np.asarray(floors, float)
    if floors.ndim != 1 or not np.all((floors >= 0) & (floors <= 1)):
        raise ParameterError("floors", f"must be activations in [0, 1] (got {floors.tolist()!r})")
    free, _, lin = anatomy.chains(plane, posture, joint_stiffness)
    _, tau_per, tau_0 = anatomy.equilibrium_rows(lin, plane, posture, "rhythm")
    chosen = np.array([bool(re.match(antagonists, c)) for c in free.controls])
    if not chosen.any():
        raise ParameterError("antagonists", f"must match at least one muscle (got {antagonists!r})")
    lumbar, weights = _lumbar_only(free), anatomy.volume_weights()
    path = []
    for floor in floors:
        status, a = solve_on_chain(
            dataclasses.replace(lumbar, lower=np.where(chosen, floor, lumbar.lower)), tau_per, tau_0, weights, "none", 0
        )
        if not np.all(np.isfinite(a)):
            raise ParameterError("floors", f"must leave the hold feasible (got {floor:g}: the optimum is {status})")
        path.append(a)
    path = np.array(path)
    crossing = np.array([c != "non-lumbar" for c in free.control_class])
    per_newton = load_stiffness_per_newton(anatomy, plane, posture, joint_stiffness)[0]
    return CoContraction(
        floors=floors,
        activations=path,
        index=np.array([least_mode(free.stiffness(a)).eigenvalue for a in path]),
        critical_load=np.array([critical_load(free.stiffness(a), per_newton, MAX_CRITICAL_LOAD) for a in path]),
        compression=path[:, crossing] @ muscle_force_per_activation(anatomy, posture)[crossing],
        residual=np.max(np.abs(path @ tau_per.T + tau_0), axis=1),
    )


def muscle_force_per_activation(anatomy: AnatomyEngine, posture=None) -> np.ndarray:
    """Each muscle's force at full activation and zero velocity at a posture, MuJoCo's own [N].

    Parameters
    ----------
    anatomy : AnatomyEngine
        A MuJoCo model.
    posture : optional
        The engine's posture; default the reference.

    Returns
    -------
    numpy.ndarray, shape (m,)
        Positive: a pull.
    """
    from .engine import require_mujoco

    mujoco, engine = require_mujoco(), anatomy.engine
    engine.set_state(anatomy.posture(posture), np.ones(engine.model.na))
    mujoco.mj_fwdActuation(engine.model, engine.data)
    return -engine.data.actuator_force[engine.muscle_ids()].copy()  # MuJoCo's muscle force is negative


@dataclass(frozen=True)
class StabilityPrice:
    """The effort stability costs against a load held (:func:`stability_price`).

    Attributes
    ----------
    loads : numpy.ndarray, shape (p,)
        The downward vertical loads at the thorax [N].
    stable_cost, classic_cost : numpy.ndarray, shape (p,)
        sum w_i a_i^2 of the optimum with the chain criterion and without one (NaN where infeasible).
    """

    loads: np.ndarray
    stable_cost: np.ndarray
    classic_cost: np.ndarray

    @property
    def price(self) -> np.ndarray:
        """The stable optimum's cost above the classic one's, shape (p,)."""
        return self.stable_cost - self.classic_cost


def stability_price(
    anatomy: AnatomyEngine, loads, joint_stiffness="mapped", margin: float = MARGIN, plane: str = "sagittal"
) -> StabilityPrice:
    """The effort stability costs above equilibrium alone, against a mass added to the torso (Cholewicki 1997).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model. The load acts along gravity at the centre of mass of its mapping's thorax body
        (:func:`spinectl.anatomy.buckling.weight_load`), as a mass added to the torso does (the protocol of
        Cholewicki et al. 1997).
    loads : array_like, shape (p,)
        Downward loads [N], >= 0 (the added mass times g).
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad].
    margin : float
        mu of the chain criterion [N m/rad].
    plane : str
        The chain.

    Returns
    -------
    StabilityPrice

    References
    ----------
    Cholewicki J, Panjabi MM, Khachatryan A (1997). Spine 22(19):2207-2212. doi:10.1097/00007632-199710010-00003.
    """
    loads = np.asarray(loads, float)
    if loads.ndim != 1 or not np.all(loads >= 0):
        raise ParameterError("loads", f"must be downward forces >= 0 [N] (got {loads.tolist()!r})")
    costs = {"chain": [], "none": []}
    for load in loads:
        held = [weight_load(anatomy, float(load))]  # a mass added to the torso: its weight at the thorax's CoM
        for criterion, out in costs.items():
            opt = optimise(anatomy, plane, criterion, margin, joint_stiffness=joint_stiffness, loads=held)
            out.append(opt.cost if opt.ok else float("nan"))
    return StabilityPrice(loads, np.array(costs["chain"]), np.array(costs["none"]))
