"""The paper's chain exported as ``.osim``, with OpenSim as the referee of its geometry, masses and gravity.

OpenSim's side is computed by OpenSim from the written file: path lengths (``Muscle.getLength``),
moment arms (``computeMomentArm``), the mass matrix (``SimbodyMatterSubsystem.calcM``) and the
gravity torques (``InverseDynamicsSolver`` at rest, muscles off). spinectl's side is docs/chain.md's
closed forms (spinectl.model.chain).
"""

from __future__ import annotations

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from spinectl.anatomy.export_osim import controls_path, export_osim  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.model import chain, geometry  # noqa: E402
from spinectl.model.config import load_preset  # noqa: E402
from spinectl.model.mechanics import fibre_length_and_lever_arm  # noqa: E402

E, LAMBDA = 0.03, 0.04  # a point of docs/chain.md's table ("Dynamic stability")
POSTURES = (np.zeros(5), np.array([0.02, -0.03, 0.01, 0.04, -0.02]))  # upright and a bent chain [rad]


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The wagner2012 preset at (E, Lambda) written as .osim and loaded back by OpenSim."""
    model = load_preset("wagner2012")
    path = tmp_path_factory.mktemp("osim") / "chain.osim"
    solution = export_osim(model, E, LAMBDA, path)
    loaded = osim.Model(str(path))
    state = loaded.initSystem()
    return model, solution, loaded, state, path


def _at(loaded, state, model, q):
    """Set spinectl's joint angles q on the coordinates of the same names and realise positions."""
    for name, value in zip(model.geometry.cor_names, q, strict=True):
        loaded.getCoordinateSet().get(name).setValue(state, float(value), False)
    loaded.assemble(state)
    loaded.realizePosition(state)


def test_path_lengths_and_moment_arms_are_opensims(exported):
    """OpenSim's muscle lengths and computeMomentArm about every coordinate equal spinectl's fibre lengths and
    lever arms h about the moved CoRs (mechanics.fibre_length_and_lever_arm) to 1e-9, upright and bent."""
    model, _, loaded, state, _ = exported
    upper, lower, _ = geometry.all_fibres(model)
    cor = geometry.cor_positions(E, LAMBDA, model.geometry)
    muscles = loaded.getMuscles()
    for q in POSTURES:
        _at(loaded, state, model, q)
        moved, _ = chain.chain_positions(q, cor)
        length, h = fibre_length_and_lever_arm(chain.carried_points(upper, q, cor)[None], lower, moved[:, None, :])
        lengths = np.array([muscles.get(f).getLength(state) for f in range(muscles.getSize())])
        arms = np.array(
            [
                [
                    muscles.get(f).computeMomentArm(state, loaded.getCoordinateSet().get(j))
                    for j in model.geometry.cor_names
                ]
                for f in range(muscles.getSize())
            ]
        )
        np.testing.assert_allclose(lengths, length[0], rtol=1e-9)
        assert np.max(np.abs(arms - h.T)) <= 1e-9 * np.max(np.abs(h))


def test_gravity_and_mass_matrix_are_opensims(exported):
    """OpenSim's mass matrix and gravity torques equal mass_matrix and chain_gravity_torque (1e-9), upright and bent.

    Gravity: minus the inverse-dynamics torque at rest with every muscle, spring and counter torque off;
    the levels' weight, which spinectl's gravity leaves out by default, cancelled by the file's
    PrescribedForces (kept on)."""
    model, _, loaded, state, _ = exported
    cor = geometry.cor_positions(E, LAMBDA, model.geometry)
    forces = loaded.getForceSet()
    for i in range(forces.getSize()):
        if not forces.get(i).getName().endswith("_weight_relief"):
            forces.get(i).setAppliesForce(state, False)
    order = [loaded.getCoordinateSet().getIndex(j) for j in model.geometry.cor_names]
    for q in POSTURES:
        _at(loaded, state, model, q)
        mass = osim.Matrix()
        loaded.getMatterSubsystem().calcM(state, mass)
        full = np.array([[mass.get(i, j) for j in range(mass.ncol())] for i in range(mass.nrow())])
        np.testing.assert_allclose(full[np.ix_(order, order)], chain.mass_matrix(model, cor, q), rtol=1e-9, atol=1e-12)
        loaded.realizeDynamics(state)
        needed = osim.InverseDynamicsSolver(loaded).solve(state, osim.Vector(state.getNU(), 0.0))
        gravity = -np.array([needed.get(i) for i in order])
        expected = chain.chain_gravity_torque(model, cor, q)
        assert np.max(np.abs(gravity - expected)) <= 1e-9 * np.max(np.abs(expected))


