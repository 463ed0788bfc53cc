"""Parameter studies: the study file's validation, the chunk plan, the Zarr store, Dask runs, kill and resume.

The reference for every result is :func:`spinectl.landscape.sweep.sweep` of the same
model, with ``chunk_size`` equal to a chunk of whole rows, so that both solve
the very same stacked problems: the answers must agree bit for bit.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest
import xarray as xr
import zarr

from spinectl.cli import main
from spinectl.errors import ConfigError, ModelError, OutputError, ParameterError
from spinectl.landscape import budget, schema, study, sweep
from spinectl.landscape.study import run, spec
from spinectl.landscape.study import store as study_store
from spinectl.model import config

ROOT = Path(__file__).resolve().parents[2]

GRID = "E = { start = 0.0, stop = 0.08, num = 6 }\nLambda = { start = 0.0, stop = 0.08, num = 10 }\n"
STUDY = f"""# four combinations x 3 tiles of 2 rows = 12 chunks of 20 points
[study]
chunk_size = 20
description = "test study"

[axes]
{GRID}K = [0.0, 15.0]
"body.mass" = [35.0, 45.0]
"""
TILE_POINTS = 20


def write(tmp_path: Path, text: str = STUDY, name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The study run in-process, uninterrupted: the results every other run must reproduce."""
    folder = tmp_path_factory.mktemp("reference")
    result = study.run_study(study.parse_study(STUDY), folder / "ref.zarr", scheduler="synchronous", progress=False)
    assert result.complete and result.computed == 12 and result.where == "in-process"
    return study.load(folder / "ref.zarr")


# --- the study file ----------------------------------------------------------------------------


def study_with(axes: str = "", head: str = "", more: str = "") -> str:
    return f"[study]\n{head}\n[axes]\n{GRID}{axes}\n{more}"


NORMAL_MASS = '[samples]\ncount = 3\nseed = 1\n[samples.parameters]\n"body.mass" = {{ {} }}\n'

BAD_STUDIES = [
    ("[studyy]\n", ConfigError, "studyy", "did you mean 'study'"),
    (study_with(head="chunksize = 8"), ConfigError, "study.chunksize", "did you mean 'chunk_size'"),
    (study_with(head='outputs = ["min_pcsa"]'), ConfigError, "study.outputs[0]", "did you mean 'min_pcsa_cm2'"),
    (study_with(head="chunk_size = 0"), ParameterError, "study.chunk_size", "must be an integer in [1, 65536]"),
    (study_with(head='preset = "nope"'), ConfigError, "study.preset", "must be one of"),
    (study_with(more="[model]\nbody.mass = -1.0\n"), ParameterError, "model.body.mass", "must be > 0"),
    (study_with('"body.mas" = [40.0]'), ConfigError, 'axes."body.mas"', "did you mean 'mass'"),
    (study_with('"body.mass" = [40.0, -1.0]'), ParameterError, 'axes."body.mass"[1]', "body.mass: must be > 0"),
    (study_with("K = [-1.0]"), ParameterError, "axes.K[0]", "passive.stiffness: must be >= 0"),
    (study_with('"body.mass" = [40.0, 40.0]'), ParameterError, 'axes."body.mass"', "must not repeat a value"),
    (study_with('"body.mass" = []'), ParameterError, 'axes."body.mass"', "at least one value"),
    (study_with('"body.mass" = [40.0, "a"]'), ParameterError, 'axes."body.mass"', "all numbers or all strings"),
    (study_with('"muscles.0.upper" = [0.1]'), ParameterError, 'axes."muscles.0.upper"', "name one of its values"),
    (study_with('"muscles.0.name" = ["a"]'), ParameterError, 'axes."muscles.0.name"', "must not rename"),
    (study_with('K = [0.0]\n"passive.stiffness" = [1.0]'), ParameterError, 'axes."passive.stiffness"', "axes.K sets"),
    (study_with('"body.mass" = [1.0]\nbody.mass = [2.0]'), ParameterError, 'axes."body.mass"', "is given twice"),
    ("[axes]\nLambda = [0.0]\n", ParameterError, "axes.E", "is required"),
    ("[axes]\nE = { start = 0.0, stop = 0.08 }\nLambda = [0.0]\n", ParameterError, "axes.E", "missing num"),
    ("[axes]\nE = { start = 0.08, stop = 0.0, num = 3 }\nLambda = [0.0]\n", ParameterError, "axes.E",
     "must be { start, stop, num } with start <= stop"),
    # the one rule of every range (_validate.linear_range): before, linspace kept 0 alone, or 0.01 three times
    ("[axes]\nE = { start = 0.0, stop = 0.08, num = 1 }\nLambda = [0.0]\n", ParameterError, "axes.E",
     "with num = 1 must have start = stop"),
    (study_with('"body.mass" = { start = 40.0, stop = 40.0, num = 3 }'), ParameterError, 'axes."body.mass"',
     "with start = stop must have num = 1: 3 values would all be 40"),
    ("[axes]\nE = [0.5]\nLambda = [0.0]\n", ParameterError, "axes.E", "must be in [-0.1, 0.1] m"),
    (study_with(more=NORMAL_MASS.format('distribution = "gauss", mean = 40.0, std = 1.0')), ParameterError,
     'samples.parameters."body.mass".distribution', "must be one of 'normal'"),
    (study_with(more=NORMAL_MASS.format('distribution = "normal", mean = 40.0')), ParameterError,
     'samples.parameters."body.mass"', "needs std"),
    (study_with(more=NORMAL_MASS.format('distribution = "normal", mean = 40.0, sd = 1.0')), ConfigError,
     'samples.parameters."body.mass".sd', "did you mean 'std'"),
    (study_with(more="[samples]\nseed = 1\n"), ParameterError, "samples.count", "is required"),
    # a count too large or not an integer is the fault named, also when the parameters are missing (before:
    # "samples.parameters: is required"); the bound is spec.MAX_COMBINATIONS, the message says why
    (study_with(more="[samples]\ncount = 1e9\n"), ParameterError, "samples.count",
     "must be an integer in [1, 10000]: each draw is a combination"),
    (study_with(more="[samples]\ncount = 1000000000\n"), ParameterError, "samples.count",
     "must be an integer in [1, 10000]: each draw is a combination, all checked before any work (got 1000000000)"),
    (study_with(more="[samples]\ncount = 3.0\n" + NORMAL_MASS.format('distribution = "normal", mean = 40.0, std = 1.0')
     .replace("[samples]\ncount = 3\n", "")), ParameterError, "samples.count",
     "must be an integer in [1, 10000]: each draw is a combination, all checked before any work (got 3.0)"),
    # a repeated output, also one after others (before: accepted, silently one array)
    (study_with(head='outputs = ["status", "min_pcsa_cm2", "status"]'), ParameterError, "study.outputs[2]",
     "must name each output once (repeated: 'status')"),
    (study_with(more="[samples]\ncount = 2\nsed = 1\nparameters = {}\n"), ConfigError, "samples.sed", "'seed'"),
]  # fmt: skip
"""(file, error class, field, part of the message): each class of mistake in a study file."""


@pytest.mark.parametrize(("text", "kind", "field", "needle"), BAD_STUDIES)
def test_study_file_errors_name_the_field(text, kind, field, needle):
    with pytest.raises(kind) as info:
        study.parse_study(text)
    assert info.value.field == field and needle in info.value.message


