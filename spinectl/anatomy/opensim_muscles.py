"""OpenSim's muscles as the OpenSim engine's muscle law: each muscle's force along its path, evaluated by OpenSim.

The muscle-law seam (:mod:`spinectl.model.laws`) holds the laws that spinectl writes itself
(the paper's). An ``.osim`` model's muscles already carry their law, its curves and its
parameters, and OpenSim evaluates them, so the OpenSim engine writes no formula of its own: this
module asks OpenSim, muscle by muscle, for the tendon force F (the force along the path,
``Muscle.getTendonForce``), its stiffness dF/dL (``getMuscleStiffness``: the fibre's stiffness
along the tendon in series with the tendon's, pennation included) and its damping dF/dV at zero
speed, whatever the muscle's class among :data:`SUPPORTED`. The linearisation
(:func:`spinectl.anatomy.opensim_engine.linearise`) takes them as each muscle's gain and bias.

- **Rigid tendon** (``ignore_tendon_compliance``): at zero velocity F = a F_act(L, V) + F_pas(L, V)
  is affine in the activation a (Millard 2012, De Groote-Fregly 2016: F_M = F_max (a f_L f_V +
  f_P + beta v~), times the pennation's cosine), so two activations inside the muscle's range give
  gain and bias exactly; dF/dV by central differences of OpenSim's force in the path's lengthening
  speed, set through one coordinate's speed.
- **Compliant tendon** (Thelen 2003 always, Millard and De Groote otherwise): the fibre length
  (or the tendon force) is a state, set by OpenSim's fibre-tendon equilibrium
  (``Model.equilibrateMuscles``); F and its slopes are not affine in a, so they are linearised
  at the operating activation: tangent gain and bias there (exact K and torque at that activation,
  first order about it). The damping is the quasi-static one of a spring k_T in series with a
  spring k_F and a damper c_F: F(s) = k_T (k_F + c_F s) / (k_T + k_F + c_F s) X(s), whose
  expansion to first order in s is k_T k_F / (k_T + k_F) + c_F (k_T / (k_T + k_F))^2 s, so
  dF/dV = c_F (k_T / (k_T + k_F))^2 (k_T ``getTendonStiffness``, k_F
  ``getFiberStiffnessAlongTendon``). c_F, the fibre's damping along the tendon, is read off
  OpenSim's own fibre dynamics at the equilibrium's state: at a fixed state the tendon force is
  fixed, so an activation step da moves the fibre's velocity along the tendon by dv with
  c_F dv + (dF_active/da) da = 0, and dF_active/da at zero velocity is the active fibre force
  along the tendon over a (``getActiveFiberForceAlongTendon``; f_V(0) = 1 in every law). Thelen's
  force-velocity relation has a kink at zero velocity (its lengthening branch is steeper): the
  central difference takes the mean of its two slopes.

A muscle of another class is refused in one line (:func:`check_muscle`).

References
----------
Millard M, Uchida T, Seth A, Delp SL (2013). Flexing computational muscle: modeling and
simulation of musculotendon dynamics. J Biomech Eng 135(2):021005. doi:10.1115/1.4023390.

Thelen DG (2003). Adjustment of muscle mechanics model parameters to simulate dynamic
contractions in older adults. J Biomech Eng 125(1):70-77. doi:10.1115/1.1531112.

De Groote F, Kinney AL, Rao AV, Fregly BJ (2016). Evaluation of direct collocation optimal
control problem formulations for solving the muscle redundancy problem. Ann Biomed Eng
44(10):2922-2936. doi:10.1007/s10439-016-1591-9.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError, ParameterError
from .engine import opensim_message
from .export_osim import require_opensim

SUPPORTED = ("Millard2012EquilibriumMuscle", "Thelen2003Muscle", "DeGrooteFregly2016Muscle")
"""The muscle classes whose force OpenSim evaluates for the linearisation."""

ACTIVATION_STEP = 1e-4
"""Activation step of a compliant muscle's tangent and of its fibre damping [1]."""

SPEED_STEP = 1e-6
"""Coordinate-speed step of a rigid muscle's damping [rad/s]: F is smooth in V there (truncation ~STEP^2)."""


def check_muscle(model_name: str, muscle) -> None:
    """Refuse, in one line, a muscle whose class is not :data:`SUPPORTED`.

    Parameters
    ----------
    model_name : str
    muscle : opensim.Muscle

    Raises
    ------
    ModelError
        Naming the muscle, its class and the supported classes.
    """
    kind = muscle.getConcreteClassName()
    if kind not in SUPPORTED:
        raise ModelError(
            f"{model_name}: muscle {muscle.getName()} ({kind}) is not supported: the OpenSim import reads "
            f"{', '.join(SUPPORTED)}"
        )