def test_springs_and_controls_hold_the_solution(exported):
    """Each joint's SpringGeneralizedForce has the exported joint stiffness, and the controls file beside the
    model holds the solution: activation = PCSA / 100 cm^2 per fibre, then the counter torques, which make the
    posture an equilibrium of OpenSim's forward dynamics (its udot at rest)."""
    model, solution, loaded, _, path = exported
    for k, name in enumerate(model.geometry.cor_names):
        spring = osim.SpringGeneralizedForce.safeDownCast(loaded.getForceSet().get(f"{name}_stiffness"))
        assert spring.getStiffness() == solution.joint_stiffness[k]
    table = osim.TimeSeriesTable(str(controls_path(path)))
    row = np.array([table.getRowAtIndex(0)[i] for i in range(table.getNumColumns())])
    assert np.max(row[:-5]) == pytest.approx(np.max(solution.pcsa) / 100e-4, rel=1e-15)
    state = loaded.initSystem()  # the counter torques hold the posture against OpenSim's own (Millard's) forces
    loaded.equilibrateMuscles(state)
    loaded.realizeAcceleration(state)
    udot = np.array([state.getUDot().get(i) for i in range(5)])
    assert np.max(np.abs(udot)) <= 1e-9 * np.max(np.abs(np.linalg.solve(solution.mass, row[-5:])))
    assert np.max(np.abs(row[-5:] / solution.counter_torque - 1)) > 0.05  # not spinectl's: the curves differ


