"""The worked lift of docs/motion.md (docs/_ext/spinectl_docs/lift.py): its numbers are ``spinectl motion``'s.

The second path is the command line, run on the lift file that the docs' generator writes, with the options
that docs/motion.md prints: the NetCDF file it writes must hold the numbers the page's ``{measured}`` values are
made of. The Pose2Sim sentence says that the model is not at the build where the shared folder is absent.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")
pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

from spinectl_docs import lift, values  # noqa: E402

from spinectl.cli import main  # noqa: E402


def test_the_lifts_numbers_are_the_commands(tmp_path, capsys):
    """`spinectl motion myotorso --coordinates lift.mot --optimise joints --joint-stiffness 50 --load
    torso:0,0,-100 --contributions --removal --group back=... --group abs=...` (docs/motion.md's command) on the
    generator's lift file: the file's index, unstable modes, class contributions and removals equal the
    generator's, and the page's values quote them."""
    import xarray as xr

    from spinectl import anatomy

    path = lift._lift(anatomy.load("myotorso"), tmp_path / "lift.mot")
    out = tmp_path / "lift.nc"
    argv = ["motion", "myotorso", "--coordinates", str(path), "--optimise", "joints", "--joint-stiffness", "50"]
    argv += ["--load", "torso:0,0,-100", "--contributions", "--removal"]
    argv += [word for name, rx in lift.GROUPS.items() for word in ("--group", f"{name}={rx}")]
    assert main([*argv, "--out", str(out)]) == 0
    ours = lift.myotorso_lift().dataset
    with xr.open_dataset(out) as ds:
        for name in ("free_index", "constrained_index", "free_unstable_modes", "free_class_contribution"):
            np.testing.assert_array_equal(ds[name].values, ours[name].values)
        for name in ("free_removed_change", "constrained_removed_change", "removal_status"):
            np.testing.assert_array_equal(ds[name].values, ours[name].values)
        least = int(np.argmin(ds["free_index"].values))
        quoted = f"{ds['free_index'].values[least]:.3g} N m/rad at t = {ds['time'].values[least]:.1f} s"
        change = ds["free_removed_change"].values[least]
        most = int(np.nanargmax(np.abs(change)))  # the removal quoted first: the largest change at that frame
        removed = f"{ds['group'].values[most]} {change[most]:+.3g} %"
    assert values.text_of("motion.lift_free_least") == quoted
    assert values.text_of("motion.lift_removal_free").startswith(removed)
    assert ours.sizes["time"] == lift.FRAMES and ours.attrs["loads_text"].count("100") == 1


def test_the_figure_is_written_for_the_page(tmp_path):
    """write_figure puts motion-lift.png and motion-lift-removal.png (the names motion.md's image directives
    give) into the folder."""
    lift.write_figure(tmp_path)
    page = (ROOT / "docs" / "motion.md").read_text(encoding="utf-8")
    for figure in (lift.FIGURE, lift.REMOVAL_FIGURE):
        assert (tmp_path / figure).stat().st_size > 10_000
        assert f"_generated/{figure}" in page


def test_the_pose2sim_sentence_says_it_is_not_at_this_build_when_absent(tmp_path, monkeypatch):
    """$SPINECTL_SHARED_MODELS naming an empty folder: the value is a note that the model is not at this build."""
    monkeypatch.setenv("SPINECTL_SHARED_MODELS", str(tmp_path))
    lift.pose2sim_lift.cache_clear()
    try:
        assert values.text_of("motion.pose2sim").startswith("(not computed: the Pose2Sim model is not at this build")
    finally:
        lift.pose2sim_lift.cache_clear()
