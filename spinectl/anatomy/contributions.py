"""What each muscle of an anatomical model contributes to its chain's stability index (docs/contributions.md).

:func:`spinectl.model.contributions.contributions` on the model's free chain and on the chain constrained by
its rhythm, at the analysed activations; for an optimum's activations the removal method re-solves the same
optimum (:func:`spinectl.anatomy.optimum.optimum_on_chains`) with the removed muscles held at 0
(Cholewicki & VanVliet 2002). :class:`WithContributions` presents them beside the analysis
(``spinectl anatomy --contributions``), and :func:`contributions_figure` draws them (contributions.png).

References
----------
Cholewicki J, McGill SM (1996). Clin Biomech 11(1):1-15. doi:10.1016/0268-0033(95)00035-6.
Cholewicki J, VanVliet JJ (2002). Clin Biomech 17(2):99-105. doi:10.1016/S0268-0033(01)00118-8.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..canvas import new_figure, save_figures
from ..errors import ParameterError
from ..model.contributions import Contributions, contributions
from .contract import AnatomyEngine

CHAIN_RTOL = 1e-9
"""The contributions' least eigenvalue and the analysis's agree to this times the largest abs(eigenvalue) of -K
(the same chain, the same activations: equal to rounding), else the posture was not the analysed one."""

TOP = 10
"""Muscles listed (and removed one by one) by default: the largest abs(d lambda_min / d a_i)."""


def optimum_resolver(anatomy: AnatomyEngine, plane, posture, joint_stiffness, stability, margin, equilibrium, loads=()):
    """The optimum re-solved with some muscles held at 0: a :data:`~spinectl.model.contributions.Resolver`.

    The same programme as :func:`spinectl.anatomy.optimum.optimise` (volume weights), its held muscles'
    bounds both 0; each set of held muscles is solved once (the free and the constrained chain share it).

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    plane, posture, joint_stiffness, stability, margin, equilibrium, loads
        As :func:`spinectl.anatomy.optimum.optimise`.

    Returns
    -------
    callable
        ``resolve(held) -> (activations or None, status)``.
    """
    from .optimum import optimum_on_chains

    free, constrained, lin = anatomy.chains(
        plane, posture, joint_stiffness, **({"loads": tuple(loads)} if loads else {})
    )
    rows, tau_per, tau_0 = anatomy.equilibrium_rows(lin, plane, posture, equilibrium)
    w = anatomy.volume_weights()
    solved = {}

    def hold(chain, held):
        return dataclasses.replace(
            chain, lower=np.where(held, 0.0, chain.lower), upper=np.where(held, 0.0, chain.upper)
        )

    def resolve(held):
        key = np.asarray(held, bool).tobytes()
        if key not in solved:
            opt = optimum_on_chains(
                hold(free, held), hold(constrained, held), lin, rows, tau_per, tau_0, w, stability, equilibrium, margin
            )
            solved[key] = (opt.activations if opt.ok else None, f"re-solved: {opt.status}")
        return solved[key]

    return resolve


@dataclass(frozen=True)
class WithContributions:
    """An analysis (or an optimum) with each muscle's contribution to the index of its free and constrained chain.

    Attributes
    ----------
    result : AnatomyResult or OptimisedResult
        What ``spinectl anatomy`` printed before.
    free, constrained : Contributions or None
        On the free chain and on the chain constrained by the rhythm; None where the optimum is infeasible.
    count : int
        Muscles listed.
    """

    result: object
    free: Contributions | None
    constrained: Contributions | None
    count: int = TOP

    def to_dict(self) -> dict:
        """The result's document with ``contributions``: ``free`` and ``constrained`` (null where not computed).

        Returns
        -------
        dict
        """
        out = self.result.to_dict()
        if self.free is None:
            out["contributions"], out["contributions_reason"] = None, "not_computed"
        else:
            out["contributions"] = {
                "free": self.free.to_dict(self.count),
                "constrained": self.constrained.to_dict(self.count),
                "listed": self.count,
            }
        return out

    def table(self) -> str:
        """The result's table, then the contributions on each chain.

        Returns
        -------
        str
        """
        lines = [self.result.table(), ""]
        if self.free is None:
            return "\n".join(lines + ["contributions: none (the optimum is infeasible, so it has no activations)"])
        lines += ["the chain, free:", self.free.table(self.count), ""]
        lines += ["the chain constrained by the rhythm:", self.constrained.table(self.count)]
        return "\n".join(lines)


def with_contributions(
    anatomy: AnatomyEngine,
    result,
    plane: str = "sagittal",
    posture=None,
    joint_stiffness="none",
    count: int = TOP,
    groups: dict | None = None,
    optimum: dict | None = None,
    loads=(),
) -> WithContributions:
    """Each muscle's, class's and group's contribution at the activations of ``result``, free and constrained.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    result : AnatomyResult or OptimisedResult
        From :func:`~spinectl.anatomy.analyses.analyse` or :func:`~spinectl.anatomy.optimum.optimised`.
    plane : str
        The chain.
    posture : optional
        The operating point (:meth:`~spinectl.anatomy.contract.AnatomyEngine.posture`); default the reference.
    joint_stiffness : {"none", "mapped"} or float
        Added at each chain joint [N m/rad] (part of the offset).
    count : int
        Muscles listed and removed one by one, by abs(d lambda_min / d a_i) on the free chain.
    groups : dict, optional
        Named groups (:func:`spinectl.model.contributions.resolve_groups`).
    optimum : dict, optional
        ``stability``, ``margin``, ``equilibrium`` of the optimum behind ``result``: the removal re-solves it.
    loads : sequence of BodyLoad, optional
        The external loads analysed (:mod:`spinectl.anatomy.loads`): in the chains and the re-solved optimum.

    Returns
    -------
    WithContributions
    """
    if optimum is not None and not result.optimum.ok:
        return WithContributions(result, None, None, count)
    a = result.optimum.activations if optimum is not None else result.activations
    loaded = {"loads": tuple(loads)} if loads else {}  # without: the engines' calls as they were
    free, constrained, _ = anatomy.chains(plane, posture, joint_stiffness, activations=a, **loaded)
    resolve = None
    if optimum is not None:
        resolve = optimum_resolver(anatomy, plane, posture, joint_stiffness, **optimum, **loaded)
    out = WithContributions(
        result, _on(free, a, count, groups, resolve), _on(constrained, a, count, groups, resolve), int(count)
    )
    _same_chain(out.free, result.analysis if optimum is not None else result)
    return out


def _same_chain(contrib: Contributions, analysis) -> None:
    """Refuse contributions of another chain than the one analysed (a posture that is not the analysis's)."""
    ours, theirs = contrib.least.eigenvalue, float(analysis.free.eigenvalues[0])
    scale = max(float(np.max(np.abs(analysis.free.eigenvalues))), 1.0)
    if abs(ours - theirs) > CHAIN_RTOL * scale:
        raise ParameterError(
            "posture",
            f"must be the analysed one: the contributions' chain has least eigenvalue {ours:.6g} N m/rad, the "
            f"analysis's {theirs:.6g} N m/rad (give with_contributions the chain analyse was given: its posture, "
            "its joint stiffness)",
        )


def _on(chain, a, count, groups, resolve) -> Contributions:
    """The contributions on one chain, its ``count`` largest muscles removed one by one."""
    listed = [chain.controls[i] for i in contributions(chain, a).largest(count)]
    return contributions(chain, a, groups=groups, remove=listed, resolve=resolve)


def contributions_figure(contrib: Contributions, count: int = TOP, title: str = ""):
    """Bars of d lambda_min / d a_i of the ``count`` largest muscles, coloured by class, and of each class's sum.

    Parameters
    ----------
    contrib : Contributions
        On one chain.
    count : int
        Muscles drawn.
    title : str
        Above the figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure(figsize=(8.0, 0.3 * count + 2.5), layout="constrained")
    ax, ax_class = fig.subplots(1, 2, width_ratios=(3, 1))
    order = contrib.largest(count)[::-1]
    classes = sorted(set(contrib.control_class))
    colour = {c: f"C{i}" for i, c in enumerate(classes)}
    value = contrib.derivative if not contrib.least.degenerate else contrib.joint_share.sum(axis=0)
    ax.barh([contrib.controls[i] for i in order], value[order], color=[colour[contrib.control_class[i]] for i in order])
    unit = "activation" if contrib.control_unit == "1" else contrib.control_unit
    what = "d lambda_min / d a_i" if not contrib.least.degenerate else "joint shares (lambda_min repeated)"
    ax.set_xlabel(f"{what} [N m/rad per {unit}]")
    ax.axvline(0, color="0.3", lw=0.8)
    sums = [contrib.sums(m)[0] for m in contrib.classes().values()]
    ax_class.barh(list(contrib.classes()), sums, color=[colour[c] for c in contrib.classes()])
    ax_class.set_xlabel("sum per class")
    ax_class.axvline(0, color="0.3", lw=0.8)
    fig.suptitle(title or f"contributions to the least eigenvalue of -K, {contrib.least.eigenvalue:.4g} N m/rad")
    return fig


def save_contributions_figure(contrib: Contributions, folder, count: int = TOP, dpi: float = 150.0) -> list:
    """contributions.png (:func:`contributions_figure`, the free chain) written into ``folder``.

    Parameters
    ----------
    contrib : Contributions
        On the free chain.
    folder : str or pathlib.Path
        The output folder (its other files kept).
    count : int
        Muscles drawn.
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    list of pathlib.Path
    """
    title = f"the free chain: contributions to the least eigenvalue of -K, {contrib.least.eigenvalue:.4g} N m/rad"
    return save_figures({"contributions.png": contributions_figure(contrib, count, title)}, folder, dpi)
