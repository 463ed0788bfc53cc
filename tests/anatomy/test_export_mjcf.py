"""The paper's chain exported as MJCF, with MuJoCo as the referee of spinectl's numbers.

Every number on MuJoCo's side is computed by MuJoCo from the written file: its tendon lengths
and Jacobians (``mj_fwdPosition``), its generalised gravity (``qfrc_bias`` at rest), its mass
matrix (``mj_fullM``), its linearisation (``mjd_transitionFD``) and its simulation
(``mj_step``). spinectl's side is docs/chain.md's closed forms (spinectl.model.chain) and the
``stability --coupled`` analysis (spinectl.optimise.coupled).
"""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl.anatomy.export_mjcf import export_mjcf, fibre_gains, mujoco_state_matrix  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.model import chain, geometry  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402
from spinectl.model.mechanics import fibre_length_and_lever_arm  # noqa: E402

E, LAMBDA = 0.03, 0.04  # a point of docs/chain.md's table ("Dynamic stability")
POSTURES = (np.zeros(5), np.array([0.02, -0.03, 0.01, 0.04, -0.02]))  # upright and a bent chain [rad]


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The wagner2012 preset at (E, Lambda) exported twice, without and with the least local stiffness."""
    model = load_preset("wagner2012")
    folder = tmp_path_factory.mktemp("mjcf")
    plain = export_mjcf(model, E, LAMBDA, folder / "chain.xml")
    local = export_mjcf(model, E, LAMBDA, folder / "local.xml", with_local_stiffness=True)
    return model, {"plain": (folder / "chain.xml", plain), "local": (folder / "local.xml", local)}


def _loaded(path):
    """MuJoCo's model of the file and data at keyframe 0 (the solution), forward dynamics run."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    return m, d


def _dofs(m, model):
    """MuJoCo's dof of each CoR, in spinectl's order (top to bottom)."""
    return np.array(
        [m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in model.geometry.cor_names]
    )


def _at(m, d, dofs, q):
    """Set spinectl's joint angles q and run MuJoCo's position stage."""
    d.qpos[:] = 0.0
    d.qpos[dofs] = q  # hinges: qpos address = dof address
    d.qvel[:] = 0.0
    mujoco.mj_fwdPosition(m, d)


def test_fibre_lengths_and_moment_arms_are_mujocos(exported):
    """MuJoCo's tendon lengths and their Jacobian equal spinectl's fibre lengths and -h about every moved CoR (1e-9).

    spinectl: chain.carried_points / chain_positions and mechanics.fibre_length_and_lever_arm (h = -dl/dq);
    at the upright posture also chain_coefficients' length_gradient. MuJoCo: ``ten_length``, ``ten_J``.
    """
    model, files = exported
    m, d = _loaded(files["plain"][0])
    dofs = _dofs(m, model)
    upper, lower, _ = geometry.all_fibres(model)
    cor = geometry.cor_positions(E, LAMBDA, model.geometry)
    for q in POSTURES:
        _at(m, d, dofs, q)
        moved, _ = chain.chain_positions(q, cor)
        tops = chain.carried_points(upper, q, cor)
        length, h = fibre_length_and_lever_arm(tops[None], lower, moved[:, None, :])  # (n, F)
        jacobian = np.zeros((m.ntendon, m.nv))
        mujoco.mju_sparse2dense(jacobian, d.ten_J, m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind)
        np.testing.assert_allclose(d.ten_length, length[0], rtol=1e-9)
        assert np.max(np.abs(jacobian[:, dofs] + h.T)) <= 1e-9 * np.max(np.abs(h))
    _at(m, d, dofs, POSTURES[0])
    mujoco.mju_sparse2dense(jacobian, d.ten_J, m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind)
    gradient = chain.chain_coefficients(model, E, LAMBDA).length_gradient
    assert np.max(np.abs(jacobian[:, dofs] - gradient)) <= 1e-9 * np.max(np.abs(gradient))


