"""The Panel app without a browser: its widgets move the state, its views show the library's numbers."""

from __future__ import annotations

import asyncio
import dataclasses
import html
import xml.etree.ElementTree as ET

import numpy as np
import param
import pytest

from spinectl.errors import ModelError
from spinectl.explore import app, design_panel
from spinectl.explore import numbers as nb
from spinectl.explore.state import initial_state, replace, slider_for
from spinectl.model.config import load_config, load_preset
from spinectl.paper.landmarks import CT_LIMIT


@pytest.fixture(scope="module")
def explorer():
    return app.Explorer(load_preset("default"), "default")


def _drag(slider, value):
    """What the browser sends when a slider is released: value and value_throttled."""
    with param.edit_constant(slider):
        slider.param.update(value=value, value_throttled=value)


def test_views_show_the_numbers_of_the_state(explorer):
    """The table's cells are PointNumbers.rows(); the drawing is drawing_svg of the same numbers, byte for byte."""
    expected = nb.point_numbers(explorer.base, explorer.state)
    for row in expected.rows():
        for key in app.ROW_KEYS:
            assert f'<td data-key="{key}">{row[key]}</td>' in explorer.table.object
    assert explorer.drawing.object == app.drawing_svg(expected)
    assert explorer.dataset is not None  # outside a server session the landscapes are solved at once
    assert "point updated in" in explorer.status.object


def test_a_slider_moves_the_point_and_the_views_follow(explorer):
    """E to 5.2 cm: numbers, drawing and landscape markers at the new point."""
    before = explorer.drawing.object
    _drag(explorer.sliders["eccentricity"], 5.2)
    assert explorer.state.eccentricity == pytest.approx(0.052, abs=1e-15)
    expected = nb.point_numbers(explorer.base, explorer.state)
    assert f'<td data-key="counter_torque_Nm">{expected.rows()[0]["counter_torque_Nm"]}</td>' in explorer.table.object
    assert explorer.drawing.object != before and explorer.drawing.object == app.drawing_svg(expected)
    for view in explorer.maps.values():
        assert view.marker.data == {"x": [pytest.approx(5.2)], "y": [pytest.approx(4.0)]}


def test_mass_solves_the_landscapes_again(explorer):
    """A new mass: the landscapes are those of nb.landscapes at the new state; a reflex change keeps them."""
    _drag(explorer.sliders["mass"], 30.0)
    expected = nb.landscapes(explorer.base, explorer.state)
    np.testing.assert_array_equal(explorer.dataset.min_pcsa_cm2, expected.min_pcsa_cm2)
    image = explorer.maps["min_pcsa_cm2"].image.data["image"][0]
    np.testing.assert_array_equal(image, expected.min_pcsa_cm2.values.T)  # Bokeh's rows are Lambda
    kept = explorer.dataset
    _drag(explorer.sliders["delay"], 150.0)
    assert explorer.dataset is kept and explorer.state.delay == pytest.approx(0.15)


def test_a_click_moves_the_point_to_the_nearest_step_inside_the_range(explorer):
    """(5.123 cm, -1 cm) -> E = 5.1 cm, Lambda = 0 (the sliders' step 0.1 cm, range 0 to 8 cm)."""
    explorer.move_to(0.05123, -0.01)
    assert (explorer.state.eccentricity, explorer.state.lordosis) == (0.051, 0.0)
    assert explorer.sliders["eccentricity"].value == pytest.approx(5.1)
    assert explorer.sliders["lordosis"].value == 0.0


def test_preset_selector_loads_the_preset_and_keeps_the_point(explorer):
    """wagner2012: its own mass and K on the sliders, the point kept."""
    point = (explorer.state.eccentricity, explorer.state.lordosis)
    explorer.preset.value = "wagner2012"
    wagner = load_preset("wagner2012")
    assert explorer.state == replace(initial_state(wagner), eccentricity=point[0], lordosis=point[1])
    assert explorer.sliders["mass"].value == wagner.body.mass


