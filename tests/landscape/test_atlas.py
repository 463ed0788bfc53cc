"""The atlas: Sobol' indices against a closed form, the fast path against one model per draw, the seed."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from spinectl.landscape import atlas
from spinectl.landscape.columns import point_columns
from spinectl.landscape.priors import parse_atlas
from spinectl.model import chain
from spinectl.model.clinical import lordosis_from_angle
from spinectl.model.config import set_parameters
from spinectl.optimise.coupled.sdp import least_local_stiffness_at
from spinectl.optimise.reference import solve_point

PRIORS = """
[[prior]]
parameter = "lordosis_angle_deg"
distribution = "truncated normal"
mean = 49.8
sd = 11.2
bounds = [20.0, 90.0]
source = "s"
[[prior]]
parameter = "eccentricity_m"
distribution = "uniform"
bounds = [0.0, 0.08]
source = "s"
[[prior]]
parameter = "body.mass"
distribution = "uniform"
bounds = [30.0, 50.0]
source = "s"
[[prior]]
parameter = "passive.stiffness"
distribution = "uniform"
bounds = [0.0, 30.0]
source = "s"
[[prior]]
parameter = "reflex.delay"
distribution = "uniform"
bounds = [0.053, 0.1]
source = "s"
"""


LOCAL = "cocontraction_local_stiffness_total_Nm_per_rad"
"""The chain's least local stiffness at each draw's co-contraction (landscape/schema.DRAW_VARIABLES)."""


def _spec(samples=4, seed=0, chain="true", chunk=16):
    return parse_atlas(f"[atlas]\nsamples = {samples}\nseed = {seed}\nchain = {chain}\nchunk_size = {chunk}\n" + PRIORS)


def test_sobol_indices_of_a_linear_output_are_its_variance_shares():
    """Y = sum a_i X_i: S1_i = ST_i = a_i^2 Var X_i / sum_j a_j^2 Var X_j (closed form), through draw and SALib.

    Var X_i: (b - a)^2 / 12 for the uniforms, scipy's truncnorm variance for the lordosis angle.
    """
    spec = _spec(samples=4096)
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    weights = np.array([0.01, 5.0, 0.02, 0.01, 3.0])
    variances = np.array(
        [
            stats.truncnorm((20 - 49.8) / 11.2, (90 - 49.8) / 11.2, loc=49.8, scale=11.2).var(),
            0.08**2 / 12,
            20.0**2 / 12,
            30.0**2 / 12,
            0.047**2 / 12,
        ]
    )
    y = sum(w * values[name] for w, name in zip(weights, spec.names, strict=True))
    found = atlas.sobol_indices(spec, y)
    share = weights**2 * variances / np.sum(weights**2 * variances)
    for name, expected in zip(spec.names, share, strict=True):
        assert found[name]["S1"] == pytest.approx(expected, abs=0.03)
        assert found[name]["ST"] == pytest.approx(expected, abs=0.03)


MORE_PRIORS = """
[[prior]]
parameter = "body.mass_height"
distribution = "uniform"
bounds = [0.28, 0.38]
source = "s"
[[prior]]
parameter = "reflex.activation_time_constant"
distribution = "uniform"
bounds = [0.03, 0.1]
source = "s"
[[prior]]
parameter = "reflex.activation"
distribution = "uniform"
bounds = [0.3, 0.9]
source = "s"
"""
"""The three fields beyond the shipped five, so that a draw varies every field of FAST."""

OTHER_PHYSICS = ("passive.convention=paper", "body.radius_of_gyration=0.05", "levels.weight_in_gravity=1")
"""K_pas = K theta_k, a gyration radius in theta_k and the levels' weight in the chain's gravity: every body term."""


@pytest.mark.parametrize("priors", [PRIORS, PRIORS + MORE_PRIORS], ids=["five", "eight"])
@pytest.mark.parametrize("assignments", [(), OTHER_PHYSICS], ids=["base", "other-physics"])
def test_the_fast_path_is_one_model_per_draw(priors, assignments):
    """Every field of FAST varied inside one stacked problem gives the outputs of one model per draw (a second method).

    The eight priors vary all of FAST at once (the mass and its height mixed from four models,
    the activation and T_a as arrays); the other physics puts every term of the body in play.
    Agreement to rtol 1e-9 (rounding of the mix); the chain's SDP to its tolerance.
    """
    head = "[atlas]\nsamples = 4\nseed = 0\nchain = true\nchunk_size = 16\n"
    spec = parse_atlas(head + priors, assignments=assignments)
    assert {p.parameter for p in spec.priors if "." in p.parameter} <= set(atlas.FAST)
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    fast, reference = atlas.evaluate(spec, values, method="fast"), atlas.evaluate(spec, values, method="per-draw")
    for name in ("min_pcsa_cm2", "counter_torque_norm_Nm", "spine_delay_margin_s", "delay_s"):
        np.testing.assert_allclose(fast[name], reference[name], rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(fast["status"], reference["status"])
    np.testing.assert_allclose(  # the stacked SDP holds each point's optimum to its tolerance (stacked_sdp)
        fast["cocontraction_local_stiffness_total_Nm_per_rad"],
        reference["cocontraction_local_stiffness_total_Nm_per_rad"],
        rtol=1e-4,
    )


def test_the_chains_local_stiffness_is_at_the_drawn_activation():
    """A draw's least local stiffness is problem (a) with the global muscles at its activation x its minimum PCSA.

    The second method: the per-point reference optimum (solve_point) of the draw's own model, scaled by
    the drawn activation, in the chain's K of that model, solved by the per-point SDP (least_local_stiffness_at).
    With the activation a prior, the minimum PCSA alone (activation 1) gives another answer.
    """
    head = "[atlas]\nsamples = 2\nseed = 3\nchain = true\nchunk_size = 16\n"
    spec = parse_atlas(head + PRIORS + MORE_PRIORS)
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    found = atlas.evaluate(spec, values, method="fast")[LOCAL]
    fields = [name for name in values if "." in name]
    for i in range(3):
        model = set_parameters(spec.model, {f: float(values[f][i]) for f in fields})
        e, lam = float(values["eccentricity_m"][i]), float(values["lordosis_m"][i])
        active = model.reflex.activation * solve_point(model, e, lam).pcsa  # per muscle [m^2]
        stiffness = chain.chain_coefficients(model, e, lam).stiffness(active)
        status, k = least_local_stiffness_at(stiffness, model.optimisation.stability_margin)
        assert status == "optimal"
        assert found[i] == pytest.approx(np.sum(k), rel=1e-4)  # the SDPs' tolerance (stacked_sdp)


@pytest.mark.parametrize("activation", [1.0, 0.5])
def test_a_draws_outputs_are_the_sweeps_at_its_model_and_point(activation):
    """The atlas computes with landscape/columns.py (before, with functions of its own). A draw of the per-draw
    path equals point_columns of its own model at its own point, bit for bit (the same functions on the same
    coefficients and one-point block).

    The chain's local stiffness at the draw's co-contraction, cocontraction_local_stiffness_total_Nm_per_rad,
    is the sweep's local_stiffness_total_Nm_per_rad (the whole minimum PCSA) bit for bit at reflex.activation = 1
    (1.0 x PCSA is PCSA), and more at 0.5 (less global muscle leaves more to the local muscles): two quantities,
    which the atlas wrote under the one name before.
    """
    head = "[atlas]\nsamples = 2\nseed = 1\nchain = true\nchunk_size = 16\n"
    spec = parse_atlas(head + PRIORS, assignments=(f"reflex.activation={activation}",))
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    found = atlas.evaluate(spec, values, method="per-draw")
    fields = [name for name in values if "." in name]
    for i in range(2):
        model = set_parameters(spec.model, {f: float(values[f][i]) for f in fields})
        point = ([values["eccentricity_m"][i]], [values["lordosis_m"][i]])
        sweep, _ = point_columns(model, *point, coupled=True)
        for name in ("min_pcsa_cm2", "counter_torque_norm_Nm", "spine_delay_margin_s"):
            assert found[name][i : i + 1].tobytes() == sweep[name].tobytes(), name
        assert found["status"][i] == sweep["status"][0]
        assert found["counter_torque_max_Nm"][i] == np.max(np.abs(sweep["counter_torque_Nm"][0]))
        local, whole = (
            found["cocontraction_local_stiffness_total_Nm_per_rad"][i],
            sweep["local_stiffness_total_Nm_per_rad"],
        )
        if activation == 1.0:
            assert local.tobytes() == whole[0].tobytes()
        else:
            assert local > whole[0] + 1.0  # N m/rad: well beyond the SDP's tolerance


def test_the_fingerprint_holds_the_output_names(monkeypatch):
    """Chunks saved under an output's former name are another atlas's: renaming an output changes the fingerprint,
    so a resumed run solves them again rather than read back outputs the verdicts no longer find."""
    spec = _spec()
    key = atlas.fingerprint(spec)
    former = {name.replace("cocontraction_", ""): v for name, v in atlas.DRAW_VARIABLES.items()}
    monkeypatch.setattr(atlas, "DRAW_VARIABLES", former)
    assert atlas.fingerprint(spec) != key
    monkeypatch.undo()
    assert atlas.fingerprint(spec) == key


def test_draws_convert_the_angle_with_the_spline():
    """Each draw's Lambda is lordosis_from_angle of its angle; its E and mass lie within the bounds."""
    spec = _spec()
    values = atlas.draw(spec, atlas.saltelli_unit(spec))
    np.testing.assert_array_equal(values["lordosis_m"], lordosis_from_angle(values["lordosis_angle_deg"], spec.model))
    assert np.all((values["body.mass"] >= 30) & (values["body.mass"] <= 50))


