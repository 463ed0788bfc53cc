"""The explorer as a Panel app: sliders, the model drawing, the numbers, clickable landscapes.

docs/explore.md. :class:`Explorer` holds one session's state and its views;
:func:`explorer` returns its layout, which shows itself inline in a Jupyter notebook
(after ``panel.extension()``), and :func:`spinectl.explore.server.serve` serves it on the loopback interface
(``spinectl explore``). Every number comes from :mod:`spinectl.explore.numbers`. The model
drawing is matplotlib's (:func:`spinectl.explore.views.model_drawing`, as SVG); the
eigenvalues, counter torques and delay margins are Bokeh plots whose data
(:func:`spinectl.explore.views.eigenvalue_data` and its siblings, the same data as the PNG
export's matplotlib views) is replaced on a move, not re-rendered on the server; the
landscapes are Bokeh images so that a click on them moves the point. They are solved again, in a worker
thread with a progress indicator, only when the mass, K or the model change.

Needs the ``explore`` extra (``pip install 'spinectl[explore]'``: Panel, which brings Bokeh).
"""

from __future__ import annotations

import asyncio
import html
import io
import time

import matplotlib
import numpy as np
import panel as pn
import xarray as xr
from bokeh.events import Tap
from bokeh.models import BoxAnnotation, ColorBar, ColumnDataSource, FactorRange, LinearColorMapper, Range1d, Span
from bokeh.plotting import figure as bokeh_figure
from matplotlib.colors import to_hex

from .._validate import choice, printable, real
from ..errors import SpinectlError
from ..model.config import DEFAULT_PRESET, list_presets, load_preset
from ..model.params import Model
from ..paper.landmarks import CT_LIMIT
from ..reflex.design import Design
from ..units import CM_PER_M, m2_to_cm2
from . import views
from .design_panel import SEARCH_WORDS, TOML_NAME, design_html
from .numbers import (
    LANDSCAPE_POINTS,
    PointNumbers,
    design_numbers,
    landscape_axis,
    landscapes,
    point_numbers,
)
from .state import (
    LANDSCAPE_PARAMETERS,
    SLIDERS,
    ExploreState,
    decimals,
    from_client,
    initial_state,
    pictures_key,
    replace,
    shown_text,
    slider_for,
    state_toml,
)

DPI = 80
"""Pixels per inch of the model drawing in the browser."""
VIEW_PIXELS = (300, 240)
"""Width and height of a small view (eigenvalues, counter torques, delay margins) [px]."""
EIGENVALUE_LEGEND_PIXELS = 70
"""Width of the eigenvalue view's legend, beside the plane [px]."""
LANDSCAPE_PIXELS = 300
"""Width and height of a landscape view [px]."""
DESIGN_PIXELS = 1040
"""Width of the design panel [px]: the views' column, so that its lines wrap there instead of widening the page."""
CONFIG_CHOICE = "--config"
"""The preset selector's entry for the model of ``--config``."""
ROW_KEYS = ("segment", "eigenvalue_1", "eigenvalue_2", "counter_torque_Nm", "delay_margin_s", "stable_at_delay")
"""The columns of the numbers table, keys of :meth:`PointNumbers.rows`."""
ROW_HEADERS = ("segment", "λ₁ [1/s]", "λ₂ [1/s]", "CT [N m]", "delay margin [s]", "stable at τ, joint by joint")
"""Their headers."""
CHAIN_KEYS = (
    "stable_at_delay",
    "delay_margin_s",
    "frequency_rad_s",
    "modes",
    "growth_times_s",
    "slowest_time_constant_s",
)
"""The cells of the chain's row, keys of :meth:`PointNumbers.chain_row` (its criterion heads the row)."""
CHAIN_HEADERS = (
    "stable at τ",
    "delay margin [s]",
    "at [rad/s]",
    "modes without reflex",
    "growth times [s]",
    "slowest time constant [s]",
)
"""Their headers."""
DESIGN_LABEL = "design for this delay"
"""The button that answers the design question at the sliders' delay (seconds: on request only)."""
SEARCH_CHOICES = {"the reflex rule alone": False, f"{SEARCH_WORDS} (tens of s)": True}
"""The chain's reflex the design answers for: the rule's alone, or also every diagonal PD reflex (``--gains
search``); buttons, since a check box's label does not toggle it in Bokeh (a click on its words did nothing)."""
DESIGN_PLACE = "under the numbers table"
"""Where the design answer shows, below the first screen: the line under the button says so."""


