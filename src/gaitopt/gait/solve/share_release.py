"""Phase shares released: the problem with the sequence's guessed shares free, kept where it
is lower, converged and plausible; the fixed-share optimum otherwise.

A contact sequence fixes each phase's share of the step time. Where those shares are the
sequence's own guesses (a built-in sequence of more than two phases: the heel-toe walk's
0.5 f, 0.35 f, 1 - f and 0.15 f of the step, from no measurement), a solve that leaves
``GaitOptions.free_phase_fractions`` to the sequence (``None``, the default;
:func:`releases_shares`) and can judge the released gait (``plausible``) runs:

1. the problem with every share free (:func:`free_options`: ``free_phase_fractions=True``,
   each within ``[s / 2, min(2 s, 0.95)]`` of its share ``s``), from its own stages: the
   naive guess, the cold stages with the shares held at the sequence's, then stage
   :data:`FREEING_STAGE` frees them on the coarse grid; then the target and check grids, and
   refined to ``GaitOptions.accuracy`` with each phase's knots following the shares solved
   (:mod:`gaitopt.gait.solve.refinement`). Its stages are named ``shares free: ...``.
2. It is the answer (:func:`release_first`) where it converged within the accuracy, freeing
   the shares lowered the coarse cost (the stage before :data:`FREEING_STAGE` is the
   fixed-share problem's coarse optimum: same grid, same speed) and it passes the caller's
   plausibility check (``plausible``: ``gaitopt verify``'s checks, which live above this
   layer). The fixed-share problem is then not solved past the coarse grid.
3. Otherwise the fixed-share problem is solved and refined as without a release, and
   :func:`decision` chooses between the two: the released optimum where it converged, is
   within the accuracy whenever the fixed one is, costs less (by more than
   :data:`SAME_COST`, relative) and is plausible; else the fixed one. Where step 1 failed or
   left no estimate, the free problem is first started from the fixed-share optimum (values
   only, the NLPs differ by the share parameters; stages ``shares free: from the fixed
   shares: ...``) on its final grid.

The gait file says which and why (``solver.phase_shares``: :func:`decision`'s record, or
:func:`release_first`'s, which has ``fixed_knots``).

Why the free problem first (measured on the seven-link, 2026-12-03, docs/feet.md "Free phase
shares by default"): it reaches the optima that the start from the fixed-share optimum
reached (3605 at 12 m/min, 2035.1 at 30, 1655.8 at 60) and lower ones where that start
crawled (1804.3 against 1867.4 at 80 m/min; with the speed free 1707.8 at 58.4 m/min against
1787.2); and where it is kept the fixed-share target and check grids are not solved at all
(the default command at 60 m/min: 20.5 s instead of 45.5 s).

A two-phase walk's single-support share is the problem's own datum (the paper's 0.85, the
user's ``single_support_fraction``): it stays fixed, and so do shares the caller gave (a
contact sequence, fraction bounds, a stride).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

from gaitopt.gait.formulations.select import contact_sequence, formulation_of
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.sequence.phase_fractions import free_phases
from gaitopt.gait.solve.staged_run import StagedRun
from gaitopt.robot.model import RobotModel

#: Put before the name of every stage of the released solve.
PREFIX = "shares free: "
#: The stage that frees the shares on the coarse grid (:data:`gaitopt.gait.solve.stages.RELEASES`).
FREEING_STAGE = "phase fractions free"
#: Put before the name of every stage of the released solve started from the fixed-share
#: optimum (where the free problem's own stages failed or left no estimate).
FROM_FIXED = PREFIX + "from the fixed shares: "
#: The released optimum is kept only when it costs less than the fixed-share one by more
#: than this (relative): within it the two are the same optimum, and the fixed shares (the
#: sequence's, as documented) are kept.
SAME_COST = 1e-6
#: IPOPT's iteration limit per stage of the released solve (or the caller's, if lower). The
#: release is an offer, not the answer: the fixed-share optimum stands. Its stages took 34-114
#: iterations where they converged (seven-link, 30 and 60 m/min), but at 80 m/min and with
#: the speed free the released check grid (36 + 26 knots) ran to the 1000-iteration limit
#: for over half an hour; with this limit such a release fails in minutes and the fixed
#: shares are kept, with the failure in ``solver.phase_shares``.
RELEASE_MAX_ITER = 300
#: IPOPT's wall-time limit (s) of each stage of the released solve: with the speed free the
#: released check grid's iterations slowed so that 300 of them ran for more than 10 minutes
#: (2026-12-03, load 2-4; the converged releases' stages took 4-63 s at a load of 8-13).
RELEASE_STAGE_SECONDS = 120.0

#: A plausibility check of a converged solve: None when plausible, else why not (a line).
Plausibility = Callable[[StagedRun], str | None]


def releases_shares(model: RobotModel, options: GaitOptions) -> bool:
    """Whether a solve with ``options`` (after
    :func:`~gaitopt.gait.options.model_defaults.options_for_model`) releases its phase shares
    (:func:`release_first`, :func:`release_shares`): ``free_phase_fractions`` left to the
    sequence (``None``), no
    share bounds given (``single_support_fraction_bounds``, a given contact sequence, a
    stride), a formulation that can free shares, and a built-in sequence whose step has more
    than two phases, none of them free already."""
    if (options.free_phase_fractions is not None or options.contact_sequence is not None
            or options.stride or options.single_support_fraction_bounds is not None
            or not formulation_of(options).traits.contact_sequences):
        return False
    seq = contact_sequence(model, options)
    return len(seq.phases) // seq.steps > 2 and not free_phases(seq)


def shares_of(run: StagedRun) -> list[float]:
    """Each phase's share of the step in ``run``'s result (duration over step time)."""
    durations = [float(ph.duration) for ph in run.result.phases]
    steps = contact_sequence(run.model, run.options).steps
    step = sum(durations) / steps
    return [d / step for d in durations]


def decision(fixed: StagedRun, free: StagedRun, plausible: Plausibility | None = None
             ) -> dict[str, Any]:
    """Which optimum a released solve keeps, as the gait file records it
    (``solver.phase_shares``): ``released`` (bool: the free-share optimum is the answer),
    ``fixed_cost`` and ``fixed_shares``, ``free_cost`` and ``free_shares`` (None where the
    released solve failed) and ``why`` (one line). ``fixed`` must have converged."""
    out: dict[str, Any] = {"released": False, "fixed_cost": float(fixed.result.objective),
                           "fixed_shares": shares_of(fixed), "free_cost": None,
                           "free_shares": None, "why": ""}
    if not free.success:
        failed = free.failed_stage
        where = f" (stage {failed.name}: {failed.status})" if failed is not None else ""
        return out | {"why": f"the free-share solve failed{where}: the fixed shares kept"}
    out |= {"free_cost": float(free.result.objective), "free_shares": shares_of(free)}
    fixed_within = (fixed.accuracy_extra or {}).get("within_target")
    free_within = (free.accuracy_extra or {}).get("within_target")
    change = out["free_cost"] / out["fixed_cost"] - 1.0
    if fixed_within is True and free_within is not True:
        return out | {"why": "the free-share optimum is not converged to the accuracy: the "
                             "fixed shares kept"}
    if change >= -SAME_COST:
        return out | {"why": f"the free shares cost no less ({100 * change:+.2f} %): the "
                             "fixed shares kept"}
    problem = plausible(free) if plausible is not None else None
    if problem is not None:
        return out | {"why": f"the free-share optimum ({100 * change:+.1f} %) is not "
                             f"plausible: {problem}; the fixed shares kept"}
    return out | {"released": True,
                  "why": f"the free shares cost {100 * -change:.1f} % less: released"}


def free_options(options: GaitOptions) -> GaitOptions:
    """The released problem of ``options``: every share free, on the same grid, within the
    release's iteration limit (:data:`RELEASE_MAX_ITER`)."""
    return options.replace(free_phase_fractions=True, phase_shares=None,
                           max_iter=min(options.max_iter, RELEASE_MAX_ITER))