@pytest.mark.parametrize(
    ("axis", "got", "hint"),
    [
        ("E = { start = 0, stop = 8, num = 81 }", "'{ start = 0, stop = 8, num = 81 }': 0 to 8 m",
         "; lengths are in metres: if you meant { start = 0, stop = 8, num = 81 } cm, "
         "give { start = 0, stop = 0.08, num = 81 }"),
        ("E = [0, 4, 8]", "'[0, 4, 8]': 0 to 8 m",
         "; lengths are in metres: if you meant [0, 4, 8] cm, give [0, 0.04, 0.08]"),
        ("E = [0, 1, 2, 3, 4, 5, 6, 7, 8]", "'[0, 1, 2, ..., 8]': 0 to 8 m",
         "; lengths are in metres: if you meant [0, 1, 2, ..., 8] cm, give [0, 0.01, 0.02, ..., 0.08]"),
        ("E = 0.5", "'0.5': 0.5 to 0.5 m", ""),  # 0.5 cm would be in range, but 0.5 m is no cm slip (5 x the range)
    ],
)  # fmt: skip
def test_a_grid_out_of_range_is_named_as_written_with_a_cm_hint(axis, got, hint):
    """Before: 'E: ... (got 0.2)', the first bad point, which the file never wrote; now the axis as the file
    writes it, its extent and, where every value read as cm lies in the range, the same axis in metres
    (the default model's range is [-0.1, 0.1] m: docs/model.md), as ``spinectl sweep --E 0:8:81`` says."""
    with pytest.raises(ParameterError) as info:
        study.parse_study(f"[axes]\n{axis}\nLambda = [0.0, 0.04]\n")
    assert info.value.field == "axes.E"
    assert info.value.message == f"must be in [-0.1, 0.1] m, the modelled range (got {got}){hint}"


def test_set_applies_before_the_grid_is_checked(tmp_path):
    """``--set`` on the base model is part of the study before its grid is checked: a wider range admits
    the grid (before, the file's own model refused it first)."""
    path = write(tmp_path, "[axes]\nE = [0.0, 0.15]\nLambda = [0.0]\n")
    with pytest.raises(ParameterError, match="got '\\[0, 0.15\\]'"):
        study.load_study(path)
    widened = study.load_study(path, overrides=["geometry.eccentricity_range=[-0.2, 0.2]"])
    assert widened.eccentricity == (0.0, 0.15)


def test_a_draw_out_of_range_is_caught_before_any_work():
    """A normal mass with std = mean draws a negative mass now and then: which draw says so."""
    text = study_with(
        more=NORMAL_MASS.replace("count = 3", "count = 50").format('distribution = "normal", mean = 40.0, std = 40.0')
    )
    with pytest.raises(ParameterError) as info:
        study.parse_study(text)
    draws = spec.Sampled("body.mass", "normal", (("mean", 40.0), ("std", 40.0))).draw(50, 1)
    first_bad = int(np.flatnonzero(draws <= 0)[0])
    assert info.value.field == f'samples.parameters."body.mass"[{first_bad}]'


def test_values_valid_alone_but_not_together_name_the_combination():
    """mass_height 0.15 m lies above the default top CoR (0.145 m), a top CoR at 0.16 m lies below the
    default mass height (0.326 m); together the mass sits below the joint (params.Model)."""
    text = study_with('"body.mass_height" = [0.15, 0.3]\n"geometry.cor_heights.0" = [0.16]')
    with pytest.raises(ParameterError) as info:
        study.parse_study(text)
    assert info.value.field == "body.mass_height"
    assert "study combination body.mass_height = 0.15, geometry.cor_heights.0 = 0.16" in info.value.message


def test_too_many_combinations_are_refused():
    text = study_with(
        '"body.mass" = { start = 30.0, stop = 50.0, num = 101 }\nK = { start = 0.0, stop = 15.0, num = 100 }'
    )
    with pytest.raises(ParameterError, match="at most 10,000 combinations"):
        study.parse_study(text)


def test_unquoted_dotted_keys_and_aliases_read_as_parameters(tmp_path):
    """TOML reads ``body.mass = [..]`` as a nested table; it names the same axis as ``"body.mass"``."""
    (tmp_path / "model.toml").write_text("[body]\nmass = 50.0\n")
    text = study_with("body.mass = [35, 45]\ndelay = [0.05]", head='config = "model.toml"')
    parsed = study.parse_study(text, base_dir=tmp_path)
    assert parsed.dims == ("body.mass", "delay") and parsed.axes[1].parameter == "reflex.delay"
    assert parsed.axes[0].values == (35, 45) and parsed.model.body.mass == 50.0
    assert parsed.overrides((1, 0)) == {"body.mass": 45, "reflex.delay": 0.05}


def test_the_example_in_the_docs_is_a_valid_study():
    page = (ROOT / "docs" / "studies.md").read_text()
    example = study.parse_study(page.split("```toml\n", 1)[1].split("```", 1)[0])
    assert example.dims == ("body.mass", "K", "delay", "sample") and example.shape == (3, 2, 3, 20)
    assert example.model.reflex.activation == 0.5 and example.tile == (50, 81) and example.n_chunks == 720


def test_digest_ignores_comments_and_follows_values():
    base = study.parse_study(STUDY).digest()
    assert study.parse_study("# another comment\n" + STUDY.replace(" = ", "=")).digest() == base
    assert study.parse_study(STUDY.replace("45.0", "46.0")).digest() != base


# --- samples -----------------------------------------------------------------------------------


def test_draws_are_fixed_by_the_seed_and_independent_of_other_parameters():
    mass = '"body.mass" = { distribution = "uniform", low = 30.0, high = 50.0 }\n'
    height = '"body.mass_height" = { distribution = "normal", mean = 0.326, std = 0.01 }\n'
    head = "[samples]\ncount = 4\nseed = {}\n[samples.parameters]\n"
    one = study.parse_study(study_with(more=head.format(7) + mass))
    two = study.parse_study(study_with(more=head.format(7) + mass + height))
    other_seed = study.parse_study(study_with(more=head.format(8) + mass))
    draws = one.samples.values()["body.mass"]
    np.testing.assert_array_equal(two.samples.values()["body.mass"], draws)
    assert not np.array_equal(other_seed.samples.values()["body.mass"], draws)
    assert one.dims == ("sample",) and one.overrides((2,)) == {"body.mass": draws[2]}
    assert np.all((draws >= 30.0) & (draws < 50.0))


@pytest.mark.parametrize(
    ("distribution", "arguments", "transform", "mean", "std"),
    [
        ("normal", (("mean", 40.0), ("std", 4.0)), lambda x: x, 40.0, 4.0),
        ("lognormal", (("median", 40.0), ("sigma", 0.1)), np.log, np.log(40.0), 0.1),
        ("uniform", (("low", 30.0), ("high", 50.0)), lambda x: x, 40.0, 20.0 / np.sqrt(12.0)),
    ],
)
def test_draws_follow_their_distribution(distribution, arguments, transform, mean, std):
    """Sample mean within 4 standard errors of the distribution's (of log x for lognormal); the standard
    deviation within 10 % (uniform: (high - low) / sqrt(12))."""
    n = 4000
    x = transform(spec.Sampled("body.mass", distribution, arguments).draw(n, 2012))
    assert abs(x.mean() - mean) < 4 * std / np.sqrt(n)
    assert x.std() == pytest.approx(std, rel=0.1)


# --- the chunk plan ----------------------------------------------------------------------------


@pytest.mark.parametrize(("chunk_size", "tile"), [(20, (2, 10)), (25, (2, 10)), (7, (1, 7)), (1000, (6, 10))])
def test_chunks_cover_every_point_once(chunk_size, tile):
    plan = study.parse_study(STUDY.replace("chunk_size = 20", f"chunk_size = {chunk_size}"))
    assert plan.tile == tile
    covered = np.zeros(plan.shape + plan.grid_shape, int)
    for i in range(plan.n_chunks):
        chunk = plan.chunk(i)
        assert chunk.index == i
        covered[chunk.combination + (chunk.eccentricity, chunk.lordosis)] += 1
    assert np.all(covered == 1)


# --- results ------------------------------------------------------------------------------------


