"""The global muscles' rank: singular values of their moment arms below 1 % of the largest count as zero."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from spinectl.anatomy.certificate import RANK_TOLERANCE, global_certificate


def _chain(n: int, classes):
    """What global_certificate reads of a chain: its controls' classes and a zero stiffness."""
    m = len(classes)
    return SimpleNamespace(
        control_class=tuple(classes),
        controls=tuple(f"m{i}" for i in range(m)),
        n_joints=n,
        stiffness=lambda a: np.zeros((n, n)),
        stiffness_per_control=np.zeros((n, n, m)),
    )


def test_a_lever_under_one_percent_of_the_largest_is_no_rank():
    """Made-up arms over 3 joints: levers of 0.05 m/rad along the first, 0.01 along the second (20 %) and
    0.06 mm/rad along the third (0.12 %, the cyclist's least): rank 2, the round-off floor 1e-9 said 3; the
    singular values are kept as they are; a local muscle's arm does not count."""
    arms = np.array([[0.05, 0, 0], [0, 0.01, 0], [0, 0, 6e-5], [0, 0, 0.04]])
    cert = global_certificate(None, _chain(3, ("global", "global", "global", "local")), arms, np.zeros(4))
    np.testing.assert_allclose(cert.singular_values, [0.05, 0.01, 6e-5])
    assert cert.rank == 2 and RANK_TOLERANCE == 1e-2
    np.testing.assert_allclose(np.abs(cert.null_space[:, 0]), [0, 0, 1], atol=1e-12)


def test_a_lever_just_above_one_percent_counts():
    """The variant on the other side: 0.6 mm/rad beside 0.05 m/rad (1.2 %) is rank."""
    arms = np.diag([0.05, 0.01, 6e-4])
    cert = global_certificate(None, _chain(3, ("global",) * 3), arms, np.zeros(3))
    assert cert.rank == 3 and cert.null_space.size == 0


def test_myotorso_keeps_rank_three(torso):
    """MyoTorso's sagittal global arms: singular values 0.451, 0.152, 0.0731 m/rad and two of round-off (1e-17):
    rank 3 of 5 as before (its least kept value is 16 % of the largest)."""
    pytest.importorskip("mujoco")
    from spinectl.anatomy.analyses import analyse

    result = analyse(torso, "sagittal", 0.0)
    assert result.certificate.rank == 3
    np.testing.assert_allclose(result.certificate.singular_values[:3], [0.451, 0.152, 0.0731], rtol=1e-2)