def coarse_release(free: StagedRun) -> tuple[float, float, tuple[int, ...]] | None:
    """What freeing the shares did on the coarse grid of a free-share run from its own
    stages: ``(cost with the shares held at the sequence's, cost with them freed, knots)``,
    the objectives of the stage before :data:`FREEING_STAGE` (the fixed-share problem's
    coarse optimum: the stages before it hold the shares) and of that stage, on the same grid
    and at the same speed. Of several starts (``--multistart``), the one freed lowest. None
    where no such pair of stages converged."""
    stages = free.stages
    pairs = [(before.objective, stage.objective, tuple(stage.knots))
             for before, stage in zip(stages, stages[1:], strict=False)
             if stage.name.endswith(FREEING_STAGE) and stage.success and before.success]
    return min(pairs, key=lambda pair: pair[1]) if pairs else None


def release_first(free: StagedRun, model: RobotModel,
                  plausible: Plausibility | None = None) -> dict[str, Any] | None:
    """The decision (:func:`decision`'s record) that keeps ``free``, the free problem solved
    first from its own stages and refined, without solving the fixed-share problem past the
    coarse grid: where ``free`` converged within the accuracy, freeing the shares lowered the
    coarse cost by more than :data:`SAME_COST` (:func:`coarse_release`) and ``plausible``
    passes. Then ``fixed_cost`` is the fixed-share problem's coarse optimum, on
    ``fixed_knots`` (the key that marks such a record), ``fixed_shares`` the sequence's own,
    and ``coarse_free_cost`` the coarse cost with the shares freed. None otherwise: the
    fixed-share problem is then solved and :func:`decision` decides."""
    if not free.success or (free.accuracy_extra or {}).get("within_target") is not True:
        return None
    coarse = coarse_release(free)
    if coarse is None:
        return None
    held, freed, knots = coarse
    change = freed / held - 1.0
    if change >= -SAME_COST or (plausible is not None and plausible(free) is not None):
        return None
    sequence = contact_sequence(model, free.options.replace(free_phase_fractions=False,
                                                            phase_shares=None))
    grid = "+".join(map(str, knots))
    return {"released": True, "fixed_cost": held,
            "fixed_shares": [float(ph.fraction) for ph in sequence.phases],
            "fixed_knots": list(knots), "free_cost": float(free.result.objective),
            "free_shares": shares_of(free), "coarse_free_cost": freed,
            "why": f"the free shares cost {100 * -change:.1f} % less on the coarse grid "
                   f"({grid} knots): released (the fixed shares not solved further)"}