def png_bytes(fig, dpi: float = DPI) -> bytes:
    """A matplotlib figure as PNG bytes, in memory.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    dpi : float
        Dots per inch.

    Returns
    -------
    bytes
        The PNG file's content; the same figure at the same dpi gives the same bytes.
    """
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
    return buffer.getvalue()


def drawing_svg(numbers: PointNumbers) -> str:
    """The model drawing of :func:`spinectl.explore.views.model_drawing` as SVG, its words as SVG text.

    The browser sets the glyphs: about 40 % faster than a PNG, in which matplotlib rasterises them.

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    str
        The ``<svg>`` element (no XML prolog); the same numbers give the same text (fixed ids, no date).
    """
    buffer = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "spinectl"}):
        views.model_drawing(numbers).savefig(buffer, format="svg", metadata={"Date": None})
    text = buffer.getvalue()
    return text[text.index("<svg") :]


def table_html(numbers: PointNumbers) -> str:
    """The numbers of every segment as an HTML table; each cell carries its key (``data-key``).

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    str
        A status line; a ``<table>`` with one row per segment (:meth:`PointNumbers.rows`), judged
        joint by joint (captioned with its criterion); and the chain's verdict under the same reflex
        (:meth:`PointNumbers.chain_row`, its cells keyed by ``data-chain``).
    """
    head = "".join(f"<th>{h}</th>" for h in ROW_HEADERS)
    body = "".join(
        "<tr>" + "".join(f'<td data-key="{key}">{html.escape(row[key])}</td>' for key in ROW_KEYS) + "</tr>"
        for row in numbers.rows()
    )
    point = numbers.report.point
    total = m2_to_cm2(np.sum(point.pcsa))
    status = (
        f'<p data-key="status">E = {point.eccentricity * CM_PER_M:.3g} cm, Λ = {point.lordosis * CM_PER_M:.3g} cm; '
        f"optimum: {html.escape(point.status)}; PCSA at this activation: {total:.4g} cm² in all</p>"
    )
    caption = f"<caption>{html.escape(numbers.criterion)}</caption>"
    return f'{status}<table class="spinectl-numbers">{caption}<tr>{head}</tr>{body}</table>{chain_html(numbers)}'


def verdicts_html(numbers: PointNumbers) -> str:
    """The two verdicts at the delay, on the first screen: joint by joint, then the chain (red where not stable).

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    str
        Two ``<p>`` lines (:meth:`PointNumbers.verdicts`), keyed ``data-verdict="joint"`` and ``"chain"``.
    """
    held = (bool(np.all(numbers.stable_at_delay)), bool(numbers.chain.stable_at_delay))
    lines = []
    for key, text, ok in zip(("joint", "chain"), numbers.verdicts(), held, strict=True):
        colour = "inherit" if ok else UNSTABLE_COLOUR
        lines.append(f'<p data-verdict="{key}" style="margin:2px 0;color:{colour}"><b>{html.escape(text)}</b></p>')
    return "".join(lines)


UNSTABLE_COLOUR = "#b00020"
"""The colour of a verdict that does not hold at the delay."""