def test_exports_toml_and_png(explorer):
    """The download buttons: the state's TOML (state_toml) and a PNG of every view."""
    toml, png = (w for w in explorer.layout.select(app.pn.widgets.FileDownload))
    assert toml.callback().getvalue().startswith("# spinectl explore: E = ")
    assert png.callback().getvalue().startswith(b"\x89PNG")


def test_the_drawing_svg_is_reproducible_and_keeps_its_words_as_text(explorer):
    """The same numbers give the same SVG text (no date, fixed ids): the browser test relies on it. It parses
    as XML, and each CoR's name is an SVG text element (svg.fonttype none), not glyphs drawn as paths."""
    numbers = nb.point_numbers(explorer.base, explorer.state)
    svg = app.drawing_svg(numbers)
    assert svg == app.drawing_svg(numbers) and svg.startswith("<svg")
    texts = {"".join(t.itertext()).strip() for t in ET.fromstring(svg).iter("{http://www.w3.org/2000/svg}text")}
    assert set(numbers.segment_names) <= texts


def test_a_model_invalid_at_the_point_is_a_message_not_a_crash(explorer, monkeypatch):
    """An error the user can cause (a SpinectlError) shows in the status line; the views keep the last point."""
    shown = explorer.table.object

    def invalid(base, state, previous=None):
        raise ModelError("fibre attachment on a centre of rotation")

    monkeypatch.setattr(app, "point_numbers", invalid)
    explorer.move_to(0.01, 0.01)
    assert explorer.status.object.startswith("**point not shown:** fibre attachment on a centre of rotation; ")
    assert explorer.table.object == shown


ON_COR = '[[muscles]]\nname = "p"\nupper = [0.1, 0.3]\nlower = [0.0, 0.005]\nspread = 0.0\nfibres = 1\n'
"""A fourth pair whose lower attachment is the CoR L5S1 (y = 0.005 m) at E = Lambda = 0, a corner of the
landscapes' grid, and nowhere else (docs/robustness.md, "Model evaluation")."""


def test_a_model_invalid_at_one_grid_point_stops_the_progress_and_says_why(tmp_path, monkeypatch):
    """In a server session the landscapes are solved in a worker thread; the model of ON_COR is invalid at
    E = Lambda = 0 only: the solve ends with the library's one-line ModelError in the status line, the progress
    bar stopped and the maps no longer loading (before: the task raised, the progress ran for ever and the
    traceback went to the server's log). The point itself (3 cm, 4 cm) is valid and shown."""
    path = tmp_path / "on_cor.toml"
    path.write_text(ON_COR)
    model = load_config(path)
    with pytest.raises(ModelError, match="L5S1 at E = 0 m, Lambda = 0 m") as raised:
        nb.landscapes(model, initial_state(model))
    tasks = []
    monkeypatch.setattr(app, "in_session", lambda: True)
    monkeypatch.setattr(app.pn.state, "onload", lambda callback, **options: callback())  # the page has loaded
    monkeypatch.setattr(app.pn.state, "execute", lambda function, **options: tasks.append(function))
    explorer = app.Explorer(model, app.CONFIG_CHOICE)
    assert explorer.progress.active and "solving…" in explorer.status.object
    (solve,) = tasks
    asyncio.run(solve())
    assert not explorer.progress.active and not any(view.pane.loading for view in explorer.maps.values())
    assert explorer.status.object.endswith(f"landscapes (41 × 41) **not solved:** {raised.value}")
    assert explorer.status.object.startswith("point updated in ") and explorer.dataset is None


