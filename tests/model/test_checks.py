"""The attachment check of spinectl.model.checks against checking every (CoR, fibre) pair.

:func:`spinectl.model.checks._check_attachments` tests only the pairs that a bound over the grid
cannot rule out; :func:`_every_pair` below is the check as it read before, over every pair at every
point. Both must give the same verdict: the same error, naming the same muscle, end, CoR and point,
or none; and the same floating-point failure where the coordinates overflow.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinectl import load_preset
from spinectl.errors import ModelError, ParameterError
from spinectl.model import checks, geometry
from spinectl.model.params import Geometry, Model, MusclePair


def _every_pair(model, eccentricity, lordosis) -> None:
    """The attachment check over every (CoR, fibre) pair and point (spinectl 0.x before the candidate bound)."""
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)
    upper, lower, share = geometry.all_fibres(model)
    for end, points in (("upper", upper), ("lower", lower)):
        offset = cor[..., :, None, :] - points
        scale = np.abs(cor[..., :, None, :]).sum(-1) + np.abs(points).sum(-1)
        on_cor = np.abs(offset).sum(-1) <= 4 * np.finfo(float).eps * scale
        if on_cor.any():
            *at, k, f = np.argwhere(on_cor)[0]
            muscle = int(np.argmax(share[f]))
            e, lam = (
                np.broadcast_to(np.asarray(x, float), on_cor.shape[:-2])[tuple(at)] for x in (eccentricity, lordosis)
            )
            raise ModelError(
                f"muscles.{muscle // 2}.{end}: the {end} attachment of a fibre of {model.muscle_names[muscle]} lies "
                f"on the centre of rotation {model.geometry.cor_names[k]} {checks._where(e, lam)}; a fibre needs a "
                "non-zero arm between the joint and each attachment"
            )


def _verdict(check, model, eccentricity, lordosis):
    """The error message of ``check`` under the model's arithmetic guard, or None."""
    try:
        with checks.arithmetic_guard(eccentricity, lordosis):
            check(model, eccentricity, lordosis)
    except ModelError as error:
        return str(error)
    return None


def _same_verdict(model, eccentricity, lordosis):
    verdict = _verdict(checks._check_attachments, model, eccentricity, lordosis)
    assert verdict == _verdict(_every_pair, model, eccentricity, lordosis)
    return verdict


def _shifted(value: float, ulps: int) -> float:
    """``value`` moved by ``ulps`` units in the last place."""
    for _ in range(abs(ulps)):
        value = float(np.nextafter(value, np.sign(ulps) * np.inf))
    return value


def _with_pair(base: Model, index: int, pair: MusclePair) -> Model:
    muscles = list(base.muscles)
    muscles.insert(min(index, len(muscles)), pair)
    return base.replace(muscles=tuple(muscles))


def _pair_at(end: str, point, far=(0.1, 0.3), below=(0.1, -0.05)) -> MusclePair:
    """One fibre per side, its ``end`` attachment at ``point`` and the other away from every CoR."""
    ends = {"upper": far, "lower": below, end: tuple(point)}
    return MusclePair("p", ends["upper"], ends["lower"], 0.0, 1)


@pytest.mark.parametrize("end", ["upper", "lower"])
@pytest.mark.parametrize("k", range(5))
def test_an_attachment_on_each_cor_is_found_at_its_grid_point(end, k):
    """Attachment placed exactly on CoR k at the middle point of a 3 x 3 grid (x_k = -E + Lambda phi_k):
    the error names that pair, end, CoR and point."""
    base = Model()
    e_axis, l_axis = np.array([0.01, 0.02, 0.03]), np.array([0.04, 0.05, 0.06])
    point = geometry.cor_positions(0.02, 0.05, base.geometry)[k]
    model = _with_pair(base, 1, _pair_at(end, point))
    verdict = _same_verdict(model, *np.meshgrid(e_axis, l_axis, indexing="ij"))
    name = base.geometry.cor_names[k]
    assert verdict is not None and verdict.startswith(f"muscles.1.{end}: ") and f"rotation {name} " in verdict
    assert "at E = 0.02 m, Lambda = 0.05 m" in verdict


