"""The atlas's report (Markdown) and its figure: the cohort's density over the E x Lambda landscape of min PCSA."""

from __future__ import annotations

import numpy as np

from ..canvas import new_figure
from ..quoting import markdown_cell_code, markdown_text
from .priors import VERDICTS, AtlasSpec, model_line


def report_text(result, spec: AtlasSpec) -> str:
    """The atlas's report: the priors with their sources, the verdicts' probabilities, the Sobol' indices.

    Parameters
    ----------
    result : spinectl.landscape.atlas.AtlasResult
    spec : AtlasSpec

    Returns
    -------
    str
        Markdown.
    """
    lines = [
        "# Population stability atlas",
        "",
        f"Model: {markdown_text(model_line(spec.model, spec.names))} (the parameters no prior varies).",
        "",
        f"{result.n_evaluations} model evaluations: Saltelli's design on a scrambled Sobol' sequence "
        f"(N = {spec.samples}, seed {spec.seed}); probabilities over the 2 N = {2 * spec.samples} draws of "
        f"its A and B matrices, with Wilson intervals at {spec.confidence:g}. The draws are quasi-random, "
        "spread more evenly than independent ones, so these intervals, which assume independent draws, are "
        "conservative: wider than the spread of the probabilities over seeds.",
        "",
        "## Priors",
        "",
        "| parameter | distribution | mean | sd | bounds | checked | source |",
        "|---|---|---|---|---|---|---|",
    ]
    for p in spec.priors:
        lines.append(
            f"| {markdown_cell_code(p.parameter)} | {p.distribution} | {_shown(p.mean)} | {_shown(p.sd)} | "
            f"[{p.bounds[0]:g}, {p.bounds[1]:g}] | {_checked(p.source)} | {markdown_text(p.source)} |"
        )
    unverified = sum(_checked(p.source) == "unverified" for p in spec.priors)
    lines += [
        "",
        f"{unverified} of {len(spec.priors)} priors are unverified as cohort distributions (their source says why).",
        "",
        "## Verdicts",
        "",
        f"Limits: counter torques within ±{spec.counter_torque_limit:g} N m; local muscle within "
        f"{spec.local_pcsa_limit:g} cm² per joint.",
        "",
        "| verdict | criterion | p | interval |",
        "|---|---|---|---|",
    ]
    for name, v in result.probabilities.items():
        lines.append(f"| {name} | {criterion(name, spec)} | {v['p']:.3f} | [{v['low']:.3f}, {v['high']:.3f}] |")
    lines += ["", "## Sobol' indices (first order S1, total ST, with bootstrap intervals)", "", SOBOL_NOTE, ""]
    tables = result.sobol | {f"{name} (indicator)": t for name, t in result.sobol_verdicts.items()}
    for output, table in tables.items():
        lines += [f"### `{output}`", ""]
        verdict = output.removesuffix(" (indicator)")
        if verdict in result.probabilities and (
            rare := rare_outcome_note(result.probabilities[verdict]["p"], 2 * spec.samples)
        ):
            lines += [rare, ""]
        if table is None:
            lines += [_not_finite(result.draws.get(output)), ""]
            continue
        lines += ["| parameter | S1 | ST |", "|---|---|---|"]
        for name, s in table.items():
            first = f"{s['S1']:.3f} ± {s['S1_conf']:.3f}{_outside(s['S1'], s['S1_conf'])}"
            total = f"{s['ST']:.3f} ± {s['ST_conf']:.3f}{_outside(s['ST'], s['ST_conf'])}"
            lines.append(f"| {markdown_cell_code(name)} | {first} | {total} |")
        lines.append("")
    return "\n".join(lines) + "\n"


SOBOL_NOTE = (
    "S1 is the share of an output's variance that a parameter causes alone, ST the share it takes part in "
    "(with the others); both lie in [0, 1], and S1 <= ST. The numbers here are estimates from the draws: "
    "sampling error can put one below 0 or above 1 (marked with how to read it) or S1 above "
    "ST. Read such an estimate by its interval: -0.05 ± 0.2 is 'no effect detected', not a negative share; "
    "more samples narrow the intervals."
)
"""The report's words on what S1 and ST are and how an estimate outside [0, 1] reads."""