def assert_equals_sweep(dataset: xr.Dataset, parsed: study.Study) -> None:
    """Every combination bit for bit equal to the sweep of its model, solved in the same blocks."""
    for combination in np.ndindex(*parsed.shape):
        model = config.set_parameters(parsed.model, parsed.overrides(combination))
        expected = sweep.sweep(model, parsed.eccentricity, parsed.lordosis, chunk_size=TILE_POINTS, progress=False)
        got = dataset.isel(dict(zip(parsed.dims, combination, strict=True)))
        for name in parsed.outputs:
            xr.testing.assert_identical(got[name].reset_coords(drop=True), expected[name].reset_coords(drop=True))


def test_in_process_study_equals_the_sweep(reference):
    assert_equals_sweep(reference, study.parse_study(STUDY))
    assert reference["K"].attrs["parameter"] == "passive.stiffness" and reference["K"].attrs["units"] == "N m/rad"
    assert reference["body.mass"].attrs["units"] == "kg" and reference.attrs["description"] == "test study"
    assert np.all(reference["chunk_done"].values == 1)


def test_one_chunk_runs_in_process_without_a_cluster(tmp_path):
    one = study.parse_study(f"[study]\noutputs = ['min_pcsa_cm2', 'status']\n[axes]\n{GRID}")
    result = study.run_study(one, tmp_path / "one.zarr", progress=False)
    assert one.n_chunks == 1 and result.where == "in-process" and result.addresses == ()
    expected = sweep.sweep(one.model, one.eccentricity, one.lordosis, chunk_size=60, progress=False)
    got = study.load(tmp_path / "one.zarr")
    assert set(got.data_vars) == {"min_pcsa_cm2", "status", "chunk_done", "chunk_crc32"}
    xr.testing.assert_identical(got["status"].reset_coords(drop=True), expected["status"].reset_coords(drop=True))


def test_the_chains_sdps_are_outputs_on_request(tmp_path):
    """Named in outputs, the coupled chain's SDP variables come out as in a sweep --coupled of the same chunk
    (the same stacked problem, so the same bits); by default they are not computed."""
    names = ["local_stiffness_Nm_per_rad", "joint_global_pcsa_cm2"]
    one = study.parse_study(f"[study]\noutputs = {names}\n[axes]\n{GRID}")
    study.run_study(one, tmp_path / "one.zarr", progress=False)
    got = study.load(tmp_path / "one.zarr")
    expected = sweep.sweep(one.model, one.eccentricity, one.lordosis, chunk_size=60, progress=False, coupled=True)
    for name in names:
        xr.testing.assert_identical(got[name].reset_coords(drop=True), expected[name].reset_coords(drop=True))
    assert "local_stiffness_total_Nm_per_rad" not in study.parse_study(f"[axes]\n{GRID}").outputs


@pytest.mark.parametrize("name", ["cocontraction_local_stiffness_total_Nm_per_rad", "delay_s"])
def test_an_atlas_output_is_no_study_output(name):
    """The atlas's own outputs (schema.DRAW_VARIABLES) are refused by name, not met with "did you mean" a landscape
    variable: the co-contraction's local stiffness would be pointed at local_stiffness_total_Nm_per_rad, another
    quantity."""
    with pytest.raises(ConfigError, match=rf"study.outputs\[1\]: .*'{name}' is an output of the atlas's draws"):
        study.parse_study(f"[study]\noutputs = ['status', '{name}']\n[axes]\n{GRID}")


def test_two_local_workers_on_loopback_give_the_same_bits(reference, tmp_path, monkeypatch):
    """A LocalCluster of two worker processes: same store as in-process; it listens on 127.0.0.1 only."""
    listening: list[str] = []
    write = study_store.Writer.write

    def spy(self, chunk, outputs):  # the cluster is up while chunks are written
        if not listening:
            processes = [psutil.Process(), *psutil.Process().children(recursive=True)]
            listening.extend(c.laddr.ip for p in processes for c in p.net_connections("inet") if c.status == "LISTEN")
        write(self, chunk, outputs)

    monkeypatch.setattr(study_store.Writer, "write", spy)
    result = study.run_study(study.parse_study(STUDY), tmp_path / "two.zarr", workers=2, progress=False)
    assert result.where == "2 local workers" and len(result.addresses) == 3
    assert all(a.startswith("tcp://127.0.0.1:") for a in result.addresses)
    assert listening and set(listening) == {"127.0.0.1"}
    xr.testing.assert_identical(study.load(tmp_path / "two.zarr"), reference)


def test_the_executor_maps_any_picklable_function():
    """The engine's public executor, outside a study: ``operator.neg`` over 0..4 is -0..-4 (the closed form),
    in order in-process, in some order on two local workers; bad options are refused before a cluster starts."""
    import operator

    from spinectl.landscape.study import executor

    with executor.executor("synchronous", None, 5) as here:
        assert list(here.as_completed(operator.neg, range(5))) == [0, -1, -2, -3, -4] and here.where == "in-process"
    with executor.executor(None, 2, 5) as there:
        found = sorted(there.as_completed(operator.neg, range(5), key=lambda i: f"neg-{i}"))
        assert found == [-4, -3, -2, -1, 0] and there.where == "2 local workers" and len(there.addresses) == 3
    with pytest.raises(ParameterError, match="^workers: sets the size of the local cluster"):
        with executor.executor("synchronous", 2, 5):
            pass


