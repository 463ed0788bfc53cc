"""A study's slices drawn as the landscape figures: titles with units, ‖CT‖ with the ±30 N m limit, round levels."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.landscape import sweep
from spinectl.model.params import Model
from spinectl.paper import slices


@pytest.fixture(scope="module")
def study():
    """K = 0 and 15 on the paper's 0-8 cm in 2 cm steps, with a body.mass axis as a study store writes it."""
    axis = np.linspace(0.0, 0.08, 5)
    landscapes = sweep.stiffness_sweep(Model(), [0.0, 15.0], axis, axis, progress=False)
    dataset = landscapes.expand_dims({"body.mass": [40.0]})
    dataset["body.mass"].attrs["units"] = "kg"
    dataset["K"].attrs["units"] = "N m/rad"
    return dataset


def test_slice_titles_name_the_values_with_units_and_ct_as_the_other_figures(study):
    drawn = slices.slice_figures(study)
    ct = drawn["counter_torque_body.mass=40_K=15.png"].axes[0]
    title = ct.get_title().replace("\n", " ")
    assert "‖CT‖" in title and "||CT||" not in title
    assert "body.mass = 40 kg, K = 15 N m/rad" in title


def test_the_ct_slices_carry_the_30_n_m_limit_and_round_levels(study):
    """Where ‖CT‖ crosses 30 N m (here at both K, as Figure 4), the slice has the dashed contour and its label;
    its contour lines are at round values (steps 1, 2, 2.5 or 5 times a power of ten)."""
    for k in (0, 15):
        fig = slices.slice_figures(study)[f"counter_torque_body.mass=40_K={k}.png"]
        ax = fig.axes[0]
        values = study["counter_torque_norm_Nm"].sel(K=float(k)).values
        assert np.nanmin(values) < 30.0 < np.nanmax(values)
        assert any(list(getattr(c, "levels", [])) == [30.0] for c in ax.collections)
        assert [t.get_text() for t in ax.texts].count("±30 N m") == 1
        lines = ax.collections[1].levels
        step = np.diff(lines)[0]
        assert np.allclose(np.diff(lines), step) and np.allclose(lines / step, np.round(lines / step))
        assert step / 10 ** np.floor(np.log10(step)) in (1, 2, 2.5, 5)


def test_an_unfinished_store_draws_its_uncomputed_points_as_not_computed(tmp_path):
    """A study of K = 0 and 15 on a 3 x 3 grid, one chunk (the K = 0 slice) of two done: the K = 15 slice's
    9 points read NaN because nothing computed them, which the figure must say (not "no self-stable activation",
    the infeasible answer), and :func:`slices.draw_study` warns with the count, 9 of 18 points."""
    from spinectl.landscape import study

    text = (
        '[study]\nchunk_size = 9\noutputs = ["min_pcsa_cm2", "counter_torque_norm_Nm", "status"]\n[axes]\n'
        "E = { start = 0.0, stop = 0.08, num = 3 }\nLambda = { start = 0.0, stop = 0.08, num = 3 }\nK = [0.0, 15.0]\n"
    )
    out = tmp_path / "s.zarr"
    study.run_study(study.parse_study(text), out, scheduler="synchronous", max_chunks=1, progress=False)
    with pytest.warns(UserWarning, match=r"'.*s\.zarr' is unfinished: 9 of 18 points not computed"):
        written = slices.draw_study(out, tmp_path / "figures")
    assert len(written) == 4
    dataset = study.load(out)
    drawn = slices.slice_figures(dataset, computed=study.store.computed(dataset))
    for stem in ("min_pcsa", "counter_torque"):
        pending = drawn[f"{stem}_K=15.png"].axes[0].get_title().replace("\n", " ")
        assert "white (9 of 9 points): not computed yet, the study is unfinished (9)" in pending
        assert "no self-stable activation" not in pending
        assert "white" not in drawn[f"{stem}_K=0.png"].axes[0].get_title()  # every point computed and feasible