def test_gravity_and_mass_matrix_are_mujocos(exported):
    """MuJoCo's generalised gravity and mass matrix equal chain_gravity_torque and mass_matrix (1e-9), bent or not.

    MuJoCo's gravity torque is -qfrc_bias at rest plus the gravity compensation of the levels (their
    weight does not enter spinectl's gravity by default, levels.weight_in_gravity = 0).
    """
    model, files = exported
    m, d = _loaded(files["plain"][0])
    dofs = _dofs(m, model)
    cor = geometry.cor_positions(E, LAMBDA, model.geometry)
    for q in POSTURES:
        _at(m, d, dofs, q)
        mujoco.mj_fwdVelocity(m, d)
        gravity = (d.qfrc_passive - d.qfrc_bias)[dofs]
        expected = chain.chain_gravity_torque(model, cor, q)
        assert np.max(np.abs(gravity - expected)) <= 1e-9 * np.max(np.abs(expected))
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        np.testing.assert_allclose(full[np.ix_(dofs, dofs)], chain.mass_matrix(model, cor, q), rtol=1e-9, atol=1e-12)


def test_the_solution_is_an_equilibrium_with_spinectls_muscle_forces(exported):
    """At keyframe 0 every fibre's actuator pulls with spinectl's tension, so the counter torques hold the posture.

    Tension T0 = sigma s f_l(l0) PCSA (fibre_gains); MuJoCo's actuator force is the affine gain at the
    tendon's length times the control. The generalised acceleration is then zero to rounding.
    """
    model, files = exported
    m, d = _loaded(files["plain"][0])
    solution = files["plain"][1]
    fibres = fibre_gains(model)
    tension = fibres.force * solution.pcsa[fibres.muscle]
    np.testing.assert_allclose(-d.actuator_force[: len(fibres.names)], tension, rtol=1e-9, atol=1e-9)
    assert np.max(np.abs(d.qacc)) <= 1e-9 * np.max(np.abs(np.linalg.solve(solution.mass, solution.counter_torque)))


@pytest.mark.parametrize("kind", ["plain", "local"])
def test_mujocos_linearisation_is_the_chains(exported, kind):
    """mjd_transitionFD of the file (controls held, continuous rates) gives the ten eigenvalues of
    ``stability --coupled`` (coupled_stability_at: with the least local stiffness for "local") to 1e-3,
    and its K = M A_vq / h is the chain's K to 1e-5.
    """
    from spinectl.optimise.coupled import coupled_stability_at

    model, files = exported
    path, solution = files[kind]
    m, d = _loaded(path)
    m.opt.timestep = 1e-4
    a = mujoco_state_matrix(m, d, model.geometry.cor_names)
    eigenvalues = np.linalg.eigvals(a)
    reference = coupled_stability_at(model, E, LAMBDA)
    expected = reference.local_eigenvalues if kind == "local" else reference.eigenvalues
    for value in expected:  # each of spinectl's eigenvalues has MuJoCo's within 1e-3 relative
        assert np.min(np.abs(eigenvalues - value)) <= 1e-3 * abs(value)
    stiffness = solution.mass @ a[5:, :5]
    np.testing.assert_allclose(stiffness, solution.stiffness, rtol=1e-5, atol=1e-5 * np.max(np.abs(solution.stiffness)))


def _simulate(m, d, dofs, x0, duration, step):
    """Step MuJoCo from keyframe 0 displaced by x0 = (q, q'); the displacements (q, q') at every step."""
    m.opt.timestep = step
    d.qpos[dofs] += x0[:5]
    d.qvel[dofs] += x0[5:]
    out = []
    for _ in range(int(round(duration / step))):
        mujoco.mj_step(m, d)
        out.append(np.concatenate([d.qpos[dofs], d.qvel[dofs]]))
    return np.array(out)


def test_mujoco_diverges_along_the_unstable_mode_at_the_predicted_rate(exported):
    """Displaced 1e-7 rad along the chain's fastest growing mode, MuJoCo's simulation grows at its
    eigenvalue (dynamic_eigenvalues of the chain, 1/s) to 5 %: a least-squares fit of log |q| over 0.1 s.
    """
    model, files = exported
    path, solution = files["plain"]
    m, d = _loaded(path)
    dofs = _dofs(m, model)
    values, vectors = np.linalg.eig(chain.state_matrix(solution.mass, solution.stiffness, solution.damping))
    top = np.argmax(values.real)
    rate, mode = values[top].real, np.real(vectors[:, top])
    assert rate > 0  # the chain is unstable without local stiffness (docs/chain.md)
    x0 = 1e-7 * mode / np.linalg.norm(mode[:5])
    path_ = _simulate(m, d, dofs, x0, 0.1, 1e-4)
    times = 1e-4 * np.arange(1, len(path_) + 1)
    fitted = np.polyfit(times, np.log(np.abs(path_[:, :5] @ mode[:5])), 1)[0]
    assert abs(fitted - rate) <= 0.05 * rate


