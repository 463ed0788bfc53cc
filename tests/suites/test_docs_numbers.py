"""The docs' numbers that a command produces are generated at the build, never typed.

- the ``published-model`` directive (docs/_ext/spinectl_docs/published.py), built in a small Sphinx site:
  its row is what ``spinectl anatomy --json`` prints for the same model and mapping;
- the ``{measured}`` values and generated tables of docs/anatomy.md are the command's own numbers;
- docs/reflex.md's generated design lines (joint by joint and the chain over every reflex's gains) are lines
  that ``spinectl design`` prints;
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
sys.path.insert(0, str(ROOT / "tests" / "anatomy"))
from shared_models import ABSENT, SHARED_MODELS  # noqa: E402 (tests/anatomy/shared_models.py)

SHARED = SHARED_MODELS

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


def setup(app):  # the directive and the role alone, without spinectl_docs' generated pages
    from spinectl_docs import errata, published, values

    app.add_directive("published-model", published.PublishedModel)
    app.add_role("measured", values.measured_role)
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


@pytest.mark.skipif(not POSE2SIM.is_file(), reason=ABSENT)
def test_published_model_directive_on_the_pose2sim_model(tmp_path):
    """The Pose2Sim model (OpenSim) named in the published models' folder (``shared:``), its mapping inline, at its
    own controls: the row's rank and verdicts are `spinectl anatomy MODEL --mapping M --json`'s."""
    pytest.importorskip("opensim", reason="the opensim extra is not installed")
    page = (
        "# Pose2Sim\n\n```{published-model} shared:pose2sim-beaucage-gauvreau/Model_Pose2Sim_muscles_flex.osim\n"
        ":name: Pose2Sim\n:licence: BSD-3-Clause\n\n"
        f"{POSE2SIM_MAPPING}```\n"
    )
    done = build_site(tmp_path, page)
    assert done.returncode == 0, done.stderr
    (tmp_path / "pose2sim.toml").write_text(POSE2SIM_MAPPING)
    doc = anatomy_json(str(POSE2SIM), "--mapping", str(tmp_path / "pose2sim.toml"))
    flat = page_text(tmp_path)
    eig = doc["eigenvalues"]
    assert f"{doc['global_rank']} of {len(eig)}" in flat
    assert f"{sum(v <= 0 for v in eig)} of {len(eig)} modes unstable ({minus(eig[0])} … {minus(eig[-1])})" in flat


def test_measured_role_puts_the_value_computed_now_and_refuses_an_unknown_name(tmp_path):
    """{measured}`errata.rate_l1l2` renders as sqrt(g/r_y) of L1L2 with r_y = K_g/(m g), K_g the diagonal of the
    chain's gravity stiffness at A (`wagner2012`), to two decimals; a name no generator registered fails the build
    (-W) naming it."""
    from spinectl.model.chain import chain_coefficients
    from spinectl.model.config import load_preset

    model = load_preset("wagner2012")
    k_g = chain_coefficients(model, 0.0, 0.0).gravity_stiffness[0, 0]
    g, m = model.body.gravity, model.body.mass
    done = build_site(tmp_path, "# Rates\n\nL1L2 grows at {measured}`errata.rate_l1l2` 1/s.\n")
    assert done.returncode == 0, done.stderr
    assert f"L1L2 grows at {(g / (k_g / (m * g))) ** 0.5:.2f} 1/s." in page_text(tmp_path)
    (tmp_path / "bad").mkdir()
    failed = build_site(tmp_path / "bad", "# Bad\n\n{measured}`errata.no_such_value`\n")
    assert failed.returncode != 0 and "unknown value 'errata.no_such_value'" in failed.stderr


def test_a_value_whose_generator_imports_a_moved_name_fails_and_a_missing_extra_is_a_note(monkeypatch):
    """A value whose generator imports a name spinectl no longer has (as anatomy.md's `least_joint_stiffness` after
    it moved to spinectl.anatomy.remedy) raises at the build instead of printing "not installed"; an extra's
    package that is absent (mujoco, or a module of it) gives the page's note."""
    from spinectl_docs import values

    def moved():
        from spinectl.anatomy.optimum import no_such_name  # noqa: F401

    def absent():
        raise ModuleNotFoundError("No module named 'mujoco'", name="mujoco")

    monkeypatch.setitem(values.VALUES, "test.moved", (moved, False))
    monkeypatch.setitem(values.VALUES, "test.absent", (absent, False))
    with pytest.raises(ImportError, match="no_such_name"):
        values.text_of("test.moved")
    assert values.text_of("test.absent") == "(not computed: mujoco is not installed at this build)"


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


