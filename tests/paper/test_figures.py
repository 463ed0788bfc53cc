"""Figures: returned without writing, saved as a separate step, non-trivial, named after the paper's figures;
the plot command."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.image import imread

from spinectl.cli import main
from spinectl.errors import ParameterError
from spinectl.landscape import netcdf, sweep
from spinectl.model.params import Model
from spinectl.paper import figures

AXIS = np.linspace(0.0, 0.08, 5)


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    path = tmp_path_factory.mktemp("plot") / "r.nc"
    return netcdf.save(sweep.stiffness_sweep(Model(), [0.0, 15.0], AXIS, AXIS, progress=False), path)


def _non_trivial(path):
    """A real figure: tens of kB of PNG and many distinct colours, not a blank canvas."""
    image = imread(path)
    coarse = (image[..., :3] * 15.99).astype(np.int64).reshape(-1, 3) @ np.array([256, 16, 1])  # 4 bits a channel
    colours = np.count_nonzero(np.bincount(coarse, minlength=4096))
    return path.stat().st_size > 20_000 and image.std() > 0.05 and colours > 20


def test_figures_3_4_and_s1_are_drawn(results, tmp_path):
    written = figures.draw_figures(netcdf.load(results), tmp_path, Model().fibre.specific_tension)
    names = sorted(p.name for p in written)
    assert names == sorted([*figures.figure_names(0.0), *figures.figure_names(15.0)])
    assert "figS1_min_pcsa_K15.png" in names
    assert all(_non_trivial(p) for p in written)


def test_figure_functions_return_figures_and_write_nothing(results, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    k0 = netcdf.load(results).sel(K=0.0)
    drawn = [figures.min_pcsa_figure(k0), figures.counter_torque_figure(k0, Model().fibre.specific_tension)]
    assert all(isinstance(f, Figure) for f in drawn) and [len(f.axes) for f in drawn] == [1, 1]
    assert [len(f.axes[0].child_axes) for f in drawn] == [1, 1]  # the colour bar, inside the axes' frame
    assert drawn[0].axes[0].get_title().startswith("Fig. 3: minimum PCSA")
    assert list(tmp_path.iterdir()) == [] and plt.get_fignums() == []
    path = figures.save_figure(drawn[0], tmp_path / "f.png")
    assert _non_trivial(path) and [p.name for p in tmp_path.iterdir()] == ["f.png"]


def test_draw_figures_reads_the_specific_tension_of_the_dataset(results, tmp_path):
    """Without it, Figure 4's scale is that of the model the sweep ran with: the same PNG bytes."""
    dataset = netcdf.load(results).sel(K=0.0)
    given = figures.draw_figures(dataset, tmp_path / "given", Model().fibre.specific_tension)
    default = figures.draw_figures(dataset, tmp_path / "default")
    assert [p.read_bytes() for p in default] == [p.read_bytes() for p in given]


def test_plot_command(results, tmp_path, capsys):
    assert main(["plot", str(results), "--out", str(tmp_path / "figs")]) == 0
    printed = capsys.readouterr().out.split()
    assert len(printed) == 4 and all(_non_trivial(tmp_path / "figs" / p.split("/")[-1]) for p in printed)


def test_plot_command_missing_file(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "none.nc"), "--out", str(tmp_path)]) == 2
    assert "results: file not found" in capsys.readouterr().err


GRIDS = {
    "partial": (np.linspace(0.02, 0.06, 3), np.linspace(0.01, 0.05, 3)),
    "offset": (np.linspace(0.02, 0.10, 4), np.linspace(-0.03, 0.01, 3)),
    "non-square": (np.linspace(0.0, 0.08, 4), np.linspace(0.0, 0.01, 3)),
}
"""Grids that are not the paper's 0-8 cm: inside it, shifted past its edges, and 8:1."""


@pytest.fixture(scope="module")
def other_grids():
    return {name: sweep.sweep(Model(), e, lam, progress=False) for name, (e, lam) in GRIDS.items()}


