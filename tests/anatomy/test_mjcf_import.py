"""spinectl's MJCF export imported back (``spinectl anatomy exported.xml``), with MuJoCo as the engine.

Everything on the import's side is MuJoCo's, read from the written file (spinectl.anatomy.linearise):
its moment arms and their Hessians, the fibres' force and slopes from MuJoCo's own actuator force
(``mj_fwdActuation``, the affine gain the exporter wrote), gravity and the passive forces
(``qfrc_bias``, ``qfrc_passive``) and the mass matrix. spinectl's side is docs/chain.md's chain
(spinectl.model.chain.linear_chain) at the exported solution's PCSA.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

from spinectl import anatomy  # noqa: E402
from spinectl.anatomy.analyses import analyse  # noqa: E402
from spinectl.anatomy.export_mjcf import export_mjcf, fibre_gains  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.model import chain, geometry  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402
from spinectl.units import M2_PER_CM2  # noqa: E402

E, LAMBDA = 0.03, 0.04  # a point of docs/chain.md's table ("Dynamic stability")
REVERSED = slice(None, None, -1)  # the mapping's chain runs L5S1 up, spinectl's top down
TOLERANCE = 1e-6  # relative; the central differences of MuJoCo's moment arms (STEP 1e-5 rad) reach ~1e-10


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    """The wagner2012 preset exported as MJCF under a name that is not the model's, and imported back."""
    model = load_preset("wagner2012")
    path = tmp_path_factory.mktemp("mjcf") / "paper.xml"
    solution = export_mjcf(model, E, LAMBDA, path)
    loaded = anatomy.load(path, cache=False)
    free, _, lin = loaded.chains("sagittal")
    return model, solution, loaded, free, lin, path


def _relative(ours, theirs) -> float:
    return float(np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs)))


def test_the_reimport_is_mapped_and_its_fibres_are_the_chains_controls(imported):
    """The file's own model name (wagner2012_chain) picks the built-in mapping whatever the file is called; the
    30 fibre actuators are the muscles (all global: thorax to the pelvis), the 5 counter_* motors are not, and the
    controls are keyframe 0's PCSA [cm^2], the solution's per muscle."""
    model, solution, loaded, free, _, _ = imported
    fibres = fibre_gains(model)
    assert loaded.engine.model_name == "wagner2012_chain" and loaded.name == "paper"
    assert loaded.muscles == fibres.names and loaded.classes == ("global",) * 30
    assert free.control_unit == "cm^2" and free.joints == tuple(model.geometry.cor_names[REVERSED])
    np.testing.assert_allclose(loaded.default_controls(), solution.pcsa[fibres.muscle] / M2_PER_CM2, rtol=1e-15)


