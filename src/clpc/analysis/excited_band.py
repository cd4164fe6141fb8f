"""The frequency band a record's inputs excite, from a power spectrum accumulated chunk by chunk.

:class:`InputSpectrum` is Welch's estimate (Hann-windowed segments of :data:`SEGMENT`
samples, each with its mean removed, no overlap) fed with the chunks of a record as they are
read: O(segment) memory, one FFT per segment, so a pass over the record stays linear in its
length. :func:`excited_band` turns the spectrum into the band ``[f_lo, f_hi]`` [Hz] where
an input's power is within :data:`BAND_LEVEL` of its peak.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BAND_LEVEL", "SEGMENT", "InputSpectrum", "excited_band"]

#: samples per Welch segment (frequency resolution ``1 / (SEGMENT * dt)``)
SEGMENT = 1024
#: an input excites a frequency where its power is at least this fraction of its peak (-20 dB)
BAND_LEVEL = 1e-2


@dataclass
class InputSpectrum:
    """Welch power spectrum of the input columns of a record fed in chunks.

    Parameters
    ----------
    dt : float
        Sample time of the fed samples [s].
    segment : int
        Samples per segment (a record shorter than one segment is one segment of its
        own length).
    """

    dt: float
    segment: int = SEGMENT

    def __post_init__(self) -> None:
        self._carry = np.empty((0, 0))
        self._sum: np.ndarray | None = None
        self._count = 0

    def feed(self, u: np.ndarray) -> None:
        """Add samples.

        Parameters
        ----------
        u : ndarray, shape (n, n_inputs)
            The next input samples (a NaN counts as 0).
        """
        u = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
        both = u if self._carry.size == 0 else np.concatenate([self._carry, u])
        n_full = both.shape[0] // self.segment
        if n_full:
            segs = both[: n_full * self.segment].reshape(n_full, self.segment, -1)
            power = self._power(segs).sum(axis=0)
            self._sum = power if self._sum is None else self._sum + power
            self._count += n_full
        self._carry = both[n_full * self.segment :]

    def _power(self, segs: np.ndarray) -> np.ndarray:
        """One-sided power of each segment, shape (n_segments, n_freqs, n_inputs)."""
        x = np.nan_to_num(segs, nan=0.0)
        x = x - x.mean(axis=1, keepdims=True)
        win = np.hanning(segs.shape[1])[None, :, None]
        spec = np.fft.rfft(x * win, axis=1)
        return np.abs(spec) ** 2 / np.sum(win**2)

    def spectrum(self) -> tuple[np.ndarray, np.ndarray]:
        """The averaged spectrum so far.

        Returns
        -------
        freqs : ndarray, shape (n_freqs,)
            [Hz].
        power : ndarray, shape (n_freqs, n_inputs)
            Mean power per segment (relative units: only its shape over frequency is used).

        Raises
        ------
        ValueError
            Fewer than 4 samples were fed.
        """
        if self._sum is not None:
            n, power = self.segment, self._sum / self._count
        elif self._carry.shape[0] >= 4:
            n, power = self._carry.shape[0], self._power(self._carry[None])[0]
        else:
            raise ValueError(
                f"the input spectrum needs at least 4 samples; got {self._carry.shape[0]}."
            )
        return np.fft.rfftfreq(n, self.dt), power


def excited_band(
    freqs: np.ndarray, power: np.ndarray, level: float = BAND_LEVEL
) -> tuple[float, float] | None:
    """The band ``[f_lo, f_hi]`` [Hz] where some input's power is within ``level`` of its peak.

    The constant (0 Hz) bin is left out: the segments have their mean removed.

    Parameters
    ----------
    freqs : ndarray, shape (n_freqs,)
        [Hz], ascending, from :meth:`InputSpectrum.spectrum`.
    power : ndarray, shape (n_freqs,) or (n_freqs, n_inputs)
        Power per frequency.
    level : float
        Fraction of each input's peak power (in (0, 1]).

    Returns
    -------
    (float, float) or None
        The lowest and the highest frequency where an input's power reaches ``level`` times
        its own peak; ``None`` when no input varies (every input constant).
    """
    p = np.asarray(power, dtype=np.float64).reshape(len(freqs), -1)[1:]
    f = np.asarray(freqs, dtype=np.float64)[1:]
    peak = p.max(axis=0, initial=0.0)
    live = peak > 0
    if not live.any() or f.size == 0:
        return None
    hit = np.any(p[:, live] >= level * peak[live], axis=1)
    idx = np.flatnonzero(hit)
    return float(f[idx[0]]), float(f[idx[-1]])
