"""The engine contract (spinectl.anatomy.contract): a made-up third engine through the seams alone, the
engines' conformance, and the registry's refusal of a model it has no engine for."""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest

from spinectl import anatomy
from spinectl.anatomy.contract import ENGINES, AnatomyEngine, MappedModel, register_engine
from spinectl.anatomy.linearise import Linearisation, Rhythm
from spinectl.anatomy.mapping import Mapping
from spinectl.cli import main
from spinectl.errors import ParameterError

# The made-up engine's fixed linearisation: 2 joints, 3 muscles (K = dtau/dq, stable where -K > 0).
K_MUSCLES = -np.stack([[[40.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 40.0]], [[20.0, 10.0], [10.0, 20.0]]], axis=-1)
K_OFFSET = np.array([[15.0, 0.0], [0.0, 10.0]])  # gravity: destabilising
TORQUE = np.array([[10.0, 0.0, 0.0], [0.0, 10.0, 0.0]])  # [N m] per unit activation: m3 only stiffens
GRAVITY = np.array([-3.0, -2.0])  # [N m] at the upright posture
TILT = np.array([-0.1, -0.1])  # [N m/deg]: gravity's torque grows with the lordosis
DEFAULT = 0.2


@dataclass
class FakeModel:
    """What a third engine would compile: here only its name and provenance."""

    name: str
    source: str
    sha256: str = "0" * 64


@dataclass
class FakeAnatomy(MappedModel):
    """A third engine: the contract's engine part, its linearisation the fixed matrices above."""

    control_unit = "1"

    def control_bounds(self):
        return np.zeros(3), np.ones(3)

    def default_controls(self):
        return np.full(3, DEFAULT)

    def default_controls_source(self):
        return "the made-up engine's fixed controls"

    def posture(self, posture=None):
        return 0.0 if posture is None else float(posture)

    def rhythm(self, plane="sagittal", posture=None):
        return Rhythm((0, 1), (0, 1), np.eye(2), np.zeros((2, 2))), list(self.plane_joints(plane))

    def linearise(self, plane="sagittal", posture=None):
        rhy, involved = self.rhythm(plane, posture)
        zeros = np.zeros((2, 2, 3))
        lin = Linearisation(
            dofs=(0, 1),
            n=2,
            stiffness_per_muscle=K_MUSCLES,
            stiffness_offset=K_OFFSET,
            damping_per_muscle=zeros,
            damping_offset=-np.eye(2),
            mass=np.diag([0.1, 0.05]),
            torque_per_muscle=TORQUE,
            torque_offset=GRAVITY + TILT * self.posture(posture),
            moment_arms=TORQUE.T / 200.0,
        )
        return lin, rhy, involved

    def equilibrium_rows(self, lin, plane, posture, equilibrium):
        return [0, 1], lin.torque_per_muscle, lin.torque_offset

    def volume_weights(self):
        return np.ones(3)

    def lordosis_posture(self, degrees, plane="sagittal"):
        return float(degrees)


def load_fake(model, mapping=None, cache=True):
    """The third engine's loader: any ``.fake`` name is the same fixed model."""
    mapped = Mapping(
        bodies={"pelvis": ("pelvis",), "vertebrae": ("v",), "thorax": ("thorax",)},
        planes={"sagittal": ("lower", "upper")},
        joint_stiffness=5.0,
        stiffness_source="made up",
        path="<fake>",
    )
    return FakeAnatomy(FakeModel("fake", str(model)), mapped, ("m1", "m2", "m3"), ("local", "local", "global"))


@pytest.fixture
def fake_engine(monkeypatch):
    """The third engine registered by its suffix, for this test only."""
    monkeypatch.setitem(ENGINES, ".fake", None)  # restored (removed) after the test
    register_engine(".FAKE", load_fake)
    return "model.fake"


def run_json(argv, capsys) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_a_made_up_third_engine_runs_through_the_seams_alone(fake_engine, capsys):
    """`spinectl anatomy model.fake --json`: the verdicts of -K = -(K_0 + 0.2 sum K_i) = [[-3, 2], [2, 2]]
    (by hand from the fixed matrices): joint `lower` alone unstable (-3), `upper` stable (2), the chain's
    eigenvalues -0.5 -+ sqrt(6.25 + 4) = -3.702, 2.702."""
    assert isinstance(anatomy.load(fake_engine), AnatomyEngine)
    doc = run_json(["anatomy", fake_engine, "--json"], capsys)
    text = json.dumps(doc)
    assert {k: doc["model"][k] for k in ("name", "source", "sha256", "engine")} == {
        "name": "fake",
        "source": "model.fake",
        "sha256": "0" * 64,
        "engine": "unnamed engine",
    }
    assert "-3.0" in text and "2.0" in text
    eig = sorted(np.linalg.eigvalsh([[-3.0, 2.0], [2.0, 2.0]]))
    assert np.allclose(eig, [-0.5 - np.sqrt(10.25), -0.5 + np.sqrt(10.25)])
    assert any(np.allclose(v, eig) for v in _lists(doc) if len(v) == 2)


