"""The Markdown report: honest about calibration, one table row per landmark."""

from __future__ import annotations

import dataclasses

import numpy as np
import xarray as xr

from spinectl.paper import landmarks, report, verdicts

AXIS = np.linspace(0.0, 0.08, 9)


def _measurements(axis=AXIS):
    e, lam = np.meshgrid(axis, axis, indexing="ij")
    ds = xr.Dataset(
        {"min_pcsa_cm2": (("E", "Lambda"), 60 - 100 * e), "counter_torque_norm_Nm": (("E", "Lambda"), 1e3 * e)},
        coords={"E": axis, "Lambda": axis},
    )
    half = ds.assign(min_pcsa_cm2=ds["min_pcsa_cm2"] / 2)
    return landmarks.measure(landmarks.Landmarks(ds, half, ds))


RUN = report.Run("preset default", "physical", "paper", 9, 1.0, ("landscapes.nc", "report.md"), 25e4)


def test_report_is_honest_and_complete():
    measured = _measurements()
    text = report.render(measured, RUN)
    assert "are **not** the calibrated preset" in text and "**calibrated**" not in text
    assert f"{sum(m.agrees for m in measured)} of {len(measured)} landmarks agree" in text
    rows = [line for line in text.splitlines() if line.startswith("| `")]
    assert len(rows) == len(landmarks.LANDMARKS)
    assert all(row.count("|") == 9 for row in rows)  # no stray pipes (e.g. ||CT||) breaking the table
    assert "`physical`" in text and "`paper`" in text and "[`report.md`](report.md)" in text


def test_report_of_the_calibrated_preset_gives_the_documented_verdicts():
    """Each row carries the verdict of docs/reproduction.md; a value that differs from the documented one
    is flagged (these constructed landscapes are not the preset)."""
    measured = _measurements()
    text = report.render(measured, dataclasses.replace(RUN, calibrated=True))
    assert "**calibrated**" in text
    for m in measured:
        row = next(line for line in text.splitlines() if line.startswith(f"| `{m.landmark.name}` |"))
        documented = verdicts.VERDICTS[m.landmark.name]
        assert documented.verdict in row
        consistent = documented.holds(m.value) and m.agrees == (documented.verdict == verdicts.REPRODUCED)
        assert ("documented for `wagner2012`" in row) == (not consistent)


def _verdict_of_row(row: str) -> str:
    """The verdict a row's verdict column states for this run (its first verdict)."""
    cell = row.split(" | ")[5].removeprefix("this run: ")
    return next(v for v in (verdicts.COMPROMISE, verdicts.STRUCTURAL, verdicts.REPRODUCED) if cell.startswith(v))


def test_no_verdict_contradicts_the_agreement_on_a_coarse_grid():
    """reproduce --points 3 .. 5 of the calibrated preset: each row's verdict follows from its own "agrees"
    (before: the documented verdicts of the 81 x 81 grid, e.g. "reproduced" beside a value that does not
    agree, or "cannot be reproduced" beside one that does), and the page says the grid is the condition."""
    for points in (3, 4, 5):
        measured = _measurements(np.linspace(0.0, 0.08, points))
        text = report.render(measured, dataclasses.replace(RUN, calibrated=True, points=points))
        assert f"This run's grid is {points} × {points}" in text
        for m in measured:
            row = next(line for line in text.splitlines() if line.startswith(f"| `{m.landmark.name}` |"))
            assert (_verdict_of_row(row) == verdicts.REPRODUCED) == m.agrees, row


def test_halving_names_the_closer_convention():
    """K = 15 halves the landscape exactly with the model's convention (constructed): it is named closer."""
    text = report.render(_measurements(), RUN)
    assert "0.5 of its K = 0 value with the model's `physical` convention" in text
    assert "`physical` comes closer" in text


def test_report_embeds_the_figures_it_links():
    """Every PNG (or SVG) of the run appears as a Markdown image and as a link; other files only as links."""
    files = ("landscapes.nc", "fig3_min_pcsa.png", "figS1_min_pcsa_K15.svg", "report.md")
    text = report.render(_measurements(), dataclasses.replace(RUN, files=files))
    for name in files[1:3]:
        assert f"![{name}]({name})" in text and f"[`{name}`]({name})" in text
    assert "![landscapes.nc]" not in text and "![report.md]" not in text
    assert "No figures were written." in report.render(_measurements(), RUN)


def test_report_names_the_grid_point_of_an_off_grid_landmark():
    """On a 9-point grid (1 cm steps) C on the ridge line, E = 8/1.7 = 4.71 cm, is read at E = 5 cm.

    The report's row says so, and the optimum (3, 4 cm: a grid point) is labelled as it is.
    """
    text = report.render(_measurements(), RUN)
    row = next(line for line in text.splitlines() if line.startswith("| `ct_D_over_C_ridge` |"))
    assert "nearest grid point: E = 5, Λ = 8 cm for E = 4.706, Λ = 8 cm" in row
    assert "E = 3, Λ = 4 cm: 30 N m" in text  # ‖CT‖ = 1000 E at E = 3 cm
    coarse = report.render(_measurements(np.linspace(0.0, 0.08, 11)), RUN)  # reproduce --points 11
    assert "E = 3.2, Λ = 4 cm (nearest grid point to E = 3, Λ = 4 cm): 32 N m" in coarse


