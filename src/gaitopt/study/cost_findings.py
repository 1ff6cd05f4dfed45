"""The cost study's findings: which cost puts a model's optimum where people walk.

Input: the rows of a cost study (:class:`gaitopt.study.cost_table.CostRow`, one speed-free
optimum per model and case). Each finding is checked per model and gets a verdict, ``True``
(holds), ``False`` (does not hold) or ``None`` (the study cannot tell: a case missing or
failed), with the numbers behind it, keyed ``<quantity>.<case>`` (e.g. ``speed_m_min.paper``).
The ids (:data:`COST_FINDING_IDS`, listed in docs/costs.md) are stable; the claims are prose.

1. ``costs.time_free_slow``: the costs without a term in the step time (paper, work) put the
   optimum far below people's speed: below half of it (:data:`SLOW_LIMIT_M_MIN`).
2. ``costs.resting_power_sets_speed``: the metabolic optimum's speed grows with the resting
   power: strictly increasing over at least three resting powers.
3. ``costs.human_speed``: at a human resting power (:data:`HUMAN_RESTING_POWER`) the metabolic
   optimum walks at people's speed: within :data:`HUMAN_TOLERANCE` of 80 m/min.
4. ``costs.human_step_length``: and with people's step: within :data:`HUMAN_TOLERANCE` of
   0.75 m.
5. ``costs.nearest_human``: some cost with physiological settings (paper, work, metabolic at a
   human resting power) puts the optimum where people walk: speed and step both within
   :data:`HUMAN_TOLERANCE`. The evidence names the nearest case by the distance of
   :func:`gaitopt.study.cost_table.human_distance`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from gaitopt.study.cost_study import HUMAN_RESTING_POWER
from gaitopt.study.cost_table import CostRow
from gaitopt.study.findings import (
    HUMAN_OPTIMAL_SPEED_M_MIN,
    HUMAN_STEP_LENGTH,
    SLOW_LIMIT_M_MIN,
    VERDICT_WORDS,
    Finding,
    Findings,
)

#: Relative tolerance of "where people walk" (speed and step length).
HUMAN_TOLERANCE = 0.25
MIN_RESTING_POWERS = 3

COST_FINDING_IDS: tuple[str, ...] = (
    "costs.time_free_slow", "costs.resting_power_sets_speed", "costs.human_speed",
    "costs.human_step_length", "costs.nearest_human")


def _human_rest(row: CostRow) -> bool:
    lo, hi = HUMAN_RESTING_POWER
    return row.cost == "metabolic" and lo <= row.resting_power <= hi


def physiological(row: CostRow) -> bool:
    """Whether a case has people's settings: the paper's or the work cost, or the metabolic
    cost at a human resting power (:data:`HUMAN_RESTING_POWER`)."""
    return row.cost != "metabolic" or _human_rest(row)


def _near(value: float, target: float) -> bool:
    return abs(value / target - 1.0) <= HUMAN_TOLERANCE


def _time_free(rows: Sequence[CostRow]) -> Finding:
    claim = ("The costs without a term in the step time (paper, work) put the optimum far "
             f"below people's speed (under {SLOW_LIMIT_M_MIN:g} m/min).")
    cases = [r for r in rows if r.cost in ("paper", "work")]
    if not cases or not all(r.success for r in cases):
        return Finding("costs.time_free_slow", claim, None,
                       "the paper or work optimum is missing or failed")
    numbers = {f"speed_m_min.{r.case}": r.speed_m_min for r in cases}
    numbers |= {f"step_length.{r.case}": r.step_length for r in cases}
    evidence = "; ".join(f"{r.case}: {r.speed_m_min:.1f} m/min, step {r.step_length:.3f} m"
                         for r in cases)
    return Finding("costs.time_free_slow", claim,
                   all(r.speed_m_min < SLOW_LIMIT_M_MIN for r in cases),
                   f"{evidence} (holds if every one < {SLOW_LIMIT_M_MIN:g} m/min)", numbers)


def _resting_power(rows: Sequence[CostRow]) -> Finding:
    claim = "The metabolic optimum walks faster the larger the resting power."
    metabolic = sorted((r for r in rows if r.cost == "metabolic"),
                       key=lambda r: r.resting_power)
    solved = [r for r in metabolic if r.success]
    numbers = {f"speed_m_min.{r.case}": r.speed_m_min for r in solved}
    if len(solved) < MIN_RESTING_POWERS:
        return Finding("costs.resting_power_sets_speed", claim, None,
                       f"{len(solved)} resting powers solved; need {MIN_RESTING_POWERS}",
                       numbers)
    speeds = [r.speed_m_min for r in solved]
    increasing = all(b > a for a, b in zip(speeds, speeds[1:], strict=False))
    evidence = ", ".join(f"{r.resting_power:g} W/kg: {r.speed_m_min:.1f} m/min" for r in solved)
    failed = len(metabolic) - len(solved)
    if failed:
        evidence += f" ({failed} failed)"
    return Finding("costs.resting_power_sets_speed", claim, increasing,
                   evidence + " (holds if strictly increasing)", numbers)


def _human_metabolic(rows: Sequence[CostRow], *, quantity: str) -> Finding:
    lo, hi = HUMAN_RESTING_POWER
    if quantity == "speed":
        fid, target, unit, fmt = "costs.human_speed", HUMAN_OPTIMAL_SPEED_M_MIN, "m/min", ".1f"
        claim = (f"At a human resting power ({lo:g}-{hi:g} W/kg) the metabolic optimum walks "
                 f"at people's speed (about {target:g} m/min).")
    else:
        fid, target, unit, fmt = "costs.human_step_length", HUMAN_STEP_LENGTH, "m", ".3f"
        claim = (f"At a human resting power ({lo:g}-{hi:g} W/kg) the metabolic optimum takes "
                 f"people's steps (about {target:g} m).")
    cases = [r for r in rows if _human_rest(r)]
    if not cases or not any(r.success for r in cases):
        return Finding(fid, claim, None, f"no metabolic optimum solved at {lo:g}-{hi:g} W/kg")
    column = "speed_m_min" if quantity == "speed" else "step_length"
    solved = [r for r in cases if r.success]
    numbers = {f"{column}.{r.case}": float(getattr(r, column)) for r in solved}
    evidence = "; ".join(f"{r.resting_power:g} W/kg: {format(getattr(r, column), fmt)} {unit} "
                         f"({getattr(r, column) / target:.0%} of people's)" for r in solved)
    holds = all(_near(float(getattr(r, column)), target) for r in solved)
    return Finding(fid, claim, holds,
                   f"{evidence} (holds if within {HUMAN_TOLERANCE:.0%} of {target:g} {unit})",
                   numbers)


def _nearest(rows: Sequence[CostRow]) -> Finding:
    claim = ("Some cost with physiological settings (paper, work, metabolic at a human resting "
             "power) puts the optimum where people walk.")
    candidates = [r for r in rows if r.success and physiological(r)]
    solved = [r for r in rows if r.success]
    if not candidates:
        return Finding("costs.nearest_human", claim, None, "no such case solved")
    numbers = {f"human_distance.{r.case}": r.human_distance for r in solved}
    best = min(candidates, key=lambda r: r.human_distance)
    overall = min(solved, key=lambda r: r.human_distance)
    holds = any(_near(r.speed_m_min, HUMAN_OPTIMAL_SPEED_M_MIN)
                and _near(r.step_length, HUMAN_STEP_LENGTH) for r in candidates)
    evidence = (f"nearest: {best.case} at {best.speed_m_min:.1f} m/min, step "
                f"{best.step_length:.3f} m (distance {best.human_distance:.2f}; 0 is people's "
                f"{HUMAN_OPTIMAL_SPEED_M_MIN:g} m/min and {HUMAN_STEP_LENGTH:g} m, 1.41 "
                "standing still)")
    if overall is not best:
        evidence += (f"; of all cases {overall.case}: {overall.speed_m_min:.1f} m/min, step "
                     f"{overall.step_length:.3f} m (distance {overall.human_distance:.2f})")
    return Finding("costs.nearest_human", claim, holds,
                   evidence + f" (holds if speed and step are within {HUMAN_TOLERANCE:.0%})",
                   numbers)


def assess_cost_findings(rows: Sequence[CostRow]) -> Mapping[str, Findings]:
    """The findings of each model (in the rows' order of models), in the order of
    :data:`COST_FINDING_IDS`; ``result["five-link"]["costs.human_speed"]``."""
    out: dict[str, Findings] = {}
    for model in dict.fromkeys(r.model for r in rows):
        mine = [r for r in rows if r.model == model]
        out[model] = Findings(optima={}, items=(
            _time_free(mine), _resting_power(mine), _human_metabolic(mine, quantity="speed"),
            _human_metabolic(mine, quantity="step"), _nearest(mine)))
    return out


def ranked(rows: Sequence[CostRow]) -> list[CostRow]:
    """The solved rows, nearest to human walking first (failed rows last)."""
    return sorted(rows, key=lambda r: (not r.success,
                                       r.human_distance if r.success else math.inf))


def cost_findings_text(findings: Mapping[str, Findings]) -> str:
    """Plain text: per model, one paragraph per finding (verdict, claim, id; evidence)."""

    lines = []
    for model, items in findings.items():
        lines.append(f"model {model}:")
        for item in items.items:
            lines.append(f"[{VERDICT_WORDS[item.holds]}] {item.claim}  ({item.id})\n"
                         f"    {item.evidence}")
    return "\n".join(lines)
