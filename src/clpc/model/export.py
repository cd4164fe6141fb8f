"""The exports of :class:`clpc.LinearModel` (a base class): scipy's ``dlti``, python-control."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from clpc.model import simulation

if TYPE_CHECKING:
    from scipy import signal

__all__ = ["Exports"]


class _Channels(Protocol):
    """What the exports read of a model (its public conventions)."""

    @property
    def numerators(self) -> np.ndarray: ...
    @property
    def denominators(self) -> np.ndarray: ...
    @property
    def intercept(self) -> np.ndarray: ...
    @property
    def n_outputs(self) -> int: ...
    @property
    def n_inputs(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def input_names(self) -> tuple[str, ...]: ...
    @property
    def output_names(self) -> tuple[str, ...]: ...
    def _padded(self, output: int, input: int) -> tuple[np.ndarray, np.ndarray]: ...


class Exports:
    """``to_scipy`` and ``to_control``: one channel pair, or the whole model."""

    def _padded(self: _Channels, output: int, input: int) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator in descending powers of ``z`` (equal length)."""
        num = self.numerators[output, input]
        den = self.denominators[output]
        n = max(num.size, den.size)
        return np.pad(num, (0, n - num.size)), np.pad(den, (0, n - den.size))

    def to_scipy(self: _Channels, output: int = 0, input: int = 0) -> signal.dlti:
        """Export one channel pair as :class:`scipy.signal.dlti` (``dt`` = sample time).

        Parameters
        ----------
        output, input : int
            Channel pair (default 0, 0).

        Returns
        -------
        scipy.signal.dlti
            ``num / den`` in descending powers of ``z``; the constant ``intercept`` is not
            exported.
        """
        num, den = self._padded(output, input)
        # leading zeros (input delay nk) are zero high-power coefficients: dropping them keeps
        # G(z) and spares scipy's "badly conditioned numerator" warning
        num = np.trim_zeros(num, "f") if np.any(num) else num[-1:]
        from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

        return signal.dlti(num, den, dt=self.dt)

    def to_control(self: _Channels, *, include_offset: bool = False) -> Any:
        """Export as a python-control ``StateSpace`` system with the channel names.

        Each output equation is realised in observer canonical form (its inputs share the
        denominator ``A_j``; ``n = max(na, nk + nb)`` states), the outputs stacked block by
        block. A state-space system simulates without slycot (a MIMO transfer function
        does not); ``control.ss2tf`` gives the transfer function of a SISO export.

        Parameters
        ----------
        include_offset : bool
            ``False`` (default): the system from the inputs alone, ``G = num/den`` per
            channel (the deviation model, like ``simulate(..., include_offset=False)``), so
            ``control.dcgain`` and ``control.step_response`` are ``n_outputs x n_inputs``
            and equal :meth:`dc_gain` and the model's step. ``True`` adds an input named
            ``"offset"`` (last) through which the constant ``intercept_j`` enters output
            ``j`` as ``intercept_j / A_j(z)``: driven with ones, ``control.forced_response``
            equals :meth:`simulate` (zero initial conditions, offset included).

        Returns
        -------
        control.StateSpace
            Inputs named after :attr:`input_names` (and ``"offset"``), outputs after
            :attr:`output_names`, ``dt`` the sample time [s]. Needs the optional
            dependency ``control`` (``pip install ".[control]"`` from the source tree).
        """
        try:
            import control
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError(
                "to_control() needs python-control: pip install control (or, in the clpc "
                "source tree, pip install '.[control]')"
            ) from None
        blocks = []
        for j in range(self.n_outputs):
            pairs = [self._padded(j, i) for i in range(self.n_inputs)]
            if include_offset:
                den = pairs[0][1]
                pairs.append((np.r_[self.intercept[j], np.zeros(den.size - 1)], den))
            blocks.append(simulation.observer_form([p[0] for p in pairs], pairs[0][1]))
        n_in = self.n_inputs + int(include_offset)
        sizes = [blk[0].shape[0] for blk in blocks]
        a = np.zeros((sum(sizes), sum(sizes)))
        b = np.zeros((sum(sizes), n_in))
        c = np.zeros((self.n_outputs, sum(sizes)))
        d = np.zeros((self.n_outputs, n_in))
        at = 0
        for j, (aj, bj, cj, dj) in enumerate(blocks):
            sl = slice(at, at + sizes[j])
            a[sl, sl], b[sl], c[j, sl], d[j] = aj, bj, cj, dj
            at += sizes[j]
        inputs = [*self.input_names, *(["offset"] if include_offset else [])]
        return control.ss(a, b, c, d, self.dt, inputs=inputs, outputs=list(self.output_names))
