"""The Python entry point: ``solve_gait(model, options) -> Gait``, usable from a notebook.

The :class:`Gait` is the one result a user gets (docs/architecture.md, "One public result");
:func:`solve_staged_run` is the internal solve under it, for the command line, the benches
and the tests.

The paper's problem at 12 m/min (0.2 m/s) on the built-in five-link biped, solved in a few
seconds, then checked and saved:

>>> from gaitopt import GaitOptions, solve_gait, verify_gait
>>> gait = solve_gait("five-link", GaitOptions(speed=0.2))
>>> gait.success, round(gait.speed * 60, 6)
(True, 12.0)
>>> [ph.name for ph in gait.phases], [e.name for e in gait.events]
(['single_support', 'double_support'], ['heel_strike', 'liftoff'])
>>> report = verify_gait(gait)
>>> report.passed, report.check("eom.residual").value < 1e-9
(True, True)
>>> gait.save("walk.gait.json")                              # doctest: +SKIP
PosixPath('walk.gait.json')

(The last line writes a file, so the test suite skips it.)
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from gaitopt.gait.formulations.full.physics import actuator_names
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, follows_model
from gaitopt.gait.options.model_defaults import default_speed, options_for_model
from gaitopt.gait.options.preflight import refuse_unwalkable
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.accuracy import accuracy_record
from gaitopt.gait.solve.diagnose import SolveFailedError, diagnose
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run
from gaitopt.gait.solve.refinement import MAX_ROUNDS, refine_to_accuracy
from gaitopt.gait.solve.share_release import (
    FROM_FIXED,
    PREFIX,
    RELEASE_STAGE_SECONDS,
    Plausibility,
    free_options,
    release_first,
    release_shares,
    releases_shares,
)
from gaitopt.gait.solve.staged import (
    ProgressFn,
    StagedRun,
    StageRecord,
    solve_walking,
    transcription_for,
)
from gaitopt.gait.solve.staged_run import check_result as check_result
from gaitopt.gait.solve.torque_rate_fallback import (
    FALLBACK_TORQUE_RATE_TIMES,
    fallback_record,
    rejection,
    verdict_on,
)
from gaitopt.gait.solve.torque_rate_fallback import PREFIX as SMOOTHED
from gaitopt.gait.solve.transcriptions import target_grid
from gaitopt.gait.solve.warm_accuracy import (
    carried_estimate,
    check_point,
    refined_grid,
    same_problem,
    stored_point,
)
from gaitopt.ocp import Guess, PhaseGuess, ProblemError, WarmStart
from gaitopt.ocp.regrid import regridded
from gaitopt.robot import RobotModel, load_model


def as_model(model: RobotModel | str | os.PathLike[str]) -> RobotModel:
    """A model object from a model, a built-in name or a model file path."""
    return model if isinstance(model, RobotModel) else load_model(model)


def guess_from_gait(gait: Gait) -> Guess:
    """An engine guess from a saved gait: its phase states (reduced or full, by name) and
    actuator torques at its knots (normalised times), and its parameters."""

    model = gait.model
    phases = {}
    for ph in gait.phases:
        tau = (ph.t - ph.t[0]) / (ph.t[-1] - ph.t[0])
        x = {n: np.asarray(ph.x)[:, j] for j, n in enumerate(ph.state_names)}
        acting = actuator_names(model, ph.contacts, ankle=bool(gait.options.get("ankle")))
        u = {n: np.asarray(ph.u)[:, model.actuator_index(n)] for n in acting}
        phases[ph.name] = PhaseGuess(x=x, u=u, tau=tau)
    p = gait.parameters
    return Guess(phases=phases, parameters={"step_length": p["step_length"],
                                            "speed": p["speed"],
                                            "impulse": p["liftoff_impulse"]})


def warm_start_usable(gait: Gait, options: GaitOptions) -> bool:
    """Whether ``gait`` can start a solve with ``options``: the same controls (ankle torques
    or not) and the same phases (single-support fraction). Otherwise it is not used."""
    return bool(gait.options.get("ankle") == options.ankle and
                gait.options.get("formulation", "reduced") == options.formulation and
                gait.options.get("single_support_fraction") ==
                options.single_support_fraction)


def solve_staged_run(model: RobotModel | str | os.PathLike[str],
                     options: GaitOptions | None = None, *,
                     warm_start: Gait | None = None, progress: ProgressFn | None = None,
                     compiled: str | None = None,
                     refine: bool | None = None,
                     speed_given: bool | None = None,
                     check_warm_start: bool = False,
                     plausible: Plausibility | None = None,
                     smooth_rejected: bool = True,
                     max_rounds: int = MAX_ROUNDS) -> StagedRun:
    """Internal: :func:`solve_gait` before the gait is recorded. Returns the
    :class:`~gaitopt.gait.solve.staged_run.StagedRun` (the engine's final result, every
    stage's record and result), which the command line, the study, the benches and the tests
    read; users get its :class:`Gait` from :func:`solve_gait`. ``progress`` is called with
    each stage's :class:`~gaitopt.gait.solve.staged_run.StageRecord`.

    ``refine``: whether the solve refines its grid to ``options.accuracy``
    (:mod:`gaitopt.gait.solve.refinement`); None: where the knots are left to the model's default.
    A warm start that refines starts on the grid its file was refined to and solves its check
    grid, unless it finds the file's own optimum again, whose estimate it then keeps
    (:mod:`gaitopt.gait.solve.warm_accuracy`).
    ``check_warm_start``: a warm start always solves its check grid too (the cost study's
    accuracy pass), whatever the file's estimate. ``max_rounds``: the most refinements
    (:data:`~gaitopt.gait.solve.refinement.MAX_ROUNDS`; the accuracy pass asks for more).
    ``plausible``: where the sequence's phase shares are guesses
    (:mod:`gaitopt.gait.solve.share_release`), the problem is solved first with them free,
    and kept where converged, lower on the coarse grid and ``plausible``; otherwise the
    fixed-share solve follows and the free one replaces it where lower, converged and
    ``plausible`` (a check of the released run: None when plausible, else why not;
    :func:`gaitopt.analysis.plausible.verified`, which ``gaitopt solve`` passes). None: no
    release, the shares stay fixed (nothing here can judge the released gait: the checks
    of ``gaitopt verify`` live above this layer). A converged answer that ``plausible``
    rejects is solved again with a torque-rate term where its cost has none
    (:mod:`gaitopt.gait.solve.torque_rate_fallback`), unless ``smooth_rejected`` is False
    (``gaitopt solve --no-verify``: then only the release is judged).
    ``speed_given``: whether the caller chose the speed; None: unless it is left to the
    model. A cold solve at the model's default speed that fails is tried once more at the
    slower default speed of the walk (:func:`slower_default`), the stages of both attempts
    in the run.

    Raises:
        UnwalkableModelError: something in the model prevents walking
            (:func:`gaitopt.gait.options.preflight.preflight`); nothing was solved.
    """
    robot = as_model(model)
    given = options or GaitOptions()
    opts = options_for_model(robot, given)
    if (warm_start is not None and given.free_phase_fractions is None
            and warm_start.options.get("free_phase_fractions") is True):
        # A file whose shares were free (released, or --free-fractions) starts a problem with
        # them free: with the sequence's fixed shares the warm start would leave the file's
        # optimum for the fixed-share one (2325 against about 1680 at 63 m/min from the
        # released seven-link walk at 60 m/min).
        opts = opts.replace(free_phase_fractions=True)
    refuse_unwalkable(robot, opts)
    if refine is None:
        refine = follows_model(given.knots)
    refines = refine and opts.accuracy is not None and opts.mesh_tol is None
    guess: Guess | WarmStart | None = None
    if warm_start is not None and warm_start_usable(warm_start, opts):
        if refines:  # start on the grid the file was refined to (gait/solve/warm_accuracy.py)
            opts = refined_grid(warm_start, robot, opts) or opts
        guess = restart_point(robot, opts, warm_start, compiled) or guess_from_gait(warm_start)
    # Where the shares are guesses, the free problem first, from its own stages, refined: kept
    # where it converges, lowers the coarse cost and is plausible, and then the fixed-share
    # problem is not solved past the coarse grid (share_release's module docstring).
    release = plausible is not None and warm_start is None and releases_shares(robot, opts)
    judged = None if plausible is None else _judged_once(plausible)
    own: StagedRun | None = None
    if release:
        own = _own_release(robot, free_options(opts), progress, compiled, refines)
        chosen = release_first(own, robot, judged)
        if chosen is not None:
            return dataclasses.replace(own, share_release=chosen)
    # A warm start that refines needs its estimate: its check grid (unless the file's holds).
    # The adaptive barrier's restart where the file solved this problem at another speed:
    # from the file of another cost it did not converge (gaitopt.study.worker.
    # ADAPTIVE_STARTS); at the file's own speed the monotone one confirms the file's point.
    first = solve_walking(robot, opts, warm_start=guess, progress=progress, compiled=compiled,
                          check_start=check_point(warm_start) if guess is not None else None,
                          check_warm_start=check_warm_start or (
                              refines and guess is not None and
                              not _file_estimate_may_hold(warm_start, opts)),
                          adaptive_restart=warm_start is not None and same_problem(
                              warm_start.options, opts, but=frozenset({"speed"}))
                          and not same_problem(warm_start.options, opts))
    carried = None
    if guess is not None and warm_start is not None and refines:
        carried = carried_estimate(warm_start, first, accuracy_record(first))
        checked = any(s.name.startswith("check grid") for s in first.stages)
        if carried is None and first.success and not checked and \
                accuracy_record(first).get("cost_error") is None:
            # The file's estimate does not hold (another optimum): the check grid now (not
            # again after a check grid that failed: the same solve, 32 minutes for nothing
            # in the seven-link's work case).
            again = solve_walking(robot, opts, warm_start=first.result, progress=progress,
                                  compiled=compiled, check_warm_start=True)
            first = dataclasses.replace(again, stages=first.stages + again.stages,
                                        wall_time_s=first.wall_time_s + again.wall_time_s)
    if speed_given is None:
        speed_given = not follows_model(given.speed)
    slower = slower_default(robot, opts)
    if not first.success and guess is None and not speed_given and slower is not None:
        retry = solve_walking(robot, opts.replace(speed=slower), progress=progress,
                              compiled=compiled)
        if retry.success:
            first = dataclasses.replace(retry, stages=first.stages + retry.stages,
                                        wall_time_s=first.wall_time_s + retry.wall_time_s)

    def solve_on(finer: GaitOptions, before: StagedRun) -> StagedRun:
        # Started from the check grid's result, which is the solution of this very NLP (the
        # check grid of the coarser grid is the finer grid), values and multipliers: IPOPT
        # confirms it in a few iterations. Without one, from the coarser grid's result (its
        # interpolants at the finer knots): no gait record needed, so a coarse motion that
        # leaves a leg's reach between knots is refined too.
        again = solve_walking(robot, finer, warm_start=check_result(before) or before.result,
                              progress=progress, compiled=compiled, check_warm_start=True)
        return dataclasses.replace(again, stages=before.stages + again.stages,
                                   wall_time_s=before.wall_time_s + again.wall_time_s)

    def accuracy_of(run: StagedRun) -> dict[str, Any]:
        record = accuracy_record(run)
        return {**record, **carried} if carried is not None and run is first else record

    run, extra = refine_to_accuracy(first, refines=refines, solve_on=solve_on,
                                    accuracy_of=accuracy_of, max_rounds=max_rounds)
    if carried is not None and run.result is first.result:
        run = dataclasses.replace(run, accuracy_extra={**carried, **extra},
                                  carried_check=check_point(warm_start))
    # A warm start follows its start: it is not released again (the file's own solve decided).
    if run.success and release:
        # The free problem's own run from above, unless the fixed solve moved to the slower
        # default speed (then solved again there).
        reused = own if own is not None and own.options.speed == run.options.speed else None

        def released(free: GaitOptions, fixed: StagedRun) -> StagedRun:
            # Where the free problem's own run failed or left no estimate, it is started from
            # the fixed-share optimum (share_release's module docstring, docs/feet.md).
            run = reused if reused is not None else \
                _own_release(robot, free, progress, compiled, refines)
            if run.success and accuracy_record(run).get("cost_error") is not None:
                return run
            warm = _prefixed(solve_walking(robot, free, warm_start=fixed.result,
                                           progress=_prefixed_progress(progress, FROM_FIXED),
                                           compiled=compiled, check_warm_start=True,
                                           stage_seconds=RELEASE_STAGE_SECONDS), FROM_FIXED)
            run = dataclasses.replace(warm, stages=run.stages + warm.stages,
                                      wall_time_s=run.wall_time_s + warm.wall_time_s)
            if accuracy_record(run).get("cost_error") is None:
                # Its check grid failed: no estimate, so not within the accuracy, and the
                # fixed shares stand; refining it further took 10 minutes and more.
                return run
            return _refined(robot, run, progress, compiled, refines, PREFIX,
                            RELEASE_STAGE_SECONDS)

        run = release_shares(run, released, judged, first=reused)
    if not smooth_rejected:
        return run
    return _smoothed_if_rejected(robot, run, judged, progress, compiled, refines)


def _smoothed_if_rejected(model: RobotModel, run: StagedRun, judged: Plausibility | None,
                          progress: ProgressFn | None, compiled: str | None,
                          refines: bool) -> StagedRun:
    """``run``, or where ``judged`` rejects its answer, the first answer of the same problem
    with a torque-rate term (each ``tau`` of
    :data:`~gaitopt.gait.solve.torque_rate_fallback.FALLBACK_TORQUE_RATE_TIMES` in turn,
    solved from the answer before and refined) that converges and passes
    (:mod:`gaitopt.gait.solve.torque_rate_fallback`); either way with every stage and the
    record of what was done."""
    why = rejection(run, judged)
    if why is None or judged is None:
        return run
    tries: list[tuple[float, float | None, str | None]] = []
    start, stages, wall = run, run.stages, run.wall_time_s
    for tau in FALLBACK_TORQUE_RATE_TIMES:
        try:
            smoothed = _prefixed(solve_walking(model, start.options.replace(torque_rate_time=tau),
                                               warm_start=start.result,
                                               progress=_prefixed_progress(progress, SMOOTHED),
                                               compiled=compiled, check_warm_start=True),
                                 SMOOTHED)
            if smoothed.success and accuracy_record(smoothed).get("cost_error") is not None:
                smoothed = _refined(model, smoothed, progress, compiled, refines, SMOOTHED)
        except GaitOptionsError as exc:  # e.g. a refinement past the knots a phase may have
            tries.append((tau, None, f"its solve was refused: {exc}"))
            break
        verdict = verdict_on(smoothed, judged)
        tries.append((tau, float(smoothed.result.objective) if smoothed.success else None,
                      verdict))
        stages, wall = stages + smoothed.stages, wall + smoothed.wall_time_s
        if verdict is None:
            return dataclasses.replace(smoothed, stages=stages, wall_time_s=wall,
                                       share_release=run.share_release,
                                       torque_rate_fallback=fallback_record(why, run, tries))
        if smoothed.success:
            start = smoothed
    return dataclasses.replace(run, stages=stages, wall_time_s=wall,
                               torque_rate_fallback=fallback_record(why, run, tries))


def _own_release(model: RobotModel, options: GaitOptions, progress: ProgressFn | None,
                 compiled: str | None, refines: bool) -> StagedRun:
    """The free-share problem ``options`` (:func:`~gaitopt.gait.solve.share_release.free_options`)
    solved from its own stages (the naive guess, the shares freed on the coarse grid), each
    stage within :data:`~gaitopt.gait.solve.share_release.RELEASE_STAGE_SECONDS`, its stages
    named with :data:`~gaitopt.gait.solve.share_release.PREFIX`, and refined to the accuracy
    where its check grid gave an estimate (a release whose check grid failed is not refined:
    that took 10 minutes and more)."""
    run = _prefixed(solve_walking(model, options, progress=_prefixed_progress(progress, PREFIX),
                                  compiled=compiled, stage_seconds=RELEASE_STAGE_SECONDS),
                    PREFIX)
    if not run.success or accuracy_record(run).get("cost_error") is None:
        return run
    return _refined(model, run, progress, compiled, refines, PREFIX, RELEASE_STAGE_SECONDS)


def _refined(model: RobotModel, run: StagedRun, progress: ProgressFn | None,
             compiled: str | None, refines: bool, prefix: str,
             stage_seconds: float | None = None) -> StagedRun:
    """``run`` refined to the accuracy, the stages of each finer grid named with ``prefix``
    and each within ``stage_seconds`` (None: no limit)."""

    def solve_on(finer: GaitOptions, before: StagedRun) -> StagedRun:
        again = _prefixed(solve_walking(model, finer,
                                        warm_start=check_result(before) or before.result,
                                        progress=_prefixed_progress(progress, prefix),
                                        compiled=compiled, check_warm_start=True,
                                        stage_seconds=stage_seconds), prefix)
        return dataclasses.replace(again, stages=before.stages + again.stages,
                                   wall_time_s=before.wall_time_s + again.wall_time_s)

    return refine_to_accuracy(run, refines=refines, accuracy_of=accuracy_record,
                              solve_on=solve_on)[0]


def _judged_once(plausible: Plausibility) -> Plausibility:
    """``plausible`` run at most once per run (a verify of the released gait takes about a
    second; the free-first decision and the fallback's may both ask)."""
    seen: dict[int, tuple[StagedRun, str | None]] = {}

    def judged(run: StagedRun) -> str | None:
        if id(run) not in seen:
            seen[id(run)] = (run, plausible(run))
        return seen[id(run)][1]

    return judged


def _prefixed(run: StagedRun, prefix: str) -> StagedRun:
    """``run`` with ``prefix`` before every stage's name."""
    if not prefix:
        return run
    return dataclasses.replace(run, stages=tuple(
        dataclasses.replace(s, name=prefix + s.name) for s in run.stages))


def _prefixed_progress(progress: ProgressFn | None, prefix: str) -> ProgressFn | None:
    """``progress`` told each stage with ``prefix`` before its name."""
    if progress is None or not prefix:
        return progress
    report = progress

    def told(stage: StageRecord) -> None:
        report(dataclasses.replace(stage, name=prefix + stage.name))

    return told


def _file_estimate_may_hold(gait: Gait | None, options: GaitOptions) -> bool:
    """Whether a warm start from ``gait`` with ``options`` may find the file's own optimum,
    so that its estimate holds (:func:`~gaitopt.gait.solve.warm_accuracy.carried_estimate`
    decides after the solve): the file has an estimate and the same problem."""
    if gait is None:
        return False
    old = gait.solver.get("accuracy")
    return (isinstance(old, Mapping) and old.get("cost_error") is not None
            and same_problem(gait.options, options))


def slower_default(model: RobotModel, options: GaitOptions) -> float | None:
    """The speed (m/s) a failed solve at the model's default speed tries next: the walk's
    default at equal Froude number (:func:`gaitopt.gait.options.model_defaults.default_speed`: 12
    m/min on 1 m legs), if it is under 90 % of ``options.speed``; else None. A model whose
    hips only swing backward, like MuJoCo's Walker2d, walks slowly with its torso leaning
    back and fails at the heel-toe walk's faster default."""
    if options.speed is None:
        return None
    slower = default_speed(model, "walk")
    return slower if slower < 0.9 * options.speed else None


def restart_point(model: RobotModel, options: GaitOptions, gait: Gait,
                  compiled: str | None = None) -> WarmStart | None:
    """The NLP point and multipliers a gait file keeps (``solver.warm_start``), if they fit
    the transcription ``options`` solve on (same layout, method and constraints; a fixed
    grid): IPOPT then restarts from them as from a result in the same process. None
    otherwise (older files keep none; the trajectories are the fallback guess)."""
    point = stored_point(gait.solver.get("warm_start"))
    if point is None or options.mesh_tol is not None:
        return None
    # The grid the warm start solves on (cosine-spaced knots are a mesh: another cache entry
    # than their counts, which would build the same NLP twice).
    tr = transcription_for(model, options, target_grid(model, options), compiled=compiled)
    return point if point.fits(tr.layout, tr.method, tr.nlp.lbg.size) else None


def regridded_point(model: RobotModel, options: GaitOptions, gait: Gait,
                    compiled: str | None = None) -> WarmStart | None:
    """The NLP point and multipliers a gait file keeps (``solver.warm_start``) mapped onto
    the grid ``options`` solve on, where the file solved the same problem on another fixed
    grid (its ``knots``, ``knot_spacing`` and ``phase_shares`` options; the layout checked):
    its values interpolated and its multipliers mapped (:func:`gaitopt.ocp.regrid.regridded`),
    as a solve maps its own solution onto its check grid. Sweep workers start IPOPT from it
    with the warm start's barrier (1e-6; :data:`gaitopt.study.worker.REGRIDDED`); a solve's
    own move from a coarser optimum uses :data:`~gaitopt.gait.solve.staged.REGRID_OPTIONS`
    (``solve_walking(warm_start_options=...)``).
    None where the file keeps no point, it does not fit the file's own grid, or either grid
    is adaptive (``mesh_tol``)."""
    point = stored_point(gait.solver.get("warm_start"))
    saved = gait.options
    if point is None or options.mesh_tol is not None or saved.get("mesh_tol") is not None:
        return None
    try:
        shares, spacing = saved.get("phase_shares"), saved["knot_spacing"]
        if spacing not in ("uniform", "cosine"):
            return None
        own = options.replace(knots=tuple(int(k) for k in saved["knots"]),
                              knot_spacing="uniform" if spacing == "uniform" else "cosine",
                              phase_shares=None if shares is None else
                              tuple(float(v) for v in shares))
        source = transcription_for(model, own, target_grid(model, own), compiled=compiled)
        target = transcription_for(model, options, target_grid(model, options),
                                   compiled=compiled)
        return regridded(target, source.result_at(point))
    except (KeyError, TypeError, ValueError, ProblemError):  # options, file or problem
        return None


def solve_gait(model: RobotModel | str | os.PathLike[str], options: GaitOptions | None = None,
               *, warm_start: Gait | None = None, progress: Callable[[str], None] | None = None,
               compiled: str | None = None, plausible: Plausibility | None = None) -> Gait:
    """Solve the minimum-energy walking problem and return the gait, the one result of a
    solve (converged or not: ``gait.success`` says; :meth:`Gait.save` refuses to write a
    failed gait). Everything the solve found is in it: ``gait.status``, ``gait.solver`` (the
    iterations, the NLP size, the largest violation, every stage in ``solver["stages"]`` and
    the error estimates in ``solver["accuracy"]``), the costates and interval error estimates
    of its phases, and for a failed solve :attr:`Gait.diagnosis` (why it failed and what to
    change).

    Args:
        model: a :class:`RobotModel`, a built-in model name or a model file.
        options: the variant, targets and bounds (default: the paper's problem at 12 m/min
            for the five-link biped; on another model the defaults that follow it, as
            ``gaitopt solve --model M``: :mod:`gaitopt.gait.options.model_defaults`).
        warm_start: a neighbouring gait to start from (the cold path is the fallback).
        progress: called after every stage with a line of text on it (its name, grid,
            outcome, iterations, cost, speed, step length, violation and time: the lines
            ``gaitopt solve`` prints); the stages are also in ``gait.solver["stages"]``.
        compiled: ``None`` or ``"codegen"`` to compile the NLP to C (cached on disk).
        plausible: the check that lets a sequence's guessed phase shares be released
            (:mod:`gaitopt.gait.solve.share_release`) and that an answer must pass, else it
            is solved again with a torque-rate term
            (:mod:`gaitopt.gait.solve.torque_rate_fallback`), e.g.
            ``gaitopt.analysis.plausible.verified`` (``gaitopt verify`` passes on the gait),
            which ``gaitopt solve`` uses; None: the shares stay fixed, no fallback.

    Raises:
        MotionOutOfReachError: the converged solution's motion between knots leaves a leg's
            reach (it cannot be recorded as a gait; solve on a finer grid).
        SolveFailedError: the solve failed and its last values cannot even be recorded; the
            message is the diagnosis (what :attr:`Gait.diagnosis` holds otherwise).
    """
    lines = None if progress is None else _stage_lines(progress)
    run = solve_staged_run(model, options, warm_start=warm_start, progress=lines,
                           compiled=compiled, plausible=plausible)
    try:
        return gait_from_run(run)
    except MotionOutOfReachError:
        if run.success:
            raise

        raise SolveFailedError(diagnose(run).text()) from None


def _stage_lines(progress: Callable[[str], None]) -> ProgressFn:
    """A stage callback that hands ``progress`` each stage's line of text."""

    def report(stage: StageRecord) -> None:
        progress(stage.line())

    return report
