"""The model drawing: its geometry read back from the Figure's artists, mirrored models, widths, torques, files."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.image import imread

from spinectl.canvas import new_figure
from spinectl.errors import ParameterError
from spinectl.model import geometry
from spinectl.model.params import Model
from spinectl.model.stability import segment_stability
from spinectl.paper import drawing, figures

CM = 100.0


def _artists(fig: Figure) -> dict:
    """Every artist of the figure's first axes that has a gid, by gid."""
    ax = fig.axes[0]
    found = {}
    for artist in [*ax.lines, *ax.patches, *ax.texts]:
        if artist.get_gid():
            found[artist.get_gid()] = artist
    return found


def _xy(line) -> np.ndarray:
    return np.column_stack([line.get_xdata(), line.get_ydata()]) / CM


def _fibres(fig: Figure, model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Upper and lower ends [m] of every fibre, in the order of geometry.all_fibres."""
    artists = _artists(fig)
    ends = [
        _xy(artists[f"fibre {name} {i}"])
        for pair, names in zip(model.muscles, np.reshape(model.muscle_names, (-1, 2)), strict=True)
        for name in names
        for i in range(pair.fibres)
    ]
    return np.array([e[0] for e in ends]), np.array([e[1] for e in ends])


@pytest.mark.parametrize(("e", "lam"), [(0.03, 0.04), (0.08, 0.0), (0.0, 0.08), (-0.02, 0.05)])
def test_cors_and_attachments_read_back_match_the_geometry(model, e, lam):
    """CoRs against geometry.cor_positions and the closed form x = -E + Lambda phi (docs/model.md,
    phi = 1.5 s - 0.5 s^3 with natural ends); fibre ends against geometry.all_fibres; mass at (0, 0.326 m)."""
    fig = drawing.draw_model(model, e, lam)
    artists = _artists(fig)
    cors = _xy(artists[drawing.GIDS["cor"]])
    np.testing.assert_allclose(cors, geometry.cor_positions(e, lam, model.geometry), rtol=0, atol=1e-12)
    y = np.array([0.145, 0.106, 0.072, 0.035, 0.005])
    s = 1 - np.abs(y - 0.088) / 0.088
    np.testing.assert_allclose(cors[:, 0], -e + lam * (1.5 * s - 0.5 * s**3), rtol=0, atol=1e-12)
    upper, lower = _fibres(fig, model)
    want_upper, want_lower, _ = geometry.all_fibres(model)
    np.testing.assert_allclose(upper, want_upper, rtol=0, atol=1e-12)
    np.testing.assert_allclose(lower, want_lower, rtol=0, atol=1e-12)
    np.testing.assert_allclose(_xy(artists[drawing.GIDS["mass"]]), [[0.0, 0.326]], rtol=0, atol=1e-12)
    spline = _xy(artists[drawing.GIDS["spline"]])  # P1, P3, P2 from the paper's definition of E and Lambda
    np.testing.assert_allclose(spline, [[-e, 0.176], [-e + lam, 0.088], [-e, 0.0]], rtol=0, atol=1e-12)


def test_the_straight_pair_in_closed_form(model):
    """Default straight pair: vertical fibres at x = +-(0.12 + linspace(-0.015, 0.015, 5)) m from y = 0.24 to 0 m."""
    upper, lower = _fibres(drawing.draw_model(model, 0.03, 0.04), model)
    x = 0.12 + np.linspace(-0.015, 0.015, 5)
    np.testing.assert_allclose(np.sort(upper[:10, 0]), np.sort(np.concatenate([x, -x])), atol=1e-12)
    np.testing.assert_allclose(upper[:10, 1], 0.24, atol=1e-12)
    np.testing.assert_allclose(lower[:10, 1], 0.0, atol=1e-12)
    np.testing.assert_allclose(upper[:10, 0], lower[:10, 0], atol=1e-12)


def _mirror_of(a: np.ndarray) -> np.ndarray:
    return a * np.array([-1.0, 1.0])


@pytest.mark.parametrize(("e", "lam"), [(0.03, 0.04), (0.0, 0.05)])
def test_mirrored_models_give_mirrored_drawings(model, e, lam):
    """(E, Lambda) and (-E, -Lambda) are mirror images in x = 0 (the muscles are symmetric, docs/model.md);
    with E = 0 (the coronal plane) a scoliosis to the left mirrors one to the right."""
    one, other = _artists(drawing.draw_model(model, e, lam)), _artists(drawing.draw_model(model, -e, -lam))
    for gid in (drawing.GIDS["spine"], drawing.GIDS["cor"], drawing.GIDS["spline"]):
        np.testing.assert_allclose(_xy(other[gid]), _mirror_of(_xy(one[gid])), atol=1e-12)
    vertebrae = [gid for gid in one if gid.startswith("vertebra")]
    assert len(vertebrae) == 5
    for gid in vertebrae:  # a mirrored rectangle: the same corners, x negated (in reversed order)
        mine, theirs = one[gid].get_xy()[:4] / CM, other[gid].get_xy()[:4] / CM
        np.testing.assert_allclose(sorted(map(tuple, theirs)), sorted(map(tuple, _mirror_of(mine))), atol=1e-12)


def test_line_widths_are_proportional_to_the_given_pcsa(model):
    """PCSA 10, 5, 0 cm² per pair: the straight pair at MAX_WIDTH, the outer oblique at half of it, the inner idle."""
    fig = drawing.draw_model(model, 0.03, 0.04, pcsa=np.array([10.0, 5.0, 0.0]) * 1e-4)
    artists = _artists(fig)
    for side in ("ventral", "dorsal"):
        assert artists[f"fibre straight_{side} 0"].get_linewidth() == pytest.approx(drawing.MAX_WIDTH)
        assert artists[f"fibre oblique_outer_{side} 4"].get_linewidth() == pytest.approx(drawing.MAX_WIDTH / 2)
        assert artists[f"fibre oblique_inner_{side} 2"].get_linestyle() == ":"


def test_counter_torque_arrows_are_scaled_in_newton_metres(model):
    """Each arrow runs from its CoR, TORQUE_SCALE m per N m of CT_k (segment_stability) towards -x for CT_k > 0."""
    pcsa = np.array([10.0, 5.0, 1.0]) * 1e-4
    fig = drawing.draw_model(model, 0.03, 0.04, pcsa=pcsa, counter_torque=True)
    torques = segment_stability(model, 0.03, 0.04, pcsa).counter_torque
    cors = geometry.cor_positions(0.03, 0.04, model.geometry)
    artists = _artists(fig)
    for name, cor, torque in zip(model.geometry.cor_names, cors, torques, strict=True):
        arrow = artists[f"counter torque {name}"]
        start, end = np.array(arrow.xyann) / CM, np.array(arrow.xy) / CM
        np.testing.assert_allclose(start, cor, atol=1e-12)
        np.testing.assert_allclose(end - start, [-torque * drawing.TORQUE_SCALE, 0.0], atol=1e-12)


def test_counter_torque_arrows_are_curved_as_torques_are_drawn(model):
    """A torque is drawn as an arc, not as a straight arrow (which reads as a force): from the CoR to the tip
    over an arc above them, counter-clockwise for CT_k > 0 (going to -x), clockwise for CT_k < 0 (to +x). Its
    height over the chord: TORQUE_RISE, or a quarter of a short chord, measured on the drawn path (the
    quadratic Bezier of matplotlib's arc3 rises half its control point's offset)."""
    fig = drawing.draw_model(model, 0.08, 0.08, pcsa="optimum", counter_torque=True)
    fig.draw_without_rendering()
    ax, artists, T = fig.axes[0], _artists(fig), np.linspace(0, 1, 41)
    checked = 0
    for name in model.geometry.cor_names:
        arrow = artists[f"counter torque {name}"]
        start, end = np.array(arrow.xyann), np.array(arrow.xy)  # [cm]
        chord = abs(end[0] - start[0])
        if chord < 4 * drawing.TORQUE_RISE * CM:
            continue  # the head is as large as the arc
        curve = [point for segment, _ in arrow.arrow_patch.get_path().iter_bezier() for point in segment(T)]
        path = ax.transData.inverted().transform(np.array(curve))  # the drawn curve, not its control points
        along = path[(path[:, 0] - start[0]) * (end[0] - start[0]) > 0]  # the arc, without the start
        rise = along[:, 1].max() - start[1]
        assert rise == pytest.approx(drawing.TORQUE_RISE * CM, rel=0.15), name
        assert along[:, 1].min() > start[1] - 0.3, name  # above the chord: the head dips a little at the tip
        checked += 1
    assert checked >= 2


def test_the_optimum_is_the_default_activation_of_the_cli_and_is_named(model):
    fig = drawing.draw_model(model, 0.03, 0.04, pcsa="optimum")
    assert "the optimum (solve_point)" in fig.axes[0].get_title()
    assert "no activation" in drawing.draw_model(model, 0.03, 0.04).axes[0].get_title()


def test_draws_into_given_axes_and_refuses_torques_without_activation(model):
    fig = new_figure()
    ax = fig.add_subplot()
    assert drawing.draw_model(model, 0.0, 0.0, ax=ax, annotate=False) is fig and ax.get_xticks().size == 0
    assert ax.get_aspect() == 1.0 and plt.get_fignums() == []
    with pytest.raises(ParameterError, match="counter_torque"):
        drawing.draw_model(model, 0.0, 0.0, counter_torque=True)
    with pytest.raises(ParameterError, match="pcsa"):
        drawing.draw_model(model, 0.0, 0.0, pcsa="best")


def test_png_pdf_and_svg_files(model, tmp_path):
    """PNG: many colours, not blank; SVG parses as XML; PDF: its header and one page."""
    fig = drawing.draw_model(model, 0.03, 0.04, pcsa="optimum", counter_torque=True)
    png, pdf, svg = (figures.save_figure(fig, tmp_path / f"model.{kind}") for kind in ("png", "pdf", "svg"))
    image = imread(png)
    assert image.std() > 0.05 and len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 20
    assert ET.parse(svg).getroot().tag.endswith("svg")
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF-") and data.count(b"/Type /Page\n") + data.count(b"/Type /Page ") == 1
    with pytest.raises(ParameterError, match="--out"):
        figures.save_figure(fig, tmp_path / "model.txt")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.pdf", "model.png", "model.svg"]


def _extent(text, renderer):
    """A label's extent on the canvas [px], its box included."""
    box = text.get_bbox_patch()
    return box.get_window_extent(renderer) if box is not None else text.get_window_extent(renderer)


@pytest.mark.parametrize(("e", "lam"), [(0.03, 0.04), (0.0, 0.0), (0.08, 0.08), (0.02, 0.0)])
def test_counter_torque_labels_clear_the_cor_labels(model, e, lam):
    """No counter torque's label overlaps a CoR's label, measured by the renderer (their drawn extents);
    at a TORQUE_LABEL_OFFSET of 3 pt they touched (before commit d70c8d2 put them 8 pt above their arrows)."""
    fig = drawing.draw_model(model, e, lam, pcsa="optimum", counter_torque=True)
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    artists = _artists(fig)
    cor_labels = [_extent(artists[f"cor label {name}"], renderer) for name in model.geometry.cor_names]
    torque_labels = [_extent(artists[f"counter torque label {name}"], renderer) for name in model.geometry.cor_names]
    for torque in torque_labels:
        assert not any(torque.overlaps(cor) for cor in cor_labels)


@pytest.mark.parametrize(("e", "lam"), [(0.03, 0.04), (0.0, 0.0), (0.08, 0.08), (0.02, 0.0), (0.0, 0.08)])
def test_counter_torque_labels_touch_no_vertebra_arrow_or_point_label(model, e, lam):
    """Measured by the renderer: no counter torque's label overlaps a vertebra, a counter-torque arrow, the
    labels of P1, P3, P2 or another torque label. Above each arrow's middle (before) the labels of L2L3 and
    L3L4 touched a vertebra and the label of P3 at E = 3, Lambda = 4 cm (the newcomer's trial)."""
    fig = drawing.draw_model(model, e, lam, pcsa="optimum", counter_torque=True)
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    artists = _artists(fig)
    names = model.geometry.cor_names
    labels = [_extent(artists[f"counter torque label {name}"], renderer) for name in names]
    others = [
        *(artists[g].get_window_extent(renderer) for g in artists if g.startswith("vertebra ")),
        *(artists[f"counter torque {name}"].arrow_patch.get_window_extent(renderer) for name in names),
        *(_extent(artists[f"point label {p}"], renderer) for p in ("P1", "P3", "P2")),
    ]
    assert len(others) == 2 * len(names) + 3
    for k, label in enumerate(labels):
        assert not any(label.overlaps(other) for other in others), names[k]
        assert not any(label.overlaps(other) for other in labels[k + 1 :]), names[k]


@pytest.mark.parametrize(("e", "lam"), [(0.03, 0.04), (0.08, 0.08), (0.02, 0.0), (0.0, 0.08), (0.08, 0.0)])
def test_cor_labels_clear_every_arrow(model, e, lam):
    """Measured by the renderer: no CoR's label lies on a counter-torque arrow or a torque label, nor on the
    labels of P1, P3, P2. Left of its CoR (before) the label of L5S1 lay on its own arrow wherever CT > 0
    (at E = 3, Lambda = 4 cm the optimum's CT of L5S1 is +24 N m; segment_stability)."""
    fig = drawing.draw_model(model, e, lam, pcsa="optimum", counter_torque=True)
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    artists = _artists(fig)
    names = model.geometry.cor_names
    others = [
        *(artists[f"counter torque {name}"].arrow_patch.get_window_extent(renderer) for name in names),
        *(_extent(artists[f"counter torque label {name}"], renderer) for name in names),
        *(_extent(artists[f"point label {p}"], renderer) for p in ("P1", "P3", "P2")),
    ]
    for name in names:
        label = _extent(artists[f"cor label {name}"], renderer)
        assert not any(label.overlaps(other) for other in others), name


@pytest.mark.parametrize(("e", "lam", "pcsa"), [(0.08, 0.0, 2.5e-3), (0.0, 0.08, 1.5e-3), (0.08, 0.08, 4e-3)])
def test_the_labels_of_long_arrows_stay_inside_the_frame(model, e, lam, pcsa):
    """Counter torques of about 100 N m and more (20 cm arrows and longer): every torque label and CoR label
    lies whole inside the axes, measured by the renderer (before: the labels of long arrows crossed the
    frame; the limits held the arrows' tips, not the labels beyond them)."""
    given = np.full(3, pcsa)
    torques = segment_stability(model, e, lam, given).counter_torque
    assert np.abs(torques).max() >= 90.0  # the long arrows this test is about
    fig = drawing.draw_model(model, e, lam, pcsa=given, counter_torque=True)
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    frame = fig.axes[0].get_window_extent(renderer)
    artists = _artists(fig)
    for name in model.geometry.cor_names:
        for gid in (f"counter torque label {name}", f"cor label {name}"):
            box = _extent(artists[gid], renderer)
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1, gid


def test_the_x_label_names_the_planes_own_side():
    """The drawing's x label read "ventral / right →" for every model: it names the +x side of the model's own
    plane (geometry.side_names[0]): "right" for examples/coronal.toml, "ventral" for the sagittal preset."""
    from pathlib import Path

    from spinectl.model.config import load_config

    coronal = load_config(str(Path(__file__).resolve().parents[2] / "examples" / "coronal.toml"))
    assert coronal.geometry.side_names[0] == "right"  # the premise: the example's own words
    label = drawing.draw_model(coronal, 0.0, 0.02).axes[0].get_xlabel()
    assert label == "x [cm] (right →)" and "ventral" not in label
    assert drawing.draw_model(Model(), 0.03, 0.04).axes[0].get_xlabel() == "x [cm] (ventral →)"
