"""A rigid muscle's path damping dF/dV where its path does not lengthen with the coordinate chosen: 0, not 0/0."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from shared_models import ABSENT, DOCUMENTED_MAPPINGS, POSE2SIM  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl.anatomy import opensim_muscles


class _Coordinate:
    """A coordinate whose speed the stand-in engine reads back."""

    def __init__(self, engine):
        self.engine = engine

    def setSpeedValue(self, state, value):  # noqa: N802 (OpenSim's name)
        self.engine.speed = value


def _engine():
    """Two muscles on one coordinate: the first lengthens at 0.05 m/rad with damping 300 N s/m; the second's arm is
    round-off (1.4e-17 m/rad, as Pose2Sim's LD_R12_r on L1_T12_Flex_Ext): its speed and force do not change."""
    engine = SimpleNamespace(state=None, speed=0.0)
    coordinate = _Coordinate(engine)
    engine.coordinate = lambda name: coordinate
    return engine


def test_a_muscle_that_does_not_lengthen_gets_no_damping(monkeypatch):
    """Muscle 0: dF/dV = 300 N s/m (its force 300 V, V = 0.05 q'); muscle 1: its speed 0 at both sides of the step,
    so 0 (before: 0/0 = NaN, which LinearChain refused: 'damping_per_control: must be finite')."""
    engine = _engine()

    def read(engine_, getter):
        speed = np.array([0.05 * engine.speed, 0.0])
        return 300.0 * speed if getter == "getTendonForce" else speed

    monkeypatch.setattr(opensim_muscles, "_read", read)
    monkeypatch.setattr(opensim_muscles, "_activate", lambda engine_, acts: None)
    arms = np.array([[0.05], [-1.4e-17]])
    out = opensim_muscles._path_damping(engine, np.ones(2), arms, ["L1_T12_Flex_Ext"], [0, 1])
    np.testing.assert_allclose(out, [300.0, 0.0])


@pytest.mark.slow
@pytest.mark.skipif(not POSE2SIM.is_file(), reason=ABSENT)
def test_pose2sims_chain_at_minus_ten_degrees_has_finite_damping(tmp_path):
    """Pose2Sim moved -10 deg along its rhythm (the trial's --lordosis -10:10:5 failed there): the chains are
    built, their damping finite."""
    pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

    from spinectl import anatomy

    mapping = DOCUMENTED_MAPPINGS / "pose2sim.toml"  # docs/anatomy.md's, as the page shows it
    loaded = anatomy.load(POSE2SIM, mapping, cache=False)
    free, constrained, _ = loaded.chains("sagittal", loaded.lordosis_posture(-10.0, "sagittal"))
    assert np.all(np.isfinite(free.damping_per_control)) and np.all(np.isfinite(constrained.damping_per_control))