def _inside_axes(fig):
    """Whether every marker lies inside the axes' limits and the (at least 4) labels of the positions and corners
    inside the axes' box, once drawn (the contour lines' labels are clipped to the axes)."""
    fig.canvas.draw()
    ax = fig.axes[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    for line in ax.lines:
        if line.get_gid() and (line.get_gid().startswith("position") or line.get_gid() == "optimum"):
            x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
            if not (np.all((x0 - 1e-9 <= x) & (x <= x1 + 1e-9)) and np.all((y0 - 1e-9 <= y) & (y <= y1 + 1e-9))):
                return False
    box = ax.get_window_extent()
    labels = [t.get_window_extent() for t in ax.texts if (t.get_gid() or "").startswith("label")]
    return len(labels) >= 4 and all(
        box.x0 - 1 <= b.x0 and b.x1 <= box.x1 + 1 and box.y0 - 1 <= b.y0 and b.y1 <= box.y1 + 1 for b in labels
    )


@pytest.mark.parametrize("name", sorted(GRIDS))
def test_any_grid_keeps_every_marker_inside_and_the_axes_unsqueezed(other_grids, name):
    """Positions A-D only where inside (B = (8, 0) cm lies in the offset and the non-square grid), the other corners
    by their coordinates; equal scales unless one axis spans more than twice the other (8:1 here)."""
    dataset = other_grids[name]
    for fig in (figures.min_pcsa_figure(dataset), figures.counter_torque_figure(dataset, 2.5e5)):
        assert _inside_axes(fig)
        ax = fig.axes[0]
        assert (ax.get_aspect() == 1.0) == (name != "non-square")
        e, lam = GRIDS[name]
        assert ax.get_xlim() == pytest.approx((e[0] * 100, e[-1] * 100))
        assert ax.get_ylim() == pytest.approx((lam[0] * 100, lam[-1] * 100))
    labels = [label for label, _ in figures.grid_marks(*GRIDS[name])]
    assert ("B" in labels) == (name != "partial") and "A" not in labels[1:] and len(labels) >= 4
    if name == "offset":
        assert labels == ["B", "2, -3 cm", "10, -3 cm", "10, 1 cm", "2, 1 cm"]


def test_the_paper_grid_marks_a_to_d_at_its_corners_the_ridge_and_the_optimum(results):
    """On 0-8 cm: A, B and D at the corners (paper, Results), C at Figure 3's interior point (3, 4) cm with the
    star (paper, Discussion), the corner (8, 8) cm by its coordinates; Lambda = 1.7 E from (0, 0) to (8/1.7, 8) cm."""
    fig = figures.min_pcsa_figure(netcdf.load(results).sel(K=0.0))
    assert _inside_axes(fig)
    lines = {line.get_gid(): line for line in fig.axes[0].lines if line.get_gid()}
    assert {g for g in lines if g.startswith("position")} == {f"position {p}" for p in ("A", "B", "C", "D", "8, 8 cm")}
    np.testing.assert_allclose(lines["ridge"].get_xdata(), [0.0, 8 / 1.7])
    np.testing.assert_allclose(lines["ridge"].get_ydata(), [0.0, 8.0])
    np.testing.assert_allclose(np.ravel(lines["optimum"].get_xydata()), [3.0, 4.0])
    np.testing.assert_allclose(np.ravel(lines["position C"].get_xydata()), [3.0, 4.0])
    assert fig.axes[0].texts  # the contour lines' labels and A-D


def test_titles_name_the_convention_not_a_bare_word(results):
    """K's unit follows its convention (docs/model.md, "Passive stiffness: two conventions"): N m/rad under
    'physical', 1/s² under eq. 2 as printed, where it adds K theta_k [N m/rad] (before: N m/rad for both)."""
    dataset = netcdf.load(results)
    k0 = figures.min_pcsa_figure(dataset.sel(K=0.0)).axes[0].get_title()
    k15 = figures.min_pcsa_figure(dataset.sel(K=15.0)).axes[0].get_title()
    assert "K = 0" in k0 and "convention" not in k0
    assert "K convention: physical" in k15 and "(physical)" not in k15 and "(paper)" not in k15
    printed = figures.min_pcsa_figure(dataset.sel(K=15.0).assign_attrs(passive_convention="paper"))
    assert "K = 15 1/s² (K convention: eq. 2 as printed)" in printed.axes[0].get_title().replace("\n", " ")
    assert "K = 15 N m/rad (K convention: physical" in k15.replace("\n", " ")


def test_shared_scale_and_given_range(results, tmp_path, monkeypatch):
    """With shared_scale both minimum-PCSA figures get the range over K = 0 and 15 (numpy's nanmin, nanmax);
    a given vmin/vmax sets the colour bar's ends."""
    dataset = netcdf.load(results)
    seen = []
    original = figures.min_pcsa_figure

    def spy(part, vmin=None, vmax=None, insets=False):
        seen.append((vmin, vmax))
        return original(part, vmin, vmax, insets)

    monkeypatch.setattr(figures.sets, "min_pcsa_figure", spy)  # where figure_set looks it up
    figures.draw_figures(dataset, tmp_path, options=figures.FigureOptions(shared_scale=True))
    values = dataset["min_pcsa_cm2"].values
    assert seen == [(np.nanmin(values), np.nanmax(values))] * 2
    fig = original(dataset.sel(K=0.0), 20.0, 80.0)
    assert _colour_bar(fig).get_ylim() == pytest.approx((20.0, 80.0))
    with pytest.raises(ParameterError, match="vmin"):
        original(dataset.sel(K=0.0), 50.0, 40.0)


def _colour_bar(fig: Figure):
    """The colour bar of a landscape figure: an inset of its first axes."""
    return fig.axes[0].child_axes[0]


def test_colour_bar_as_tall_as_the_axes(results):
    """The colour bar spans the drawn axes exactly (figures.COLOUR_BAR), not the figure's height, also on a
    non-square grid where equal scales shorten the axes."""
    dataset = netcdf.load(results).sel(K=0.0)
    for part in (dataset, dataset.isel(Lambda=slice(0, max(2, dataset.sizes["Lambda"] // 2)))):
        fig = figures.min_pcsa_figure(part)
        fig.canvas.draw()
        axes, bar = fig.axes[0].get_window_extent(), _colour_bar(fig).get_window_extent()
        assert (bar.y0, bar.y1) == pytest.approx((axes.y0, axes.y1), abs=0.5) and bar.x0 > axes.x1


def test_ratio_map_and_insets(results, tmp_path, other_grids):
    """The ratio S1 / 3 on round levels over its range (numpy's nanmin, nanmax); insets: four model drawings around
    Figure 3; both need what they need."""
    dataset = netcdf.load(results)
    ratio = figures.ratio_figure(dataset)
    values = (dataset["min_pcsa_cm2"].sel(K=15.0) / dataset["min_pcsa_cm2"].sel(K=0.0)).values
    low, high = _colour_bar(ratio).get_ylim()
    assert low <= np.nanmin(values) < np.nanmax(values) <= high and "halving" in ratio.axes[0].get_title()
    inset = figures.min_pcsa_figure(dataset.sel(K=0.0), insets=True)
    titles = sorted(ax.get_title() for ax in inset.axes[1:])
    # C is Figure 3's interior point (3, 4) cm, so the corner (8, 8) cm is drawn under its coordinates
    assert titles == ["A: E = 0, Λ = 0 cm", "B: E = 8, Λ = 0 cm", "D: E = 0, Λ = 8 cm", "E = 8, Λ = 8 cm"]
    with pytest.raises(ParameterError, match="K = 0"):
        figures.ratio_figure(other_grids["partial"])
    with pytest.raises(ParameterError, match="--ratio"):
        figures.draw_figures(other_grids["partial"], tmp_path, options=figures.FigureOptions(ratio=True))
    assert list(tmp_path.iterdir()) == []  # checked before anything is written
    path = figures.save_figure(inset, tmp_path / "inset.png")
    assert _non_trivial(path)


def test_plot_command_options_write_vector_files(results, tmp_path, capsys):
    """--format svg/pdf: SVG parses as XML, PDF starts with its header; --ratio adds the ratio map."""
    assert main(["plot", str(results), "--out", str(tmp_path / "svg"), "--format", "svg", "--ratio"]) == 0
    svgs = sorted((tmp_path / "svg").iterdir())
    assert [p.name for p in svgs] == sorted(
        [*figures.figure_names(0, "svg"), *figures.figure_names(15, "svg"), figures.ratio_name(15, "svg")]
    )
    assert all(ET.parse(p).getroot().tag.endswith("svg") for p in svgs)
    argv = ["plot", str(results), "--out", str(tmp_path / "pdf"), "--format", "pdf", "--vmin", "0", "--vmax", "80"]
    assert main(argv) == 0
    assert all(p.read_bytes().startswith(b"%PDF-") for p in (tmp_path / "pdf").iterdir())
    capsys.readouterr()
    assert main(["plot", str(results), "--out", str(tmp_path / "x"), "--dpi", "0"]) == 2
    assert "--dpi" in capsys.readouterr().err and not (tmp_path / "x").exists()


def test_an_interrupted_plot_leaves_the_old_figures_not_a_mix(results, tmp_path, monkeypatch, capsys):
    """Ctrl-C while the third of four figures is saved: the folder holds the old four, byte for byte.

    Before, the first two were already the new ones. A file of the user's in the folder is kept
    by the run that finishes, and no staging folder is left beside it.
    """
    from spinectl import canvas

    out = tmp_path / "figs"
    assert main(["plot", str(results), "--out", str(out)]) == 0
    (out / "notes.txt").write_text("mine")
    for name in figures.figure_names(0.0) + figures.figure_names(15.0):
        (out / name).write_bytes(b"old " + name.encode())  # old figures that a new run would change
    old = {p.name: p.read_bytes() for p in out.iterdir()}
    save, calls = canvas.save_file, []

    def interrupted(figure, path, dpi):
        calls.append(path)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return save(figure, path, dpi)

    monkeypatch.setattr(canvas, "save_file", interrupted)
    assert main(["plot", str(results), "--out", str(out)]) == 130
    assert {p.name: p.read_bytes() for p in out.iterdir()} == old
    assert [p.name for p in tmp_path.iterdir()] == ["figs"]
    monkeypatch.setattr(canvas, "save_file", save)
    assert main(["plot", str(results), "--out", str(out)]) == 0
    assert (out / "notes.txt").read_text() == "mine" and _non_trivial(out / "fig3_min_pcsa.png")
    assert [p.name for p in tmp_path.iterdir()] == ["figs"]


def test_plot_into_a_folder_with_a_folder_in_a_figure_s_place_writes_nothing(results, tmp_path, capsys):
    """``fig4_counter_torque.png`` is a folder: refused before drawing, one line, the folder as it was."""
    out = tmp_path / "figs"
    (out / "fig4_counter_torque.png").mkdir(parents=True)
    (out / "fig3_min_pcsa.png").write_bytes(b"old")
    assert main(["plot", str(results), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "fig4_counter_torque.png': Is a directory" in err
    assert (out / "fig3_min_pcsa.png").read_bytes() == b"old" and sorted(tmp_path.iterdir()) == [out]


def test_a_link_to_the_output_folder_stays_a_link(results, tmp_path):
    """``--out link`` with link -> real: the figures go into real, the link is left as it is."""
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert main(["plot", str(results), "--out", str(tmp_path / "link")]) == 0
    assert (tmp_path / "link").is_symlink() and (tmp_path / "real" / "fig3_min_pcsa.png").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_the_working_directory_is_not_replaced_as_an_output_folder(results, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["plot", str(results), "--out", "."]) == 2
    err = capsys.readouterr().err
    assert "it is the working directory or holds it" in err
    assert "its other files are kept" in err  # a newcomer read the old wording as "the run would wipe it"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("stiffness", "near"), [(15.0, 15.000001), (1e-7, 1.0000001e-7), (123456.0, 123456.5)])
def test_distinct_stiffnesses_give_distinct_figure_names(stiffness, near):
    """``f"{K:g}"`` keeps 6 digits: 15 and 15.000001 (and 123456 and 123456.5) used to share a file name.

    The names must also read back as their K: the part after 'K' parses to the float given.
    """
    names = [figures.figure_names(k) for k in (stiffness, near)]
    assert len(set(names[0]) | set(names[1])) == 4
    for k, (pcsa, _) in zip((stiffness, near), names, strict=True):
        assert float(pcsa.removeprefix("figS1_min_pcsa_K").removesuffix(".png")) == k
    assert figures.figure_names(15.0) == ("figS1_min_pcsa_K15.png", "fig4_counter_torque_K15.png")


@pytest.fixture(scope="module")
def coupled(tmp_path_factory):
    """A sweep --coupled of the default model on 3 x 3 points over the paper's 0 to 8 cm (A at the origin)."""
    axis = np.linspace(0.0, 0.08, 3)
    path = tmp_path_factory.mktemp("coupled") / "c.nc"
    return netcdf.save(sweep.sweep(Model(), axis, axis, progress=False, coupled=True), path)


def test_coupled_ratio_is_the_joint_global_pcsa_over_the_per_segment_minimum(coupled):
    """At A: 33.0 cm^2 of global muscle in the joint optimum (docs/chain.md, the finding) over the paper's
    63.7 cm^2 (Figure 3 at A), about 0.52; at (4, 8) cm the ratio of optimise.coupled.joint_optimum's total
    global PCSA to optimise.solve_point's minimum, each solved on its own."""
    from spinectl.optimise import solve_point
    from spinectl.optimise.coupled import joint_optimum

    ratio = figures.coupled_ratio(netcdf.load(coupled))
    assert ratio.dims == ("E", "Lambda")
    assert float(ratio.sel(E=0.0, Lambda=0.0)) == pytest.approx(33.0 / 63.7, abs=0.002)
    expected = joint_optimum(Model(), 0.04, 0.08).total_pcsa / solve_point(Model(), 0.04, 0.08).min_pcsa
    assert float(ratio.sel(E=0.04, Lambda=0.08)) == pytest.approx(expected, rel=1e-4)  # the SDP's tolerance


def test_plot_draws_the_coupled_ratio_when_the_sweep_has_it(coupled, results, tmp_path):
    """spinectl plot on a sweep --coupled adds the map (the colour bar holds the ratio's range);
    a sweep without the coupled variables has none, and coupled_ratio says what it needs."""
    assert main(["plot", str(coupled), "--out", str(tmp_path / "c")]) == 0
    name = figures.coupled_ratio_name(0.0)
    assert name == "coupled_over_per_segment_K0.png" and _non_trivial(tmp_path / "c" / name)
    fig = figures.coupled_ratio_figure(netcdf.load(coupled))
    low, high = _colour_bar(fig).get_ylim()
    ratio = figures.coupled_ratio(netcdf.load(coupled)).values
    assert low <= np.nanmin(ratio) < np.nanmax(ratio) <= high
    assert "coupled / per segment" in fig.axes[0].get_title()
    assert main(["plot", str(results), "--out", str(tmp_path / "r")]) == 0
    assert not any(p.name.startswith("coupled") for p in (tmp_path / "r").iterdir())
    with pytest.raises(ParameterError, match="sweep --coupled"):
        figures.coupled_ratio(netcdf.load(results))


def test_pareto_figure_draws_the_computed_front():
    """The figure plots exactly the front's feasible points (global total in cm^2 against local total in
    N m/rad) and reads the local stiffness as PCSA on the top axis; wagner2012 at A leaves out the
    infeasible global-only point and draws no ring for it."""
    from spinectl import load_preset
    from spinectl.model import chain
    from spinectl.optimise.coupled import pareto_front

    model = load_preset("wagner2012")
    front = pareto_front(model, 0.0, 0.0, 4)
    fig = figures.pareto_figure(front, model)
    ax = fig.axes[0]
    (line,) = ax.get_lines()
    np.testing.assert_allclose(line.get_xdata(), front.local_total[1:])
    np.testing.assert_allclose(line.get_ydata(), front.global_total[1:] * 1e4)
    fig.canvas.draw()  # the secondary axis takes its limits when drawn
    (top,) = ax.child_axes  # the secondary axis: A = k / kappa, 1 cm^2 per kappa N m/rad (model.chain)
    kappa = chain.local_stiffness_per_pcsa(model) * 1e-4
    np.testing.assert_allclose(top.get_xlim(), np.array(ax.get_xlim()) / kappa)


def _drawn(fig):
    """The figure's landscape axes and a renderer, after a draw (extents on the canvas)."""
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    return fig.axes[0], renderer


def _position_labels(ax, renderer):
    return {
        t.get_gid(): t.get_bbox_patch().get_window_extent(renderer)
        for t in ax.texts
        if (t.get_gid() or "").startswith("label")
    }


@pytest.mark.parametrize("stiffness", [0.0, 15.0])
def test_the_legend_covers_no_label_or_marker_on_the_papers_grid(wagner2012_landscapes, stiffness):
    """wagner2012 on the 81 x 81 grid (the report's figures): the legend lies outside the landscape, so it covers
    neither D's label nor the corner (8, 8) cm (inside the axes at the top, it covered both)."""
    dataset = wagner2012_landscapes[0].sel(K=stiffness)
    for fig in (figures.min_pcsa_figure(dataset), figures.counter_torque_figure(dataset, 2.5e5)):
        ax, renderer = _drawn(fig)
        (legend,) = fig.legends
        box = legend.get_window_extent(renderer)
        labels = _position_labels(ax, renderer)
        assert {"label D", "label C"} <= set(labels)
        assert not box.overlaps(ax.get_window_extent(renderer))
        assert not any(box.overlaps(label) for label in labels.values())
        assert not any(box.overlaps(a.get_window_extent(renderer)) for a in fig.axes)  # nor the colour bar


@pytest.fixture(scope="module")
def coarse_wagner2012():
    """wagner2012 at K = 0 and 15 on 21 x 21 points (4 mm): matplotlib's own place for the ±30 N m label lay on C."""
    from spinectl.model import config
    from spinectl.paper import grid

    return grid.paper_landscapes(config.load_preset("wagner2012"), 21, progress=False)[0]


@pytest.mark.parametrize("stiffness", [0.0, 15.0])
@pytest.mark.parametrize("points", [21, 81])
def test_the_30_n_m_label_clears_c_and_every_label(wagner2012_landscapes, coarse_wagner2012, points, stiffness):
    """The ±30 N m line passes close by C (3, 4) cm: its label overlaps neither C's star nor any position's
    label nor the other contour lines' labels, measured on the canvas (before: on C's star and label on the
    21-point grid at K = 0, and on C's label at K = 15)."""
    dataset = (coarse_wagner2012 if points == 21 else wagner2012_landscapes[0]).sel(K=stiffness)
    ax, renderer = _drawn(figures.counter_torque_figure(dataset, 2.5e5))
    (limit,) = [t for t in ax.texts if t.get_text() == "±30 N m"]
    box = limit.get_window_extent(renderer)
    star = next(line for line in ax.lines if line.get_gid() == "optimum").get_window_extent(renderer)
    assert not box.overlaps(star)
    assert not any(box.overlaps(label) for label in _position_labels(ax, renderer).values())
    others = [t.get_window_extent(renderer) for t in ax.texts if t is not limit and not t.get_gid()]
    assert others and not any(box.overlaps(other) for other in others)
    assert ax.get_window_extent(renderer).contains(*box.p0) and ax.get_window_extent(renderer).contains(*box.p1)


def _round(values) -> bool:
    """Whether ``values`` are equally spaced multiples of a round step: 1, 2, 2.5 or 5 times a power of ten."""
    values = np.asarray(values, float)
    step = np.diff(values)
    if values.size < 2 or not np.allclose(step, step[0], rtol=1e-6):
        return False
    mantissa = step[0] / 10.0 ** np.floor(np.log10(step[0]))
    multiples = values / step[0]
    return any(np.isclose(mantissa, m) for m in (1, 2, 2.5, 5)) and np.allclose(multiples, np.round(multiples))


def _bar_ticks(fig):
    bar = _colour_bar(fig)
    low, high = bar.get_ylim()
    return [t for t in bar.get_yticks() if low - 1e-9 <= t <= high + 1e-9]


def test_colour_bar_ticks_filled_levels_and_contour_lines_are_round(results):
    """Figure S1 on its own range, on a shared range of non-round ends (13.75 to 36.26 cm^2, as --shared-scale gave
    13.75, 16.56, ...) and Figure 4: colour-bar ticks round; levels and contour lines round on the data's range."""
    dataset = netcdf.load(results)
    s1 = dataset.sel(K=15.0)
    for fig in (
        figures.min_pcsa_figure(s1),
        figures.min_pcsa_figure(s1, 13.75, 36.26),
        figures.counter_torque_figure(s1, 2.5e5),
    ):
        fig.draw_without_rendering()
        assert len(_bar_ticks(fig)) >= 3 and _round(_bar_ticks(fig))
    fig = figures.min_pcsa_figure(s1)
    filled, lines = fig.axes[0].collections[:2]
    assert _round(filled.levels) and _round(lines.levels) and len(lines.levels) >= 2


def _title_clear(fig):
    """The title lies inside the figure and within the axes' width, so it overlaps no tick label (measured drawn)."""
    ax, renderer = _drawn(fig)
    title = ax.title.get_window_extent(renderer)
    frame, page = ax.get_window_extent(renderer), fig.bbox
    ticks = [t.get_window_extent(renderer) for t in (*ax.get_xticklabels(), *ax.get_yticklabels()) if t.get_text()]
    return (
        frame.x0 - 1 <= title.x0
        and title.x1 <= frame.x1 + 1
        and page.x0 <= title.x0
        and title.x1 <= page.x1
        and title.y1 <= page.y1
        and not any(title.overlaps(t) for t in ticks)
    )


def test_titles_fit_the_axes(results, coupled):
    """Figure S1, Figure 4 at K = 15 (the longest titles: K and its convention) and the ratio maps: each title is
    wrapped to the axes' width (before, wider than the axes, they crowded the top "8" tick label)."""
    dataset = netcdf.load(results)
    drawn = [
        figures.min_pcsa_figure(dataset.sel(K=15.0)),
        figures.counter_torque_figure(dataset.sel(K=15.0), 2.5e5),
        figures.ratio_figure(dataset),
        figures.coupled_ratio_figure(netcdf.load(coupled)),
        figures.min_pcsa_figure(dataset.sel(K=15.0), insets=True),
    ]
    assert all(_title_clear(fig) for fig in drawn)
    assert "K convention: physical" in drawn[0].axes[0].get_title().replace("\n", " ")


def _linear_ratio():
    """A sweep --coupled stand-in whose ratio rises linearly in E from 0.3 at E = 0 to 1.2 at E = 8 cm."""
    axis = np.linspace(0.0, 0.08, 9)
    e = xr.DataArray(axis, dims="E")
    per_segment = 40.0 + 0.0 * (e + xr.DataArray(axis, dims="Lambda"))
    joint = per_segment * (0.3 + 0.9 * e / 0.08)
    return xr.Dataset(
        {"min_pcsa_cm2": per_segment, figures.COUPLED_VARIABLE: joint},
        coords={"E": axis, "Lambda": axis, "K": 0.0},
    )


def test_ratio_maps_take_their_levels_from_the_data_and_mark_halving_and_equal():
    """Ratio 0.3 + 0.9 E / 8 cm: the colour bar spans the data (not 0 to 1), on round levels with labelled contour
    lines; 0.5 and 1 are white labelled contours at E = 8 (0.5 - 0.3) / 0.9 = 1.78 cm and 8 (1 - 0.3) / 0.9 =
    6.22 cm (solved by hand from the linear ratio), and lines on the colour bar."""
    fig = figures.coupled_ratio_figure(_linear_ratio())
    ax = fig.axes[0]
    low, high = _colour_bar(fig).get_ylim()
    assert low == pytest.approx(0.3) and high == pytest.approx(1.2)  # round ends that hold the data
    filled = ax.collections[0]
    assert _round(filled.levels) and len(filled.levels) >= 8  # not 2 or 3 bands
    texts = [t.get_text() for t in ax.texts if not t.get_gid()]
    assert "0.5: halved" in texts and "1: equal" in texts and len(texts) >= 4  # the round lines labelled too
    marked = [c for c in ax.collections if len(getattr(c, "levels", [])) == 1]
    assert sorted(float(c.levels[0]) for c in marked) == [0.5, 1.0]
    for contour in marked:
        x = np.concatenate(contour.allsegs[0])[:, 0]
        expected = 8 * (float(contour.levels[0]) - 0.3) / 0.9
        np.testing.assert_allclose(x, expected, atol=1e-9)
    assert {line.get_gid() for line in _colour_bar(fig).lines} == {"ratio 0.5", "ratio 1"}


def test_a_ratio_map_says_which_marks_its_range_does_not_reach():
    """Ratio 0.3 + 0.9 E / 8 cm on E up to 4 cm only: at most 0.75, so the title says 1 is not reached."""
    fig = figures.coupled_ratio_figure(_linear_ratio().isel(E=slice(0, 5)))
    title = fig.axes[0].get_title()
    assert "1 not reached" in title and "0.5 and" not in title and "0.30 to 0.75" in title


def _touches(text, paths, renderer, pad=0.0):
    box = text.get_window_extent(renderer).padded(pad)
    return any(path.intersects_bbox(box, filled=False) for path in paths)


@pytest.mark.parametrize("stiffness", [0.0, 15.0])
@pytest.mark.parametrize("points", [21, 81])
def test_c_s_label_clears_the_30_n_m_line_and_the_30_n_m_label_the_ridge(
    wagner2012_landscapes, coarse_wagner2012, points, stiffness
):
    """The ±30 N m line passes close by C: C's label box touches neither the line nor (drawn) the ridge; the
    ±30 N m label does not sit on the ridge (before: C's box on the line at K = 0, the label on the ridge at
    K = 15). Measured as paths on the canvas crossing the labels' extents."""
    dataset = (coarse_wagner2012 if points == 21 else wagner2012_landscapes[0]).sel(K=stiffness)
    ax, renderer = _drawn(figures.counter_torque_figure(dataset, 2.5e5))
    limit = next(c for c in ax.collections if list(getattr(c, "levels", [])) == [30.0])
    line = [ax.transData.transform_path(p) for p in limit.get_paths()]
    ridge = next(line for line in ax.lines if line.get_gid() == "ridge")
    ridge = [ridge.get_transform().transform_path(ridge.get_path())]
    c = next(t for t in ax.texts if t.get_gid() == "label C")
    assert not _touches(c, line, renderer, pad=3)  # the round box's padding
    (label,) = [t for t in ax.texts if t.get_text() == "±30 N m"]
    assert not _touches(label, ridge, renderer)


@pytest.mark.parametrize("stiffness", [0.0, 15.0])
@pytest.mark.parametrize("points", [21, 81])
def test_contour_values_clear_the_labels_of_a_to_d_and_the_corners(
    wagner2012_landscapes, coarse_wagner2012, points, stiffness
):
    """Every contour line's value lies whole inside the axes and under no position's label, measured on the
    canvas, in Figures 3 (alone and with the corner drawings) and 4 (before: the 20 cm² of Figure 3 and the
    104 N m of Figure 4 lay under B's label at K = 0, on either grid)."""
    dataset = (coarse_wagner2012 if points == 21 else wagner2012_landscapes[0]).sel(K=stiffness)
    for fig in (
        figures.min_pcsa_figure(dataset),
        figures.min_pcsa_figure(dataset, insets=True),
        figures.counter_torque_figure(dataset, 2.5e5),
    ):
        ax, renderer = _drawn(fig)
        labels = _position_labels(ax, renderer)
        assert {"label A", "label B", "label D"} <= set(labels)
        values = [t.get_window_extent(renderer) for t in ax.texts if not t.get_gid()]
        frame = ax.get_window_extent(renderer)
        assert len(values) >= 4  # the lines are still labelled
        for box in values:
            assert not any(box.overlaps(label) for label in labels.values())
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1


@pytest.mark.parametrize("width", [30, 40, 46, 56])
def test_a_wrapped_title_keeps_settings_units_and_short_parentheses_whole(width):
    """A newcomer read "K = 0 N / m/rad" and "(K / convention: ...)" split across lines: a setting with its value
    and unit, and a parenthesis of at most 40 characters, stay on one line; the text is unchanged otherwise."""
    title = "Minimum PCSA of the study, body.mass = 24 kg, K = 15 N m/rad (K convention: physical, -K in dM/dα)"
    wrapped = figures._wrap(title, width)
    lines = wrapped.split("\n")
    for whole in ("body.mass = 24 kg", "K = 15 N m/rad", "(K convention: physical, -K in dM/dα)"):
        assert any(whole in line for line in lines), (whole, lines)
    assert " ".join(lines) == title


def test_on_an_angle_axis_a_corner_names_e_lambda_and_theta_and_k_0_has_its_unit(results):
    """`plot --lordosis-axis angle`: a corner's box read "0, 4.92 cm" beside a θ [deg] axis, and the title "K = 0":
    each corner now names E and Λ in cm and its θ in degrees (model.clinical.lordosis_angle, the axis's own
    conversion), and K = 0 carries its unit (N m/rad under the physical convention)."""
    from spinectl.model.clinical import lordosis_angle
    from spinectl.paper.figures.sets import angle_ticks

    dataset = netcdf.load(results).sel(K=0.0)
    model = netcdf.model_of(dataset)
    fig = figures.min_pcsa_figure(dataset)
    angle_ticks(fig, model)
    ax = fig.axes[0]
    assert ax.get_title().replace("\n", " ").endswith("K = 0 N m/rad")
    corners = [t for t in ax.texts if (t.get_gid() or "").startswith("label ") and len(t.get_gid()) > len("label A")]
    assert corners  # the paper's grid: the corner (8, 8) cm is none of A-D
    for label in corners:
        e_cm, lambda_cm = label.xy
        theta = float(lordosis_angle(np.array([lambda_cm / 100.0]), model)[0])
        assert label.get_text() == f"E {e_cm:.3g} cm, Λ {lambda_cm:.3g} cm (θ {theta:.0f}°)"


def test_a_corner_read_from_an_angle_axis_is_labelled_to_three_digits():
    """An axis even in degrees (sweep --lordosis-angle) puts its corners at Lambda values such as
    0.0699162 m: the label reads 6.99 cm (3 significant digits), not 6.99162 cm."""
    e, lam = np.array([0.02, 0.1]), np.array([0.0123456, 0.0699162])
    labels = [label for label, _ in figures.grid_marks(e, lam)]
    assert labels == ["C", "2, 1.23 cm", "10, 1.23 cm", "10, 6.99 cm", "2, 6.99 cm"]  # C = (3, 4) cm inside