def _outside(value: float, interval: float) -> str:
    """How to read an estimate outside [0, 1]: as the nearest possible value where its interval reaches it, else
    a sign of too few samples; '' inside [0, 1]."""
    if not np.isfinite(value) or 0.0 <= value <= 1.0:
        return ""
    nearest = 0 if value < 0 else 1
    if abs(value - nearest) <= interval:
        return f" (read as {nearest}: within its interval)"
    return " (outside [0, 1] beyond its interval: too few samples)"


def criterion(verdict: str, spec: AtlasSpec) -> str:
    """A verdict's criterion as the report states it: :data:`VERDICTS`, with the delay it was judged at.

    Parameters
    ----------
    verdict : str
        A key of :data:`VERDICTS`.
    spec : AtlasSpec

    Returns
    -------
    str
    """
    return verdict_criterion(verdict, spec.names, spec.model)


def verdict_criterion(verdict: str, varied, model) -> str:
    """A verdict's criterion (:data:`VERDICTS`), the delay verdict's with the delay it was judged at.

    Parameters
    ----------
    verdict : str
        A key of :data:`VERDICTS`.
    varied : iterable of str
        The parameters the priors vary.
    model : Model
        The base model (its reflex delay where no prior draws one).

    Returns
    -------
    str
        E.g. ``"..., the model's 53 ms at every draw (no prior draws it)"`` for ``spine_stable_at_delay``.
    """
    text = VERDICTS[verdict]
    if verdict != "spine_stable_at_delay":
        return text
    if "reflex.delay" in set(varied):
        return f"{text}, each draw's delay drawn from its prior"
    return f"{text}, the model's {model.reflex.delay * 1e3:g} ms at every draw (no prior draws it)"


RARE_OUTCOMES = 20
"""Fewer draws than this on a verdict's rarer side (failures, or successes) leave its indicator's Sobol' indices
unestimated: their bootstrap intervals span most of [0, 1] (0.756 ± 1.259 at 4 failures of 512)."""


def rare_outcome_note(probability: float, draws: int) -> str:
    """The note over a verdict indicator's Sobol' table when too few draws fail (or pass) to estimate them; ''.

    Parameters
    ----------
    probability : float
        The verdict's probability over ``draws``.
    draws : int
        The draws it is counted over (2 N).

    Returns
    -------
    str
        E.g. ``"Too few failures to estimate these indices (4 of 512 draws fail): read them as unknown, not as
        shares."``; '' when both sides have at least :data:`RARE_OUTCOMES` draws.
    """
    failures = round((1.0 - probability) * draws)
    rare, side = (failures, "failures") if failures <= draws - failures else (draws - failures, "successes")
    if rare >= RARE_OUTCOMES:
        return ""
    verb = "fail" if side == "failures" else "pass"
    return (
        f"Too few {side} to estimate these indices ({rare} of {draws} draws {verb}; fewer than {RARE_OUTCOMES}): "
        "read them as unknown, not as shares."
    )


def console_st_note(value: float, samples: int) -> str:
    """The console's reading of a total-order index above 1 (the report marks each, :func:`_outside`); ''.

    Parameters
    ----------
    value : float
        The estimate ST.
    samples : int
        The atlas's N.

    Returns
    -------
    str
        E.g. ``" (ST > 1 is sampling error at N = 256: read as 1; more samples narrow it)"``.
    """
    if not np.isfinite(value) or value <= 1.0:
        return ""
    return f" (ST > 1 is sampling error at N = {samples}: read as 1; more samples narrow it)"


def _checked(source: str) -> str:
    """'unverified' where a prior's source says so (examples/atlas.toml's convention), else 'cited'."""
    return "unverified" if "unverified" in source.lower() else "cited"


def _not_finite(values) -> str:
    """Why an output has no indices: its unbounded draws (a margin of a spine stable without the reflex) and NaNs."""
    values = np.asarray(values, float)
    unbounded, infeasible = int(np.sum(np.isinf(values))), int(np.sum(np.isnan(values)))
    parts = [f"{unbounded} unbounded (stable at every delay: no reflex needed)"] if unbounded else []
    parts += [f"{infeasible} not a number (infeasible)"] if infeasible else []
    return f"Not finite at {unbounded + infeasible} draws ({'; '.join(parts)}): no indices."