def _lists(doc):
    """Every list of numbers in a JSON document."""
    if isinstance(doc, dict):
        for value in doc.values():
            yield from _lists(value)
    elif isinstance(doc, list):
        if doc and all(isinstance(v, float | int) and not isinstance(v, bool) for v in doc):
            yield doc
        for value in doc:
            yield from _lists(value)


def test_the_optimum_and_the_lordosis_curve_on_the_third_engine(fake_engine, capsys):
    """`--optimise --json`: the classic optimum is min |a|^2 with 10 a1 = 3, 10 a2 = 2 (m3 has no torque),
    so a = (0.3, 0.2, 0), cost 0.13, whose -K = [[-3, 0], [0, -2]] is unstable; the chain optimum's -K has
    its least eigenvalue >= mu = 1 (m3's stiffness) and costs more. `--lordosis -2:2:3`: the classic cost
    0.1^2 ((3 + 0.1 d)^2 + (2 + 0.1 d)^2) = 0.1108, 0.13, 0.1508 at d = -2, 0, 2 deg."""
    doc = run_json(["anatomy", fake_engine, "--optimise", "--json"], capsys)
    assert doc["classic"]["status"] == "optimal"
    assert abs(doc["classic"]["cost"] - 0.13) <= 1e-6
    assert doc["optimum"]["status"] == "optimal" and doc["optimum"]["eigenvalues"][0] >= 1.0 - 1e-6
    assert doc["optimum"]["cost"] > doc["classic"]["cost"]
    curve = run_json(["anatomy", fake_engine, "--lordosis", "-2:2:3", "--json"], capsys)["lordosis_curve"]
    assert curve["lordosis_deg"] == [-2.0, 0.0, 2.0]
    assert np.allclose(curve["none"]["cost"], [0.1108, 0.13, 0.1508], atol=1e-6)
    assert curve["chain"]["status"] == ["optimal"] * 3


def test_mujocos_model_is_an_anatomy_engine(torso):
    """MuJoCo's Anatomy meets the contract (runtime_checkable: every member present)."""
    assert isinstance(torso, AnatomyEngine)


def test_an_object_lacking_a_member_is_no_anatomy_engine():
    """The conformance check can fail: the contract's engine part missing (here on the bare base class)."""
    assert not isinstance(MappedModel(None, None, (), ()), AnatomyEngine)


@pytest.mark.parametrize("model", ["model.txt", "model.STL", "nosuchmodel", "folder/"])
def test_a_model_no_engine_reads_is_refused_in_one_line(model, capsys):
    """`spinectl anatomy model.txt` (and a suffix-less name that is no built-in model): one line naming the
    built-in names and every registered suffix, exit 2, nothing on stdout."""
    assert main(["anatomy", model]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("spinectl: error: model: ")
    assert all(allowed in err for allowed in ("'myotorso'", ".xml", ".mjcf", ".osim"))
    with pytest.raises(ParameterError, match="must be one of"):
        anatomy.load(model)


def test_an_engine_without_geometry_refuses_plot_in_one_line(fake_engine, tmp_path, capsys):
    """`spinectl anatomy model.fake --plot DIR` on an engine that gives no points to draw (MappedModel's
    default): one line naming `plot`, exit 2, nothing on stdout, no figure written."""
    out_dir = tmp_path / "figs"
    assert main(["anatomy", fake_engine, "--plot", str(out_dir)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("spinectl: error: plot: ")
    assert not out_dir.exists() or not any(out_dir.iterdir())


def test_every_exported_suffix_names_an_engine():
    """Every suffix `spinectl export` writes (interchange.FORMATS: .xml, .mjcf, .osim) is one ENGINES reads, so
    each exported file loads back (before the registry, `.mjcf` reached MuJoCo only by default)."""
    from spinectl.anatomy.interchange import FORMATS

    assert {suffix for suffixes in FORMATS.values() for suffix in suffixes} <= set(ENGINES)