def activation_floor(muscle) -> float:
    """The least activation the muscle's law holds: Millard's and Thelen's ``minimum_activation``, else 0.

    Parameters
    ----------
    muscle : opensim.Muscle

    Returns
    -------
    float
    """
    osim = require_opensim()
    for kind in ("Millard2012EquilibriumMuscle", "Thelen2003Muscle"):
        cast = getattr(osim, kind).safeDownCast(muscle)
        if cast is not None:
            return float(cast.get_minimum_activation())
    return 0.0


def compliant(muscle) -> bool:
    """Whether the muscle's tendon is compliant (Thelen's always is).

    Parameters
    ----------
    muscle : opensim.Muscle

    Returns
    -------
    bool
    """
    return muscle.getConcreteClassName() == "Thelen2003Muscle" or not muscle.get_ignore_tendon_compliance()


def _activate(engine, acts) -> None:
    """Each muscle at its activation at the state's velocity stage, then realised to dynamics.

    A muscle that ignores its activation dynamics takes its activation from the controls, which
    OpenSim recomputes (from the model's controllers) whenever the velocity stage is invalidated:
    so the activations are set anew after every change of a speed or of the fibres' cache.
    """
    model, state = engine.model, engine.state
    model.realizeVelocity(state)
    muscles = model.getMuscles()
    for i in range(muscles.getSize()):
        muscles.get(i).setActivation(state, float(acts[i]))
    model.realizeDynamics(state)


def _state_at(engine, values: dict, acts) -> None:
    """The posture at zero speed, each muscle at its activation, compliant fibres in equilibrium, realised."""
    engine.set_posture(values)
    _activate(engine, acts)
    try:
        engine.model.equilibrateMuscles(engine.state)  # a no-op for rigid tendons
    except Exception as exc:  # OpenSim's own exception types; a compliant fibre with no equilibrium there
        raise ParameterError(
            "posture", f"OpenSim cannot put the muscles' fibres in equilibrium at this posture: {opensim_message(exc)}"
        ) from None
    _activate(engine, acts)


def _read(engine, getter: str) -> np.ndarray:
    """One getter of every muscle at the realised state."""
    muscles = engine.model.getMuscles()
    return np.array([getattr(muscles.get(i), getter)(engine.state) for i in range(muscles.getSize())])


def _fibre_damping(engine, acts, floors, rows) -> np.ndarray:
    """c_F of the compliant muscles ``rows`` at the realised equilibrium (module docstring), 0 elsewhere [N s/m]."""
    osim = require_opensim()
    state = engine.state
    active = _read(engine, "getActiveFiberForceAlongTendon")
    out = np.zeros(len(acts))
    steps = [np.minimum(acts + ACTIVATION_STEP, 1.0), np.maximum(acts - ACTIVATION_STEP, floors)]
    speeds = []
    for step in steps:
        moved = np.array(acts, float)
        moved[rows] = step[rows]
        # the fibre's velocity is a velocity-stage cache that an activation alone does not invalidate
        state.invalidateAllCacheAtOrAbove(osim.Stage(osim.Stage.Velocity))
        _activate(engine, moved)
        speeds.append(_read(engine, "getFiberVelocityAlongTendon"))
    for i in rows:
        slope = (speeds[0][i] - speeds[1][i]) / (steps[0][i] - steps[1][i])
        out[i] = -(active[i] / acts[i]) / slope if acts[i] > 0 and slope != 0 else 0.0
    state.invalidateAllCacheAtOrAbove(osim.Stage(osim.Stage.Velocity))
    _activate(engine, acts)
    return out


