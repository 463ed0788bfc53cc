"""The numbers of ``docs/anatomy.md`` that ``spinectl anatomy`` produces on MyoTorso, measured at the build.

Each computation (the model loaded, an analysis at an activation, an optimum) runs once per build
(``functools.cache``) and feeds every table and every ``{measured}`anatomy.*``` value that quotes it.
Without the anatomy extra (mujoco, myo-sim) at the build, the tables and values say so instead.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .values import NotAtBuild, missing_extra, value

CRITERIA = (("none", "classic"), ("joints", "joint by joint"), ("rhythm", "rhythm"), ("chain", "the chain (free)"))
"""The optimum table's columns: ``--stability`` and its heading."""

ADDED = (0.0, 50.0, 100.0, "mapped")
"""The optimum table's rows: the stiffness added at each joint [N m/rad], ``mapped`` the mapping's."""

ACTIVATIONS = (0.0, 0.05, 0.2)
"""The verdict table's rows: every muscle at this activation [1]."""

LORDOSIS = (-20.0, -10.0, 0.0, 10.0, 20.0)
"""The lordosis table's columns [deg]."""

LORDOSIS_FINE = tuple(np.arange(-20.0, 20.5, 5.0))
"""The lordosis without added stiffness, in 5 degree steps [deg]: where its joint-by-joint cost peaks."""

STIFFNESS = 50.0
"""The stiffness added [N m/rad] where the page's sentences and the lordosis table say "50 N m/rad added"."""

REFLEX_KP = (120.0, 150.0, 200.0, 300.0)
REFLEX_KD = (0.0, 2.0, 5.0, 10.0)
REFLEX_LAG = 0.05
"""The reflex table: k_p [N m/rad] rows, k_d [N m s/rad] columns, T_a [s], at the classic optimum."""


@cache
def model(name: str = "myotorso"):
    """The model, loaded once per build."""
    from spinectl import anatomy

    return anatomy.load(name)


@cache
def analysis(activation: float, added=0.0, plane: str = "sagittal", name: str = "myotorso", check: bool = False):
    """``spinectl anatomy --activation A --joint-stiffness K``'s analysis."""
    from spinectl.anatomy.analyses import analyse

    return analyse(model(name), plane, activation, joint_stiffness=added, check=check)


@cache
def optimum(stability: str, added=0.0, plane: str = "sagittal"):
    """``spinectl anatomy --optimise --stability S --joint-stiffness K``'s optimum (an ``Optimum``)."""
    from spinectl.anatomy.optimum import optimise

    return optimise(model(), plane=plane, stability=stability, joint_stiffness=added)


@cache
def optimised_at(stability: str = "chain", added=0.0, check: bool = False):
    """``spinectl anatomy --optimise``'s whole answer (the remedy where infeasible; the analysis at the optimum)."""
    from spinectl.anatomy.optimum import optimised

    return optimised(model(), stability=stability, joint_stiffness=added, check=check)


@cache
def classic_stable_from() -> float:
    """The least stiffness added at each joint [N m/rad] from which the classic optimum meets the chain criterion."""
    from spinectl.anatomy.optimum import MARGIN
    from spinectl.anatomy.remedy import least_joint_stiffness

    # to 1e-4 rather than the remedy's 0.1 %: the page quotes it to 0.1 N m/rad
    return least_joint_stiffness(lambda c: optimum("none", c).eigenvalues[0] >= MARGIN, rtol=1e-4)


@cache
def lordosis(added: float, degrees: tuple) -> dict:
    """``spinectl anatomy --lordosis ... --joint-stiffness K``'s curve."""
    from spinectl.anatomy.optimum import lordosis_curve

    return lordosis_curve(model(), degrees, joint_stiffness=added)


def _guarded(function):
    """A table's text, or the note on the extra missing at the build."""
    try:
        return function()
    except ImportError as error:
        return f"*{missing_extra(error)}*\n"


def _cost(opt) -> str:
    return f"{opt.cost:.2f}" if opt.ok else "infeasible"


def _numbers(values, digits: str = ".1f") -> str:
    return ", ".join(f"{v:{digits}}".replace("-", "\u2212") for v in values)