def chain_html(numbers: PointNumbers) -> str:
    """The chain's verdict under the same reflex, every CoR free, as a one-row HTML table captioned with its criterion.

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    str
        A ``<table>`` whose cells carry their key of :meth:`PointNumbers.chain_row` (``data-chain``).
    """
    row = numbers.chain_row()
    head = "".join(f"<th>{h}</th>" for h in CHAIN_HEADERS)
    cells = "".join(f'<td data-chain="{key}">{html.escape(row[key])}</td>' for key in CHAIN_KEYS)
    words = html.escape(row["criterion"])
    rule = "the same reflex rule at every joint (gains from each joint's own stiffness)"
    caption = f'<caption data-chain="criterion">{words}, {rule}</caption>'
    return f'<table class="spinectl-chain">{caption}<tr>{head}</tr><tr>{cells}</tr></table>'


class Explorer:
    """One session of the explorer: its state, widgets and views.

    Parameters
    ----------
    base : Model
        The model to start from (a preset, or the model of ``--config``).
    preset : str
        The preset selector's entry for ``base``: a preset's name or :data:`CONFIG_CHOICE`.
    """

    def __init__(self, base: Model, preset: str):
        self.models = {CONFIG_CHOICE: base} if preset == CONFIG_CHOICE else {}
        self.base, self.current = base, preset
        self.state = initial_state(base)
        self.numbers: PointNumbers | None = None
        self._numbers_base: Model | None = None
        self.dataset: xr.Dataset | None = None
        self._generation = 0
        self._pictures_key = None
        self.seconds = {"point": np.nan, "landscapes": np.nan}
        self.errors: dict[str, str | None] = {"input": None, "point": None, "landscapes": None, "design": None}
        self.preset = ClientSelect(
            self._refuse, label="preset", value=preset, options=[*self.models, *list_presets()], width=260
        )
        self.sliders = {s.field: self._slider(s) for s in SLIDERS}
        self.drawing = pn.pane.SVG(None, width=int(views.DRAWING_SIZE[0] * DPI), name="drawing")
        self.views = {"eigenvalues": _EigenvalueView(), **{name: _BarView(name) for name in BAR_VIEWS}}
        self.table = pn.pane.HTML("", name="numbers")
        self.verdicts = pn.pane.HTML("", name="verdicts")
        self.status = pn.pane.Markdown("", name="status")
        self.progress = pn.indicators.Progress(active=False, visible=False, width=200)
        self.design_button = pn.widgets.Button(label=DESIGN_LABEL, width=260)
        self.design_search = pn.widgets.RadioButtonGroup(
            options=SEARCH_CHOICES, value=False, orientation="vertical", width=275
        )
        self.design_spinner = pn.indicators.LoadingSpinner(value=False, visible=False, width=24, height=24)
        self.design = pn.pane.HTML("", name="design", width=DESIGN_PIXELS)  # its long lines wrap in the column
        self.design_status = pn.pane.Markdown("", name="design_status", width=260)
        self.design_answer: tuple[ExploreState, Model, Design] | None = None
        self._design_generation = 0
        self.design_button.on_click(lambda event: self.run_design())
        self.maps = {variable: _LandscapeView(variable, self.move_to) for variable in views.LANDSCAPE_LABELS}
        self.preset.param.watch(self._on_preset, "value")
        self.layout = self._layout()
        if in_session():
            self.progress.param.update(active=True, visible=True)  # "solving…" until the page is connected
        self.update_point()
        if in_session():  # solved once the page is connected: a solve done before, its views were at times not sent
            pn.state.onload(self.refresh_landscapes)
        else:
            self.refresh_landscapes()

    def _slider(self, spec) -> pn.widgets.FloatSlider:
        value = getattr(self.state, spec.field) * spec.scale
        slider = pn.widgets.FloatSlider(
            label=spec.label,
            start=min(spec.start, value),
            end=max(spec.end, value),
            step=spec.step,
            value=value,
            format="0" if not decimals(spec) else "0." + "0" * decimals(spec),  # the digits a step means
            width=260,
        )
        slider.param.watch(lambda event, spec=spec: self._on_slider(spec, event.new), "value_throttled")
        return slider

    def _layout(self) -> pn.viewable.Viewable:
        toml = pn.widgets.FileDownload(
            callback=lambda: io.StringIO(state_toml(self.base, self.state)),
            filename=TOML_NAME,
            label="export TOML config",
            width=260,
        )
        png = pn.widgets.FileDownload(
            callback=lambda: io.BytesIO(png_bytes(views.state_figure(self.numbers, self.dataset), dpi=100)),
            filename="spinectl-explore.png",
            label="export PNG",
            width=260,
        )
        controls = pn.Column(
            "## spinectl explore",
            self.preset,
            *self.sliders.values(),
            toml,
            png,
            self.progress,
            self.status,
            pn.Row(self.design_button, self.design_spinner),
            self.design_search,
            self.design_status,
            width=290,
        )
        point = pn.Row(self.drawing, self.views["eigenvalues"].pane, self.views["counter_torques"].pane)
        below = pn.Row(self.views["delay_margins"].pane, *(view.pane for view in self.maps.values()))
        return pn.Row(controls, pn.Column(self.verdicts, point, below, self.table, self.design))

    # --- events ---------------------------------------------------------------------------

    def _on_slider(self, spec, shown) -> None:
        old, slider = self.state, self.sliders[spec.field]
        try:  # a forged message can send anything: refused in one line, the state kept
            value = from_client(spec, shown, slider.start, slider.end)
        except SpinectlError as exc:
            self._refuse(exc)
            return
        self.errors["input"] = None
        self.state = replace(self.state, **{spec.field: value})
        self.update_point()
        if spec.field in LANDSCAPE_PARAMETERS and getattr(old, spec.field) != getattr(self.state, spec.field):
            self.refresh_landscapes()

    def _refuse(self, exc: SpinectlError) -> None:
        """A value from the page refused: say so in the status line, show the state's values again."""
        self.errors["input"] = printable(str(exc))
        self.preset.value = self.current
        self._show_state()
        self._show_status()

    def _on_preset(self, event) -> None:
        name = event.new
        if name == self.current:  # the selector set back after a refusal
            return
        if name not in self.models:
            try:  # a forged message can name any preset
                self.models[name] = load_preset(name)
            except SpinectlError as exc:
                self._refuse(exc)
                return
        self.current, self.errors["input"] = name, None
        self.base = self.models[name]
        point = (self.state.eccentricity, self.state.lordosis)
        self.state = replace(initial_state(self.base), eccentricity=point[0], lordosis=point[1])
        self._show_state()
        self.update_point()
        self.refresh_landscapes()

    def move_to(self, eccentricity: float, lordosis: float) -> None:
        """Move the point to (E, Lambda) [m], snapped to the sliders' steps and clipped to their ranges.

        Parameters
        ----------
        eccentricity, lordosis : float
            E and Lambda [m], e.g. where a landscape was clicked.
        """
        values = {}
        for field, value in (("eccentricity", eccentricity), ("lordosis", lordosis)):
            slider, spec = self.sliders[field], slider_for(field)
            try:  # a click's coordinates come from the page: a forged NaN is refused, not clipped
                shown = float(np.clip(real(spec.label, value) * spec.scale, slider.start, slider.end))
                values[field] = from_client(spec, shown, slider.start, slider.end)
            except SpinectlError as exc:
                self._refuse(exc)
                return
        self.errors["input"] = None
        self.state = replace(self.state, **values)
        self._show_state()
        self.update_point()

    def _show_state(self) -> None:
        for spec in SLIDERS:
            slider = self.sliders[spec.field]
            value = getattr(self.state, spec.field) * spec.scale
            slider.param.update(start=min(slider.start, value), end=max(slider.end, value), value=value)

    # --- views ----------------------------------------------------------------------------

    def update_point(self) -> float:
        """Recompute the numbers at the state and redraw every view of the point.

        Returns
        -------
        float
            Seconds taken [s] (also shown in the status line, or the error of a model that is invalid
            at this point; the views then keep the last point).
        """
        start = time.perf_counter()
        same_base = self.numbers is not None and self._numbers_base is self.base
        try:  # the chain's margin of the last point is reused where only the delay moved
            numbers = point_numbers(self.base, self.state, previous=self.numbers if same_base else None)
        except SpinectlError as exc:  # e.g. a fibre attachment on a CoR of a --config model: say so, keep the views
            self.errors["point"] = printable(str(exc))
            self._show_status()
            return time.perf_counter() - start
        self.errors["point"] = None
        key = (id(self.base), pictures_key(self.state))
        changed = key != self._pictures_key  # the delay and the lag move the margins only: redraw the rest if needed
        drawing = drawing_svg(numbers) if changed else None
        with pn.io.hold():
            self.numbers, self._numbers_base, self._pictures_key = numbers, self.base, key
            if changed:
                self.drawing.object = drawing
            for view in self.views.values():
                if changed or view.name == "delay_margins":
                    view.show(numbers)
            self.table.object = table_html(numbers)
            self.verdicts.object = verdicts_html(numbers)
            self._show_design()
            for view in self.maps.values():
                view.mark(self.state)
            self.seconds["point"] = time.perf_counter() - start
            self._show_status()
        return self.seconds["point"]

    def refresh_landscapes(self) -> None:
        """Solve the landscapes again, in a worker thread inside a server session; progress shows meanwhile.

        Outside a session (a notebook's first display, a test) they are solved at once.
        """
        self._generation += 1
        generation, state, base = self._generation, self.state, self.base
        self.progress.param.update(active=True, visible=True)
        for view in self.maps.values():
            view.pane.loading = True

        async def solve():
            start = time.perf_counter()
            dataset, error = None, "internal error (the server's log has the traceback)"
            try:
                dataset, error = await asyncio.to_thread(_solved, base, state)
            finally:  # a bug too stops the progress bar; its traceback goes to the server's log
                if generation == self._generation:  # a later change started another solve: show only that one
                    self._show_landscapes(dataset, time.perf_counter() - start, error)

        if not in_session():
            start = time.perf_counter()
            dataset, error = _solved(base, state)
            self._show_landscapes(dataset, time.perf_counter() - start, error)
            return
        self._show_status()
        pn.state.execute(solve)

    def run_design(self) -> None:
        """Answer the design question at the sliders' state: in a server session in a worker thread, with a spinner.

        Seconds (:func:`spinectl.explore.numbers.design_numbers`): the sliders stay free; an answer for
        a state the sliders have left is shown as such. Outside a session it is computed at once.
        """
        self._design_generation += 1
        generation, state, base, search = self._design_generation, self.state, self.base, self.design_search.value
        self.design_spinner.param.update(value=True, visible=True)
        self.design_button.disabled = True
        self.design_status.object = f"designing… the answer comes {DESIGN_PLACE}"

        async def solve():
            answer, error = None, "internal error (the server's log has the traceback)"
            try:
                answer, error = await asyncio.to_thread(_designed, base, state, search)
            finally:  # a bug too stops the spinner
                if generation == self._design_generation:
                    self._design_done(state, base, answer, error)

        if not in_session():
            self._design_done(state, base, *_designed(base, state, search))
            return
        pn.state.execute(solve)

    def _design_done(self, state: ExploreState, base: Model, answer: Design | None, error: str | None) -> None:
        with pn.io.hold():
            self.design_spinner.param.update(value=False, visible=False)
            self.design_button.disabled = False
            self.design_answer = None if answer is None else (state, base, answer)
            self.errors["design"] = error
            self.design_status.object = (
                f"design: status {answer.status}, {DESIGN_PLACE}"
                if answer is not None
                else f"design not found: {DESIGN_PLACE}"
            )
            self._show_design()

    def _show_design(self) -> None:
        """The last design answer, marked when the sliders have left its state; or its one-line error."""
        if self.errors["design"]:
            self.design.object = f"<p><b>design not found:</b> {html.escape(self.errors['design'])}</p>"
        elif self.design_answer is not None:
            state, base, answer = self.design_answer
            self.design.object = design_html(answer, state, state == self.state and base is self.base)

    def _show_landscapes(self, dataset: xr.Dataset | None, elapsed: float, error: str | None = None) -> None:
        """Show the landscapes solved, or keep the last ones (each titled with its own mass and K) and the error."""
        with pn.io.hold():
            if dataset is not None:
                self.dataset = dataset
            for view in self.maps.values():
                if dataset is not None:
                    view.show(dataset, self.state)
                view.pane.loading = False
            self.progress.param.update(active=False, visible=False)
            self.seconds["landscapes"] = elapsed
            self.errors["landscapes"] = error
            self._show_status()

    def _show_status(self) -> None:
        self.status.object = status_text(self.seconds, self.errors, self.progress.active)