def _path_damping(engine, acts, arms, names, rows) -> np.ndarray:
    """dF/dV of the rigid muscles ``rows`` at the realised state, by central differences in one coordinate's speed.

    Each muscle's speed is set through the coordinate of its largest moment arm; a muscle with no
    arm on ``names``, or whose lengthening speed that coordinate's speed does not change, gets 0 (it adds
    nothing to D).
    """
    state = engine.state
    out = np.zeros(arms.shape[0])
    pick = np.argmax(np.abs(arms), axis=1)
    for k, name in enumerate(names):
        mine = [i for i in rows if pick[i] == k and np.abs(arms[i, k]) > 0]
        if not mine:
            continue
        coordinate = engine.coordinate(name)
        sides = []
        for sign in (1.0, -1.0):
            coordinate.setSpeedValue(state, sign * SPEED_STEP)
            _activate(engine, acts)
            sides.append((_read(engine, "getTendonForce"), _read(engine, "getLengtheningSpeed")))
        coordinate.setSpeedValue(state, 0.0)
        for i in mine:
            speed = sides[0][1][i] - sides[1][1][i]
            # a path that does not lengthen with the coordinate adds no damping through it: its largest arm is
            # round-off (Pose2Sim's LD_R12_r on L1_T12_Flex_Ext at -10 deg: 1.4e-17 m/rad), its speed and force
            # unchanged, 0/0 (before: NaN in D, the chain refused)
            out[i] = (sides[0][0][i] - sides[1][0][i]) / speed if speed != 0 else 0.0
    _activate(engine, acts)
    return out


def _evaluate(engine, values: dict, acts, floors, arms, names, rigid) -> np.ndarray:
    """(F, dF/dL, dF/dV) of every muscle at the activations ``acts``, shape (3, m) [N, N/m, N s/m]."""
    _state_at(engine, values, acts)
    force, stiffness = _read(engine, "getTendonForce"), _read(engine, "getMuscleStiffness")
    damping = _path_damping(engine, acts, arms, names, np.flatnonzero(rigid))
    springs = np.flatnonzero(~rigid)
    if springs.size:
        k_t, k_f = _read(engine, "getTendonStiffness")[springs], _read(engine, "getFiberStiffnessAlongTendon")[springs]
        c_f = _fibre_damping(engine, np.asarray(acts, float), floors, springs)[springs]
        # a slack tendon (k_T = 0) passes no damping: the share k_T / (k_T + k_F) is 0; a tendon that OpenSim
        # reports infinitely stiff (a Thelen tendon below its slack strain's toe, say) passes it all: 1
        share = np.divide(k_t, k_t + k_f, out=np.where(np.isinf(k_t), 1.0, 0.0), where=np.isfinite(k_t) & (k_t > 0))
        damping[springs] = c_f * share**2
    return np.array([force, stiffness, damping])


def tension_terms(engine, values: dict, operating, arms, names) -> tuple:
    """Every muscle's gain and bias, and their slopes in length and velocity, from OpenSim (module docstring).

    Parameters
    ----------
    engine : OsimEngine
    values : dict
        Coordinate name -> value [rad] of the posture.
    operating : array_like, shape (m,)
        The operating activations [1]: where a compliant muscle is linearised (clipped to its range).
    arms : numpy.ndarray, shape (m, s)
        dL/dq over ``names`` [m/rad]: which coordinate's speed moves each muscle.
    names : sequence of str
        The coordinates involved.

    Returns
    -------
    tuple
        (numpy.ndarray of shape (6, m): gain, dgain/dL, dgain/dV, bias, dbias/dL, dbias/dV, the force
        along the path with a pull negative [N, N/m, N s/m]; the notes on how, a tuple of str).
    """
    muscles = engine.model.getMuscles()
    items = [muscles.get(i) for i in range(muscles.getSize())]
    floors = np.array([activation_floor(m) for m in items])
    rigid = np.array([not compliant(m) for m in items], dtype=bool)  # bool also without muscles
    a0 = np.clip(np.asarray(operating, float), floors, 1.0)
    # rigid: two activations across the range (F affine in a there); compliant: the tangent at a0
    low = np.where(rigid, floors + 0.25 * (1.0 - floors), np.maximum(a0 - ACTIVATION_STEP, floors))
    high = np.where(rigid, 1.0, np.minimum(a0 + ACTIVATION_STEP, 1.0))
    try:
        at_low = _evaluate(engine, values, low, floors, arms, names, rigid)
        at_high = _evaluate(engine, values, high, floors, arms, names, rigid)
    finally:
        engine.set_posture(values)
    gain = (at_high - at_low) / (high - low)
    bias = at_low - gain * low
    notes = ()
    if not rigid.all():
        names_ = [m.getName() for m, r in zip(items, rigid, strict=True) if not r]
        notes = (
            f"{len(names_)} compliant-tendon muscle(s) ({', '.join(names_[:3])}{', ...' if len(names_) > 3 else ''})"
            " linearised at the operating activations (tangent gain and bias; quasi-static series damping)",
        )
    return -np.concatenate([gain, bias]), notes
