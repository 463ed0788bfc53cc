"""Labels placed clear of each other on the laid-out canvas: contour values, the ±30 N m label, A-D.

matplotlib places a contour's labels blind to other artists, and a position's label on a fixed side
of its point. These functions measure the boxes after the layout (:func:`spinectl.canvas.laid_out`)
and move a label that meets another, or is cut by the axes' edge, to a place where it is whole.
"""

from __future__ import annotations

import numpy as np

from ...canvas import laid_out

LABEL_MARGIN = 0.08
"""Least distance of a placed contour label from the axes' edges, as a fraction of their span."""

_LINES = "contour lines"
"""gid of a landscape's labelled contour lines."""


def _label_lines(ax) -> None:
    """Each contour line's value, clear of the labels of A-D and the corners as drawn.

    matplotlib places a value where its line is straight enough, blind to other artists: the 20 cm²
    of Figure 3 (K = 0) lay under B's label. So, as for the ±30 N m label (:func:`_label_place`), the
    places are measured on the canvas after the layout (the labels' offsets are in points, the lines
    in data units that the layout scales): a value whose box meets a mark's label, or is cut by the
    axes' edge, moves along its own line to the nearest vertex where it is whole and meets no mark's
    label and no other value, or is left out.
    """
    lines = next((c for c in ax.collections if c.get_gid() == _LINES), None)
    if lines is None:
        return
    renderer = laid_out(ax.figure)  # the layout sizes the axes
    pad = renderer.points_to_pixels(2.0)  # their boxes' padding (0.2 of a 9 pt font) lies outside a text's extent
    labels = (t for t in ax.texts if (t.get_gid() or "").startswith("label"))  # A-D and the corners
    marks = [t.get_window_extent(renderer).padded(pad) for t in labels]
    ax.clabel(lines, fmt="%.3g", fontsize=6, inline=False)  # matplotlib's places, to be checked
    frame = ax.get_window_extent(renderer)
    places, boxes = [], []
    for text in list(lines.labelTexts):
        place = text.get_position()
        if not _clear(text.get_window_extent(renderer), marks, frame):
            place = _clear_place(lines, place, marks + boxes, frame, renderer)
        if place is not None:
            places.append(place)
            boxes.append(_label_box(lines, *place, renderer))
    while lines.labelTexts:
        lines.pop_label()
    for text in ax.clabel(lines, fmt="%.3g", fontsize=6, manual=places):  # the lines broken where labelled
        text.set_clip_on(True)  # a label near the edge is cut, never drawn outside the axes


def _clear(box, others, frame) -> bool:
    """``box`` inside ``frame`` (not cut by the axes' edge) and meeting none of ``others`` (window extents)."""
    inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
    return inside and not any(box.overlaps(other) for other in others)


def _label_box(lines, x: float, y: float, renderer):
    """The window extent of a value label at the point of ``lines`` nearest (x, y) [cm], as clabel draws it."""
    lines.add_label_near(x, y, inline=False)
    box = lines.labelTexts[-1].get_window_extent(renderer)
    lines.pop_label()
    return box


def _clear_place(lines, start, keep_clear, frame, renderer, tries: int = 60):
    """The vertex of the line through ``start`` [cm] nearest it whose value label meets nothing of ``keep_clear``
    and lies inside ``frame``, away from the axes' edges (:data:`LABEL_MARGIN`); None if none does within
    ``tries`` vertices. The same connected line only: matplotlib labels each of a level's lines once."""
    segments = [segment for level in lines.allsegs for segment in level if len(segment)]
    vertices = min(segments, key=lambda v: np.linalg.norm(v - np.asarray(start), axis=1).min())
    ax = lines.axes
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    scaled = (vertices - (x0, y0)) / (x1 - x0, y1 - y0)
    vertices = vertices[np.all((scaled >= LABEL_MARGIN) & (scaled <= 1 - LABEL_MARGIN), axis=1)]
    order = np.argsort(np.linalg.norm(vertices - np.asarray(start), axis=1))
    for x, y in vertices[order][:: max(1, len(order) // tries)]:
        if _clear(_label_box(lines, x, y, renderer), keep_clear, frame):
            return float(x), float(y)
    return None


OFFSETS = ((6, 6), (-6, 6), (6, -6), (-6, -6))
"""Offsets [points] of a position's label from its point, in the order tried: right and up first."""


def _clear_of(ax, gid: str, contour) -> None:
    """Move the label ``gid`` of a position to the first side of its point (:data:`OFFSETS`) where its box
    neither touches ``contour`` nor leaves the axes; where none is, it stays. Measured on the laid-out canvas."""
    label = next((t for t in ax.texts if t.get_gid() == gid), None)
    if label is None:
        return
    renderer = laid_out(ax.figure)  # the layout first: the label's offset is in points, the line in data
    paths = [ax.transData.transform_path(p) for p in contour.get_paths()]
    frame = ax.get_window_extent(renderer)
    first = label.xyann
    for dx, dy in (first, *OFFSETS, first):  # none clear: back where it was
        label.set(position=(dx, dy), ha="left" if dx > 0 else "right", va="bottom" if dy > 0 else "top")
        box = label.get_window_extent(renderer).padded(3)  # the round box around the text
        inside = frame.contains(box.x0, box.y0) and frame.contains(box.x1, box.y1)
        if inside and not any(p.intersects_bbox(box, filled=False) for p in paths):
            return


def _label_place(contour, marks, ax) -> tuple[float, float] | None:
    """Where a contour's one label goes [cm]: its vertex farthest from every mark (A-D, the corners, C's star,
    the other contour lines' labels).

    matplotlib's own choice can fall on C, which the ±30 N m line passes close by. Distances are measured
    in fractions of the axes' spans; vertices within :data:`LABEL_MARGIN` of the edges are skipped (the
    label would be cut). None if no vertex qualifies (matplotlib's choice then).

    Parameters
    ----------
    contour : matplotlib.contour.QuadContourSet
        A contour of one level.
    marks : list of (float, float)
        Points to keep clear of [cm].
    ax : matplotlib.axes.Axes
        The axes, their limits set.

    Returns
    -------
    (float, float) or None
        (E, Lambda) [cm] of the label.
    """
    vertices = np.concatenate([s for s in contour.allsegs[0] if len(s)] or [np.empty((0, 2))])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    span = np.array([x1 - x0, y1 - y0])
    scaled = (vertices - (x0, y0)) / span
    inside = np.all((scaled >= LABEL_MARGIN) & (scaled <= 1 - LABEL_MARGIN), axis=1)
    if not inside.any():
        return None
    points = (np.array(marks, float).reshape(-1, 2) - (x0, y0)) / span
    distance = np.linalg.norm(scaled[inside, None, :] - points[None], axis=-1).min(axis=1)
    return tuple(float(c) for c in vertices[inside][np.argmax(distance)])