def test_the_header_names_both_stiffnesses_and_the_table_its_own_grid():
    """The run covers K = 0 and 15 (and 15 in the other convention): the header says so, not only the model's K = 0
    (before: 'Parameters: preset wagner2012, K = 0 N m/rad, convention physical'). The preset table comes from a
    separate 41 x 41 grid (assumptions.TABLE_POINTS), not this run's 9 x 9: its columns say so."""
    from spinectl.model import config, source

    measured = _measurements()
    presets = (("wagner2012", 24.06, measured), ("wagner2012_mass_free", 10.2, measured))
    text = report.render(measured, dataclasses.replace(RUN, presets=presets, preset_points=41))
    assert (
        "Parameters: preset default; K = 0 and K = 15 N m/rad with the `physical` convention,\n"
        "K = 15 1/s² also with the `paper` convention." in text  # eq. 2 as printed reads K in 1/s^2
    )
    head = next(line for line in text.splitlines() if line.startswith("| landmark | paper | `wagner2012`"))
    assert "`wagner2012` (separate 41 × 41 grid)" in head and "`wagner2012_mass_free` (separate 41 × 41 grid)" in head
    assert "measured afresh on a separate 41 × 41 grid (not this run's landscapes)" in text
    model = config.load_preset("wagner2012")  # what reproduce passes as Run.preset: no K of its own
    assert source.origin(model) == "preset wagner2012" and "K = " not in source.origin(model)
    assert source.header(model) == "preset wagner2012, K = 0 N m/rad, convention physical"
    assert source.origin(config.set_parameter(model, "body.mass", 30.0)) == "preset wagner2012; overridden: body.mass"


def test_the_landmark_table_names_this_runs_grid():
    """report.md's landmark table is measured on this run's grid, its summary's preset table on another
    (41 x 41): ct_B_over_C_ridge read 2.04 in one and 2.05 in the other with nothing to say why."""
    text = report.render(_measurements(), RUN)
    head = next(line for line in text.splitlines() if line.startswith("| landmark | paper | spinectl"))
    assert f"| spinectl ({RUN.points} × {RUN.points} grid) |" in head


def test_a_config_path_in_the_report_is_text_not_markdown():
    """Run.preset names the --config path (source.origin): a path with a line break, a heading, a table row, HTML
    and a link adds no block, no row and no tag to report.md; it reads as the text (line breaks as \\n). Before,
    the path was written as it is: its '# Injected' line became a heading."""
    from spinectl._validate import printable

    path = "runs/a\n# Injected\n| x | y |\n<script>x</script> [l](http://e) `c` *e*.toml"
    text = report.render(_measurements(), dataclasses.replace(RUN, preset=f"preset default; config {path}"))
    assert not any(line.startswith(("# Injected", "| x |", "<script>")) for line in text.splitlines())
    line = next(line for line in text.splitlines() if line.startswith("Parameters:")).split("; K = 0 and")[0]
    for markup in "`*[]<>|#":
        assert all(line[i - 1] == "\\" for i, char in enumerate(line) if char == markup), markup
    assert printable(path).replace("\\", "") in line.replace("\\", "")  # the text itself, escapes aside


def test_the_report_opens_with_the_papers_question_and_the_answer():
    """The synthetic landscape's ‖CT‖ = 1000 E N m grows with E alone: at E = 3 cm it is 30 N m everywhere
    (not inside the 30 N m limit), and its least lies at the first Lambda of the column (0 cm, not about
    4 cm): the claim is not reproduced, and both landmarks are named."""
    text = report.render(_measurements(), RUN)
    head = text.split("## Read this first")[0]
    assert "## The paper's question and spinectl's answer" in head and "±30 N m" in head
    assert "**The paper's main claim is not reproduced with these parameters**" in head
    assert "(`optimum_lordosis` and `ct_optimum` disagree)" in head
    assert "‖CT‖ is 30 N m" in head and "at Λ = 0 cm" in head


def test_the_answer_says_reproduced_when_both_landmarks_agree():
    measured = [
        dataclasses.replace(m, agrees=True) if m.landmark.name in ("optimum_lordosis", "ct_optimum") else m
        for m in _measurements()
    ]
    text = report.answer(measured)
    assert "**The paper's main claim is reproduced:**" in text and "not reproduced" not in text


def test_the_count_says_which_grid_it_rests_on_and_k_is_glossed():
    """A newcomer read "11 of 22 landmarks agree" as the presets' count on their separate 41 × 41 grid (the same
    number there): this run's count now names this run's grid, and the presets' counts their own; "K = 15 1/s²"
    beside "K = 15 N m/rad" comes with one sentence on what K is (report.K_GLOSS)."""
    measured = _measurements()
    agree = sum(m.agrees for m in measured)
    run = dataclasses.replace(RUN, presets=(("wagner2012", 24.1, tuple(measured)),), preset_points=41)
    lines = report.render(measured, run).splitlines()
    first = next(i for i, line in enumerate(lines) if f"{agree} of {len(measured)}" in line)
    said = " ".join(lines[first : first + 2])
    assert f"measured on this run's {RUN.points} × {RUN.points}" in said and "separate 41 × 41 grid" in said
    head = report.render(measured, RUN).split("## The paper's question")[0]
    assert report.K_GLOSS in head and "1/s²" in head and report.K_GLOSS.startswith("K is the passive stiffness")
    assert "separate" not in report.render(measured, RUN).split("## Landmarks")[0]  # no presets, no other grid