def spinectl_design(*args: str) -> str:
    """What ``spinectl design ... --E 0.03 --Lambda 0.04`` prints (the command's own output, the referee)."""
    done = subprocess.run(
        [sys.executable, "-m", "spinectl", "design", *args, "--E", "0.03", "--Lambda", "0.04"],
        capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout


def block_lines(block: str) -> list[str]:
    """The lines of a generated ``text`` block that the command printed (not the fence, the command, the ellipsis)."""
    return [line for line in block.splitlines() if not line.startswith(("```", "$ ", "..."))]


def test_reflex_pages_joint_searched_lines_and_boundary_are_spinectl_designs():
    """docs/reflex.md's generated joint-by-joint searched lines at 120 ms (``wagner2012``, (3, 4) cm) are lines of
    the table `spinectl design --delay 0.12` prints, and the boundary sentence's margin at 120 ms is the JSON's
    chain ``delay_margin_s`` of the same command, in ms to four decimals."""
    from spinectl_docs import searched
    from spinectl_docs.values import text_of

    printed = spinectl_design("--delay", "0.12").splitlines()
    lines = block_lines(searched.joint_search_table())
    assert lines[0].startswith("over any PD gains per segment") and len(lines) == 4
    for line in lines:
        assert line in printed, line
    margin = json.loads(spinectl_design("--delay", "0.12", "--json"))["chain"]["delay_margin_s"]
    assert text_of("reflex.boundary_margins").endswith(f"and {1e3 * margin:.4f} ms at 120 ms")


@pytest.mark.slow
def test_reflex_pages_chain_searched_lines_are_spinectl_design_gains_search():
    """docs/reflex.md's generated lines of the chain's answer over every diagonal PD reflex at 40 ms are lines of
    the table `spinectl design --delay 0.04 --gains search` prints (the seeded search: the same lines), and the
    rule's f the page quotes is the table's (``0.5617 x the least for static stability`` when written)."""
    from spinectl_docs import searched
    from spinectl_docs.values import text_of

    printed = spinectl_design("--delay", "0.04", "--gains", "search").splitlines()
    lines = block_lines(searched.chain_search_table())
    assert lines[0].startswith("over diagonal PD gains (the rule's shape") and len(lines) == 5
    for line in lines:
        assert line in printed, line
    assert any(f"({text_of('reflex.rule_f_40')} x the least for static stability" in line for line in printed)


# --- typed outputs ---------------------------------------------------------------------------------------------

OUTPUT_PATTERNS = {
    "a signed or decimal number with an output's unit": re.compile(
        r"(?:[−\-+]\d+(?:\.\d+)?|\d+\.\d+)\s*(?:N m/rad|N m s/rad|1/s)\b"
    ),
    "a cost": re.compile(r"\bcosts? (?:of )?\d+\.\d+"),
    "an eigenvalue": re.compile(r"\beigenvalues?(?: of \S+)? (?:is |at )?[−\-+]?\d+\.\d+"),
    "a delay margin": re.compile(r"\b\d+(?:\.\d+)? ms of margin|\bmargin (?:of )?\d+\.\d+ ms"),
    "a rank": re.compile(r"\brank [1-9]\d*\b"),
    "singular values": re.compile(r"\bsingular values? \d"),
    "a table cell of numbers": re.compile(r"\|\s*[−\-+]?\d+\.\d+(?:,\s*[−\-+]?\d+\.\d+)+"),
    "a ratio's range": re.compile(r"\b\d+\.\d+ to \d+\.\d+ times\b"),
    "a signed value of an engine": re.compile(r"[−\-+]\d+(?:\.\d+)? in (?:OpenSim|spinectl|MuJoCo)\b"),
    "a fraction of k*": re.compile(r"\b\d+\.\d+ (?:times )?k\*"),
    "a preset's margin": re.compile(r"\b\d+\.\d+ ms,? \(`(?:default|wagner2012)`"),
    "a margin beside its lagless one": re.compile(r"\b\d+\.\d+ s \(\d+\.\d+\)"),
    "a largest delay met": re.compile(r"\blargest\s+delay\s+met:? \d+(?:\.\d+)? ms"),
}
"""The rule: what a command prints, typed beside the words that name it. The patterns of the numbers that were
typed in docs/anatomy.md (-K_jj and eigenvalues in N m/rad, rates in 1/s, costs, the rank and singular values,
"feasible from 40.2 N m/rad") and of those still typed elsewhere (interchange.md's "1.12 to 1.18 times" and
"+39.0 in OpenSim", reflex.md's "0.28 k*", chain.md's "0.909 ms (`default`)", reflex.md's margins tables'
"0.057 s (0.101)"); an integer without a sign before a unit is an input (``--joint-stiffness 50``,
``K = 10 N m/rad``) and is not matched."""

ALLOWED = {
    # inputs, definitions and citations: not a command's output
    ("anatomy.md", "0.5 N m s/rad"): "MuJoCo's joint damping in MyoTorso's file, an input",
    ("anatomy.md", "−131.0 N m/rad"): "history: what spinectl read before the abdomen left the rhythm",
    ("anatomy.md", "cost of 11.19"): "history: the same",
    ("anatomy.md", "cost 21.37"): "the benchmark's run (Speed), a measurement of time, not an output",
    ("interchange.md", "costs 0.21"): "the benchmark's run (benchmarks/bench_osim_replay.py), wall time",
    ("chain.md", "+258 N m/rad"): "a quotation of the issue that asked for the page (its words, not a run)",
    ("chain.md", "0.5 N m/rad"): "a range of a derivation's per-cm² stiffness, explained in the text",
    ("chain.md", "0.01 N m/rad"): "the bisection's tolerance, an input",
    ("chain.md", "0.1 N m/rad"): "the margin mu, an input",
    ("chain.md", "0.2 N m/rad"): "the figure's layout: two values 0.2 apart",
    ("interchange.md", "0.1 N m/rad"): "the margin mu, an input",
    ("errata.md", "0.01 N m s/rad"): "an input of the erratum's example",
    ("robustness.md", "*"): "bad inputs and the messages they get (typed on purpose: inputs)",
    ("optimisation.md", "rank 1"): "a rank theorem (a property of the formulation, not a run)",
    ("optimisation.md", "rank 3"): "a rank theorem",
    ("chain.md", "rank 2"): "a rank theorem (rank 2 where the CoRs are collinear)",
    ("interchange.md", "rank 3"): "the rank theorem, read off OpenSim's arms by the test",
    ("reflex.md", "−25 N m s/rad"): "a bound of the gain search, an input",
    ("reflex.md", "3.9 N m s/rad"): "the issue's quoted case (L1L2 at k_d = 8 instead of 3.9), an input",
}
"""(page, the matched text) -> why it stays typed; ``*`` allows a whole page."""


def typed_outputs() -> list[tuple[str, int, str, str]]:
    """Every match of :data:`OUTPUT_PATTERNS` in docs/*.md and README.md: (page, line, text, pattern)."""
    found = []
    for page in [*sorted(DOCS.glob("*.md")), ROOT / "README.md"]:
        for number, line in enumerate(page.read_text().splitlines(), 1):
            for what, pattern in OUTPUT_PATTERNS.items():
                found += [(page.name, number, m.group(0), what) for m in pattern.finditer(line)]
    return found


def test_no_typed_numbers_beside_a_commands_output_words():
    """docs/*.md and README.md hold no number typed beside the words of a command's output (OUTPUT_PATTERNS)
    but those ALLOWED with a reason; each allowed entry still matches (the list does not outlive its text)."""
    found = typed_outputs()
    typed = [f"{p}:{n}: {t!r} ({w})" for p, n, t, w in found if (p, t) not in ALLOWED and (p, "*") not in ALLOWED]
    assert not typed, "numbers a command produces, typed by hand (generate them: docs/_ext/spinectl_docs):\n" + (
        "\n".join(typed)
    )
    matched = {(p, t) for p, _, t, _ in found} | {(p, "*") for p, _, _, _ in found}
    assert not set(ALLOWED) - matched, f"allowed but no longer in the docs: {sorted(set(ALLOWED) - matched)}"


def test_the_typed_number_scan_finds_what_it_is_for(tmp_path, monkeypatch):
    """The scan flags the typed outputs it was written for (anatomy.md's former sentences and table cells)
    and leaves inputs and the generated role alone."""
    (tmp_path / "x.md").write_text(
        "from 40.2 N m/rad at every joint one does\n| 0 | −81.4, 62.9 | −126.5, +316.6 |\n"
        "rank 3, singular values 0.451\nthe chain optimum costs 14.98\n"
        "--joint-stiffness 50 and K = 10 N m/rad\nfrom {measured}`anatomy.remedy` N m/rad\n"
        "D is 1.12 to 1.18 times the chain's, L1L2-L2L3 +39.0 in OpenSim\nwith T_a = 50 ms 0.28 k* at 5 ms\n"
        "found 0.909 ms (`default`) and 2.90 ms (`wagner2012`)\n10 times below 100 ms, 0 k* at 0 ms\n"
        "| 0.5 | 0.195 s (0.243) | unbounded |\nT_a = 0.1 s (a lag of 0.1 s) and 3.7 s of CPU\n"
        "no activation (largest delay met 26.36 ms)\n"
    )
    monkeypatch.setattr(sys.modules[__name__], "DOCS", tmp_path)
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "README.md").write_text("")
    lines = sorted({(n, w) for _, n, _, w in typed_outputs()})
    assert [n for n, _ in lines] == [1, 2, 3, 3, 4, 7, 7, 8, 9, 11, 13]