def release_shares(fixed: StagedRun, solve_free: Callable[[GaitOptions, StagedRun], StagedRun],
                   plausible: Plausibility | None = None, *,
                   first: StagedRun | None = None) -> StagedRun:
    """The released solve of ``fixed`` (module docstring) and the decision between them.

    Args:
        fixed: the converged fixed-share solve, refined.
        solve_free: solves ``options`` (the free-share problem on ``fixed``'s final grid;
            from its own stages, or from ``fixed``'s optimum where those fail) and refines it
            to the accuracy; its stage names carry :data:`PREFIX`.
        plausible: the plausibility check of the released optimum (None: none).
        first: the free problem's own run, solved before ``fixed`` (where
            :func:`release_first` did not keep it), which ``solve_free``'s run starts with:
            its stages are listed first, in the order they ran.

    Returns:
        The run kept (:func:`decision`), with every stage of both solves, their wall times
        added, and the decision in ``share_release``.
    """
    free = solve_free(free_options(fixed.options), fixed)
    chosen = decision(fixed, free, plausible)
    kept = free if chosen["released"] else fixed
    before = () if first is None else first.stages
    stages = before + fixed.stages + free.stages[len(before):]
    return dataclasses.replace(kept, stages=stages,
                               wall_time_s=fixed.wall_time_s + free.wall_time_s,
                               share_release=chosen)

