"""The chain's verdict beside the segments' (spinectl.reflex.chain_verdict): one operating point, two criteria."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.model import config
from spinectl.reflex.chain_margins import coupled_margins
from spinectl.reflex.chain_verdict import margins_with_chain

SUBJECT = {"body.mass": 35.0, "passive.stiffness": 10.0, "reflex.delay": 0.12}
"""A 35 kg subject with K = 10 N m/rad and a 120 ms reflex delay, at E = 3 cm, Lambda = 4 cm."""


def _subject():
    return config.set_parameters(config.load_preset("wagner2012"), SUBJECT)


def test_joint_by_joint_stable_and_the_chain_not_at_one_point():
    """At the subject's point every segment alone is stable at 120 ms, the chain is not: its exact delay margin
    (about 0.06 ms) equals that of ``margins --coupled`` (coupled_margins: the chain's matrices through the
    optimiser's coupled_stability_at and its cvxpy SDP, a second path to the same loop) and lies far below
    the delay. Both verdicts name their criterion, in the table and in the JSON."""
    model = _subject()
    report = margins_with_chain(model, 0.03, 0.04)
    assert report.all_stable_at_delay
    chain = report.chain
    reference = coupled_margins(model, 0.03, 0.04)
    # the gains follow the least local stiffness of two SDP solvers (stacked Clarabel, cvxpy): equal to ~1e-5
    assert chain.exact.margin == pytest.approx(reference.exact.margin, rel=1e-4)
    assert chain.kp == pytest.approx(reference.kp, rel=1e-4)
    assert not chain.stable_at_delay and not reference.stable_at_delay and chain.exact.margin < 1e-4
    doc = report.to_dict()
    assert doc["criterion"].startswith("joint by joint (each CoR alone, the others fixed")
    assert doc["chain"]["criterion"] == "chain (all 5 CoRs free)" and doc["chain"]["stable_at_delay"] is False
    assert doc["chain"]["without_reflex"]["criterion"] == "chain (all 5 CoRs free)"
    table = report.table()
    rule = "the same reflex rule at every joint (gains from each joint's own stiffness)"
    assert report.verdict() in table and f"chain (all 5 CoRs free), {rule}: NOT stable" in table


def test_without_level_masses_the_chain_is_undefined_not_an_error():
    """levels.mass = 0 makes the mass matrix singular (rank 2): the chain's verdict is 'undefined', NaN margins,
    and the segments' report is unchanged."""
    model = config.set_parameters(config.load_preset("default"), {"levels.mass": 0.0})
    report = margins_with_chain(model, 0.0, 0.0)
    assert np.isnan(report.chain.exact.margin) and not report.chain.stable_at_delay
    assert "undefined" in report.chain.lines()[0]
    assert report.to_dict()["chain"]["without_reflex"]["defined"] is False
