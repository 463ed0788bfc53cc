"""The population stability atlas: verdicts' probabilities and Sobol' indices of the draws, run chunk by chunk.

The draws and their outputs are :mod:`spinectl.landscape.atlas_draws`. Here: the probability of each
verdict with its Wilson interval and the first- and total-order Sobol' indices with SALib's bootstrap
intervals (docs/atlas.md); the draws solved chunk by chunk on the study engine's executor
(:func:`spinectl.landscape.study.executor.executor`), each chunk saved in ``DIR/chunks`` as it finishes
so that an interrupted atlas resumes where it stopped; the output files.
"""

from __future__ import annotations

import dataclasses
import hashlib
import warnings
from pathlib import Path

import numpy as np

from ..atomic import atomic_path, atomic_write_text, check_distinct, check_folder, output_errors, staged_directory
from ..jsondoc import dumps
from ..model.clinical import lordosis_from_angle
from ..model.params import Model
from ..model.source import provenance
from ..optimise.problem import OK_STATUSES
from . import atlas_chunks, budget, columns
from .atlas_draws import (  # noqa: F401 (AtlasUnavailable, FAST, draw and evaluate are the atlas's public names too)
    FAST,
    SEGMENT_OUTPUTS,
    AtlasUnavailable,
    draw,
    evaluate,
    require_salib,
    saltelli_unit,
    unit_problem,
)
from .priors import PAPER_OPTIMUM, VERDICTS, AtlasSpec, model_line
from .schema import DRAW_VARIABLES

OUTPUTS = (
    "min_pcsa_cm2",
    "counter_torque_norm_Nm",
    "cocontraction_local_stiffness_total_Nm_per_rad",
    "spine_delay_margin_s",
)
"""The outputs whose Sobol' indices the atlas reports, each named and defined once in :mod:`spinectl.landscape.schema`
(:data:`~spinectl.landscape.schema.VARIABLES` or :data:`~spinectl.landscape.schema.DRAW_VARIABLES`)."""


