"""Each muscle's contribution to an anatomical chain's stability index (spinectl.anatomy.contributions).

On MyoTorso (the session's fixture): d lambda_min / d a_i against central differences of lambda_min in a_i,
free and constrained, and Euler's identity; the removal method with the optimum re-solved. On a single joint
built through MuJoCo's MjSpec API: the muscle's K_i against Potvin & Brown's (2005) closed form. The command:
its table, JSON and figure, and its one-line errors.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from spinectl.cli import main
from spinectl.model.contributions import contributions

STEP = 1e-4
"""Central-difference step of each activation [1]. Measured on MyoTorso: the difference from the derivative is
1e-10 of the largest at this step (the truncation, ~STEP^2 lambda''', and the rounding, ~eps |K| / STEP, both
below it); 1e-5 gives 2e-10, 1e-6 2e-9 (rounding)."""

FD_TOLERANCE = 1e-7
"""Relative to the largest |derivative|: above the error measured at :data:`STEP` by a factor 500."""


def _lambda_min(chain, a):
    s = chain.stiffness(a)
    return np.linalg.eigvalsh(-0.5 * (s + s.T))[0]


@pytest.mark.parametrize(("plane", "which", "seed"), [("sagittal", 0, None), ("sagittal", 0, 1), ("3d", 1, 2)])
def test_the_derivative_is_the_central_difference_of_lambda_min_on_myotorso(torso, plane, which, seed):
    """d lambda_min / d a_i = -v^T K_i v against central differences of lambda_min in a_i (STEP, FD_TOLERANCE), on
    the free sagittal chain at a = 0.05 and at random activations, and on the 3-D chain constrained by the rhythm
    (3 coordinates: the sagittal one has a single coordinate, where lambda is linear and the check is empty)."""
    chain = torso.chains(plane)[which]
    m = chain.n_controls
    a = np.full(m, 0.05) if seed is None else np.random.default_rng(seed).uniform(0.0, 0.3, m)
    c = contributions(chain, a)
    assert chain.n_joints > 1 and not c.least.degenerate
    fd = np.array(
        [(_lambda_min(chain, a + STEP * e) - _lambda_min(chain, a - STEP * e)) / (2 * STEP) for e in np.eye(m)]
    )
    np.testing.assert_allclose(c.derivative, fd, rtol=0, atol=FD_TOLERANCE * np.max(np.abs(fd)))
    assert c.offset + c.share.sum() == pytest.approx(c.least.eigenvalue, rel=1e-12)  # Euler's identity


MAPPING = """
[bodies]
pelvis = ["pelvis"]
vertebrae = ["top"]
thorax = ["chest"]

[planes]
sagittal = ["j1"]
"""


def _single_joint(tmp_path, origin, insertion):
    """One hinge j1 (about y, at the pelvis's origin) and one muscle from ``origin`` on the pelvis to ``insertion``
    on the rotating body, both (x, z) from the joint [m]; no gravity. Built with MuJoCo's MjSpec API."""
    mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    from spinectl import anatomy

    spec = mujoco.MjSpec()
    spec.modelname = "single"
    spec.compiler.LRopt.mode = mujoco.mjtLRMode.mjLRMODE_NONE
    spec.option.gravity = [0.0, 0.0, 0.0]
    pelvis = spec.worldbody.add_body(name="pelvis", pos=[0, 0, 1.0])
    top = pelvis.add_body(name="top")
    top.add_joint(name="j1", axis=[0, 1, 0])
    chest = top.add_body(name="chest", pos=[0, 0, 0.1])
    for body in (pelvis, top, chest):
        body.add_geom(size=[0.04, 0, 0], mass=1.0)
    pelvis.add_site(name="origin", pos=[origin[0], 0, origin[1]])
    top.add_site(name="insertion", pos=[insertion[0], 0, insertion[1]])
    tendon = spec.add_tendon(name="m")
    tendon.wrap_site("origin")
    tendon.wrap_site("insertion")
    actuator = spec.add_actuator(name="m", target="m", trntype=mujoco.mjtTrn.mjTRN_TENDON)
    actuator.set_to_muscle(tausmooth=0.0, force=500.0)
    actuator.lengthrange = [0.05, 0.4]  # given: a joint without limits has no range to search
    path, mapping = tmp_path / "single.xml", tmp_path / "single.toml"
    path.write_text(spec.to_xml())
    mapping.write_text(MAPPING)
    return anatomy.load(path, mapping, cache=False)


@pytest.mark.parametrize(
    ("origin", "insertion"),
    [((0.05, -0.1), (0.06, 0.12)), ((0.01, -0.1), (-0.005, 0.1)), ((-0.08, -0.05), (-0.02, 0.15))],
)
def test_a_single_muscles_stiffness_is_potvin_and_browns_closed_form(tmp_path, origin, insertion):
    """Potvin & Brown (2005, J Biomech 38:973-980, doi:10.1016/j.jbiomech.2004.05.021), one muscle about one
    joint axis, from the potential energy of its force F and stiffness k = q F / L, A and B its origin and insertion
    from the joint centre in the plane of rotation, L = |B - A|:

        -K_i = F/L [A.B - (A x B)^2 / L^2] + q F/L (A x B)^2 / L^2,

    (A x B)/L the moment arm, the first term F d^2L/dtheta^2. F and k are MuJoCo's muscle gain at the posture and
    its slope in length (mju_muscleGain, per unit activation): spinectl's K_i comes from MuJoCo's moment arms and
    their central differences instead. Cases: a flexor in front, a muscle nearly through the joint (the first term
    negative: destabilising), one behind."""
    mujoco = pytest.importorskip("mujoco")
    loaded = _single_joint(tmp_path, origin, insertion)
    free, _, _ = loaded.chains("sagittal")
    model, data = loaded.engine.model, loaded.engine.data
    loaded.engine.set_state(model.qpos0)
    lr, acc0, prm = model.actuator_lengthrange[0], model.actuator_acc0[0], model.actuator_gainprm[0][:9]
    a, b = np.array(origin), np.array(insertion)
    length = float(np.linalg.norm(b - a))
    assert data.actuator_length[0] == pytest.approx(length, rel=1e-12)

    def gain(x):
        return mujoco.mju_muscleGain(x, 0.0, lr, acc0, prm)

    h = 1e-7 * length
    force = -gain(length)  # MuJoCo's muscle force is negative (a pull)
    q = -(gain(length + h) - gain(length - h)) / (2 * h) * length / force
    cross, dot = a[0] * b[1] - a[1] * b[0], a @ b
    closed = force / length * (dot - cross**2 / length**2) + q * force / length * cross**2 / length**2
    assert -free.stiffness_per_control[0, 0, 0] == pytest.approx(closed, rel=1e-8)


@pytest.fixture(scope="module")
def optimum(torso):
    """The stability-constrained optimum at 50 N m/rad per joint (feasible from 40.2: docs/anatomy.md) and its
    contributions with the removal re-solving it."""
    from spinectl.anatomy.contributions import with_contributions
    from spinectl.anatomy.optimum import optimised

    settings = {"stability": "chain", "margin": 1.0, "equilibrium": "rhythm"}
    result = optimised(torso, joint_stiffness=50.0, **settings)
    return result, with_contributions(torso, result, joint_stiffness=50.0, count=3, optimum=settings)


def test_the_removal_re_solves_the_optimum_holding_the_removed_muscles(torso, optimum):
    """With --optimise each removal is the optimum re-solved with the muscles held at 0: its activations hold
    them at 0 and keep the equilibrium (the net torque on the rhythm's rows within the solver's tolerance); a
    muscle idle at the optimum leaves the index as it was; the table names the re-solve."""
    from spinectl.anatomy.contributions import optimum_resolver

    result, contrib = optimum
    assert result.optimum.ok
    resolve = optimum_resolver(torso, "sagittal", None, 50.0, "chain", 1.0, "rhythm")
    free, _, lin = torso.chains("sagittal", joint_stiffness=50.0)
    _, tau_per, tau_0 = torso.equilibrium_rows(lin, "sagittal", None, "rhythm")
    active = int(np.argmax(result.optimum.activations))
    held = np.eye(free.n_controls, dtype=bool)[active]
    a, status = resolve(held)
    assert status == "re-solved: optimal" and a[active] == 0.0
    assert np.max(np.abs(tau_per @ a + tau_0)) <= 1e-6 * np.max(np.abs(tau_0))
    idle = int(np.argmin(result.optimum.activations))
    a_idle, _ = resolve(np.eye(free.n_controls, dtype=bool)[idle])
    lam = contrib.free.least.eigenvalue
    assert _lambda_min(free, a_idle) == pytest.approx(lam, abs=1e-3 * abs(lam))
    assert "the optimum re-solved" in contrib.table()


def test_an_infeasible_optimum_has_no_contributions(torso):
    """Without added stiffness the stability-constrained optimum is infeasible (docs/anatomy.md): no activations,
    so no contributions, said in the table and as null with its reason in the JSON."""
    from spinectl.anatomy.contributions import with_contributions
    from spinectl.anatomy.optimum import optimised

    settings = {"stability": "chain", "margin": 1.0, "equilibrium": "rhythm"}
    result = optimised(torso, **settings)
    out = with_contributions(torso, result, optimum=settings)
    assert out.free is None and "contributions: none" in out.table()
    assert out.to_dict()["contributions_reason"] == "not_computed"


def test_the_command_prints_json_and_draws_the_figure(torso, tmp_path, capsys):
    """spinectl anatomy --contributions 4 --group ... --json: the 4 largest per chain, the classes, the group, the
    removals; --plot writes contributions.png beside the other figures."""
    args = ["anatomy", "--activation", "0.05", "--contributions", "4", "--group", "abs=rect_abd|EO|IO"]
    assert main([*args, "--json", "--plot", str(tmp_path)]) == 0
    doc = json.loads(capsys.readouterr().out)["contributions"]
    free = doc["free"]
    assert len(free["controls"]) == 4 and free["groups"]["abs"]["members"] > 0
    assert set(free["classes"]) == {"global", "local", "between", "non-lumbar"}
    assert "group:abs" in free["removal"] and free["controls"][0]["name"] in free["removal"]
    assert (tmp_path / "contributions.png").stat().st_size > 0
    assert main(args) == 0
    assert "d lambda/du" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        (["--group", "x=IL"], "--group: goes with --contributions"),
        (["--contributions", "--group", "x=("], "group x: must be a regular expression (got '('"),
        (["--contributions", "--group", "x=nothing_named_so"], "group x: must match at least one muscle"),
        (["--contributions", "0"], "--contributions must be in [1, 100000]"),
        (["--contributions", "--group", "noequals"], "--group must be NAME=REGEX"),
    ],
)
def test_the_commands_errors_are_one_line(torso, tmp_path, capsys, extra, said):
    """A group without --contributions, a bad regular expression, a group matching no muscle, a count out of
    range, a group without NAME=: one line on stderr, exit 2, nothing on stdout, no figure written (--plot)."""
    folder = tmp_path / "figs"
    assert main(["anatomy", "--activation", "0.05", *extra, "--plot", str(folder)]) == 2
    err = capsys.readouterr()
    assert err.out == "" and said in err.err and len(err.err.strip().splitlines()) == 1
    assert not folder.exists()


def test_the_figure_draws_the_listed_derivatives_and_the_class_sums(torso):
    """contributions.png: one bar per listed muscle, its length d lambda_min / d a_i, the largest on top; one bar
    per class, its length the class's sum (the numbers of the table, read back from the drawn rectangles)."""
    from spinectl.anatomy.contributions import contributions_figure

    free = torso.chains("sagittal")[0]
    c = contributions(free, np.full(free.n_controls, 0.05))
    figure = contributions_figure(c, count=6)
    muscles, classes = figure.axes[0].patches, figure.axes[1].patches
    order = c.largest(6)
    assert [p.get_width() for p in muscles] == pytest.approx(list(c.derivative[order][::-1]))
    assert [p.get_width() for p in classes] == pytest.approx([c.sums(m)[0] for m in c.classes().values()])


def test_the_papers_chain_exported_to_mujoco_gives_each_muscle_the_same_part(tmp_path):
    """The paper's chain at E = 3 cm, Lambda = 4 cm exported as MJCF (each of the 30 fibres a MuJoCo actuator
    whose control is its muscle's PCSA [cm^2]) and read back by MuJoCo: the index is the paper's, and each muscle's
    derivative on the paper's chain (pair_contributions, spinectl's own formulas) is the sum of its fibres'
    derivatives on MuJoCo's linearisation (its moment arms and their differences), to 1e-6 relative (the
    re-import's tolerance, tests/anatomy/test_mjcf_import.py)."""
    pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    from spinectl import anatomy
    from spinectl.anatomy.export_mjcf import export_mjcf, fibre_gains
    from spinectl.model.config import load_preset
    from spinectl.model.contributions import pair_contributions
    from spinectl.model.operating_point import OperatingPoint

    model = load_preset("wagner2012")
    solution = export_mjcf(model, 0.03, 0.04, tmp_path / "paper.xml")
    loaded = anatomy.load(tmp_path / "paper.xml", cache=False)
    free = loaded.chains("sagittal")[0]
    ours = contributions(free, loaded.default_controls())
    paper = pair_contributions(OperatingPoint(model, 0.03, 0.04, solution.pcsa, slip_check=False)).contributions
    owner = fibre_gains(model).muscle
    summed = [ours.derivative[owner == k].sum() for k in range(len(paper.controls))]
    assert ours.least.eigenvalue == pytest.approx(paper.least.eigenvalue, rel=1e-6)
    np.testing.assert_allclose(summed, paper.derivative, rtol=0, atol=1e-6 * np.max(np.abs(paper.derivative)))


def test_contributions_at_another_posture_than_the_analysed_are_refused(torso):
    """with_contributions checks that its chain is the analysed one (their least eigenvalues agree to 1e-9 of the
    largest): the analysis at a lordosis posture 10 degrees off the reference, the contributions asked at the
    reference posture, is one ParameterError naming the posture; at the same posture it passes."""
    from spinectl.anatomy.analyses import analyse
    from spinectl.anatomy.contributions import with_contributions
    from spinectl.errors import ParameterError

    bent = torso.lordosis_posture(10.0)
    result = analyse(torso, activation=0.05, posture=bent)
    with pytest.raises(ParameterError, match="posture"):
        with_contributions(torso, result)
    assert with_contributions(torso, result, posture=bent).free is not None
