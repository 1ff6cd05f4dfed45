"""IPOPT's linear-algebra options on the gait NLPs: MUMPS's permuting scaling, measured.

Solves the same gaits with two (or more) sets of IPOPT options in one process, alternately
(the order flips from case to case, so both sets see the same machine load), and prints per
case the wall time, the time in the stages' solves, the IPOPT iterations and the cost, then
per suite the sums and medians, their ratios to the first set, the largest relative cost
difference (the gait's cost and its check grid's; other optima of the coarse 8 + 5 stages
are listed apart) and any point that converged with the first set and failed with
another.

The options are merged over every solver of every stage (a wrapper of
:meth:`gaitopt.ocp.Transcription.solver`), over the defaults, so both sets are explicit
whatever :data:`gaitopt.ocp.solver.DEFAULT_OPTIONS` says. Default sets:
``ipopt.mumps_permuting_scaling`` 7 (MUMPS's automatic choice, MC64 matching and scaling at
every factorization; IPOPT's default) and 0 (none).

Suites (``--suite``):

* ``representative`` (default, about a minute): the five-link walk at 12 m/min in reduced and
  full coordinates on the default grid (cosine 16 + 6 checked on 24 + 8) and on uniform
  40 + 10 (checked on 60 + 15), and in full coordinates at 48 m/min;
* ``grid``: the convergence grid of ``bench/gait_grid.py`` (4 variants x 3..60 m/min,
  default settings, reduced coordinates);
* ``full``: the same speeds in full coordinates for the two ankle variants (with impulse);
  ``--speeds`` narrows it;
* ``seven``: the seven-link heel-toe walk (24 + 16 knots) at 12 and 36 m/min;
* ``sweep``: ``gaitopt sweep``'s 80 points on the paper grid (``GaitOptions.paper()`` in
  the separated form, as ``bench/sweep.py --grid paper``), in this process (no workers),
  once untimed to build the transcriptions, then ``--repeat`` times per set, alternately;
* ``ocp``: the engine's known-answer problems of ``bench/ocp.py`` at 40 and 160 intervals
  (no biped: the generic OCP).

Per solve the sets' times are compared as they come (the sums take the fastest of
``--repeat`` runs); the tables per solve (small suites) and per stage take the medians. A
set can change the iterations of the cold stages (another pivot sequence, other inertia
corrections); ``--fine-only`` applies the sets only to grids finer than the coarse 8 + 5,
so the cold stages run alike and the fine stages show the time per iteration.

The summary's "fine stages" columns sum the stages on grids finer than 8 + 5 (seconds: per
solve the median of the repetitions). ``--mumps-used`` first solves each suite's first case
once per set with MUMPS's report on and prints the ordering and scalings MUMPS effectively
used (CasADi's MUMPS has AMD, AMF, METIS and QAMD; it replaces SCOTCH and PORD by AMF).

The sets are merged over the options the stages ask for, so a set that leaves a key out
keeps the stage's value: on the full walk's fine grids that is
``gaitopt.gait.solve.stages.FULL_WALK_FINE_GRID_OPTIONS`` (``mumps_permuting_scaling`` 0), which a
set overrides only by naming the key.

Run: ``PYTHONPATH=src python bench/linear_solver.py [--suite representative grid full seven
sweep ocp] [--speeds 3 12 ...] [--repeat 1] [--only TEXT] [--fine-only] [--mumps-used]
[--set NAME:KEY=VALUE[,KEY=VALUE] ...]``
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as the gaitopt command runs

import argparse  # noqa: E402
import contextlib  # noqa: E402
import ctypes  # noqa: E402
import gc  # noqa: E402
import math  # noqa: E402
import re  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator, Mapping  # noqa: E402
from dataclasses import dataclass, replace  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from gaitopt.gait.api import solve_staged_run  # noqa: E402
from gaitopt.gait.options.gait_options import GaitOptions  # noqa: E402
from gaitopt.gait.solve.transcriptions import clear_cache  # noqa: E402
from gaitopt.ocp import Transcription  # noqa: E402
from gaitopt.ocp.solver import merge_options  # noqa: E402
from gaitopt.robot import load_model  # noqa: E402
from gaitopt.study.driver import run_sweep  # noqa: E402
from gaitopt.study.executors import inline_backend  # noqa: E402
from gaitopt.study.plan import SweepSpec  # noqa: E402
from gaitopt.study.summary import VARIANTS as SWEEP_VARIANTS  # noqa: E402

#: The option sets compared by default: name -> options (the first is the reference).
DEFAULT_SETS: dict[str, dict[str, Any]] = {
    "scaling 7": {"ipopt.mumps_permuting_scaling": 7},
    "scaling 0": {"ipopt.mumps_permuting_scaling": 0},
}
#: The sweep suite's transcription: ``bench/sweep.py``'s default (the paper's grid and
#: control model, solved in the separated form).
SWEEP_TRANSCRIPTION = "hermite-simpson-separated"
#: The convergence grid's variants (``bench/gait_grid.py``): name -> GaitOptions fields.
VARIANTS = {
    "ankle+impulse": {"ankle": True, "impulse": True},
    "ankle": {"ankle": True, "impulse": False},
    "impulse": {"ankle": False, "impulse": True},
    "plain": {"ankle": False, "impulse": False},
}
SPEEDS_M_MIN = tuple(float(s) for s in range(3, 61, 3))
#: Suites of at most this many solves also get a table per solve.
CASE_TABLE_MAX = 10
#: Relative cost difference below which two optima count as the same.
SAME_OPTIMUM = 1e-6


@dataclass(frozen=True)
class Case:
    """One solve: a label, the model and its options."""

    label: str
    model: str
    options: GaitOptions


@dataclass(frozen=True)
class Run:
    """What one solve (or sweep point) measured with one option set."""

    success: bool
    #: The costs of the full-problem grids, coarse to fine: the last two are the gait's cost
    #: (target grid) and its check grid's (the error estimate); a sweep point's cost alone.
    costs: tuple[float, ...]
    iterations: int
    solve_s: float  # the stages' solves (IPOPT and their setup), no transcription builds
    wall_s: float
    stages: tuple[tuple[str, int, float], ...] = ()  # (stage, iterations, seconds)
    #: The names of the stages on grids finer than the coarse 8 + 5 (:data:`COARSE_KNOTS`).
    fine: frozenset[str] = frozenset()


#: The most knots (mesh points, intervals + 1) a phase has on the coarse grid of the first
#: stages (8 + 5 for the walk, at most 8 in every phase of other sequences);
#: ``--fine-only`` applies the sets to finer grids only.
COARSE_KNOTS = 8
#: Whether the option sets apply to the fine grids only (set by ``--fine-only``).
FINE_ONLY = [False]


@contextlib.contextmanager
def extra_options(options: Mapping[str, Any]) -> Iterator[None]:
    """Every solver that a :class:`Transcription` creates while inside gets ``options``
    merged over the ones it is asked for (the solver cache is keyed by the merged
    options, so each set has its own solvers); with :data:`FINE_ONLY`, only those of
    grids with more than :data:`COARSE_KNOTS` knots in a phase."""
    original = Transcription.solver

    def solver(self: Transcription, asked: Mapping[str, Any]) -> Any:
        if FINE_ONLY[0] and max(m.size for m in self.mesh) <= COARSE_KNOTS:
            return original(self, asked)
        return original(self, merge_options(asked, options))

    Transcription.solver = solver  # type: ignore[method-assign,assignment]
    try:
        yield
    finally:
        Transcription.solver = original  # type: ignore[method-assign]


def solve_case(case: Case) -> Run:
    """One cold solve of ``case`` (stages, check grid) with the current options."""
    start = time.perf_counter()
    sol = solve_staged_run(case.model, case.options)
    wall = time.perf_counter() - start
    costs = tuple(c for _, c in sol.grid_costs) if sol.success else ()
    return Run(sol.success, costs, sum(s.iterations for s in sol.stages),
               sum(s.wall_time_s for s in sol.stages), wall,
               tuple((s.name, s.iterations, s.wall_time_s) for s in sol.stages),
               frozenset(s.name for s in sol.stages if max(s.knots) > COARSE_KNOTS))


def fine_stages(runs: list[Run]) -> tuple[int, float]:
    """The stages on the fine grids of one solve repeated: their iterations (of the first
    repetition) and the median over the repetitions of their summed seconds."""
    def seconds(run: Run) -> float:
        return sum(sec for stage, _, sec in run.stages if stage in run.fine)

    return (sum(it for stage, it, _ in runs[0].stages if stage in runs[0].fine),
            statistics.median(seconds(r) for r in runs))


def cases_of(suite: str, speeds: list[float] | None) -> list[Case]:
    """The solves of ``suite`` (see the module docstring)."""
    def walk(speed: float, **fields: Any) -> GaitOptions:
        return GaitOptions(speed=speed / 60.0, **fields)

    if suite == "representative":
        return [
            Case("reduced 12 m/min, default grid", "five-link", walk(12)),
            Case("reduced 12 m/min, uniform 40+10", "five-link",
                 walk(12, knots=(40, 10), knot_spacing="uniform")),
            Case("full 12 m/min, default grid", "five-link", walk(12, formulation="full")),
            Case("full 48 m/min, default grid", "five-link", walk(48, formulation="full")),
            Case("full 12 m/min, uniform 40+10", "five-link",
                 walk(12, formulation="full", knots=(40, 10), knot_spacing="uniform")),
        ]
    if suite == "grid":
        return [Case(f"reduced {v} {s:g} m/min", "five-link", walk(s, **VARIANTS[v]))
                for v in VARIANTS for s in (speeds or SPEEDS_M_MIN)]
    if suite == "full":
        return [Case(f"full {v} {s:g} m/min", "five-link",
                     walk(s, formulation="full", **VARIANTS[v]))
                for v in ("ankle+impulse", "impulse") for s in (speeds or SPEEDS_M_MIN)]
    if suite == "seven":
        return [Case(f"seven-link heel-toe 24+16 {s:g} m/min", "seven-link",
                     walk(s, gait="heel-toe", knots=(24, 16), formulation="full"))
                for s in (speeds or [12.0, 36.0])]
    raise ValueError(f"suite must be one of {SUITES}, got {suite!r}")


def alternately(labels: list[str], sets: Mapping[str, Mapping[str, Any]], repeat: int,
                measure: Callable[[str], Run], show: Callable[[str, str, Run], None],
                warm_up: Callable[[str], bool] | None = None
                ) -> dict[str, dict[str, list[Run]]]:
    """``measure(label)`` for every label, ``repeat`` times with every option set, the sets'
    order reversed from one label (and repetition) to the next; first once untimed where
    ``warm_up(label)`` (the first solve of a problem structure builds its transcriptions,
    which neither set should be charged with)."""
    runs: dict[str, dict[str, list[Run]]] = {name: {} for name in sets}
    names = list(sets)
    k = 0
    for label in labels:
        if warm_up is not None and warm_up(label):
            with extra_options(sets[names[0]]):
                measure(label)
        for _ in range(repeat):
            for name in (names if k % 2 == 0 else names[::-1]):
                with extra_options(sets[name]):
                    run = measure(label)
                runs[name].setdefault(label, []).append(run)
                show(label, name, run)
            k += 1
    return runs


def best(runs: list[Run]) -> Run:
    """The fastest of repeated runs (the least disturbed by the machine's other load)."""
    return min(runs, key=lambda r: r.wall_s)


def relative_difference(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """Largest relative difference of two solves' final costs: the gait's cost and its
    check grid's (the last two grid costs; NaN if either failed)."""
    if len(a) < 1 or len(b) < 1:
        return math.nan
    return max(abs(x - y) / abs(x) for x, y in zip(a[-2:], b[-2:], strict=False))


def coarse_difference(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """Largest relative difference of the coarser grids' costs (the 8 + 5 stages; 0 if
    none)."""
    pairs = list(zip(a[:-2], b[:-2], strict=False)) if len(a) == len(b) else []
    return max((abs(x - y) / abs(x) for x, y in pairs), default=0.0)


def ratio(x: float, ref: float) -> str:
    """``x / ref`` to three decimals, or ``-`` where the reference is zero (a suite with no
    fine-grid stage, a sweep point)."""
    return f"{x / ref:.3f}" if ref else "-"


def summary(runs: dict[str, dict[str, list[Run]]], title: str) -> None:
    """Per set: converged, sums and medians, their ratios to the first set; cost checks."""
    names = list(runs)
    ref = runs[names[0]]
    labels = list(ref)
    print(f"\n### {title}: {len(labels)} solves per set\n")
    print("| options | converged | wall sum (s) | wall median (s) | solves sum (s) | "
          "solves median (s) | iterations | wall sum / ref | solves sum / ref | "
          "iterations / ref | fine stages (s) | fine iterations | fine s / ref | "
          "fine iterations / ref |")
    print("|:---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    totals = {}
    for name in names:
        rs = [best(runs[name][label]) for label in labels]
        fine = [fine_stages(runs[name][label]) for label in labels]
        totals[name] = (sum(r.wall_s for r in rs), statistics.median(r.wall_s for r in rs),
                        sum(r.solve_s for r in rs), statistics.median(r.solve_s for r in rs),
                        sum(r.iterations for r in rs), sum(r.success for r in rs),
                        sum(s for _, s in fine), sum(it for it, _ in fine))
    w0, _, s0, _, i0, _, f0, fi0 = totals[names[0]]
    for name in names:
        w, wm, s, sm, it, ok, f, fi = totals[name]
        print(f"| {name} | {ok}/{len(labels)} | {w:.2f} | {wm:.3f} | {s:.2f} | {sm:.3f} | "
              f"{it} | {w / w0:.3f} | {s / s0:.3f} | {it / i0:.3f} | {f:.2f} | {fi} | "
              f"{ratio(f, f0)} | {ratio(fi, fi0)} |")
    for name in names[1:]:
        diffs = {label: relative_difference(best(ref[label]).costs, best(runs[name][label]).costs)
                 for label in labels}
        lost = [label for label in labels
                if best(ref[label]).success and not best(runs[name][label]).success]
        gained = [label for label in labels
                  if not best(ref[label]).success and best(runs[name][label]).success]
        finite = [d for d in diffs.values() if not math.isnan(d)]
        largest = max(finite) if finite else math.nan
        print(f"\n{name} against {names[0]}: largest relative difference of the final costs "
              f"(target and check grid) {largest:.1e} over {len(finite)} solves converged "
              "with both")
        for label, d in diffs.items():
            if not d <= SAME_OPTIMUM and not math.isnan(d):
                print(f"  other optimum: {label}: {best(ref[label]).costs} against "
                      f"{best(runs[name][label]).costs} ({d:.1e})")
        for label in labels:
            d = coarse_difference(best(ref[label]).costs, best(runs[name][label]).costs)
            if d > SAME_OPTIMUM:
                print(f"  other optimum on the coarse grid: {label}: "
                      f"{best(ref[label]).costs[:-2]} against "
                      f"{best(runs[name][label]).costs[:-2]} ({d:.1e})")
        print(f"  converged with {names[0]} only: {lost or 'none'}; "
              f"with {name} only: {gained or 'none'}")
    if len(labels) <= CASE_TABLE_MAX:
        case_table(runs, labels)
    stage_table(runs, labels)


def stage_table(runs: dict[str, dict[str, list[Run]]], labels: list[str]) -> None:
    """Per stage name: iterations (of the first repetition) and the median over the
    repetitions of its seconds, summed over the solves, per set, and the ratio of the
    seconds to the first set's."""
    names = list(runs)
    per: dict[str, dict[str, tuple[int, float]]] = {}
    for name in names:
        for label in labels:
            reps = runs[name][label]
            for stage, it, _ in reps[0].stages:
                secs = [sec for r in reps for st, _, sec in r.stages if st == stage]
                i0, s0 = per.setdefault(stage, {}).get(name, (0, 0.0))
                per[stage][name] = (i0 + it, s0 + statistics.median(secs))
    if not per:
        return
    print("\n| stage | " + " | ".join(f"{n}: iterations, s" for n in names) + " | "
          + " | ".join(f"{n} / {names[0]} (s)" for n in names[1:]) + " |")
    print("|:---|" + "---:|" * (2 * len(names) - 1))
    for stage, by in per.items():
        cells = [f"{by.get(n, (0, 0.0))[0]}, {by.get(n, (0, 0.0))[1]:.2f}" for n in names]
        ref = by.get(names[0], (0, math.nan))[1]
        ratios = [f"{by.get(n, (0, math.nan))[1] / ref:.2f}" for n in names[1:]]
        print(f"| {stage} | " + " | ".join(cells + ratios) + " |")


def case_table(runs: dict[str, dict[str, list[Run]]], labels: list[str]) -> None:
    """Per solve: iterations and the median over the repetitions of the stages' solve
    seconds per set, and their ratio to the first set's."""
    names = list(runs)
    print("\n| solve | " + " | ".join(f"{n}: iterations, solves median (s)" for n in names)
          + " | " + " | ".join(f"{n} / {names[0]}" for n in names[1:]) + " |")
    print("|:---|" + "---:|" * (2 * len(names) - 1))
    for label in labels:
        med = {n: statistics.median(r.solve_s for r in runs[n][label]) for n in names}
        cells = [f"{runs[n][label][0].iterations}, {med[n]:.3f}" for n in names]
        ratios = [f"{med[n] / med[names[0]]:.2f}" for n in names[1:]]
        print(f"| {label} | " + " | ".join(cells + ratios) + " |")


def sweep_suite(sets: Mapping[str, Mapping[str, Any]], repeat: int) -> None:
    """``gaitopt sweep``'s paper grid in this process: once untimed (builds), then each set
    ``repeat`` times alternately; per point the cost and iterations, in all the times."""
    spec = SweepSpec(model=load_model("five-link"), speeds=tuple(s / 60 for s in SPEEDS_M_MIN),
                     variants=SWEEP_VARIANTS, free_speed=False,
                     base=GaitOptions.paper(transcription=SWEEP_TRANSCRIPTION))

    def once() -> tuple[float, dict[str, Run]]:
        with tempfile.TemporaryDirectory(prefix="gaitopt-bench-linear-") as tmp:
            start = time.perf_counter()
            report = run_sweep(spec, Path(tmp) / "sweep", backend=inline_backend())
            wall = time.perf_counter() - start
        return wall, {o.key: Run(o.success, (o.row.cost,), o.iterations,
                                 o.timings.get("ipopt_s", math.nan), o.wall_time_s)
                      for o in report.outcomes}

    names = list(sets)
    with extra_options(sets[names[0]]):
        wall, _ = once()
    print(f"untimed first sweep (transcription builds): {wall:.1f} s")
    walls: dict[str, list[float]] = {name: [] for name in names}
    sweeps: dict[str, list[dict[str, Run]]] = {name: [] for name in names}
    for k in range(repeat):
        for name in (names if k % 2 == 0 else names[::-1]):
            with extra_options(sets[name]):
                wall, points = once()
            walls[name].append(wall)
            sweeps[name].append(points)
            ok = sum(p.success for p in points.values())
            print(f"  sweep {name:<12} {wall:6.2f} s, {ok}/{len(points)} converged", flush=True)
    runs = {name: {key: [s[key] for s in sweeps[name]] for key in sweeps[name][0]}
            for name in names}
    summary(runs, "paper-grid sweep, 80 points (per point: the fastest repetition)")
    print("\nwhole sweeps (s): " + "; ".join(
        f"{name}: " + ", ".join(f"{w:.2f}" for w in walls[name]) for name in names))


def solve_suite(suite: str, sets: Mapping[str, Mapping[str, Any]],
                speeds: list[float] | None, repeat: int, only: str | None = None,
                mumps_used: bool = False) -> None:
    """The solves of ``suite``, each set alternately; one line per solve, then the summary.
    The first solve of each problem structure (the options but the speed) runs once untimed
    first. ``only``: the solves whose label contains it; ``mumps_used``: first print what
    MUMPS effectively used with each set on the first solve (:func:`show_mumps_choices`)."""
    cases = {c.label: c for c in cases_of(suite, speeds) if only is None or only in c.label}
    if not cases:
        raise SystemExit(f"--only {only!r}: no solve of suite {suite} has it in its label")
    if mumps_used:
        first = next(iter(cases.values()))
        print(f"{suite}: what MUMPS used on {first.label}")
        show_mumps_choices(first, sets)
    seen: set[str] = set()

    def first_of_structure(label: str) -> bool:
        key = f"{cases[label].model} {replace(cases[label].options, speed=0.2)!r}"
        new = key not in seen
        seen.add(key)
        return new

    def show(label: str, name: str, run: Run) -> None:
        cost = f"{run.costs[-2 if len(run.costs) > 1 else -1]:.6f}" if run.costs else "FAILED"
        print(f"  {label:<40} {name:<12} {cost:>14} it {run.iterations:5d} "
              f"solves {run.solve_s:6.2f} s wall {run.wall_s:6.2f} s", flush=True)

    runs = alternately(list(cases), sets, repeat, lambda label: solve_case(cases[label]),
                       show, first_of_structure)
    summary(runs, suite)


def ocp_suite(sets: Mapping[str, Mapping[str, Any]], repeat: int) -> None:
    """The engine's known-answer problems (``bench/ocp.py``: five problems with analytic
    optima and a 5-link chain) at 40 and 160 intervals, each transcribed once (MX mode) and
    solved ``repeat`` x 2 times per set alternately (the options passed to ``solve``); per
    problem the fastest IPOPT time, the iterations, and the objective's difference."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from ocp import PROBLEMS  # the engine benchmark's problems

    from gaitopt.ocp import transcribe

    names = list(sets)
    totals = dict.fromkeys(names, 0.0)
    print("\n| problem | intervals | " + " | ".join(f"{n}: s, iterations" for n in names)
          + " | " + " | ".join(f"{n} / {names[0]}" for n in names[1:])
          + " | largest relative objective difference |")
    print("|:---|---:|" + "---:|" * (2 * len(names)))
    for problem, (build, guess, _) in PROBLEMS.items():
        for n in (40, 160):
            tr = transcribe(build(n), expand=False, compiled=None)
            fastest: dict[str, tuple[float, int, float, bool]] = {}
            for k in range(2 * repeat):
                for name in (names if k % 2 == 0 else names[::-1]):
                    res = tr.solve(guess, options=sets[name])
                    t = float(res.times["total"])
                    if name not in fastest or t < fastest[name][0]:
                        fastest[name] = (t, res.iterations, res.objective, res.success)
            ref = fastest[names[0]]
            for name in names:
                totals[name] += fastest[name][0]
            diff = max(abs(fastest[m][2] - ref[2]) / max(abs(ref[2]), 1e-300) for m in names)
            cells = [f"{fastest[m][0]:.3f}, {fastest[m][1]}"
                     + ("" if fastest[m][3] else " FAILED") for m in names]
            ratios = [f"{fastest[m][0] / ref[0]:.2f}" for m in names[1:]]
            print(f"| {problem} | {n} | " + " | ".join(cells + ratios) + f" | {diff:.1e} |",
                  flush=True)
    print("\nsum of the fastest solves (s): " + ", ".join(
        f"{name} {totals[name]:.3f} ({totals[name] / totals[names[0]]:.3f})" for name in names))


#: MUMPS's fill-reducing orderings (ICNTL(7), IPOPT's ``mumps_pivot_order``): value -> name.
ORDERINGS = {0: "AMD", 1: "given", 2: "AMF", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD",
             7: "automatic"}
#: What MUMPS reports (at ``ipopt.mumps_print_level`` 2) of the choices it made: name ->
#: pattern of the line holding the value it effectively used. (Its line "ICNTL (6) Maximum
#: transversal option" reads 0 after the analysis even where the matching was used: the
#: analysis says "Compute maximum matching (Maximum Transversal): JOB" where it is.)
MUMPS_CHOICES = {
    "ordering": re.compile(r"\(7\) Ordering option effectively used\s*=\s*(-?\d+)"),
    "scaling": re.compile(r"ICNTL\s*\(8\) Scaling effectively used\s*=\s*(-?\d+)"),
}
MATCHING = re.compile(r"Compute maximum matching \(Maximum Transversal\):\s*(\d+)")
#: MUMPS's analysis call (JOB 1) with the order N of the matrix and its stored entries NNZ.
ANALYSIS = re.compile(r"JOB, N, NNZ =\s*1\s+(\d+)\s+(\d+)")


def mumps_choices(report: str) -> dict[str, list[int]]:
    """The values MUMPS effectively used, each distinct value once in order of appearance,
    from its printed report: the ordering (ICNTL(7); an unavailable one, SCOTCH or PORD in
    CasADi's build, shows as the one used instead), the permuting scaling (the maximum
    matching's job of ICNTL(6) per analysis, 0 where none ran) and the scaling (ICNTL(8);
    -2: computed during the analysis, with the matching); and the rows of the matrices
    analysed (IPOPT's augmented system: free variables + equality rows + twice the
    inequality rows, one of them for the slacks)."""
    analyses = [part.split("Leaving analysis phase")[0]
                for part in report.split("ANALYSIS STEP")[1:]]
    choices = {name: list(dict.fromkeys(int(v) for v in pattern.findall(report)))
               for name, pattern in MUMPS_CHOICES.items()}
    matchings = [int(m.group(1)) if (m := MATCHING.search(a)) else 0 for a in analyses]
    return {"ordering": choices["ordering"], "permuting scaling": list(dict.fromkeys(matchings)),
            "scaling": choices["scaling"],
            "rows": list(dict.fromkeys(int(n) for n, _ in ANALYSIS.findall(report)))}


def flush_fortran() -> None:
    """Flush the output buffers of every Fortran runtime (libgfortran) in the process, where
    MUMPS's report waits otherwise (standard output is buffered when it is not a terminal)."""
    with open("/proc/self/maps") as maps:
        libraries = {line.split()[-1] for line in maps if "libgfortran" in line}
    for library in sorted(libraries):
        flush = getattr(ctypes.CDLL(library), "_gfortran_flush_i4", None)
        if flush is not None:
            flush(None)  # no unit: all of them


@contextlib.contextmanager
def captured_fd1() -> Iterator[list[str]]:
    """What the process writes to its standard output (file descriptor 1, where MUMPS
    prints) while inside: the list gets the text on leaving."""
    out: list[str] = []
    sys.stdout.flush()
    saved = os.dup(1)
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        os.dup2(tmp.fileno(), 1)
        try:
            yield out
        finally:
            sys.stdout.flush()
            flush_fortran()
            os.dup2(saved, 1)
            os.close(saved)
            tmp.seek(0)
            out.append(tmp.read().decode(errors="replace"))


def show_mumps_choices(case: Case, sets: Mapping[str, Mapping[str, Any]]) -> None:
    """Solve ``case`` once per set (untimed) with MUMPS's report on and print the ordering
    and scalings it effectively used in the stages the sets apply to. The transcriptions
    (and their solvers, whose MUMPS instances report again when destroyed) are dropped
    after each: the suite's first solve of a structure builds them again untimed."""
    for name, options in sets.items():
        with captured_fd1() as out:
            with extra_options({**options, "ipopt.mumps_print_level": 2}):
                solve_case(case)
            clear_cache()
            gc.collect()  # the solvers' MUMPS instances report their end while captured
        used = mumps_choices(out[0])
        orders = ", ".join(f"{ORDERINGS.get(v, v)} ({v})" for v in used["ordering"])
        permuting = ", ".join(map(str, used["permuting scaling"]))
        scaling = ", ".join(map(str, used["scaling"]))
        rows = ", ".join(f"{n:,}" for n in used["rows"])
        print(f"  {name:<16} MUMPS used: ordering {orders or '?'}; permuting scaling "
              f"{permuting or '?'}; scaling {scaling or '?'} (rows {rows or '?'})", flush=True)


SUITES = ("representative", "grid", "full", "seven", "sweep", "ocp")


def parse_set(text: str) -> tuple[str, dict[str, Any]]:
    """``NAME:KEY=VALUE[,KEY=VALUE...]`` -> (NAME, options); values as int, float or text."""
    name, sep, rest = text.partition(":")
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"--set {text!r}: expected NAME:KEY=VALUE[,...]")
    options: dict[str, Any] = {}
    for item in filter(None, rest.split(",")):
        key, eq, value = item.partition("=")
        if not eq:
            raise argparse.ArgumentTypeError(f"--set {text!r}: {item!r} is not KEY=VALUE")
        parsed: Any = value
        for kind in (int, float):
            try:
                parsed = kind(value)
                break
            except ValueError:
                pass
        options[key if key.startswith("ipopt.") else f"ipopt.{key}"] = parsed
    return name, options


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--suite", nargs="+", choices=SUITES, default=["representative"])
    parser.add_argument("--speeds", type=float, nargs="+", help="m/min (grid, full, seven)")
    parser.add_argument("--repeat", type=int, default=1,
                        help="solves per case and set (the sums count the fastest, the "
                             "tables per solve and per stage the medians)")
    parser.add_argument("--set", dest="sets", type=parse_set, action="append",
                        help="an option set NAME:KEY=VALUE[,...] (repeat; the first is the "
                             "reference; default: mumps_permuting_scaling 7 and 0)")
    parser.add_argument("--only", help="only the solves whose label contains this text, "
                                       "e.g. 'uniform 40+10' (grid, full, seven, "
                                       "representative)")
    parser.add_argument("--mumps-used", action="store_true",
                        help="first solve each suite's first case once per set with MUMPS's "
                             "report on and print the ordering and scalings it effectively "
                             "used (an unavailable ordering falls back to another; grid, "
                             "full, seven, representative)")
    parser.add_argument("--fine-only", action="store_true",
                        help="apply the sets only to grids finer than the coarse 8+5 (the "
                             "coarse stages then run alike)")
    args = parser.parse_args(argv)
    FINE_ONLY[0] = args.fine_only
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1, got {args.repeat}")
    sets = dict(args.sets) if args.sets else DEFAULT_SETS
    if len(sets) < 2:
        parser.error("--set: give at least two option sets")
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"{time.strftime('%Y-%m-%d %H:%M', time.gmtime())} UTC, load average {load} "
          f"({os.cpu_count()} cores); option sets: {sets}"
          + (" on the fine grids only" if args.fine_only else ""))
    for suite in args.suite:
        if suite == "sweep":
            sweep_suite(sets, args.repeat)
            continue
        if suite == "ocp":
            ocp_suite(sets, args.repeat)
            continue
        solve_suite(suite, sets, args.speeds, args.repeat, args.only, args.mumps_used)
    print(f"\nload average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