def test_wilson_interval_is_the_closed_form():
    """p = 30/100 at 95 %: (p + z^2/2n -+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n), z = 1.959964 (Wilson 1927)."""
    z, n, p = stats.norm.ppf(0.975), 100, 0.3
    centre, half = p + z**2 / (2 * n), z * np.sqrt(p * (1 - p) / n + z**2 / (4 * n**2))
    found = atlas.wilson(30, 100, 0.95)
    assert found["low"] == pytest.approx((centre - half) / (1 + z**2 / n), rel=1e-9)
    assert found["high"] == pytest.approx((centre + half) / (1 + z**2 / n), rel=1e-9)


def test_same_seed_same_numbers_and_resume(tmp_path, monkeypatch):
    """The same seed gives the same JSON; another seed other draws; a second run reads its saved chunks."""
    spec, here = _spec(chain="false"), {"progress": False, "scheduler": "synchronous"}
    first = atlas.run_atlas(spec, tmp_path / "a", **here).to_dict()
    assert atlas.run_atlas(spec, tmp_path / "b", **here).to_dict() == first
    other = atlas.run_atlas(dataclasses.replace(spec, seed=1), None, **here).to_dict()
    assert other["sobol"] != first["sobol"]
    assert {p.name for p in (tmp_path / "a").iterdir()} >= {"atlas.json", "report.md", "density.png", "draws.npz"}

    def refuse(*args, **kwargs):
        raise AssertionError("solved a chunk that was saved")

    monkeypatch.setattr(atlas, "evaluate", refuse)
    assert atlas.run_atlas(spec, tmp_path / "a", progress=False).to_dict() == first  # nothing to solve: no cluster


