"""The index along a motion on a published ``.osim`` model is analyse's at each frame, each linearised anew.

benchmarks/bench_osim_motion.py times ``spinectl motion`` on the shared Pose2Sim model (318 muscles) against
:func:`spinectl.anatomy.analyses.analyse` frame by frame and asserts their indices equal; this is that check as a
test, on two frames with activations from a file. The second path is ``analyse`` with the engine's in-memory
linearisations emptied and no cache of linearisations (``cache=False``), frames in the reverse order: each frame
is linearised again from another history of OpenSim's state than the motion's, so a linearisation that kept
anything of the previous frame (an activation, a fibre state, a coordinate's speed) would differ here.
"""

from __future__ import annotations

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from shared_models import ABSENT, DOCUMENTED_MAPPINGS, POSE2SIM  # noqa: E402 (tests/anatomy/shared_models.py)

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.motion import motion_response, write_motion  # noqa: E402
from spinectl.anatomy.recordings import read_recording  # noqa: E402

TIMES = np.array([0.0, 0.1])
"""Two frames [s]."""

FLEXION = np.array([0.0, -6.0])
"""Each sagittal joint's angle added to the model's default at each frame [deg]."""


@pytest.mark.skipif(not POSE2SIM.is_file(), reason=ABSENT)
def test_the_pose2sim_motion_with_activations_is_analyse_frame_by_frame_linearised_anew(tmp_path):
    """Pose2Sim (docs/mappings/pose2sim.toml), two frames (upright, then 6 deg of flexion at each sagittal joint),
    random activations per frame from a .sto: every eigenvalue of both chains, the unstable counts and the least
    mode (up to sign) equal analyse(posture=FILE, activation=FILE, time=t) bit for bit, analyse linearising each
    frame again (nothing kept, frames reversed); the two frames' indices differ (the comparison can fail)."""
    model = anatomy.load(POSE2SIM, DOCUMENTED_MAPPINGS / "pose2sim.toml", cache=False)
    columns = model.posture_columns()
    names = list(columns.required)
    default = [model.engine.coordinate(n).getDefaultValue() for n in names]
    upright = [np.degrees(v) if n in columns.rotational else v for n, v in zip(names, default, strict=True)]
    rows = np.tile(upright, (2, 1))
    for joint in model.plane_joints("sagittal"):
        rows[:, names.index(joint)] += FLEXION
    mot = write_motion(tmp_path / "flexion.mot", names, TIMES, rows)
    a = np.random.default_rng(3).uniform(0.05, 0.3, (2, len(model.muscles)))
    sto = write_motion(tmp_path / "so.sto", model.muscles, TIMES, a, in_degrees=None)
    ds = motion_response(
        model, read_recording(mot, "posture"), read_recording(sto, "activations"), progress=False
    ).dataset
    for i in (1, 0):
        model.engine.linearisations.clear()
        one = analyse(model, posture=mot, activation=sto, time=float(TIMES[i]))
        np.testing.assert_array_equal(ds["activation"].values[i], one.activations)
        for name, chain in (("free", one.free), ("constrained", one.constrained)):
            np.testing.assert_array_equal(ds[f"{name}_eigenvalues"].values[i], chain.eigenvalues)
            assert ds[f"{name}_unstable_modes"].values[i] == np.sum(chain.eigenvalues <= 0)
            np.testing.assert_array_equal(np.abs(ds[f"{name}_mode_shape"].values[i]), np.abs(chain.modes[:, 0]))
    assert abs(ds["free_index"].values[1] - ds["free_index"].values[0]) > 1.0  # N m/rad: the frames differ
