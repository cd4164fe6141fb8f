"""The record of a subspace fit: channels centred, scaled and the input delayed, in chunks.

Step 1 of :mod:`clpc.lpc.subspace`: every channel is centred and divided by its standard
deviation (two passes in chunks, no copy of the record) and the input is delayed by ``nk``
samples; the later steps read the scaled samples of one experiment at a time
(:meth:`ScaledRecord.inputs`, :meth:`ScaledRecord.outputs`).
"""

from __future__ import annotations

import numpy as np

from clpc.data import DataError, IOData

__all__ = ["CHUNK_ELEMENTS", "ScaledRecord", "paired_record"]

#: Elements of one chunk of a data matrix whose R factor is updated chunk by chunk (2 MiB).
CHUNK_ELEMENTS = 1 << 18


class ScaledRecord:
    """A record's channels centred, scaled and the input delayed by ``nk``, read in chunks.

    Parameters
    ----------
    data : IOData
        The record (one or more experiments; ``m`` inputs, ``l`` outputs).
    nk : int
        Input delay [samples] (>= 0): ``inputs`` returns ``u(t - nk)`` beside ``y(t)``.

    Raises
    ------
    DataError
        A constant channel, or a delay that leaves no sample.
    """

    def __init__(self, data: IOData, nk: int) -> None:
        self.u, self.y, self.nk = data.u, data.y, nk
        self.m, self.ny = data.n_inputs, data.n_outputs
        lengths = np.asarray(data.experiments)
        self.starts = np.cumsum(lengths) - lengths
        self.lengths = [int(n) - nk for n in lengths]  # samples after the delay
        self.u_mean, self.u_scale = _mean_scale(self.u)
        self.y_mean, self.y_scale = _mean_scale(self.y)
        const = [n for n, s in zip(data.input_names, self.u_scale, strict=True) if s == 0]
        const += [n for n, s in zip(data.output_names, self.y_scale, strict=True) if s == 0]
        if const:
            raise DataError(
                f"nothing to identify: constant channel(s) {const}. A subspace fit needs "
                "inputs and outputs that vary over the record."
            )
        if max(self.lengths) < 1:
            raise DataError(f"the delay nk={nk} leaves no sample of the record.")

    def segments(self, stop: int | None = None) -> list[tuple[int, int]]:
        """``(experiment, samples)`` used, from each experiment's start, ``y`` before ``stop``.

        Parameters
        ----------
        stop : int, optional
            First sample (index into the whole record) left out; default: none.

        Returns
        -------
        list of (int, int)
            Experiment index and the number of samples (after the delay) used from its start;
            experiments with none are left out.
        """
        out = []
        for e, (start, length) in enumerate(zip(self.starts, self.lengths, strict=True)):
            n = length if stop is None else min(length, stop - int(start) - self.nk)
            if n > 0:
                out.append((e, n))
        return out

    def inputs(self, e: int, a: int, b: int) -> np.ndarray:
        """Scaled inputs ``u(t - nk)`` of experiment ``e``, ``t = a .. b-1``: (b-a, m).

        Parameters
        ----------
        e : int
            Experiment index.
        a, b : int
            First and one-past-last sample, counted after the delay from the experiment's start.

        Returns
        -------
        numpy.ndarray, shape (b - a, m)
            Centred inputs divided by their standard deviations (dimensionless).
        """
        s = int(self.starts[e])
        return (self.u[s + a : s + b] - self.u_mean) / self.u_scale

    def outputs(self, e: int, a: int, b: int) -> np.ndarray:
        """Scaled outputs ``y(t)`` of experiment ``e`` (``t`` after the delay): (b-a, l).

        Parameters
        ----------
        e : int
            Experiment index.
        a, b : int
            First and one-past-last sample, counted after the delay from the experiment's start.

        Returns
        -------
        numpy.ndarray, shape (b - a, l)
            Centred outputs divided by their standard deviations (dimensionless).
        """
        s = int(self.starts[e]) + self.nk
        return (self.y[s + a : s + b] - self.y_mean) / self.y_scale


def _mean_scale(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Column means and standard deviations, two passes in chunks (no copy of ``x``)."""
    n = x.shape[0]
    mean = x.sum(axis=0) / n
    ss = np.zeros(x.shape[1])
    step = max(1, CHUNK_ELEMENTS // max(x.shape[1], 1))
    for a in range(0, n, step):
        d = x[a : a + step] - mean
        ss += np.einsum("ij,ij->j", d, d)
    return mean, np.sqrt(ss / n)


def paired_record(data: IOData, j: int) -> IOData:
    """Input ``j`` and output ``j`` of a record (its experiments kept).

    Parameters
    ----------
    data : IOData
        The record, with at least ``j + 1`` inputs and outputs.
    j : int
        Channel index (``mimo="paired"``: output ``j`` on input ``j``).

    Returns
    -------
    IOData
        The SISO record of the pair, same sample time and experiments.
    """
    return IOData(
        data.u[:, j],
        data.y[:, j],
        data.dt,
        [data.input_names[j]],
        [data.output_names[j]],
        data.experiments,
    )