def _draws(folder):
    with np.load(folder / "draws.npz") as saved:
        return {k: saved[k] for k in saved.files}


def _same_bits(found, expected):
    assert found.keys() == expected.keys()
    for name, values in expected.items():
        assert found[name].dtype == values.dtype and found[name].tobytes() == values.tobytes(), name


@pytest.fixture(scope="module")
def in_process(tmp_path_factory):
    """N = 64 (448 draws of the five priors, the chain's SDP too) in chunks of 64, in this process: the reference."""
    spec = _spec(samples=64, chunk=64)
    out = tmp_path_factory.mktemp("atlas") / "ref"
    return spec, atlas.run_atlas(spec, out, scheduler="synchronous", progress=False).to_dict(), _draws(out)


def test_two_local_workers_give_the_in_process_bits(in_process, tmp_path):
    """A local Dask cluster of two worker processes solves the 7 chunks to the same bits as this process.

    Every draw's parameters and outputs (draws.npz) byte for byte, and the JSON answer equal: a chunk's
    answer depends only on the chunk (:func:`spinectl.landscape.atlas.solve_chunk`), not on where it ran.
    """
    spec, answer, draws = in_process
    notes = []
    result = atlas.run_atlas(spec, tmp_path / "two", workers=2, progress=False, notify=notes.append)
    _same_bits(_draws(tmp_path / "two"), draws)
    assert result.to_dict() == answer and notes == []  # nothing read back, nothing long to announce


def test_an_interrupted_cluster_run_resumes_to_the_same_bits(in_process, tmp_path, monkeypatch):
    """Ctrl-C after three chunks saved on two local workers: three chunk files, nothing else; the run
    again (in-process) solves only the four others and gives the reference's bits."""
    spec, answer, draws = in_process
    save, saved = atlas._save, []

    def interrupted(path, found, *marks):
        if len(saved) == 3:
            raise KeyboardInterrupt
        save(path, found, *marks)
        saved.append(path.name)

    monkeypatch.setattr(atlas, "_save", interrupted)
    with pytest.raises(KeyboardInterrupt) as caught:
        atlas.run_atlas(spec, tmp_path / "cut", workers=2, progress=False)
    folder = str(tmp_path / "cut" / "chunks")  # the line the command prints: the three saved, how to go on
    again = "run the atlas again to continue from them"
    assert str(caught.value) == f"interrupted: 3 of 7 chunks saved in {folder!r}; {again}"
    assert sorted(p.name for p in (tmp_path / "cut" / "chunks").iterdir()) == sorted(saved)
    assert sorted(p.name for p in (tmp_path / "cut").iterdir()) == ["chunks"]  # no temporaries, no answer

    monkeypatch.setattr(atlas, "_save", save)
    evaluate, solved, notes = atlas.evaluate, [], []
    monkeypatch.setattr(atlas, "evaluate", lambda spec, part: solved.append(1) or evaluate(spec, part))
    result = atlas.run_atlas(spec, tmp_path / "cut", scheduler="synchronous", progress=False, notify=notes.append)
    assert len(solved) == 7 - 3 and notes == [
        f"atlas: 3 of 7 chunks read from {str(tmp_path / 'cut' / 'chunks')!r}, saved by an earlier run"
    ]
    _same_bits(_draws(tmp_path / "cut"), draws)
    assert result.to_dict() == answer


def test_verdicts_name_their_criteria():
    """Every verdict the atlas reports names joint by joint or the chain."""
    assert all("joint by joint" in text or "the chain" in text for text in atlas.VERDICTS.values())