def test_the_preset_grids_have_no_attachment_on_a_cor():
    """Both presets over the modelled range: no attachment within 1 mm of a CoR's height (their fibres end
    at y >= 0.21 m or <= 0.04 m, the CoRs lie at 0.005-0.145 m), so neither check may object."""
    axis = np.linspace(-0.1, 0.1, 41)
    for preset in ("default", "wagner2012"):
        assert _same_verdict(load_preset(preset), *np.meshgrid(axis, axis, indexing="ij")) is None


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.floats(-0.1, 0.1), min_size=1, max_size=3),
    st.lists(st.floats(-0.1, 0.1), min_size=1, max_size=3),
    st.integers(0, 8),
    st.integers(0, 4),
    st.sampled_from(["upper", "lower"]),
    st.integers(-12, 12),
    st.integers(-12, 12),
    st.integers(0, 3),
)
def test_the_verdict_is_that_of_every_pair(e_axis, l_axis, where, k, end, dx, dy, index):
    """An attachment on CoR k at one grid point, moved by up to 12 ulps in x and y (on both sides of the
    tolerance of 4 eps), the pair inserted at any index: the same verdict as checking every pair."""
    base = Model()
    e_grid, l_grid = np.meshgrid(e_axis, l_axis, indexing="ij")
    at = np.unravel_index(where % e_grid.size, e_grid.shape)
    x, y = geometry.cor_positions(e_grid[at], l_grid[at], base.geometry)[k]
    model = _with_pair(base, index, _pair_at(end, (_shifted(x, dx), _shifted(y, dy))))
    _same_verdict(model, e_grid, l_grid)
    _same_verdict(model, e_grid[at], l_grid[at])  # a single point: no leading dimensions


def test_far_attachments_rule_out_every_pair_and_near_ones_keep_theirs():
    """The bound keeps no pair for the presets' fibres, and the pair of an attachment 12 ulps off a CoR."""
    base = Model()
    cor = geometry.cor_positions(np.linspace(0, 0.08, 9), 0.03, base.geometry)
    upper, lower, _ = geometry.all_fibres(base)
    for points in (upper, lower):
        assert checks._attachment_candidates(cor, points)[0].size == 0
    near = np.array([[0.3, 0.3], [_shifted(cor[4, 2, 0], 12), cor[4, 2, 1]]])  # CoR L3L4 at the fifth point
    cors, fibres = checks._attachment_candidates(cor, near)
    assert (2, 1) in set(zip(cors.tolist(), fibres.tolist(), strict=True))
    assert 0 not in fibres  # the point far from every CoR


@pytest.mark.parametrize(
    ("eccentricity", "x"),
    [
        (1.7e308, 1.7e308),  # x_k - P_x = -3.4e308 overflows: both checks fail the same way
        (-1e308, 1e308),  # on L1L2 at x = 1e308, but the scale 2e308 overflows first
        (-1e307, 1e307),  # on L1L2, below the threshold: the bound, at large coordinates
        (-3e307, 3e307),  # on L1L2, above the threshold: every pair is checked, no overflow
        (-3e307, 4e307),  # above the threshold, no attachment on a CoR
    ],
)
def test_coordinates_near_overflow_give_the_same_verdict(eccentricity, x):
    """Beyond float max / 8 the bound could overflow, so every pair is checked, with the arithmetic of
    the full check: its overflow (a ModelError naming the arithmetic) or its verdict."""
    # Model validation refuses lengths beyond MAX_BODY_LENGTH (1 m) since the checks were written; they
    # stay the defence for a model built around validation, so the test builds one that way
    geometry_, pair = Geometry(), MusclePair("far", (0.1, 0.145), (0.1, 0.0), 0.0, 1)
    object.__setattr__(geometry_, "eccentricity_range", (-1.79e308, 1.79e308))
    object.__setattr__(pair, "upper", (x, 0.145))
    object.__setattr__(pair, "lower", (x, 0.0))
    model = Model(geometry=geometry_, muscles=(pair,))
    verdict = _same_verdict(model, eccentricity, 0.0)
    if abs(x) >= 1e308:
        assert "arithmetic fails" in verdict and "overflow" in verdict
    elif x == -eccentricity:  # the upper attachment is L1L2 (x = -E, y = 0.145)
        assert verdict.startswith("muscles.0.upper: ") and "rotation L1L2 " in verdict
    else:
        assert verdict is None


@pytest.mark.parametrize(
    ("pcsa", "said"),
    [
        ([1e-3, 1e-3], "got 2 values"),
        ([1e-3], "got 1 value"),
        (1e-3, "got one number"),
        ([[1e-3] * 4] * 2, "got 4 per row (shape (2, 4))"),
    ],
)
def test_a_pcsa_of_the_wrong_length_is_counted_in_words(pcsa, said):
    """The count given, in words (was numpy's shape, ``got (2,)``); the preset has 3 pairs, 6 muscles."""
    from spinectl.model.stability import segment_stability

    with pytest.raises(ParameterError, match=r"must have 3 values \(one per pair\) or 6 \(one per muscle\); ") as err:
        segment_stability(load_preset("wagner2012"), 0.03, 0.04, pcsa)
    assert said in str(err.value) and "(2,)" not in str(err.value)
