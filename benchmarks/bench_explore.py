"""Benchmark: how fast the explorer's views follow a change (``spinectl explore``, docs/explore.md).

    python benchmarks/bench_explore.py                # 5 points, the 41 x 41 landscapes twice
    python benchmarks/bench_explore.py --repeats 10

In-process, without a browser (the browser adds its own rendering):

- a point: :meth:`spinectl.explore.app.Explorer.update_point` after a move of E, split
  into the numbers (:func:`spinectl.explore.numbers.point_numbers`: the optimum, the
  margins, the eigenvalues) and the pictures: the drawing as SVG, and the three small views
  (eigenvalues, counter torques, delay margins) as Bokeh data updates, each against what
  the explorer did before in the same run (the reference): the drawing as PNG, the three
  views drawn as matplotlib PNGs; and after a move of the delay slider, which updates the
  margins only;
- the landscapes: :func:`spinectl.explore.numbers.landscapes` at 41 x 41 on the stacked
  fast path, against the per-point reference solver on the same grid's every 4th point
  per axis (11 x 11), scaled per point: the ratio is the fast path's speed-up.

Timings on a shared machine are noisy; each figure is the median of the repeats, and
the load average at the start is printed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from spinectl.explore import app, numbers, views
from spinectl.explore.state import model_at, replace, slider_for
from spinectl.landscape.sweep import sweep
from spinectl.model.config import load_preset


def _median(func, repeats: int) -> float:
    times = []
    for i in range(repeats):
        start = time.perf_counter()
        func(i)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    explorer = app.Explorer(load_preset("default"), "default")  # outside a session: landscapes solved at once
    base, state = explorer.base, explorer.state

    def move(i):
        explorer.move_to(0.02 + 0.002 * i, 0.04)

    point = _median(move, args.repeats)
    delay = slider_for("delay")
    reflex = _median(lambda i: explorer._on_slider(delay, 80.0 + 5 * i), args.repeats)  # what the slider calls
    computed = _median(
        lambda i: numbers.point_numbers(base, replace(state, eccentricity=0.02 + 0.002 * i)), args.repeats
    )
    shown = numbers.point_numbers(base, state)

    drawing = _median(lambda i: app.drawing_svg(shown), args.repeats)
    drawing_png = _median(lambda i: app.png_bytes(views.model_drawing(shown)), args.repeats)

    def bokeh_views(i):
        for view in explorer.views.values():
            view.show(shown)

    updated = _median(bokeh_views, args.repeats)
    as_png = _median(
        lambda i: [
            app.png_bytes(plot(shown))
            for plot in (views.eigenvalue_plot, views.counter_torque_plot, views.delay_margin_plot)
        ],
        args.repeats,
    )
    before = computed + drawing_png + as_png
    print(
        f"point update: {point:.3f} s (numbers {computed:.3f} s, drawing as SVG {drawing:.3f} s, "
        f"three views as Bokeh data {updated * 1e3:.1f} ms)"
    )
    print(
        f"  as before (drawing as PNG {drawing_png:.3f} s, the three views as matplotlib PNGs {as_png:.3f} s): "
        f"{before:.3f} s, {before / point:.1f} x the update now"
    )
    print(f"a reflex slider (delay): {reflex:.3f} s (the margins view only is updated)")

    fast = _median(lambda i: numbers.landscapes(base, replace(state, mass=30.0 + i)), 2)
    axis = numbers.landscape_axis()[::4]
    model = model_at(base, state)
    start = time.perf_counter()
    sweep(model, axis, axis, method="per-point", progress=False)
    per_point = (time.perf_counter() - start) / axis.size**2
    n = numbers.LANDSCAPE_POINTS**2
    print(
        f"landscapes {numbers.LANDSCAPE_POINTS} x {numbers.LANDSCAPE_POINTS}: fast path {fast:.2f} s; "
        f"per-point reference {per_point * 1e3:.1f} ms a point, {per_point * n:.1f} s for the grid "
        f"(fast path {per_point * n / fast:.0f} x faster)"
    )


if __name__ == "__main__":
    main()