def test_an_existing_cluster_by_its_address(reference, tmp_path):
    """``scheduler='tcp://...'``: the study connects to a cluster it did not start, and leaves it running."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None) as cluster:
        address = cluster.scheduler_address
        result = study.run_study(study.parse_study(STUDY), tmp_path / "s.zarr", scheduler=address, progress=False)
        assert result.where == f"{address} (1 worker)" and len(cluster.scheduler_info["workers"]) == 1
    xr.testing.assert_identical(study.load(tmp_path / "s.zarr"), reference)


# --- interruption and resume ---------------------------------------------------------------------


def test_stopped_study_resumes_to_the_same_bits(reference, tmp_path):
    parsed, out = study.parse_study(STUDY), tmp_path / "s.zarr"
    first = study.run_study(parsed, out, scheduler="synchronous", max_chunks=5, progress=False)
    assert (first.computed, first.complete) == (5, False)
    partial = study.load(out)
    np.testing.assert_array_equal(partial["chunk_done"].values, [1] * 5 + [0] * 7)
    assert np.isnan(partial["min_pcsa_cm2"].values).sum() == 7 * TILE_POINTS  # unwritten chunks read NaN
    second = study.run_study(parsed, out, scheduler="synchronous", resume=True, progress=False)
    assert (second.done_before, second.computed, second.complete) == (5, 7, True)
    xr.testing.assert_identical(study.load(out), reference)  # every chunk written exactly once


def test_computed_points_are_those_of_the_chunks_done(tmp_path):
    """5 of the 12 chunks done (3 tiles of 2 E-rows each per combination of K and body.mass): the points the
    store marks computed are those whose status was written (a second reading: statuses read '' where not),
    the first combination whole and the first 4 of 6 E-rows of the second."""
    parsed, out = study.parse_study(STUDY), tmp_path / "s.zarr"
    study.run_study(parsed, out, scheduler="synchronous", max_chunks=5, progress=False)
    partial = study.load(out)
    done = study_store.computed(partial)
    assert done.dims == ("K", "body.mass", "E", "Lambda")
    np.testing.assert_array_equal(done.values, partial["status"].values != "")
    assert done.values[0, 0].all() and done.values[0, 1, :4].all() and not done.values[0, 1, 4:].any()
    assert int(done.sum()) == 5 * TILE_POINTS


def test_the_k_axis_has_the_unit_of_its_convention():
    """Under eq. 2 as printed (``wagner2012_mass_free``) K is read in 1/s^2 (docs/model.md, "Passive stiffness: two
    conventions"), so a study's K axis says so; under 'physical' it stays N m/rad (before: N m/rad for both)."""
    for preset, unit in (("wagner2012_mass_free", "1/s^2"), ("wagner2012", "N m/rad")):
        parsed = study.parse_study(f'[study]\npreset = "{preset}"\n[axes]\n{GRID}K = [0.0, 15.0]\n')
        assert study_store._parameter_attributes(parsed.model, "passive.stiffness")["units"] == unit


def test_killed_study_resumes_without_computing_a_chunk_twice(reference, tmp_path):
    """SIGKILL a study run by the CLI once two chunks are done, then resume it.

    ``chunk_done`` counts the writes of each chunk: after the resume every count
    is 1, so the chunks finished before the kill were not computed again.
    """
    path, out = write(tmp_path), tmp_path / "killed.zarr"
    command = [sys.executable, "-m", "spinectl", "study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    env = os.environ | {"PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(command, cwd=ROOT, env=env, start_new_session=True, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None and done_chunks(out) < 2:
            time.sleep(0.005)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    before = study.load(out)["chunk_done"].values
    assert 2 <= before.sum() < 12, "the kill must land mid-study"
    result = study.run_study(study.parse_study(STUDY), out, scheduler="synchronous", resume=True, progress=False)
    assert (result.done_before, result.computed) == (before.sum(), 12 - before.sum())
    xr.testing.assert_identical(study.load(out), reference)


def done_chunks(out: Path) -> int:
    try:
        return int(zarr.open_group(out, mode="r")["chunk_done"][:].sum())
    except (OSError, KeyError, ValueError, zarr.errors.BaseZarrError):
        return 0  # not created yet


# --- the store's guards ----------------------------------------------------------------------------


def test_existing_store_is_refused_without_resume(tmp_path):
    parsed, out = study.parse_study(STUDY), tmp_path / "s.zarr"
    study.run_study(parsed, out, scheduler="synchronous", max_chunks=1, progress=False)
    files = sorted(p.relative_to(out) for p in out.rglob("*"))
    with pytest.raises(OutputError, match="add --resume"):
        study.run_study(parsed, out, scheduler="synchronous", progress=False)
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == files
    other = study.parse_study(STUDY.replace("45.0", "46.0"))
    with pytest.raises(ParameterError, match="holds another study") as info:
        study.run_study(other, out, scheduler="synchronous", resume=True, progress=False)
    assert info.value.field == "store"
    with pytest.raises(ParameterError, match="not a spinectl study store"):
        study.run_study(parsed, tmp_path, scheduler="synchronous", resume=True, progress=False)


def test_resume_without_a_store_starts_one(tmp_path):
    parsed = study.parse_study(STUDY)
    result = study.run_study(parsed, tmp_path / "new.zarr", scheduler="synchronous", resume=True, max_chunks=0)
    assert (result.done_before, result.computed) == (0, 0)
    assert study.load(tmp_path / "new.zarr")["chunk_done"].sum() == 0


def test_unreachable_scheduler_leaves_no_store(tmp_path):
    with pytest.raises(ParameterError, match="cannot connect") as info:
        study.run_study(
            study.parse_study(STUDY), tmp_path / "s.zarr", scheduler="tcp://127.0.0.1:1", connect_timeout=0.5
        )
    assert info.value.field == "scheduler" and not (tmp_path / "s.zarr").exists()


def test_open_store_rejects_other_folders(tmp_path):
    with pytest.raises(ParameterError, match="not a spinectl study store"):
        study.open_store(tmp_path)


def test_an_attachment_on_a_centre_of_rotation_stops_the_study_before_work(tmp_path):
    """A lower attachment at (0, 0.005) is L5S1 itself at E = Lambda = 0 (tests/suites/test_robustness.py)."""
    text = study_with('"muscles.0.lower.0" = [0.12, 0.0]\n"muscles.0.lower.1" = [0.005]\n"muscles.0.spread" = [0.0]')
    text = text.replace(GRID, "E = [0.0]\nLambda = [0.0]\n")
    with pytest.raises(ModelError, match="study combination muscles.0.lower.0 = 0.0"):
        study.parse_study(text)


# --- the command line ------------------------------------------------------------------------------


def test_cli_runs_and_resumes_a_study(tmp_path, capsys):
    path, out = write(tmp_path), tmp_path / "s.zarr"
    assert main(["study", str(path), "--out", str(out), "--scheduler", "synchronous", "--max-chunks", "4"]) == 0
    line = capsys.readouterr().out.strip()
    assert line.startswith("study: 4 of 12 chunks done") and "run again with --resume" in line and str(out) in line
    assert main(["study", str(path), "--out", str(out), "--scheduler", "synchronous", "--resume"]) == 0
    assert "12 of 12 chunks done (8 computed now, 4 before)" in capsys.readouterr().out


def test_an_interrupted_study_says_how_much_is_saved_and_how_to_continue(tmp_path, capsys, monkeypatch):
    """Ctrl-C while the third chunk is written: the line counts the two chunks in the store (the resume
    computes exactly the other ten) and says how to continue; before, it said only "spinectl: interrupted"."""
    from spinectl.landscape.study.interrupt import interrupted_text

    path, out = write(tmp_path), tmp_path / "s.zarr"
    write_chunk, written = study_store.Writer.write, []

    def interrupted(self, chunk, outputs):
        if len(written) == 2:
            raise KeyboardInterrupt
        write_chunk(self, chunk, outputs)
        written.append(chunk.index)

    monkeypatch.setattr(study_store.Writer, "write", interrupted)
    assert main(["study", str(path), "--out", str(out), "--scheduler", "synchronous"]) == 130
    expected = interrupted_text(2, 12, str(out), run.RESUME)
    assert capsys.readouterr().err == f"spinectl: {expected}\n"
    assert expected.endswith("; continue with --resume")
    monkeypatch.setattr(study_store.Writer, "write", write_chunk)
    assert main(["study", str(path), "--out", str(out), "--scheduler", "synchronous", "--resume"]) == 0
    assert "12 of 12 chunks done (10 computed now, 2 before)" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("arguments", "needle"),
    [
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "workers: sets the size of the local cluster"),
        (["--scheduler", "localhost"], "scheduler: must be 'synchronous' or a dask.distributed address"),
        (["--workers", "0"], "--workers must be >= 1"),
        (["--workers", "100000"], "workers: must be an integer in [1,"),
        (["--max-chunks", "-1"], "--max-chunks must be >= 0"),
        # addresses without a host or a usable port: before, a wait of 10 s or Python's "invalid literal for int()"
        (["--scheduler", "tcp://127.0.0.1:99999"], "scheduler: must be tcp://HOST:PORT with a host and a port in"),
        (["--scheduler", "tcp://127.0.0.1:abc"], "scheduler: must be tcp://HOST:PORT"),
        (["--scheduler", "tcp://:8786"], "scheduler: must be tcp://HOST:PORT"),
        (["--scheduler", "tcp://127.0.0.1"], "scheduler: must be tcp://HOST:PORT"),
    ],
)
def test_cli_bad_options_are_one_line(tmp_path, capsys, arguments, needle):
    code = main(["study", str(write(tmp_path)), "--out", str(tmp_path / "s.zarr"), *arguments])
    err = capsys.readouterr().err
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "s.zarr").exists()


def test_cli_bad_study_file_is_one_line(tmp_path, capsys):
    path = write(tmp_path, STUDY.replace("35.0", "-35.0"))
    code = main(["study", str(path), "--out", str(tmp_path / "s.zarr")])
    err = capsys.readouterr().err
    assert code == 2 and 'axes."body.mass"[0]: body.mass: must be > 0' in err and len(err.strip().splitlines()) == 1
    assert main(["study", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "s.zarr")]) == 2
    assert "study: file not found" in capsys.readouterr().err
    assert not (tmp_path / "s.zarr").exists()


