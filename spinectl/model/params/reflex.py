"""The delayed PD reflex per segment and its time-domain simulation (docs/reflex.md, "The loop")."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ... import _validate as v
from ...errors import ParameterError
from .bounds import MAX_ACTIVATION, MAX_ACTIVATION_TIME_CONSTANT, MAX_DELAY, MAX_PADE_ORDER, _store, param, seconds


@dataclass(frozen=True)
class Reflex:
    """Delayed PD reflex per segment and its time-domain simulation (docs/reflex.md, "The loop").

    Beyond the paper, which discusses reflexes in words only (Discussion: "reflexes are
    delayed by up to 100 ms ... the force generation of the muscles takes another
    50-100 ms"). The reflex command -(kp alpha + kd omega)(t - delay) becomes the torque u
    through the force-generation lag T_a u' + u = command (``activation_time_constant``); see
    ``docs/reflex.md`` for the default gain rule and the margins.
    """

    delay: float = param(
        0.1,
        "s",
        "Reflex delay tau. The paper's Discussion: reflexes follow a perturbation by up to 100 ms "
        f"(force generation adds another 50-100 ms). 0 to {MAX_DELAY:g} s.",
    )
    activation_time_constant: float = param(
        0.05,
        "s",
        "Force generation (excitation-contraction dynamics) of the reflex torque as a first-order lag "
        "1/(T_a s + 1) after the delay. The paper's Discussion: force generation takes another 50-100 ms. "
        "Default 50 ms: the contraction time constants (tau1 = tau2 = 50 ms) of active human muscle at "
        "about 20 % of maximum effort (Zahalak GI, Heyman SJ 1979, J Biomech Eng 101:28-37, "
        "doi:10.1115/1.3426220); spinectl keeps one of the two. 0 is the pure delay; at most "
        f'{MAX_ACTIVATION_TIME_CONSTANT:g} s (docs/reflex.md, "Force generation: the activation lag").',
    )
    pade_order: int = param(
        5, "1", f"Order of the Pade approximant of exp(-s tau) in the python-control models, 1 to {MAX_PADE_ORDER}."
    )
    activation: float = param(
        0.5,
        "1",
        "Global-muscle activation as a fraction of the minimum stabilising PCSA (optimise.solve_point): "
        f"0 = no co-contraction, reflex only; 1 = self-stable, no reflex needed; at most {MAX_ACTIVATION:g}.",
    )
    gains: str = param(
        "rule",
        "",
        "'rule': kp and kd from the default rule (gain_factor, damping_ratio); 'explicit': the kp and kd below.",
    )
    gain_factor: float = param(
        1.5,
        "1",
        "Default rule: kp = gain_factor * max(S, 0), the stiffness deficit below self-stability times this "
        "factor (> 1, so that the net stiffness kp - S is positive). 1.5 leaves half the deficit as net "
        "stiffness and, with damping_ratio 1, gives the reflex-only spine about the largest delay margin "
        "the rule can (docs/reflex.md).",
    )
    damping_ratio: float = param(
        1.0,
        "1",
        "Default rule: kd = max(0, 2 zeta sqrt(theta (kp - S)) + D), the derivative gain that gives the "
        "delay-free closed loop this damping ratio zeta (1: critical damping), after the muscles' own "
        "damping D <= 0.",
    )
    kp: float = param(0.0, "N m/rad", "Proportional reflex gain, used when gains = 'explicit'.")
    kd: float = param(0.0, "N m s/rad", "Derivative reflex gain, used when gains = 'explicit'.")
    sim_duration: float = param(
        12.0, "s", "Length of a nonlinear simulation; should span several periods of the slowest oscillation."
    )
    sim_time_step: float = param(
        0.004, "s", "Fixed RK4 step of the simulation (reduced to the delay when the delay is shorter)."
    )
    sim_perturbation: float = param(
        1e-3, "rad", "Initial angle: the segment is held at this angle (omega = 0) and released at t = 0."
    )
    sim_divergence: float = param(
        0.2,
        "rad",
        "A simulation stops as unstable once |alpha| exceeds this angle (the linear verdict no longer holds).",
    )

    def __post_init__(self):
        factor = v.real("gain_factor", self.gain_factor)
        if factor <= 1.0:
            raise ParameterError("gain_factor", f"must be > 1, or the reflex cannot stabilise (got {factor:g})")
        v.choice("gains", self.gains, ("rule", "explicit"))
        duration = v.positive("sim_duration", self.sim_duration)
        step = v.positive("sim_time_step", self.sim_time_step)
        if step >= duration:
            raise ParameterError("sim_time_step", f"must be < sim_duration = {duration:g} s (got {step:g})")
        limit = v.positive("sim_divergence", self.sim_divergence)
        if limit > math.pi / 2:
            raise ParameterError("sim_divergence", f"must be <= pi/2 rad, a quarter turn (got {limit:g})")
        kick = v.positive("sim_perturbation", self.sim_perturbation)
        if kick >= limit:
            raise ParameterError("sim_perturbation", f"must be < sim_divergence = {limit:g} rad (got {kick:g})")
        _store(
            self,
            delay=seconds("delay", self.delay, MAX_DELAY),
            activation_time_constant=seconds(
                "activation_time_constant", self.activation_time_constant, MAX_ACTIVATION_TIME_CONSTANT
            ),
            pade_order=v.integer("pade_order", self.pade_order, 1, MAX_PADE_ORDER),
            activation=v.in_range("activation", self.activation, 0.0, MAX_ACTIVATION),
            gain_factor=factor,
            damping_ratio=v.positive("damping_ratio", self.damping_ratio),
            kp=v.non_negative("kp", self.kp),
            kd=v.non_negative("kd", self.kd),
            sim_duration=duration,
            sim_time_step=step,
            sim_perturbation=kick,
            sim_divergence=limit,
        )
