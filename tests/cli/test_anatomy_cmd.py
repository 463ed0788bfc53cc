"""``spinectl anatomy``: JSON keys, the table's criteria and clean failures (MyoTorso loaded once)."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from spinectl import jsondoc
from spinectl.cli import main

KEYS = (
    "model",
    "joints",
    "muscles",
    "global_rank",
    "stiffness_matrix_Nm_per_rad",
    "damping_matrix_Nms_per_rad",
    "mass_matrix_kgm2",
    "joint_stiffness_Nm_per_rad",
    "eigenvalues",
    "dynamic_eigenvalues",
    "joint_self_stable",
    "chain_stable",
    "constrained",
)


@pytest.fixture
def cached(monkeypatch):
    """The session's MyoTorso for ``myotorso`` (loading it takes seconds), MuJoCo's own load otherwise."""
    pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    import spinectl.anatomy as package

    real = package.load
    loaded = {}

    def load(model="myotorso", mapping=None, cache=True):
        if model == "myotorso" and mapping is None:
            return loaded.setdefault("torso", real("myotorso", cache=cache))
        return real(model, mapping, cache=cache)

    monkeypatch.setattr(package, "load", load)


def test_json_is_the_results_dict(cached, capsys):
    """``--json --check`` prints :meth:`AnatomyResult.to_dict` with the documented keys and MuJoCo's eigenvalues."""
    import spinectl.anatomy as package
    from spinectl.anatomy.analyses import analyse

    assert main(["anatomy", "--activation", "0.05", "--check", "--json"]) == 0
    out = capsys.readouterr().out
    doc = json.loads(out)
    assert all(key in doc for key in KEYS)
    assert set(doc["model"]) == {"name", "source", "sha256", "sha256_short", "engine", "versions"}
    assert set(doc["muscles"]) == {"global", "local", "between", "non-lumbar"}
    assert len(doc["mujoco_eigenvalues"]) == 10
    assert out == jsondoc.dumps(analyse(package.load(), activation=0.05, check=True).to_dict())


def test_the_table_names_every_criterion(cached, capsys):
    assert main(["anatomy"]) == 0
    out = capsys.readouterr().out
    assert "joint by joint (others fixed)" in out
    assert "the chain, free (every joint free, equality constraints off)" in out
    assert "the chain constrained by the model's rhythm" in out
    lines = out.splitlines()
    title = next(i for i, line in enumerate(lines) if "-K_jj [N m/rad]" in line)
    assert lines[title + 1].strip() == "(> 0 restores)"  # the sign, where stability's S is < 0 restoring


