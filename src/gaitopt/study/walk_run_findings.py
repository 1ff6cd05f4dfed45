"""The walk-run study's findings, per (model, cost), stated with numbers (docs/running.md).

Each is a :class:`gaitopt.study.findings.Finding` with a stable id; the verdict is ``True``,
``False`` or ``None`` (the study cannot tell: fewer than two speeds where both converged):

1. ``walk.low_speed``: walking is the cheapest gait at low speed (Srinivasan and Ruina,
   Nature 2006, qualitative): at the lowest speed where both the walk and the run converged,
   the cheapest walking branch costs less than the run.
2. ``run.high_speed``: running is the cheapest gait at high speed: at the highest such speed
   the run costs less than every walking branch.
3. ``transition.people``: the transition lies near people's, about 2 m/s at a Froude number
   ``v^2 / (g l)`` of 0.5: the interpolated crossing's Froude number (on the model's leg
   length) lies within :data:`~gaitopt.study.transition.HUMAN_FROUDE_BAND`.
4. ``run.flight``: where the run is the cheapest gait (and a walk converged too), it is a
   run of its own, not a walk
   with the shortest flight allowed: its stance share lies below the upper bound of
   :data:`~gaitopt.gait.options.model_defaults.RUN_STANCE_BOUNDS` (0.95) by more than
   :data:`AT_BOUND`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from gaitopt.gait.options.model_defaults import RUN_STANCE_BOUNDS
from gaitopt.study.findings import Finding, Findings
from gaitopt.study.transition import HUMAN_FROUDE_BAND, HUMAN_TRANSITION_FROUDE
from gaitopt.study.walk_run import TransitionRow, WalkRunRow

FINDING_IDS = ("walk.low_speed", "run.high_speed", "transition.people", "run.flight")
#: A run's stance share within this of its upper bound counts as on the bound.
AT_BOUND = 0.005


def _at(rows: Sequence[WalkRunRow], model: str, cost: str, speed_m_min: float,
        kind: str) -> WalkRunRow | None:
    pool = [r for r in rows if r.model == model and r.cost == cost and r.kind == kind
            and r.success and abs(r.speed_m_min - speed_m_min) < 1e-6]
    return min(pool, key=lambda r: r.cost_value) if pool else None


def _end(rows: Sequence[WalkRunRow], t: TransitionRow, *, low: bool) -> Finding:
    fid, claim = (("walk.low_speed", "walking is the cheapest gait at low speed") if low else
                  ("run.high_speed", "running is the cheapest gait at high speed"))
    speeds = t.transition.speeds
    if not speeds:
        return Finding(fid, claim, None, "no speed where both the walk and the run converged")
    v = (speeds[0] if low else speeds[-1]) * 60.0
    walk = _at(rows, t.model, t.cost, v, "walk")
    run = _at(rows, t.model, t.cost, v, "run")
    assert walk is not None and run is not None  # both converged at every compared speed
    holds = walk.cost_value < run.cost_value if low else run.cost_value < walk.cost_value
    cheaper, dearer = (walk, run) if walk.cost_value < run.cost_value else (run, walk)
    ratio = dearer.cost_value / cheaper.cost_value - 1.0
    where = "lowest" if low else "highest"
    evidence = (f"at {v:g} m/min (the {where} speed where both converged; Froude "
                f"{walk.froude:.2f}) the {cheaper.branch} costs {cheaper.cost_value:.4g}, the "
                f"{dearer.branch} {100 * ratio:.0f} % more ({dearer.cost_value:.4g})")
    return Finding(fid, claim, holds, evidence,
                   {"speed_m_min": v, "walk": walk.cost_value, "run": run.cost_value})


def _people(t: TransitionRow) -> Finding:
    lo, hi = HUMAN_FROUDE_BAND
    claim = (f"the walk-run transition lies near people's (about 2 m/s, Froude "
             f"{HUMAN_TRANSITION_FROUDE:g})")
    tr = t.transition
    if tr.kind != "crossing":
        text = {"walk": "the walk is cheaper at every speed where both converged: no "
                        "transition within the grid",
                "run": "the run is cheaper or equal at every speed where both converged: the "
                       "transition, if any, lies at or below the lowest",
                "run-to-walk": "the run is cheaper at low speed and the walk at high speed: "
                               "no walk-to-run transition",
                "none": "fewer than two speeds where both converged"}[tr.kind]
        return Finding("transition.people", claim, None if tr.kind == "none" else False, text)
    fr = t.froude
    evidence = (f"crossing at {tr.speed * 60:.1f} m/min ({tr.speed:.2f} m/s) between "
                f"{tr.bracket[0] * 60:g} and {tr.bracket[1] * 60:g} m/min, grid error "
                f"{tr.interval[0] * 60:.1f}-{tr.interval[1] * 60:.1f} m/min; Froude "
                f"{fr:.2f} on {t.leg_length_m:.3f} m legs (people {HUMAN_TRANSITION_FROUDE:g}; "
                f"near: {lo:g}-{hi:g})")
    return Finding("transition.people", claim, lo <= fr <= hi, evidence,
                   {"speed_m_min": tr.speed * 60, "froude": fr})


def _flight(rows: Sequence[WalkRunRow], t: TransitionRow) -> Finding:
    claim = ("where running is cheapest, the optimal run has a flight of its own (its stance "
             f"share below the bound {RUN_STANCE_BOUNDS[1]:g})")
    both = {round(v * 60.0, 6) for v in t.transition.speeds}
    runs = sorted((r for r in rows if r.model == t.model and r.cost == t.cost
                   and r.kind == "run" and r.cheapest and round(r.speed_m_min, 6) in both),
                  key=lambda r: r.speed_m_min)
    if not runs:
        return Finding("run.flight", claim, None, "the run is the cheapest gait at no speed "
                                                  "where a walk converged too")
    on = [r for r in runs if r.first_phase_share >= RUN_STANCE_BOUNDS[1] - AT_BOUND]
    shares = ", ".join(f"{r.first_phase_share:.2f} at {r.speed_m_min:g}" for r in runs)
    evidence = (f"stance share of the cheapest run: {shares} m/min"
                + (f"; on the bound at {', '.join(f'{r.speed_m_min:g}' for r in on)} m/min: "
                   "a walk without double support but for the shortest flight allowed"
                   if on else ""))
    return Finding("run.flight", claim, not on, evidence,
                   {f"share.{r.speed_m_min:g}": r.first_phase_share for r in runs})


def assess_walk_run(rows: Sequence[WalkRunRow],
                    transitions: Sequence[TransitionRow]) -> Mapping[str, Findings]:
    """The findings of each (model, cost), keyed ``"<model> / <cost>"``."""
    out = {}
    for t in transitions:
        items = (_end(rows, t, low=True), _end(rows, t, low=False), _people(t),
                 _flight(rows, t))
        out[f"{t.model} / {t.cost}"] = Findings(optima={}, items=items)
    return out
