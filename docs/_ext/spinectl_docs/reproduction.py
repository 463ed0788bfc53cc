"""The tables of ``docs/reproduction.md``, from :mod:`spinectl.paper.calibration` and :mod:`spinectl.paper.verdicts`.

The free parameters with their bounds, sources and calibrated values (read
from the ``wagner2012`` preset), and the documented verdict of every landmark.
The assumption table is measured at each build (:mod:`spinectl.paper.assumptions`,
on a coarse grid); the test suite checks the documented values against a fresh
measurement of the preset (tests/paper/test_verdicts.py) and the documented
assumptions against that table (tests/paper/test_assumptions.py). The chain's numbers of "The whole chain"
are measured at the build too: the landscape's chain margin (``spinectl sweep`` on the paper's 1 mm grid,
about a second) and the chain at the paper's optimum (:mod:`.chain`'s computations). The counter torques'
readings as ‖x‖ times F (the spline's offsets and the landscape's ‖CT‖), the mass-free preset's and
independent activation's landmarks (the assumption table's rows, measured once) and what the calibrated
presets' headers record (losses, conventions, run times: read, never a calibration at the build) feed the
sentences of those sections.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from spinectl.model.config import load_preset
from spinectl.paper import assumptions, calibration, verdicts

from .markup import md_escape
from .values import VALUES, value


def parameter_table() -> str:
    """The free parameters: name, unit, bounds, both presets' values, what it is and where the bounds come from."""
    fitted, free = load_preset(verdicts.PRESET), load_preset(assumptions.MASS_FREE_PRESET)
    lines = [
        f"| parameter | unit | lower | upper | `{verdicts.PRESET}` | `{assumptions.MASS_FREE_PRESET}` "
        "| what it is | source of the bounds |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for p in calibration.FREE_PARAMETERS:
        lines.append(
            f"| `{p.name}` | {p.unit} | {p.lower:g} | {p.upper:g} | {p.value(fitted):.4g} | {p.value(free):.4g} "
            f"| {md_escape(p.doc)} | {md_escape(p.source)} |"
        )
    lines.append(
        f"\n`{assumptions.MASS_FREE_PRESET}` is calibrated with the mass within "
        f"{calibration.MASS_FREE[0]:g}-{calibration.MASS_FREE[1]:g} kg (`--bounds mass=10,55`), "
        "its other bounds as above."
    )
    return "\n".join(lines) + "\n"


@cache
def assumption_rows() -> dict:
    """Every landmark under each choice the paper does not make, measured once per build (a coarse grid, a few
    seconds): landmark name -> :class:`spinectl.paper.assumptions.Row`, the table's and the sentences' source."""
    return {row.name: row for row in assumptions.documented_rows()}


def assumption_table() -> str:
    """Every landmark under each choice the paper does not make, measured now (:func:`assumption_rows`)."""
    return assumptions.markdown(list(assumption_rows().values()))


def _under(name: str, column: str) -> float:
    """A landmark's value in a column of the assumption table (``"mass"``: the mass-free preset's;
    ``"activation"``: independent activation; ``"chosen"``: ``wagner2012`` on the table's grid)."""
    return assumption_rows()[name].values[column][0]


def landmark_table() -> str:
    """The documented verdict of every landmark (:func:`spinectl.paper.verdicts.documented_table`)."""
    return verdicts.documented_table()


def _documented(name: str) -> str:
    """A landmark's documented value for ``wagner2012``, as the landmark table prints it (the tests check it
    against a fresh measurement: tests/paper/test_verdicts.py)."""
    return verdicts.format_number(verdicts.VERDICTS[name].value)


def claim() -> str:
    """'reproduced' or 'not reproduced': the paper's main claim, from its two landmarks' documented verdicts."""
    both = all(verdicts.VERDICTS[n].verdict == verdicts.REPRODUCED for n in ("optimum_lordosis", "ct_optimum"))
    return "reproduced" if both else "not reproduced"


def agreeing() -> str:
    """'11 of 22': how many landmarks the documented verdicts call reproduced, of all."""
    marks = verdicts.VERDICTS.values()
    return f"{sum(v.verdict == verdicts.REPRODUCED for v in marks)} of {len(marks)}"


value("reproduction.claim")(claim)
value("reproduction.optimum_lordosis")(lambda: _documented("optimum_lordosis"))
value("reproduction.ct_optimum")(lambda: _documented("ct_optimum"))
value("reproduction.agreeing")(agreeing)
for _name in verdicts.VERDICTS:  # every landmark's documented value: {measured}`reproduction.<landmark>`
    if f"reproduction.{_name}" not in VALUES:
        value(f"reproduction.{_name}")(lambda n=_name: _documented(n))


# --- "The whole chain: what the paper's conclusions become" (numbers of ``docs/chain.md``'s computations) ---

LANDSCAPE_POINTS = 81
"""Points per axis of the E x Lambda landscape over 0-8 cm whose chain margin the page quotes (the paper's 1 mm)."""

OPTIMUM = (0.03, 0.04)
"""The paper's optimum (E, Lambda) [m], where the page reads the chain (docs/chain.md's tables)."""


@cache
def landscape():
    """``spinectl sweep`` of ``wagner2012`` on the paper's grid (:data:`LANDSCAPE_POINTS` per axis, about a
    second): the landscape whose chain margin and counter torques the page quotes."""
    from spinectl.landscape.sweep import sweep
    from spinectl.paper.grid import paper_axis

    axis = paper_axis(LANDSCAPE_POINTS)
    return sweep(load_preset(verdicts.PRESET), axis, axis, progress=False)


def chain_margins():
    """The chain's static margin with the global muscles alone at each point's per-segment optimum,
    ``coupled_margin_Nm_per_rad`` of :func:`landscape` [N m/rad]."""
    return landscape()["coupled_margin_Nm_per_rad"]


def _largest_margin() -> str:
    """The landscape's largest chain margin; the page says every point is unstable, so a non-negative one fails."""
    largest = float(chain_margins().max())
    if not largest < 0:
        raise RuntimeError(
            f"docs/reproduction.md says the chain is unstable at every point; its margin reaches {largest}"
        )
    return f"{largest:.0f}".replace("-", "\u2212")


def _growing() -> str:
    """'4 of its 10 dynamic eigenvalues grow, at 18 to 68 1/s' at :data:`OPTIMUM`."""
    from .chain import coupled

    real = np.real(coupled(verdicts.PRESET, *OPTIMUM).eigenvalues)
    up = np.sort(real[real > 0])
    return f"{up.size} of its {real.size} dynamic eigenvalues grow, at {up[0]:.0f} to {up[-1]:.0f} 1/s"


def _local(preset: str) -> float:
    from .chain import coupled

    return float(np.sum(coupled(preset, *OPTIMUM).local.local_stiffness))


@cache
def _joint():
    """The joint optimum (c) of the preset at :data:`OPTIMUM`."""
    from spinectl.optimise.coupled.joint import joint_optimum

    return joint_optimum(load_preset(verdicts.PRESET), *OPTIMUM)


def _cm2(m2: float, fmt: str = ".1f") -> str:
    return f"{1e4 * m2:{fmt}}"


def _local_pcsa(k: float) -> float:
    """The local muscles' PCSA [m^2] for a local stiffness ``k`` [N m/rad] (docs/chain.md's kappa)."""
    from spinectl.model.local_muscles import local_stiffness_per_pcsa

    return k / local_stiffness_per_pcsa(load_preset(verdicts.PRESET))


def _segment_total() -> float:
    from .chain import coupled

    return float(np.sum(coupled(verdicts.PRESET, *OPTIMUM).pcsa))


value("reproduction.chain_margin_max")(_largest_margin)
value("reproduction.chain_growing")(_growing)
value("reproduction.local_total")(lambda: f"{_local(verdicts.PRESET):.0f}")
value("reproduction.local_total_default")(lambda: f"{_local('default'):.0f}")
value("reproduction.local_pcsa")(lambda: _cm2(_local_pcsa(_local(verdicts.PRESET))))
value("reproduction.joint_global")(lambda: _cm2(_joint().total_pcsa))
value("reproduction.joint_local")(lambda: _cm2(_joint().total_local_pcsa))
value("reproduction.segment_global")(lambda: _cm2(_segment_total()))
value("reproduction.joint_less")(lambda: "less" if _joint().total_pcsa + _joint().total_local_pcsa < _segment_total()
                                  else "no less")  # fmt: skip


# --- the optimal lordosis against the local stiffness, at E = 3 cm ---

LORDOSES = np.linspace(0.0, 0.08, 33)
"""Lambda [m] of the sweep at E = 3 cm that the page reads: 0 to 8 cm in 2.5 mm steps."""


@cache
def lordosis_sweep(preset: str) -> dict:
    """``spinectl sweep --coupled`` at E = 3 cm over :data:`LORDOSES`: where the counter torques are least, the
    chain's least local stiffness there, its largest and its least over Lambda, each with its Lambda [cm]."""
    from spinectl.landscape.sweep import sweep

    land = sweep(load_preset(preset), [OPTIMUM[0]], LORDOSES, progress=False, coupled=True).isel(E=0)
    torque = land["counter_torque_norm_Nm"].values
    local = land["local_stiffness_total_Nm_per_rad"].values
    at, most, least = (int(i) for i in (np.nanargmin(torque), np.nanargmax(local), np.nanargmin(local)))
    cm = 100 * LORDOSES
    return {"at": (cm[at], local[at]), "most": (cm[most], local[most]), "least": (cm[least], local[least]),
            "edge": least == len(LORDOSES) - 1}  # fmt: skip


def _both(text) -> str:
    """``wagner2012``'s text and ``default``'s in brackets: 'a (b)'."""
    return f"{text(verdicts.PRESET)} ({text('default')})"


def _within(preset: str) -> str:
    row = lordosis_sweep(preset)
    return f"{100 * (1 - row['at'][1] / row['most'][1]):.0f}"


def _over_least(preset: str) -> str:
    row = lordosis_sweep(preset)
    return f"{100 * (row['at'][1] / row['least'][1] - 1):.0f}"


def _least_where() -> str:
    """'at the grid's edge Lambda = 8 cm' where both presets' least lies at the sweep's end, else where it lies."""
    rows = [lordosis_sweep(p) for p in (verdicts.PRESET, "default")]
    if all(r["edge"] for r in rows) and rows[0]["least"][0] == rows[1]["least"][0]:
        return f"at the grid's edge Λ = {rows[0]['least'][0]:g} cm"
    return "at Λ = " + _both(lambda p: f"{lordosis_sweep(p)['least'][0]:g}") + " cm"


value("reproduction.lordosis_ct")(lambda: _both(lambda p: f"{lordosis_sweep(p)['at'][0]:g} cm"))
value("reproduction.lordosis_local")(lambda: f"{lordosis_sweep(verdicts.PRESET)['at'][1]:.0f}")
value("reproduction.lordosis_local_default")(lambda: f"{lordosis_sweep('default')['at'][1]:.0f}")
value("reproduction.lordosis_within")(lambda: _both(lambda p: f"{_within(p)} %"))
value("reproduction.lordosis_most")(
    lambda: "; ".join(f"{lordosis_sweep(p)['most'][1]:.0f} at {lordosis_sweep(p)['most'][0]:g} cm"
                      for p in (verdicts.PRESET, "default"))
)  # fmt: skip
value("reproduction.lordosis_over_least")(lambda: _both(lambda p: f"{_over_least(p)} %"))
value("reproduction.lordosis_least")(lambda: _both(lambda p: f"{lordosis_sweep(p)['least'][1]:.0f}"))
value("reproduction.lordosis_least_where")(_least_where)


# --- the reflex: one joint at a time against the chain, at A ---


@cache
def margins_at_a(preset: str):
    """``spinectl margins --preset P --E 0 --Lambda 0``: each joint alone (a MarginsReport)."""
    from spinectl.reflex.margins import margins_report

    return margins_report(load_preset(preset), 0.0, 0.0)


def _joint_margin(preset: str) -> float:
    """The least delay margin over the joints, each alone [s] (``spinectl margins --E 0 --Lambda 0``)."""
    return min(s.delay_margin for s in margins_at_a(preset).segments)


def _cli_margins() -> str:
    """'0.1962': L1L2's delay margin [s] of ``spinectl margins --json`` with its defaults, guarding the page's
    'L5S1 is self-stable' (its margin unbounded)."""
    segments = margins_at_a(verdicts.PRESET).segments
    if np.isfinite(segments[-1].delay_margin):
        raise RuntimeError("docs/cli.md says L5S1's margin is unbounded (self-stable) under margins' defaults")
    return f"{segments[0].delay_margin:.4f}"


value("cli.l1l2_margin")(_cli_margins)


def _chain_rule_margin(preset: str) -> str:
    """The rule's reflex on the chain at A at ``reflex.activation`` 0.5 with the lag [ms] (docs/chain.md's table)."""
    from .chain import rule_margin

    return f"{1e3 * rule_margin(preset, 0.5, 0.05).margin:.3f}"


value("reproduction.joint_reflex_margin")(lambda: _both(lambda p: f"{1e3 * _joint_margin(p):.0f}") + " ms")
value("reproduction.chain_reflex_margin")(lambda: _both(_chain_rule_margin) + " ms")


# --- the ±30 N m region and the least counter torque against E ("Almost independent of E") ---

CT_ECCENTRICITIES = np.arange(1, 9) / 100
"""E [m] at which the page reads the least counter torque over Lambda: 1, ..., 8 cm."""


def least_counter_torques() -> np.ndarray:
    """The least ``counter_torque_norm_Nm`` over Lambda of :func:`landscape` at each of :data:`CT_ECCENTRICITIES`."""
    torque = landscape()["counter_torque_norm_Nm"]
    return np.array([float(torque.sel(E=e, method="nearest").min()) for e in CT_ECCENTRICITIES])


def _grows() -> str:
    """The least counter torques against E, guarding the page's "it grows": '9.5, 19.0, … and 74.2'."""
    torques = least_counter_torques()
    if not np.all(np.diff(torques) > 0):
        raise RuntimeError(f"docs/reproduction.md says the least counter torque grows with E; it is {torques}")
    texts = [f"{t:.1f}" for t in torques]
    return ", ".join(texts[:-1]) + " and " + texts[-1]


def _region() -> tuple[float, float]:
    """The share of the grid where ‖CT‖ < 30 N m (the paper's limit) [%] and the largest E there [cm]."""
    from spinectl.paper.landmarks import CT_LIMIT

    torque = landscape()["counter_torque_norm_Nm"]
    inside = torque < CT_LIMIT
    return 100 * float(inside.mean()), 100 * float(torque["E"].where(inside).max())


value("reproduction.least_ct_by_e")(_grows)
value("reproduction.ct_region_share")(lambda: f"{_region()[0]:.0f} %")
value("reproduction.ct_region_e")(lambda: f"{_region()[1]:.1f}")


# --- the counter torques as ‖x‖ times F ("D twice C", "Minimal along the bisector", "The ±30 N m region") ---


def offset_norm(position) -> float:
    """‖x‖ [m] at (E, Lambda) [m]: the CoRs' horizontal offsets x_k = -E + Lambda phi_k (the spline alone)."""
    from spinectl.model.geometry import cor_positions

    return float(np.linalg.norm(cor_positions(*position, load_preset(verdicts.PRESET).geometry)[:, 0]))


def _grid(position) -> tuple[float, float]:
    """The point of :func:`landscape` that the landmarks read for ``position`` (the nearest, as ``readings.at``)."""
    from spinectl.paper.readings import grid_point

    return grid_point(landscape(), position)


def counter_torque(position) -> float:
    """‖CT‖ [N m] of :func:`landscape` at the grid point nearest ``position``."""
    from spinectl.paper.readings import at

    return at(landscape(), "counter_torque_norm_Nm", position)


def vertical_force(position) -> float:
    """F = ‖CT‖ / ‖x‖ [N] at the grid point nearest ``position``: the weight and the muscles' vertical pull."""
    return counter_torque(position) / offset_norm(_grid(position))


C_READING_POINTS = {"corner": "C", "interior": "OPTIMUM", "ridge": "RIDGE_C"}
"""The three readings of C, by the name of their position in :mod:`spinectl.paper.landmarks` (grid or landmarks)."""


def c_position(reading: str):
    """(E, Lambda) [m] of C under a reading (:data:`C_READING_POINTS`)."""
    from spinectl.paper import landmarks
    from spinectl.paper.grid import POSITIONS

    return POSITIONS["C"] if reading == "corner" else getattr(landmarks, C_READING_POINTS[reading])


def offset_ratio(corner: str, reading: str) -> str:
    """‖x(corner)‖ / ‖x(C)‖ at the positions themselves (the spline alone, no grid), to 2 decimals."""
    from spinectl.paper.grid import POSITIONS

    return f"{offset_norm(POSITIONS[corner]) / offset_norm(c_position(reading)):.2f}"


def _force_ratio() -> str:
    """'598/910': F at B and at C on the ridge reading [N]."""
    from spinectl.paper.grid import POSITIONS

    return f"{vertical_force(POSITIONS['B']):.0f}/{vertical_force(c_position('ridge')):.0f}"


def _grid_ratio(top: str, reading: str, digits: int) -> str:
    """‖CT(top)‖ / ‖CT(C)‖ on the paper's 81 x 81 grid (the report's landmark table), to ``digits`` decimals."""
    from spinectl.paper.grid import POSITIONS

    return f"{counter_torque(POSITIONS[top]) / counter_torque(c_position(reading)):.{digits}f}"


def _valley() -> str:
    """'1.24 ± 0.002': the valley floor's slope on the paper's grid and its standard error (landmarks' fit)."""
    from spinectl.paper.readings import crest_fit

    fit = crest_fit(landscape(), "counter_torque_norm_Nm", "min")
    return f"{fit.slope:.2f} ± {fit.uncertainty:.1g}"


def _mass_free_mass() -> str:
    return f"{load_preset(assumptions.MASS_FREE_PRESET).body.mass:.1f} kg"


def _mass_free_halving() -> str:
    """'0.557 with paper, 0.511 with physical': the mass-free preset's halving under its own K convention and
    the other."""
    own = load_preset(assumptions.MASS_FREE_PRESET).passive.convention
    other = "physical" if own == "paper" else "paper"
    return (f"{verdicts.format_number(_under('halving_K15', 'mass'))} with {own}, "
            f"{verdicts.format_number(_under('halving_K15_other', 'mass'))} with {other}")  # fmt: skip


def _spline_slope() -> str:
    """sum phi / sum phi^2: where ‖x‖ is least, Lambda over E [1]."""
    from spinectl.model.geometry import lordosis_shape

    phi = lordosis_shape(load_preset(verdicts.PRESET).geometry)
    return f"{np.sum(phi) / np.sum(phi**2):.2f}"


def _least_offset() -> str:
    """sqrt(5 - (sum phi)^2 / sum phi^2): the least ‖x‖ over Lambda per unit E [1]."""
    from spinectl.model.geometry import lordosis_shape

    phi = lordosis_shape(load_preset(verdicts.PRESET).geometry)
    return f"{np.sqrt(phi.size - np.sum(phi) ** 2 / np.sum(phi**2)):.2f}"


value("reproduction.optimum_offset")(lambda: f"{100 * offset_norm(OPTIMUM):.1f}")
value("reproduction.optimum_force")(lambda: f"{vertical_force(OPTIMUM):.0f}")
value("reproduction.valley_slope")(_valley)
value("reproduction.spline_slope")(_spline_slope)
value("reproduction.least_offset")(_least_offset)
value("reproduction.mass_free_ridge_over_B")(lambda: verdicts.format_number(_under("ridge_over_B", "mass")))
value("reproduction.mass_free_mass")(_mass_free_mass)
value("reproduction.mass_free_valley")(lambda: verdicts.format_number(_under("ct_valley_slope", "mass")))
value("reproduction.mass_free_halving")(_mass_free_halving)
value("reproduction.independent_D_over_C")(lambda: verdicts.format_number(_under("ct_D_over_C_text", "activation")))
value("reproduction.summary_B_over_C_ridge")(lambda: verdicts.format_number(_under("ct_B_over_C_ridge", "chosen")))
value("reproduction.grid_D_over_C_text")(lambda: _grid_ratio("D", "interior", 4))
value("reproduction.grid_B_over_C_ridge")(lambda: _grid_ratio("B", "ridge", 3))
value("reproduction.force_B_over_C_ridge")(_force_ratio)
for _corner in ("D", "B"):
    for _reading in C_READING_POINTS:
        value(f"reproduction.offset_{_corner}_over_C_{_reading}")(lambda c=_corner, r=_reading: offset_ratio(c, r))


# --- what the calibrated presets' headers record (read, never a calibration run at the build) ---


def preset_header(preset: str) -> list[str]:
    """The comment lines at the head of a built-in preset's TOML (``spinectl calibrate`` writes its run there)."""
    from importlib import resources

    from spinectl.model.config import PRESET_PACKAGE

    text = resources.files(PRESET_PACKAGE).joinpath(f"{preset}.toml").read_text(encoding="utf-8")
    return [line[1:].strip() for line in text.splitlines() if line.startswith("#")]


def _header_line(preset: str, words: str) -> str:
    line = next((line for line in preset_header(preset) if words in line), None)
    if line is None:
        raise RuntimeError(f"the {preset} preset's header no longer says {words!r}: docs/reproduction.md reads it")
    return line


def convention_losses(preset: str) -> dict[str, float]:
    """Each convention's loss at the preset's vector, as its header records them ('picked at ...')."""
    import re

    line = _header_line(preset, "picked at")
    return {c: float(v) for c, v in re.findall(r"\b(physical|paper) (\d+\.\d+)", line)}


def calibration_loss(preset: str) -> tuple[float, str]:
    """The preset's loss on the verifying grid and how many landmarks agree ('11 of 22'), from its header."""
    import re

    found = re.search(r"Loss: (\d+\.\d+) .*?(\d+ of \d+) landmarks agree", _header_line(preset, "Loss: "))
    return float(found.group(1)), found.group(2)


def search_time(preset: str) -> tuple[int, int]:
    """The calibration's wall time [s] and loss evaluations, from the preset's header."""
    import re

    found = re.search(r"wall time (\d+) s, (\d+) loss evaluations", _header_line(preset, "wall time"))
    return int(found.group(1)), int(found.group(2))


def _loss_pair(preset: str) -> str:
    """'0.891 against 0.977': the loss of the preset's own convention at its vector and the other's, 3 digits."""
    own = load_preset(preset).passive.convention
    losses = convention_losses(preset)
    other = next(c for c in losses if c != own)
    return f"{losses[own]:.3f} against {losses[other]:.3f}"


value("reproduction.wagner_convention", code=True)(lambda: load_preset(verdicts.PRESET).passive.convention)
value("reproduction.wagner_loss_pair")(lambda: _loss_pair(verdicts.PRESET))
value("reproduction.wagner_search")(lambda: "{:,} s ({} evaluations)".format(*search_time(verdicts.PRESET)))
value("reproduction.mass_free_search")(lambda: f"{search_time(assumptions.MASS_FREE_PRESET)[0]:,} s")
value("reproduction.mass_free_convention", code=True)(
    lambda: load_preset(assumptions.MASS_FREE_PRESET).passive.convention
)
value("reproduction.mass_free_loss")(lambda: f"{calibration_loss(assumptions.MASS_FREE_PRESET)[0]:.3f}")
value("reproduction.mass_free_agree")(lambda: calibration_loss(assumptions.MASS_FREE_PRESET)[1])


def _limit_pcsa() -> str:
    """'17.1 cm²': the paper's ±30 N m limit as local muscle at its 7 cm lever arm (``wagner2012``'s tension)."""
    from spinectl.paper.landmarks import CT_LIMIT, local_pcsa_equivalent

    return (
        f"{1e4 * float(local_pcsa_equivalent(CT_LIMIT, load_preset(verdicts.PRESET).fibre.specific_tension)):.1f} cm²"
    )


value("reproduction.limit_pcsa")(_limit_pcsa)