def test_the_3d_mapping_is_named_all_three_planes(cached, capsys):
    """--plane 3d analyses every chain joint at once: the first line says "all three planes (3-D)", not "3d plane"."""
    assert main(["anatomy", "--plane", "3d"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert "all three planes (3-D)" in first and "3d plane" not in first


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--activation", "1.5"], "activation: must be in [0, 1]"),
        (["--plane", "axial"], "plane: must be one of"),
        (["--joint-stiffness", "soft"], "--joint-stiffness must be none, mapped or a number"),
        (["no-such-model"], "model: must be one of"),
    ],
)
def test_bad_input_is_one_line_exit_2(cached, capsys, argv, message):
    assert main(["anatomy", *argv]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and message in captured.err and len(captured.err.strip().splitlines()) == 1


def test_optimise_json_has_the_activations_cost_and_net_torque(cached, capsys):
    """``--optimise --json``: activations by muscle name, cost and net torque at top level, the classic optimum
    beside, and the analysis at the optimum's activations (its eigenvalues those of the optimum)."""
    argv = ["anatomy", "--optimise", "--stability", "joints", "--joint-stiffness", "50", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["activations"]) == 210 and doc["cost"] > 0 and len(doc["net_torque_Nm"]) == 3
    assert doc["optimum"]["stability"] == "joints" and doc["classic"]["stability"] == "none"
    assert doc["eigenvalues"] == pytest.approx(doc["optimum"]["eigenvalues"], abs=1e-6)
    assert doc["price_of_stability"] >= 1


def test_an_infeasible_optimum_is_an_answer(cached, capsys):
    assert main(["anatomy", "--optimise", "--equilibrium", "free"]) == 0
    assert "infeasible" in capsys.readouterr().out


def test_lordosis_curve_in_json_and_bad_range(cached, capsys):
    assert main(["anatomy", "--lordosis", "-10:10:3", "--joint-stiffness", "50", "--json"]) == 0
    curve = json.loads(capsys.readouterr().out)["lordosis_curve"]
    assert curve["lordosis_deg"] == [-10.0, 0.0, 10.0] and len(curve["chain"]["cost"]) == 3
    assert main(["anatomy", "--lordosis", "1:2"]) == 2
    assert "--lordosis: must be START:STOP:N" in capsys.readouterr().err


def test_the_lordosis_curve_says_the_thorax_tilts_with_it(cached, capsys):
    """The anatomy's lordosis axis moves the chain along the rhythm, which tilts the thorax: the table says so
    above the curve (a reader took it for a lordosis at an upright trunk)."""
    from spinectl.anatomy.optimum import CURVE_MEANING

    assert main(["anatomy", "--lordosis", "-10:10:3", "--joint-stiffness", "50"]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = lines.index(next(line for line in lines if line.startswith("summed angle change [deg]  cost")))
    assert lines[head - 2] == f"lordosis curve ({CURVE_MEANING})" and "thorax" in CURVE_MEANING
    # the first column's title says what it is and its unit, explained on the line above (a reader saw a bare
    # change in degrees and could not tell of what); each row's value sits under it
    assert lines[head - 1].startswith("summed angle change [deg]: the chain's summed joint angle minus the model's")
    assert [float(line.split()[0]) for line in lines[head + 1 : head + 4]] == [-10.0, 0.0, 10.0]


def test_the_joint_table_names_each_joint_with_its_level(cached, capsys):
    """MyoTorso's L5S1 joint is called flex_extension, the others L4_L5_FE ...: the table prints each with its
    level (spinectl.anatomy.naming), in a column titled so, the same way for every joint; the JSON keeps the
    model's names, which scripts match."""
    assert main(["anatomy"]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("joint (level)"))
    rows = [line.split("  ")[0].strip() for line in lines[head + 2 : head + 7]]
    assert rows == ["flex_extension (L5S1)", "L4_L5_FE (L4L5)", "L3_L4_FE (L3L4)", "L2_L3_FE (L2L3)", "L1_L2_FE (L1L2)"]
    assert main(["anatomy", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["joints"][0] == "flex_extension"


def test_reflex_options_give_the_delay_margin(cached, capsys):
    assert main(["anatomy", "--optimise", "--stability", "none", "--kp", "120", "--kd", "5", "--json"]) == 0
    reflex = json.loads(capsys.readouterr().out)["reflex"]
    assert reflex["kp_Nm_per_rad"] == 120 and reflex["activation_lag_s"] == 0.05 and reflex["delay_margin_s"] > 0
    assert main(["anatomy", "--kp", "-1"]) == 2


def test_without_the_extra_one_line_says_what_to_install(monkeypatch, capsys):
    """MuJoCo's import blocked: one line naming ``pip install 'spinectl[anatomy]'``, exit 2, no traceback."""
    import sys

    monkeypatch.setitem(sys.modules, "mujoco", None)
    assert main(["anatomy"]) == 2
    err = capsys.readouterr().err
    assert "pip install 'spinectl[anatomy]'" in err and len(err.strip().splitlines()) == 1


def test_plot_writes_the_figures(cached, capsys, tmp_path):
    """``--plot DIR --lordosis`` writes the three PNGs (non-empty, PNG signature) and prints the usual table."""
    assert main(["anatomy", "--activation", "0.05", "--lordosis", "-5:5:2", "--plot", str(tmp_path / "fig")]) == 0
    assert "the chain, free" in capsys.readouterr().out
    for name in ("sagittal.png", "modes.png", "lordosis.png"):
        assert (tmp_path / "fig" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_in_3d_says_modes_png_is_not_drawn(cached, capsys, tmp_path):
    """``--plane 3d --plot`` wrote sagittal.png alone, modes.png dropped without a word: one line after the answer
    says so (anatomy.figures.figures_left_out); the sagittal plane's --plot draws both and says nothing."""
    from types import SimpleNamespace

    from spinectl.anatomy.analyses import plane_text
    from spinectl.anatomy.figures import figures_left_out

    assert main(["anatomy", "--plane", "3d", "--plot", str(tmp_path / "fig")]) == 0
    err = capsys.readouterr().err
    assert sorted(p.name for p in (tmp_path / "fig").iterdir()) == ["sagittal.png"]
    assert err == f"spinectl: warning: {figures_left_out(SimpleNamespace(plane='3d'))}\n"
    assert err.startswith("spinectl: warning: modes.png not drawn") and plane_text("3d") in err
    assert main(["anatomy", "--plot", str(tmp_path / "sagittal")]) == 0
    assert "modes.png" not in capsys.readouterr().err and (tmp_path / "sagittal" / "modes.png").exists()


def test_plot_into_an_unwritable_folder_is_one_line(cached, capsys, tmp_path):
    """``--plot`` under a regular file: one line naming the path, exit 2, no table printed, nothing written."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["anatomy", "--plot", str(blocker / "figs")]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.strip().splitlines()) == 1 and "file" in captured.err
    assert blocker.read_text() == ""


def test_an_infeasible_optimum_keeps_the_json_keys(cached, capsys):
    """``--optimise --json`` on MyoTorso (no joint stiffness): the chain criterion is infeasible, the classic one
    solved (so the stability criterion fails, not the equilibrium). Its JSON has every key of a solved optimum's
    (``--stability none``), the nested ``constrained`` ones too, the numbers it has no activations for null with
    ``<key>_reason`` "not_computed" (spinectl.jsondoc's convention)."""

    def keys(doc):
        return {k for k in doc if not k.endswith("_reason")}

    assert main(["anatomy", "--optimise", "--json"]) == 0
    infeasible = json.loads(capsys.readouterr().out)
    assert main(["anatomy", "--optimise", "--stability", "none", "--json"]) == 0
    solved = json.loads(capsys.readouterr().out)
    assert infeasible["optimum"]["status"] == "infeasible" and solved["optimum"]["status"] == "optimal"
    assert infeasible["infeasible_constraint"] == "stability" and solved["infeasible_constraint"] == "none"
    assert keys(infeasible) == keys(solved) and set(KEYS) <= keys(infeasible)
    assert keys(infeasible["constrained"]) == keys(solved["constrained"])
    for key in ("eigenvalues", "joint_self_stable", "chain_stable"):
        assert infeasible[key] is None and infeasible[f"{key}_reason"] == "not_computed"
    assert infeasible["muscles"] == solved["muscles"] and infeasible["joints"] == solved["joints"]


BOUND = "must be in [0, 1e+06] N m/rad, the bound of the chain's arithmetic"
"""spinectl.anatomy.mapping.MAX_STIFFNESS: 1e6 N m/rad (its docstring: measured exact to 1e8, wrong from 1e9-1e12)."""


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--joint-stiffness", "1e308"], f"--joint-stiffness {BOUND}"),  # before: NaN eigenvalues, exit 0
        (["--joint-stiffness", "1.1e6"], f"--joint-stiffness {BOUND}"),
        (["--joint-stiffness", "-0.5"], f"--joint-stiffness {BOUND}"),
        (["--kp", "1e308"], f"--kp {BOUND}"),  # before: a LinAlgError traceback
        (["--kp", "2e6"], f"--kp {BOUND}"),
        (["--kp", "100", "--kd", "1e300"], "--kd must be in [0, 1e+06] N m s/rad"),
        (
            ["--kp", "100", "--activation-lag", "5"],
            "--activation-lag must be in [0, 1] s",
        ),  # MAX_ACTIVATION_TIME_CONSTANT
        (["--activation", "1e308"], "--activation must be at most 1e+06"),
        (["--optimise", "--margin", "1e308"], f"--margin {BOUND}"),  # before: 90 s, then solver_error
    ],
)
def test_every_number_has_its_bound(capsys, argv, message):
    """Each numeric option of `anatomy` refused beyond the bound where its arithmetic holds: one line, exit 2,
    before any model is loaded (argparse's type)."""
    assert main(["anatomy", *argv]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and message in captured.err and captured.err.count("\n") == 1


def test_the_bounds_themselves_are_answers(cached, capsys):
    """At the bounds (1e6 N m/rad added, kp = 1e6, kd = 1e6, lag 1 s) the answer is finite: the chain's
    eigenvalues of -K all about 1e6 (the added stiffness dominates MyoTorso's own, |K_0| < 400 N m/rad), the
    delay margin finite and positive."""
    argv = ["anatomy", "--joint-stiffness", "1e6", "--kp", "1e6", "--kd", "1e6", "--activation-lag", "1", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert np.allclose(doc["eigenvalues"], 1e6, rtol=1e-3)
    assert doc["reflex"]["delay_margin_status"] == "finite" and 0 < doc["reflex"]["delay_margin_s"] < 1


@pytest.mark.parametrize("kind", ["5000-character path", "300-character name", "folder", "fifo"])
def test_a_model_path_that_is_no_file_is_one_line(tmp_path, capsys, kind):
    """A model path too long for the file system (the whole path, or one name over 255 bytes), a folder, a FIFO:
    `model: ...`, one line, exit 2 (before: an OSError traceback for the long names)."""
    path = {
        "5000-character path": "a" * 5000 + ".xml",
        "300-character name": str(tmp_path / ("b" * 300 + ".osim")),
        "folder": str(tmp_path),
        "fifo": str(tmp_path / "model.xml"),
    }[kind]
    if kind == "fifo":
        os.mkfifo(path)
    assert main(["anatomy", path]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith("spinectl: error: model: ") and captured.err.count("\n") == 1


def test_the_optimum_refuses_an_activation_it_would_ignore(cached, capsys):
    """--optimise finds the activations itself: a given --activation was ignored without a word (exit 0)."""
    assert main(["anatomy", "--optimise", "--activation", "0.5"]) == 2
    assert capsys.readouterr().err == (
        "spinectl: error: --activation: cannot go with --optimise, which finds the activations itself\n"
    )


def test_json_with_a_posture_file_on_a_model_missing_its_meshes_is_json_alone(tmp_path):
    """An .osim whose mesh file is absent (OpenSim warns as it builds it) analysed at a posture file's frame:
    `anatomy --json` in a subprocess (OpenSim's C++ logger writes to file descriptor 1, which capsys does not see)
    prints one JSON document on stdout, which names the file, the frame and the model's identity; the warning goes
    to stderr."""
    import subprocess
    import sys

    osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
    from spinectl.anatomy.export_osim import export_osim
    from spinectl.model.config import load_preset

    exported = tmp_path / "chain.osim"
    export_osim(load_preset("wagner2012"), 0.03, 0.04, exported)
    built = osim.Model(str(exported))
    built.getBodySet().get(0).attachGeometry(osim.Mesh("absent_mesh.vtp"))
    built.finalizeConnections()
    meshed = tmp_path / "meshed.osim"
    built.printToXML(str(meshed))
    names = ["L5S1", "L4L5", "L3L4", "L2L3", "L1L2"]
    table = osim.TimeSeriesTable()
    table.setColumnLabels(osim.StdVectorString(names))
    for t in (0.0, 0.1):
        table.appendRow(t, osim.RowVector(np.full(5, 10 * t)))
    table.addTableMetaDataString("inDegrees", "yes")
    osim.STOFileAdapter.write(table, str(tmp_path / "ik.mot"))
    argv = ["anatomy", str(meshed), "--posture", str(tmp_path / "ik.mot"), "--time", "0.1", "--json"]
    result = subprocess.run([sys.executable, "-m", "spinectl", *argv], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    doc = json.loads(result.stdout)
    assert doc["posture_source"] == "ik.mot at t = 0.1 s (the time asked)"
    assert doc["model"]["engine"] == "OpenSim" and doc["model"]["versions"]["opensim"] == osim.__version__
    assert "absent_mesh.vtp" in result.stderr and "absent_mesh.vtp" not in result.stdout
