"""Internal: what a staged solve returns inside gaitopt, a record per stage and the run, and
the judgement of one stage's IPOPT result (converged or not, the best of several).

:class:`StagedRun` and :class:`StageRecord` are not results for users: the one public result
is :class:`~gaitopt.gait.record.file.Gait`, which :func:`gaitopt.gait.solve.record.gait_from_run`
makes of a run (its status, stages, solver statistics, error estimates, costates and, for a
failed solve, its diagnosis). They are not exported from ``gaitopt`` nor in the API reference
(docs/architecture.md, "One public result"); the command line, the study worker, the benches
and the tests use them.

A stage converges when IPOPT says so and, at its "acceptable" level (which CasADi reports as
success, with a constraint violation up to ``acceptable_constr_viol_tol``), only if the
constraint violation is at most :data:`ACCEPTABLE_VIOLATION`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.ocp import Guess, PhaseGuess, Result, WarmStart
from gaitopt.robot.model import RobotModel

#: Largest constraint violation (in the constraints' own units) of a solution that IPOPT
#: accepted at its "acceptable" level for it to count as converged: the tolerance to which
#: verify checks what the transcription imposes exactly.
ACCEPTABLE_VIOLATION = 1e-6

ProgressFn = Callable[["StageRecord"], None]


@dataclass(frozen=True)
class StageRecord:
    """Internal: what one stage did: its name, the grid, the outcome and the time it took (the
    gait keeps it as an entry of ``solver["stages"]``)."""

    name: str
    #: Knots per phase, in phase order (two for the walk, one per phase of a longer step).
    knots: tuple[int, ...]
    status: str
    success: bool
    iterations: int
    objective: float
    violation: float
    wall_time_s: float
    parameters: dict[str, float]
    #: Solves the target problem itself (no relaxation, nothing held): its objective is
    #: comparable between grids (the cost error estimate uses it).
    full_problem: bool = False

    def line(self) -> str:
        """The stage as one line of text for a terminal (what ``gaitopt solve`` prints and
        :func:`gaitopt.solve_gait` hands its ``progress``)."""
        p = self.parameters
        return (f"{self.name:<22} {'+'.join(map(str, self.knots))} knots  "
                f"{'ok ' if self.success else 'FAILED'} {self.status:<28} "
                f"it {self.iterations:>4}  J {self.objective:10.4g}  "
                f"v {p.get('speed', float('nan')) * 60:6.2f} m/min  "
                f"L {p.get('step_length', float('nan')):.4f} m  "
                f"viol {self.violation:.1e}  {self.wall_time_s:6.2f} s")


@dataclass(frozen=True)
class StagedRun:
    """Internal: the outcome of :func:`~gaitopt.gait.solve.staged.solve_walking`, the final
    result of the collocation engine (:class:`gaitopt.ocp.Result`) and every stage. Users get
    the :class:`~gaitopt.gait.record.file.Gait` made of it
    (:func:`gaitopt.gait.solve.record.gait_from_run`)."""

    model: RobotModel
    options: GaitOptions
    result: Result
    stages: tuple[StageRecord, ...]
    wall_time_s: float
    stage_results: tuple[tuple[str, Result], ...] = ()
    """Every stage's name and result, in order (for diagnosing a failure)."""
    #: The full-problem stages that converged, (knots per phase, cost), in order: the grids
    #: the cost was computed on (the cost error estimate compares the last two).
    grid_costs: tuple[tuple[tuple[int, ...], float], ...] = ()
    #: What the refinement to an accuracy adds to the gait file's ``solver.accuracy``
    #: (:func:`gaitopt.gait.solve.refinement.refine_to_accuracy`); None before it ran.
    accuracy_extra: Mapping[str, Any] | None = None
    #: The check grid's NLP point of the gait file whose estimate this run carries over
    #: (:func:`gaitopt.gait.solve.warm_accuracy.carried_estimate`: the same optimum on the same
    #: grid, so the same check grid optimum); written again with the new gait file. None
    #: otherwise.
    carried_check: WarmStart | None = None
    #: Where the phase shares were released, which optimum was kept and why
    #: (:func:`gaitopt.gait.solve.share_release.decision` or ``release_first``, the gait file's
    #: ``solver.phase_shares``); None where they were not.
    share_release: Mapping[str, Any] | None = None
    #: Where the answer was rejected and solved again with a torque-rate term, what was done
    #: (:func:`gaitopt.gait.solve.torque_rate_fallback.fallback_record`, the gait file's
    #: ``solver.torque_rate_fallback``); None where it was not.
    torque_rate_fallback: Mapping[str, Any] | None = None

    @property
    def success(self) -> bool:
        """Whether the final result converged."""
        return self.result.success

    @property
    def failed_stage(self) -> StageRecord | None:
        """The last failed stage when the solve failed."""
        if self.success:
            return None
        failed = [s for s in self.stages if not s.success]
        return failed[-1] if failed else None


def converged_or_failed(result: Result) -> Result:
    """``result``, marked failed if IPOPT stopped at its acceptable level (which CasADi reports
    as success) with a constraint violation above :data:`ACCEPTABLE_VIOLATION`: such a point
    does not meet the requested tolerances. A feasible acceptable-level point stays a success
    and keeps its status ``Solved_To_Acceptable_Level``, which the gait file records."""
    if (result.success and result.status == "Solved_To_Acceptable_Level"
            and result.constraint_violation > ACCEPTABLE_VIOLATION):
        return dataclasses.replace(
            result, success=False,
            message=f"IPOPT stopped at its acceptable level with a constraint violation of "
                    f"{result.constraint_violation:.2g} (more than {ACCEPTABLE_VIOLATION:g})")
    return result


def result_guess(result: Result) -> Guess:
    """A result's knot values and parameters as a guess (values only, no multipliers)."""
    phases = {ph.name: PhaseGuess(x=ph.x, u=ph.u, tau=(ph.t - ph.t[0]) / (ph.t[-1] - ph.t[0]))
              for ph in result.phases}
    return Guess(phases=phases, parameters=dict(result.parameters))


def best_of(results: Sequence[Result | None]) -> Result | None:
    """The converged result with the lowest objective (None if none converged)."""
    ok = [r for r in results if r is not None and r.success]
    return min(ok, key=lambda r: r.objective) if ok else None


def as_failed(result: Result, failed: Result) -> Result:
    """``result``'s values with the failed stage's status (never reported as converged)."""
    return dataclasses.replace(result, success=False, status=failed.status,
                               message=f"{failed.message} (values of an earlier stage)")


#: The stage that solves the problem on the check grid (:meth:`gaitopt.gait.solve.staged.
#: _Run.check`), whose cost the cost error estimate compares with.
CHECK_GRID_STAGE = "check grid"
#: The same problem solved again from the target grid's values only, where stage
#: :data:`CHECK_GRID_STAGE` started from them mapped with their multipliers did not converge
#: within :data:`~gaitopt.gait.solve.stages.CHECK_REGRID_MAX_ITER` iterations.
CHECK_FROM_VALUES_STAGE = "check grid, from values"


def check_result(run: StagedRun) -> Result | None:
    """The converged result of the run's last ``check grid`` stage (the problem on the check
    grid of its knots, :meth:`gaitopt.gait.solve.staged._Run.check`; or of its stage ``check
    grid, from values`` after it), or None."""
    for name, result in reversed(run.stage_results):
        if name.endswith((CHECK_GRID_STAGE, CHECK_FROM_VALUES_STAGE)):
            return result if result.success else None
    return None