def test_reimported_k_d_m_are_the_papers_chain(imported):
    """K, D and M of the re-imported chain at keyframe 0's controls equal linear_chain's at the solution's PCSA
    (docs/chain.md) to 1e-6 relative (measured: K 4e-11, D 1e-10, M 5e-16), and so do every control's K_i and D_i
    and K_0: the fibres' per-cm^2 matrices summed over each muscle (and pair) are linear_chain's per control.

    The counter_* motors are constant joint torques (no moment-arm change, no slope): they add to neither K nor D,
    so linear_chain, which has none, is the reference as it is."""
    model, solution, loaded, free, _, _ = imported
    reference = chain.linear_chain(model, E, LAMBDA)
    paired = model.optimisation.activation == "paired"  # linear_chain's controls: one per pair, or per muscle
    n_muscles = len(model.muscle_names)
    pairing = geometry.pairing_matrix(n_muscles // 2) if paired else np.eye(n_muscles)
    x = np.linalg.lstsq(pairing, solution.pcsa / M2_PER_CM2, rcond=None)[0]  # the solution's PCSA per pair [cm^2]
    u = loaded.default_controls()
    assert _relative(free.stiffness(u)[REVERSED, REVERSED], reference.stiffness(x)) <= TOLERANCE
    assert _relative(free.damping(u)[REVERSED, REVERSED], reference.damping(x)) <= TOLERANCE
    np.testing.assert_allclose(free.mass_matrix[REVERSED, REVERSED], reference.mass_matrix, rtol=TOLERANCE)
    owner = np.eye(n_muscles)[fibre_gains(model).muscle]  # fibre -> its muscle
    for ours, theirs in (
        (free.stiffness_per_control, reference.stiffness_per_control),
        (free.damping_per_control, reference.damping_per_control),
    ):
        assert _relative(ours[REVERSED, REVERSED] @ owner @ pairing, theirs) <= TOLERANCE
    assert _relative(free.stiffness_offset[REVERSED, REVERSED], reference.stiffness_offset) <= TOLERANCE


def test_the_counter_torques_enter_the_equilibrium_only(imported):
    """The motors are held at keyframe 0's torques: the import's torque offset is spinectl's gravity torque
    (chain_gravity_torque) plus the counter torques -tau_0 to 1e-9, and at the solution's controls the net torque
    vanishes (the posture is an equilibrium, as in the file) to 1e-9 of the counter torques."""
    model, solution, loaded, _, lin, _ = imported
    cor = geometry.cor_positions(E, LAMBDA, model.geometry)
    gravity = chain.chain_gravity_torque(model, cor, np.zeros(cor.shape[0]))
    offset = lin.torque_offset[list(lin.dofs[: lin.n])][REVERSED]
    scale = np.max(np.abs(solution.counter_torque))
    assert np.max(np.abs(offset - gravity - solution.counter_torque)) <= 1e-9 * scale
    net = lin.torque_per_muscle @ loaded.default_controls() + lin.torque_offset
    assert np.max(np.abs(net)) <= 1e-9 * scale


def test_mujocos_own_linearisation_agrees_with_the_reimport(imported):
    """analyse(check=True): MuJoCo's mjd_transitionFD of the re-imported file's free chain has the import's ten
    eigenvalues to 1e-6 (measured 5e-9), and MuJoCo's simulation grows along the leading mode at its rate to 1 %."""
    _, _, loaded, _, _, _ = imported
    result = analyse(loaded, check=True)
    assert result.referee_error() <= 1e-6
    predicted = result.free.dynamic_eigenvalues[0].real
    assert predicted > 0 and abs(result.simulated_rate - predicted) <= 0.01 * predicted


def test_cli_analyses_the_export_and_refuses_what_it_cannot(imported, capsys):
    """`spinectl anatomy paper.xml` analyses the solution (keyframe 0) and names each criterion; a control outside
    [0, inf) cm^2 and --optimise (its volume weights need MuJoCo muscles) are one line, exit 2."""
    *_, path = imported
    assert main(["anatomy", str(path), "--no-cache"]) == 0
    out = capsys.readouterr().out
    assert "30 global" in out and "cm^2" in out and "joint by joint (others fixed)" in out
    for extra in (["--activation", "-1"], ["--optimise"]):
        assert main(["anatomy", str(path), "--no-cache", *extra]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("spinectl: error:")


def _with_wrap(path, out, offset):
    """The export with a cylinder (axis along the hinges, radius 1 cm) on the pelvis, its centre ``offset`` beside
    straight_ventral_0's straight path at mid-height, in that fibre's tendon: MuJoCo's own wrapping."""
    text = path.read_text()
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    top, bottom = (
        d.site_xpos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"straight_ventral_0_{s}")]
        for s in ("upper", "lower")
    )
    centre = 0.5 * (top + bottom) + np.array([offset, 0.0, 0.0])  # the fibre runs along z
    geom = (
        f'<geom name="belly" type="cylinder" size="0.01 0.1" pos="{" ".join(repr(float(v)) for v in centre)}" '
        'euler="1.5707963267948966 0 0" contype="0" conaffinity="0"/>'
    )
    text = text.replace('<body name="ground">', f'<body name="ground">\n{geom}', 1)
    text = text.replace(
        '<site site="straight_ventral_0_upper" />', '<site site="straight_ventral_0_upper" />\n<geom geom="belly" />', 1
    )
    out.write_text(text)
    return out


