"""Verdicts as functions of the assumptions (docs/reproduction.md): which choice decides each landmark, measured."""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from spinectl.landscape import sweep
from spinectl.model import config
from spinectl.paper import assumptions, calibration, grid, landmarks, report, verdicts

DOCS = Path(__file__).resolve().parents[2] / "docs" / "reproduction.md"


@pytest.fixture(scope="module")
def rows():
    """The table of docs/reproduction.md, measured afresh (both presets, every choice; about half a minute)."""
    return assumptions.documented_rows()


def test_every_verdict_names_the_assumptions_that_decide_it(rows):
    """A documented verdict depends on exactly the choices whose alternative changes the landmark's agreement
    in the measured table, and says 'reproduced' exactly when the preset's own choices agree."""
    for row in rows:
        documented = verdicts.VERDICTS[row.name]
        assert documented.assumptions == row.deciders, row.name
        assert (documented.verdict == verdicts.REPRODUCED) == row.values["chosen"][1], row.name


def test_cannot_be_reproduced_only_with_a_proof():
    """'cannot be reproduced' links a section of docs/reproduction.md with its proof; no other verdict claims one."""
    headings = DOCS.read_text(encoding="utf-8")
    for v in verdicts.VERDICTS.values():
        if v.verdict == verdicts.STRUCTURAL:
            assert v.proof and re.search(rf"^\({re.escape(v.proof)}\)=$", headings, re.M), v.name
        else:
            assert not v.proof and verdicts.STRUCTURAL not in v.label


def test_the_coarse_table_has_the_agreements_of_the_paper_grid(rows, wagner2012_landscapes):
    """The table's 41-point grid (2 mm) gives every landmark the agreement it has on the paper's 81 x 81 grid."""
    both, other = wagner2012_landscapes
    fine = landmarks.measure(landmarks.Landmarks(both.sel(K=0.0), both.sel(K=grid.PAPER_STIFFNESS), other))
    assert [m.agrees for m in fine] == [row.values["chosen"][1] for row in rows]


def test_one_side_of_a_pair_is_half_its_pcsa():
    """Paired activation: the ventral muscles of the three pairs carry half of the minimum PCSA (the solver's
    per-muscle PCSA, a second source), which is what one_side reports; ratios do not change."""
    preset = config.load_preset(verdicts.PRESET)
    axis = grid.paper_axis(5)
    land = sweep.sweep(preset, axis, axis, progress=False)
    names = land["muscle"].values
    ventral = land["pcsa_cm2"].sel(muscle=[m for m in names if m.endswith("ventral")]).sum("muscle").values
    dorsal = land["pcsa_cm2"].sel(muscle=[m for m in names if m.endswith("dorsal")]).sum("muscle").values
    half = land["min_pcsa_cm2"].values / 2  # the chosen activation lies within ct_tolerance of the minimum
    np.testing.assert_array_equal(ventral, dorsal)
    band = (1 + preset.optimisation.ct_tolerance) * (1 + 1e-9)  # the chosen total may sit on the band's edge
    assert np.all(ventral >= half * (1 - 1e-9)) and np.all(ventral <= half * band)
    found = landmarks.measure(landmarks.Landmarks(land))
    halved = {m.landmark.name: m.value for m in assumptions.one_side(found)}
    for m in found:
        expected = m.value / 2 if m.landmark.name in assumptions.PCSA_LANDMARKS else m.value
        assert halved[m.landmark.name] == pytest.approx(expected, nan_ok=True)


def test_c_ratio_families():
    """The three readings of C of one ratio belong together; other landmarks read no C."""
    reading, family = assumptions.c_ratio_family("ct_D_over_C_text")
    assert reading == "interior" and family == {
        "corner": "ct_D_over_C",
        "interior": "ct_D_over_C_text",
        "ridge line": "ct_D_over_C_ridge",
    }
    assert assumptions.c_ratio_family("ct_B_over_C")[0] == "corner"
    assert assumptions.c_ratio_family("ct_B") is None and assumptions.c_ratio_family("ridge_over_B") is None


@pytest.mark.parametrize("name", assumptions.CALIBRATED_PRESETS)
def test_each_shipped_preset_reproduces_the_count_its_header_and_the_report_state(name):
    """The count in each preset's header (written by spinectl calibrate on the paper's grid) is the count
    measured afresh, and it is what the report of spinectl reproduce states, with the preset's mass."""
    presets = assumptions.calibrated_measurements()
    mass, found = next((m, f) for n, m, f in presets if n == name)
    agree, total = sum(m.agrees for m in found), len(found)
    header = resources.files("spinectl.presets").joinpath(f"{name}.toml").read_text(encoding="utf-8")
    assert f"{agree} of {total} landmarks agree" in header.split("\n[body]")[0]
    assert mass == config.load_preset(name).body.mass
    run = report.Run("preset", "physical", "paper", 9, 1.0, (), 25e4, True, presets, 41)
    text = report.render(landmarks.measure(calibration.coarse_landmarks(config.load_preset(name), 9)), run)
    assert f"`{name}` (m = {mass:.3g} kg" in text and f"**{agree} of {total}**" in text
    rows = [line for line in text.splitlines() if line.startswith("| `") and line.count("✓") + line.count("✗") == 2]
    assert len(rows) == len(landmarks.LANDMARKS)


def test_the_table_has_a_row_per_landmark_and_a_count_per_column(rows):
    """docs/reproduction.md's table: one row per landmark whose last cell names its deciders, and per column
    the number of ✓, which for wagner2012's own choices is the count of its agreeing landmarks."""
    table = assumptions.markdown(rows)
    lines = [line for line in table.splitlines() if line.startswith("| `")]
    assert len(lines) == len(landmarks.LANDMARKS)
    for line, row in zip(lines, rows, strict=True):
        words = [verdicts.ASSUMPTION_WORDS[d] for d in row.deciders] or ["none of these"]
        assert line.endswith(f"| {', '.join(words)} |")
    total = sum(row.values["chosen"][1] for row in rows)
    assert f"**{total} of {len(rows)}**" in table.splitlines()[-1]


def test_every_assumption_has_its_words_and_its_alternative():
    """The verdicts' words and the table's columns name the same assumptions, in the same order."""
    assert list(assumptions.ALTERNATIVES) == list(verdicts.ASSUMPTION_WORDS)
    assert all(set(v.assumptions) <= set(verdicts.ASSUMPTION_WORDS) for v in verdicts.VERDICTS.values())
