"""Sweeps: many walking problems on a grid, solved in parallel by continuation, resumable.

``run_sweep(spec, directory)`` solves every point of
:class:`~gaitopt.study.plan.SweepSpec` (the grid and the warm-start chains are described there) on a
:class:`~gaitopt.study.executors.Backend` (local processes by default, a Dask cluster, or
this process) and writes the sweep directory (``docs/outputs.md`` section 2):

* ``sweep.json`` first: the settings. A directory made with other settings is refused
  (:class:`SweepSettingsError` lists the differences); so is one where another sweep runs.
* each point's gait file, written atomically by the driver as soon as the worker returns the
  solved gait (a failed point never gets a file). Workers write nothing and read nothing of
  the sweep directory, so a Dask cluster needs no filesystem shared with the driver;
* ``summary.csv`` (of each sub-sweep), rewritten atomically after every finished point: a row
  per finished point, failed points as failed rows naming the failed stage.

The driver keeps ``backend.slots`` points in flight. A point is ready when the neighbour it
continues from (its *parent*) has finished; it is warm-started from that neighbour's engine
Result (values and multipliers, passed in memory from task to task), or, when the neighbour
was kept from an earlier run, from its gait file (whose text the driver sends); when the
neighbour failed, from what the neighbour was given. Among ready points the driver prefers, in
order: one whose problem structure the process that just finished has already built; a
chain's cold start; the point with the most points waiting on it (the longest chain first).

Resuming: rerunning with the same settings keeps every point whose gait file loads, converged
and was solved with this point's options and model (its summary row is rebuilt from the
file, so a file written just before a kill is kept too); failed and missing points are
solved. Killing the sweep at any moment loses no finished point and corrupts no file: every
write is atomic (temporary file + rename) and leftovers of interrupted writes are removed. On
Ctrl-C the driver first writes every point already returned, then stops the workers.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from gaitopt.gait.formulations.select import biped_for
from gaitopt.gait.options.gait_options import GaitOptionsError, validate_options
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.ocp import Result
from gaitopt.study.executors import (
    BROKEN_ERRORS,
    Backend,
    BackendError,
    dask_backend,
    inline_backend,
    local_backend,
)
from gaitopt.study.plan import (
    SweepPoint,
    SweepSpec,
    SweepSpecError,
)
from gaitopt.study.summary import (
    SummaryRow,
)
from gaitopt.study.sweep_directory import SweepSettingsError as SweepSettingsError
from gaitopt.study.sweep_directory import (
    directory_lock,
    prepare_directory,
    remove_leftovers,
    scan_directory,
    write_summaries,
)
from gaitopt.study.worker import (
    PointOutcome,
    PointTask,
    SavedGait,
    failed_point_row,
    solve_point,
)

#: Restarts of a broken process pool in a row (no point finishing between) before giving up.
MAX_WORKER_DEATHS = 3


@dataclass(frozen=True)
class Counts:
    """Progress: points in the grid, kept from an earlier run, to solve this run, and of
    those finished (succeeded + failed)."""

    total: int
    kept: int
    to_solve: int
    succeeded: int = 0
    failed: int = 0

    @property
    def finished(self) -> int:
        return self.succeeded + self.failed

    @property
    def remaining(self) -> int:
        return self.to_solve - self.finished


@dataclass(frozen=True)
class SweepStart:
    """What a sweep is about to do: the counts, where it runs, and notes from the scan of
    an earlier run (unreadable or mismatched gait files, which are solved again)."""

    directory: Path
    counts: Counts
    backend: str
    notes: tuple[str, ...]


@dataclass(frozen=True)
class SweepReport:
    """The outcome of :func:`run_sweep`."""

    directory: Path
    counts: Counts
    wall_time_s: float
    summaries: tuple[Path, ...]
    interrupted: bool = False
    notes: tuple[str, ...] = ()
    outcomes: tuple[PointOutcome, ...] = field(default=(), repr=False)


StartFn = Callable[[SweepStart], None]
PointFn = Callable[[SweepPoint, PointOutcome, Counts], None]


def check_points(spec: SweepSpec) -> None:
    """Validate every point's options before any solve (:class:`SweepSpecError` names the
    point and the option)."""
    for point in spec.points:
        options = spec.options(point)  # the legs as the point's formulation sees them
        try:
            validate_options(options, biped_for(spec.model_of(point), options))
        except GaitOptionsError as exc:
            raise SweepSpecError(f"{point.label().strip()}: {exc}") from None


# -- the driver ---------------------------------------------------------------------------------

def make_backend(*, workers: int | None = None, scheduler: str | None = None,
                 start_method: str | None = None) -> Backend:
    """Dask when ``scheduler`` is given; else ``workers`` local processes (default: the
    CPUs this process may use), or this process for ``workers=0``."""
    if scheduler:
        return dask_backend(scheduler)
    n = default_workers() if workers is None else workers
    if n == 0:
        return inline_backend()
    return local_backend(n, start_method=start_method)


def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover  (not Linux)
        return max(1, os.cpu_count() or 1)


@dataclass
class _Driver:
    spec: SweepSpec
    directory: Path
    backend: Backend
    fail_points: frozenset[str]
    seeds: Mapping[str, str]
    on_point: PointFn | None
    rows: dict[str, SummaryRow]
    state: dict[str, str]  # todo, running, ok, failed, kept
    counts: Counts
    inflight: dict[Any, tuple[str, int]] = field(default_factory=dict)  # future -> key, gen.
    offers: dict[str, Result | str | None] = field(default_factory=dict)
    given: dict[str, Result | str | None] = field(default_factory=dict)
    tasks: dict[str, PointTask] = field(default_factory=dict)
    outcomes: list[PointOutcome] = field(default_factory=list)
    generation: int = 0
    deaths: int = 0

    def __post_init__(self) -> None:
        self.points = {p.key: p for p in self.spec.points}
        self.order = {p.key: i for i, p in enumerate(self.spec.points)}
        self.parents = self.spec.parents
        self.children: dict[str, list[str]] = {k: [] for k in self.points}
        for k, parent in self.parents.items():
            if parent is not None:
                self.children[parent].append(k)
        self.waiting = self._descendants()
        cold_rank: dict[str, int] = {}
        self.rank: dict[str, int] = {}
        for k in self.points:  # round robin over structures among the cold starts
            if self.parents[k] is None:
                s = self.points[k].structure
                self.rank[k] = cold_rank.get(s, 0)
                cold_rank[s] = self.rank[k] + 1
        for k, s in self.state.items():
            if s == "kept":
                self.offers[k] = str(self.directory / k)

    def _descendants(self) -> dict[str, int]:
        """Points waiting (directly or not) on each point."""
        depth: dict[str, int] = {}
        for k in self.points:
            d, p = 0, self.parents[k]
            while p is not None:
                d, p = d + 1, self.parents[p]
            depth[k] = d
        waiting = dict.fromkeys(self.points, 0)
        for k in sorted(self.points, key=lambda k: -depth[k]):
            parent = self.parents[k]
            if parent is not None:
                waiting[parent] += 1 + waiting[k]
        return waiting

    def settled(self, key: str | None) -> bool:
        return key is None or self.state[key] in ("ok", "failed", "kept")

    def ready(self) -> list[str]:
        return [k for k, s in self.state.items() if s == "todo" and self.settled(
            self.parents[k])]

    def pick(self, ready: list[str], built: frozenset[str]) -> str:
        def score(k: str) -> tuple[int, int, int, int, int]:
            cold = self.parents[k] is None
            return (0 if self.points[k].structure in built else 1, 0 if cold else 1,
                    self.rank.get(k, 0), -self.waiting[k], self.order[k])
        return min(ready, key=score)

    def task(self, key: str) -> PointTask:
        p, parent = self.points[key], self.parents[key]
        offer = self.offers.get(parent) if parent is not None else self.seeds.get(key)
        self.given[key] = offer
        # a kept neighbour's gait file is read here: workers may not see this directory
        warm = SavedGait.read(offer) if isinstance(offer, str) else offer
        secant = self.spec.secant_step(key)
        before = self.offers.get(secant[0]) if secant is not None else None
        trend = ((before, secant[1]) if secant is not None and isinstance(warm, Result)
                 and isinstance(before, Result) and self.state[secant[0]] == "ok" else None)
        self.tasks[key] = PointTask(key=key, model=self.spec.model_of(p),
                                    options=self.spec.options(p), variant=p.variant,
                                    speed_mode=p.speed_mode, structure=p.structure, warm=warm,
                                    relfile=p.relfile, force_fail=key in self.fail_points,
                                    check_grid=self.spec.check_grid,
                                    check_cold=self.spec.check_cold, secant=trend)
        return self.tasks[key]

    def run(self) -> None:
        """Solve every point left (``self.counts`` follows); on Ctrl-C, :meth:`drain`."""
        built: frozenset[str] = frozenset()
        try:
            while True:
                ready = self.ready()
                while ready and len(self.inflight) < self.backend.slots:
                    key = self.pick(ready, built)
                    ready.remove(key)
                    self.state[key] = "running"
                    self.inflight[self.backend.submit(solve_point, self.task(key))] = (
                        key, self.generation)
                    built = frozenset()
                if not self.inflight:
                    return
                future = self.backend.next_finished()
                if future is None or future not in self.inflight:
                    continue
                key, generation = self.inflight.pop(future)
                outcome = self._outcome(key, future, generation)
                built = outcome.structures
                self.settle(key, outcome)
        except KeyboardInterrupt:
            self.drain()
            raise

    def drain(self) -> None:
        """Settle (write) every point whose worker has already returned its outcome; the
        others are left to a rerun."""
        while (future := self.backend.next_finished(timeout=0.0)) is not None:
            if future in self.inflight and not future.cancelled() and \
                    future.exception() is None:
                key, _ = self.inflight.pop(future)
                self.settle(key, future.result())

    def _outcome(self, key: str, future: Any, generation: int) -> PointOutcome:
        try:
            outcome: PointOutcome = future.result()
            self.deaths = 0
            return outcome
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt | SystemExit):
                raise
            if isinstance(exc, BROKEN_ERRORS) and generation == self.generation:
                self.deaths += 1
                if self.deaths >= MAX_WORKER_DEATHS:
                    raise BackendError(
                        f"the worker processes died {self.deaths} times in a row (the last "
                        f"while solving {key}); see the messages above. A script that runs "
                        "a sweep must start it under `if __name__ == '__main__':`") from None
                self.generation += 1
                self.backend.restart()
            status = ("error: the worker process died" if isinstance(exc, BROKEN_ERRORS)
                      else f"error: {type(exc).__name__}: {exc}")
            return PointOutcome(key=key, row=failed_point_row(self.tasks[key], status),
                                gait=None, result=None,
                                warm="?", fell_back=False, stages=0, iterations=0,
                                wall_time_s=math.nan, worker="?", structures=frozenset(),
                                error=repr(exc))

    def save(self, key: str, outcome: PointOutcome) -> PointOutcome:
        """Write the point's gait file atomically; a write that fails makes the point failed
        (its row says why), as a failed solve would."""
        if outcome.gait is None:
            return outcome
        mark = time.perf_counter()
        try:  # validated on the way: the file holds a gait that loads
            Gait.from_dict(outcome.gait, source=key).save(self.directory / key)
        except (OSError, GaitFileError) as exc:
            status = f"error: cannot write the gait file: {type(exc).__name__}: {exc}"
            return replace(outcome, row=failed_point_row(self.tasks[key], status), gait=None,
                           result=None, error=repr(exc))
        # the gait data is dropped once written (the report keeps every outcome)
        return replace(outcome, gait=None,
                       timings={**outcome.timings, "write_s": time.perf_counter() - mark})

    def settle(self, key: str, outcome: PointOutcome) -> None:
        outcome = self.save(key, outcome)
        self.outcomes.append(outcome)
        self.rows[key] = outcome.row
        counts = self.counts
        if outcome.success:
            self.state[key] = "ok"
            self.offers[key] = outcome.result
            counts = Counts(counts.total, counts.kept, counts.to_solve, counts.succeeded + 1,
                            counts.failed)
        else:
            self.state[key] = "failed"
            self.offers[key] = self.given.get(key)
            counts = Counts(counts.total, counts.kept, counts.to_solve, counts.succeeded,
                            counts.failed + 1)
        self.counts = counts
        write_summaries(self.spec, self.directory, self.rows, {self.points[key].subdir})
        if self.on_point is not None:
            self.on_point(self.points[key], outcome, counts)


def run_sweep(spec: SweepSpec, directory: str | os.PathLike[str], *,
              backend: Backend | None = None, workers: int | None = None,
              scheduler: str | None = None, on_start: StartFn | None = None,
              on_point: PointFn | None = None,
              fail_points: Collection[str] = (),
              seeds: Mapping[str, str | os.PathLike[str]] | None = None) -> SweepReport:
    """Run (or resume) the sweep ``spec`` in ``directory`` (see the module docstring).

    Args:
        backend: where points run; default :func:`make_backend` (``workers``, ``scheduler``).
        on_start: called once with what will be done; on_point: after every finished point.
        fail_points: testing hook: keys of points solved with ``max_iter = 1`` (they fail).
        seeds: point key -> a gait file (e.g. the same point solved on another grid) that
            warm-starts the point when it starts a chain (no parent), instead of a cold start.

    Raises :class:`SweepSpecError` (a bad grid or point option) and
    :class:`SweepSettingsError` (a directory with other settings) before any solve. On
    Ctrl-C, stops the workers and returns with ``interrupted=True``; the directory is
    consistent and a rerun resumes.
    """
    start = time.perf_counter()
    out = Path(directory)
    check_points(spec)
    prepare_directory(spec, out)
    with directory_lock(out):
        remove_leftovers(out)
        scan = scan_directory(spec, out)
        rows = {**scan.old_failed, **scan.kept}
        summaries = write_summaries(spec, out, rows)
        state = {p.key: ("kept" if p.key in scan.kept else "todo") for p in spec.points}
        counts = Counts(total=len(state), kept=len(scan.kept),
                        to_solve=len(state) - len(scan.kept))
        owned = backend is None and counts.to_solve > 0
        if owned:
            backend = make_backend(workers=workers, scheduler=scheduler)
        if on_start is not None:
            on_start(SweepStart(directory=out, counts=counts,
                                backend=backend.name if backend else "nothing to solve",
                                notes=tuple(scan.notes)))
        if counts.to_solve == 0 or backend is None:
            return SweepReport(directory=out, counts=counts,
                               wall_time_s=time.perf_counter() - start,
                               summaries=tuple(summaries), notes=tuple(scan.notes))
        driver = _Driver(spec=spec, directory=out, backend=backend,
                         fail_points=frozenset(fail_points),
                         seeds={k: str(v) for k, v in (seeds or {}).items()},
                         on_point=on_point, rows=rows,
                         state=state, counts=counts)
        interrupted = False
        try:
            driver.run()
        except KeyboardInterrupt:
            interrupted = True
        finally:
            if owned:
                backend.close(wait=not interrupted)
        return SweepReport(directory=out, counts=driver.counts,
                           wall_time_s=time.perf_counter() - start,
                           summaries=tuple(summaries), interrupted=interrupted,
                           notes=tuple(scan.notes), outcomes=tuple(driver.outcomes))