def test_the_atlas_runs_in_process_unless_dask_is_asked_for(monkeypatch):
    """Without --scheduler or --workers the executor is asked for 'synchronous' (in-process, no cluster).

    docs/atlas.md, "Where the chunks run": a local cluster cost twice in-process's time on two cores.
    """
    from spinectl.landscape.study import executor as engine

    asked, real = [], engine.executor

    def recording(*args, **kwargs):
        asked.append((kwargs.get("scheduler"), kwargs.get("workers")))
        return real(*args, **kwargs)

    monkeypatch.setattr(engine, "executor", recording)
    atlas.run_atlas(_spec(chain="false"), None, progress=False)
    assert asked == [("synchronous", None)]


def test_a_long_atlas_is_announced_and_what_cannot_fit_refused(tmp_path, monkeypatch):
    """As the study's: the estimate's line before a run of at least NOTICE_SECONDS (here 0), with the draws
    to solve and their CPU time from the benchmark's costs per draw; a memory estimate above what is
    available is one error naming atlas.samples, before --out is made."""
    from spinectl.errors import ParameterError
    from spinectl.landscape import budget

    spec, notes = _spec(chain="false"), []
    monkeypatch.setattr(budget, "NOTICE_SECONDS", 0.0)
    atlas.run_atlas(spec, None, scheduler="synchronous", progress=False, notify=notes.append)
    seconds = 28 * budget.ATLAS_SECONDS_PER_DRAW  # N (D + 2) = 4 x 7 draws on the fast path, no chain
    # one process, chunks of 16, and the atlas's arrays: N = 4, D = 5, 100 bootstrap resamples
    memory = budget.PROCESS_BYTES + 16 * budget.WORKING_BYTES_PER_POINT + budget.atlas_memory(4, 5, 100)
    disk = budget.size(28 * budget.ATLAS_BYTES_PER_DRAW)
    shown = budget.size(memory)
    assert notes == [
        f"atlas: 28 draws, about {disk} on disk, {shown} of memory, {budget.duration(seconds)} of CPU (estimated)"
    ]
    monkeypatch.setattr(budget, "available_memory", lambda: 1e6)
    with pytest.raises(ParameterError, match=f"^atlas.samples: 28 draws need about {shown} of memory"):
        atlas.run_atlas(spec, tmp_path / "out", scheduler="synchronous", progress=False)
    assert not (tmp_path / "out").exists()


EIGHT = "[atlas]\nsamples = {samples}\nchain = false\nbootstrap = {bootstrap}\n" + PRIORS + MORE_PRIORS


