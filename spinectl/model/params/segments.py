"""What each joint of the chain adds: the passive stiffness K, the local muscles, the levels' inertia.

docs/chain.md sets out the coupled chain these parameters describe.
"""

from __future__ import annotations

from dataclasses import dataclass

from ... import _validate as v
from .bounds import MAX_LOCAL_DAMPING, _length, _store, param


@dataclass(frozen=True)
class Passive:
    """Passive stiffness K of the ligamentous sheath (paper, Elastic elements, eq. 2)."""

    stiffness: float = param(0.0, "N m/rad", "K; the paper's value is 15 N m/rad (its ref. 26). 0 = Figure 3.")
    convention: str = param(
        "physical",
        "",
        "'physical': K adds -K to dM/dalpha (i.e. -K/theta to d(omega')/dalpha). 'paper': eq. 2 as "
        "printed, -K subtracted from d(omega')/dalpha itself (K then read in 1/s^2). docs/model.md, Units of eq. 2.",
    )

    def __post_init__(self):
        _store(self, stiffness=v.non_negative("stiffness", self.stiffness))
        v.choice("convention", self.convention, ("physical", "paper"))


@dataclass(frozen=True)
class Local:
    """Local (intersegmental) muscles as a joint stiffness and damping of the coupled chain (docs/chain.md).

    A local muscle of PCSA A at full activation pulls with F = specific_tension * A at the
    lever arm r of one joint; its short-range stiffness q F / l (Bergmark 1989,
    doi:10.3109/17453678909154177) gives the joint the rotational stiffness q F r^2 / l. The
    slope of the global fibres' Hill curve at rest, F f_H'(0), gives it the rotational damping
    r^2 F abs(f_H'(0)) (Hill 1938, doi:10.1098/rspb.1938.0050), ``damping`` times that.
    """

    stiffness_gain: float = param(
        10.0,
        "1",
        "Dimensionless q of the muscle stiffness k = q F / l (Bergmark 1989, doi:10.3109/17453678909154177; "
        "used for spine stability by Cholewicki & McGill 1996, doi:10.1016/0268-0033(95)00035-6). 10 is "
        "spinectl's assumption, not a measurement: Brown et al. 2010 (doi:10.1080/10255841003630652) find "
        "q falling with activation. Local PCSAs scale with 1/q.",
    )
    lever_arm: float = param(
        0.07,
        "m",
        "Lever arm r of a local muscle about its joint (paper, Discussion: a conservative 7.0 cm, so that "
        "its +-30 N m limit is a PCSA of 17 cm^2).",
    )
    length: float = param(
        0.035,
        "m",
        "Length l of a local muscle in k = q F / l: one motion segment, the mean spacing of the paper's "
        "centres of rotation, (145 - 5 mm) / 4 = 35 mm.",
    )
    cost_weight: float = param(
        1.0,
        "1",
        "Weight w of the local PCSA against the global PCSA in the joint optimum of the coupled chain "
        "(docs/chain.md): 1 counts a cm^2 of local muscle like a cm^2 of global muscle.",
    )
    damping: float = param(
        1.0,
        "1",
        "Factor on the local muscles' damping from the force-velocity slope (docs/chain.md, 'Local muscles as "
        "joint stiffness and damping'): a joint of local stiffness k_j gets the damping damping * c_loc * k_j "
        "[N m s/rad], c_loc = l abs(f_H'(0)) / q [s] from the global fibres' Hill curve (section fibre; Hill "
        "1938, doi:10.1098/rspb.1938.0050), 0.038 s at the defaults. 1 (default): that slope; 0: no damping, "
        f"the stiffness-only model. At most {MAX_LOCAL_DAMPING:g}: all slow-twitch fibres (fibre.fast_twitch "
        "= 0) give 1.8.",
    )

    def __post_init__(self):
        _store(
            self,
            stiffness_gain=v.positive("stiffness_gain", self.stiffness_gain),
            lever_arm=_length("lever_arm", self.lever_arm),
            length=_length("length", self.length),
            cost_weight=v.non_negative("cost_weight", self.cost_weight),
            damping=v.in_range("damping", self.damping, 0.0, MAX_LOCAL_DAMPING),
        )


@dataclass(frozen=True)
class Levels:
    """The lumbar levels as bodies of the coupled chain: their inertia and weight (docs/chain.md).

    One body per vertebral level between two neighbouring centres of rotation (L2 to L5
    for the paper's five CoRs), a slice of the trunk with its centre of mass on the line
    of gravity (x = 0, like the upper body's point mass) halfway up between its CoRs. The
    per-segment analysis (eq. 1) has no such bodies; they make the chain's mass matrix
    regular (the point mass alone gives it rank 2).
    """

    mass: float = param(
        1.8,
        "kg",
        "Mass of each lumbar level (a slice of the trunk between two CoRs). The default, 1.8 kg, is 2.5 % of "
        "a 73 kg body, within "
        "the per-vertebral-level masses measured by CT (1.1 % at T1 rising to 2.6 % at L5; Pearsall, Reid "
        "and Livingston 1996, doi:10.1007/BF02667349). 0 removes the levels (the paper's point mass alone).",
    )
    radius_of_gyration: float = param(
        0.06,
        "m",
        "Radius of gyration of a level about its centre of mass for sagittal rotation. The default, 0.06 m, "
        "is spinectl's estimate: a uniform slab of the abdomen's sagittal depth d of about 0.2 m, "
        "sqrt(d^2 / 12) = 0.058 m.",
    )
    weight_in_gravity: float = param(
        0.0,
        "1",
        "Fraction of the levels' weight that enters the chain's gravity stiffness K_g (docs/chain.md, "
        "'The weight of the levels'). 0 (default): the levels carry inertia only, so the diagonal of K stays "
        "the paper's S_k; 1: their full weight, each level an inverted pendulum on the joints below it.",
    )

    def __post_init__(self):
        _store(
            self,
            mass=v.non_negative("mass", self.mass),
            radius_of_gyration=_length("radius_of_gyration", self.radius_of_gyration, allow_zero=True),
            weight_in_gravity=v.in_range("weight_in_gravity", self.weight_in_gravity, 0.0, 1.0),
        )
