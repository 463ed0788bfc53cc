"""The buckling load of an anatomical model's chain (spinectl.anatomy.buckling; docs/anatomy.md, "Buckling load").

The closed form is a single hinge with stiffness k (the joint stiffness added, plus the engine's own spring k_s):
a vertebra of mass m1 whose centre of mass is h1 above the hinge and a thorax welded to it, of mass m at h above
the hinge, the load P along gravity at the thorax's centre of mass. The potential about the upright is
(k + k_s) theta^2 / 2 + (m1 g h1 + (m g + P) h) cos(theta), so -K = k + k_s - g (m1 h1 + m h) - P h and

    P_c = (k + k_s - g (m1 h1 + m h)) / h.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy import trends  # noqa: E402
from spinectl.anatomy.buckling import buckling_load, critical_load, weight_load  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.model.contributions import least_mode  # noqa: E402
from spinectl.model.loads import MAX_LOAD  # noqa: E402

M1, H1, M, H = 1.0, 0.05, 10.0, 0.3  # [kg], [m], [kg], [m]
MAPPING = '[bodies]\npelvis = ["pelvis"]\nvertebrae = ["v1"]\nthorax = ["top"]\n[planes]\nsagittal = ["j1"]\n'


def closed_form(k: float, g: float, spring: float = 0.0) -> float:
    """P_c of the module docstring [N]."""
    return (k + spring - g * (M1 * H1 + M * H)) / H


def hinge(tmp_path, y_up=False, spring=0.0, g=9.81):
    """The single hinge of the module docstring through MuJoCo's MjSpec: z up (hinge about y) or y up (about z)."""
    spec = mujoco.MjSpec()
    up, axis = ((0, 1, 0), (0, 0, 1)) if y_up else ((0, 0, 1), (0, 1, 0))
    spec.option.gravity = -g * np.array(up, float)
    pelvis = spec.worldbody.add_body(name="pelvis")
    v1 = pelvis.add_body(name="v1", mass=M1, ipos=H1 * np.array(up, float), inertia=[0.01, 0.01, 0.01])
    v1.add_joint(name="j1", type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis, stiffness=spring)
    v1.add_body(name="top", mass=M, ipos=H * np.array(up, float), inertia=[0.1, 0.1, 0.1])  # welded: no joint
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    model_path, mapping = tmp_path / "hinge.xml", tmp_path / "hinge.toml"
    model_path.write_text(spec.to_xml())
    mapping.write_text(MAPPING)
    return model_path, mapping


@pytest.mark.parametrize("y_up", [False, True])
def test_a_single_hinge_buckles_at_the_closed_form(tmp_path, y_up):
    """P_c = (k - g (m1 h1 + m h)) / h (module docstring) with k = 200 N m/rad added, gravity along -z or along -y:
    the load is along gravity at the thorax's centre of mass (MuJoCo's body_ipos) whichever way is up."""
    loaded = anatomy.load(*hinge(tmp_path, y_up), cache=False)
    found = buckling_load(loaded, joint_stiffness=200.0)
    assert found.free == pytest.approx(closed_form(200.0, 9.81), rel=1e-6)
    assert found.body == "top"
    np.testing.assert_allclose(found.point, (0, H, 0) if y_up else (0, 0, H), atol=1e-12)
    np.testing.assert_allclose(found.direction, (0, -1, 0) if y_up else (0, 0, -1), atol=1e-12)


def test_the_engines_own_spring_and_the_added_stiffness_both_hold_the_load(tmp_path):
    """A MuJoCo joint spring of 150 N m/rad and 60 added: P_c = (210 - g (m1 h1 + m h)) / h."""
    loaded = anatomy.load(*hinge(tmp_path, spring=150.0), cache=False)
    assert buckling_load(loaded, joint_stiffness=60.0).free == pytest.approx(closed_form(60.0, 9.81, 150.0), rel=1e-6)