@pytest.mark.parametrize(
    ("field", "sent", "message"),
    [
        ("eccentricity", float("nan"), "E [cm]: must be finite (got nan)"),
        ("mass", 1e6, "mass [kg]: must be in [10, 80] (got 1e+06)"),
        ("delay", -5.0, "reflex delay τ [ms]: must be in [0, 250] (got -5)"),
        ("stiffness", float("inf"), "K [N m/rad]: must be finite (got inf)"),
    ],
)
def test_a_forged_slider_value_is_refused_in_one_line(field, sent, message):
    """What a forged message can send past Bokeh's own type check (which refuses a string): NaN, inf, a value
    outside the slider's range. The status line says so, the state, the views and the landscapes stay (before:
    NaN raised in the server, its traceback sent back to the page; 1e6 kg left the landscapes solving for ever)."""
    explorer = app.Explorer(load_preset("default"), "default")
    state, table, dataset = explorer.state, explorer.table.object, explorer.dataset
    _drag(explorer.sliders[field], sent)
    assert explorer.status.object.startswith(f"**refused:** {message}; point updated in ")
    assert explorer.state == state and explorer.table.object == table and explorer.dataset is dataset
    assert explorer.sliders[field].value == pytest.approx(getattr(state, field) * slider_for(field).scale)
    _drag(explorer.sliders[field], explorer.sliders[field].start)  # a valid value clears the message
    assert not explorer.status.object.startswith("**refused:**")


def test_a_forged_click_or_preset_is_refused_in_one_line():
    """A tap at NaN (a forged Bokeh event), a preset that is not one: one line; the point and preset stay."""
    explorer = app.Explorer(load_preset("default"), "default")
    state = explorer.state
    explorer.move_to(float("nan"), 0.02)
    assert explorer.status.object.startswith("**refused:** E [cm]: must be finite (got nan); ")
    explorer.preset.value = "nope"  # set in Python, past the widget's check: the explorer's own refuses it
    assert explorer.status.object.startswith("**refused:** preset: must be one of ")
    assert explorer.state == state and explorer.preset.value == "default"


@pytest.mark.parametrize("value", ["nope", 5, None, ""])
def test_a_select_value_from_the_page_not_among_its_options_is_refused_in_one_line(value):
    """What Panel does with a message from the page (``_process_events``): a value that is no option, a number, null,
    empty (Panel's "first option"), is refused in the status line, the preset kept (before: Panel's ValueError "nope
    not in list" and its traceback in the server's log; "" silently chose the first option)."""
    explorer = app.Explorer(load_preset("wagner2012"), "wagner2012")
    state = explorer.state
    explorer.preset._process_events({"value": value})
    status = html.unescape(explorer.status.object)
    assert (
        status.startswith("**refused:** preset: must be one of 'default', 'wagner2012', ")
        and f"(got {value!r})" in status
    )
    assert explorer.state == state and explorer.preset.value == "wagner2012" and explorer.current == "wagner2012"
    explorer.preset._process_events({"value": "default"})  # an option is taken
    assert explorer.current == "default" and not explorer.status.object.startswith("**refused:**")


def test_explorer_for_a_notebook_reads_the_config_named(tmp_path):
    """explorer(config=...) starts from that file's model; the layout displays itself (Jupyter's mimebundle)."""
    path = tmp_path / "mine.toml"
    path.write_text("[body]\nmass = 33.0\n")
    layout = app.explorer(config=path)
    assert hasattr(layout, "_repr_mimebundle_")
    sliders = [w for w in layout.select(app.pn.widgets.FloatSlider) if w.label == "mass [kg]"]
    assert [s.value for s in sliders] == [33.0]
    assert [w.value for w in layout.select(app.pn.widgets.Select)] == [app.CONFIG_CHOICE]


def test_the_delay_redraws_the_margins_only():
    """The reflex delay and the lag do not change the PCSA: the drawing, eigenvalues and CT pictures stay the same
    objects; the margins view and the table follow (state.REFLEX_ONLY). At the README's point of 'default' every
    delay margin is finite (0.22 to 0.42 s), so a longer lag changes them."""
    explorer = app.Explorer(load_preset("default"), "default")
    kept = {name: view.source.data for name, view in explorer.views.items()} | {"drawing": explorer.drawing.object}
    table = explorer.table.object
    _drag(explorer.sliders["activation_lag"], 100.0)
    assert explorer.state.activation_lag == pytest.approx(0.1)
    for name in ("eigenvalues", "counter_torques"):
        assert explorer.views[name].source.data is kept[name]
    assert explorer.drawing.object is kept["drawing"]
    margins = explorer.views["delay_margins"].source.data["value"]
    assert margins != kept["delay_margins"]["value"] and explorer.table.object != table
    expected = nb.point_numbers(explorer.base, explorer.state)
    np.testing.assert_allclose(margins, expected.delay_margin * 1000, rtol=1e-12)