def in_session() -> bool:
    """Whether the code runs in a server session (a browser tab), not in a notebook's first display or a test.

    Returns
    -------
    bool
    """
    return pn.state.curdoc is not None and pn.state.curdoc.session_context is not None


def status_text(seconds: dict[str, float], errors: dict[str, str | None], solving: bool) -> str:
    """The status line: a refused input, the point's time or error, the landscapes' time, progress or error.

    Parameters
    ----------
    seconds : dict
        ``point`` and ``landscapes``: the last times taken [s].
    errors : dict
        ``input``, ``point``, ``landscapes``: one-line errors, or None.
    solving : bool
        The landscapes are being solved.

    Returns
    -------
    str
        Markdown, e.g. ``point updated in 0.15 s; landscapes (41 × 41) solved in 0.68 s``.
    """
    point = f"point updated in {seconds['point']:.2f} s"
    if errors["point"]:
        point = f"**point not shown:** {html.escape(errors['point'])}"
    maps = "solving…" if solving else f"solved in {seconds['landscapes']:.2f} s"
    if errors["landscapes"] and not solving:
        maps = f"**not solved:** {html.escape(errors['landscapes'])}"
    text = f"{point}; landscapes ({LANDSCAPE_POINTS} × {LANDSCAPE_POINTS}) {maps}"
    return f"**refused:** {html.escape(errors['input'])}; {text}" if errors["input"] else text


