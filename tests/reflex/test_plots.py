"""Bode, Nyquist and time-response figures: drawn and returned, written only by the save step."""

from __future__ import annotations

import dataclasses
import warnings

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure

from spinectl.model.params import Optimisation, Reflex
from spinectl.reflex import loops, margins, plots, simulate
from spinectl.reflex.delay import delay_text

PNG = b"\x89PNG\r\n\x1a\n"


def _loop():
    return {"L3L4": loops.loop_transfer(50.0, -15.0, 2.6, 75.0, 1.3, 0.1, 5)}


def _runs(model):
    plant = simulate.segment_plant(model, 0.03, 0.04, 2, np.array([15, 15, 0, 0, 0.2, 0.2]) * 1e-4)
    return {"L3L4": simulate.simulate(plant, [75.0, 0.0], [1.3, 0.0], 0.1, Reflex(sim_duration=0.3))}


def _reflex(model, **changes):
    return model.replace(reflex=dataclasses.replace(model.reflex, **changes))


def test_figure_functions_return_figures_and_write_nothing(tmp_path, monkeypatch, model):
    monkeypatch.chdir(tmp_path)
    figures = [
        plots.bode_figure(_loop(), omega_limits=(0.1, 100.0)),
        plots.nyquist_figure(_loop()),
        plots.response_figure(_runs(model)),
    ]
    assert all(isinstance(f, Figure) for f in figures)
    assert list(tmp_path.iterdir()) == []
    assert plt.get_fignums() == []  # drawn on their own canvas: pyplot holds none of them
    assert [len(f.axes) for f in figures] == [2, 1, 1]  # magnitude and phase; one Nyquist axes; one segment
    assert [f.get_suptitle() for f in figures] == [
        "Reflex loop L(jw)",
        "Nyquist plot of L(jw)",
        "Response to a perturbation (nonlinear, true delay)\n"
        "segments: joint by joint (each CoR alone, the others fixed; the paper's criterion)",
    ]


def test_bode_magnitude_is_that_of_the_loop():
    """The curve python-control draws on our axes is |L(jw)|, evaluated here by the transfer function itself."""
    loop = _loop()
    w, magnitude = plots.bode_figure(loop, omega_limits=(0.1, 100.0)).axes[0].get_lines()[0].get_data()
    assert w.min() == pytest.approx(0.1) and w.max() == pytest.approx(100.0)
    np.testing.assert_allclose(magnitude, abs(loop["L3L4"](1j * w)), rtol=1e-9)


