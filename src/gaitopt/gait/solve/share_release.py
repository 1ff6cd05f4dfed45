"""Phase shares released last: the fixed-share optimum first, then the problem with them free.

A contact sequence fixes each phase's share of the step time. Where those shares are the
sequence's own guesses (a built-in sequence of more than two phases: the heel-toe walk's
0.5 f, 0.35 f, 1 - f and 0.15 f of the step, from no measurement), a solve that leaves
``GaitOptions.free_phase_fractions`` to the sequence (``None``, the default;
:func:`releases_shares`) runs in two parts:

1. the problem with the shares fixed, refined to ``GaitOptions.accuracy`` (the solve as
   before);
2. the same problem with every share free (``free_phase_fractions=True``: each within
   ``[s / 2, min(2 s, 0.95)]`` of its share ``s``), on the first part's final grid, solved
   from its own stages (the naive guess, the shares freed on the coarse grid: stage ``phase
   fractions free``), or, where that fails or its check grid does not converge, started
   from the first part's optimum (values only, the NLPs differ by the share parameters;
   stages ``shares free: from the fixed shares: ...``); then refined to the accuracy with
   each phase's knots following the shares solved (:mod:`gaitopt.gait.solve.refinement`).
   Its stages are named ``shares free: ...``.

The answer is the released optimum when it converged, is within the accuracy whenever the
fixed one is, costs less (by more than :data:`SAME_COST`, relative) and passes the caller's
plausibility check (``plausible``: e.g. the swing checks of ``gaitopt verify``, which live
above this layer); otherwise the fixed-share optimum, and the gait file says which and why
(``solver.phase_shares``, :func:`decision`).

Why the free problem from its own stages, not from the fixed-share optimum (measured on the
seven-link, 2026-12-03, docs/feet.md "Free phase shares by default"): both reach the same
optima at 12, 30 and 60 m/min (3605, 2035.1, 1655.8), but from the fixed-share optimum IPOPT
crawls where the shares move far: at 80 m/min it stopped at J 1867.4, a point whose check grid
ran to the iteration limit, where the free problem's own stages reach 1804.3 and converge on
three grids; with the speed free, 1787.2 at 62.2 m/min (check grid failed) against 1707.8 at
58.4 m/min. The fixed-share optimum is still solved first: it is the fallback, and the
answer wherever the release is not kept.

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
    after the fixed-share solve: ``free_phase_fractions`` left to the sequence (``None``), no
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


def release_shares(fixed: StagedRun, solve_free: Callable[[GaitOptions, StagedRun], StagedRun],
                   plausible: Plausibility | None = None) -> StagedRun:
    """The released solve of ``fixed`` (module docstring) and the decision between them.

    Args:
        fixed: the converged fixed-share solve, refined.
        solve_free: solves ``options`` (the free-share problem on ``fixed``'s final grid;
            from its own stages, or from ``fixed``'s optimum where those fail) and refines it
            to the accuracy; its stage names carry :data:`PREFIX`.
        plausible: the plausibility check of the released optimum (None: none).

    Returns:
        The run kept (:func:`decision`), with every stage of both solves, their wall times
        added, and the decision in ``share_release``.
    """
    options = fixed.options.replace(free_phase_fractions=True, phase_shares=None,
                                    max_iter=min(fixed.options.max_iter, RELEASE_MAX_ITER))
    free = solve_free(options, fixed)
    chosen = decision(fixed, free, plausible)
    kept = free if chosen["released"] else fixed
    return dataclasses.replace(kept, stages=fixed.stages + free.stages,
                               wall_time_s=fixed.wall_time_s + free.wall_time_s,
                               share_release=chosen)