def test_a_wrap_touched_at_the_posture_is_named_and_refused(imported, tmp_path, capsys):
    """A wrap cylinder tangent to straight_ventral_0's path at the posture (centre one radius beside it): MuJoCo's
    tendon wraps on one side of L5S1 = 0 only (ten_wrapnum changes), so the moment arm has a kink there; the CLI
    names the muscle, the geom and the joint, one line, exit 2, nothing on stdout. The same cylinder pushed into
    the path (half a radius beside it) is wrapped on both sides and linearised: the fibre's moment arm about L5S1
    is then MuJoCo's (ten_J) at the posture."""
    *_, path = imported
    tangent = _with_wrap(path, tmp_path / "tangent.xml", 0.01)
    assert main(["anatomy", str(tangent), "--no-cache"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert all(word in captured.err for word in ("straight_ventral_0", "belly", "L5S1"))
    inside = anatomy.load(_with_wrap(path, tmp_path / "inside.xml", 0.005), cache=False)
    _, _, lin = inside.chains()
    m, d = inside.engine.model, inside.engine.data
    inside.engine.set_state(m.qpos0)
    jacobian = np.zeros((m.ntendon, m.nv))
    mujoco.mju_sparse2dense(jacobian, d.ten_J, m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind)
    assert d.ten_wrapnum[0] == 4  # wrapped: two tangent points beside the two sites
    np.testing.assert_allclose(lin.moment_arms[0], jacobian[0], rtol=1e-12)


def test_a_mapping_naming_joints_the_export_lacks_is_one_line(imported, tmp_path, capsys):
    """A mapping whose chain names a joint the MJCF lacks (L9L10): one line naming it, exit 2, nothing on stdout."""
    *_, path = imported
    mapping = tmp_path / "bad.toml"
    mapping.write_text(
        '[bodies]\npelvis = ["ground"]\nvertebrae = ["vertebra_above_L5S1"]\nthorax = ["thorax"]\n'
        '[planes]\nsagittal = ["L5S1", "L9L10"]\n'
    )
    assert main(["anatomy", str(path), "--mapping", str(mapping), "--no-cache"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1 and "L9L10" in captured.err


@pytest.mark.parametrize("target", ["fifo", "/dev/zero", "folder"])
def test_a_file_the_mjcf_names_that_is_no_regular_file_is_refused_before_mujoco_reads_it(tmp_path, target):
    """An ``<include file>`` (or a mesh's file) that is a FIFO hung MuJoCo's reader for ever: it is refused in one
    line naming the file, by a check that only looks at the files (so this test cannot hang), before MuJoCo
    opens them; a nested include is followed; a regular included file passes."""
    import os

    from spinectl.anatomy.engine import check_files_named
    from spinectl.errors import ParameterError

    named = {"fifo": tmp_path / "x.fifo", "/dev/zero": Path("/dev/zero"), "folder": tmp_path / "d"}[target]
    if target == "fifo":
        os.mkfifo(named)
    elif target == "folder":
        named.mkdir()
    inner = tmp_path / "inner.xml"
    inner.write_text(f'<mujocoinclude><include file="{named}"/></mujocoinclude>')
    outer = tmp_path / "outer.xml"
    outer.write_text('<mujoco><include file="inner.xml"/><worldbody/></mujoco>')
    with pytest.raises(ParameterError, match=f"{named.name}', which is not a regular file") as info:
        check_files_named(outer)
    assert info.value.field == "model" and "inner.xml' names" in info.value.message
    inner.write_text("<mujocoinclude/>")
    check_files_named(outer)  # nothing raised