def test_cli_writes_osim_and_refuses_to_overwrite_its_input(tmp_path, capsys):
    """``spinectl export`` to .osim writes the model and its controls; --out equal to --config: one line, exit 2."""
    out = tmp_path / "chain.osim"
    assert main(["export", "--E", "0.03", "--Lambda", "0.04", "--out", str(out)]) == 0
    assert out.exists() and controls_path(out).exists()
    capsys.readouterr()
    config = tmp_path / "model.osim"
    config.write_text("")
    assert main(["export", "--config", str(config), "--out", str(config)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and config.read_text() == ""


def test_without_opensim_the_export_says_what_to_install(tmp_path, monkeypatch, capsys):
    """With ``opensim`` not importable (None in sys.modules), ``spinectl export`` to .osim is one line naming the
    extra, exit 2, and writes nothing."""
    monkeypatch.setitem(__import__("sys").modules, "opensim", None)
    out = tmp_path / "chain.osim"
    assert main(["export", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "spinectl[opensim]" in err
    assert not out.exists()


def test_an_unwritable_model_leaves_no_controls_behind(tmp_path, capsys):
    """--out naming a folder: one line, exit 2, and neither the model nor its controls .sto is written (the
    controls were written first and left behind before both went through one atomic step)."""
    out = tmp_path / "taken.osim"
    out.mkdir()
    assert main(["export", "--format", "osim", "--E", "0.03", "--Lambda", "0.04", "--out", str(out)]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken.osim"] and not any(out.iterdir())


def test_names_opensim_refuses_are_one_line_and_others_read_back(tmp_path, capsys):
    """A pair named with a space, '"', '<', '&', '--', ']]' and '|' (a printable label): the MJCF export writes it
    as MuJoCo's escaped attributes (MuJoCo finds the actuator by its exact name); the OpenSim export refuses it in
    one line naming the field, exit 2, nothing written, before the solve (before: OpenSim's 20-line traceback and
    a segmentation fault). The same name without the space is exported and OpenSim finds its muscle."""
    import mujoco

    from spinectl.quoting import toml_string

    def config(name):
        path = tmp_path / f"{len(name)}.toml"
        path.write_text(
            f'preset = "wagner2012"\n[[muscles]]\nname = {toml_string(name)}\nupper = [0.04, 0.26]\n'
            "lower = [0.04, 0.035]\n",
            encoding="utf-8",
        )
        return str(path)

    spaced, plain = 'st"r<a>&--ight]] |`x`', 'st"r<a>&--ight]]|`x`'
    assert main(["export", "--config", config(spaced), "--out", str(tmp_path / "n.xml")]) == 0
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "n.xml"))
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{spaced}_ventral_0") >= 0
    capsys.readouterr()
    assert main(["export", "--config", config(spaced), "--out", str(tmp_path / "n.osim")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "muscles.3.name: must hold no space" in err  # appended after the preset's 3
    assert not (tmp_path / "n.osim").exists() and not controls_path(tmp_path / "n.osim").exists()
    assert main(["export", "--config", config(plain), "--out", str(tmp_path / "p.osim")]) == 0
    assert osim.Model(str(tmp_path / "p.osim")).getMuscles().contains(f"{plain}_ventral_0")


def _full_fs(path):
    """os.statvfs of a file system with no byte free."""
    import types

    return types.SimpleNamespace(f_bavail=0, f_frsize=4096)


def _opensims_full_disk_error(self, path):
    """What Model.printToXML raises onto a full disk (OpenSim 4.6 on a 64 kB tmpfs, tried by hand)."""
    raise RuntimeError(
        "std::exception in 'bool OpenSim::Object::print(std::string const &) const': SimTK Exception thrown at "
        f"Xml.cpp:113:\n  Error detected by Simbody method Xml::writeToFile(): Failed to write to the Xml file "
        f"'{path}' with error ' (line=1, col=1)'.\n  (Required condition 'saveOK' was not met.)\n"
    )


def _truncating_sto_writer(table, path):
    """What STOFileAdapter.write does onto a full disk: an empty file, and no error (OpenSim 4.6, tried by hand)."""
    open(path, "w", encoding="utf-8").close()


@pytest.mark.parametrize(
    ("owner", "method", "fake", "expected"),
    [
        ("Model", "printToXML", _opensims_full_disk_error, "chain.osim': OpenSim's writer failed; No space left"),
        ("STOFileAdapter", "write", staticmethod(_truncating_sto_writer), "chain_controls.sto': OpenSim's writer"),
    ],
)
def test_a_full_disk_is_one_line_and_leaves_nothing(tmp_path, monkeypatch, capsys, owner, method, fake, expected):
    """OpenSim's writers on a full disk (simulated: the error or the silent empty file OpenSim gives there, and a
    file system with no space): one line naming the output and the full disk, exit 2, neither file nor a
    temporary left, the previous model intact (before: a 24-line traceback; an empty controls .sto passed)."""
    out = tmp_path / "chain.osim"
    out.write_text("old", encoding="utf-8")
    monkeypatch.setattr(getattr(osim, owner), method, fake)
    monkeypatch.setattr("os.statvfs", _full_fs)
    assert main(["export", "--E", "0.03", "--Lambda", "0.04", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected in err and "No space left on device" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chain.osim"] and out.read_text(encoding="utf-8") == "old"


def test_a_muscle_law_without_opensim_expressions_is_refused_and_nothing_written(tmp_path):
    """A law registered with ``opensim=None`` (docs/model.md, "The muscle-law seam"): the ``paper`` muscles, which
    carry the law's own curves, are one ParameterError naming fibre.law and leave no file; Millard's muscles, whose
    curves are Millard's whatever the law, are written."""
    import dataclasses

    from spinectl.errors import ParameterError
    from spinectl.model import laws

    law = laws.register_law(dataclasses.replace(laws.LAWS["wagner2012"], name="without_opensim", opensim=None))
    try:
        paper = load_preset("wagner2012")
        model = dataclasses.replace(paper, fibre=dataclasses.replace(paper.fibre, law=law.name))
        with pytest.raises(ParameterError, match="^fibre.law: the muscle law 'without_opensim' has no OpenSim"):
            export_osim(model, E, LAMBDA, tmp_path / "paper.osim", muscle="paper")
        assert list(tmp_path.iterdir()) == []
        export_osim(model, E, LAMBDA, tmp_path / "millard.osim", muscle="millard")
        assert (tmp_path / "millard.osim").is_file()
    finally:
        del laws.LAWS[law.name]
