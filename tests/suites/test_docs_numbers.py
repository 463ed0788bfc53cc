"""The docs' numbers that a command produces are generated at the build, never typed.

- the ``published-model`` directive (docs/_ext/spinectl_docs/published.py), built in a small Sphinx site:
  its row is what ``spinectl anatomy --json`` prints for the same model and mapping;
- the ``{measured}`` values and generated tables of docs/anatomy.md are the command's own numbers;
- a scan of docs/*.md and README.md for numbers typed beside the words of a command's output (the patterns
  of the numbers that were typed and are now generated), with an allow-list of citations, inputs and
  history, so that a new typed output fails here.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
SHARED = Path("/work/shared/models")
POSE2SIM = SHARED / "pose2sim-beaucage-gauvreau" / "Model_Pose2Sim_muscles_flex.osim"
POSE2SIM_MAPPING = """[bodies]
pelvis = ["pelvis"]
vertebrae = ["lumbar5", "lumbar4", "lumbar3", "lumbar2", "lumbar1"]
thorax = ["torso"]

[planes]
sagittal = ["L5_S1_Flex_Ext", "L4_L5_Flex_Ext", "L3_L4_Flex_Ext", "L2_L3_Flex_Ext", "L1_L2_Flex_Ext", "L1_T12_Flex_Ext"]
"""

SITE_CONF = f"""
import sys
sys.path.insert(0, {str(DOCS / "_ext")!r})
sys.path.insert(0, {str(ROOT)!r})
extensions = ["myst_parser"]
exclude_patterns = ["_build"]


def setup(app):  # the directive alone, without spinectl_docs' generated pages
    from spinectl_docs import published

    app.add_directive("published-model", published.PublishedModel)
"""


def build_site(folder: Path, page: str, files: dict | None = None) -> subprocess.CompletedProcess:
    """A one-page Sphinx site (MyST) holding ``page``, built as docutils XML with warnings as errors."""
    pytest.importorskip("myst_parser", reason="the docs extra is not installed")
    (folder / "conf.py").write_text(SITE_CONF)
    (folder / "index.md").write_text(page)
    for name, text in (files or {}).items():
        (folder / name).write_text(text)
    command = [sys.executable, "-m", "sphinx", "-W", "-q", "-b", "xml", str(folder), str(folder / "_build")]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)


def page_text(folder: Path) -> str:
    """The built page's paragraphs (table cells whole, whatever their width), one space between words."""
    from xml.etree import ElementTree

    tree = ElementTree.parse(folder / "_build" / "index.xml")
    return " | ".join(" ".join("".join(p.itertext()).split()) for p in tree.iter("paragraph"))


