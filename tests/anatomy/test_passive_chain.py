"""A model without muscles is its passive chain on every engine: gravity, its springs and the stiffness added.

The .osim case (a model built with OpenSim's API, as Christophy's skeleton) is in test_joint_angles.py; here an
MJCF of two hinges with springs, built as text and read by MuJoCo.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl import anatomy  # noqa: E402
from spinectl.cli import main  # noqa: E402

BARE = """<mujoco model="bare">
  <worldbody>
    <body name="pelvis">
      <body name="v1" pos="0 0 0.1">
        <joint name="j1" type="hinge" axis="0 1 0" stiffness="30"/>
        <geom type="sphere" size="0.02" pos="0.02 0 0.05" mass="2"/>
        <body name="top" pos="0 0 0.1">
          <joint name="j2" type="hinge" axis="0 1 0" stiffness="40"/>
          <geom type="sphere" size="0.02" pos="0.02 0 0.05" mass="2"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
MAPPING = '[bodies]\npelvis = ["pelvis"]\nvertebrae = ["v1"]\nthorax = ["top"]\n[planes]\nsagittal = ["j1", "j2"]\n'


def test_an_mjcf_without_muscles_answers_its_passive_chain(tmp_path, capsys):
    """Two hinges with MuJoCo joint springs of 30 and 40 N m/rad and 5 added: the chain's stiffness is the springs,
    the added 5 and gravity (MuJoCo's own qfrc_bias by central differences, the reference), with its verdicts; the
    JSON has no muscles, a null mean activation and no slopes (a hinge turns 1 rad per radian)."""
    model_path, mapping = tmp_path / "bare.xml", tmp_path / "bare.toml"
    model_path.write_text(BARE)
    mapping.write_text(MAPPING)
    loaded = anatomy.load(model_path, mapping, cache=False)
    free = loaded.chain("sagittal", joint_stiffness=5.0)
    model = mujoco.MjModel.from_xml_string(BARE)
    data = mujoco.MjData(model)
    gravity = np.zeros((2, 2))
    for k in range(2):
        sides = []
        for sign in (1, -1):
            data.qpos[:] = 0
            data.qpos[k] = sign * 1e-6
            mujoco.mj_forward(model, data)
            sides.append(-data.qfrc_bias.copy())
        gravity[:, k] = (sides[0] - sides[1]) / 2e-6
    expected = 0.5 * (gravity + gravity.T) - np.diag([35.0, 45.0])
    np.testing.assert_allclose(free.stiffness_offset, expected, rtol=1e-6, atol=1e-6)
    assert main(["anatomy", str(model_path), "--mapping", str(mapping), "--joint-stiffness", "5", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["muscles"] == {"global": [], "local": [], "between": [], "non-lumbar": []}
    assert doc["chain_stable"] is True
    assert doc["activation_mean"] is None and "joint_rad_per_coordinate_rad" not in doc


def test_a_model_without_muscles_says_so_and_refuses_activations(tmp_path, capsys):
    """The table's first line says 'no muscles' (before: 'mean activation nan'); a joint that restores without any
    damping is 'undamped' (its eigenvalues +-i w: before 'slowest time constant inf s'); --activation and
    --optimise are refused in one line each, with no numpy warning (before: 'Mean of empty slice', then
    'infeasible (the solver: solver_error)')."""
    model_path, mapping = tmp_path / "bare.xml", tmp_path / "bare.toml"
    model_path.write_text(BARE)
    mapping.write_text(MAPPING)
    base = ["anatomy", str(model_path), "--mapping", str(mapping)]
    assert main(base) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith("no muscles (the passive chain)") and "nan" not in lines[0]
    j1 = next(x for x in lines if x.startswith("j1 "))  # 30 N m/rad spring beats gravity's 0.78 N m over 0.05 m
    assert "self-stable, marginal: undamped" in j1 and "inf" not in j1
    for extra, field in ((["--activation", "0.5"], "activation"), (["--optimise"], "optimise")):
        assert main(base + extra) == 2
        err = capsys.readouterr().err
        assert err == f"spinectl: error: {field}: bare has no muscles" + err.split("has no muscles", 1)[1]
        assert err.count("\n") == 1 and "warning" not in err