@pytest.mark.parametrize(
    ("samples", "bootstrap", "available"),
    [
        (2**24, 100, 16 * 2**30),  # the issue's: the design alone 2^24 x 10 x 8 doubles = 10 GiB; 16 GiB available
        (2**20, 2, 2**30),  # a variant: the design (1.34 GB with its copy) alone tips it; the bootstrap is small
    ],
)
def test_the_design_is_counted_before_it_is_built(tmp_path, monkeypatch, samples, bootstrap, available):
    """An atlas whose design does not fit is refused naming atlas.samples before the design is built.

    The design of N base samples and D = 8 priors is N (D + 2) x D doubles (SALib's, and its clipped copy);
    the estimate used to count only the workers' chunks (150 MB + 16 MB), and the design was built first.
    tracemalloc: the refusal allocates no design (its peak stays below a MB).
    """
    import tracemalloc

    from spinectl.errors import ParameterError
    from spinectl.landscape import budget

    spec = parse_atlas(EIGHT.format(samples=samples, bootstrap=bootstrap))
    design = samples * 10 * 8 * 8  # one copy, in bytes
    assert budget.atlas_memory(samples, 8, bootstrap) >= 2 * design
    monkeypatch.setattr(budget, "available_memory", lambda: float(available))

    def built(spec):
        raise AssertionError("the design was built before the memory check")

    monkeypatch.setattr(atlas, "saltelli_unit", built)
    tracemalloc.start()
    try:
        with pytest.raises(ParameterError) as raised:
            atlas.run_atlas(spec, tmp_path / "out", progress=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert raised.value.field == "atlas.samples" and f"{samples * 10:,} draws need about" in str(raised.value)
    assert f"{budget.size(available)} is available" in str(raised.value) and peak < 1e6
    assert not (tmp_path / "out").exists()


def test_the_memory_estimate_bounds_the_design_and_draws():
    """tracemalloc's peak of building the design and the draws (N = 4096, the eight priors: 7.7 MB) stays within the
    estimate of the atlas's arrays (budget.atlas_memory): the constants are measured, this keeps them honest."""
    import tracemalloc

    from spinectl.landscape import budget

    spec = parse_atlas(EIGHT.format(samples=4096, bootstrap=2))  # few resamples: the design and draws decide
    atlas.saltelli_unit(spec)  # SALib's and scipy's imports, not the design's memory
    tracemalloc.start()
    try:
        atlas.draw(spec, atlas.saltelli_unit(spec))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= budget.atlas_memory(4096, 8, 2)


def test_the_report_tells_an_unbounded_margin_from_an_infeasible_draw():
    """An output with +inf (a spine stable without the reflex) and NaN (infeasible) draws: the report counts each
    by name; it called every non-finite draw infeasible. The limits and the unverified priors are stated."""
    from types import SimpleNamespace

    from spinectl.landscape.atlas_report import report_text

    spec = _spec(chain="false")
    margin = np.array([0.1, np.inf, np.inf, np.nan])
    result = SimpleNamespace(
        n_evaluations=4,
        probabilities={},
        sobol={"spine_delay_margin_s": None},
        sobol_verdicts={},
        nonfinite={"spine_delay_margin_s": 3},
        draws={"spine_delay_margin_s": margin},
    )
    text = report_text(result, spec)
    assert "Not finite at 3 draws (2 unbounded (stable at every delay: no reflex needed); 1 not a number" in text
    assert "within ±30 N m" in text and "within 17 cm² per joint" in text
    unverified = sum("unverified" in p.source.lower() for p in spec.priors)
    assert f"{unverified} of {len(spec.priors)} priors are unverified" in text


def test_damaged_copied_and_foreign_chunks_are_solved_again(in_process, tmp_path, monkeypatch):
    """The reference's seven chunks, then: chunk 1 cut short, chunk 2's file copied over chunk 4's, another atlas's
    chunk renamed as chunk 5, chunk 6 re-saved with other outputs under its old checksum, and another atlas's
    chunk under its own name. Those four are solved again (4 of 7, one line naming them), the answer is the
    reference's to the bit (it read chunk 4 as chunk 2's draws and ended with a traceback on chunk 1), and the
    other atlas's chunk is gone at the end."""
    import shutil

    from spinectl.landscape import atlas_chunks

    spec, answer, draws = in_process
    reference = tmp_path / "ref"
    atlas.run_atlas(spec, reference, scheduler="synchronous", progress=False)
    other = dataclasses.replace(spec, seed=1, chain=False)
    atlas.run_atlas(other, tmp_path / "other", scheduler="synchronous", progress=False)
    out = tmp_path / "out"
    shutil.copytree(reference / "chunks", out / "chunks")
    key, foreign = atlas.fingerprint(spec), atlas.fingerprint(other)
    chunk = {i: out / "chunks" / atlas_chunks.name(key, i) for i in range(7)}
    chunk[1].write_bytes(chunk[1].read_bytes()[:500])
    shutil.copyfile(chunk[2], chunk[4])
    shutil.copyfile(tmp_path / "other" / "chunks" / atlas_chunks.name(foreign, 0), chunk[5])
    with np.load(chunk[6]) as saved:
        edited = {k: saved[k] for k in saved.files}
    edited["min_pcsa_cm2"] = edited["min_pcsa_cm2"] + 1.0
    np.savez(chunk[6], **edited)
    stray = out / "chunks" / atlas_chunks.name(foreign, 0)
    shutil.copyfile(tmp_path / "other" / "chunks" / stray.name, stray)

    evaluate, solved, notes = atlas.evaluate, [], []
    monkeypatch.setattr(atlas, "evaluate", lambda spec, part: solved.append(1) or evaluate(spec, part))
    result = atlas.run_atlas(spec, out, scheduler="synchronous", progress=False, notify=notes.append)
    assert len(solved) == 4 and len(notes) == 2 and notes[0].startswith("atlas: 3 of 7 chunks read")
    line = notes[1]
    assert line.startswith(f"atlas: 4 chunk(s) in {str(out / 'chunks')!r} not used, computing them again: ")
    assert "cannot be read" in line and "holds chunk 2 (a copy from another position)" in line
    assert "is a chunk of another atlas" in line and "1 more" in line and "\n" not in line
    _same_bits(_draws(out), draws)
    assert result.to_dict() == answer
    assert sorted(p.name for p in (out / "chunks").iterdir()) == sorted(p.name for p in chunk.values())
    for index, path in chunk.items():  # every chunk saved again passes its checks
        assert atlas_chunks.read(path, key, index, 64)[1] is None


def test_an_edited_chunk_is_caught_by_its_checksum(in_process, tmp_path):
    """A chunk re-saved with one output changed but its marks kept: read refuses it by the CRC-32."""
    from spinectl.landscape import atlas_chunks

    spec, _, _ = in_process
    key = atlas.fingerprint(spec)
    found = {"status": np.array(["optimal"] * 3), "min_pcsa_cm2": np.array([1.0, 2.0, 3.0])}
    path = tmp_path / atlas_chunks.name(key, 0)
    atlas_chunks.save(path, found, key, 0)
    read, problem = atlas_chunks.read(path, key, 0, 3)
    assert problem is None and read.keys() == found.keys()
    assert all(np.array_equal(read[k], found[k]) for k in found)
    with np.load(path) as saved:
        edited = {k: saved[k] for k in saved.files}
    edited["min_pcsa_cm2"][1] = 2.5
    np.savez(path, **edited)
    assert atlas_chunks.read(path, key, 0, 3) == (None, "holds other outputs than were saved (its checksum differs)")
    assert atlas_chunks.read(path, key, 0, 4)[0] is None  # and a chunk of another size


def test_a_folder_at_a_chunks_name_is_one_line_before_any_solve(tmp_path, monkeypatch):
    """A folder where a chunk belongs could never be saved again: refused at once, naming it (not after the solve)."""
    from spinectl.errors import OutputError
    from spinectl.landscape import atlas_chunks

    spec = _spec(chain="false")
    blocked = tmp_path / "out" / "chunks" / atlas_chunks.name(atlas.fingerprint(spec), 1)
    blocked.mkdir(parents=True)
    monkeypatch.setattr(atlas, "evaluate", lambda *a: (_ for _ in ()).throw(AssertionError("solved")))
    with pytest.raises(OutputError, match="a folder .* stands where a chunk of the atlas belongs"):
        atlas.run_atlas(spec, tmp_path / "out", scheduler="synchronous", progress=False)


def _files(folder):
    """Every output file of an atlas folder (not its chunks) -> its bytes."""
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


@pytest.mark.parametrize("before", [True, False], ids=["previous-set", "fresh"])
def test_an_interrupted_write_leaves_the_previous_set_or_none(tmp_path, monkeypatch, before):
    """Ctrl-C between atlas.json and report.md: the folder holds the previous atlas's four files, byte for byte
    (they were written one by one: a new atlas.json beside the old report.md), or none of them; no temporary
    beside or inside it. The second atlas's chunks stay, to resume it."""
    spec, here = _spec(chain="false"), {"scheduler": "synchronous", "progress": False}
    out = tmp_path / "out"
    if before:
        atlas.run_atlas(spec, out, **here)
    previous = _files(out) if before else {}
    write = atlas.atomic_write_text

    def interrupted(target, text):
        if Path(target).name == "report.md":
            raise KeyboardInterrupt
        return write(target, text)

    monkeypatch.setattr(atlas, "atomic_write_text", interrupted)
    with pytest.raises(KeyboardInterrupt):
        atlas.run_atlas(dataclasses.replace(spec, seed=1), out, **here)
    assert _files(out) == previous and set(previous) in ({"atlas.json", "draws.npz", "report.md", "density.png"}, set())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging folder left
    assert {p.name for p in out.iterdir()} == set(previous) | {"chunks"}


def test_a_killed_write_leaves_the_previous_set_and_the_next_run_the_new(tmp_path):
    """SIGKILL of a subprocess between atlas.json and report.md: the previous four files stand; the next run (of
    the killed atlas) removes the dead run's staging folder, writes its four files and drops the other atlas's
    chunks from out/chunks."""
    import os
    import signal
    import subprocess
    import sys

    from spinectl.landscape import atlas_chunks

    spec, here = _spec(chain="false"), {"scheduler": "synchronous", "progress": False}
    out = tmp_path / "out"
    atlas.run_atlas(spec, out, **here)
    previous = _files(out)
    script = f"""
import dataclasses, os, signal, sys
sys.path.insert(0, {str(Path(__file__).parent)!r})
from test_atlas import _spec
from spinectl.landscape import atlas
from spinectl.landscape.columns import point_columns
write = atlas.atomic_write_text
def killed(target, text):
    if str(target).endswith("report.md"):
        os.kill(os.getpid(), signal.SIGKILL)
    return write(target, text)
atlas.atomic_write_text = killed
spec = dataclasses.replace(_spec(chain="false"), seed=1)
atlas.run_atlas(spec, {str(out)!r}, scheduler="synchronous", progress=False)
"""
    done = subprocess.run([sys.executable, "-c", script], env=os.environ, capture_output=True, timeout=600)
    assert done.returncode == -signal.SIGKILL, done.stderr.decode()[-2000:]
    assert _files(out) == previous
    assert [p.name for p in tmp_path.iterdir() if p.name != "out"]  # the dead run's staging folder, for now
    second = dataclasses.replace(spec, seed=1)
    result = atlas.run_atlas(second, out, **here)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert json.loads((out / "atlas.json").read_text())["sobol"] == json.loads(json.dumps(result.to_dict()))["sobol"]
    key = atlas.fingerprint(second)
    assert {atlas_chunks.NAME.fullmatch(p.name)["atlas"] for p in (out / "chunks").iterdir()} == {key}


def test_the_reports_user_text_cannot_add_markup():
    """A prior's source and the model's --config path (atlas files and paths are the user's) with '|', a line
    break, a heading and HTML: each table row keeps its 7 cells, no line is a heading or a tag the text made, and
    the text reads back escapes aside. Before, a '|' in a source split its row into more cells."""
    from types import SimpleNamespace

    from spinectl.landscape.atlas_report import report_text
    from spinectl.model.source import ModelSource, with_source

    spec = _spec(chain="false")
    hostile = "Doe 2020 | n = 40\n# Injected <b>bold</b> `x`"
    model = with_source(spec.model, ModelSource("wagner2012", "runs/a\n## Injected.toml", "0" * 64))
    priors = tuple(dataclasses.replace(p, source=hostile) for p in spec.priors)
    spec = dataclasses.replace(spec, priors=priors, model=model)
    result = SimpleNamespace(n_evaluations=4, probabilities={}, sobol={}, sobol_verdicts={}, draws={})
    lines = report_text(result, spec).splitlines()
    assert not any(line.startswith(("# Injected", "## Injected", "<b>")) for line in lines)
    start = lines.index("| parameter | distribution | mean | sd | bounds | checked | source |")
    rows = lines[start + 2 : start + 2 + len(priors)]
    for row in rows:  # 8 unescaped pipes: 7 cells
        assert sum(1 for i, c in enumerate(row) if c == "|" and row[i - 1] != "\\") == 8, row
        assert row.endswith("Doe 2020 \\| n = 40\\\\n\\# Injected \\<b\\>bold\\</b\\> \\`x\\` |")
    assert any(line.startswith("Model: ") and "runs/a\\\\n\\#\\# Injected.toml" in line for line in lines)


def test_the_report_says_what_each_verdict_and_interval_rests_on():
    """K and the delay are priors of _spec: the model line says K is drawn (not the base model's 'K = 0'), the
    delay verdict says each draw's delay; without those priors, the model's K and its delay in ms. The
    probabilities' draws are called quasi-random and the intervals conservative, never independent."""
    from types import SimpleNamespace

    from spinectl.landscape.atlas_report import report_text
    from spinectl.landscape.priors import VERDICTS

    band = {"p": 0.5, "low": 0.4, "high": 0.6}
    result = SimpleNamespace(
        n_evaluations=4, probabilities=dict.fromkeys(VERDICTS, band), sobol={}, sobol_verdicts={}, draws={}
    )
    spec = _spec(chain="false")
    text = report_text(result, spec)
    model = next(line for line in text.splitlines() if line.startswith("Model: "))
    assert "K drawn from its prior" in model and "K = " not in model
    assert "each draw's delay drawn from its prior" in text and "independent draws" in text
    assert "are quasi-random" in text and "conservative" in text and "independent draws of" not in text
    assert "| stabilisable_joint_by_joint | some global activation" in text
    fixed = dataclasses.replace(spec, priors=spec.priors[:3])  # the angle, E and the mass: K and the delay fixed
    text = report_text(result, fixed)
    delay_ms = f"{fixed.model.reflex.delay * 1e3:g} ms"
    assert f"the model's {delay_ms} at every draw (no prior draws it)" in text
    assert f"K = {fixed.model.passive.stiffness:g} N m/rad" in text and "K drawn" not in text


def test_the_console_table_says_k_is_drawn_where_a_prior_draws_it():
    """The atlas's table (its stdout) named the base model's 'K = 0 N m/rad' while K was drawn from 0 to 30 N m/rad
    (the report said "K drawn from its prior"): both now say it, from one function (priors.model_line)."""
    spec = _spec(chain="false")
    assert "passive.stiffness" in spec.names  # the premise
    result = atlas.AtlasResult(1, {}, {}, {}, {}, {"passive.stiffness": np.array([5.0])}, spec.model)
    first = result.table().splitlines()[0]
    assert "K drawn from its prior" in first and "K = " not in first
    fixed = atlas.AtlasResult(1, {}, {}, {}, {}, {"body.mass": np.array([40.0])}, spec.model)
    assert f"K = {spec.model.passive.stiffness:g} N m/rad" in fixed.table().splitlines()[0]


def test_the_console_states_the_delay_verdicts_delay_and_reads_an_st_above_one():
    """The console's delay verdict said "at the reflex delay" with no delay: it says the one the report does
    (atlas_report.verdict_criterion): each draw's, drawn, or the model's in ms. A largest ST above 1 (1.133 in a
    newcomer's N = 256 atlas) is read in the same line as sampling error at this N; one in [0, 1] has no note."""
    from spinectl.landscape.atlas_report import verdict_criterion

    spec = _spec(chain="false")
    band = {"p": 0.5, "low": 0.4, "high": 0.6}
    sobol = {"counter_torque_norm_Nm": {p: {"S1": 0.1, "S1_conf": 0.1, "ST": 0.2, "ST_conf": 0.1} for p in spec.names}}
    sobol["counter_torque_norm_Nm"]["eccentricity_m"]["ST"] = 1.133
    n = 256 * (len(spec.names) + 2)
    drawn = atlas.AtlasResult(
        n, {"spine_stable_at_delay": band}, sobol, {}, {}, {"reflex.delay": np.ones(1)}, spec.model
    )
    lines = drawn.table().splitlines()
    assert lines[2].endswith(f"({verdict_criterion('spine_stable_at_delay', spec.names, spec.model)})")
    assert lines[2].endswith("each draw's delay drawn from its prior)")
    assert lines[3].endswith(
        "(eccentricity_m) (ST > 1 is sampling error at N = 256: read as 1; more samples narrow it)"
    )
    fixed = atlas.AtlasResult(n, {"spine_stable_at_delay": band}, {}, {}, {}, {"body.mass": np.ones(1)}, spec.model)
    assert (
        fixed.table()
        .splitlines()[2]
        .endswith(f"the model's {spec.model.reflex.delay * 1e3:g} ms at every draw (no prior draws it))")
    )
    sobol["counter_torque_norm_Nm"]["eccentricity_m"]["ST"] = 0.99
    assert "sampling error" not in drawn.table()


@pytest.mark.parametrize(
    ("p", "rare"),
    [
        (0.992, "Too few failures to estimate these indices (4 of 512 draws fail;"),
        (0.02, "Too few successes to estimate these indices (10 of 512 draws pass;"),
        (0.5, None),
    ],
)
def test_a_verdict_with_few_failures_says_its_indices_are_not_estimated(p, rare):
    """The report's "0.756 ± 1.259" for a verdict with p = 0.992 (4 failures of 2 N = 512 draws) read as a share:
    the verdict's indicator table now says there are too few failures (or successes) to estimate it; p = 0.5 not."""
    from types import SimpleNamespace

    from spinectl.landscape.atlas_report import RARE_OUTCOMES, report_text

    spec = dataclasses.replace(_spec(chain="false"), samples=256)
    table = {name: {"S1": 0.0, "S1_conf": 0.02, "ST": 0.756, "ST_conf": 1.259} for name in spec.names}
    result = SimpleNamespace(
        n_evaluations=256 * (len(spec.names) + 2),
        probabilities={"chain_stabilisable_locally": {"p": p, "low": 0.0, "high": 1.0}},
        sobol={},
        sobol_verdicts={"chain_stabilisable_locally": table},
        draws={},
    )
    lines = report_text(result, spec).splitlines()
    below = lines[lines.index("### `chain_stabilisable_locally (indicator)`") + 2]
    if rare is None:
        assert below == "| parameter | S1 | ST |"
    else:
        assert below.startswith(rare) and f"fewer than {RARE_OUTCOMES})" in below


def test_the_density_figure_says_what_it_draws_and_at_which_mass_and_k():
    """density.png draws the cohort's (E, Lambda) over a min-PCSA landscape of the base model alone: its title
    says so with the number of draws, the colour bar's label names the quantity and its unit, the legend names the
    white contours (the density's levels, % of its peak) beside C, and the footer gives the base model's mass [kg]
    and K [N m/rad], the ones the background is at, and the drawn parameters it does not follow (body.mass,
    passive.stiffness, reflex.delay: each draw's own). A variant with K set to 12 N m/rad names 12."""
    from spinectl.landscape.atlas_report import base_text, density_figure

    spec = _spec()
    grid = np.linspace(0.0, 0.08, 5)
    landscape = {"eccentricity_m": grid, "lordosis_m": grid, "min_pcsa_cm2": np.ones((5, 5))}
    rng = np.random.default_rng(0)
    draws = {"eccentricity_m": rng.uniform(0, 0.08, 30), "lordosis_m": rng.uniform(0, 0.08, 30)}
    fig = density_figure(landscape, draws, atlas.PAPER_OPTIMUM, base_text(spec))
    ax, bar = fig.axes
    assert "30 draws lie in (E, Λ)" in ax.get_title() and "base model's min PCSA" in ax.get_title()
    assert bar.get_ylabel() == "background: min PCSA [cm²], joint by joint"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "cohort density: 10, 30, 50, 70, 90 % of its peak",
        "the paper's optimum C",
    ]
    footer = " ".join(fig.get_supxlabel().split())
    mass, k = spec.model.body.mass, spec.model.passive.stiffness
    assert f"body.mass {mass:g} kg, passive.stiffness K = {k:g} N m/rad" in footer
    assert "each draw's own body.mass, passive.stiffness, reflex.delay varies" in footer
    stiff = dataclasses.replace(spec, model=set_parameters(spec.model, {"passive.stiffness": 12.0}))
    assert "passive.stiffness K = 12 N m/rad" in base_text(stiff)


