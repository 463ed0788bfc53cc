"""The removal method along a motion (spinectl.anatomy.motion_removal), on MyoTorso and files written by OpenSim.

The second path for every removal is the one-posture removal: ``spinectl anatomy --posture FILE --time t
--contributions --json`` at each frame's time (its own reading of the file, its own linearisation, its own
optimum and resolver), whose ``removal`` entries the motion's frame must equal bit for bit; and, for the
single muscles, the least eigenvalue of -K with that muscle's activation set to 0 by numpy's ``eigvalsh``.
The motion is MyoTorso's lumbar flexion and return of tests/anatomy/test_motion.py (21 frames over 1 s).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

osim = pytest.importorskip("opensim", reason="needs the opensim extra: pip install 'spinectl[opensim]'")

from test_motion import TIMES, flexion_file  # noqa: E402 (tests/anatomy/test_motion.py)
from test_recordings import write_table  # noqa: E402 (tests/anatomy/test_recordings.py: OpenSim's STOFileAdapter)

from spinectl.anatomy.motion import motion_response, removal_plot  # noqa: E402
from spinectl.anatomy.motion_removal import check_removal  # noqa: E402
from spinectl.anatomy.recordings import read_recording  # noqa: E402
from spinectl.cli import main  # noqa: E402
from spinectl.errors import ParameterError  # noqa: E402

GROUPS = {"back": "IL|LTp", "abs": "rect_abd|EO|IO"}
"""MyoTorso's erector spinae (iliocostalis, longissimus) and abdominal muscles, by name prefix."""


@pytest.fixture(scope="module")
def files(torso, tmp_path_factory):
    """The flexion file and an activations file with a different random vector per frame."""
    folder = tmp_path_factory.mktemp("removal")
    path = flexion_file(torso, folder / "flexion.mot")
    a = np.random.default_rng(11).uniform(0.0, 0.3, (TIMES.size, len(torso.muscles)))
    return path, write_table(folder / "so.sto", torso.muscles, a, times=TIMES)


def _one_posture(capsys, path, time, *options) -> dict:
    """``spinectl anatomy myotorso --posture path --time t --contributions 1 --json`` with the groups: its
    ``contributions`` (the one-posture removal at that frame)."""
    groups = [word for name, rx in GROUPS.items() for word in ("--group", f"{name}={rx}")]
    argv = ["anatomy", "myotorso", "--posture", str(path), "--time", repr(time), "--contributions", "1", *groups]
    capsys.readouterr()
    assert main([*argv, *options, "--json"]) == 0
    return json.loads(capsys.readouterr().out)["contributions"]


def _assert_frames_are_one_posture(ds, capsys, path, *options) -> list:
    """Every frame's removal of every class and group, both chains, equals the one-posture removal bit for bit
    (the JSON's floats are repr round trips, exact); the statuses too. Returns the statuses seen."""
    seen = []
    for i, t in enumerate(ds["time"].values):
        one = _one_posture(capsys, path, float(t), *options)
        for name in ("free", "constrained"):
            for k, key in enumerate(ds["group"].values):
                removed = one[name]["removal"][str(key)]
                expected = removed["least_eigenvalue_Nm_per_rad"]
                expected = np.nan if expected is None else expected  # jsondoc: NaN as null
                change = np.nan if removed["percent_change"] is None else removed["percent_change"]
                np.testing.assert_array_equal(ds[f"{name}_removed_index"].values[i, k], expected)
                np.testing.assert_array_equal(ds[f"{name}_removed_change"].values[i, k], change)
                assert ds["removal_status"].values[i, k] == removed["status"]
                seen.append(removed["status"])
    return seen


def test_each_frames_removal_with_activations_given_is_the_one_posture_removal(torso, files, capsys):
    """Activations from a file, frames 0, 0.5 and 1 s: each class's and group's removal on both chains is
    ``spinectl anatomy --activations FILE --time t --contributions``'s at that time, bit for bit, the others kept
    (status 'removed'); a removal changes the index and the change differs between frames (the test can fail)."""
    path, sto = files
    rec, act = read_recording(path, "posture"), read_recording(sto, "activations")
    ds = motion_response(torso, rec, act, frames=(0, 20, 10), removal="groups", groups=GROUPS, progress=False).dataset
    classes = [f"class:{c}" for c in ("global", "local", "between", "non-lumbar")]  # MyoTorso's four
    assert list(ds["group"].values) == [*classes, "group:back", "group:abs"]
    seen = _assert_frames_are_one_posture(ds, capsys, path, "--activations", str(sto))
    assert set(seen) == {"removed"}
    change = ds["free_removed_change"].values
    assert np.nanmax(np.abs(change)) > 1.0 and not np.allclose(change[0], change[1])  # [%]
    assert "not re-solved" in ds["free_removed_index"].attrs["method"]