def _designed(base: Model, state: ExploreState, search: bool) -> tuple[Design | None, str | None]:
    """The design answer of :func:`spinectl.explore.numbers.design_numbers`, or its one-line error."""
    try:
        return design_numbers(base, state, search), None
    except SpinectlError as exc:
        return None, printable(str(exc))


def _solved(base: Model, state: ExploreState) -> tuple[xr.Dataset | None, str | None]:
    """The landscapes of :func:`spinectl.explore.numbers.landscapes`, or the one-line error of a model invalid
    at one of their points (e.g. a fibre attachment on a CoR at E = Lambda = 0)."""
    try:
        return landscapes(base, state), None
    except SpinectlError as exc:
        return None, printable(str(exc))


BAR_VIEWS = {
    "counter_torques": (views.counter_torque_data, "CT [N m]"),
    "delay_margins": (views.delay_margin_data, "delay margin [ms]"),
}
"""The bar views of the point: their data function (:mod:`spinectl.explore.views`) and value axis."""


def _small_figure(x_range, y_range, **options):
    figure = bokeh_figure(
        width=VIEW_PIXELS[0],
        height=VIEW_PIXELS[1],
        x_range=x_range,
        y_range=y_range,
        tools="",
        toolbar_location=None,
        **options,
    )
    figure.title.text_font_size = "8pt"
    return figure