def test_the_bokeh_views_plot_the_librarys_numbers(explorer):
    """Read back from the Bokeh views' data sources: the eigenvalues (paper eq. 1), CT_k [N m] and the exact
    delay margins [ms] of point_numbers at the state, the delay line at tau [ms], the +-30 N m band."""
    explorer.move_to(0.035, 0.045)
    expected = nb.point_numbers(explorer.base, explorer.state)
    eigen = explorer.views["eigenvalues"].source.data
    np.testing.assert_allclose(eigen["re"], expected.eigenvalues.real.ravel(), rtol=1e-12)
    np.testing.assert_allclose(eigen["im"], expected.eigenvalues.imag.ravel(), rtol=1e-12)
    assert eigen["segment"][::2] == list(expected.segment_names)
    torques = explorer.views["counter_torques"]
    np.testing.assert_allclose(torques.source.data["value"], expected.counter_torque, rtol=1e-12)
    band = next(r for r in torques.figure.center if isinstance(r, app.BoxAnnotation))
    assert (band.bottom, band.top) == (-CT_LIMIT, CT_LIMIT)
    margins = explorer.views["delay_margins"]
    finite = np.isfinite(expected.delay_margin)  # an infinite margin (any delay): a bar of 0 marked '∞'
    np.testing.assert_allclose(margins.source.data["value"], np.where(finite, expected.delay_margin * 1000, 0.0))
    assert [m == "∞" for m in margins.source.data["mark"]] == list(~finite)
    assert margins.line.location == pytest.approx(explorer.state.delay * 1000)


def _text_px(text: str, size: str, bold: bool) -> float:
    """Width [px] of one line as Chromium sets a Bokeh title here: Bokeh's 'helvetica' is DejaVu Sans on Debian
    (fc-match), matplotlib's own font, measured at 72 dpi so that a point is a pixel (8pt = 8 * 96 / 72 px)."""
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties

    px = float(size[:-2]) * (96 / 72 if size.endswith("pt") else 1.0)
    font = FontProperties(family="DejaVu Sans", weight="bold" if bold else "normal", size=px)
    return RendererAgg(1, 1, 72).get_text_width_height_descent(text, font, ismath=False)[0]


FRAME_LEFT_PX = 60
"""Room taken left of a plot's frame, where its title starts, by the y axis: its label, tick labels and ticks
(about 45 px in the browser; 60 to be safe)."""


def test_every_title_of_the_bokeh_views_fits_its_view():
    """Each title line of every Bokeh view, for the calibrated preset wagner2012 (24.056578609556272 kg) and a
    3-digit delay, is narrower than the view right of its frame (before: 'minimum PCSA [cm²]: mass 24.0566 kg,
    K 0 N m/rad' and 'delay margins (red: unstable at τ = 100 ms)' were cut at the view's right edge)."""
    explorer = app.Explorer(load_preset("wagner2012"), "wagner2012")
    figures = [view.figure for view in explorer.views.values()] + [view.figure for view in explorer.maps.values()]
    for figure in figures:
        title = figure.title
        bold = title.text_font_style == "bold"
        for line in title.text.split("\n"):
            assert _text_px(line, title.text_font_size, bold) <= figure.width - FRAME_LEFT_PX, line


