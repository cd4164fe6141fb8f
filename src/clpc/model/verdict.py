"""Identifiability verdicts in plain words, for a fit (and, re-exported, for a trace).

The numbers behind them come from the solve (:mod:`clpc.lpc.solve`): the dimension of the
near-null subspace the solution was taken from (``n_null``), the near-null relations that
involve almost no output (``n_input_relations``: the input alone satisfies them, so it is not
persistently exciting of the model's order), the separation of the solution's eigenvalue from
the next one, and the stability of the monic model.

A fit's verdict opens with the evidence that the model describes the record, when the
estimator stored it (:mod:`clpc.lpc.assessment`): the held-out free-run and ``k``-step fit
and the residual tests. The model is *adequate* when the held-out free-run fit is at least
:data:`clpc.core.rules.MIN_HELDOUT_FIT` % and the residuals are independent of the input;
"the data determine the parameters" speaks of identifiability only and never stands alone
beside a model that is not adequate.

What the record cannot decide comes first (:mod:`clpc.model.identifiability`): an input not
persistently exciting of the order the structure needs, or a DC gain whose sign is
undetermined, opens the verdict with its numbers and thresholds, and the verdict then
states the held-out fit without calling the model good. One finding per message;
``str(verdict)`` puts each on its own line.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.compact import compact_repr
from clpc.core.polynomials import pole_class, pole_words
from clpc.core.rules import MIN_HELDOUT_FIT
from clpc.model.identifiability import identifiability
from clpc.model.trace_findings import describe_trace

__all__ = ["Verdict", "describe_trace", "fit_verdict"]


@compact_repr
@dataclass(frozen=True)
class Verdict:
    """Identifiability of one fitted equation.

    Attributes
    ----------
    n_null : int
        Dimension of the near-null subspace (1: the generic, unique solution).
    persistently_exciting : bool
        No input-only relation is as small as the system relation.
    determined : bool
        The data determine the parameter vector (unique and well separated).
    stable : bool
        All poles strictly inside the unit circle.
    order : int
        The input order the excitation was checked for (``nb + 1`` lags).
    messages : tuple of str
        Plain-language findings.
    stability : str
        ``"stable"``, ``"integrating"`` (a pole at z = 1: an integrator, not a failure),
        ``"marginal"`` or ``"unstable"`` (:func:`clpc.core.polynomials.pole_class`).
    heldout_fit, heldout_kstep : float or None
        Held-out free-run and ``k``-step fit % (``None``: not assessed).
    residuals_independent, residuals_white : bool or None
        Outcome of the residual tests of this output (``None``: not assessed).
    adequate : bool or None
        Held-out free-run fit at least :data:`~clpc.core.rules.MIN_HELDOUT_FIT` % and
        residuals independent of the input (``None``: not assessed).
    identifiable : bool or None
        The input excites the order the structure needs and every DC gain's sign is
        determined (:class:`clpc.model.identifiability.Identifiability`); ``None``: not
        judged.
    excitation_order, needed_order : int or None
        The record's input's order of persistent excitation (up to the needed order;
        ``None``: the model keeps no record) and the order the structure needs
        (``na + nb + 1``).
    """

    n_null: int
    persistently_exciting: bool
    determined: bool
    stable: bool
    order: int
    messages: tuple[str, ...]
    stability: str = "stable"
    heldout_fit: float | None = None
    heldout_kstep: float | None = None
    residuals_independent: bool | None = None
    residuals_white: bool | None = None
    adequate: bool | None = None
    identifiable: bool | None = None
    excitation_order: int | None = None
    needed_order: int | None = None

    def __str__(self) -> str:
        return "\n".join(self.messages)


def _fmt(fit: float) -> str:
    if not np.isfinite(fit):
        return "diverges"
    return f"{fit:.1f} %" if abs(fit) < 1e4 else f"{fit:.2g} %"


def evidence(
    info: dict[str, Any], output: int, neutral: bool = False
) -> tuple[list[str], dict[str, Any]]:
    """Words and numbers of the stored held-out fit and residual tests of one output.

    ``neutral``: the record does not identify the model, so no head calls it good (the
    held-out fit is stated, not judged a fit).
    """
    msgs: list[str] = []
    found: dict[str, Any] = {}
    held = info.get("heldout")
    if isinstance(held, dict) and "free_run" in held:
        fr, ks = float(held["free_run"]), float(held["kstep"])
        if "free_run_outputs" in held:  # this output's own fits
            fr = float(np.atleast_1d(held["free_run_outputs"])[output])
            ks = float(np.atleast_1d(held["kstep_outputs"])[output])
        found["heldout_fit"], found["heldout_kstep"] = fr, ks
        poor = not fr >= MIN_HELDOUT_FIT
        msgs.append(
            f"held-out fit (refit on the first {int(held['split'])} samples, scored on the last "
            f"{int(held['n_heldout'])}): free run {_fmt(fr)}, {int(held['horizon'])}-step "
            f"prediction {_fmt(ks)}"
            + (
                f" - below {MIN_HELDOUT_FIT:g} %: the model describes the record poorly"
                if poor
                else ""
            )
        )
    test = info.get("residual_test")
    if isinstance(test, dict) and "white" in test:
        white = bool(np.atleast_1d(test["white"])[output])
        indep = np.atleast_2d(test["independent"])[output]
        zeta = np.atleast_2d(test["independence_zeta"])[output]
        z_thr = np.atleast_2d(test["independence_threshold"])[output]
        q, q_thr = (np.atleast_1d(test[k])[output] for k in ("whiteness_Q", "whiteness_threshold"))
        found["residuals_independent"], found["residuals_white"] = bool(np.all(indep)), white
        worst = int(np.argmax(zeta / z_thr))
        if np.all(indep):
            msgs.append(
                f"residuals independent of the input (zeta = {zeta[worst]:.3g} <= "
                f"{z_thr[worst]:.3g})"
            )
        else:
            msgs.append(
                f"residuals correlated with the input (zeta = {zeta[worst]:.3g} > "
                f"{z_thr[worst]:.3g}): the model misses part of the input's effect - try "
                "another order or input delay (nk)"
            )
        msgs.append(
            f"residuals white (Q = {q:.3g} <= {q_thr:.3g})"
            if white
            else f"residuals not white (Q = {q:.3g} > {q_thr:.3g}): colored noise or "
            "dynamics the model misses"
        )
    if "heldout_fit" in found and "residuals_independent" in found:
        ok = found["heldout_fit"] >= MIN_HELDOUT_FIT and found["residuals_independent"]
        found["adequate"] = bool(ok)
        if not found["heldout_fit"] >= MIN_HELDOUT_FIT:
            msgs.insert(0, "the model does NOT describe the record well")
        elif not neutral:
            msgs.insert(
                0,
                "the model describes the record"
                if ok
                else "the model fits held-out data, but its residuals still carry the input",
            )
    return msgs, found


#: why a model has no eigenvalue statistics, by ``info["method"]``
_NO_EIGENVALUES = {
    "least-squares": "least squares has no eigenvalue structure to judge",
    "output-error": "output error has no eigenvalue structure to judge",
    "subspace": "subspace identification has no eigenvalue structure to judge",
    "clpc-steady-state": "an average of CLPC windows: each window's statistics are in the trace",
}


def fit_verdict(model: Any, output: int = 0) -> Verdict:
    """The verdict of a fit (:meth:`clpc.LPC.fit`, :meth:`clpc.ARX.fit`) for one output.

    Parameters
    ----------
    model : LinearModel
        A fitted model; its ``info`` holds the solve's statistics and the assessment when
        the estimator stored them (without them the verdict says so).
    output : int
        Output index whose equation is judged (default 0).

    Returns
    -------
    Verdict
    """
    info = model.info
    ident = identifiability(model, output)
    lead = ident.messages(model.structure)
    words, found = evidence(info, output, neutral=bool(lead))
    found |= {
        "identifiable": ident.identifiable,
        "excitation_order": ident.excitation_order,
        "needed_order": ident.needed_order,
    }
    stable, kind, said = _stability(model, output)
    if "n_null" not in info:  # e.g. least squares, or a CLPC steady-state model
        what = "no eigenvalue statistics" if words else "no fit statistics"
        why = _NO_EIGENVALUES.get(str(info.get("method")), "a loaded or hand-built model")
        notes = (*lead, *words, f"{what} ({why})", f"the model is {said}")
        return Verdict(
            0, True, False, stable, model.structure.nb + 1, notes, stability=kind, **found
        )
    n_null = int(np.atleast_1d(info["n_null"])[output])
    n_input = int(np.atleast_1d(info["n_input_relations"])[output])
    determined = bool(np.atleast_1d(info["determined"])[output])
    sep = float(np.atleast_1d(info["separation"])[output])
    order = model.structure.nb + 1
    msgs = []
    if n_input:
        msgs.append(
            f"input is not persistently exciting of order {order}: it satisfies {n_input} "
            "linear relation(s) by itself (e.g. a smooth or ramp-like input); the input part "
            "of the model is the minimum-norm choice and may not describe other inputs"
        )
    cancelled = int(info.get("cancelled", 0))
    if cancelled:
        fitted = info.get("fitted_structure", {})
        na, nb = fitted.get("na"), fitted.get("nb")
        msgs.append(
            f"order larger than the data support: {cancelled} pole/zero factor(s) common to "
            f"A and B (closer than 0.02) were cancelled; fitted na={na}, nb={nb}, kept "
            f"na={model.structure.na}, nb={model.structure.nb}"
        )
    elif n_null - n_input > 1:
        msgs.append(
            f"{n_null - n_input} output relations are equally small: the order may be larger "
            "than the system's (common pole-zero factors); consider a lower order"
        )
    if determined and lead:
        msgs.append(
            f"one eigenvector stands out (eigenvalue separation {sep:.2g}), yet the record "
            "leaves the model undetermined (above)"
        )
    elif determined:
        but = " - identifiability only, not a good fit" if found.get("adequate") is False else ""
        msgs.append(f"the data determine the parameters (eigenvalue separation {sep:.2g}){but}")
    elif not n_input and n_null == 1:
        msgs.append(
            f"the parameters are poorly determined (smallest eigenvalue {sep:.2g} of the next):"
            " the data hardly prefer this model to others"
        )
    msgs.append(f"the model is {said}")
    return Verdict(
        n_null,
        n_input == 0,
        determined,
        stable,
        order,
        (*lead, *words, *msgs),
        stability=kind,
        **found,
    )


def _stability(model: Any, output: int) -> tuple[bool, str, str]:
    """Strictly stable; the pole class; its words (``"integrating (pole at z = 1)"``)."""
    try:
        poles = model.poles(output)
    except ValueError:
        return False, "unstable", "NOT stable (no poles)"
    kind = pole_class(poles)
    return bool(np.all(np.abs(poles) < 1.0)), kind, pole_words(kind)
