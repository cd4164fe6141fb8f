"""The CLPC kernel's setup of a record: its plan, blocks and settings (:class:`KernelSetup`).

:func:`record_setup` makes it once per record: :func:`window_plan` (which sample feeds
which lag column), :func:`block_rows` (the rows of a block), :func:`settings_for` (the
solve settings) and the FSM output's settings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from clpc.appraiser.kernel_types import FsmSettings, WindowPlan
from clpc.core.rules import RobustRule, SolveSettings, solve_settings, transform_mode, trust_rows
from clpc.lpc.solve import fixed_transform, noise_covariance
from clpc.model.structure import Structure

if TYPE_CHECKING:
    from clpc.appraiser.settings import Settings

__all__ = [
    "KernelSetup",
    "block_rows",
    "cache_blocks",
    "record_setup",
    "settings_for",
    "window_plan",
]


@dataclass(frozen=True)
class KernelSetup:
    """What the kernel needs, fixed for a record: the plan and the settings."""

    plan: WindowPlan
    settings: SolveSettings
    fsm: FsmSettings
    n_inputs: int
    plain: tuple[tuple[Any, ...], ...] = ()  #: (plan, settings, fsm) as plain tuples

    def __post_init__(self) -> None:
        # what the kernel's entry point takes (fast to type at every call)
        plain = (tuple(self.plan), tuple(self.settings), tuple(self.fsm))
        object.__setattr__(self, "plain", plain)


def record_setup(
    settings: Settings, channels: tuple[int, int, bool], p: int, min_rows: int
) -> KernelSetup:
    """The plan and settings of a record.

    ``channels = (n_inputs, n_outputs, miso)``; ``p`` parameters per equation; windows of
    fewer than ``min_rows`` rows are not solved.
    """
    st, s = settings, settings.structure
    n_in, _, miso = channels
    cov = noise_covariance(st.noise_cov, st.noise_ratio, s, n_in if miso else 1)
    plan, n_channels = window_plan(s, channels, (st.window_size, st.cluster_size, min_rows), cov)
    trusted = trust_rows(p, st.window_size) if st.trust_rows is None else st.trust_rows
    return KernelSetup(
        plan=plan,
        settings=settings_for((st.method, st.scaling), st.rule, cov, s.na, n_channels),
        fsm=FsmSettings(
            min_rows,
            st.guard,
            trusted,
            st.rule.separation,
            float(st.rule.min_a0_weight),
            s.na,
            s.nb,
            s.nk,
            not miso,
        ),
        n_inputs=n_in,
    )


def window_plan(
    structure: Structure,
    channels: tuple[int, int, bool],
    sizes: tuple[int, int, int],
    noise: np.ndarray | None,
) -> tuple[WindowPlan, int]:
    """Column maps of the lag rows and the transform of the solved problem.

    Parameters
    ----------
    structure : Structure
    channels : (n_inputs, n_outputs, miso)
        ``miso``: every equation uses every input (else the paper's pairing).
    sizes : (window, cluster, min_rows)
    noise : ndarray, shape (p,) or (p, p), optional
        Known noise covariance of the lag vector (weighted LPC).

    Returns
    -------
    plan : WindowPlan
    n_channels : int
        Channel blocks of a lag vector (the output, then one per input block).
    """
    n_in, n_out, miso = channels
    s = structure
    n_blocks = n_in if miso else 1
    p = s.n_params(n_blocks)
    col_channel = np.zeros(p, dtype=np.int64)
    for blk in range(n_blocks):
        col_channel[s.na + 1 + blk * (s.nb + 1) : s.na + 1 + (blk + 1) * (s.nb + 1)] = blk + 1
    # column a of equation e is buf[k - lag, chan] (buffer columns: inputs, then outputs)
    chan = np.empty((n_out, p), dtype=np.int64)
    lag = np.empty((n_out, p), dtype=np.int64)
    for e in range(n_out):
        chan[e, : s.na + 1] = n_in + e
        lag[e, : s.na + 1] = np.arange(s.na + 1)
        for i, inp in enumerate(range(n_in) if miso else [e]):
            cols = slice(s.na + 1 + i * (s.nb + 1), s.na + 1 + (i + 1) * (s.nb + 1))
            chan[e, cols] = inp
            lag[e, cols] = s.nk + np.arange(s.nb + 1)
    transform = np.eye(p) if noise is None else fixed_transform(noise, p)
    window, cluster, min_rows = sizes
    plan = WindowPlan(
        chan,
        lag,
        col_channel,
        np.ascontiguousarray(transform),
        window,
        cluster,
        min_rows,
        block_rows(window, cluster),
    )
    return plan, n_blocks + 1


def cache_blocks(plan: WindowPlan) -> int:
    """Blocks a :class:`BlockCache` holds: those of one window, and one more."""
    return plan.window // plan.block + 2


def block_rows(window: int, cluster: int) -> int:
    """Rows ``B`` of a block: ``C``, or a multiple of it near ``sqrt(W)`` when ``C`` is small.

    A window costs its tail and head pieces (up to ``B`` rows each, summarised per window)
    plus a merge over its ``W / B`` full blocks; ``B ~ sqrt(W)`` balances the two. With
    ``C >= sqrt(W) / 1.5`` (the paper's ``C = 12``, ``W = 201``) ``B = C`` and windows have
    no head piece.
    """
    return cluster * max(1, round(math.sqrt(window) / cluster))


def settings_for(
    method: tuple[str, str],
    rule: RobustRule,
    noise: np.ndarray | None,
    na: int,
    n_channels: int,
) -> SolveSettings:
    """The solve settings of an appraiser: ``method = (method, scaling)``.

    See :func:`clpc.core.rules.solve_settings` and :func:`clpc.core.rules.transform_mode`.
    """
    name, scaling = method
    mode = transform_mode(scaling, noise is not None)
    return solve_settings(rule, name == "robust", mode, na + 1, n_channels)
