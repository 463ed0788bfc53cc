"""The search for attachments on centres of rotation (``checks.attachments_on_cors``) against comparing every pair."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.model import checks, config, geometry


def every_pair(cor: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The dense comparison the search replaces: every (grid point, CoR, attachment), as written in checks."""
    offset = cor[..., :, None, :] - points
    scale = np.abs(cor[..., :, None, :]).sum(-1) + np.abs(points).sum(-1)
    return np.argwhere(np.abs(offset).sum(-1) <= checks.ON_COR_TOLERANCE * scale)


def planted(rng, n: int, k: int, f: int, hits: int) -> tuple[np.ndarray, np.ndarray]:
    """Random CoRs and attachments with ``hits`` attachments moved onto, or a few ulp beside, some CoRs;
    also ties in x (equal x, other y), which only the comparison of both coordinates can tell apart."""
    cor = rng.uniform(-0.1, 0.3, size=(n, k, 2))
    points = rng.uniform(-0.1, 0.3, size=(f, 2))
    for i in range(hits):
        target = cor[rng.integers(n), rng.integers(k)]
        ulps = rng.integers(-12, 13, size=2)  # on (0), within round-off, or just beyond the tolerance
        points[i] = [np.float64(t) + u * np.spacing(t) for t, u in zip(target, ulps, strict=True)]
    points[hits : 2 * hits, 0] = cor[:hits, 0, 0]  # x equal, y not: candidates that are no hits
    return cor, points


@pytest.mark.parametrize("seed", range(20))
def test_the_search_finds_what_comparing_every_pair_finds(seed):
    """The same hits, in the same order, as the O(N K F) comparison (random layouts, planted exact and
    near hits on both sides of the tolerance)."""
    rng = np.random.default_rng(seed)
    cor, points = planted(rng, n=int(rng.integers(1, 300)), k=int(rng.integers(1, 6)), f=30, hits=8)
    np.testing.assert_array_equal(checks.attachments_on_cors(cor, points), every_pair(cor, points))


def test_many_ties_in_x_are_compared_in_full():
    """Every CoR at x = 0 and every attachment at x = 0 (a worst case: every pair a candidate): still exact."""
    rng = np.random.default_rng(7)
    cor, points = planted(rng, n=50, k=5, f=12, hits=0)
    cor[..., 0], points[:, 0] = 0.0, 0.0
    points[3, 1] = cor[17, 2, 1]  # one hit
    found = checks.attachments_on_cors(cor, points)
    np.testing.assert_array_equal(found, every_pair(cor, points))
    np.testing.assert_array_equal(found, [[17, 2, 3]])


def test_on_the_models_grid_the_first_hit_is_the_one_named():
    """An attachment moved onto a CoR at one inner point of a grid: the error names that point and CoR."""
    model = config.load_preset("default")
    e_grid, l_grid = np.meshgrid(np.linspace(0.0, 0.08, 9), np.linspace(0.0, 0.08, 7), indexing="ij")
    cor = geometry.cor_positions(e_grid, l_grid, model.geometry)
    upper, _, _ = geometry.all_fibres(model)
    assert checks.attachments_on_cors(cor.reshape(-1, *cor.shape[-2:]), upper).size == 0
    x, y = cor[4, 3, 2]
    moved = config.set_parameters(model, {"muscles.0.upper.0": float(x), "muscles.0.upper.1": float(y)})
    with pytest.raises(checks.ModelError, match=r"centre of rotation \S+ at E = 0.04 m, Lambda = 0.04 m"):
        checks.validate_position(moved, e_grid, l_grid)
