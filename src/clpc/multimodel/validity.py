"""Validity functions and centres of a multi-model (normalised Gaussians on one variable).

Model ``i`` of ``M`` is valid around its centre ``c_i`` with width ``s_i``; the validity of
model ``i`` at scheduling value ``psi`` is

    phi_i(psi) = exp(-(psi - c_i)^2 / (2 s_i^2)) / sum_j exp(-(psi - c_j)^2 / (2 s_j^2)),

so the validities are non-negative and sum to 1 at every ``psi``. The width is
:data:`WIDTH_FACTOR` times the distance from a centre to its nearest neighbour (a single
model has infinite width: ``phi = 1``). Centres come from a 1-D k-means (Lloyd's
iterations started at quantiles: deterministic, no random restart).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["WIDTH_FACTOR", "kmeans_1d", "validity", "widths_for"]

#: width of a validity function over the distance to the nearest centre (issue 18's
#: prototype: 0.6 blends neighbours smoothly without washing out the local models)
WIDTH_FACTOR = 0.6


def kmeans_1d(values: Any, n_centres: int, iterations: int = 100) -> np.ndarray:
    """Centres of ``n_centres`` clusters of 1-D ``values`` (ascending, distinct).

    Parameters
    ----------
    values : array_like, shape (n,)
        Finite samples (e.g. window operating points).
    n_centres : int
        Number of clusters (>= 1); fewer distinct centres are returned when the values
        hold fewer distinct points.
    iterations : int
        Most Lloyd iterations.

    Returns
    -------
    ndarray, shape (m,), m <= n_centres
    """
    x = np.sort(np.asarray(values, dtype=np.float64).ravel())
    if x.size == 0 or not np.all(np.isfinite(x)):
        raise ValueError("kmeans_1d needs at least one value, all finite.")
    k = min(int(n_centres), np.unique(x).size)
    centres = np.quantile(x, (np.arange(k) + 0.5) / k)
    for _ in range(iterations):
        # 1-D: the clusters are intervals between midpoints of sorted centres
        edges = 0.5 * (centres[1:] + centres[:-1])
        label = np.searchsorted(edges, x)
        sums = np.bincount(label, weights=x, minlength=k)
        counts = np.bincount(label, minlength=k)
        new = np.where(counts > 0, sums / np.maximum(counts, 1), centres)
        new.sort()
        if np.array_equal(new, centres):
            break
        centres = new
    return np.unique(centres)


def widths_for(centres: np.ndarray) -> np.ndarray:
    """Widths ``WIDTH_FACTOR * distance to the nearest centre`` (inf for one centre)."""
    c = np.asarray(centres, dtype=np.float64)
    if c.size == 1:
        return np.array([np.inf])
    gaps = np.diff(c)
    nearest = np.minimum(np.r_[np.inf, gaps], np.r_[gaps, np.inf])
    return WIDTH_FACTOR * nearest


def validity(psi: Any, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """Normalised Gaussian validities, shape ``psi.shape + (M,)``; each row sums to 1.

    Computed as a softmax (the largest exponent subtracted), so no underflow to 0/0 far
    from every centre: there the nearest model (in width units) takes over.
    """
    p = np.asarray(psi, dtype=np.float64)
    inv_w = 1.0 / np.asarray(widths, dtype=np.float64)
    e = -0.5 * ((p[..., None] - centres) * inv_w) ** 2
    e -= e.max(axis=-1, keepdims=True)
    w = np.exp(e)
    return w / w.sum(axis=-1, keepdims=True)