def test_with_the_least_local_stiffness_every_mode_decays_in_mujoco(exported):
    """With the least local stiffness as joint springs, every mode of the chain (dynamic_eigenvalues), all
    excited at once by 1e-6, has a smaller amplitude after 10 s of MuJoCo's simulation than at the start,
    the slowest as its eigenvalue predicts (5 %), and the chain stays within 10 times the start.
    """
    model, files = exported
    path, solution = files["local"]
    m, d = _loaded(path)
    dofs = _dofs(m, model)
    values, vectors = np.linalg.eig(chain.state_matrix(solution.mass, solution.stiffness, solution.damping))
    assert np.all(values.real < 0)
    x0 = 1e-6 * np.real(vectors @ np.ones(10))
    path_ = _simulate(m, d, dofs, x0, 10.0, 5e-4)
    start, end = np.linalg.solve(vectors, x0), np.linalg.solve(vectors, path_[-1])
    assert np.all(np.abs(end) < np.abs(start))
    slow = np.argmax(values.real)
    predicted = np.abs(start[slow]) * np.exp(10.0 * values[slow].real)
    assert abs(np.abs(end[slow]) - predicted) <= 0.05 * predicted
    assert np.max(np.abs(path_[:, :5])) <= 10 * np.max(np.abs(x0[:5]))


def test_the_file_holds_every_number_to_the_last_bit(exported):
    """The written MJCF compiles to the same model as the spec it was written from: no number rounded.

    MuJoCo's own to_xml writes six significant digits (5e-7 relative on a site), which the round trip at
    1e-9 would not survive; spinectl rewrites them (export_mjcf.exact_xml).
    """
    from spinectl.anatomy.export_mjcf import paper_spec

    model, files = exported
    path, solution = files["plain"]
    written = mujoco.MjModel.from_xml_path(str(path))
    compiled = paper_spec(solution).compile()
    for field in ("site_pos", "jnt_pos", "body_ipos", "body_mass", "body_inertia", "actuator_gainprm", "key_ctrl"):
        assert np.array_equal(getattr(written, field), getattr(compiled, field)), field