def test_a_finished_store_opens_with_plain_xarray_without_warnings(tmp_path):
    """After the last chunk the metadata is consolidated: xarray.open_zarr needs no options."""
    import warnings

    from spinectl.landscape.study import load_study, run_study

    path = tmp_path / "s.toml"
    path.write_text(
        '[study]\npreset = "default"\noutputs = ["min_pcsa_cm2"]\n'
        "[axes]\nE = { start = 0.0, stop = 0.08, num = 3 }\nLambda = { start = 0.0, stop = 0.08, num = 3 }\n"
    )
    run_study(load_study(path), tmp_path / "s.zarr", scheduler="synchronous", progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ds = xr.open_zarr(tmp_path / "s.zarr")
    assert ds.min_pcsa_cm2.shape == (3, 3)


def test_an_attachment_on_a_centre_of_rotation_inside_the_grid_stops_the_study_before_work(tmp_path):
    """The same attachment, at L5S1 for E = Lambda = 0, now the middle of a 3 x 3 grid, not a corner.

    Before, only the corners were checked: the study made its store, solved the chunks
    before the bad point and could never finish.
    """
    text = study_with('"muscles.0.lower.0" = [0.12, 0.0]\n"muscles.0.lower.1" = [0.005]\n"muscles.0.spread" = [0.0]')
    text = text.replace(GRID, "E = [-0.01, 0.0, 0.01]\nLambda = [-0.01, 0.0, 0.01]\n")
    with pytest.raises(ModelError, match="at E = 0 m, Lambda = 0 m.*study combination muscles.0.lower.0 = 0.0"):
        study.parse_study(text)
    assert list(tmp_path.iterdir()) == []


# --- faults: one store per run, lost chunks, schedulers that are not (tests of docs/robustness.md) -----------


def test_a_second_run_on_the_same_store_is_refused_while_the_first_runs(reference, tmp_path):
    """Two fresh runs on one store: the second starts while the first is past its existence check.

    The second is started from inside the first's ``store.create`` (the moment at which both
    used to have passed the check); it must stop at once naming the first, and the first
    must finish its store whole (every chunk of the reference, written once).
    """
    parsed, out = study.parse_study(STUDY), tmp_path / "s.zarr"
    create, refusals = study_store.create, []

    def create_with_a_rival(*args):
        with pytest.raises(OutputError, match=f"in use by another study run \\(process {os.getpid()} ") as info:
            study.run_study(parsed, out, scheduler="synchronous", progress=False)
        refusals.append(str(info.value))
        return create(*args)

    study_store.create = create_with_a_rival
    try:
        study.run_study(parsed, out, scheduler="synchronous", progress=False)
    finally:
        study_store.create = create
    assert len(refusals) == 1 and len(refusals[0].splitlines()) == 1
    xr.testing.assert_identical(study.load(out), reference)
    assert not Path(f"{out}.lock").exists()


def test_a_stale_lock_of_a_dead_process_is_taken_over(tmp_path):
    """A lock of a process that has ended (on this host) is taken over; one of another host is not."""
    import socket

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()  # its pid is free now (reuse within the test is astronomically unlikely)
    out = tmp_path / "s.zarr"
    lock = Path(f"{out}.lock")
    lock.write_text(f"{dead.pid} {socket.gethostname()}\n")
    parsed = study.parse_study(STUDY)
    result = study.run_study(parsed, out, scheduler="synchronous", max_chunks=1, progress=False)
    assert result.computed == 1 and not lock.exists()
    lock.write_text(f"{dead.pid} another-host.invalid\n")
    with pytest.raises(OutputError, match=f"process {dead.pid} on host another-host.invalid"):
        study.run_study(parsed, out, scheduler="synchronous", resume=True, progress=False)
    assert lock.read_text() == f"{dead.pid} another-host.invalid\n"  # not the refused run's to remove


def test_a_lock_whose_pid_runs_another_process_is_taken_over(tmp_path):
    """A lock naming a live pid with another start time (the pid reused after the run died) is stale and
    taken over (before: the live pid blocked the store for ever); with its true start time it is held, and
    so is a lock of an older version (pid and host only) whose pid runs."""
    import socket

    from spinectl.atomic import Owner

    me, host = Owner.me(), socket.gethostname()
    if not me.start:
        pytest.skip("no /proc: process start times cannot be read here")
    out = tmp_path / "s.zarr"
    lock = Path(f"{out}.lock")
    lock.write_text(f"{me.pid} {me.start + 1} {host}\n")
    with study_store.locked(out):
        assert lock.read_text() == f"{me.pid} {me.start} {host}\n"
    for held in (f"{me.pid} {me.start} {host}\n", f"{me.pid} {host}\n"):
        lock.write_text(held)
        with pytest.raises(OutputError, match=f"in use by another study run \\(process {me.pid} on host"):
            with study_store.locked(out):
                pass
        assert lock.read_text() == held
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr.lock"]  # no temporary left


def delete_chunk_file(out: Path, name: str, key: str) -> None:
    """Remove one chunk file of a finished store (and the consolidated metadata is left as it was)."""
    (out / name / key).unlink()


def test_a_lost_chunk_file_is_refused_on_load_and_recomputed_on_resume(reference, tmp_path):
    """Chunk 5 of STUDY (combination (0, 1), third tile of E) is key 0.1.2.0 of min_pcsa_cm2.

    The key follows from the layout: combinations outer (K index 0, mass index 1), the
    three tiles of two E rows inner (5 = 1 * 3 + 2, so E tile 2: rows 4 and 5), one Lambda tile.
    """
    parsed, out = study.parse_study(STUDY), tmp_path / "s.zarr"
    study.run_study(parsed, out, scheduler="synchronous", progress=False)
    assert parsed.chunk(5).combination == (0, 1) and parsed.chunk(5).eccentricity == slice(4, 6)
    delete_chunk_file(out, "min_pcsa_cm2", "0.1.2.0")
    assert_refused_then_computed_again(parsed, out, reference, r"have lost their data")
    group = zarr.open_group(out, mode="r+")  # a store made before every chunk was a file: not checked
    del group.attrs[study_store.CHUNK_FILES]
    delete_chunk_file(out, "min_pcsa_cm2", "0.1.2.0")
    assert np.isnan(study.open_store(out)["min_pcsa_cm2"].values).sum() == TILE_POINTS


def test_a_chunk_file_with_other_bytes_is_refused_on_load_and_recomputed_on_resume(reference, tmp_path):
    """A chunk file present but not as written (a byte appended, as a partial or foreign copy would leave):
    its CRC-32 differs from the one recorded with its count (presence alone would pass it)."""
    parsed, out = study.parse_study(STUDY), tmp_path / "s.zarr"
    study.run_study(parsed, out, scheduler="synchronous", progress=False)
    with (out / "status" / "0.1.2.0").open("ab") as file:  # chunk 5, as in the test above
        file.write(b"x")
    assert_refused_then_computed_again(parsed, out, reference, r"hold other bytes than written")


def assert_refused_then_computed_again(parsed, out: Path, reference, needle: str) -> None:
    """Chunk 5 of ``out`` is damaged: loading refuses it, --resume computes it again, and only it."""
    with pytest.raises(ParameterError, match=r"1 chunk\(s\) counted done .*" + needle + r".* \(chunk 5\)"):
        study.load(out)
    notes = []
    result = study.run_study(parsed, out, scheduler="synchronous", resume=True, progress=False, notify=notes.append)
    assert (result.done_before, result.computed) == (11, 1) and "computing it again" in notes[0]
    xr.testing.assert_identical(study.load(out), reference)


@pytest.mark.parametrize(
    ("lost", "needle"),
    [
        ("min_pcsa_cm2/.zarray", "array 'min_pcsa_cm2': its metadata is lost"),  # the .zmetadata still lists it
        ("E/0", "array 'E': its values are not those written"),  # a coordinate's chunk: read as fill values
        ("K/0", "array 'K': its values are not those written"),
        ("status/.zattrs", "array 'status': its attributes (the dimensions' names) are lost"),
        ("chunk_done/.zarray", "array 'chunk_done': its metadata is lost"),
    ],
)
def test_a_store_with_lost_metadata_or_coordinates_is_refused_in_one_line(tmp_path, capsys, lost, needle):
    """Loading and resuming a store that lost an array's metadata or a coordinate's chunk: one line, exit 2.

    Before, both passed: the loader read the coordinate E as NaN (or dropped the array), and
    ``--resume`` found every chunk done.
    """
    path, out = write(tmp_path), tmp_path / "s.zarr"
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous", "--max-chunks", "3"]
    assert main(arguments) == 0
    (out / lost).unlink()
    with pytest.raises(ParameterError, match=re.escape(needle)):
        study.load(out)
    capsys.readouterr()
    assert main([*arguments, "--resume"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and needle in err and "remove it and run the study afresh" in err


def test_resume_of_a_store_the_user_cannot_write_is_one_line(tmp_path, capsys, monkeypatch):
    """A store the user may read but not write (another user's, read-only, immutable): exit 2, one line,
    before any chunk is solved (before: a PermissionError traceback at the first chunk written).

    Without root, the store's folders lose their write permission; as root (which permissions do
    not stop) the making of a file inside the store fails as it would there.
    """
    path, out = write(tmp_path), tmp_path / "s.zarr"
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    assert main([*arguments, "--max-chunks", "3"]) == 0
    folders = [out, *(p for p in out.iterdir() if p.is_dir())]
    real = study_store.tempfile.mkstemp

    def refused(*args, dir=None, **kwargs):
        if Path(dir).is_relative_to(out):
            raise PermissionError(13, "Permission denied")
        return real(*args, dir=dir, **kwargs)

    if os.geteuid() == 0:
        monkeypatch.setattr(study_store.tempfile, "mkstemp", refused)
    for folder in folders:
        folder.chmod(0o555)
    try:
        files = sorted(p.relative_to(out) for p in out.rglob("*"))
        capsys.readouterr()
        assert main([*arguments, "--resume"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("spinectl: error: cannot write ") and "Permission denied" in err
        assert len(err.splitlines()) == 1 and sorted(p.relative_to(out) for p in out.rglob("*")) == files
    finally:
        for folder in folders:
            folder.chmod(0o755)


def test_a_full_disk_while_chunks_are_written_is_one_line_and_resumable(reference, tmp_path, capsys, monkeypatch):
    """ENOSPC at the third chunk's write (as on a 400 kB tmpfs): one line, exit 2, two chunks done, and
    --resume finishes the store (before: zarr's OSError traceback)."""
    import errno

    real, writes = zarr.Array.__setitem__, []

    def filling(self, selection, value):
        if self.basename == "status":  # one output of each chunk: the third chunk's write fails
            writes.append(selection)
            if len(writes) == 3:
                raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, selection, value)

    path, out = write(tmp_path), tmp_path / "s.zarr"
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    with monkeypatch.context() as patch:
        patch.setattr(zarr.Array, "__setitem__", filling)
        assert main(arguments) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "No space left on device" in err and "--resume" in err
    assert done_chunks(out) == 2 and not Path(f"{out}.lock").exists()
    assert main([*arguments, "--resume"]) == 0
    xr.testing.assert_identical(study.load(out), reference)


def test_an_all_nan_chunk_is_still_a_file(tmp_path):
    """A chunk whose values are all fill values (every point infeasible: pcsa_max tiny) is written as a file.

    Without ``write_empty_chunks`` zarr would skip it, and the check of lost chunks could
    not tell it from a deleted one.
    """
    text = f"[study]\noutputs = ['min_pcsa_cm2']\n[model]\nbody.mass = 40.0\n[axes]\n{GRID}"
    parsed = study.parse_study(text.replace("[model]\n", "[model]\noptimisation.pcsa_max = 1e-6\n"))
    out = tmp_path / "s.zarr"
    study.run_study(parsed, out, scheduler="synchronous", progress=False)
    loaded = study.load(out)
    assert np.isnan(loaded["min_pcsa_cm2"].values).all() and (out / "min_pcsa_cm2" / "0.0").is_file()


def test_the_writer_writes_the_files_that_xarray_writes(tmp_path):
    """Each chunk goes straight into its zarr arrays' regions: the same files, bit for bit, as the
    ``Dataset.to_zarr(region=...)`` the writer used before (the second method), also for a chunk of
    fill values only (every point infeasible), which both write as a file."""
    text = STUDY.replace("[axes]\n", '[axes]\n"optimisation.pcsa_max" = [1e-6, 1.0]\n')
    parsed = study.parse_study(text)
    chunks = [parsed.chunk(i) for i in (0, parsed.n_chunks - 1)]  # all-infeasible, and one of pcsa_max = 1
    solved = [run.solve_chunk(task) for task in run.tasks(parsed, [c.index for c in chunks])]
    probe = run._probe(parsed)
    ours, theirs = tmp_path / "ours.zarr", tmp_path / "theirs.zarr"
    writer = study_store.Writer(parsed, ours, study_store.create(parsed, ours, probe))
    study_store.create(parsed, theirs, probe)
    lead = (np.newaxis,) * len(parsed.dims)
    for chunk, (_, outputs) in zip(chunks, solved, strict=True):
        writer.write(chunk, outputs)
        region = {d: slice(i, i + 1) for d, i in zip(parsed.dims, chunk.combination, strict=True)}
        region |= {"E": chunk.eccentricity, "Lambda": chunk.lordosis}
        part = {n: (parsed.dims + schema.dims_of(n, x.ndim), x[lead]) for n, x in outputs.items()}
        xr.Dataset(part).to_zarr(theirs, region=region, consolidated=False, zarr_format=2, write_empty_chunks=True)
    assert np.isnan(solved[0][1]["min_pcsa_cm2"]).all() and not np.isnan(solved[1][1]["min_pcsa_cm2"]).all()
    files = {p.relative_to(theirs) for p in theirs.rglob("*") if p.is_file()} - {Path(".zattrs")}
    outputs = [p for p in files if p.parts[0] in solved[0][1] and not p.name.startswith(".")]
    assert len(outputs) == 2 * len(solved[0][1])  # a file per output and chunk, the empty one too
    for name in sorted(p for p in files if p.parts[0] not in (study_store.DONE, study_store.CHECKSUM)):
        assert (ours / name).read_bytes() == (theirs / name).read_bytes(), name


@pytest.fixture
def http_server():
    """A plain HTTP server on 127.0.0.1 (something that listens but is no Dask scheduler), closed after."""
    import http.server
    import threading

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.BaseHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_something_else_than_a_scheduler_gives_up_in_time(http_server, tmp_path):
    """An HTTP server at the address: one ParameterError after ``connect_timeout``, no store, no lock."""
    start = time.monotonic()
    with pytest.raises(ParameterError, match="cannot connect to .*no answer of a Dask scheduler within 1 s"):
        study.run_study(study.parse_study(STUDY), tmp_path / "s.zarr", scheduler=http_server, connect_timeout=1.0)
    assert time.monotonic() - start < 10
    assert not (tmp_path / "s.zarr").exists() and not (tmp_path / "s.zarr.lock").exists()


def test_a_scheduler_without_workers_stops_after_the_worker_timeout(tmp_path, capsys):
    """A scheduler with no worker: the CLI says so, waits --worker-timeout, then one line, exit 2, no store."""
    from distributed import LocalCluster

    options = {"processes": False, "protocol": "tcp://", "host": "127.0.0.1", "dashboard_address": None}
    with LocalCluster(n_workers=0, **options) as cluster:
        address = cluster.scheduler_address
        arguments = ["study", str(write(tmp_path)), "--out", str(tmp_path / "s.zarr"), "--scheduler", address]
        start = time.monotonic()
        code = main([*arguments, "--worker-timeout", "0.5"])
        elapsed = time.monotonic() - start
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and elapsed < 10
    assert err[0] == f"study: {address} (0 workers)" and "waiting up to 0.5 s" in err[1]
    assert err[-1].startswith(f"spinectl: error: scheduler: {address} has no worker, and none joined within 0.5 s")
    assert not (tmp_path / "s.zarr").exists()


def test_workers_vanishing_mid_run_stop_the_study_after_the_worker_timeout(reference, tmp_path, capsys):
    """Every worker of the cluster gone once a chunk is written: one line after --worker-timeout, exit 2,
    a store that --resume finishes (before: the run waited for ever, silently)."""
    import threading

    from distributed import LocalCluster

    options = {"processes": False, "protocol": "tcp://", "host": "127.0.0.1", "dashboard_address": None}
    out = tmp_path / "s.zarr"
    with LocalCluster(n_workers=1, threads_per_worker=1, **options) as cluster:

        def stop_the_workers():
            deadline = time.monotonic() + 120
            while done_chunks(out) < 1 and time.monotonic() < deadline:
                time.sleep(0.005)
            cluster.scale(0)

        threading.Thread(target=stop_the_workers, daemon=True).start()
        arguments = ["study", str(write(tmp_path)), "--out", str(out), "--scheduler", cluster.scheduler_address]
        start = time.monotonic()
        code = main([*arguments, "--worker-timeout", "1"])
        elapsed = time.monotonic() - start
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and elapsed < 60, (code, elapsed)
    assert "every worker has gone, and none joined within 1 s" in err[-1] and "--resume" in err[-1]
    assert 1 <= done_chunks(out) < 12 and not Path(f"{out}.lock").exists()
    result = study.run_study(study.parse_study(STUDY), out, scheduler="synchronous", resume=True, progress=False)
    assert result.complete
    xr.testing.assert_identical(study.load(out), reference)


@pytest.mark.parametrize("scheme", ["ucx", "inproc", "tls", "ws", "wss"])
def test_schemes_spinectl_cannot_use_are_refused_with_the_reason(tmp_path, capsys, scheme):
    address = f"{scheme}://127.0.0.1:8786"
    code = main(["study", str(write(tmp_path)), "--out", str(tmp_path / "s.zarr"), "--scheduler", address])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert f"(got '{address}'): {scheme}:// {study.executor.UNUSABLE_SCHEMES[scheme]}" in err


def test_ctrl_c_while_the_local_cluster_starts_is_one_line(tmp_path):
    """SIGINT to the whole process group (as a terminal's Ctrl-C) once the first worker process exists.

    Its worker processes used to print their own KeyboardInterrupt tracebacks, and
    closing the half-started cluster raised an AssertionError.
    """
    out = tmp_path / "s.zarr"
    command = [sys.executable, "-m", "spinectl", "study", str(write(tmp_path)), "--out", str(out), "--workers", "2"]
    env = os.environ | {"PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(command, cwd=ROOT, env=env, start_new_session=True, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None and not psutil.Process(proc.pid).children():
            time.sleep(0.01)
        os.killpg(proc.pid, signal.SIGINT)
        err = proc.communicate(timeout=60)[1]
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert (proc.returncode, err) == (130, "spinectl: interrupted\n")
    assert not Path(f"{out}.lock").exists()


def test_a_server_announcing_an_exabyte_frame_is_no_scheduler(tmp_path):
    """A server on 127.0.0.1 that answers with a frame length of 2**62 bytes: Dask's reader tries to
    allocate it (MemoryError); that is one ParameterError, not a traceback, and no store or lock."""
    import socket
    import struct
    import threading

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)

    def answer():
        connection, _ = listener.accept()
        with connection:
            connection.sendall(struct.pack("<Q", 2**62))  # the length of the frames that would follow
            connection.recv(1024)

    thread = threading.Thread(target=answer, daemon=True)
    thread.start()
    address = f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    try:
        with pytest.raises(ParameterError, match="cannot connect to"):
            study.run_study(study.parse_study(STUDY), tmp_path / "s.zarr", scheduler=address, connect_timeout=2.0)
    finally:
        listener.close()
    assert not (tmp_path / "s.zarr").exists() and not (tmp_path / "s.zarr.lock").exists()


def test_one_lock_per_store_however_it_is_named(tmp_path):
    """A second run naming the store with a trailing slash, through '..' or a symbolic link is refused too
    (before: each name had its own lock file, 's.zarr/.lock' even inside the store, and both runs went on)."""
    out = tmp_path / "s.zarr"
    out.mkdir()
    (tmp_path / "link.zarr").symlink_to(out)
    (tmp_path / "sub").mkdir()
    with study_store.locked(out):
        for name in (f"{out}/", tmp_path / "link.zarr", tmp_path / "sub" / ".." / "s.zarr"):
            with pytest.raises(OutputError, match="is in use by another study run"):
                with study_store.locked(name):
                    pass
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.zarr", "s.zarr", "sub"]  # the lock removed


# --- resources: bounded by cost, estimated before the work ---------------------------------------


def test_too_many_chunks_are_refused_before_the_combinations_are_checked(monkeypatch):
    """The test study has 12 chunks (4 combinations x 3 tiles): with at most 11 allowed it is refused, naming
    chunk_size (each chunk is a file of every output: a million chunks of 1 point would be millions of files)."""
    monkeypatch.setattr(spec, "MAX_CHUNKS", 11)
    with pytest.raises(ParameterError, match="gives 12 chunks, more than the 11") as info:
        study.parse_study(STUDY)
    assert info.value.field == "study.chunk_size"


def test_the_store_template_is_one_dask_task_per_array_whatever_the_chunks():
    """Making the store built a dask graph of one task per study chunk and output (324,000 chunks of two
    outputs: 2.3 GB and 153 s before the first chunk): each array is now one dask chunk, its Zarr chunks the
    study's through its encoding. Counted: 12 chunks, yet one task per variable."""
    parsed = study.parse_study(STUDY)
    probe = run._probe(parsed)
    template = study_store.template(parsed, probe)
    for name in (*probe, study_store.DONE, study_store.CHECKSUM):
        variable = template[name]
        assert variable.data.npartitions == 1 and len(variable.data.__dask_graph__()) == 1
    assert template["min_pcsa_cm2"].encoding["chunks"] == (1, 1, *parsed.tile)


def test_a_study_beyond_the_free_disk_is_refused_before_the_store_is_made(tmp_path, monkeypatch):
    """With 100 bytes free, the store (about 1 kB a point, compressed) cannot fit: one line, no store, no lock."""
    monkeypatch.setattr(budget, "free_disk", lambda path: 100.0)
    out = tmp_path / "s.zarr"
    with pytest.raises(OutputError, match=r"240 points need about .*, and its file system has 100 B free"):
        study.run_study(study.parse_study(STUDY), out, scheduler="synchronous", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_a_long_study_states_its_estimate_first(tmp_path, monkeypatch):
    """Work estimated to take NOTICE_SECONDS or more (0 here) is announced in one line: the study's 240
    points (4 combinations x 60 grid points), disk, memory and CPU time, from the benchmark's cost a point."""
    monkeypatch.setattr(budget, "NOTICE_SECONDS", 0.0)
    lines = []
    parsed = study.parse_study(STUDY)
    study.run_study(parsed, tmp_path / "s.zarr", scheduler="synchronous", progress=False, notify=lines.append)
    assert [line for line in lines if line.startswith("study: 240 points, about ")] == lines and len(lines) == 1
    cost = run.estimate(parsed, parsed.n_chunks, run._probe(parsed))
    assert cost.seconds == pytest.approx(240 * budget.STUDY_SECONDS_PER_POINT)


@pytest.mark.parametrize(
    ("dtype", "problem"), [('"<f4"', "its dtype is <f4, not <f8"), ('"<i2"', "its metadata cannot be read")]
)
def test_an_edited_dtype_is_one_line_at_open_and_resume(tmp_path, dtype, problem):
    """A store whose array metadata says another dtype (edited by hand): reading and --resume name the array
    and the problem in one line, exit 2 (before: a reshape ValueError, or zarr's TypeError for a NaN fill value
    of an integer dtype, as tracebacks)."""
    path = write(tmp_path)
    out = tmp_path / "s.zarr"
    assert main(["study", str(path), "--out", str(out), "--scheduler", "synchronous", "--max-chunks", "2"]) == 0
    metadata = out / "min_pcsa_cm2" / ".zarray"
    metadata.write_text(metadata.read_text().replace('"<f8"', dtype))
    with pytest.raises(ParameterError, match=f"array 'min_pcsa_cm2': {problem}"):
        study.load(out)
    with pytest.raises(ParameterError, match=f"array 'min_pcsa_cm2': {problem}"):
        study.run_study(study.parse_study(STUDY), out, scheduler="synchronous", resume=True, progress=False)


def test_a_folder_in_place_of_a_chunk_file_gets_advice_that_works(tmp_path):
    """A folder where a done chunk's file belongs: the resume used to compute the chunk, fail to write it
    ("Is a directory") and advise --resume again, for ever. Now it names the folder to remove at once, and
    once it is removed the resume finishes the study."""
    out = tmp_path / "s.zarr"
    parsed = study.parse_study(STUDY)
    study.run_study(parsed, out, scheduler="synchronous", max_chunks=2, progress=False)
    chunk = out / "min_pcsa_cm2" / "0.0.0.0"
    chunk.unlink()
    chunk.mkdir()
    with pytest.raises(ParameterError, match=f"remove '{chunk}', which is not a file"):
        study.load(out)
    for _ in range(2):  # the same advice each time, and no chunk computed
        with pytest.raises(OutputError, match=f"cannot write '{chunk}': a folder .* remove it, then run again"):
            study.run_study(parsed, out, scheduler="synchronous", resume=True, progress=False)
    chunk.rmdir()
    result = study.run_study(parsed, out, scheduler="synchronous", resume=True, progress=False)
    assert result.complete and result.computed == 11


def test_a_combination_whose_arithmetic_fails_is_named(tmp_path):
    """K = 1e308 passes validation (a finite stiffness) but overflows the reflex columns of its chunks: the one
    line names the combination, as validation errors do, so the user knows which value to change."""
    text = study_with(axes="K = [0.0, 1e308]\n")
    with pytest.raises(
        ModelError, match=r"the model's arithmetic fails .*\(study combination passive\.stiffness = 1e\+308\)"
    ):
        study.run_study(study.parse_study(text), tmp_path / "s.zarr", scheduler="synchronous", progress=False)


@pytest.mark.parametrize(
    ("damage", "needle"),
    [
        (lambda text: "{not json", "cannot be read as JSON (Expecting property name"),  # garbage (the case)
        (lambda text: text[: len(text) // 2], "cannot be read as JSON ("),  # truncated, as by a full disk
        (lambda text: "[1, 2]", "is not Zarr's consolidated metadata"),  # JSON of the wrong shape
        (lambda text: '{"metadata": {}, "zarr_consolidated_format": 1}', "does not list the store's metadata files"),
        (lambda text: text.replace('"study_digest": "', '"study_digest": "0'), "does not hold what '.zattrs'"),
    ],
)
def test_a_damaged_zmetadata_is_named_with_its_remedy(tmp_path, capsys, damage, needle):
    """A finished store whose consolidated metadata is damaged: loading and ``--resume`` say so in one line, naming
    the file and the remedy, which works: without the file, --resume writes it again (before: "'s.zarr' is not a
    spinectl study store" for garbage; an empty listing gave a KeyError traceback; an edited one passed)."""
    text = STUDY.replace('"body.mass" = [35.0, 45.0]\n', "")  # 6 chunks
    path, out = write(tmp_path, text), tmp_path / "s.zarr"
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    assert main(arguments) == 0
    file = out / ".zmetadata"
    written = file.read_text()
    file.write_text(damage(written))
    with pytest.raises(ParameterError, match=re.escape(needle)) as info:
        study.load(out)
    assert info.value.field == "store" and repr(str(file)) in info.value.message
    capsys.readouterr()
    assert main([*arguments, "--resume"]) == 2
    err = capsys.readouterr().err
    assert (
        len(err.splitlines()) == 1 and needle in err and "remove that file and run the study again with --resume" in err
    )
    file.unlink()
    assert main([*arguments, "--resume"]) == 0
    assert json.loads(file.read_text()) == json.loads(written)


@pytest.mark.parametrize(
    ("name", "make"),
    [
        (".zmetadata", lambda file: file.symlink_to("/dev/zero")),  # read until the memory ran out (24 GB, OOM)
        (".zmetadata", os.mkfifo),  # read for ever
        ("status/.zarray", os.mkfifo),  # an array's own metadata: --resume hung, its lock left behind
        (".zattrs", lambda file: file.mkdir()),
    ],
)
def test_a_metadata_file_that_is_no_regular_file_is_named_not_read(tmp_path, capsys, name, make):
    """A store's metadata file replaced by a FIFO, a link to /dev/zero or a folder: --resume and load refuse it in
    one line naming the file, before zarr opens it (before: a hang, or the kernel's OOM killer), and no lock is
    left behind."""
    text = STUDY.replace('"body.mass" = [35.0, 45.0]\n', "")
    path, out = write(tmp_path, text), tmp_path / "s.zarr"
    arguments = ["study", str(path), "--out", str(out), "--scheduler", "synchronous"]
    assert main(arguments) == 0
    file = out / name
    file.unlink()
    make(file)
    capsys.readouterr()
    assert main([*arguments, "--resume"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and f"its metadata file {str(file)!r} is not a regular file" in err
    assert not Path(f"{out}.lock").exists()
    with pytest.raises(ParameterError, match="is not a regular file"):
        study.load(out)


def test_a_text_file_beyond_the_bound_is_refused_unread(tmp_path, capsys, monkeypatch):
    """Every TOML reader (config, study, atlas, mapping) refuses a file over 16 MiB before reading it (before: an
    8 GB file read whole, 17 GB of memory, then "not valid TOML"); a sparse file costs no disk here."""
    from spinectl.model._toml import MAX_TEXT_BYTES

    monkeypatch.chdir(tmp_path)  # a short name in the messages
    big = Path("big.toml")
    with big.open("wb") as stream:
        stream.truncate(MAX_TEXT_BYTES + 1)
    for argv, field in (
        (["config", "show", "--config", str(big)], "config"),
        (["study", str(big), "--out", "s.zarr"], "study"),
        (["atlas", str(big), "--out", "a"], "atlas"),
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err == f"spinectl: error: {field}: 'big.toml' is larger than 16 MiB: not a spinectl TOML file\n"
    big.write_text("# a comment\n" * 10)  # a small file of the same name reads
    assert main(["config", "show", "--config", str(big)]) == 0


def test_a_ctrl_c_sent_to_the_process_while_the_cluster_starts_waits_for_the_start():
    """A SIGINT sent to the process (kill -INT pid, as job managers send it) while the main thread blocks SIGINT
    is delivered to another thread, and Python raised KeyboardInterrupt in the main thread at once, in the
    middle of LocalCluster's start (distributed asserted about a minute later). Held, it is noted and raised by
    release, after the start; an ignored SIGINT stays ignored."""
    import threading

    from spinectl.landscape.study.executor import _block_interrupts, _HeldInterrupt, _restore_interrupts

    started, stop = threading.Event(), threading.Event()
    helper = threading.Thread(target=lambda: (started.set(), stop.wait(5)))  # SIGINT not blocked in it
    helper.start()
    started.wait()
    held = _HeldInterrupt()
    previous = _block_interrupts()
    try:
        os.kill(os.getpid(), signal.SIGINT)  # to the process: the helper thread takes it
        time.sleep(0.2)  # Python would raise KeyboardInterrupt here, without the hold
        _restore_interrupts(previous)
        with pytest.raises(KeyboardInterrupt):
            held.release()
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        _restore_interrupts(previous)
        stop.set()
        helper.join()
    ignored = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        quiet = _HeldInterrupt()
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        quiet.release()  # nothing held, nothing raised
    finally:
        signal.signal(signal.SIGINT, ignored)
