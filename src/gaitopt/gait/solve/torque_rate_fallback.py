"""An optimum that ``verify`` rejects, solved again with a torque-rate term.

Some optima of a cost without a torque-rate term are not plausible motions. The seven-link
run at 400 m/min holds its swing ankle on its plantarflexion limit, touching it three times
with arcs of about 3 deg between, and ``swing.reversals`` counts 6 turns (docs/running.md,
"The swing of a run"). A torque-rate term of ``tau`` = 0.02 s
(:attr:`gaitopt.gait.options.gait_options.GaitOptions.torque_rate_time`: ``tau^2 int sum
u'^2 dt`` in the cost's numerator, which prices torque changes faster than about ``1 / (2
pi tau)`` = 8 Hz) removes those arcs for +2.6 % of the cost there.

Where a solve is handed a plausibility check (``gaitopt solve`` hands it ``verify``:
:func:`gaitopt.analysis.plausible.verified`), its cost has no torque-rate term and its
converged answer fails the check, the problem is solved again with each ``tau`` of
:data:`FALLBACK_TORQUE_RATE_TIMES` in turn (from the answer before: values and
multipliers on the same grid, only the cost changes), refined to the accuracy, until one
converges with an estimate and passes the check: that answer replaces the first. Where none
does, the first answer stands (and is reported as failing verify).
The gait file says which: its ``options.torque_rate_time`` and ``cost`` text, and
``solver.torque_rate_fallback`` (:func:`fallback_record`; docs/outputs.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from gaitopt.gait.solve.accuracy import accuracy_record
from gaitopt.gait.solve.share_release import Plausibility
from gaitopt.gait.solve.staged_run import StagedRun

#: The ``tau`` (s) of the torque-rate terms a rejected answer is solved again with, in
#: order, each from the answer before it, until one passes: the seven-link run at 400 m/min
#: passes with 0.02 s (+2.6 % of the cost), its 1.4 m step at 240 m/min with 0.03 s (+5.9 %;
#: 0.02 s leaves its ankle 4 turns), both with 0.05 s (+6.8 %, +10.2 %; docs/running.md).
FALLBACK_TORQUE_RATE_TIMES = (0.02, 0.03, 0.05)

#: Before the name of each stage of a smoothed solve.
PREFIX = "smoothed: "


def rejection(run: StagedRun, judged: Plausibility | None) -> str | None:
    """Why ``run``'s converged answer is rejected by ``judged`` and may be smoothed (one
    line, e.g. ``verify fails swing.reversals (6 > 3 turns)``), or None: no check, a failed
    solve, an answer outside its accuracy target (reported as such, exit status 3: the
    check rejects it for that, which a torque-rate term does not mend, and refining a
    smoothed answer from its finest grid went past the 400 knots a phase may have), a cost
    that already has a torque-rate term, or a plausible answer."""
    if judged is None or not run.success or run.options.torque_rate_time > 0.0 \
            or not within_accuracy(run):
        return None
    return judged(run)


def within_accuracy(run: StagedRun) -> bool:
    """False where ``run`` was refined toward an accuracy target and did not reach it."""
    return (run.accuracy_extra or {}).get("within_target") is not False


def verdict_on(run: StagedRun, judged: Plausibility) -> str | None:
    """None where a smoothed ``run`` may be kept: converged, with a cost error estimate, and
    passed by ``judged``; else why not (one line)."""
    if not run.success:
        return "its solve failed"
    if accuracy_record(run).get("cost_error") is None:
        return "its check grid gave no error estimate"
    if not within_accuracy(run):
        return "not within the accuracy target"
    return judged(run)


def fallback_record(why: str, first: StagedRun,
                    tries: list[tuple[float, float | None, str | None]]) -> dict[str, Any]:
    """The gait file's ``solver.torque_rate_fallback``: ``why`` the first answer was
    rejected, its cost (``first_cost``, without the term, in the cost's units), ``kept``
    (whether a smoothed answer is the gait), ``torque_rate_time`` (s: the kept answer's
    ``tau``, None where none was kept) and ``tries``: each ``(tau, cost, verdict)`` tried, in
    order, as ``torque_rate_time``, ``cost`` (the term included; None where its solve
    failed) and ``verdict`` (None where it passed, else why not: :func:`verdict_on`)."""
    kept = [tau for tau, _, verdict in tries if verdict is None]
    return {"why": why, "first_cost": float(first.result.objective), "kept": bool(kept),
            "torque_rate_time": kept[0] if kept else None,
            "tries": [{"torque_rate_time": tau, "cost": cost, "verdict": verdict}
                      for tau, cost, verdict in tries]}


def fallback_line(record: Mapping[str, Any]) -> str:
    """One line of a :func:`fallback_record` for the command line: why the first answer
    was rejected and what the smoothed solves gave."""
    head = f"torque rate: {record['why']} (J {record['first_cost']:.6g}); solved again with"
    tried = ", ".join(
        f"tau {t['torque_rate_time']:g} s: " + (
            "failed" if t["cost"] is None else
            f"J {t['cost']:.6g} ({100.0 * (t['cost'] / record['first_cost'] - 1.0):+.1f} %)")
        + ("" if t["verdict"] is None else f", {t['verdict']}")
        for t in record["tries"])
    tail = (f"this answer (tau {record['torque_rate_time']:g} s, the term in its cost)"
            if record["kept"] else "the first answer stands")
    return f"{head} a torque-rate term: {tried}; {tail}"
