"""Published trends of spinal stability on the paper's chain (docs/contributions.md, "Published trends").

The paper's chain (Wagner et al. 2012, five CoRs, the upper body a point mass) at E = 3 cm, Lambda = 4 cm with
the ``wagner2012`` preset; the loads are held at the point mass (:class:`spinectl.model.loads.PointLoad`).
"""

from __future__ import annotations

import numpy as np

from spinectl import load_preset
from spinectl.model.contributions import least_mode
from spinectl.model.loads import PointLoad
from spinectl.model.operating_point import OperatingPoint, chain_at
from spinectl.optimise.coupled.at_activation import point_at_activation
from spinectl.optimise.coupled.local import least_local_stiffness

BODY_WEIGHT = 75.0 * 9.81
"""A nominal adult's weight [N] (75 kg); the chain's point mass is the upper body's part of it only."""


def test_the_least_added_stiffness_rises_with_the_load_held_on_the_papers_chain_cholewicki_1997():
    """Cholewicki, Panjabi & Khachatryan (1997), "Stabilizing function of trunk flexor-extensor muscles around a
    neutral spine posture", Spine 22(19):2207-2212, doi:10.1097/00007632-199710010-00003. Abstract: the
    flexor-extensor coactivation "increased with added mass to the torso", explained "entirely on the basis of the
    need ... to provide the mechanical stability to the lumbar spine".

    Computed: on the paper's chain at its own per-segment optimum (the global PCSA of the unloaded posture, kept),
    a weight held at the point mass, 0 to 60 % of a 75 kg body's weight in steps of 10 % (the issue's range, that
    of Cholewicki & VanVliet 2002); the least total local stiffness sum(k) that makes the chain stable
    (:func:`spinectl.optimise.coupled.local.least_local_stiffness`, the SDP with margin mu), the model's measure
    of the stability that must be added. A weight held destabilises as gravity does (K_load = -F_y h on a single
    joint), so the need rises: measured 252 N m/rad unloaded to 1283 N m/rad at 60 %, strictly at each step
    (one joint's share may fall while the sum rises: L4L5's and L5S1's do up to 20 %, L5S1's again at 40 %).
    Asserted: strictly rising, and the chain at the least stiffness is stable (lambda_min of -K > 0) at each
    load, and the chain without local stiffness loses stability (its lambda_min falls) at each step.
    """
    model = load_preset("wagner2012")
    point = point_at_activation(model, 0.03, 0.04)
    needed, index = [], []
    for weight in np.linspace(0.0, 0.6, 7) * BODY_WEIGHT:
        held = (PointLoad((0.0, -float(weight))),)
        least = least_local_stiffness(model, 0.03, 0.04, point.pcsa, given=False, loads=held)
        assert least.status == "optimal"
        stiffened = OperatingPoint(model, 0.03, 0.04, point.pcsa, least.local_stiffness, loads=held, slip_check=False)
        assert least_mode(chain_at(stiffened).stiffness_offset).eigenvalue > 0  # the SDP's load is chain_at's
        bare = OperatingPoint(model, 0.03, 0.04, point.pcsa, loads=held, slip_check=False)
        index.append(least_mode(chain_at(bare).stiffness_offset).eigenvalue)
        needed.append(float(np.sum(least.local_stiffness)))
    assert np.all(np.diff(index) < 0)  # the weight destabilises the chain without local muscles
    assert np.all(np.diff(needed) > 0)