def _hex(columns: dict) -> dict:
    """The columns with matplotlib's colour names as hex, which Bokeh reads."""
    return {**columns, "colour": [to_hex(c) for c in columns["colour"]]}


class ClientSelect(pn.widgets.Select):
    """Panel's ``Select`` that takes from the page only one of its options; anything else is refused in one line.

    Panel maps the page's value to an option where it takes it (``_process_property_change``) and
    raises there on any other, a traceback in the server's log (a forged message can send anything).
    Here such a value is dropped before that and given to ``on_refused``; the widget keeps its value.

    Parameters
    ----------
    on_refused : callable
        Called with the :class:`~spinectl.errors.ParameterError` that names the field and the options.
    **params
        Those of ``panel.widgets.Select``; ``label`` names the field in the message.
    """

    def __init__(self, on_refused, **params):
        super().__init__(**params)
        self._on_refused = on_refused

    def _process_property_change(self, props: dict) -> dict:
        if "value" in props:
            try:
                choice(self.label or self.name, props["value"], self.labels)
            except SpinectlError as exc:
                props = {key: value for key, value in props.items() if key != "value"}
                self._on_refused(exc)
        return super()._process_property_change(props)


class _EigenvalueView:
    """Both eigenvalues of each segment as markers in the complex plane (Bokeh), the unstable half shaded."""

    name = "eigenvalues"

    def __init__(self):
        self.source = ColumnDataSource({"segment": [], "colour": [], "re": [], "im": []})
        self.figure = _small_figure(
            Range1d(-1, 1), Range1d(-1, 1), x_axis_label="Re λ [1/s]", y_axis_label="Im λ [1/s]"
        )
        self.figure.add_layout(BoxAnnotation(left=0, fill_color="red", fill_alpha=0.08, line_alpha=0))
        for dimension in ("width", "height"):
            self.figure.add_layout(Span(location=0, dimension=dimension, line_color="gray", line_width=0.8))
        self.figure.scatter(
            "re", "im", source=self.source, marker="x", size=10, line_width=2, color="colour", legend_field="segment"
        )
        self.figure.width += EIGENVALUE_LEGEND_PIXELS
        self.figure.add_layout(self.figure.legend[0], "right")  # beside the plane: it hid eigenvalues inside
        self.figure.legend.label_text_font_size = "8pt"
        self.pane = pn.pane.Bokeh(self.figure, name=self.name)

    def show(self, numbers: PointNumbers) -> None:
        data = views.eigenvalue_data(numbers)
        self.source.data = _hex(data.columns)
        for axis in (self.figure.x_range, self.figure.y_range):
            axis.update(start=data.limits[0], end=data.limits[1])
        self.figure.title.text = data.title.replace(" (", "\n(", 1)  # two lines: one is wider than the view


