"""The cost study's start speed: where each case's sweep starts (docs/costs.md).

Each case's speed-free optimum is warm-started from a walk solved cold at a *start speed*
(:mod:`gaitopt.study.cost_study`). One number does not suit every model: the five-link
biped's optima lie at 3-44 m/min and start well from the paper's 12 m/min, while the
seven-link model with feet walks best at about 75 m/min under the paper's cost, and from
12 m/min its metabolic speed-free optimum stops at IPOPT's iteration limit (measured
2026-12-02, docs/feet.md).

So by default (``start_speed="auto"``) the study solves each model's paper case first, from
:data:`~gaitopt.study.plan.START_SPEED` (12 m/min), and starts the model's other cases at the
speed ``v_0`` of that case's speed-free optimum (the one its sweep reached), rounded to the
nearest multiple of :data:`AUTO_START_STEP_M_MIN` (3 m/min, the step of the paper's speed grid)::

    v_0 = max(dv, min(v_max, dv * round(v_paper / dv)))      dv = 3 m/min

clamped to ``[dv, v_max]`` (``v_max`` the upper speed bound of the solves, 90 m/min by default).
The five-link biped's paper optimum (11.1 m/min on 8 + 5 knots) gives 12 m/min, the start its
study always had; the seven-link model's (73.5-74.8 m/min) gives 75 m/min, the start measured
to work. The rounding makes the start a round number that a rerun reproduces from the kept
paper sweep, so an interrupted study resumes into the same case folders. When the paper case's
speed-free point failed, the other cases start at 12 m/min and the settings say why.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

from gaitopt.study.plan import START_SPEED
from gaitopt.study.summary import SummaryRow, rows_of

#: ``start_speed`` value (and ``--start-speed`` word) of the automatic start.
AUTO_START: Final = "auto"
#: The automatic start is the paper optimum's speed rounded to a multiple of this (m/min):
#: the step of the paper's speed grid.
AUTO_START_STEP_M_MIN = 3.0


@dataclass(frozen=True)
class StartChoice:
    """The start speed of one model's cases: ``speed`` (m/s), ``rule`` (``auto`` or
    ``given``), the paper case's speed-free optimum it was taken from (``paper_optimum``,
    m/s; None if given or failed) and ``reason`` in words."""

    speed: float
    rule: str
    reason: str
    paper_optimum: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain data for ``cost_study.json`` (speeds in m/min)."""
        return {"speed_m_min": round(self.speed * 60.0, 6), "rule": self.rule,
                "paper_optimum_m_min": (None if self.paper_optimum is None
                                        else self.paper_optimum * 60.0),
                "reason": self.reason}


def given_start(speed: float) -> StartChoice:
    """The start speed (m/s) the user gave."""
    return StartChoice(speed=speed, rule="given", reason=f"given: {speed * 60.0:g} m/min")


def auto_start_speed(paper_rows: Sequence[SummaryRow], variant: str,
                     max_speed: float) -> StartChoice:
    """The automatic start speed from the paper case's sweep (its ``summary.csv`` rows): the
    speed-free optimum of ``variant`` rounded to :data:`AUTO_START_STEP_M_MIN` and clamped
    to ``[AUTO_START_STEP_M_MIN, max_speed]`` (``max_speed`` in m/s); :data:`START_SPEED` when
    that point is missing or failed."""
    free = rows_of(paper_rows, variant, speed_mode="free", success=None)
    if not free or not free[0].success or not free[0].speed_m_s > 0.0:
        why = free[0].status if free else "not solved"
        return StartChoice(speed=START_SPEED, rule=AUTO_START,
                           reason=f"the paper case's speed-free optimum is missing ({why}): "
                                  f"{START_SPEED * 60.0:g} m/min")
    v, dv = free[0].speed_m_s, AUTO_START_STEP_M_MIN
    speed = min(max_speed, max(1, round(v * 60.0 / dv)) * dv / 60.0)
    return StartChoice(speed=speed, rule=AUTO_START, paper_optimum=v,
                       reason=f"the paper case's speed-free optimum, {v * 60.0:.2f} m/min, "
                              f"rounded to {dv:g} m/min: "
                              f"{speed * 60.0:g} m/min")