def test_reflex_pages_design_against_k_is_spinectl_design_at_that_k():
    """docs/reflex.md's design against K (bends.py calls the chain's design alone, not the command): at K = 40
    N m/rad the global PCSA, the local stiffness, f and k* the page quotes (the second of each list) are the
    JSON's chain of `spinectl design --delay 0.12 --K 40` (global_pcsa_cm2, the sum of
    local_stiffness_Nm_per_rad, local_stiffness_fraction, the sum of least_static_local_stiffness_Nm_per_rad)."""
    from spinectl_docs.values import text_of

    chain = json.loads(spinectl_design("--delay", "0.12", "--K", "40", "--json"))["chain"]
    second = {
        name: re.split(r", | and ", text_of(f"reflex.{name}"))[1]
        for name in ("k_pcsa", "k_local", "k_fraction", "k_static")
    }
    assert second == {
        "k_pcsa": f"{chain['global_pcsa_cm2']:.2f}",
        "k_local": f"{sum(chain['local_stiffness_Nm_per_rad']):.0f}",
        "k_fraction": f"{chain['local_stiffness_fraction']:.3f}",
        "k_static": f"{sum(chain['least_static_local_stiffness_Nm_per_rad']):.0f}",
    }


def test_reflex_pages_stiff_passive_case_is_spinectl_designs_table():
    """docs/reflex.md's case where the rule has no design (`design --delay 0.1 --K 200`; reflex.py calls the
    library's answer): the largest delay met and the rule's k_d range the page quotes are the command's own
    line ('the largest delay met: ...') and its 'k_d 22.3-35.2 N m s/rad' rounded to integers."""
    from spinectl_docs.values import text_of

    printed = spinectl_design("--delay", "0.1", "--K", "200")
    assert f"the largest delay met: {text_of('reflex.stiff_largest_delay')}" in printed
    low, high = re.search(r"k_d (\d+\.\d+)-(\d+\.\d+) N m s/rad", printed).groups()
    assert text_of("reflex.stiff_rule_kd") == f"{float(low):.0f}\u2013{float(high):.0f}"