class _BarView:
    """Bars per segment (Bokeh): the counter torques with the local muscles' band, or the delay margins and tau."""

    def __init__(self, name: str):
        self.name = name
        self.data_of, label = BAR_VIEWS[name]
        self.source = ColumnDataSource({"segment": [], "colour": [], "value": [], "mark": []})
        self.figure = _small_figure(FactorRange(), Range1d(0, 1), y_axis_label=label)
        self.figure.add_layout(Span(location=0, dimension="width", line_color="gray", line_width=0.8))
        if name == "counter_torques":  # the local muscles' +-30 N m (paper, Discussion)
            band = BoxAnnotation(bottom=-CT_LIMIT, top=CT_LIMIT, fill_color="green", fill_alpha=0.12, line_alpha=0)
            self.figure.add_layout(band)
        self.line = Span(location=0, dimension="width", line_color="black", line_dash="dashed", visible=False)
        self.figure.add_layout(self.line)
        self.figure.vbar(x="segment", top="value", width=0.8, color="colour", source=self.source)
        self.figure.text(x="segment", y=0, text="mark", source=self.source, text_align="center", text_font_size="9pt")
        self.pane = pn.pane.Bokeh(self.figure, name=name)

    def show(self, numbers: PointNumbers) -> None:
        data = self.data_of(numbers)
        self.figure.x_range.factors = list(data.columns["segment"])
        self.source.data = _hex(data.columns)
        self.figure.y_range.update(start=data.limits[0], end=data.limits[1])
        self.line.update(location=data.line or 0.0, visible=data.line is not None)
        self.figure.title.text = data.title.replace(" (", "\n(", 1)  # two lines: one is wider than the view