def test_cli_writes_the_file_and_refuses_to_overwrite_its_input(tmp_path, capsys):
    """``spinectl export`` writes an MJCF MuJoCo loads and names the chain's criterion; ``--out`` equal to
    ``--config`` or an unknown suffix is one line, exit 2, nothing written.
    """
    out = tmp_path / "chain.xml"
    assert main(["export", "--E", "0.03", "--Lambda", "0.04", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "spinectl's chain with them (all CoRs free, the paper's muscle laws): unstable" in printed
    assert "exported: global PCSA 35.80 cm^2 (the per-segment optimum unless given), no local stiffness" in printed
    assert mujoco.MjModel.from_xml_path(str(out)).nu == 35
    config = tmp_path / "model.toml"
    config.write_text("")
    before = config.read_bytes()
    assert main(["export", "--config", str(config), "--format", "mjcf", "--out", str(config)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out" in err
    assert config.read_bytes() == before
    assert main(["export", "--out", str(tmp_path / "chain.txt")]) == 2
    assert "format" in capsys.readouterr().err
    assert not (tmp_path / "chain.txt").exists()


def test_a_joint_stiff_in_name_only_is_marginal_as_in_stability(exported, capsys):
    """At (E, Lambda) = (3, 4) cm spinectl's L1L2 has -S = 0.1 N m/rad: `spinectl stability` calls it marginal
    (slowest time constant above spinectl.model.stability.MARGINAL_TIME_CONSTANT). `spinectl anatomy chain.xml`
    at keyframe 0 (the solution) uses the same rule on K_jj, D_jj, M_jj of the re-imported chain: L1L2 marginal
    with the time constant of segment_stability (to 1e-6 relative: at the top joint the chain's M_jj is the
    segment's theta), the stiffer joints not, their time constants within 3 % (the chain's M_jj below the top
    differs from the segment model's theta by up to 3 %, S and D agree)."""
    import json

    from spinectl.model.stability import segment_stability

    model, files = exported
    path, solution = files["plain"]
    reference = segment_stability(model, E, LAMBDA, solution.pcsa)
    assert main(["anatomy", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    order = [doc["joints"].index(name) for name in reference.segment_names]
    marginal = [doc["joint_marginal"][k] for k in order]
    assert marginal == list(reference.marginal) and marginal.count(True) == 1
    taus = np.array([doc["slowest_time_constant_s"][k] for k in order])
    assert abs(taus[0] - reference.time_constants[0]) <= 1e-6 * reference.time_constants[0]
    assert np.allclose(taus, reference.time_constants, rtol=0.03)
    assert main(["anatomy", str(path)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("L1L2"))
    assert "marginal" in row


INCLUDED = '<mujoco><worldbody><body name="injected"/></worldbody></mujoco>'
"""A model that an include made live by a path would add: a body named ``injected``."""


@pytest.mark.parametrize(
    "folder",
    [
        'a--><include file="x.xml"/><!--',  # ends the comment: MuJoCo followed the include
        "runs/2026-12--a",  # an ordinary '--': the export failed with an XML parse error after the solve
        "ctl\x01\x1b",  # characters XML allows nowhere
        "undecodable\udcff",  # a byte of the path that is not UTF-8, as Python holds it
        "b--->\n<include file='x.xml'/>",  # a line break and three dashes
        "pct%2D%2D&amp;<!--",  # percent signs (the encoding's own escape) and an entity
    ],
)
def test_a_config_path_is_data_in_the_exported_file(tmp_path, capsys, folder):
    """``spinectl export --config PATH`` names PATH in the file's comment (spinectl.quoting.xml_comment): the file
    parses as one <mujoco> root whose only comment is spinectl's, holds no <include>, MuJoCo loads it with none of
    x.xml's bodies, and the comment decodes to text naming PATH exactly."""
    import xml.etree.ElementTree as ET

    from spinectl.quoting import from_xml_comment

    (tmp_path / "x.xml").write_text(INCLUDED, encoding="utf-8")
    config = tmp_path / folder / "model.toml"
    config.parent.mkdir(parents=True)
    config.write_text('preset = "wagner2012"\n', encoding="utf-8")
    out = tmp_path / "chain.xml"
    assert main(["export", "--config", str(config), "--out", str(out)]) == 0, capsys.readouterr().err
    root = ET.parse(out, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))).getroot()
    assert root.tag == "mujoco" and not list(root.iter("include"))
    comments = [element.text for element in root.iter(ET.Comment)]
    assert len(comments) == 1 and f"config {config} (sha256 " in from_xml_comment(comments[0])
    m = mujoco.MjModel.from_xml_path(str(out))
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "injected") == -1 and m.nbody == 7  # world, ground, 5


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--out", "{tmp}/taken.xml"], "cannot write '{tmp}/taken.xml': Is a directory"),  # a folder in the way
        (["--out", "{tmp}/file/chain.xml"], "cannot write '{tmp}/file/chain.xml': "),  # a file where a folder goes
        (["--format", "osim", "--out", "{tmp}/chain.xml"], "--out: an osim file ends in .osim"),  # suffix of another
        (["--format", "mjcf", "--out", "{tmp}/chain.osim"], "--out: an mjcf file ends in .xml or .mjcf"),
        (["--config", "{tmp}/m_controls.sto", "--out", "{tmp}/m.osim"], "controls: is the same file as --config"),
    ],
)
def test_the_output_is_checked_before_the_model_is_solved(tmp_path, monkeypatch, capsys, argv, expected):
    """An output that cannot be written, of the wrong suffix or an input (the .osim's controls .sto too): one line,
    exit 2, nothing written, and no solve: paper_solution raises if reached (before: found after the solve)."""
    import spinectl.anatomy.export_mjcf as export_mjcf

    def solved(*args, **kwargs):
        raise AssertionError("the model was solved before the output was checked")

    monkeypatch.setattr(export_mjcf, "paper_solution", solved)
    (tmp_path / "taken.xml").mkdir()
    (tmp_path / "file").write_text("")
    (tmp_path / "m_controls.sto").write_text('preset = "wagner2012"\n')
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main(["export", *(word.format(tmp=tmp_path) for word in argv)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected.format(tmp=tmp_path) in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
