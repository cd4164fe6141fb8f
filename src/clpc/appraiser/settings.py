"""The settings of an appraiser: one name each, checked once, read-only.

:class:`Settings` is what :class:`clpc.CLPC` is built with (its constructor's arguments, in
the same order); it holds no state. :class:`SettingsProperties` shows each setting as a
read-only property of the appraiser. :meth:`Settings.from_config` reads the saved form,
mapping the names of states saved before one name per setting once.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from dataclasses import field as dc_field
from typing import Any

import numpy as np

from clpc.appraiser.decimation import decimation_factor
from clpc.appraiser.inputs import check_noise_cov
from clpc.appraiser.state_schema import StateError
from clpc.core.checks import check_bool, check_choice, check_int, check_positive
from clpc.core.rules import SCALINGS, RobustRule
from clpc.data import DataError
from clpc.model.structure import Structure

__all__ = ["Settings", "SettingsProperties"]

#: counts of rows: beyond this no window fits in memory anyway
_TOP = 2**31 - 1


@dataclass(frozen=True, eq=False)
class Settings:
    """The checked settings of :class:`clpc.CLPC` (see its parameters)."""

    order: int = 2
    window_size: int = 201
    cluster_size: int = 12
    dt: float | None = None
    decimate_to: float | None = None
    guard: bool = True
    na: int | None = None
    nb: int | None = None
    nk: int = 0
    method: str = "robust"
    scaling: str = "none"
    mimo: str | None = None
    noise_ratio: float | None = None
    noise_cov: np.ndarray | None = None
    rule: RobustRule = dc_field(default_factory=RobustRule)
    trust_rows: int | None = None
    min_rows: int | None = None
    n_jobs: int = 1
    chunk_samples: int = 524288
    structure: Structure = dc_field(init=False)

    def __post_init__(self) -> None:
        def put(name: str, value: Any) -> None:
            object.__setattr__(self, name, value)

        def count(name: str, low: int, high: int | None = None, required: bool = False) -> None:
            value = getattr(self, name)
            if value is not None or required:  # check_int refuses None with the name
                put(name, check_int(value, name, low, high))

        def seconds(name: str) -> None:
            value = getattr(self, name)
            if value is not None:
                put(name, check_positive(value, name, "s"))

        count("order", 1)
        count("window_size", 2, required=True)
        count("cluster_size", 1, required=True)
        seconds("dt")
        seconds("decimate_to")
        put("guard", check_bool(self.guard, "guard"))
        o = self.order
        put(
            "structure",
            Structure(
                o if self.na is None else self.na, o if self.nb is None else self.nb, self.nk
            ),
        )
        put("method", check_choice(self.method, "method", ("robust", "paper")))
        put("scaling", check_choice(self.scaling, "scaling", SCALINGS))
        put("noise_cov", check_noise_cov(self.noise_cov))
        put("rule", self.rule or RobustRule())
        count("trust_rows", 1, _TOP)
        count("min_rows", 2, _TOP)
        count("n_jobs", 1, required=True)
        count("chunk_samples", 1024, required=True)
        self.check_window(self.structure.n_params())  # one input: the fewest parameters

    def check_window(self, p: int) -> None:
        """Refuse a window that can never hold ``min_rows`` lag vectors for ``p`` parameters."""
        need = max(self.min_rows if self.min_rows is not None else 2 * p, p + 1)
        if self.window_size < need:
            raise ValueError(
                f"window_size={self.window_size} cannot hold the {need} lag vectors that {p} "
                f"parameters need (min_rows, default 2 p): every update would be 'not enough "
                f"data'. Use window_size >= {need} or fewer parameters."
            )

    def factor(self, data_dt: float | None) -> int:
        """The decimation factor for data sampled every ``data_dt`` [s] (``None``: ``dt``)."""
        own = self.dt
        if data_dt is not None and own is not None and not math.isclose(data_dt, own, rel_tol=1e-9):
            raise DataError(
                f"the record's sample time is {data_dt:g} s but CLPC(dt={own:g}); they must "
                "agree (dt is the data's sample time; decimate_to is the rate to work at)."
            )
        rate = data_dt if data_dt is not None else own
        if rate is None and self.decimate_to is not None:
            raise DataError(
                f"decimate_to={self.decimate_to:g} s needs the data's sample time; pass dt= "
                "to CLPC (or to run()), or give an IOData with its dt."
            )
        return decimation_factor(self.decimate_to, rate)

    def config(self) -> dict[str, Any]:
        """The constructor arguments (JSON-safe)."""
        s = self.structure
        return {
            "order": self.order,
            "window_size": self.window_size,
            "cluster_size": self.cluster_size,
            "dt": self.dt,
            "decimate_to": self.decimate_to,
            "guard": self.guard,
            "na": s.na,
            "nb": s.nb,
            "nk": s.nk,
            "method": self.method,
            "scaling": self.scaling,
            "mimo": self.mimo,
            "noise_ratio": self.noise_ratio,
            "noise_cov": None if self.noise_cov is None else self.noise_cov.tolist(),
            "rule": asdict(self.rule),
            "trust_rows": self.trust_rows,
            "min_rows": self.min_rows,
            "n_jobs": self.n_jobs,
            "chunk_samples": self.chunk_samples,
        }

    @classmethod
    def from_config(cls, config: dict[str, Any]) -> Settings:
        """The settings saved by :meth:`config` (:class:`StateError` naming what is wrong).

        States saved before one name per setting are mapped once: ``parameters_size`` to
        ``order`` (``N + 1``), ``gate`` to ``guard``; the former ``sample_time`` meant either
        ``dt`` or ``decimate_to`` and is refused.
        """
        cfg = dict(config)
        if "sample_time" in cfg:
            raise StateError(
                "state['config'] has the former, ambiguous sample_time (the data's sample time "
                "or a decimation target): this state cannot be continued; run the record again "
                "with dt and decimate_to."
            )
        size = cfg.pop("parameters_size", None)
        if size is not None and "order" not in cfg:
            cfg["order"] = check_int(size, "parameters_size", 2) - 1
        if "gate" in cfg and "guard" not in cfg:
            cfg["guard"] = cfg.pop("gate")
        cfg.pop("engine", None)  # states written while the kernel had an engine setting
        rule = cfg.pop("rule", None)
        if not isinstance(rule, dict):
            raise StateError("state['config']['rule'] must be an object of thresholds.")
        try:
            return cls(rule=RobustRule(**rule), **cfg)
        except (TypeError, ValueError) as exc:
            raise StateError(f"state['config'] does not describe an appraiser: {exc}") from None


def _setting(name: str, doc: str) -> Any:
    return property(lambda self: getattr(self.settings, name), doc=doc)


class SettingsProperties:
    """Every setting as a read-only property of an object that holds ``settings``.

    :class:`clpc.CLPC` exposes its :class:`Settings` this way (``appraiser.window_size``).
    """

    settings: Settings

    order = _setting("order", "``N``: ``na = nb = N`` unless ``na``/``nb`` are given.")
    window_size = _setting("window_size", "``W``: lag vectors per LPC.")
    cluster_size = _setting("cluster_size", "``C``: lag vectors between updates.")
    dt = _setting("dt", "The data's sample time [s] given to the constructor (or ``None``).")
    decimate_to = _setting("decimate_to", "Sample time [s] worked at (``None``: the data's).")
    guard = _setting("guard", "Accept estimates of trusted windows only.")
    structure = _setting("structure", "The model structure (``na``, ``nb``, ``nk``).")
    method = _setting("method", "The LPC solve: ``'robust'`` or ``'paper'``.")
    scaling = _setting("scaling", "Channel scaling of the LPC solve.")
    mimo = _setting("mimo", "Multi-channel structure (``None``: from the data).")
    noise_ratio = _setting("noise_ratio", "Known noise ratio of the LPC solve (or ``None``).")
    noise_cov = _setting("noise_cov", "Known noise covariance of the lag vector (or ``None``).")
    rule = _setting("rule", "The thresholds of the robust solve.")
    trust_rows = _setting("trust_rows", "Lag vectors a trusted window needs (``None``: default).")
    min_rows = _setting("min_rows", "Fewest rows of a usable window (``None``: ``2 p``).")
    n_jobs = _setting("n_jobs", "Threads of the batched solves.")
    chunk_samples = _setting("chunk_samples", "Samples processed at a time by :meth:`push`.")