def _shown(value: float) -> str:
    """A prior's moment for the table: a dash where its family has none (uniform)."""
    return "–" if np.isnan(value) else f"{value:g}"


DENSITY_LEVELS = (0.1, 0.3, 0.5, 0.7, 0.9)
"""The density figure's contours, as fractions of the cohort density's peak."""


def base_text(spec: AtlasSpec) -> str:
    """What the density figure's background is computed at: the base model, its mass and K with units, and the
    drawn parameters it does not follow (each draw's own mass or K is not the background's).

    Parameters
    ----------
    spec : AtlasSpec

    Returns
    -------
    str
        E.g. ``"the base model (preset default): body.mass 40 kg, passive.stiffness K = 0 N m/rad; each draw's
        own body.mass, passive.stiffness varies, the background does not"``.
    """
    from ..model.source import origin

    model = spec.model
    text = (
        f"the base model ({origin(model)}): body.mass {model.body.mass:g} kg, passive.stiffness K = "
        f"{model.passive.stiffness:g} N m/rad"
    )
    others = [p.parameter for p in spec.priors if p.parameter not in PLANE_PARAMETERS]
    return text + (f"; each draw's own {', '.join(others)} varies, the background does not" if others else "")


PLANE_PARAMETERS = ("eccentricity_m", "lordosis_m", "lordosis_angle_deg")
"""The priors that place a draw on the figure's (E, Lambda) plane; the others vary what the background omits."""


def density_figure(landscape: dict, draws: dict, optimum: tuple[float, float], base: str = ""):
    """The cohort's density of (E, Lambda) drawn over the landscape of min PCSA, with the paper's optimum.

    Parameters
    ----------
    landscape : dict
        ``eccentricity_m`` (nE,), ``lordosis_m`` (nL,) and ``min_pcsa_cm2`` (nE, nL) of the base model.
    draws : dict of str to numpy.ndarray
        ``eccentricity_m`` and ``lordosis_m`` of every draw [m].
    optimum : tuple of float
        (E, Lambda) to mark [m].
    base : str
        What the background is computed at (:func:`base_text`), in the colour bar's label.

    Returns
    -------
    matplotlib.figure.Figure
        Drawn on :func:`spinectl.canvas.new_figure`; axes in cm.
    """
    import textwrap

    from matplotlib.lines import Line2D

    fig = new_figure(figsize=(6.4, 5.6), layout="constrained")
    ax = fig.add_subplot()
    e, lam = 100 * np.asarray(landscape["eccentricity_m"]), 100 * np.asarray(landscape["lordosis_m"])
    mesh = ax.pcolormesh(e, lam, np.asarray(landscape["min_pcsa_cm2"]).T, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="background: min PCSA [cm²], joint by joint")
    points = 100 * np.stack([draws["eccentricity_m"], draws["lordosis_m"]])
    handles = []
    if np.all(np.ptp(points, axis=1) > 0):  # a kernel density needs spread in both
        from scipy.stats import gaussian_kde

        x, y = np.meshgrid(e, lam, indexing="ij")
        density = gaussian_kde(points)(np.stack([x.ravel(), y.ravel()])).reshape(x.shape)
        ax.contour(e, lam, density.T / density.max(), levels=DENSITY_LEVELS, colors="white")
        levels = ", ".join(f"{100 * v:g}" for v in DENSITY_LEVELS)
        handles.append(Line2D([], [], color="white", label=f"cohort density: {levels} % of its peak"))
    (star,) = ax.plot(100 * optimum[0], 100 * optimum[1], "r*", markersize=14, label="the paper's optimum C")
    ax.set_xlabel("eccentricity E [cm]")
    ax.set_ylabel("lordosis Λ [cm]")
    ax.set_title(
        f"where the cohort's {points.shape[1]} draws lie in (E, Λ), over the base model's min PCSA", fontsize=10
    )
    if base:
        fig.supxlabel(textwrap.fill(f"background: {base}", 90), fontsize=8)
    legend = ax.legend(handles=[*handles, star], loc="lower right", fontsize=8, facecolor="0.4", labelcolor="white")
    legend.get_frame().set_alpha(0.8)
    return fig