class _LandscapeView:
    """One landscape as a Bokeh image, the point marked; a click moves the point."""

    def __init__(self, variable: str, on_click):
        self.variable = variable
        axis = landscape_axis() * CM_PER_M
        span = (float(axis[0]), float(axis[-1]))
        self.mapper = LinearColorMapper(palette="Viridis256", nan_color="lightgray")
        self.image = ColumnDataSource({"image": [np.full((2, 2), np.nan)]})
        self.marker = ColumnDataSource({"x": [np.nan], "y": [np.nan]})
        self.figure = bokeh_figure(
            width=LANDSCAPE_PIXELS + 80,
            height=LANDSCAPE_PIXELS,
            x_range=span,
            y_range=span,
            title=views.LANDSCAPE_LABELS[variable] + "\nclick to move the point",
            x_axis_label="E [cm]",
            y_axis_label="Λ [cm]",
            tools="tap",
            toolbar_location=None,
            match_aspect=True,
        )
        self.glyph = self.figure.image(
            "image",
            source=self.image,
            x=span[0],
            y=span[0],
            dw=span[1] - span[0],
            dh=span[1] - span[0],
            color_mapper=self.mapper,
        )
        self.figure.scatter("x", "y", source=self.marker, size=11, fill_color="white", line_color="black")
        self.figure.add_layout(ColorBar(color_mapper=self.mapper, width=10), "right")
        self.figure.on_event(Tap, lambda event: on_click(event.x / CM_PER_M, event.y / CM_PER_M))
        self.pane = pn.pane.Bokeh(self.figure, name=variable)

    def show(self, dataset: xr.Dataset, state: ExploreState) -> None:
        e, lam = (dataset[name].values * CM_PER_M for name in ("E", "Lambda"))
        half_e, half_l = (np.diff(a).mean() / 2 if a.size > 1 else 0.5 for a in (e, lam))
        values = dataset[self.variable].values.T  # Bokeh: rows are y (Lambda)
        self.glyph.glyph.update(
            x=e[0] - half_e, y=lam[0] - half_l, dw=e[-1] - e[0] + 2 * half_e, dh=lam[-1] - lam[0] + 2 * half_l
        )
        finite = values[np.isfinite(values)]
        if finite.size:
            self.mapper.update(low=float(finite.min()), high=float(finite.max()))
        self.image.data = {"image": [values]}
        mass, stiffness = (shown_text(slider_for(f), getattr(state, f)) for f in ("mass", "stiffness"))
        self.figure.title.text = f"{views.LANDSCAPE_LABELS[self.variable]}\nmass {mass} kg, K {stiffness} N m/rad"
        self.mark(state)

    def mark(self, state: ExploreState) -> None:
        self.marker.data = {"x": [state.eccentricity * CM_PER_M], "y": [state.lordosis * CM_PER_M]}


def explorer(preset: str | None = None, config=None) -> pn.viewable.Viewable:
    """The explorer's layout for a notebook or a server: ``explorer("wagner2012")`` in a cell.

    Parameters
    ----------
    preset : str, optional
        A built-in preset (default 'default').
    config : str or path-like, optional
        A model file, read once (:func:`spinectl.model.config.load_config`).

    Returns
    -------
    panel.viewable.Viewable
        The layout (call ``panel.extension()`` first in a notebook).

    Raises
    ------
    ConfigError, ParameterError
        A bad preset or configuration file.
    """
    from ..model.config import load_config

    model = load_config(config, preset)
    return Explorer(model, CONFIG_CHOICE if config else (preset or DEFAULT_PRESET)).layout