def test_values_show_the_digits_their_slider_steps_mean():
    """wagner2012's calibrated mass 24.056578609556272 kg is shown as 24.1 kg (steps of 0.5 kg) in its slider's
    format and the landscapes' titles, not 24.0566; the state keeps the model's own value."""
    explorer = app.Explorer(load_preset("wagner2012"), "wagner2012")
    assert explorer.state.mass == load_preset("wagner2012").body.mass
    assert explorer.sliders["mass"].format == "0.0" and explorer.sliders["activation"].format == "0.00"
    assert explorer.sliders["delay"].format == "0"
    assert explorer.maps["min_pcsa_cm2"].figure.title.text == "minimum PCSA [cm²]\nmass 24.1 kg, K 0.0 N m/rad"


def test_the_table_gives_the_chains_verdict_beside_the_segments():
    """Under the segments' table, captioned with their criterion (joint by joint), the chain's row: its criterion
    and every cell of PointNumbers.chain_row at the state; the header of the segments' verdict names its criterion."""
    explorer = app.Explorer(load_preset("default"), "default")
    expected = nb.point_numbers(explorer.base, explorer.state)
    table = explorer.table.object
    assert "<caption>joint by joint (each CoR alone, the others fixed; the paper&#x27;s criterion)</caption>" in table
    assert "<th>stable at τ, joint by joint</th>" in table
    row = expected.chain_row()
    rule = "the same reflex rule at every joint (gains from each joint's own stiffness)"
    assert f'<caption data-chain="criterion">chain (all 5 CoRs free), {rule}</caption>' in table
    for key in app.CHAIN_KEYS:
        assert f'<td data-chain="{key}">{row[key]}</td>' in table
    assert row["stable_at_delay"] == "no"  # at the README's point the chain is not (docs/chain.md), the segments are
    assert all(r["stable_at_delay"] == "yes" for r in expected.rows())


def test_the_design_button_shows_the_answer_for_its_state_and_marks_it_when_the_sliders_move(monkeypatch):
    """The button runs numbers.design_numbers at the sliders' state (here outside a server session, at once) and
    shows design_panel.design_html of its answer, every line of design_rows in it; the line under the button
    says where; a moved slider marks it as for another state; an error is one line."""
    explorer = app.Explorer(load_preset("default"), "default")
    assert explorer.design.object == ""  # seconds of work: only on request
    explorer.design_button.clicks += 1
    state, base, answer = explorer.design_answer
    assert state == explorer.state and base is explorer.base and answer.searched is None  # the rule alone
    assert explorer.design.object == design_panel.design_html(answer, state, current=True)
    for key, lines in nb.design_rows(answer).items():
        for line, _ in lines:
            assert html.escape(line) in explorer.design.object, key
    assert explorer.design_status.object == f"design: status {answer.status}, {app.DESIGN_PLACE}"
    assert "press again" not in explorer.design.object and not explorer.design_spinner.visible
    _drag(explorer.sliders["delay"], 40.0)
    assert "the sliders have moved since: press again" in explorer.design.object

    def refused(base, state, search):
        raise ModelError("levels.mass: must be > 0 for the chain")

    monkeypatch.setattr(app, "design_numbers", refused)
    explorer.run_design()
    assert explorer.design.object == "<p><b>design not found:</b> levels.mass: must be &gt; 0 for the chain</p>"
    assert explorer.design_status.object == f"design not found: {app.DESIGN_PLACE}"
    assert not explorer.design_button.disabled and not explorer.design_spinner.value


def test_the_search_choice_asks_for_the_answer_over_every_diagonal_reflex(monkeypatch):
    """The choice *also over every diagonal PD reflex* hands search=True to design_numbers (spinectl design --gains
    search), and the command the panel gives says --gains search; off, neither (the search itself, tens of
    seconds: tests/reflex/test_design_gain_searched.py)."""
    asked = []
    explorer = app.Explorer(load_preset("default"), "default")
    answer = nb.design_numbers(explorer.base, explorer.state)

    def recorded(base, state, search):
        asked.append(search)
        return dataclasses.replace(answer, searched=object()) if search else answer

    monkeypatch.setattr(app, "design_numbers", recorded)
    monkeypatch.setattr(design_panel, "design_rows", lambda design: nb.design_rows(answer))  # object() has no lines
    explorer.run_design()
    assert "--gains search" not in _command(explorer.design.object)
    explorer.design_search.value = app.SEARCH_CHOICES[f"{design_panel.SEARCH_WORDS} (tens of s)"]
    explorer.run_design()
    assert asked == [False, True]
    assert _command(explorer.design.object) == design_panel.design_command(explorer.state) + " --gains search"