def test_save_figure_writes_pngs_and_leaves_no_temporaries(tmp_path, model):
    written = [
        plots.save_figure(plots.bode_figure(_loop()), tmp_path / "bode.png"),
        plots.save_figure(plots.nyquist_figure(_loop()), tmp_path / "nyquist.png"),
        plots.save_figure(plots.response_figure(_runs(model)), tmp_path / "response.png"),
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bode.png", "nyquist.png", "response.png"]
    assert all(p.read_bytes()[:8] == PNG for p in written)


def test_write_plots_of_a_reflex_only_report(tmp_path, model):
    """Activation 0: every segment needs its reflex, so every plot has something to draw."""
    model = _reflex(model, activation=0.0, sim_duration=0.3)
    report = margins.margins_report(model, 0.03, 0.04)
    written = plots.write_plots(report, tmp_path / "p", model)
    assert [p.name for p in written] == list(plots.PLOT_FILES)
    assert sorted(p.name for p in (tmp_path / "p").iterdir()) == sorted(plots.PLOT_FILES)
    assert all(p.read_bytes()[:8] == PNG for p in written)


def test_write_plots_without_a_loop_writes_the_response_only(tmp_path, model):
    """Activation 1: self-stable, the rule gives kp = kd = 0, so there is no loop to draw.

    Into a folder with the plots of an earlier run (activation 0) and a file of the
    user's: the earlier Bode and Nyquist plots go (they showed another configuration),
    the user's file stays.
    """
    plots.write_plots(
        margins.margins_report(_reflex(model, activation=0.0, sim_duration=0.3), 0.03, 0.04), tmp_path, model
    )
    (tmp_path / "notes.txt").write_text("mine")
    model = _reflex(model, activation=1.0, sim_duration=0.3)
    written = plots.write_plots(margins.margins_report(model, 0.03, 0.04), tmp_path, model)
    assert [p.name for p in written] == ["response.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt", "response.png"]


def test_report_figures_draw_the_responses_they_are_given(model):
    model = _reflex(model, activation=0.0, sim_duration=0.3)
    report = margins.margins_report(model, 0.03, 0.04)
    figures = plots.report_figures(report, margins.ReportResponses(loops={}, simulations=_runs(model)))
    assert list(figures) == ["response.png"] and "E = 3 cm, Lambda = 4 cm" in figures["response.png"].get_suptitle()


def test_frequency_range_spans_the_loops_rates(model):
    """A decade around every crossover, the Pade corner order/tau and the lag's corner 1/T_a; (0.1, 10) rad/s
    when no rate is known (no segment, no delay, no lag)."""
    report = margins.margins_report(_reflex(model, activation=0.0), 0.03, 0.04)
    low, high = plots.frequency_range(report)
    crossovers = [s.crossover_rad_s for s in report.segments]
    assert low <= min(crossovers) / 10 and high >= report.pade_order / report.delay * 10
    infeasible = model.replace(optimisation=Optimisation(pcsa_max=1e-8))
    lagged = margins.margins_report(_reflex(infeasible, activation=0.5, delay=0.0), 0.03, 0.04)
    assert plots.frequency_range(lagged) == pytest.approx((2.0, 200.0))  # 1/T_a = 20 rad/s alone
    nothing = margins.margins_report(
        _reflex(infeasible, activation=0.5, delay=0.0, activation_time_constant=0.0), 0.03, 0.04
    )
    assert plots.frequency_range(nothing) == pytest.approx((0.1, 10.0))


def test_frequency_plots_of_subnormal_coefficients_are_silent(tmp_path):
    """python-control evaluates L(jw) under np.errstate(all="warn"); a subnormal damping
    (activation 1e-308 in ``spinectl margins --plot``) printed underflow warnings."""
    transfer = {"L1L2": loops.loop_transfer(71.0, -1.1e-308, 1.31, 106.5, 13.6, 0.0, 5)}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plots.save_figure(plots.bode_figure(transfer), tmp_path / "bode.png")
        plots.save_figure(plots.nyquist_figure(transfer), tmp_path / "nyquist.png")
    assert (tmp_path / "bode.png").read_bytes()[:8] == PNG


def test_bode_marks_the_margins_of_a_report(model):
    """Half activation: every loop gets a legend entry with its exact delay margin, a dot at (w_c, 1) and a phase
    bar of length PM at w_c, from the drawn phase at w_c to -180 deg (mod 360)."""
    model = _reflex(model, activation=0.5, sim_duration=0.3)
    report = margins.margins_report(model, 0.03, 0.04)
    responses = margins.report_responses(model, report)
    fig = plots.report_figures(report, responses)["bode.png"]
    magnitude, phase = fig.axes[:2]
    labels = [text.get_text() for text in phase.get_legend().get_texts()][: len(report.segments)]  # then the keys
    assert all(
        f"tau_m {delay_text(s.delay_margin, 3)}" in label for s, label in zip(report.segments, labels, strict=True)
    )
    n = len(report.segments)
    bars = phase.get_lines()[n:]
    assert len(bars) == n
    for seg, bar in zip(report.segments, bars, strict=True):
        w, y = bar.get_data()
        assert w[0] == w[1] == pytest.approx(seg.crossover_rad_s)
        assert y[0] - y[1] == pytest.approx(seg.phase_margin_deg)
        assert np.mod(y[1], 360.0) == pytest.approx(180.0, abs=0.5)  # the bar ends on -180 deg (mod 360)


def test_responses_span_five_slowest_time_constants(model):
    """The simulated response of a segment lasts 5 / |Re p| of its slowest root (Padé closed loop or, without
    reflex, paper eq. 1), between 1 s and sim_duration: not a fixed length."""
    model = _reflex(model, activation=0.5)
    report = margins.margins_report(model, 0.03, 0.04)
    seg = report.segments[2]
    poles = loops.closed_loop(
        seg.stiffness, seg.damping, seg.inertia, seg.kp, seg.kd, report.delay, report.pade_order, lag=0.05
    ).poles()
    open_loop = np.roots([seg.inertia, -seg.damping, -seg.stiffness])
    slow = max(1 / abs(poles.real.max()), 1 / abs(open_loop.real.max()))
    duration = margins.response_duration(seg, report, model.reflex)
    assert duration == pytest.approx(min(max(5 * slow, 1.0), model.reflex.sim_duration), rel=1e-9)
    assert 1.0 < duration < model.reflex.sim_duration  # here neither bound applies


@pytest.fixture(scope="module")
def at_a():
    """wagner2012 at A, half activation (``spinectl margins --plot`` as the CLI runs it): L5S1 is self-stable
    there, the gain rule gives it kp = kd = 0, so it has no loop; the four others have finite gain margins."""
    from spinectl import load_preset

    model = load_preset("wagner2012")
    # 12 s: five slowest time constants of the lagged loops are 3.6-10 s for L1L2-L4L5 (the rule does not
    # compensate the lag), so a shorter cap would end every simulation at the same time
    model = _reflex(model, activation=0.5, sim_duration=12.0)
    report = margins.margins_report(model, 0.0, 0.0)
    return report, plots.report_figures(report, margins.report_responses(model, report))


def test_bode_legend_below_the_curves_labelled_markers_and_round_phase_ticks(at_a):
    """The legend lies outside both axes (on the magnitude axes it covered the curves) and names the markers; the
    gain-margin markers are thin, a triangle at abs(L) = 1/GM (the definition of the upper gain margin, GM from
    the report), not merged thick bars; phase ticks every 180 deg or more (python-control's every 90 deg ran to
    -990); the title says which segment is left out and why."""
    report, figures = at_a
    fig = figures["bode.png"]
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    magnitude, phase = fig.axes[:2]
    legend = phase.get_legend()
    assert magnitude.get_legend() is None and legend is not None
    box = legend.get_window_extent(renderer)
    assert not any(box.overlaps(ax.get_window_extent(renderer)) for ax in (magnitude, phase))
    assert fig.bbox.contains(box.x0, box.y0) and fig.bbox.contains(box.x1, box.y1)
    assert any("gain margin" in t.get_text() for t in legend.get_texts())
    marks = [line for line in magnitude.get_lines() if line.get_gid() == "gain margin"]
    assert marks and all(line.get_linewidth() <= 1.0 for line in marks if line.get_linestyle() != "None")
    triangles = [line for line in marks if line.get_marker() == "v"]
    drawn = [s for s in report.segments if s.name != "L5S1"]
    assert len(triangles) == len(drawn) == 4
    for seg, triangle in zip(drawn, triangles, strict=True):
        assert triangle.get_ydata()[0] * seg.gain_margin == pytest.approx(1.0, rel=0.05)  # on the drawn grid
    low, high = phase.get_ylim()
    ticks = [t for t in phase.get_yticks() if low <= t <= high]
    assert np.all(np.diff(ticks) >= 180.0) and len(ticks) <= plots.PHASE_TICKS_MAX + 1
    assert "no reflex loop drawn: L5S1 (kp = kd = 0, self-stable)" in fig.get_suptitle()
    assert "L5S1" in figures["nyquist.png"].get_suptitle()


def test_each_response_panel_spans_its_own_simulation(at_a):
    """The simulations of the segments end at different times (five slowest time constants each, see
    test_responses_span_five_slowest_time_constants): each panel's time axis is that of its simulation,
    and the title says why, instead of short curves on one shared axis."""
    report, figures = at_a
    fig = figures["response.png"]
    assert plots.RESPONSE_NOTE in fig.get_suptitle()
    ends = []
    assert len(fig.axes) == len(report.segments)  # every segment simulated, L5S1 too
    for ax in fig.axes:
        time = ax.get_lines()[0].get_xdata()
        assert ax.get_xlim() == pytest.approx((time[0], time[-1]))
        ends.append(time[-1])
    assert len(set(np.round(ends, 6))) > 1  # the lengths differ, so one shared axis would cut some curves short


def test_the_response_title_lies_inside_the_figure(at_a):
    """The response figure's two-line title (the note on the panels' own time axes) was cut at both edges
    (a newcomer read 'ach segment over its own time ... at most sim_duratio'): measured drawn, it lies inside."""
    _, figures = at_a
    fig = figures["response.png"]
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1 and box.y1 <= fig.bbox.y1


def test_the_response_names_each_criterion_and_draws_the_chain():
    """``margins --plot`` at E = 3 cm, Lambda = 4 cm, activation 0.5, 100 ms (wagner2012): every segment alone is
    stable at the delay while the chain is not (its exact margin, 0.157 ms, is far below 100 ms;
    test_margins_cmd): the figure says the segments' criterion, and a last panel draws the chain, all CoRs free,
    under the same reflex, titled with the chain's exact verdict; its simulation diverges, as that verdict says."""
    from spinectl import load_preset
    from spinectl.reflex.chain_verdict import margins_with_chain

    model = _reflex(load_preset("wagner2012"), activation=0.5, delay=0.1)
    report = margins_with_chain(model, 0.03, 0.04)
    assert report.chain is not None and not report.chain.stable_at_delay  # the premise
    responses = margins.report_responses(model, report)
    fig = plots.report_figures(report, responses)["response.png"]
    assert "segments: joint by joint" in fig.get_suptitle()
    assert len(fig.axes) == len(report.segments) + 1
    chain_ax = fig.axes[-1]
    assert (
        chain_ax.get_title()
        .replace("\n", " ")
        .startswith("chain (all 5 CoRs free), the same reflex at every joint: NOT stable at 100 ms")
    )
    with_reflex, without = responses.chain
    assert with_reflex.alpha.shape[0] == without.alpha.shape[0] == 5  # one run per joint
    assert with_reflex.diverged.any()  # the simulation agrees with the exact verdict
    np.testing.assert_array_equal(with_reflex.kp, np.asarray(report.chain.kp))


def test_the_loop_figures_name_their_criterion_and_the_chains_verdict_and_explain_their_lines(at_a):
    """Bode and Nyquist draw each segment's loop alone: both titles say so (joint by joint, the paper's criterion)
    and, where the report has the chain (``margins --plot``: wagner2012 at E = 3 cm, Lambda = 4 cm, 100 ms, where
    every segment alone is stable and the chain is not), its exact verdict under the same reflex (not drawn: a
    multi-input loop); the Nyquist legend names every segment and explains the solid and dashed lines and the
    critical point -1, inside the figure (it had the segments alone, python-control's, the line styles
    unexplained). Without the chain (the fixture at A) the titles name the segments' criterion alone."""
    from spinectl import load_preset
    from spinectl.reflex.chain_verdict import margins_with_chain

    model = _reflex(load_preset("wagner2012"), activation=0.5, delay=0.1)
    report = margins_with_chain(model, 0.03, 0.04)
    assert report.chain is not None and not report.chain.stable_at_delay  # the premise
    figures = plots.report_figures(report, margins.report_responses(model, report))
    for name in ("bode.png", "nyquist.png"):
        title = " ".join(figures[name].get_suptitle().split())
        assert "each curve one segment's loop alone: joint by joint (each CoR alone" in title
        assert "chain (all 5 CoRs free), same reflex: NOT stable at 100 ms" in title and "not drawn here" in title
        bare = " ".join(at_a[1][name].get_suptitle().split())
        assert "each curve one segment's loop alone: joint by joint" in bare and "chain (all" not in bare
    fig = figures["nyquist.png"]
    fig.draw_without_rendering()
    legend = fig.axes[0].get_legend()
    texts = [t.get_text() for t in legend.get_texts()]
    drawn = [s.name for s in report.segments if s.name != "L5S1"]  # L5S1: kp = kd = 0, no loop (at_a's title)
    assert texts[: len(drawn)] == drawn
    assert any(t.startswith("solid:") for t in texts) and any(t.startswith("dashed:") for t in texts)
    assert any(t.startswith("-1, the critical point") for t in texts)
    box = legend.get_window_extent(fig.canvas.get_renderer())
    assert fig.bbox.contains(box.x0, box.y0) and fig.bbox.contains(box.x1, box.y1)


@pytest.mark.parametrize("divergence", [None, 0.1])
def test_the_chain_panel_says_its_traces_stop_at_the_divergence_limit_and_names_its_joints(divergence):
    """``margins --delay 0.1 --plot`` (wagner2012 at E = 3 cm, Lambda = 4 cm, activation 0.5): the chain's runs
    diverge and stop at reflex.sim_divergence (the preset's 0.2 rad; 0.1 rad, a variant), their angles frozen after,
    which read as a new resting posture: the panel's title says where the traces stop and why (the limit read from
    the model, in mrad), and a legend names each joint's colour (the model's CoR names, the runs' order)."""
    from spinectl import load_preset
    from spinectl.reflex.chain_verdict import margins_with_chain

    model = _reflex(load_preset("wagner2012"), activation=0.5, delay=0.1)
    if divergence is not None:
        model = _reflex(model, sim_divergence=divergence)
    report = margins_with_chain(model, 0.03, 0.04)
    responses = margins.report_responses(model, report)
    assert responses.chain[0].diverged.any()  # the premise: the chain's run with the reflex stops at the limit
    limit = model.reflex.sim_divergence
    assert np.max(np.abs(responses.chain[0].alpha)) == pytest.approx(limit, rel=0.1)  # flat near the limit
    chain_ax = plots.report_figures(report, responses)["response.png"].axes[-1]
    title = " ".join(chain_ax.get_title().split())
    assert f"diverged: each trace is held flat from its last step before |alpha| passes {limit * 1e3:g} mrad" in title
    assert "(reflex.sim_divergence)" in title and "not a posture" in title
    legend = chain_ax.get_legend()
    assert legend is not None and [t.get_text() for t in legend.get_texts()] == list(model.geometry.cor_names)
    colours = [line.get_color() for line in legend.get_lines()]
    assert colours == [chain_ax.get_lines()[2 * j].get_color() for j in range(len(colours))]


def test_the_chain_panel_says_nothing_of_divergence_where_no_run_diverged(model):
    """A run that stays inside the limit gets no divergence note (the note would be false): the chain runs of the
    figure function itself, here two made-up runs that never diverge."""
    runs = _runs(model)
    sim = runs["L3L4"]
    calm = dataclasses.replace(sim, diverged=np.zeros_like(sim.diverged))
    assert plots.divergence_note((calm, calm), 0.2) == ""
    assert plots.divergence_note((dataclasses.replace(calm, diverged=np.ones_like(sim.diverged)), calm), 0.2)
