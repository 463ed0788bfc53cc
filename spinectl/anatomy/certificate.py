"""The global muscles' certificate: the rank of their moment arms over the chain and what is left in its null space.

Their moment arms over the chain's joints have rank r; the n - r directions of their null space are modes
whose stiffness they can give only through their lengths' curvature (docs/chain.md), left to the local
muscles, passive tissue and reflexes (docs/anatomy.md, "The global muscles' rank").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.linear_chain import LinearChain
from .contract import AnatomyEngine

RANK_TOLERANCE = 1e-2
"""A singular value of the global muscles' moment arms below this times the largest counts as zero (their rank).

Physical, not numerical: along a direction whose lever is under 1 % of the global muscles' best one, they
need a hundred times the force for the same torque, so in practice they leave it to the local muscles,
passive tissue and reflexes. The round-off floor (1e-9, before) counted the Allaire cyclist's 0.06 mm/rad
(5.76e-5 m/rad beside 0.454) as rank; MyoTorso's least kept value is 16 % of its largest (0.073 of 0.451
m/rad), its rank 3 either way."""


@dataclass(frozen=True)
class GlobalCertificate:
    """The global muscles' moment arms over the chain: rank, null space and what is left in it.

    Attributes
    ----------
    muscles : tuple of str
        The global muscles.
    singular_values : numpy.ndarray, shape (n,)
        Of their moment-arm matrix [m/rad].
    rank : int
        Singular values above :data:`RANK_TOLERANCE` times the largest.
    null_space : numpy.ndarray, shape (n, n - rank)
        Orthonormal directions in which no global muscle changes length.
    null_space_stiffness : numpy.ndarray, shape (n - rank,)
        Eigenvalues of -N^T K(a) N: the chain's stiffness there at the activations [N m/rad].
    global_null_space_stiffness : numpy.ndarray, shape (n - rank,)
        Eigenvalues of -N^T (sum over global i of K_i) N: what all global muscles at full activation add
        there (their lengths' curvature only) [N m/rad].
    """

    muscles: tuple
    singular_values: np.ndarray
    rank: int
    null_space: np.ndarray
    null_space_stiffness: np.ndarray
    global_null_space_stiffness: np.ndarray


def global_certificate(anatomy: AnatomyEngine, chain: LinearChain, arms, a) -> GlobalCertificate:
    """The global muscles' null-space certificate on a chain.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (its muscle classes).
    chain : LinearChain
        The (free) chain.
    arms : numpy.ndarray, shape (m, n)
        The muscles' moment arms over the chain's coordinates [m/rad].
    a : array_like, shape (m,)
        Activations.

    Returns
    -------
    GlobalCertificate
    """
    is_global = np.array([c == "global" for c in chain.control_class], bool)  # bool also without muscles
    _, sv, vt = np.linalg.svd(arms[is_global], full_matrices=True)
    sv = np.concatenate([sv, np.zeros(chain.n_joints - sv.size)])
    rank = int(np.sum(sv > RANK_TOLERANCE * sv.max())) if sv.size and sv.max() > 0 else 0
    null = vt[rank:].T
    k = chain.stiffness(a)
    k_global = chain.stiffness_per_control[..., is_global].sum(axis=-1)
    return GlobalCertificate(
        muscles=tuple(np.array(chain.controls, object)[is_global]),
        singular_values=sv[: chain.n_joints],
        rank=rank,
        null_space=null,
        null_space_stiffness=np.linalg.eigvalsh(-null.T @ k @ null) if null.size else np.zeros(0),
        global_null_space_stiffness=np.linalg.eigvalsh(-null.T @ k_global @ null) if null.size else np.zeros(0),
    )
