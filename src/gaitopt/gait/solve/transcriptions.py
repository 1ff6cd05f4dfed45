"""The walking problem's transcriptions, built once per process for each NLP structure.

A transcription (the NLP and its IPOPT solver) depends on the model, the options that shape
the NLP, the grid and the compilation mode. Speed, step length and impulse enter through
parameter bounds only, so problems that differ in those share one transcription: the cache key
is an :class:`NlpStructure`, derived from every
:class:`~gaitopt.gait.options.gait_options.GaitOptions`
field except :data:`BOUNDS_ONLY_OPTIONS` (a new option shapes the NLP until listed there).

A grid is knots per phase (single support, double support), uniform, or one array of
normalised knot times in [0, 1] per phase of the problem (a refined mesh).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gaitopt.dynamics.function_cache import cached_functions as cached_functions
from gaitopt.dynamics.function_cache import disk_cached as disk_cached
from gaitopt.dynamics.function_cache import function_file as function_file
from gaitopt.dynamics.function_cache import save_functions as save_functions
from gaitopt.dynamics.function_cache import source_hash as source_hash
from gaitopt.gait.formulations.cost import COST_TRAITS
from gaitopt.gait.formulations.select import problem_for
from gaitopt.gait.options.gait_options import FIELD_GROUPS, GaitOptions, GaitOptionsError
from gaitopt.ocp import Guess, Result, Transcription, WarmStart, transcribe
from gaitopt.process_memory import memory_budget_bytes, release_freed_memory, resident_bytes
from gaitopt.robot.model import RobotModel

#: A grid: knots per phase (single support, double support; or one count per phase of the
#: step, :mod:`gaitopt.gait.sequence.knots`), uniform, or one array of normalised knot times
#: in [0, 1] per phase of the problem (a refined mesh).
Grid = tuple[int, ...] | tuple[np.ndarray, ...]

#: Options that enter a solve only through bounds or the solve's own logic, never the NLP's
#: structure: problems that differ only in these share one transcription.
BOUNDS_ONLY_OPTIONS = frozenset({"speed", "step_length", "step_time", "knots", "multistart",
                                 "continuation", "mesh_tol", "accuracy"})


def is_mesh(grid: Grid) -> bool:
    """Whether ``grid`` is a mesh (arrays of normalised knots) rather than knot counts."""
    return not all(isinstance(k, int | np.integer) for k in grid)


def grid_knots(grid: Grid, options: GaitOptions) -> tuple[int, ...]:
    """Knots per phase of a grid: its counts, or a mesh's first two phases' (a phase the
    problem lacks keeps ``options.knots``)."""
    if not is_mesh(grid):
        return tuple(int(k) for k in grid)
    sizes = [np.asarray(m).size for m in grid]
    return (sizes[0], sizes[1] if len(sizes) > 1 else options.knots[1])


@dataclass(frozen=True)
class NlpStructure:
    """Everything that shapes the walking NLP; equal structures share one transcription.

    ``options`` holds ``(field, repr(value))`` for every :class:`GaitOptions` field but
    :data:`BOUNDS_ONLY_OPTIONS`, sorted by field name; ``grid`` the knot counts or the mesh's
    knot times; ``step_time_row`` whether the step-time constraint row exists.
    """

    model_hash: str
    grid: tuple[Any, ...]
    step_time_row: bool
    compiled: str | None
    options: tuple[tuple[str, str], ...]

    @classmethod
    def of(cls, model: RobotModel, options: GaitOptions, grid: Grid,
           compiled: str | None) -> NlpStructure:
        # A smooth cost has no positive parts to smooth: its NLP is the same at any
        # cost_smoothing (which follows the speed, gaitopt.gait.options.model_defaults).
        traits = COST_TRAITS.get(options.cost)
        unused = {"cost_smoothing"} if traits is not None and traits.smooth else set()
        shaping = sorted((name, repr(getattr(getattr(options, group), name)))
                         for name, group in FIELD_GROUPS.items()
                         if name not in BOUNDS_ONLY_OPTIONS and name not in unused)
        if is_mesh(grid):
            key: tuple[Any, ...] = tuple(tuple(float(v) for v in np.asarray(m)) for m in grid)
        else:
            key = tuple(int(k) for k in grid)
        return cls(model_hash=model.content_hash(), grid=key,
                   step_time_row=options.step_time is not None, compiled=compiled,
                   options=tuple(shaping))


#: The process-wide cache, the least recently used first. It keeps the process within its
#: memory budget (:func:`gaitopt.process_memory.memory_budget_bytes`, ``$GAITOPT_MEMORY_MB``):
#: a transcription evaluated as one expanded SX graph (the compressed form, whose exact Hessian
#: of the whole mesh is derived) takes 0.2-0.6 GB once its solver is built on the walk's
#: small grids and 1.28 GB for the five-link walk in full coordinates on 40 + 10 knots, where a
#: point-wise one takes 5-16 MB; a count of entries suits neither. Sweeps reuse the entries
#: point after point, so an entry goes only when a new one is made while the process is over
#: its budget.
_CACHE: dict[NlpStructure, Transcription] = {}


def clear_cache() -> None:
    """Forget every cached transcription (a benchmark's fresh start) and hand the freed
    memory back to the system."""
    _CACHE.clear()
    release_freed_memory()


def evaluation_mode(options: GaitOptions, compiled: str | None) -> str | None:
    """How the NLP of ``options`` is evaluated (``transcribe(..., compiled=...)``): the
    separated Hermite-Simpson form always by ``"points"``, its derivatives assembled from
    compiled functions of one grid point (:mod:`gaitopt.ocp.pointwise`: compiled once per
    model and problem structure into the disk cache, CasADi's VM without a C compiler;
    several times faster per iteration than the alternatives); other transcriptions as
    ``compiled`` asks (``None``: CasADi's VM on the expanded NLP), but not ``"codegen"``,
    whose one C file of the whole NLP does not compile in minutes."""
    if options.transcription == "hermite-simpson-separated":
        return "points"
    if compiled == "codegen":
        raise GaitOptionsError(
            f"compiled: the {options.transcription!r} NLP generated as one C file does not "
            "compile in minutes (34 MB of C at 8 + 5 knots); use transcription "
            "'hermite-simpson-separated', whose derivatives are always compiled per grid "
            "point")
    return compiled


#: Version of the disk cache of the walking problem's symbolic functions (part of its key).
FUNCTIONS_FORMAT = "gaitopt-walking-functions-1"


def functions_file(key: NlpStructure) -> Path:
    """Where the symbolic functions (``Transcription.functions``) of the problem of the
    structure ``key`` are cached on disk: keyed by the model, every shaping option, the
    gaitopt sources and CasADi's version, not the grid or the evaluation mode."""
    return function_file("walking-functions",
                         (FUNCTIONS_FORMAT, key.model_hash, key.step_time_row, key.options))


def transcription_for(model: RobotModel, options: GaitOptions, knots: Grid, *,
                      compiled: str | None = None) -> Transcription:
    """The (process-wide cached) transcription of the walking problem on ``knots`` (knot
    counts per phase, or a mesh: normalised knot times per phase). Its symbolic functions
    (independent of the grid) come from another grid's transcription in this process, or
    from the disk cache (:func:`functions_file`), or are built and saved there."""
    compiled = evaluation_mode(options, compiled)
    key = NlpStructure.of(model, options, knots, compiled)
    if key in _CACHE:
        _CACHE[key] = _CACHE.pop(key)  # the most recently used last
    else:
        same = [tr.functions for k, tr in _CACHE.items()
                if dataclasses.replace(k, grid=key.grid) == key]
        path = functions_file(key)
        functions = same[0] if same else cached_functions(path)
        counts = grid_knots(knots, options)
        problem = problem_for(model, options.replace(knots=counts))
        intervals: dict[str, Any] = {
            ph.name: (np.asarray(knots[i], dtype=float) if is_mesh(knots) else ph.intervals)
            for i, ph in enumerate(problem.phases)}
        _CACHE[key] = transcribe(
            problem, method=options.transcription, intervals=intervals, compiled=compiled,
            options={"ipopt.tol": options.tol, "ipopt.max_iter": options.max_iter,
                     "ipopt.acceptable_tol": max(options.tol * 100, 1e-6),
                     "show_eval_warnings": False},
            build_solver=False, functions=functions)
        if functions is None:
            save_functions(path, _CACHE[key].functions)
        _keep_within_budget(key)
    return _CACHE[key]


def _keep_within_budget(newest: NlpStructure) -> None:
    """While the process's resident memory exceeds its budget, drop the least recently used
    transcription other than ``newest`` and hand the freed memory back to the system (a
    caller still holding one keeps it alive)."""
    budget = memory_budget_bytes()
    if resident_bytes() <= budget:
        return
    for key in [k for k in _CACHE if k != newest]:
        del _CACHE[key]
        release_freed_memory()
        if resident_bytes() <= budget:
            return


def cosine_knots(n: int) -> np.ndarray:
    """``n`` normalised knot times ``(1 - cos(pi k / (n - 1))) / 2``, k = 0..n-1: clustered
    at both ends of the phase (intervals about ``pi^2 / (4 (n - 1)^2)`` there, ``pi / (2 (n -
    1))`` in the middle)."""
    return 0.5 * (1.0 - np.cos(np.pi * np.arange(n) / (n - 1)))


def target_grid(model: RobotModel, options: GaitOptions) -> Grid:
    """The target grid of a solve: ``options.knots``, uniform, or with ``knot_spacing =
    "cosine"`` a mesh of :func:`cosine_knots` for each phase of the problem, with the knot
    count the problem gives that phase (two-phase walks: ``options.knots``; longer contact
    sequences: :func:`gaitopt.gait.sequence.contact_sequence.phase_knots`)."""
    if options.knot_spacing == "uniform":
        return options.knots
    return tuple(cosine_knots(n) for n in _phase_knots(model, options))


#: The knots per phase of the problems :func:`target_grid` was asked for in this process, by
#: model hash and ``repr`` of the options: building a problem only to count its knots took
#: a quarter of a second for the seven-link, three times in a warm start.
_PHASE_KNOTS: dict[tuple[str, str], tuple[int, ...]] = {}


def _phase_knots(model: RobotModel, options: GaitOptions) -> tuple[int, ...]:
    """The knots of each phase of the problem of ``options`` (its intervals + 1), memoised."""
    key = (model.content_hash(), repr(options))
    if key not in _PHASE_KNOTS:
        if len(_PHASE_KNOTS) > 256:
            _PHASE_KNOTS.clear()
        _PHASE_KNOTS[key] = tuple(ph.intervals + 1 for ph in problem_for(model, options).phases)
    return _PHASE_KNOTS[key]


def warm_start_grid(model: RobotModel, options: GaitOptions,
                    warm_start: Guess | Result | WarmStart) -> Grid:
    """The grid of a warm start: :func:`target_grid`; with ``mesh_tol``, the warm start's own
    mesh (a refined gait's non-uniform knots), every other knot of it when each phase has an
    odd number >= 5: the mesh before the halving that ended its refinement, so that a chain
    of warm starts (a sweep) does not double the grid at every point."""
    if options.mesh_tol is None or isinstance(warm_start, WarmStart):
        return target_grid(model, options)
    if isinstance(warm_start, Result):
        taus = [np.asarray(m, dtype=float) for m in warm_start.mesh]
    else:
        taus = [np.asarray(g.tau, dtype=float) for g in warm_start.phases.values()
                if g.tau is not None]
    if (len(taus) != len(problem_for(model, options).phases)
            or any(t.size < 2 for t in taus)):
        return target_grid(model, options)
    if all(t.size % 2 == 1 and t.size >= 5 for t in taus):
        taus = [t[::2] for t in taus]
    return tuple(taus)
