"""External loads on OpenSim models (anatomy/osim_loads.py, OsimAnatomy.apply_loads; docs/anatomy.md, "Loads").

The referees: OpenSim's inverse dynamics with the load as a PrescribedForce (the generalised force it needs to
hold the load is -J^T F), the closed form of a two-pin chain built here with OpenSim's API, and the paper's own
load stiffness (model/loads.py, -(P - c_hi) . F) on spinectl's export of the paper's chain read back by OpenSim.
"""

from __future__ import annotations

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.export_osim import export_osim  # noqa: E402
from spinectl.anatomy.loads import BodyLoad  # noqa: E402
from spinectl.anatomy.opensim_engine import _mobility_order, load_engine  # noqa: E402
from spinectl.anatomy.osim_loads import osim_load_terms  # noqa: E402
from spinectl.errors import ParameterError  # noqa: E402
from spinectl.model import geometry  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402
from spinectl.model.loads import PointLoad, load_stiffness  # noqa: E402

E, LAMBDA = 0.03, 0.04


def _two_pins(prescribed: BodyLoad | None = None):
    """Two pins about z (y up): the lower at the origin, the upper 0.3 m above; no gravity; optionally the load."""
    model = osim.Model()
    model.setName("two_pins")
    model.setGravity(osim.Vec3(0, 0, 0))
    lower = osim.Body("lower", 1.0, osim.Vec3(0, 0.15, 0), osim.Inertia(0.01, 0.01, 0.01))
    upper = osim.Body("upper", 1.0, osim.Vec3(0, 0.2, 0), osim.Inertia(0.01, 0.01, 0.01))
    model.addBody(lower)
    model.addBody(upper)
    zero = osim.Vec3(0, 0, 0)
    model.addJoint(osim.PinJoint("bottom", model.getGround(), zero, zero, lower, zero, zero))
    model.addJoint(osim.PinJoint("top", lower, osim.Vec3(0, 0.3, 0), zero, upper, zero, zero))
    if prescribed is not None:  # OpenSim's own external force: the referee
        force = osim.PrescribedForce("load", upper)
        force.setPointFunctions(*(osim.Constant(v) for v in prescribed.point))
        force.setForceFunctions(*(osim.Constant(v) for v in prescribed.force))
        force.setForceIsInGlobalFrame(prescribed.frame == "ground")
        force.setPointIsInGlobalFrame(False)
        model.addForce(force)
    model.finalizeConnections()
    return model


@pytest.fixture(scope="module")
def pins(tmp_path_factory):
    path = tmp_path_factory.mktemp("osim_loads") / "two_pins.osim"
    _two_pins().printToXML(str(path))
    engine = load_engine(path, cache=False)
    names = [engine.model.getCoordinateSet().get(i).getName() for i in range(2)]
    return engine, names


@pytest.mark.parametrize("frame", ["ground", "body"])
def test_generalised_force_is_opensims_external_force(pins, frame):
    """J^T F equals minus OpenSim's inverse dynamics of the model with the load as a PrescribedForce (1e-9 rel.)."""
    engine, names = pins
    load = BodyLoad("upper", (10.0, -100.0, 3.0), (0.05, 0.4, 0.01), frame)
    values = {names[0]: 0.1, names[1]: -0.2}
    tau, _ = osim_load_terms(engine, [load], names, values, _mobility_order(engine))
    referee = _two_pins(load)
    state = referee.initSystem()
    for name, value in values.items():
        referee.getCoordinateSet().get(name).setValue(state, value)
    referee.realizeDynamics(state)
    needed = osim.InverseDynamicsSolver(referee).solve(state, osim.Vector(state.getNU(), 0.0)).to_numpy()
    assert np.max(np.abs(tau + needed)) <= 1e-9 * np.max(np.abs(needed))


def test_two_pins_closed_form(pins):
    """P 0.7 m above the lower pin, 0.4 m above the upper: K = -F_y [[0.7, 0.4], [0.4, 0.4]]; body-fixed
    F_y [[0, 0.3], [0, 0]] (docs/anatomy.md, "Loads"); central differences, so to 1e-6 N m/rad."""
    engine, names = pins
    f_y = -100.0
    ground = osim_load_terms(engine, [BodyLoad("upper", (0, f_y, 0), (0, 0.4, 0))], names, {}, _mobility_order(engine))
    assert np.allclose(ground[0], 0.0, atol=1e-12)
    assert np.allclose(ground[1], -f_y * np.array([[0.7, 0.4], [0.4, 0.4]]), atol=1e-6)
    body = BodyLoad("upper", (0, f_y, 0), (0, 0.4, 0), "body")
    follower = osim_load_terms(engine, [body], names, {}, _mobility_order(engine))
    assert np.allclose(follower[1], f_y * np.array([[0.0, 0.3], [0.0, 0.0]]), atol=1e-6)


def test_unknown_body_refused(pins):
    """A body the model lacks: one ParameterError naming --load."""
    engine, names = pins
    with pytest.raises(ParameterError, match="BODY must be a body of the model"):
        osim_load_terms(engine, [BodyLoad("thorax", (0, 1, 0))], names, {}, _mobility_order(engine))


def test_paper_chain_read_back_has_the_papers_load_stiffness(tmp_path):
    """A weight at the point mass of spinectl's .osim export: the free chain's K gains the paper's K_load.

    The export's bodies have their frames at the ground's origin upright, so the point mass is
    (0, mass_height, 0) in the thorax's frame; the mapping's chain runs L5S1 up, the paper's top down.
    """
    model = load_preset("wagner2012")
    path = tmp_path / "chain.osim"
    export_osim(model, E, LAMBDA, path)
    loaded = anatomy.load(path, cache=False)
    load = BodyLoad("thorax", (0.0, -200.0, 0.0), (0.0, model.body.mass_height, 0.0))
    bare = loaded.chains("sagittal")[0]
    held = loaded.chains("sagittal", loads=[load])[0]
    order = [held.joints.index(name) for name in model.geometry.cor_names]
    difference = (held.stiffness_offset - bare.stiffness_offset)[np.ix_(order, order)]
    expected = load_stiffness(model, geometry.cor_positions(E, LAMBDA, model.geometry), [PointLoad((0.0, -200.0))])
    assert np.allclose(difference, expected, rtol=1e-6, atol=1e-6)
    # the linearisation kept (and cached) holds no load: the chain without loads is the same again
    assert np.array_equal(loaded.chains("sagittal")[0].stiffness_offset, bare.stiffness_offset)
