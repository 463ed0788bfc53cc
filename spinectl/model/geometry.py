"""Geometry: the spine line, the centres of rotation, the muscle fibres.

Pure array functions, SI units, no I/O. Frame (docs/model.md, "Frame and units"):
x horizontal, positive ventral (sagittal) or right (coronal); y vertical, up;
the body's symmetry axis is x = 0; P2 (pelvic joint) at y = 0.
"""

from __future__ import annotations

import numpy as np

from .params import Geometry, Model, MusclePair

SPLINE_SHAPES = {
    "natural": lambda s: 1.5 * s - 0.5 * s**3,  # phi''(P1) = phi''(P2) = 0
    "clamped": lambda s: 3.0 * s**2 - 2.0 * s**3,  # phi'(P1) = phi'(P2) = 0
    "not-a-knot": lambda s: 2.0 * s - s**2,  # one cubic through three knots, symmetric: the parabola
}
"""The cubic spline phi through (0, 0), (L/2, 1), (L, 0) for each end condition, as a function of
s = 1 - abs(y - L/2) / (L/2) in [0, 1] (docs/model.md, "The spine line").

The data are symmetric about L/2, so the spline is, and phi'(L/2) = 0: each half is the cubic with
phi(0) = 0, phi(1) = 1, phi'(1) = 0 and the end condition. In closed form because
scipy.interpolate.CubicSpline, which gives the same values (tests/model/test_mechanics.py), takes
longer to import than numpy and scipy together, and ``spinectl stability`` needs only these values.
"""


def lordosis_shape(geometry: Geometry) -> np.ndarray:
    """Horizontal offset of each CoR per unit lordosis, phi_k [1].

    The spine line is a cubic spline through P2 (y = 0), P3 (y = L/2) and P1
    (y = L), L the spine length (paper, Methods; docs/model.md, "The spine line"). The
    spline is linear in its data, so with P1 and P2 at x = -E and P3 at
    x = -E + Lambda the line is x(y) = -E + Lambda phi(y), phi being the spline
    through (0, 0), (L/2, 1), (L, 0), in closed form (:data:`SPLINE_SHAPES`); for natural
    end conditions phi = 1.5 s - 0.5 s^3 with s = 1 - abs(y - L/2) / (L/2).

    Parameters
    ----------
    geometry : Geometry
        Heights of the CoRs [m], spine length L [m], spline end conditions.

    Returns
    -------
    numpy.ndarray, shape (n_cor,)
        phi at each CoR height [1].
    """
    half = geometry.spine_length / 2
    s = 1.0 - np.abs(np.asarray(geometry.cor_heights, float) - half) / half
    return SPLINE_SHAPES[geometry.spline_bc](s)


def cor_positions(eccentricity, lordosis, geometry: Geometry) -> np.ndarray:
    """Positions of the centres of rotation for an eccentricity and a lordosis.

    x_k = -E + Lambda phi_k, y_k = the CoR heights (docs/model.md, "Centres of
    rotation and the point mass").

    Parameters
    ----------
    eccentricity : array_like
        E, dorsal shift of the spine [m]; any shape.
    lordosis : array_like
        Lambda, ventral displacement of P3 [m]; broadcast against E.
    geometry : Geometry

    Returns
    -------
    numpy.ndarray, shape (..., n_cor, 2)
        (x, y) of every CoR [m].
    """
    e, lam = np.broadcast_arrays(np.asarray(eccentricity, float), np.asarray(lordosis, float))
    phi = lordosis_shape(geometry)
    x = -e[..., None] + lam[..., None] * phi
    y = np.broadcast_to(np.asarray(geometry.cor_heights), x.shape)
    return np.stack([x, y], axis=-1)


def mass_position(model: Model) -> np.ndarray:
    """Position of the upper-body point mass, (0, mass_height) [m] (paper, Methods).

    Parameters
    ----------
    model : Model
        Supplies ``body.mass_height`` [m].

    Returns
    -------
    numpy.ndarray, shape (2,)
        (x, y) of the point mass [m].
    """
    return np.array([0.0, model.body.mass_height])


