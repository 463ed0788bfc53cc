"""``--load`` on ``spinectl stability --coupled`` and ``spinectl anatomy`` (docs/chain.md and docs/anatomy.md, loads).

The loaded outputs against the unloaded ones and the library's closed forms (model/loads.py, anatomy/loads.py,
each checked against central differences and MuJoCo's mj_applyFT in tests/model and tests/anatomy); the refusals
as one line, exit 2 (docs/robustness.md).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from spinectl import load_preset
from spinectl.cli import main
from spinectl.model import geometry
from spinectl.model.loads import PointLoad, load_stiffness

E, LAMBDA = 0.03, 0.04


def _json(capsys, argv) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def _refused(capsys, argv, needle: str) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("spinectl: error: ") and needle in err, err


def test_stability_coupled_load_in_k_and_named(capsys):
    """K with a 200 N weight held is K without plus -(P - c_hi) . F; the JSON and the table name the load."""
    base = ["stability", "--coupled", "--E", str(E), "--Lambda", str(LAMBDA), "--pcsa", "10,10,10"]
    bare = _json(capsys, [*base, "--json"])["coupled"]
    loaded = _json(capsys, [*base, "--load", "0,-200", "--json"])["coupled"]
    model = load_preset("default")
    cor = geometry.cor_positions(E, LAMBDA, model.geometry)
    expected = load_stiffness(model, cor, [PointLoad((0.0, -200.0))])
    difference = np.array(loaded["stiffness_matrix_Nm_per_rad"]) - np.array(bare["stiffness_matrix_Nm_per_rad"])
    assert np.allclose(difference, expected, rtol=1e-12, atol=1e-9)
    assert loaded["margin_Nm_per_rad"] < bare["margin_Nm_per_rad"]  # a weight held destabilises
    assert loaded["loads"] == [{"force_N": [0.0, -200.0], "frame": "ground", "at": "point mass"}]
    # the torque (P - c_j) x F upright: -x_j F_y, x_j the CoR's horizontal position
    assert np.allclose(list(loaded["load_torque_Nm"].values()), -cor[:, 0] * -200.0, rtol=1e-12)
    assert "loads" not in bare and "load_torque_Nm" not in bare
    assert main([*base, "--load", "0,-200", "--load", "10,0"]) == 0
    table = capsys.readouterr().out
    assert "load (in K): F = (0, -200) N at the point mass" in table and "load (in K): F = (10, 0) N" in table


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["stability", "--load", "0,-200"], "--load: goes with --coupled"),
        (["stability", "--coupled", "--load", "0,x"], "--load must be a number"),
        (["stability", "--coupled", "--load", "1e9,0"], "--load must be in [-100000, 100000] N"),
        (["stability", "--coupled", "--load", "1,2,3"], "--load must be FX,FY"),
    ],
)
def test_stability_load_refusals(capsys, argv, needle):
    """A load without --coupled, not a number, beyond the bound or of three components: one line, exit 2."""
    _refused(capsys, argv, needle)


@pytest.fixture(scope="module")
def anatomy_extra():
    pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")


def test_anatomy_load_named_and_in_k(anatomy_extra, capsys):
    """anatomy --load: K of the free chain is the unloaded K plus the library's load stiffness; JSON names it."""
    from spinectl import anatomy
    from spinectl.anatomy.loads import BodyLoad, load_terms

    bare = _json(capsys, ["anatomy", "--json"])
    loaded = _json(capsys, ["anatomy", "--load", "torso:0,0,-200@0.1,0,0.3:body", "--json"])
    assert loaded["loads"] == [
        {"body": "torso", "force_N": [0.0, 0.0, -200.0], "point_m": [0.1, 0.0, 0.3], "frame": "body"}
    ]
    assert "loads" not in bare
    torso = anatomy.load("myotorso")
    free, _, lin = torso.chains("sagittal")
    _, k = load_terms(torso.engine, [BodyLoad("torso", (0, 0, -200.0), (0.1, 0, 0.3), "body")], torso.posture())
    dofs = list(lin.dofs[: free.n_joints])
    difference = np.array(loaded["stiffness_matrix_Nm_per_rad"]) - np.array(bare["stiffness_matrix_Nm_per_rad"])
    assert np.allclose(difference, k[np.ix_(dofs, dofs)], rtol=1e-9, atol=1e-9)
    assert main(["anatomy", "--load", "torso:0,0,-200"]) == 0
    assert "load (in the equilibrium and K): F = (0, 0, -200) N at (0, 0, 0) m of torso, fixed in the ground" in (
        capsys.readouterr().out
    )


@pytest.mark.parametrize(
    ("load", "needle"),
    [
        ("thorax:0,0,-100", "--load: BODY must be a body of the model"),
        ("torso:0,0", "--load must be BODY:FX,FY,FZ"),
        ("torso:0,0,1@1,2", "--load must be BODY:FX,FY,FZ"),
        (":0,0,1", "--load must be BODY:FX,FY,FZ"),
        ("torso:0,0,nan", "--load must be finite"),
        ("torso:0,0,1e7", "--load must be in [-100000, 100000] N"),
        ("torso:0,0,1@0,0,11", "--load must be in [-10, 10] m"),
    ],
)
def test_anatomy_load_refusals(anatomy_extra, capsys, load, needle):
    """A body the model lacks, a malformed load, a number beyond its bound: one line, exit 2."""
    _refused(capsys, ["anatomy", "--load", load], needle)


def test_anatomy_load_with_check_refused(anatomy_extra, capsys):
    """--check with a load: refused (the referee's copy of the model holds no load)."""
    _refused(capsys, ["anatomy", "--load", "torso:0,0,-1", "--check"], "--check: compares the chain without loads")
