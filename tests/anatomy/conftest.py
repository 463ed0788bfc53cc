"""Fixtures of the anatomy tests: MyoTorso loaded once per session (MuJoCo and myo-sim, the anatomy extra)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def torso():
    """MyoTorso with its built-in mapping; the tests skip where the anatomy extra is not installed."""
    pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    from spinectl import anatomy

    return anatomy.load("myotorso")


@pytest.fixture(scope="session")
def sagittal(torso):
    """The sagittal chains at the reference posture, no stiffness added: (free, constrained, linearisation)."""
    return torso.chains("sagittal")