def fibre_offsets(n: int, spread: float) -> np.ndarray:
    """Offsets of ``n`` parallel fibres across a surface of width ``spread`` [m].

    Evenly spaced and centred: ``linspace(-spread/2, spread/2, n)``; a single
    fibre lies on the line of action.

    Parameters
    ----------
    n : int
        Number of fibres [1].
    spread : float
        Width of the attachment surface [m].

    Returns
    -------
    numpy.ndarray, shape (n,)
        Offset of each fibre from the line of action along its unit normal [m].
    """
    if n == 1:
        return np.zeros(1)
    return np.linspace(-spread / 2, spread / 2, n)


def pair_fibres(pair: MusclePair) -> tuple[np.ndarray, np.ndarray]:
    """Upper and lower attachment points of the fibres of one pair.

    The fibres of a muscle are parallel copies of its line of action shifted
    along the unit normal by :func:`fibre_offsets` (paper: "five parallel
    muscle fibers, to simulate physiologically realistic surfaces of
    attachment"). The dorsal muscle is the mirror image x -> -x.

    Parameters
    ----------
    pair : MusclePair
        Attachments of the ventral muscle [m], spread [m] and number of fibres.

    Returns
    -------
    upper, lower : numpy.ndarray, shape (2, n_fibres, 2)
        Attachment points [m], indexed [side, fibre, xy], side 0 ventral, 1 dorsal.
    """
    upper, lower = np.asarray(pair.upper), np.asarray(pair.lower)
    direction = (lower - upper) / np.linalg.norm(lower - upper)
    normal = np.array([-direction[1], direction[0]])
    shift = fibre_offsets(pair.fibres, pair.spread)[:, None] * normal
    mirror = np.array([-1.0, 1.0])
    ups = np.stack([upper + shift, (upper + shift) * mirror])
    lows = np.stack([lower + shift, (lower + shift) * mirror])
    return ups, lows


def all_fibres(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every fibre of every muscle, with the matrix that sums fibres into muscles.

    Each fibre carries an equal share of its muscle's PCSA.

    Parameters
    ----------
    model : Model
        Supplies the muscle pairs.

    Returns
    -------
    upper, lower : numpy.ndarray, shape (n_fibres_total, 2)
        Upper (moving) and lower (fixed) attachment points [m].
    share : numpy.ndarray, shape (n_fibres_total, n_muscles)
        share[f, j] = 1 / n_fibres(j) if fibre f belongs to muscle j, else 0 [1].
        Muscles are ordered as :attr:`~spinectl.model.params.model.Model.muscle_names`.
    """
    uppers, lowers, shares = [], [], []
    n_muscles = 2 * len(model.muscles)
    for p, pair in enumerate(model.muscles):
        ups, lows = pair_fibres(pair)
        for side in range(2):
            uppers.append(ups[side])
            lowers.append(lows[side])
            block = np.zeros((pair.fibres, n_muscles))
            block[:, 2 * p + side] = 1.0 / pair.fibres
            shares.append(block)
    return np.concatenate(uppers), np.concatenate(lowers), np.concatenate(shares)


def pairing_matrix(n_pairs: int) -> np.ndarray:
    """Map pair PCSAs to muscle PCSAs: pcsa_muscles = P @ pcsa_pairs, shape (2 n, n).

    Paired activation gives both sides of a pair the same PCSA (docs/model.md,
    "The muscles"), so each pair's total PCSA is twice its per-side value;
    the decision variable here is the per-side PCSA.

    Parameters
    ----------
    n_pairs : int
        Number of antagonistic pairs.

    Returns
    -------
    numpy.ndarray, shape (2 n_pairs, n_pairs)
        P[2 j + side, j] = 1, else 0 [1]; rows in the order of
        :attr:`~spinectl.model.params.model.Model.muscle_names`.
    """
    return np.repeat(np.eye(n_pairs), 2, axis=0)