@dataclasses.dataclass(frozen=True)
class AtlasResult:
    """The atlas's answer: probabilities of the verdicts and Sobol' indices of the outputs.

    Attributes
    ----------
    n_evaluations : int
        Model evaluations, N (D + 2).
    probabilities : dict
        {verdict: {p, low, high}} over the 2 N draws of Saltelli's A and B [1] (quasi-random, so the
        Wilson intervals, which assume independent draws, are conservative).
    sobol : dict
        {output: {parameter: {S1, S1_conf, ST, ST_conf}}}; None where an output is not finite
        at some draw (counted in ``nonfinite``).
    sobol_verdicts : dict
        The same for each verdict's indicator (1 where it holds): which parameter decides it.
    nonfinite : dict
        {output: number of draws where it is NaN or infinite}.
    draws : dict of str to numpy.ndarray
        Every draw's parameters and outputs, shape (n_evaluations,).
    model : Model or None
        The base model (the parameters no prior varies), named in :meth:`table` and :meth:`to_dict`.
    """

    n_evaluations: int
    probabilities: dict
    sobol: dict
    sobol_verdicts: dict
    nonfinite: dict
    draws: dict = dataclasses.field(repr=False, compare=False)
    model: Model | None = dataclasses.field(default=None, repr=False, compare=False)

    def table(self) -> str:
        """The verdicts' probabilities and the largest total-order index of each output, as text.

        Returns
        -------
        str
            The base model (:func:`~spinectl.landscape.priors.model_line`), then a line per verdict and per output.
        """
        from .atlas_report import console_st_note, verdict_criterion

        lines = [model_line(self.model, self.draws)] if self.model is not None else []
        lines.append(f"{self.n_evaluations} evaluations")
        for name, v in self.probabilities.items():
            said = VERDICTS[name] if self.model is None else verdict_criterion(name, self.draws, self.model)
            lines.append(f"P({name}) = {v['p']:.3f}  [{v['low']:.3f}, {v['high']:.3f}]  ({said})")
        for output, table in self.sobol.items():
            if table is None:
                lines.append(f"{output}: not finite at {self.nonfinite[output]} draws, no Sobol' indices")
                continue
            top = max(table, key=lambda name: table[name]["ST"])
            note = console_st_note(table[top]["ST"], self.n_evaluations // (len(table) + 2))  # N (d + 2) draws
            lines.append(f"{output}: largest ST {table[top]['ST']:.3f} +- {table[top]['ST_conf']:.3f} ({top}){note}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The JSON answer: the model's provenance, n_evaluations, probabilities, sobol(_verdicts), nonfinite, criteria.

        Returns
        -------
        dict
            Plain floats and strings; ``preset``, ``config``, ``config_sha256``, ``overridden``, K and its
            convention as every command's (:func:`~spinectl.model.source.provenance`).
        """
        named = provenance(self.model) if self.model is not None else {}
        return named | {
            "n_evaluations": self.n_evaluations,
            "probabilities": self.probabilities,
            "sobol": self.sobol,
            "sobol_verdicts": self.sobol_verdicts,
            "nonfinite": self.nonfinite,
            "criteria": dict(VERDICTS),
        }


def verdicts(spec: AtlasSpec, outputs: dict) -> dict[str, np.ndarray]:
    """Each verdict of :data:`VERDICTS` at every draw.

    Parameters
    ----------
    spec : AtlasSpec
        Supplies the limits.
    outputs : dict of str to numpy.ndarray
        :func:`evaluate`'s answer.

    Returns
    -------
    dict of str to numpy.ndarray of bool
        NaN outputs (infeasible) count as False.
    """
    feasible = np.isin(outputs["status"], OK_STATUSES)
    out = {
        "stabilisable_joint_by_joint": feasible,
        "counter_torque_within_limit": feasible & (outputs["counter_torque_max_Nm"] <= spec.counter_torque_limit),
        "spine_stable_at_delay": outputs["spine_delay_margin_s"] > outputs["delay_s"],
    }
    if "cocontraction_local_stiffness_max_Nm_per_rad" in outputs:
        k, limit = outputs["cocontraction_local_stiffness_max_Nm_per_rad"], outputs["local_stiffness_limit_Nm_per_rad"]
        out["chain_stabilisable_locally"] = np.isfinite(k) & (k <= limit)
    return out


def wilson(successes: int, n: int, confidence: float) -> dict[str, float]:
    """The proportion and its Wilson score interval.

    Parameters
    ----------
    successes, n : int
        Draws where the verdict holds, and all draws.
    confidence : float
        Level of the interval.

    Returns
    -------
    dict
        ``p``, ``low``, ``high`` [1].

    References
    ----------
    Wilson EB (1927). Probable inference, the law of succession, and statistical inference.
    J Am Stat Assoc 22(158):209-212. doi:10.1080/01621459.1927.10502953.
    """
    from scipy.stats import binomtest

    # Wilson's interval, not the normal one: it stays inside [0, 1] and keeps its level for a rare verdict
    ci = binomtest(int(successes), int(n)).proportion_ci(confidence_level=confidence, method="wilson")
    return {"p": successes / n, "low": float(ci.low), "high": float(ci.high)}


def sobol_indices(spec: AtlasSpec, y: np.ndarray) -> dict | None:
    """First- and total-order Sobol' indices of one output with SALib's bootstrap intervals.

    Parameters
    ----------
    spec : AtlasSpec
        Supplies the priors, ``bootstrap``, ``confidence`` and ``seed``.
    y : numpy.ndarray, shape (N (D + 2),)
        The output at Saltelli's design, in SALib's row order.

    Returns
    -------
    dict or None
        {parameter: {S1, S1_conf, ST, ST_conf}}; None if ``y`` is not finite everywhere.

    References
    ----------
    Saltelli A, Annoni P, Azzini I, Campolongo F, Ratto M, Tarantola S (2010). Variance based
    sensitivity analysis of model output. Comput Phys Commun 181(2):259-270.
    doi:10.1016/j.cpc.2009.09.018. Herman J, Usher W (2017). SALib: an open-source Python library
    for sensitivity analysis. J Open Source Softw 2(9):97. doi:10.21105/joss.00097.
    """
    require_salib()
    from SALib.analyze import sobol

    y = np.asarray(y, float)
    if not np.all(np.isfinite(y)):
        return None
    if np.ptp(y) == 0:  # no variance to share out
        return {name: {"S1": 0.0, "S1_conf": 0.0, "ST": 0.0, "ST_conf": 0.0} for name in spec.names}
    with warnings.catch_warnings():
        # y itself varies (above); SALib also warns when a bootstrap resample of a rare verdict holds no
        # variance. Those resamples widen the interval, which is the answer: a rare verdict is poorly resolved.
        warnings.filterwarnings("ignore", "Constant values encountered", UserWarning)
        found = sobol.analyze(
            unit_problem(len(spec.priors)),
            y,
            calc_second_order=False,
            num_resamples=spec.bootstrap,
            conf_level=spec.confidence,
            print_to_console=False,
            seed=spec.seed + 1,  # SALib 1.6 seeds its bootstrap only `if seed:`, so seed 0 was no seed at all
        )
    keys = ("S1", "S1_conf", "ST", "ST_conf")
    return {name: {k: float(found[k][i]) for k in keys} for i, name in enumerate(spec.names)}


def probability_rows(spec: AtlasSpec, n_rows: int) -> np.ndarray:
    """Rows of Saltelli's A and B matrices: the 2 N draws the probabilities count (the rows between them
    recombine A's and B's columns, so they are not draws of the cohort).

    Parameters
    ----------
    spec : AtlasSpec
    n_rows : int
        N (D + 2).

    Returns
    -------
    numpy.ndarray of int, shape (2 N,)
    """
    step = len(spec.priors) + 2
    starts = np.arange(0, n_rows, step)
    return np.sort(np.concatenate([starts, starts + step - 1]))


def summarise(spec: AtlasSpec, values: dict, outputs: dict) -> AtlasResult:
    """Probabilities and Sobol' indices from the outputs at Saltelli's design.

    Parameters
    ----------
    spec : AtlasSpec
    values, outputs : dict of str to numpy.ndarray
        :func:`draw`'s and :func:`evaluate`'s answers.

    Returns
    -------
    AtlasResult

    Examples
    --------
    A cohort whose upper-body mass alone varies, 30 to 50 kg, at the preset's posture (needs SALib):

    >>> from spinectl.landscape import atlas
    >>> from spinectl.landscape.priors import parse_atlas
    >>> spec = parse_atlas(
    ...     "[atlas]\\nsamples = 16\\nchain = false\\n[[prior]]\\nparameter = 'body.mass'\\n"
    ...     "distribution = 'uniform'\\nbounds = [30.0, 50.0]\\nsource = 'an example'\\n"
    ... )
    >>> values = atlas.draw(spec, atlas.saltelli_unit(spec))
    >>> result = atlas.summarise(spec, values, atlas.evaluate(spec, values))
    >>> result.n_evaluations  # N (D + 2) = 16 x 3
    48
    >>> {name: round(v["p"], 2) for name, v in result.probabilities.items()}
    {'stabilisable_joint_by_joint': 1.0, 'counter_torque_within_limit': 0.0, 'spine_stable_at_delay': 1.0}
    """
    n = outputs["status"].size
    rows = probability_rows(spec, n)  # A's and B's rows only: the others mix two draws' columns, no cohort's member
    found = verdicts(spec, outputs)
    probabilities = {name: wilson(int(v[rows].sum()), rows.size, spec.confidence) for name, v in found.items()}
    names = [o for o in OUTPUTS if o in outputs]
    sobol = {o: sobol_indices(spec, outputs[o]) for o in names}
    by_verdict = {name: sobol_indices(spec, v.astype(float)) for name, v in found.items()}
    nonfinite = {o: int(np.sum(~np.isfinite(outputs[o]))) for o in names}
    return AtlasResult(n, probabilities, sobol, by_verdict, nonfinite, values | outputs, spec.model)


def fingerprint(spec: AtlasSpec) -> str:
    """A short hash of everything that decides the draws and their outputs: resume only the same atlas.

    Parameters
    ----------
    spec : AtlasSpec

    Returns
    -------
    str
        16 hex digits.
    """
    from .. import __version__

    # the output names too: chunks saved under an output's former name are another atlas's, solved again
    named = (spec, __version__, SEGMENT_OUTPUTS, tuple(DRAW_VARIABLES))
    return hashlib.sha256(repr(named).encode()).hexdigest()[:16]


def atlas_file(
    path,
    out,
    *,
    lordosis_angle: float | None = None,
    model: Model | None = None,
    assignments=(),
    progress: bool | None = None,
    config=None,
    **where,
) -> AtlasResult:
    """The atlas of an atlas file (``spinectl atlas``), the lordosis optionally fixed as an angle.

    Parameters
    ----------
    path : str or Path
        The atlas file (:func:`spinectl.landscape.priors.load_atlas`).
    out : str or Path
        Output folder (:func:`run_atlas`).
    lordosis_angle : float, optional
        The lordosis angle [deg] where no prior varies the lordosis
        (:func:`spinectl.model.clinical.lordosis_from_angle`).
    model : Model, optional
        The base model (``--preset``, ``--config``), instead of the file's ``[atlas] model``; neither:
        the preset :data:`~spinectl.model.config.DEFAULT_PRESET`.
    assignments : sequence of str
        ``SECTION.FIELD=VALUE`` over the base model (``--set``).
    progress : bool or None
        As for :func:`run_atlas`.
    config : str or Path, optional
        The ``--config`` file the model was read from, protected like the atlas file.
    **where
        ``scheduler``, ``workers``, ``connect_timeout``, ``worker_timeout`` and ``notify``, as for :func:`run_atlas`.

    Returns
    -------
    AtlasResult

    Raises
    ------
    ConfigError
        The file is invalid.
    ParameterError
        ``lordosis_angle`` is given and a prior varies the lordosis, or it is out of range; bad scheduler
        options; a file that ``out`` would be written over is the atlas file or ``config``.
    """
    from ..errors import ParameterError
    from .priors import load_atlas

    check_distinct({"--out": _outputs(out)}, {"PRIORS.toml": path, "--config": config})
    spec = load_atlas(path, model=model, assignments=assignments)
    if lordosis_angle is not None:
        if {"lordosis_angle_deg", "lordosis_m"} & set(spec.names):
            raise ParameterError("--lordosis-angle", "a prior varies the lordosis already")
        spec = dataclasses.replace(spec, lordosis=float(lordosis_from_angle(lordosis_angle, spec.model)))
    return run_atlas(spec, out, progress=progress, **where)


@dataclasses.dataclass(frozen=True)
class ChunkTask:
    """What a worker needs for one chunk of the atlas: the spec and the chunk's draws (no folder, no file).

    Attributes
    ----------
    index : int
        The chunk: its draws start at ``index * spec.chunk_size``.
    spec : AtlasSpec
        The atlas.
    part : dict of str to numpy.ndarray
        The chunk's draws (:func:`draw`'s answer for them).
    """

    index: int
    spec: AtlasSpec
    part: dict


def solve_chunk(task: ChunkTask) -> tuple[int, dict[str, np.ndarray]]:
    """Solve one chunk of the atlas (:func:`evaluate`); picklable, for the study engine's executor.

    The answer depends only on the chunk, so in-process and any number of workers give the same bits.

    Parameters
    ----------
    task : ChunkTask
        The chunk.

    Returns
    -------
    index : int
        ``task.index``.
    outputs : dict of str to numpy.ndarray
        :func:`evaluate`'s answer for the chunk's draws.
    """
    return task.index, evaluate(task.spec, task.part)


def run_atlas(
    spec: AtlasSpec,
    out: str | Path | None = None,
    *,
    progress: bool | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    connect_timeout: float | None = None,
    worker_timeout: float | None = None,
    notify=None,
) -> AtlasResult:
    """The atlas of a validated spec, its chunks on the study engine's executor, resumable through ``out/chunks``.

    Each chunk is saved (atomically) as it finishes; a run of the same atlas (the same
    :func:`fingerprint`) reads the chunks saved and solves only the others.

    Parameters
    ----------
    spec : AtlasSpec
    out : str or Path, optional
        Output folder: chunks in ``out/chunks`` as they finish (each with its atlas, position and checksum,
        checked when read back: :mod:`spinectl.landscape.atlas_chunks`), then ``atlas.json``, ``draws.npz``,
        ``report.md`` and ``density.png`` together (a staging folder swapped in), then the chunks of
        other atlases removed.
    progress : bool or None
        A progress bar of draws on stderr; None: only on a terminal.
    scheduler : str or None
        Where the chunks run, as for ``spinectl study`` (:func:`spinectl.landscape.study.executor.executor`):
        None, in-process unless ``workers`` is given, then a local Dask cluster; ``'synchronous'``,
        in-process; ``'tcp://host:port'``, an existing ``dask.distributed`` scheduler.
    workers : int or None
        Local worker processes of a local Dask cluster (at most one per chunk).
    connect_timeout, worker_timeout : float or None
        Seconds for a remote scheduler's answer, and to wait for a worker [s]; None: the engine's defaults.
    notify : callable or None
        Called with a line of text for the user: the estimate of a long run, the chunks read back,
        a remote scheduler's worker count.

    Returns
    -------
    AtlasResult

    Raises
    ------
    ParameterError
        Bad scheduler options (before anything is written), an unreachable scheduler; more than the
        available memory holds (:func:`spinectl.landscape.budget.check`, field ``atlas.samples``; the
        design, the draws, their outputs and the bootstrap counted before the design is built).
    OutputError
        ``out`` cannot be written.
    """
    from .study.executor import check_options

    if scheduler is None and workers is None:  # a local cluster cost twice in-process's time on 2 cores (docs/atlas.md)
        scheduler = "synchronous"
    timeouts = {"connect_timeout": connect_timeout, "worker_timeout": worker_timeout}
    timeouts = {k: v for k, v in timeouts.items() if v is not None}
    check_options(scheduler, workers, **timeouts)  # before anything is drawn or written
    where = {"scheduler": scheduler, "workers": workers, **timeouts}
    n = spec.samples * (len(spec.priors) + 2)
    budget.check(_estimate(spec, n, -(-n // spec.chunk_size), where), out)  # before the design is built
    if out is not None:
        check_folder(out, OUTPUT_FILES)  # an output folder that cannot take the files: one line, before the work
    values = draw(spec, saltelli_unit(spec))
    folder = Path(out) / "chunks" if out is not None else None
    outputs = _solve(spec, values, folder, progress, where, notify or (lambda line: None))
    result = summarise(spec, values, outputs)
    if out is not None:
        _write(result, Path(out), spec)
        atlas_chunks.remove_others(Path(out) / "chunks", fingerprint(spec))  # the folder is this atlas's now
    return result


def _solve(spec: AtlasSpec, values: dict, folder: Path | None, progress, where: dict, notify) -> dict:
    """Every chunk's outputs: those saved in ``folder`` read back, the others solved on the executor and saved."""
    from tqdm import tqdm  # plain: tqdm.auto warns in kernels without ipywidgets (as the study)

    from .study.executor import executor

    n, key = values["eccentricity_m"].size, fingerprint(spec)
    names = [atlas_chunks.name(key, index) for index in range(-(-n // spec.chunk_size))]
    parts = _read_saved(spec, folder, names, n, notify)
    todo = [index for index in range(len(names)) if index not in parts]
    done = sum(part["status"].size for part in parts.values())
    cost = _estimate(spec, n - done, len(todo), where)
    if cost.long:
        notify(cost.line())
    if folder is not None:  # an unwritable --out is one line now, not a traceback after the solving
        with output_errors(folder.parent):
            folder.mkdir(parents=True, exist_ok=True)
    tasks = (ChunkTask(index, spec, _part(values, spec, index)) for index in todo)
    kept = f"every chunk finished is saved in {str(folder)!r}" if folder else "no folder, nothing saved"
    options = {"notify": notify, "name": "atlas", "again": f"{kept}; start a worker and run the atlas again"}
    with (
        _saved_on_interrupt(folder, parts, len(names)),
        tqdm(total=n, initial=done, unit="draw", disable=_no_bar(progress), desc="atlas") as bar,
        executor(n_chunks=len(todo), **where, **options) as chunks,
    ):
        for index, found in chunks.as_completed(solve_chunk, tasks, key=lambda task: f"atlas-{key}-{task.index}"):
            if folder is not None:
                _save(folder / names[index], found, key, index)
            parts[index] = found
            bar.update(found["status"].size)
    return {k: np.concatenate([parts[i][k] for i in range(len(names))]) for k in parts[0]}


def _saved_on_interrupt(folder: Path | None, parts: dict, n_chunks: int):
    """Ctrl-C says how many chunks ``folder`` holds and that a second run resumes from them (none without one)."""
    from contextlib import nullcontext

    from .study.interrupt import saved_on_interrupt

    if folder is None:
        return nullcontext()
    return saved_on_interrupt(lambda: len(parts), n_chunks, str(folder), "run the atlas again to continue from them")


def _part(values: dict, spec: AtlasSpec, index: int) -> dict:
    """The draws of chunk ``index``."""
    start = index * spec.chunk_size
    return {k: v[start : start + spec.chunk_size] for k, v in values.items()}


def _no_bar(progress: bool | None) -> bool | None:
    return None if progress is None else not progress  # None: tqdm shows it on a terminal only (as the study)


def _read_saved(spec: AtlasSpec, folder: Path | None, names: list[str], n: int, notify) -> dict[int, dict]:
    """The chunks an earlier run of this atlas saved in ``folder``, each checked (:func:`atlas_chunks.read`).

    A chunk that fails its checks is left to be solved again, with one line for the user naming it and why.
    """
    if folder is None:
        return {}
    key, parts, bad = fingerprint(spec), {}, []
    for index, name in enumerate(names):
        size = min(spec.chunk_size, n - index * spec.chunk_size)
        found, problem = atlas_chunks.read(folder / name, key, index, size)
        if found is not None:
            parts[index] = found
        elif problem:
            bad.append(f"{name} {problem}")
    if parts:
        notify(f"atlas: {len(parts)} of {len(names)} chunks read from {str(folder)!r}, saved by an earlier run")
    if bad:
        more = f"; and {len(bad) - 3} more" if len(bad) > 3 else ""
        listed = "; ".join(bad[:3]) + more
        notify(f"atlas: {len(bad)} chunk(s) in {str(folder)!r} not used, computing them again: {listed}")
    return parts


def _save(path: Path, found: dict, key: str, index: int) -> None:
    """Save a chunk atomically with its atlas, index and checksum (:func:`atlas_chunks.save`)."""
    atlas_chunks.save(path, found, key, index)


def _estimate(spec: AtlasSpec, n_todo: int, n_chunks: int, where: dict) -> budget.Estimate:
    """What the atlas will cost: its arrays in this process (the design first), the workers, the files, the CPU."""
    from .study.executor import local_processes

    processes = local_processes(where["scheduler"], where["workers"], n_chunks)
    fast = {p.parameter for p in spec.priors if "." in p.parameter} <= set(FAST)  # as evaluate's 'auto'
    per_draw = budget.ATLAS_SECONDS_PER_DRAW if fast else budget.ATLAS_PER_DRAW_SECONDS
    seconds = n_todo * (per_draw + spec.chain * budget.ATLAS_CHAIN_SECONDS_PER_DRAW)
    memory = processes * (budget.PROCESS_BYTES + spec.chunk_size * budget.WORKING_BYTES_PER_POINT)
    memory += budget.atlas_memory(spec.samples, len(spec.priors), spec.bootstrap)
    disk, fewer = n_todo * budget.ATLAS_BYTES_PER_DRAW, "samples, or bootstrap resamples (atlas.bootstrap)"
    return budget.Estimate("atlas", n_todo, memory, disk, seconds, field="atlas.samples", fewer=fewer, unit="draws")


OUTPUT_FILES = ("atlas.json", "draws.npz", "report.md", "density.png")
"""The files of an atlas's output folder, beside its ``chunks`` folder."""


def _outputs(out) -> list[Path]:
    """Every file an atlas run into ``out`` may write: :data:`OUTPUT_FILES` and the chunks there already."""
    chunks = Path(out) / "chunks"
    return [Path(out) / name for name in OUTPUT_FILES] + (sorted(chunks.iterdir()) if chunks.is_dir() else [])


def _write(result: AtlasResult, out: Path, spec: AtlasSpec) -> None:
    """The four files, written into a staging folder that then replaces ``out`` as a whole (its chunks kept):
    an interruption leaves the previous atlas's four files or this one's, never a mix."""
    from ..canvas import save_file
    from .atlas_report import base_text, density_figure, report_text

    figure = density_figure(base_landscape(spec, result.draws), result.draws, PAPER_OPTIMUM, base_text(spec))
    with staged_directory(out, OUTPUT_FILES, replaces=OUTPUT_FILES) as stage:
        atomic_write_text(stage / "atlas.json", dumps(result.to_dict()))
        with atomic_path(stage / "draws.npz") as tmp, open(tmp, "wb") as handle:
            np.savez(handle, **{k: np.asarray(v) for k, v in result.draws.items()})
        atomic_write_text(stage / "report.md", report_text(result, spec))
        save_file(figure, stage / "density.png", 120)


def base_landscape(spec: AtlasSpec, draws: dict, n: int = 41) -> dict[str, np.ndarray]:
    """Min PCSA of the base model on an E x Lambda grid spanning the draws (the fast path of the sweep).

    Parameters
    ----------
    spec : AtlasSpec
    draws : dict of str to numpy.ndarray
        ``eccentricity_m`` and ``lordosis_m`` of the draws [m].
    n : int
        Grid points per axis.

    Returns
    -------
    dict
        ``eccentricity_m`` (n,), ``lordosis_m`` (n,) [m] and ``min_pcsa_cm2`` (n, n) [cm^2].
    """

    def axis(values, point):
        low, high = min(values.min(), point), max(values.max(), point)
        pad = 0.05 * (high - low) or 0.01
        return np.linspace(low - pad, high + pad, n)

    e = axis(draws["eccentricity_m"], PAPER_OPTIMUM[0])
    lam = axis(draws["lordosis_m"], PAPER_OPTIMUM[1])
    grid_e, grid_l = np.meshgrid(e, lam, indexing="ij")
    found, _ = columns.point_columns(spec.model, grid_e.ravel(), grid_l.ravel())
    return {"eccentricity_m": e, "lordosis_m": lam, "min_pcsa_cm2": found["min_pcsa_cm2"].reshape(n, n)}