def test_reproduction_pages_counter_torque_is_offset_times_force():
    """docs/reproduction.md's ‖CT‖ = ‖x‖ F at (3, 4) cm: the counter torques `spinectl stability --E 0.03 --Lambda
    0.04` computes (its optimum's CT_k) are -x_k F, x_k the CoRs' offsets (geometry.cor_positions) and F the
    page's generated force, to its printed rounding; the page's ‖x‖ is that of those offsets."""
    from spinectl_docs.values import text_of

    from spinectl.model.config import load_preset
    from spinectl.model.geometry import cor_positions
    from spinectl.optimise.stabilising import stability_at

    model = load_preset("wagner2012")
    ct = stability_at(model, 0.03, 0.04).counter_torque
    x = cor_positions(0.03, 0.04, model.geometry)[:, 0]
    force = float(text_of("reproduction.optimum_force"))
    assert np.allclose(np.abs(ct), np.abs(x) * force, rtol=1e-3, atol=0)
    assert text_of("reproduction.optimum_offset") == f"{100 * np.linalg.norm(x):.1f}"


def test_reproduction_pages_ratios_are_the_documented_landmarks():
    """docs/reproduction.md's ratios of the paper's 81 x 81 grid (3.4346 and 2.038 when written) round to the
    landmark values of spinectl.paper.verdicts (which tests/paper/test_verdicts.py checks against a fresh
    measurement), and its ‖x‖ ratios times F's ratio give those counter-torque ratios (‖CT‖ = ‖x‖ F)."""
    from spinectl_docs import reproduction
    from spinectl_docs.values import text_of

    from spinectl.paper.verdicts import VERDICTS

    assert float(text_of("reproduction.grid_D_over_C_text")) == pytest.approx(VERDICTS["ct_D_over_C_text"].value,
                                                                               abs=0.005)  # fmt: skip
    assert float(text_of("reproduction.grid_B_over_C_ridge")) == pytest.approx(VERDICTS["ct_B_over_C_ridge"].value,
                                                                                abs=0.005)  # fmt: skip
    b, c = (float(f) for f in text_of("reproduction.force_B_over_C_ridge").split("/"))
    ratio = reproduction.offset_norm((0.08, 0.0)) / reproduction.offset_norm((0.047, 0.08))  # the grid's points
    assert ratio * b / c == pytest.approx(float(text_of("reproduction.grid_B_over_C_ridge")), rel=2e-3)


