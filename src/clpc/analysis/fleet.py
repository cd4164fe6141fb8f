"""How far each record's model of a fleet is from the fleet's median model, and which differ.

A fleet is many records of plants that should be alike (the axes of a machine line). Each
record gives one model (transfer functions ``num/den`` per output and input, monic, ascending
powers of ``z^-1``). The **median model** is the coefficient-wise median of the models
that share the most common sample time and structure. The **distance** of a model from it
is the relative RMS difference of their frequency responses over a band (the band the data
excite), over every output/input pair::

    d = sqrt( sum_k sum_ij |G_ij(f_k) - M_ij(f_k)|^2 / sum_k sum_ij |M_ij(f_k)|^2 )

on log-spaced frequencies ``f_k`` - so a model with a 20 % lower gain everywhere has
``d = 0.2``. A record is an **outlier** when its robust z-score
``(d - median d) / max(1.4826 MAD(d), MIN_SCALE)`` exceeds :data:`OUTLIER_Z`.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from clpc.core.filters import frequency_response

__all__ = [
    "BAND_POINTS",
    "MIN_SCALE",
    "OUTLIER_Z",
    "FleetModel",
    "band_grid",
    "fleet_band",
    "gain_drift",
    "median_model",
    "outlier_scores",
    "response_distance",
]

#: log-spaced frequencies the distance is computed on
BAND_POINTS = 200
#: robust z-score above which a record is an outlier (Iglewicz and Hoaglin's 3.5)
OUTLIER_Z = 3.5
#: the smallest spread of distances the z-score divides by (1 % relative distance): a fleet
#: of near-identical models does not turn differences of noise into outliers
MIN_SCALE = 0.01


@dataclass(frozen=True)
class FleetModel:
    """A record's model as plain arrays.

    Parameters
    ----------
    den : ndarray, shape (n_outputs, na + 1)
        Monic denominators, ascending powers of ``z^-1``.
    num : ndarray, shape (n_outputs, n_inputs, nb + 1)
        Numerators.
    dt : float
        Sample time [s].
    """

    den: np.ndarray
    num: np.ndarray
    dt: float

    def response(self, freqs: np.ndarray) -> np.ndarray:
        """Frequency response at ``freqs`` [Hz], shape (n_freqs, n_outputs, n_inputs)."""
        n_out, n_in = self.num.shape[:2]
        out = np.empty((len(freqs), n_out, n_in), dtype=complex)
        fs = 1.0 / self.dt
        for j in range(n_out):
            for i in range(n_in):
                out[:, j, i] = frequency_response(self.num[j, i], self.den[j], freqs, fs)[1]
        return out

    def dc_gain(self) -> np.ndarray:
        """Static gains ``num(1) / den(1)``, shape (n_outputs, n_inputs) (inf at an integrator)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.num.sum(axis=2) / self.den.sum(axis=1)[:, None]

    @property
    def key(self) -> tuple[float, tuple[int, ...], tuple[int, ...]]:
        """Sample time and array shapes: models with equal keys can be averaged."""
        return (self.dt, self.den.shape, self.num.shape)


def median_model(models: Sequence[FleetModel]) -> FleetModel:
    """The coefficient-wise median of the models of the most common sample time and shape.

    Parameters
    ----------
    models : sequence of FleetModel
        At least one.

    Returns
    -------
    FleetModel
    """
    if not models:
        raise ValueError("the median model needs at least one model.")
    key = Counter(m.key for m in models).most_common(1)[0][0]
    same = [m for m in models if m.key == key]
    den = np.median(np.stack([m.den for m in same]), axis=0)
    num = np.median(np.stack([m.num for m in same]), axis=0)
    return FleetModel(den, num, key[0])


def fleet_band(bands: Sequence[tuple[float, float]]) -> tuple[float, float]:
    """The fleet's band [Hz]: the median of the records' lower and of their upper edges.

    Parameters
    ----------
    bands : sequence of (float, float)
        Each record's excited band ``(f_lo, f_hi)`` [Hz].

    Returns
    -------
    (float, float)
    """
    if not bands:
        raise ValueError("the fleet's band needs at least one record's band.")
    lo, hi = (float(np.median([b[k] for b in bands])) for k in (0, 1))
    if not 0 < lo < hi:
        raise ValueError(f"the records' bands give no band: median edges {lo:g} to {hi:g} Hz.")
    return lo, hi


def band_grid(band: tuple[float, float], n: int = BAND_POINTS) -> np.ndarray:
    """``n`` log-spaced frequencies [Hz] from ``band[0]`` to ``band[1]``."""
    return np.geomspace(band[0], band[1], n)


def response_distance(model: FleetModel, reference: FleetModel, freqs: np.ndarray) -> float:
    """The relative RMS distance of two models' frequency responses (see the module).

    Parameters
    ----------
    model, reference : FleetModel
        The same numbers of outputs and inputs; their sample times may differ.
    freqs : ndarray, shape (n_freqs,)
        [Hz], below both models' Nyquist frequencies.

    Returns
    -------
    float
        ``inf`` when the reference response is zero on ``freqs``.
    """
    h = model.response(freqs)
    m = reference.response(freqs)
    norm = float(np.sum(np.abs(m) ** 2))
    diff = float(np.sum(np.abs(h - m) ** 2))
    return float(np.sqrt(diff / norm)) if norm > 0 else float("inf")


def outlier_scores(distances: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """Robust z-scores of distances and which are outliers (see the module).

    Parameters
    ----------
    distances : sequence of float
        One per record (finite or ``inf``).

    Returns
    -------
    z : ndarray, shape (n,)
        ``(d - median) / max(1.4826 MAD, MIN_SCALE)``.
    outlier : ndarray of bool, shape (n,)
        ``z > OUTLIER_Z``; all ``False`` with fewer than 3 records (no spread to judge by).
    """
    d = np.asarray(distances, dtype=np.float64)
    if d.size < 3:
        return np.zeros(d.size), np.zeros(d.size, dtype=bool)
    med = float(np.median(d))
    scale = max(1.4826 * float(np.median(np.abs(d - med))), MIN_SCALE)
    z = (d - med) / scale
    return z, z > OUTLIER_Z


def gain_drift(gain: np.ndarray) -> float | None:
    """How much a DC gain moved over a record: last quarter against first quarter.

    Parameters
    ----------
    gain : ndarray, shape (n,)
        The DC gain of each accepted update, in time order (NaN entries are left out).

    Returns
    -------
    float or None
        ``(median of the last quarter - median of the first quarter) / |median of all|``
        of the finite values; ``None`` with fewer than 8 of them or a zero median.
    """
    g = np.asarray(gain, dtype=np.float64)
    g = g[np.isfinite(g)]
    if g.size < 8:
        return None
    q = g.size // 4
    level = abs(float(np.median(g)))
    if level == 0:
        return None
    return (float(np.median(g[-q:])) - float(np.median(g[:q]))) / level