def test_each_frames_removal_with_the_optimum_is_the_one_posture_re_solved(torso, files, capsys):
    """optimise='chain' with 50 N m/rad added (feasible at every frame): each removal re-solves the optimum
    without the set, and equals ``spinectl anatomy --optimise --stability chain --contributions`` at that time bit
    for bit; upright, removing every global muscle leaves no equilibrium: NaN with status 're-solved: infeasible'
    on both chains, as the one-posture removal says; the others are re-solved 'optimal', finite (can fail)."""
    path, _ = files
    rec = read_recording(path, "posture")
    ds = motion_response(
        torso, rec, optimise="chain", joint_stiffness=50.0, frames=(0, 10, 10), removal="groups", groups=GROUPS
    ).dataset
    options = ("--optimise", "--stability", "chain", "--joint-stiffness", "50")
    seen = _assert_frames_are_one_posture(ds, capsys, path, *options)
    assert "re-solved: infeasible" in seen and "re-solved: optimal" in seen
    k = list(ds["group"].values).index("class:global")
    assert ds["removal_status"].values[0, k] == "re-solved: infeasible"  # upright: nothing else extends
    failed = ds["removal_status"].values == "re-solved: infeasible"
    for name in ("free", "constrained"):
        assert np.all(np.isnan(ds[f"{name}_removed_index"].values[failed]))
        assert np.all(np.isnan(ds[f"{name}_removed_change"].values[failed]))
        assert np.all(np.isfinite(ds[f"{name}_removed_index"].values[~failed]))
    assert "re-solved" in ds["constrained_removed_change"].attrs["method"]


def test_a_frame_without_an_operating_point_has_no_removal(torso, files):
    """optimise='chain' without added stiffness: MyoTorso's optimum is infeasible at the upright frame (no
    activations, so no index): every removal is NaN with status '' (no operating point), as the index is."""
    path, _ = files
    ds = motion_response(
        torso, read_recording(path, "posture"), optimise="chain", frames=(0, 0, 1), removal="groups", progress=False
    ).dataset
    assert ds["optimum_status"].values[0] == "infeasible" and np.isnan(ds["free_index"].values[0])
    assert np.all(np.isnan(ds["free_removed_index"].values)) and np.all(np.isnan(ds["constrained_removed_change"]))
    assert set(ds["removal_status"].values.ravel()) == {""}


def test_every_muscle_removed_is_the_least_eigenvalue_without_it(torso, files):
    """removal='muscles': every muscle is a group too; three of them at frame 0.5 s against -K with that muscle's
    activation at 0 (chains() at that posture, numpy's eigvalsh: a second eigensolver, so to 1e-12 relative)."""
    path, sto = files
    rec = read_recording(path, "posture")
    ds = motion_response(
        torso, rec, read_recording(sto, "activations"), frames=(10, 10, 1), removal="muscles", progress=False
    ).dataset
    assert ds.sizes["group"] == 4 + len(torso.muscles)  # MyoTorso's four classes, then each muscle
    posture = torso.named_posture(rec.frame(torso.posture_columns(), 0.5).values)
    a = ds["activation"].values[0]
    free, con, _ = torso.chains("sagittal", posture, activations=a)
    for muscle in ("IL_L1_r", "rect_abd_l", torso.muscles[-1]):
        held = np.where(np.array(torso.muscles) == muscle, 0.0, a)
        for name, chain in (("free", free), ("constrained", con)):
            k = chain.stiffness(held)
            expected = np.linalg.eigvalsh(-(k + k.T) / 2)[0]
            got = ds[f"{name}_removed_index"].sel(group=muscle).values[0]
            np.testing.assert_allclose(got, expected, rtol=1e-12)
    assert ds["free_removed_index"].sel(group="IL_L1_r").values[0] != ds["free_index"].values[0]