def signed(v: float, digits: str = ".1f") -> str:
    """A number with its sign as the page writes it (a typographic minus, + where positive)."""
    return f"{v:+{digits}}".replace("-", "\u2212") if v > 0 else f"{v:{digits}}".replace("-", "\u2212")


# --- tables -----------------------------------------------------------------------------------------------------


def verdict_table() -> str:
    """Joint by joint and the chain, free and constrained, at each uniform activation (no stiffness added)."""

    def table():
        lines = [
            "| activation | $-K_{jj}$ L5S1 … L1L2 [N m/rad] | eigenvalues of $-K$, free chain [N m/rad] | unstable "
            "| $-K_c$, constrained [N m/rad] |",
            "| --- | --- | --- | --- | --- |",
        ]
        for a in ACTIVATIONS:
            r = analysis(a)
            free, con = r.free, r.constrained
            lines.append(
                f"| {a:g} | {_numbers(free.joint_stiffness)} | {', '.join(signed(v) for v in free.eigenvalues)} "
                f"| {int(np.sum(free.eigenvalues <= 0))} of {free.eigenvalues.size} | {_numbers(con.eigenvalues)} |"
            )
        return "\n".join(lines) + "\n"

    return _guarded(table)


def optimum_table() -> str:
    """The optima's cost (and the chain's least eigenvalue of -K where the criterion does not impose it)."""

    def cell(stability, added):
        opt = optimum(stability, added)
        return f"{opt.cost:.2f}; chain {signed(opt.eigenvalues[0])}" if opt.ok else "infeasible"

    def table():
        mapped = float(model().added_stiffness("mapped", 1)[0])
        lines = [
            "| joint stiffness added [N m/rad] | " + " | ".join(h for _, h in CRITERIA) + " |",
            "| --- |" + " --- |" * len(CRITERIA),
        ]
        for added in ADDED:
            label = (
                f"{mapped:.1f} (mapped)" if added == "mapped" else f"{added:g}" + (" (MyoTorso's)" if not added else "")
            )
            lines.append(f"| {label} | " + " | ".join(cell(s, added) for s, _ in CRITERIA) + " |")
        return "\n".join(lines) + "\n"

    return _guarded(table)


def lordosis_table() -> str:
    """The three optima's cost along the rhythm, 50 N m/rad added."""

    def table():
        curve = lordosis(STIFFNESS, LORDOSIS)
        lines = [
            "| summed angle change [deg] | " + " | ".join(signed(d, "g") for d in LORDOSIS) + " |",
            "| --- |" + " --- |" * len(LORDOSIS),
        ]
        for key, label in (("none", "classic"), ("joints", "joint by joint"), ("chain", "the chain")):
            costs = [
                f"{c:.2f}" if s.startswith("optimal") else "infeasible"
                for c, s in zip(curve[key]["cost"], curve[key]["status"], strict=True)
            ]
            lines.append(f"| {label} | " + " | ".join(costs) + " |")
        return "\n".join(lines) + "\n"

    return _guarded(table)


def reflex_table() -> str:
    """The free chain's exact delay margin at the classic optimum (no stiffness added) over k_p and k_d."""

    def table():
        from spinectl.anatomy.analyses import reflex_margin
        from spinectl.anatomy.optimum import optimise
        from spinectl.reflex.delay import delay_text

        classic = optimise(model(), stability="none")
        chain = model().chains("sagittal", None, "none")[0]
        lines = [
            "| $k_p$ [N m/rad], $k_d$ [N m s/rad] → | " + " | ".join(f"{kd:g}" for kd in REFLEX_KD) + " |",
            "| --- |" + " --- |" * len(REFLEX_KD),
        ]
        for kp in REFLEX_KP:
            cells = []
            for kd in REFLEX_KD:
                r = reflex_margin(chain, classic.activations, kp, kd, REFLEX_LAG)
                if r["delay_margin_status"] == "unstable_without_delay":
                    cells.append("unstable")
                else:
                    cells.append(delay_text(r["delay_margin_s"], 2))
            lines.append(f"| {kp:g} | " + " | ".join(cells) + " |")
        return "\n".join(lines) + "\n"

    return _guarded(table)


