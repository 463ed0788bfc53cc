"""What each control contributes to the chain's stability index, on any LinearChain (docs/contributions.md).

The stability index is the least eigenvalue lambda_min of -sym(K) (Cholewicki & McGill 1996), K = dtau/dq
the chain's stiffness (spinectl's sign: -K positive definite is statically stable,
:mod:`spinectl.model.linear_chain`). K is affine in the controls,

    K(u) = K_0 + sum_i u_i K_i,

so at a simple (not repeated) least eigenvalue with unit mode v, -sym(K) v = lambda_min v, first-order
eigenvalue perturbation gives each control's derivative

    d lambda_min / d u_i = v^T (-K_i) v            [N m/rad per control unit],

and, K being affine, Euler's identity for the index itself: v^T (-K(u)) v = lambda_min with
v^T v = 1 and K(u) = K_0 + sum_i u_i K_i, so

    lambda_min = -v^T K_0 v + sum_i u_i (d lambda_min / d u_i),

each term u_i (d lambda_min / d u_i) the control's share of the index (the offset -v^T K_0 v:
gravity, passive tissue, the added joint stiffness). A class's or a group's derivative and share
are the sums over its members. A repeated least eigenvalue is not differentiable (its one-sided
derivatives differ with the direction): said, and the derivatives left NaN.

The removal method (Cholewicki & VanVliet 2002): the index with a control or a group held at 0,
and where the activations come from an optimum, that optimum re-solved with them held (the caller's
``resolve``), as a percent change of the index.

References
----------
Cholewicki J, McGill SM (1996). Mechanical stability of the in vivo lumbar spine: implications for
injury and chronic low back pain. Clin Biomech 11(1):1-15. doi:10.1016/0268-0033(95)00035-6.
Cholewicki J, VanVliet JJ (2002). Relative contribution of trunk muscles to the stability of the
lumbar spine during isometric exertions. Clin Biomech 17(2):99-105. doi:10.1016/S0268-0033(01)00118-8.
Kato T (1995). Perturbation Theory for Linear Operators (reprint of the 1980 edition). Springer.
doi:10.1007/978-3-642-66282-9.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .linear_chain import CONTROL_CLASSES, LinearChain

DEGENERATE_RTOL = 1e-6
"""The least eigenvalue counts as repeated when the next one is within this times the largest abs(eigenvalue)
of -sym(K): the first-order derivative then holds only for steps far below that gap, so it is not given."""

ROUNDING = 1e-9
"""A share below this times the largest abs(share) counts as none (a pair at 0 PCSA, up to the solver's rounding)."""


@dataclass(frozen=True)
class LeastMode:
    """The least eigenvalue of -sym(K) and its mode.

    Attributes
    ----------
    eigenvalue : float
        lambda_min [N m/rad].
    mode : numpy.ndarray, shape (n,)
        Unit eigenvector v (its largest entry positive).
    gap : float
        lambda_2 - lambda_min [N m/rad]; inf for a single joint.
    multiplicity : int
        How many eigenvalues lie within :data:`DEGENERATE_RTOL` of lambda_min (1: simple).
    subspace : numpy.ndarray, shape (n, multiplicity)
        Orthonormal eigenvectors of those eigenvalues (the first column ``mode`` up to its sign).
    """

    eigenvalue: float
    mode: np.ndarray
    gap: float
    multiplicity: int
    subspace: np.ndarray | None = None

    @property
    def degenerate(self) -> bool:
        """The least eigenvalue is repeated: not differentiable."""
        return self.multiplicity > 1


def least_mode(stiffness) -> LeastMode:
    """The least eigenvalue of -sym(K), its unit mode, the gap to the next and its multiplicity.

    Parameters
    ----------
    stiffness : array_like, shape (n, n)
        K [N m/rad].

    Returns
    -------
    LeastMode
    """
    k = np.asarray(stiffness, float)
    values, vectors = np.linalg.eigh(-0.5 * (k + k.T))
    v = vectors[:, 0]
    v = v if v[np.argmax(np.abs(v))] >= 0 else -v  # one sign, so that modes compare across operating points
    tol = DEGENERATE_RTOL * max(float(np.max(np.abs(values))), np.finfo(float).tiny)
    gap = float(values[1] - values[0]) if values.size > 1 else float("inf")
    count = int(np.sum(values - values[0] <= tol))
    return LeastMode(float(values[0]), v, gap, count, vectors[:, :count])


def resolve_groups(controls, patterns: dict) -> dict:
    """Named groups of controls: each a regular expression matched at the start of every name, or a list of names.

    Parameters
    ----------
    controls : sequence of str
        The chain's control names.
    patterns : dict of str to str or sequence of str
        Group name -> a regular expression (:func:`re.match`: anchored at the start, so a name prefix is one)
        or the members' names.

    Returns
    -------
    dict of str to tuple of str
        Group name -> its members, in the chain's order.

    Raises
    ------
    ParameterError
        A pattern that is no regular expression, a name the chain lacks, or a group without members.
    """
    out = {}
    for name, pattern in patterns.items():
        if isinstance(pattern, str):
            try:
                rx = re.compile(pattern)
            except re.error as exc:
                raise ParameterError(
                    f"group {name}", f"must be a regular expression (got {pattern!r}: {exc})"
                ) from None
            members = tuple(c for c in controls if rx.match(c))
        else:
            unknown = sorted(set(pattern) - set(controls))
            if unknown:
                raise ParameterError(f"group {name}", f"names muscles the model lacks: {unknown[:5]}")
            members = tuple(c for c in controls if c in set(pattern))
        if not members:
            raise ParameterError(f"group {name}", f"must match at least one muscle (got {pattern!r}, matching none)")
        out[str(name)] = members
    return out


@dataclass(frozen=True)
class Removal:
    """The index with some controls held at 0 (Cholewicki & VanVliet 2002).

    Attributes
    ----------
    members : tuple of str
        The controls removed.
    least_eigenvalue : float
        lambda_min without them [N m/rad]; NaN where the re-solved optimum is infeasible.
    percent_change : float
        100 (lambda_removed - lambda_min) / abs(lambda_min) [%]; NaN where either is NaN or lambda_min is 0.
    status : str
        ``"removed"`` (the others kept), or the re-solved optimum's status.
    """

    members: tuple
    least_eigenvalue: float
    percent_change: float
    status: str

    def to_dict(self) -> dict:
        """JSON-ready, units in the keys.

        Returns
        -------
        dict
        """
        return {
            "members": list(self.members),
            "least_eigenvalue_Nm_per_rad": self.least_eigenvalue,
            "percent_change": self.percent_change,
            "status": self.status,
        }


Resolver = Callable[[np.ndarray], tuple]
"""``resolve(held) -> (u or None, status)``: the controls re-solved with those of the bool mask ``held`` at 0."""


def removal(chain: LinearChain, u, members, least: float, local_stiffness=0.0, resolve: Resolver | None = None):
    """The index with ``members`` held at 0: just removed, or the equilibrium re-solved by ``resolve``.

    Parameters
    ----------
    chain : LinearChain
        The chain.
    u : array_like, shape (m,)
        The controls [control unit].
    members : sequence of str
        The controls removed.
    least : float
        lambda_min at ``u`` [N m/rad].
    local_stiffness : array_like, shape (n,)
        k added at each joint [N m/rad].
    resolve : callable, optional
        :data:`Resolver`; None: the other controls kept as they are.

    Returns
    -------
    Removal

    References
    ----------
    Cholewicki J, VanVliet JJ (2002). Clin Biomech 17(2):99-105. doi:10.1016/S0268-0033(01)00118-8.
    """
    held = np.isin(np.array(chain.controls, object), list(members))
    if resolve is None:
        new, status = np.where(held, 0.0, np.asarray(u, float)), "removed"
    else:
        new, status = resolve(held)
    if new is None or not np.all(np.isfinite(new)):
        value = float("nan")
    else:
        value = least_mode(chain.stiffness(new, local_stiffness)).eigenvalue
    change = 100.0 * (value - least) / abs(least) if least != 0 else float("nan")
    return Removal(tuple(members), value, float(change), status)


@dataclass(frozen=True)
class Contributions:
    """Each control's, class's and group's contribution to the least eigenvalue of -sym(K) at one operating point.

    Attributes
    ----------
    joints, controls, control_class : tuple of str
        The chain's.
    control_unit : str
        The unit of u (``"1"`` activations, ``"cm^2"`` PCSA).
    controls_at : numpy.ndarray, shape (m,)
        u [control unit].
    least : LeastMode
        lambda_min [N m/rad], the mode, gap and multiplicity.
    derivative : numpy.ndarray, shape (m,)
        d lambda_min / d u_i = -v^T K_i v [N m/rad per control unit]; NaN where lambda_min is repeated.
    derivative_up : numpy.ndarray, shape (m,)
        The one-sided derivative as u_i rises [N m/rad per control unit]: where lambda_min is simple the derivative,
        where it is repeated the least eigenvalue of V^T (-K_i) V over its eigenvectors V (the eigenvalues of a
        symmetric matrix split along them; Kato 1995, ch. II).
    offset : float
        -v^T (K_0 - diag(k)) v [N m/rad]: what no control gives; NaN where repeated.
    joint_share : numpy.ndarray, shape (n, m)
        -u_i (K_i)_jj: each control's part of each joint's own stiffness, the others fixed [N m/rad].
    groups : dict of str to tuple of str
        The named groups' members.
    removals : dict of str to Removal
        The removal method, by name of what was removed (a control, ``class:<name>``, ``group:<name>``).
    """

    joints: tuple
    controls: tuple
    control_class: tuple
    control_unit: str
    controls_at: np.ndarray
    least: LeastMode
    derivative: np.ndarray
    offset: float
    joint_share: np.ndarray
    derivative_up: np.ndarray | None = None
    groups: dict = field(default_factory=dict)
    removals: dict = field(default_factory=dict)

    @property
    def share(self) -> np.ndarray:
        """u_i d lambda_min / d u_i [N m/rad], shape (m,): the terms of Euler's identity."""
        return self.controls_at * self.derivative

    def sums(self, members) -> tuple:
        """The derivative and the share summed over ``members``.

        Parameters
        ----------
        members : sequence of str
            Control names.

        Returns
        -------
        tuple of float
            (sum of d lambda_min / d u_i [N m/rad per control unit], sum of u_i d lambda_min / d u_i [N m/rad]).
        """
        pick = np.isin(np.array(self.controls, object), list(members))
        return float(self.derivative[pick].sum()), float(self.share[pick].sum())

    def classes(self) -> dict:
        """Each class present and its members.

        Returns
        -------
        dict of str to tuple of str
        """
        return {
            c: tuple(m for m, k in zip(self.controls, self.control_class, strict=True) if k == c)
            for c in CONTROL_CLASSES
            if c in self.control_class
        }

    def largest(self, count: int) -> np.ndarray:
        """The controls of largest abs(d lambda_min / d u_i), first the largest.

        Parameters
        ----------
        count : int
            How many.

        Returns
        -------
        numpy.ndarray of int, shape (min(count, m),)
            Their indices; where lambda_min is repeated (no derivative), by abs(sum of their joint shares) instead.
        """
        key = self.derivative if not self.least.degenerate else self.joint_share.sum(axis=0)
        return np.argsort(-np.abs(key), kind="stable")[: max(int(count), 0)]

    def degenerate_text(self) -> str:
        """Why the derivatives are not given.

        Returns
        -------
        str
            A sentence; '' where lambda_min is simple.
        """
        if not self.least.degenerate:
            return ""
        return (
            f"the least eigenvalue is repeated ({self.least.multiplicity} eigenvalues within "
            f"{DEGENERATE_RTOL:g} times the largest |eigenvalue| of -K): it is not differentiable there, so no "
            "derivative is given, only the one-sided rate as each control rises (derivative_up, the least "
            "eigenvalue of V^T (-K_i) V over its eigenvectors V); the removal method still is"
        )

    def to_dict(self, count: int | None = None) -> dict:
        """JSON-ready: per control (the ``count`` largest, else all), per class, per group, the removals.

        Parameters
        ----------
        count : int, optional
            How many controls to list, by abs(d lambda_min / d u_i); None: all.

        Returns
        -------
        dict
        """
        unit = "Nm_per_rad_per_activation" if self.control_unit == "1" else "Nm_per_rad_per_cm2"
        order = self.largest(len(self.controls) if count is None else count)
        per = [
            {
                "name": self.controls[i],
                "class": self.control_class[i],
                "control": float(self.controls_at[i]),
                f"derivative_{unit}": float(self.derivative[i]),
                f"derivative_up_{unit}": float(self.derivative_up[i]),
                "share_Nm_per_rad": float(self.share[i]),
                "joint_share_Nm_per_rad": self.joint_share[:, i].tolist(),
            }
            for i in order
        ]

        def summed(members):
            d, s = self.sums(members)
            return {"members": len(members), f"derivative_{unit}": d, "share_Nm_per_rad": s}

        return {
            "least_eigenvalue_Nm_per_rad": self.least.eigenvalue,
            "mode": self.least.mode.tolist(),
            "gap_Nm_per_rad": self.least.gap,
            "multiplicity": self.least.multiplicity,
            "degenerate": self.least.degenerate,
            "degenerate_reason": self.degenerate_text(),
            "offset_Nm_per_rad": self.offset,
            "joints": list(self.joints),
            "controls": per,
            "classes": {c: summed(m) for c, m in self.classes().items()},
            "groups": {g: {**summed(m), "names": list(m)} for g, m in self.groups.items()},
            "removal": {k: r.to_dict() for k, r in self.removals.items()},
        }

    def table(self, count: int = 10) -> str:
        """The ``count`` largest by abs(d lambda_min / d u_i), with class; then per class and group; the removals.

        Parameters
        ----------
        count : int
            Rows of controls.

        Returns
        -------
        str
        """
        per = "activation" if self.control_unit == "1" else self.control_unit
        lines = [
            f"contributions to the least eigenvalue of -K, lambda_min = {self.least.eigenvalue:.4g} N m/rad "
            "(> 0 restores; "
            + (f"gap to the next {self.least.gap:.3g} N m/rad)" if np.isfinite(self.least.gap) else "one coordinate)"),
        ]
        if self.least.degenerate:
            lines.append(self.degenerate_text())
        else:
            lines.append(
                f"d lambda/du = -v^T K_i v [N m/rad per {per}] at the least-stable mode v; share = u_i d lambda/du "
                f"[N m/rad]; they sum with the offset {self.offset:.4g} N m/rad (gravity, passive, added) to lambda_min"
            )
        rate = self.derivative_up if self.least.degenerate else self.derivative  # one-sided where repeated
        label = "d+ lambda/du" if self.least.degenerate else "d lambda/du"
        head = f"{'name':<28}{'class':<12}{'u':>10}{label:>14}{'share':>12}{'removed [%]':>13}"
        lines += ["", head]
        for i in self.largest(count):
            name = self.controls[i]
            cell = _removed_cell(self.removals.get(name))
            lines.append(
                f"{name:<28}{self.control_class[i]:<12}{self.controls_at[i]:>10.4g}{rate[i]:>14.4g}"
                f"{self.share[i]:>12.4g}{cell}"
            )
        sets = [(f"class:{c}", m) for c, m in self.classes().items()]
        sets += [(f"group:{g}", m) for g, m in self.groups.items()]
        lines += ["", f"{'class or group':<28}{'members':>8}{'d lambda/du':>16}{'share':>12}{'removed [%]':>13}"]
        for key, members in sets:
            d, s = self.sums(members)
            cell = _removed_cell(self.removals.get(key))
            lines.append(f"{key:<28}{len(members):>8}{d:>16.4g}{s:>12.4g}{cell}")
        statuses = sorted({r.status for r in self.removals.values()})
        if statuses:
            lines.append(
                "removed: lambda_min with the muscle or set held at 0, "
                + ("the others kept" if statuses == ["removed"] else "the optimum re-solved")
                + " (Cholewicki & VanVliet 2002); "
                + f"statuses: {', '.join(statuses)}"
            )
        return "\n".join(lines)


def _removed_cell(removed: Removal | None) -> str:
    """The removal's percent change in a 13-wide cell; blank where not removed, 'infeasible' where not re-solved."""
    if removed is None:
        return f"{'':>13}"
    return f"{removed.percent_change:>13.3g}" if np.isfinite(removed.percent_change) else f"{'infeasible':>13}"


def contributions(
    chain: LinearChain,
    u,
    local_stiffness=0.0,
    groups: dict | None = None,
    remove=(),
    resolve: Resolver | None = None,
) -> Contributions:
    """Each control's contribution to the least eigenvalue of -sym(K(u)), and the removal method.

    Parameters
    ----------
    chain : LinearChain
        The free or the rhythm-constrained chain (its K_i are those of its own coordinates).
    u : array_like, shape (m,)
        The controls [control unit].
    local_stiffness : array_like, shape (n,)
        k added at each joint [N m/rad]: part of the offset.
    groups : dict of str to str or sequence of str, optional
        Named groups (:func:`resolve_groups`).
    remove : sequence of str
        Controls removed one by one (the removal method); every class and group is removed too.
    resolve : callable, optional
        Re-solves the controls with some held at 0 (:data:`Resolver`); None: the others kept.

    Returns
    -------
    Contributions

    References
    ----------
    Cholewicki J, McGill SM (1996). Clin Biomech 11(1):1-15. doi:10.1016/0268-0033(95)00035-6.
    Cholewicki J, VanVliet JJ (2002). Clin Biomech 17(2):99-105. doi:10.1016/S0268-0033(01)00118-8.

    Examples
    --------
    >>> import numpy as np
    >>> from spinectl import load_preset
    >>> from spinectl.model.chain import linear_chain
    >>> chain = linear_chain(load_preset("wagner2012"), 0.03, 0.04)
    >>> c = contributions(chain, [5.0, 5.0, 5.0])
    >>> bool(np.isclose(c.offset + c.share.sum(), c.least.eigenvalue))
    True
    """
    u = np.asarray(u, float)
    if u.shape != (chain.n_controls,) or not np.all(np.isfinite(u)):
        raise ParameterError("controls", f"must be {chain.n_controls} finite numbers (got shape {u.shape})")
    k = np.broadcast_to(np.asarray(local_stiffness, float), (chain.n_joints,))
    least = least_mode(chain.stiffness(u, k))
    v, k_i = least.mode, chain.stiffness_per_control
    if least.degenerate:
        derivative, offset = np.full(chain.n_controls, np.nan), float("nan")
        block = -np.einsum("ai,abm,bj->mij", least.subspace, k_i, least.subspace)
        up = np.linalg.eigvalsh(0.5 * (block + block.transpose(0, 2, 1)))[:, 0] if chain.n_controls else np.zeros(0)
    else:
        derivative = -np.einsum("a,abm,b->m", v, k_i, v)
        up = derivative
        offset = float(-v @ (chain.stiffness_offset - np.diag(k)) @ v)
    diag = np.einsum("jjm->jm", k_i)
    named = resolve_groups(chain.controls, groups or {})
    result = Contributions(
        joints=chain.joints,
        controls=chain.controls,
        control_class=chain.control_class,
        control_unit=chain.control_unit,
        controls_at=u,
        least=least,
        derivative=derivative,
        offset=offset,
        joint_share=-diag * u,
        derivative_up=up,
        groups=named,
    )
    unknown = sorted(set(remove) - set(chain.controls))
    if unknown:
        raise ParameterError("remove", f"names controls the chain lacks: {unknown[:5]}")
    sets = {name: (name,) for name in remove}
    sets |= {f"class:{c}": m for c, m in result.classes().items()}
    sets |= {f"group:{g}": m for g, m in named.items()}
    removals = {key: removal(chain, u, m, least.eigenvalue, k, resolve) for key, m in sets.items()}
    return dataclasses.replace(result, removals=removals)


@dataclass(frozen=True)
class PairContributions:
    """The paper's chain at an operating point: each antagonistic pair's part of each CoR's and the chain's stability.

    Attributes
    ----------
    contributions : Contributions
        Per muscle (the chain with ``optimisation.activation = "independent"``, u the PCSA [cm^2]), the pairs as
        its groups.
    """

    contributions: Contributions

    @property
    def pairs(self) -> tuple:
        """The pairs' names."""
        return tuple(self.contributions.groups)

    def cor_share(self) -> np.ndarray:
        """Each pair's part of each CoR's own stiffness -K_jj, the others fixed.

        Returns
        -------
        numpy.ndarray, shape (n, pairs)
            [N m/rad].
        """
        c = self.contributions
        return np.stack([c.joint_share[:, np.isin(c.controls, m)].sum(axis=1) for m in c.groups.values()], axis=1)

    def chain_share(self) -> np.ndarray:
        """Each pair's share u_i d lambda_min/du_i of the chain's least eigenvalue.

        Returns
        -------
        numpy.ndarray, shape (pairs,)
            [N m/rad].
        """
        return np.array([self.contributions.sums(m)[1] for m in self.contributions.groups.values()])

    def _name(self, index):
        return None if index is None else self.pairs[index]

    def to_dict(self) -> dict:
        """JSON-ready: per pair and CoR, the chain's, the pair that stabilises most of each (null: none gives any
        restoring stiffness), the per-muscle detail.

        Returns
        -------
        dict
        """
        cor, chain = self.cor_share(), self.chain_share()
        c = self.contributions
        return {
            "pairs": list(self.pairs),
            "cors": list(c.joints),
            "cor_share_Nm_per_rad": cor.T.tolist(),
            "cor_stabilised_most_by": [self._name(_most(row)) for row in cor],
            "chain_share_Nm_per_rad": chain.tolist(),
            "chain_stabilised_most_by": self._name(_most(chain)),
            "muscles": c.to_dict(),
        }

    def table(self) -> str:
        """Rows of pairs: their part of each CoR's -K_jj and of the chain's lambda_min, the largest of each marked.

        Returns
        -------
        str
        """
        cor, chain = self.cor_share(), self.chain_share()
        c = self.contributions
        width = max(len(p) for p in self.pairs) + 2
        lines = [
            "",
            f"each pair's part of each CoR's stiffness -K_jj (the others fixed) and of the chain's least eigenvalue "
            f"lambda_min = {c.least.eigenvalue:.4g} N m/rad (u_i d lambda/du_i at the least-stable mode) [N m/rad]; "
            "* the largest restoring part",
            f"{'pair':<{width}}" + "".join(f"{j:>12}" for j in c.joints) + f"{'chain':>13}{'removed [%]':>13}",
        ]
        best_cor, best_chain = [_most(row) for row in cor], _most(chain)
        for p, name in enumerate(self.pairs):
            cells = "".join(f"{cor[j, p]:>11.4g}{'*' if best_cor[j] == p else ' '}" for j in range(len(c.joints)))
            removed = _removed_cell(c.removals.get(f"group:{name}"))
            lines.append(f"{name:<{width}}{cells}{chain[p]:>12.4g}{'*' if best_chain == p else ' '}{removed}")
        if c.least.degenerate:
            lines.append(c.degenerate_text())
        lines.append("removed: lambda_min with the pair at 0, the others kept (Cholewicki & VanVliet 2002)")
        return "\n".join(lines)


def _most(values) -> int | None:
    """The index of the largest positive value (restoring), None where none is above rounding (1e-9 of the largest)."""
    values = np.asarray(values, float)
    if not np.all(np.isfinite(values)) or values.max() <= ROUNDING * np.abs(values).max():
        return None
    return int(np.argmax(values))


def pair_contributions(point) -> PairContributions:
    """Each muscle's and pair's contribution at the paper's operating point (docs/contributions.md).

    Parameters
    ----------
    point : OperatingPoint
        The model, (E, Lambda), the PCSA of each muscle [m^2] and the local stiffness [N m/rad].

    Returns
    -------
    PairContributions

    Examples
    --------
    >>> import numpy as np
    >>> from spinectl import load_preset
    >>> from spinectl.model.operating_point import OperatingPoint
    >>> result = pair_contributions(OperatingPoint(load_preset("wagner2012"), 0.03, 0.04, np.full(6, 5e-4)))
    >>> result.pairs
    ('straight', 'oblique_outer', 'oblique_inner')
    """
    from ..units import M2_PER_CM2
    from .chain import linear_chain

    model = point.model
    per_muscle = model.replace(optimisation=dataclasses.replace(model.optimisation, activation="independent"))
    chain = linear_chain(per_muscle, point.eccentricity, point.lordosis)
    if point.loads:  # their load stiffness in K_0, as chain_at adds it
        from . import geometry
        from .loads import load_stiffness

        cor = geometry.cor_positions(point.eccentricity, point.lordosis, model.geometry)
        chain = dataclasses.replace(
            chain, stiffness_offset=chain.stiffness_offset + load_stiffness(model, cor, point.loads)
        )
    pairs = {p: [f"{p}_{side}" for side in model.geometry.side_names] for p in model.pair_names}
    u = np.asarray(point.pcsa, float) / M2_PER_CM2
    return PairContributions(contributions(chain, u, point.local_stiffness, groups=pairs))