def test_errata_pages_removed_fractions_are_the_models_stiffness_ratios():
    """docs/errata.md's table of the fraction of gravity stiffness that K = 15 N m/rad removes at A (errata.py
    writes K r/g and K/(m g r) in closed form) is the model's own passive over gravity stiffness
    (segment_coefficients of `wagner2012` with K = 15 in each convention), to the table's two decimals; and the
    header's loss pair the page quotes is the preset's own convention first."""
    from spinectl_docs.values import text_of

    from spinectl.model.checks import checked_coefficients
    from spinectl.model.config import load_preset
    from spinectl.paper import grid

    model = load_preset("wagner2012")
    for convention in ("paper", "physical"):
        c = checked_coefficients(grid.with_stiffness(model, grid.PAPER_STIFFNESS, convention), 0.0, 0.0)
        shown = [float(text_of(f"errata.{convention}_{k}")) for k in range(5)]
        np.testing.assert_allclose(shown, np.abs(c.passive_stiffness / c.gravity_stiffness), atol=0.005 + 1e-9)
    own, other = (float(v) for v in text_of("reproduction.wagner_loss_pair").split(" against "))
    assert own < other and model.passive.convention == "physical"


def test_atlas_pages_angle_range_is_what_the_command_refuses_beyond():
    """docs/atlas.md's '±10 cm is ±119.2°' (atlas.py converts the model's Lambda range) is the range that
    `spinectl stability --lordosis-angle` states when it refuses an angle beyond it (its own message)."""
    from spinectl_docs.values import text_of

    angle = float(re.search(r"±(\d+\.\d+)°", text_of("atlas.range_angles")).group(1))
    done = subprocess.run(
        [sys.executable, "-m", "spinectl", "stability", "--E", "0", "--lordosis-angle", "150"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 2
    low, high = (float(v) for v in re.search(r"\[(-?\d+\.\d+), (\d+\.\d+)\] deg", done.stderr).groups())
    assert (round(low, 1), round(high, 1)) == (-angle, angle)


def test_cli_pages_margin_is_spinectl_margins_json():
    """docs/cli.md's L1L2 margin (reproduction.py calls margins_report) is `spinectl margins --json`'s first
    segment's delay_margin_s to the page's four decimals, and its last segment's margin is null, 'unbounded'."""
    from spinectl_docs.values import text_of

    done = subprocess.run([sys.executable, "-m", "spinectl", "margins", "--json"], capture_output=True, text=True,
                          timeout=300)  # fmt: skip
    first, last = json.loads(done.stdout)["segments"][0], json.loads(done.stdout)["segments"][-1]
    assert text_of("cli.l1l2_margin") == f"{first['delay_margin_s']:.4f}"
    assert last["delay_margin_s"] is None and last["delay_margin_s_reason"] == "unbounded"


def test_interchange_pages_causes_together_are_opensims_own_k():
    """docs/interchange.md's causes of Millard's instability (millard.py puts Millard's activation floor, curve
    value and slope into spinectl's chain one at a time): all three together give OpenSim's own linearised K of
    the Millard export with the least local stiffness to 1e-6 of its largest entry (the derivation that
    tests/anatomy/test_osim_replay.py checks), so each alone is that model's, not a guess."""
    pytest.importorskip("opensim", reason="the opensim extra is not installed")
    from spinectl_docs import interchange, millard

    together, opensim_k = millard.chain_with(millard.CAUSES), interchange.opensim_k("millard", True)
    assert np.max(np.abs(together - opensim_k)) <= 1e-6 * np.max(np.abs(opensim_k))
    assert millard.least(millard.chain_with(())) == pytest.approx(
        millard.least(interchange.exported("osim", "millard", True)[1].stiffness)
    )


def test_atlas_pages_shares_and_indices_are_what_the_command_prints(tmp_path):
    """docs/atlas.md's shares, Sobol' rankings and E < Lambda share (atlas_run.py, the library in-process) are
    what `spinectl atlas examples/atlas.toml --json` prints and writes (draws.npz) in a subprocess."""
    from spinectl_docs import atlas_run
    from spinectl_docs.values import text_of

    done = subprocess.run(
        [sys.executable, "-m", "spinectl", "atlas", str(ROOT / "examples" / "atlas.toml"), "--out", str(tmp_path),
         "--json"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    printed = json.loads(done.stdout)
    for verdict, v in printed["probabilities"].items():
        if verdict == "stabilisable_joint_by_joint":
            continue  # p = 1: shown as '100 %'
        shown = [float(x) for x in re.findall(r"\d+\.\d", text_of(f"atlas.share.{verdict}"))]
        np.testing.assert_allclose(shown, [100 * v["p"], 100 * v["low"], 100 * v["high"]], atol=0.05 + 1e-9)
    table = printed["sobol"]["min_pcsa_cm2"]
    first = max(table, key=lambda name: table[name]["ST"])
    assert text_of("atlas.rank.min_pcsa_cm2").startswith(f"{atlas_run.WORDS[first]} (ST {table[first]['ST']:.2f}")
    assert f"{printed['nonfinite']['spine_delay_margin_s']} draws" in text_of("atlas.margin_nonfinite")
    draws = np.load(tmp_path / "draws.npz")
    step = len(atlas_run.WORDS) + 2  # Saltelli's A and B rows: the first and last of each block of D + 2
    rows = np.sort(np.concatenate([np.arange(0, draws["eccentricity_m"].size, step) + k for k in (0, step - 1)]))
    behind = 100 * np.mean(draws["eccentricity_m"][rows] < draws["lordosis_m"][rows])
    assert text_of("atlas.behind_apex") == f"{behind:.0f} %"