# --- values quoted in sentences ---------------------------------------------------------------------------------


def _global_sum(opt) -> float:
    classes = np.array(model().classes)
    return float(np.sum(opt.activations[classes == "global"]))


def _local_sum(opt) -> float:
    classes = np.array(model().classes)
    return float(np.sum(opt.activations[classes == "local"]))


value("anatomy.global_rank")(lambda: str(analysis(0.0).certificate.rank))
value("anatomy.global_singular_values")(
    lambda: ", ".join(f"{s:.3g}" for s in analysis(0.0).certificate.singular_values[: analysis(0.0).certificate.rank])
)
value("anatomy.global_zeros")(lambda: str(analysis(0.0).free.eigenvalues.size - analysis(0.0).certificate.rank))
value("anatomy.global_rank_3d")(
    lambda: f"{analysis(0.0, plane='3d').certificate.rank} of {analysis(0.0, plane='3d').free.eigenvalues.size}"
)
value("anatomy.null_space_0")(lambda: " and ".join(signed(v) for v in analysis(0.0).certificate.null_space_stiffness))
value("anatomy.null_space_02")(lambda: " and ".join(signed(v) for v in analysis(0.2).certificate.null_space_stiffness))
value("anatomy.constrained_0")(lambda: _numbers(analysis(0.0).constrained.eigenvalues))
value("anatomy.mapped")(lambda: f"{float(model().added_stiffness('mapped', 1)[0]):.1f}")
value("anatomy.mapped_eigenvalues_02")(
    lambda: "{} … {}".format(*(f"{v:.0f}" for v in analysis(0.2, "mapped").free.eigenvalues[[0, -1]]))
)
value("anatomy.remedy")(lambda: f"{optimised_at('chain', 0.0).remedy:.3g}")
value("anatomy.remedy_line", code=True)(
    lambda: (
        __import__("spinectl.anatomy.optimum", fromlist=["remedy_text"])
        .remedy_text(optimised_at("chain", 0.0).remedy)
        .lstrip("; ")
    )
)
value("anatomy.classic_stable_from")(lambda: f"{classic_stable_from():.1f}")
value("anatomy.price_50")(lambda: f"{optimum('chain', STIFFNESS).cost / optimum('none', STIFFNESS).cost:.2g}")
value("anatomy.global_sum_chain_50")(lambda: f"{_global_sum(optimum('chain', STIFFNESS)):.1f}")
value("anatomy.global_sum_classic")(lambda: f"{_global_sum(optimum('none', STIFFNESS)):.1f}")
value("anatomy.global_sum_joints_50")(lambda: f"{_global_sum(optimum('joints', STIFFNESS)):.1f}")
value("anatomy.global_count")(lambda: str(len(analysis(0.0).muscles["global"])))
value("anatomy.joints_chain_50")(lambda: signed(optimum("joints", STIFFNESS).eigenvalues[0], ".0f"))
value("anatomy.local_sums")(
    lambda: "{:.1f} of {:.1f} at the classic optimum, {:.1f} of {:.1f} at the chain optimum".format(
        _local_sum(optimum("none", STIFFNESS)),
        float(np.sum(optimum("none", STIFFNESS).activations)),
        _local_sum(optimum("chain", STIFFNESS)),
        float(np.sum(optimum("chain", STIFFNESS).activations)),
    )
)
value("anatomy.coronal_chain_50")(lambda: _cost(optimum("chain", STIFFNESS, "coronal")))
value("anatomy.coronal_price_50")(
    lambda: f"{optimum('chain', STIFFNESS, 'coronal').cost / optimum('none', STIFFNESS, 'coronal').cost:.3g}"
)
value("anatomy.coronal_classic_50")(lambda: signed(optimum("none", STIFFNESS, "coronal").eigenvalues[0], ".0f"))
value("anatomy.chain_3d_50")(lambda: _cost(optimum("chain", STIFFNESS, "3d")))
value("anatomy.classic_3d_50")(lambda: signed(optimum("none", STIFFNESS, "3d").eigenvalues[0], ".0f"))
value("anatomy.lumbar_torque_max")(lambda: f"{np.max(np.abs(optimum('none').lumbar_torque)):.0f}")