def _command(page: str) -> str:
    """The command line the design panel gives, unescaped."""
    return html.unescape(page.split('<code data-design="command">')[1].split("</code>")[0])


def test_design_html_puts_each_line_of_the_answer_in_its_part():
    """design_html at a state other than the opening one (wagner2012, 200 ms, activation 0.3, K 10): each
    part of design_rows in elements whose data-design is the part, in the command's order; a note indented,
    the segments' table one <pre> of its lines; the command for the state's TOML export last; an answer for
    another state marked."""
    base = load_preset("wagner2012")
    state = replace(initial_state(base), delay=0.2, activation=0.3, stiffness=10.0)
    answer = nb.design_numbers(base, state)
    page = design_panel.design_html(answer, state, current=True)
    rows = nb.design_rows(answer)
    positions = []
    for key in design_panel.PARTS[2:]:  # the lines of the answers: joint, chain_title, chain
        for line, note in rows[key]:
            if key == "chain_title":
                element = f'<b data-design="{key}">{html.escape(line)}</b>'
            else:
                style = f' style="{design_panel.NOTE_STYLE}"' if note else ""
                element = f'<div data-design="{key}"{style}>{html.escape(line)}</div>'
            assert element in page
            positions.append(page.index(element))
    assert positions == sorted(positions)
    table = "\n".join(line for line, _ in rows["joint_table"])
    assert f'<pre data-design="joint_table">{html.escape(table)}</pre>' in page
    assert any(note for _, note in rows["chain"]) and any(not note for _, note in rows["chain"])
    assert page.index('data-design="command"') > positions[-1]
    assert _command(page) == f"spinectl design --config spinectl-explore.toml --E {0.03!r} --Lambda {0.04!r}"
    assert "press again" not in page and "press again" in design_panel.design_html(answer, state, current=False)


def test_in_a_session_the_design_runs_in_a_worker_and_the_sliders_stay_free(monkeypatch):
    """In a server session the button starts a task (a worker thread) and shows a spinner, the button disabled;
    a slider moved meanwhile updates the point at once; the task answers for the state of the press and ends
    with the spinner stopped and the button enabled, also when the library refuses (its one-line error)."""
    tasks, asked = [], []
    monkeypatch.setattr(app, "in_session", lambda: True)
    monkeypatch.setattr(app.pn.state, "onload", lambda callback, **options: None)
    monkeypatch.setattr(app.pn.state, "execute", lambda function, **options: tasks.append(function))

    def refused(base, state, search):
        asked.append(state)
        raise ModelError("levels.mass: must be > 0 for the chain")

    monkeypatch.setattr(app, "design_numbers", refused)
    explorer = app.Explorer(load_preset("default"), "default")
    pressed = explorer.state
    explorer.design_button.clicks += 1
    (solve,) = tasks
    assert explorer.design_spinner.value and explorer.design_spinner.visible and explorer.design_button.disabled
    table = explorer.table.object
    _drag(explorer.sliders["activation_lag"], 100.0)  # moves every delay margin (test_the_delay_redraws_...)
    assert explorer.table.object != table  # the point follows the slider while the design is pending
    asyncio.run(solve())
    assert asked == [pressed]
    assert explorer.design.object == "<p><b>design not found:</b> levels.mass: must be &gt; 0 for the chain</p>"
    assert not explorer.design_spinner.value and not explorer.design_spinner.visible
    assert not explorer.design_button.disabled