@pytest.mark.parametrize(
    ("removal", "groups", "optimise", "word"),
    [
        ("muscles", None, "chain", "once per muscle"),
        ("muscles", None, "joints", "once per muscle"),
        ("all", None, "none", "must be one of"),
        (None, {"back": "IL"}, "none", "goes with removal"),
    ],
)
def test_a_removal_the_motion_cannot_do_is_refused(removal, groups, optimise, word):
    """Every muscle re-solved per frame (either criterion), an unknown removal, groups without a removal: one
    ParameterError naming the field (check_removal, which the command calls before any file is read)."""
    with pytest.raises(ParameterError, match=word):
        check_removal(removal, groups, optimise)


def test_a_group_that_matches_no_muscle_is_refused_before_any_frame(torso, files, monkeypatch):
    """A group matching no muscle: ParameterError naming it, and no frame solved (the chains never asked for)."""
    path, _ = files
    calls = []
    monkeypatch.setattr(type(torso), "chains", lambda *args, **kw: calls.append(1))
    with pytest.raises(ParameterError, match="group none: must match at least one muscle"):
        motion_response(torso, read_recording(path, "posture"), removal="groups", groups={"none": "zzz"})
    assert calls == []


def test_the_removal_figure_draws_the_files_changes(torso, files, tmp_path):
    """removal_plot: two panels (free, constrained), one line per class and group (single muscles not drawn)
    whose values are the Dataset's *_removed_change, read back from the NetCDF file with its units and method."""
    import xarray as xr

    from spinectl.landscape.netcdf import save

    path, sto = files
    result = motion_response(
        torso,
        read_recording(path, "posture"),
        read_recording(sto, "activations"),
        frames=(0, 20, 10),
        removal="muscles",
        groups=GROUPS,
        progress=False,
    )
    save(result.dataset, tmp_path / "m.nc")
    with xr.open_dataset(tmp_path / "m.nc") as ds:
        assert ds["free_removed_change"].attrs["units"] == "%" and ds["free_removed_index"].attrs["units"] == "N m/rad"
        assert ds["removal_status"].values[0, 0] == "removed"
        assert "VanVliet" in ds.attrs["references"] and "McGill" in ds.attrs["references"]
        assert json.loads(ds["group"].attrs["members"])["group:back"][0].startswith(("IL", "LTp"))
        np.testing.assert_array_equal(ds["constrained_removed_index"], result.dataset["constrained_removed_index"])
    axes = removal_plot(result).axes
    drawn = [line for line in axes[0].get_lines() if line.get_label() and not line.get_label().startswith("_")]
    assert [line.get_label() for line in drawn] == list(result.dataset["group"].values[:6])
    np.testing.assert_array_equal(drawn[4].get_ydata(), result.dataset["free_removed_change"].values[:, 4])
    assert "least change" in result.summary()


def test_the_exported_osim_chains_removal_is_the_one_posture_removal(tmp_path):
    """OpenSim (spinectl's export of the paper's chain, its own controls, PCSA in cm^2): removal='muscles' with a
    group, at 0, 0.5 and 1 s, equals with_contributions on analyse at that time (the one-posture removal of
    ``spinectl anatomy --contributions``, every muscle listed) to 1e-12 relative; a muscle's removal changes the
    index (the test can fail)."""
    from spinectl import anatomy
    from spinectl.anatomy.analyses import analyse
    from spinectl.anatomy.contributions import with_contributions
    from spinectl.anatomy.export_osim import export_osim
    from spinectl.anatomy.recordings import recorded_point
    from spinectl.model.config import load_preset

    export_osim(load_preset("wagner2012"), 0.03, 0.04, tmp_path / "chain.osim")
    loaded = anatomy.load(tmp_path / "chain.osim")
    path = flexion_file(loaded, tmp_path / "flexion.mot")
    groups = {"straight": "straight"}
    ds = motion_response(
        loaded, read_recording(path, "posture"), frames=(0, 20, 10), removal="muscles", groups=groups, progress=False
    ).dataset
    for i, t in enumerate(ds["time"].values):
        one = analyse(loaded, posture=path, time=float(t))
        posture = recorded_point(loaded, path, None, float(t)).posture
        parts = with_contributions(loaded, one, posture=posture, count=len(loaded.muscles), groups=groups)
        for name, contrib in (("free", parts.free), ("constrained", parts.constrained)):
            expected = [contrib.removals[str(key)].least_eigenvalue for key in ds["group"].values]
            np.testing.assert_allclose(ds[f"{name}_removed_index"].values[i], expected, rtol=1e-12, atol=0)
    muscle = loaded.muscles[0]
    assert ds["free_removed_index"].sel(group=muscle).values[0] != ds["free_index"].values[0]