def _peak() -> str:
    curve = lordosis(0.0, LORDOSIS_FINE)
    costs = np.array(curve["joints"]["cost"])
    top = int(np.nanargmax(costs))
    return (
        f"{costs[0]:.1f} at {LORDOSIS_FINE[0]:+g}° to a peak of {costs[top]:.1f} at {LORDOSIS_FINE[top]:+g}°".replace(
            "-", "\u2212"
        )
    )


def _chain_feasible_nowhere() -> str:
    curve = lordosis(0.0, LORDOSIS_FINE)
    ok = [s.startswith("optimal") for s in curve["chain"]["status"]]
    return "is infeasible everywhere" if not any(ok) else f"is feasible at {sum(ok)} of {len(ok)} postures"


value("anatomy.lordosis_joints_peak_0")(_peak)
value("anatomy.lordosis_chain_0")(_chain_feasible_nowhere)


def _referee_leading() -> str:
    r = analysis(0.05, check=True)
    return f"{r.simulated_rate:.4g} 1/s against the predicted {r.free.dynamic_eigenvalues[0].real:.4g} 1/s"


def _referee_optimum() -> str:
    r = optimised_at("chain", STIFFNESS, check=True).analysis
    return f"{signed(r.simulated_rate, '.4g')} against {signed(r.free.dynamic_eigenvalues[0].real, '.4g')} 1/s"


value("anatomy.referee_error")(lambda: f"{analysis(0.05, check=True).referee_error():.0e}")
value("anatomy.referee_leading")(_referee_leading)
value("anatomy.referee_optimum")(_referee_optimum)
value("anatomy.fullbody_joints")(lambda: _numbers(analysis(0.0, name="myofullbody").free.joint_stiffness))
value("anatomy.fullbody_constrained")(lambda: _numbers(analysis(0.0, name="myofullbody").constrained.eigenvalues))
value("anatomy.myotorso_joints_ends")(
    lambda: "{} … {}".format(*(_numbers([v]) for v in analysis(0.0).free.joint_stiffness[[0, -1]]))
)


CHRISTOPHY = (
    "christophy-skeleton/Christophy2012_axialRotationUpd_skeletonOnly.osim",
    """[bodies]
pelvis = ["sacrum"]
vertebrae = ["lumbar5", "lumbar4", "lumbar3", "lumbar2", "lumbar1"]
thorax = ["torso"]
[planes]
sagittal = ["flex_extension", "L4_L5_FE", "L3_L4_FE", "L2_L3_FE", "L1_L2_FE"]
""",
)
"""Christophy's skeleton (its file in the published models' folder) and its mapping."""


def christophy():
    """Christophy's skeleton upright with 50 N m/rad added per joint radian (``published-model``'s cache)."""
    from .published import analysed, shared_models

    path = shared_models() / CHRISTOPHY[0]
    if not path.is_file():
        raise NotAtBuild(f"the published models ({shared_models()}) are not at this build")
    return analysed(str(path), CHRISTOPHY[1], None, STIFFNESS)


def _christophy_chain() -> str:
    free = christophy().free
    unstable = free.eigenvalues[free.eigenvalues <= 0]
    return f"{len(unstable)} of {free.eigenvalues.size} modes ({_numbers(unstable)})"


value("anatomy.christophy_joints")(lambda: _numbers(christophy().free.joint_stiffness))
value("anatomy.christophy_chain")(_christophy_chain)
value("anatomy.christophy_constrained")(lambda: _numbers(christophy().constrained.eigenvalues, ".0f"))
value("anatomy.versions")(lambda: f"{model().source.split(',')[0]}, MuJoCo {__import__('mujoco').__version__}")
for _class in ("global", "local", "between", "non-lumbar"):
    value(f"anatomy.count_{_class}")(lambda c=_class: str(len(analysis(0.0).muscles[c])))


def _all_rank() -> str:
    free, _, lin = model().chains("sagittal")
    arms = lin.moment_arms[:, list(lin.dofs[: lin.n])]
    return str(int(np.linalg.matrix_rank(arms)))


value("anatomy.all_rank")(_all_rank)
value("anatomy.muscle_count")(lambda: str(len(model().muscles)))