def test_a_sobol_estimate_outside_zero_one_says_how_to_read_it():
    """S1 and ST are variance shares in [0, 1]; their estimates are not (the report showed S1 = -0.158 ± 0.511 with
    no word): the report says what they are and marks each estimate outside [0, 1], read as the nearest possible
    value where its interval reaches it, else as too few samples; estimates inside are unmarked."""
    from types import SimpleNamespace

    from spinectl.landscape.atlas_report import SOBOL_NOTE, report_text

    row = {"S1": -0.158, "S1_conf": 0.511, "ST": 0.222, "ST_conf": 0.419}
    far = {"S1": 1.4, "S1_conf": 0.1, "ST": 0.5, "ST_conf": 0.1}
    result = SimpleNamespace(
        n_evaluations=4, probabilities={}, sobol={"min_pcsa_cm2": {"body.mass": row, "eccentricity_m": far}},
        sobol_verdicts={}, draws={},
    )  # fmt: skip
    text = report_text(result, _spec(chain="false"))
    assert SOBOL_NOTE in text and "not a negative share" in SOBOL_NOTE
    assert "| `body.mass` | -0.158 ± 0.511 (read as 0: within its interval) | 0.222 ± 0.419 |" in text
    assert "| `eccentricity_m` | 1.400 ± 0.100 (outside [0, 1] beyond its interval: too few samples) | 0.500" in text