def anatomy_json(*args: str) -> dict:
    """``spinectl anatomy ... --json``'s document: the command's own numbers, the directive's referee."""
    done = subprocess.run(
        [sys.executable, "-m", "spinectl", "anatomy", *args, "--json"], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def minus(v: float) -> str:
    return f"{v:.4g}".replace("-", "\u2212")


def test_published_model_directive_gives_spinectl_anatomys_verdicts_on_myotorso(tmp_path):
    """The directive on MyoTorso, its mapping inline and as a file (relative to the docs): the row's muscle
    counts, global rank, self-stable joints and their range, the free chain's unstable modes and the constrained
    chain's eigenvalue are those `spinectl anatomy --json` prints for the model (the command's own numbers); a
    model file absent at the build gives a sentence instead, and a mapping the model refuses fails the build."""
    pytest.importorskip("mujoco", reason="the anatomy extra is not installed")
    mapping = (ROOT / "spinectl" / "anatomy" / "mappings" / "myotorso.toml").read_text()
    page = (
        "# Models\n\n```{published-model} myotorso\n:name: MyoTorso inline\n:source: myo-sim\n:licence: Apache-2.0\n\n"
        + mapping
        + "```\n\n```{published-model} myotorso\n:name: MyoTorso file\n:mapping: maps/torso.toml\n```\n\n"
        "```{published-model} models/absent.osim\n:name: Absent\n:source: nowhere\n:licence: MIT\n```\n"
    )
    (tmp_path / "maps").mkdir()
    done = build_site(tmp_path, page, {"maps/torso.toml": mapping})
    assert done.returncode == 0, done.stderr
    doc = anatomy_json("myotorso")
    muscles = ", ".join(str(len(doc["muscles"][c])) for c in ("global", "local", "between", "non-lumbar"))
    restoring = doc["restoring_stiffness_Nm_per_rad"]
    eig, con = doc["eigenvalues"], doc["constrained"]["eigenvalues"]
    expected = [
        muscles,
        f"{doc['global_rank']} of {len(eig)}",
        f"{sum(doc['joint_self_stable'])} of {len(restoring)} ({minus(restoring[0])} … {minus(restoring[-1])} N m/rad)",
        f"unstable, {sum(v <= 0 for v in eig)} of {len(eig)} modes unstable ({minus(eig[0])} … {minus(eig[-1])})",
        f"unstable ({minus(con[0])} N m/rad, 1 coordinate(s))",
    ]
    flat = page_text(tmp_path)
    for name in ("MyoTorso inline", "MyoTorso file"):
        row = flat[flat.index(name) :]
        for cell in expected:
            assert f"| {cell} |" in row[:600], (name, cell)
    assert "Absent (nowhere, MIT): not analysed at this build, its file is not here" in flat

    bad = mapping.replace('"L4_L5_FE"', '"L4_L5_XX"', 1)
    (tmp_path / "bad").mkdir()
    failed = build_site(tmp_path / "bad", "# Bad\n\n```{published-model} myotorso\n\n" + bad + "```\n")
    assert failed.returncode != 0 and "L4_L5_XX" in failed.stderr


@pytest.mark.skipif(not POSE2SIM.is_file(), reason="the shared downloaded models (/work/shared/models) are absent")
def test_published_model_directive_on_the_pose2sim_model(tmp_path):
    """The Pose2Sim model (OpenSim) with its mapping inline, at its own controls: the row's rank and verdicts are
    `spinectl anatomy MODEL --mapping M --json`'s."""
    pytest.importorskip("opensim", reason="the opensim extra is not installed")
    page = f"# Pose2Sim\n\n```{{published-model}} {POSE2SIM}\n:name: Pose2Sim\n:licence: BSD-3-Clause\n\n{POSE2SIM_MAPPING}```\n"
    done = build_site(tmp_path, page)
    assert done.returncode == 0, done.stderr
    (tmp_path / "pose2sim.toml").write_text(POSE2SIM_MAPPING)
    doc = anatomy_json(str(POSE2SIM), "--mapping", str(tmp_path / "pose2sim.toml"))
    flat = page_text(tmp_path)
    eig = doc["eigenvalues"]
    assert f"{doc['global_rank']} of {len(eig)}" in flat
    assert f"{sum(v <= 0 for v in eig)} of {len(eig)} modes unstable ({minus(eig[0])} … {minus(eig[-1])})" in flat


def test_anatomy_pages_numbers_are_spinectl_anatomys():
    """docs/anatomy.md's generated verdict table and its remedy are what `spinectl anatomy` prints: the row at
    activation 0 holds the JSON's -K_jj and eigenvalues of -K, and the remedy value is the JSON's
    feasible_from_joint_stiffness_Nm_per_rad of `--optimise` (MyoTorso's chain criterion is infeasible
    without added stiffness)."""
    pytest.importorskip("mujoco", reason="the anatomy extra is not installed")
    from spinectl_docs import anatomy
    from spinectl_docs.values import text_of

    doc = anatomy_json("--activation", "0")
    row = anatomy.verdict_table().splitlines()[2]
    assert row.startswith("| 0 |")
    for v in doc["restoring_stiffness_Nm_per_rad"] + doc["eigenvalues"]:
        assert f"{abs(v):.1f}" in row
    optimum = anatomy_json("--optimise")
    assert optimum["infeasible_constraint"] == "stability"
    assert text_of("anatomy.remedy") == f"{optimum['feasible_from_joint_stiffness_Nm_per_rad']:.3g}"
    assert np.isclose(float(text_of("anatomy.remedy")), optimum["feasible_from_joint_stiffness_Nm_per_rad"], rtol=2e-3)