def test_unstable_without_a_load_is_zero_and_none_up_to_the_cap_is_infinite(tmp_path, capsys):
    """k below g (m1 h1 + m h) = 29.9 N m/rad: 0, said so; k large enough to hold the cap (P_c > 1e5 N): none.
    The command's table line and its JSON say the same (null where none)."""
    model_path, mapping = hinge(tmp_path)
    loaded = anatomy.load(model_path, mapping, cache=False)
    assert buckling_load(loaded, joint_stiffness=10.0).free == 0.0
    big = H * MAX_LOAD * 2
    assert np.isinf(buckling_load(loaded, joint_stiffness=big).free)
    base = ["anatomy", str(model_path), "--mapping", str(mapping), "--buckling", "--joint-stiffness"]
    assert main([*base, "10"]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert line.startswith("buckling load (a load at top's centre of mass, along gravity,")
    assert "free chain 0 N (unstable without it)" in line
    assert main([*base, str(big), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)["buckling_load_N"]
    assert doc["free"] is None and doc["cap_N"] == MAX_LOAD and doc["body"] == "top"
    assert doc["point_m"] == pytest.approx([0, 0, H])


def test_the_command_counts_the_other_loads_held(tmp_path, capsys):
    """--load top:0,0,-100@0,0,0.3 (100 N along gravity at the same point) lowers the buckling load by 100 N."""
    model_path, mapping = hinge(tmp_path)
    base = ["anatomy", str(model_path), "--mapping", str(mapping), "--buckling", "--joint-stiffness", "200", "--json"]
    assert main([*base, "--load", f"top:0,0,-100@0,0,{H}"]) == 0
    doc = json.loads(capsys.readouterr().out)["buckling_load_N"]
    assert doc["free"] == pytest.approx(closed_form(200.0, 9.81) - 100.0, rel=1e-6)


def test_trends_loads_along_gravity_on_a_y_up_model(tmp_path):
    """The co-contraction path's critical load is the buckling module's (trends calls it): on a y-up model
    (hinge about z) the closed form; before, trends pushed along -z, which turns no hinge about z (infinite)."""
    loaded = anatomy.load(*hinge(tmp_path, y_up=True), cache=False)
    free = loaded.chain("sagittal", joint_stiffness=200.0)
    per_newton = trends.load_stiffness_per_newton(loaded, "sagittal", None, 200.0)[0]
    found = trends.critical_load(free.stiffness_offset, per_newton, trends.MAX_CRITICAL_LOAD)
    assert found == pytest.approx(closed_form(200.0, 9.81), rel=1e-6)


def test_myotorsos_least_eigenvalue_crosses_zero_at_its_buckling_load():
    """MyoTorso at its own controls with 200 N m/rad added: lambda_min of -K(P) is 0 at the load found, to 1e-6 of
    lambda_min at P = 0, and positive 0.1 % below it; the same for the chain constrained by the rhythm."""
    torso = anatomy.load("myotorso")
    a = torso.default_controls()
    found = buckling_load(torso, joint_stiffness=200.0, activations=a)
    for p, index in ((found.free, 0), (found.constrained, 1)):
        assert 0 < p < MAX_LOAD
        at, below = (
            torso.chains(activations=a, joint_stiffness=200.0, loads=[weight_load(torso, x)]) for x in (p, 0.999 * p)
        )
        unloaded = torso.chains(activations=a, joint_stiffness=200.0)[index]
        scale = least_mode(unloaded.stiffness(a)).eigenvalue
        assert abs(least_mode(at[index].stiffness(a)).eigenvalue) <= 1e-6 * scale
        assert least_mode(below[index].stiffness(a)).eigenvalue > 0


def test_critical_load_refuses_no_crossing_and_finds_a_linear_root():
    """K = -diag(5, 3), K_1 = diag(0.01, 0.1): lambda_min(-K(P)) = min(5 - 0.01 P, 3 - 0.1 P), zero at P = 30."""
    assert critical_load(-np.diag([5.0, 3.0]), np.diag([0.01, 0.1])) == pytest.approx(30.0, rel=1e-12)
    assert critical_load(np.diag([1.0, -3.0]), np.eye(2)) == 0.0
    assert np.isinf(critical_load(-np.eye(2), np.zeros((2, 2))))


def pin(tmp_path, spring: float):
    """The single hinge of the module docstring through OpenSim's API: y up (its default gravity), a PinJoint about
    z from the ground, a thorax welded to the vertebra and a SpringGeneralizedForce of ``spring`` N m/rad."""
    osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    model = osim.Model()
    model.setName("pin")
    v1 = osim.Body("v1", M1, osim.Vec3(0, H1, 0), osim.Inertia(0.01, 0.01, 0.01))
    top = osim.Body("top", M, osim.Vec3(0, H, 0), osim.Inertia(0.1, 0.1, 0.1))
    joint = osim.PinJoint("j1", model.getGround(), osim.Vec3(0), osim.Vec3(0), v1, osim.Vec3(0), osim.Vec3(0))
    joint.upd_coordinates(0).setName("q1")
    for body in (v1, top):
        model.addBody(body)
    model.addJoint(joint)
    model.addJoint(osim.WeldJoint("w", v1, osim.Vec3(0), osim.Vec3(0), top, osim.Vec3(0), osim.Vec3(0)))
    force = osim.SpringGeneralizedForce("q1")
    force.setStiffness(spring)
    model.addForce(force)
    model.finalizeConnections()
    model_path, mapping = tmp_path / "pin.osim", tmp_path / "pin.toml"
    model.printToXML(str(model_path))
    mapping.write_text(MAPPING.replace('"pelvis"]', '"ground"]').replace('"j1"', '"q1"'))
    return model_path, mapping, -model.getGravity().get(1)


def test_an_osim_pin_buckles_at_the_closed_form_along_its_own_gravity(tmp_path):
    """The OpenSim pin (y up, g = OpenSim's 9.80665) with a 100 N m/rad spring and 50 added: the closed form, the
    load at the thorax's centre of mass (Body.getMassCenter) along -y."""
    model_path, mapping, g = pin(tmp_path, 100.0)
    found = buckling_load(anatomy.load(model_path, mapping, cache=False), joint_stiffness=50.0)
    assert found.free == pytest.approx(closed_form(50.0, g, 100.0), rel=1e-5)
    np.testing.assert_allclose(found.point, (0, H, 0), atol=1e-12)
    np.testing.assert_allclose(found.direction, (0, -1, 0), atol=1e-12)


def test_christophys_skeleton_answers_its_buckling_load(capsys):
    """The issue's case, the published skeleton without muscles: with 1000 N m/rad per joint radian the free and
    the constrained chain are stable unloaded and lose stability under a load below the cap; lambda_min of -K(P)
    is 0 at it (to 1e-6 of lambda_min unloaded), and the table says so."""
    pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    from shared_models import ABSENT, CHRISTOPHY, DOCUMENTED_MAPPINGS

    if not CHRISTOPHY.exists():
        pytest.skip(ABSENT)
    mapping = DOCUMENTED_MAPPINGS / "christophy.toml"
    loaded = anatomy.load(CHRISTOPHY, mapping)
    found = buckling_load(loaded, joint_stiffness=1000.0)
    assert found.body == "torso"
    for p, index in ((found.free, 0), (found.constrained, 1)):
        assert 0 < p < MAX_LOAD
        unloaded = loaded.chains(joint_stiffness=1000.0)[index].stiffness_offset
        at = loaded.chains(joint_stiffness=1000.0, loads=[weight_load(loaded, p)])[index].stiffness_offset
        assert abs(least_mode(at).eigenvalue) <= 1e-6 * least_mode(unloaded).eigenvalue
    argv = ["anatomy", str(CHRISTOPHY), "--mapping", str(mapping), "--joint-stiffness", "1000", "--buckling"]
    assert main(argv) == 0
    assert f"free chain {found.free:.6g} N, constrained {found.constrained:.6g} N" in capsys.readouterr().out


def test_a_model_without_gravity_is_refused_in_one_line(tmp_path, capsys):
    """Gravity 0 (MuJoCo's option): the load has no direction; one line naming --buckling and the model, exit 2,
    nothing on stdout (without --buckling the model answers: only the buckling load needs gravity)."""
    model_path, mapping = hinge(tmp_path, y_up=True, g=0.0)
    base = ["anatomy", str(model_path), "--mapping", str(mapping)]
    assert main([*base, "--buckling"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert err.startswith("spinectl: error: buckling: hinge has no gravity (0 m/s^2)")
    assert main(base) == 0


def test_an_engine_without_gravity_and_centres_of_mass_refuses_in_one_line(monkeypatch, capsys):
    """A third engine that does not override ``body_weight`` (test_contract.py's made-up one) still answers the
    table, and refuses --buckling in one line, exit 2, nothing on stdout (MappedModel's default)."""
    from test_contract import load_fake

    from spinectl.anatomy.contract import ENGINES, register_engine

    monkeypatch.setitem(ENGINES, ".fake", None)  # restored (removed) after the test
    register_engine(".FAKE", load_fake)
    assert main(["anatomy", "model.fake"]) == 0
    capsys.readouterr()
    assert main(["anatomy", "model.fake", "--buckling"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == "spinectl: error: buckling: is not available on this engine's models yet (got fake)\n"


def test_the_command_buckles_the_optimum_at_its_own_activations(capsys):
    """With --optimise the load is found at the optimum's activations (the JSON's ``activations``), not the model's
    own controls: the library's buckling_load at those activations is the command's."""
    argv = ["anatomy", "myotorso", "--optimise", "--joint-stiffness", "100", "--buckling", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    torso = anatomy.load("myotorso")
    activations = doc["activations"]
    a = np.array([activations[m] for m in torso.muscles]) if isinstance(activations, dict) else np.array(activations)
    found = buckling_load(torso, joint_stiffness=100.0, activations=a)
    assert doc["buckling_load_N"]["free"] == pytest.approx(found.free, rel=1e-9)
    assert doc["buckling_load_N"]["constrained"] == pytest.approx(found.constrained, rel=1e-9)
    own = buckling_load(torso, joint_stiffness=100.0, activations=torso.default_controls())
    assert own.free != pytest.approx(found.free, rel=1e-3)  # the activations matter: the test can tell them apart
