"""The cost study: which cost puts a model's optimal walk where people walk (docs/costs.md).

For every model asked for, the speed-free optimal walk of each *case*: the paper's cost, the
mechanical cost of transport (``work``) and the metabolic cost at each resting power
``P_rest`` (W/kg) of a list (the human value, about 1.2-1.5 W/kg, among them). Each case is a
small sweep (:mod:`gaitopt.study.plan`: the walk at the case's start speed solved cold, the
speed-free optimum warm-started from it) in its own folder, so everything the sweeps do holds
here too: points written atomically as they finish, resumable, refused when the folder holds
other settings. The start speed is given, or by default each model's paper case starts at
12 m/min and its other cases at the speed of the paper case's optimum rounded to 3 m/min
(:mod:`gaitopt.study.cost_start`).

The problems have several local optima, and the speed-free optimum reached from the 12 m/min
walk is not always the lowest (metabolic cost, 4.8 W/kg: 42.2 m/min with 0.39 m steps, 1.8 %
above the 43.9 m/min, 0.26 m optimum of the staged solve). So each case is reached at least
two ways and the lowest optimum is the case's result, by the model's *strategy*
(:meth:`CostStudySpec.strategy_of`): ``cold`` (the paper's walk), the sweep and the *direct*
solve, the staged solve of ``gaitopt solve --speed free`` (the paper's cost through its
stages, then the case's cost); ``continuation`` (a model with feet, whose cold solves of the
costs of transport take minutes each), each case from the previous case's optimum
(:mod:`gaitopt.study.cost_continuation`). The table keeps which start won and the next one's
cost. Each case's lowest optimum is then refined until its error estimates are within
``accuracy`` (1 %; :mod:`gaitopt.study.cost_accuracy`), and the table reports that gait::

    DIR/cost_study.json                      the study's settings (written first)
    DIR/costs.csv                            one row per (model, case): the speed-free optimum
    DIR/<model>/<case>/sweep.json, summary.csv, gaits/<variant>/...   each case's sweep
    DIR/<model>/<case>/direct.gait.json      the direct solve (written atomically; kept on a
                                             rerun when it matches the case's options)
    DIR/<model>/<case>/from-<case>/...       the continuation's sweep from the previous case
    DIR/<model>/<case>/accurate.gait.json    the optimum refined to the accuracy (and
                                             accurate.json: what it started from)
    DIR/report/report.html                   figure, table, findings (gaitopt.viz.cost_report)

``<model>`` is the model's name, ``<case>`` ``paper``, ``work`` or ``metabolic-rest-1.2``
(the resting power in W/kg). The formulation of a model is ``reduced`` (the paper's) when the
model is the five-link biped that formulation describes and ``full`` otherwise (a model with
feet or more links), unless one is asked for; its gait is the paper's walk, or the heel-toe
walk for a model with feet (two contact points on a foot link).

The distance of an optimum from human walking is
``d = sqrt((v / v_h - 1)^2 + (L / L_h - 1)^2)`` with ``v_h = 80 m/min`` and ``L_h = 0.75 m``
(the paper's reference, :data:`gaitopt.study.findings.HUMAN_OPTIMAL_SPEED_M_MIN` and
:data:`~gaitopt.study.findings.HUMAN_STEP_LENGTH`): 0 where people walk, sqrt(2) = 1.41 for
standing still, 0.5 at half people's speed with people's step.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from gaitopt import __version__
from gaitopt.fileio import write_text_atomic
from gaitopt.gait.formulations.cost import smoothing_record
from gaitopt.gait.options.gait_options import (
    FORMULATIONS,
    KNOT_SPACINGS,
    Formulation,
    GaitOptions,
    KnotSpacing,
)
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.gait.solve.refinement import diverging_text
from gaitopt.robot.biped import has_reduced_shape
from gaitopt.robot.model import RobotModel
from gaitopt.study.cost_accuracy import (
    ACCURATE_FILE,
    AccuracyOutcome,
    AccuracyTask,
    accuracy_failure,
    accurate_gait,
    estimate_of,
    save_accurate,
    solve_accurate,
)
from gaitopt.study.cost_continuation import free_candidates
from gaitopt.study.cost_start import AUTO_START, StartChoice, auto_start_speed, given_start
from gaitopt.study.cost_table import CostRow
from gaitopt.study.cost_table import CostStudyError as CostStudyError
from gaitopt.study.executors import Backend
from gaitopt.study.findings import HUMAN_OPTIMAL_SPEED_M_MIN, HUMAN_STEP_LENGTH
from gaitopt.study.plan import START_SPEED, SweepPoint, SweepSpec
from gaitopt.study.summary import (
    SUMMARY_FILE,
    VARIANTS,
    SummaryError,
    read_summary,
    rows_of,
)
from gaitopt.study.worker import PointOutcome, PointTask, gait_file_matches, solve_point

CostStudyFormulation = Literal["auto", "reduced", "full"]

#: Resting powers (W/kg) of the metabolic cases by default: none, half, the human value
#: (adults at rest, about 1.2 W/kg), twice and four times it.
DEFAULT_RESTING_POWERS: tuple[float, ...] = (0.0, 0.6, 1.2, 2.4, 4.8)
#: People's resting metabolic power (W/kg): the band marked in the figure and used by the
#: findings (docs/costs.md gives the sources).
HUMAN_RESTING_POWER: tuple[float, float] = (1.2, 1.5)
#: Knots per phase of each case by gait (``knots=None``): the paper's 8 + 5 for its walk;
#: for the heel-toe walk 24 + 16 (phase 0, the others at least; docs/feet.md's grid, on which
#: the seven-link model's costs were measured).
DEFAULT_KNOTS: dict[str, tuple[int, int]] = {"walk": (8, 5), "heel-toe": (24, 16)}
#: IPOPT's iteration limit per stage of every solve of the study (``GaitOptions.max_iter``,
#: 1000 elsewhere). The smoothing stages of the costs of transport take hundreds to thousands
#: of iterations on the model with feet (bang-bang torques): at 75 m/min on cosine 24 + 16
#: knots the metabolic cost's last stage stopped at 1000 and converged in 2071 (docs/feet.md).
#: A solve that converges within 1000 iterations is the same with this limit.
STUDY_MAX_ITER = 3000
#: How each model's cases are started (``CostStudySpec.strategy``; ``auto`` chooses by the
#: model's gait, :meth:`CostStudySpec.strategy_of`): ``cold``, each case's sweep from a cold
#: start and its direct staged solve (cold); ``continuation``, each case started from the
#: optima of the case solved before it (:func:`case_neighbour`), no direct solve.
STRATEGIES = ("cold", "continuation")
AUTO_STRATEGY = "auto"
#: The relative accuracy each case's optimum is refined to by the accuracy pass
#: (:mod:`gaitopt.study.cost_accuracy`): 1 %, the accuracy of ``gaitopt solve``
#: (``GaitOptions.accuracy``).
ACCURACY = 0.01
#: Whether the accuracy pass runs (``CostStudySpec.accuracy_pass``): ``auto`` for the models
#: whose gait is in :data:`AUTO_ACCURACY_GAITS`, ``on`` for every model, ``off`` for none.
ACCURACY_PASSES = ("auto", "on", "off")
#: The gaits whose cases the accuracy pass refines by default: the heel-toe walk (a model with
#: feet; measured 2026-12-03 with the check grid's smoothing ladder, docs/costs.md). Not the
#: paper's walk: on the five-link biped the pass took the study from 43 s to 667 s and its
#: costs of transport still ended 2.4-34 % off at 36 + 12 knots (``--accuracy-pass`` runs it).
AUTO_ACCURACY_GAITS = frozenset({"heel-toe"})
COST_STUDY_FILE = "cost_study.json"
COST_STUDY_FORMAT = "gaitopt.cost-study"
DIRECT_FILE = "direct.gait.json"
#: How a case's optimum was reached (the ``start`` column): warm from the sweep's cold start
#: (``from {speed} m/min``, the case's start speed) or by the direct staged solve.
STARTS = ("from {speed:g} m/min", "direct")


@dataclass(frozen=True)
class CostCase:
    """One cost: ``paper``, ``work`` or ``metabolic`` with its resting power (W/kg)."""

    cost: str
    resting_power: float | None = None

    @property
    def tag(self) -> str:
        """The case's folder name: ``paper``, ``work``, ``metabolic-rest-1.2``."""
        if self.cost != "metabolic":
            return self.cost
        return f"metabolic-rest-{self.resting_power:g}"

    @property
    def label(self) -> str:
        if self.cost != "metabolic":
            return {"paper": "paper (u'u per metre)",
                    "work": "work (mechanical cost of transport)"}[self.cost]
        return f"metabolic, resting {self.resting_power:g} W/kg"

    def options(self) -> dict[str, Any]:
        """The :class:`GaitOptions` fields of this case."""
        if self.cost == "metabolic":
            return {"cost": "metabolic", "resting_power": self.resting_power}
        return {"cost": self.cost}


@dataclass(frozen=True)
class CostSweep:
    """One (model, case) of the study: its folder (relative to the study directory), its
    formulation and its sweep."""

    model: str
    case: CostCase
    formulation: str
    subdir: str
    spec: SweepSpec

    @property
    def free_point(self) -> SweepPoint:
        return next(p for p in self.spec.points if p.speed is None)

    def direct_task(self) -> PointTask:
        """The direct (staged, cold) solve of the speed-free optimum, as a sweep worker's
        task: :func:`gaitopt.study.worker.solve_point` runs it anywhere."""
        point = self.free_point
        return PointTask(key=f"{self.subdir}/{DIRECT_FILE}", model=self.spec.model_of(point),
                         options=self.spec.options(point), variant=point.variant,
                         speed_mode="free", structure=point.structure, warm=None,
                         relfile=DIRECT_FILE)


@dataclass(frozen=True, kw_only=True)
class CostStudySpec:
    """What the cost study solves (SI units; resting powers W/kg).

    ``costs`` a subset of paper, work, metabolic (the metabolic cost once per resting power);
    ``regularization`` the weight of ``int sum (u / u_max)^2 dt / T`` added to the work and
    metabolic costs (``GaitOptions.cost_regularization``); ``gait`` ``auto`` (see
    :meth:`gait_of`), ``walk`` or ``heel-toe``; ``knot_spacing`` that of every solve
    (``cosine`` or ``uniform``); ``start_speed`` (m/s) the speed of each case's
    cold start, from which its speed-free optimum is warm-started, or ``"auto"`` (the
    default): each model's paper case starts at 12 m/min and its other cases at the speed of
    the paper case's optimum rounded to 3 m/min (:mod:`gaitopt.study.cost_start`; 12 m/min
    for the five-link biped, 75 m/min for the seven-link model with feet);
    ``swing_clearance`` (m) the least mid-swing height of the swing tip in every case
    (``GaitOptions.swing_clearance``; None: no such constraint); ``formulation`` ``auto``
    (see the module docstring), ``reduced`` or ``full``; ``variant`` one of
    :data:`gaitopt.study.summary.VARIANTS`; ``knots`` per phase, or None: by each model's
    gait (:data:`DEFAULT_KNOTS`, :meth:`knots_of`).
    """

    models: tuple[RobotModel, ...]
    costs: tuple[str, ...] = ("paper", "work", "metabolic")
    resting_powers: tuple[float, ...] = DEFAULT_RESTING_POWERS
    regularization: float = 0.0
    swing_clearance: float | None = None
    formulation: CostStudyFormulation = "auto"
    gait: str = "auto"
    variant: str = "ankle+impulse"
    knots: tuple[int, int] | None = None
    start_speed: float | str = AUTO_START
    knot_spacing: KnotSpacing = "cosine"
    strategy: str = AUTO_STRATEGY
    accuracy: float | None = ACCURACY
    accuracy_pass: str = "auto"

    def __post_init__(self) -> None:
        if not self.models:
            raise CostStudyError("models: at least one model is needed")
        if self.knot_spacing not in KNOT_SPACINGS:
            raise CostStudyError(f"knot_spacing = {self.knot_spacing!r}: must be one of "
                                 f"{', '.join(KNOT_SPACINGS)}")
        if self.start_speed != AUTO_START and not (
                isinstance(self.start_speed, float | int)
                and not isinstance(self.start_speed, bool)
                and math.isfinite(self.start_speed) and 0.0 < self.start_speed <= 5.0):
            raise CostStudyError(f"start_speed = {self.start_speed!r} m/s: must be "
                                 f"{AUTO_START!r} or lie in (0, 5] m/s (0-300 m/min)")
        names = [m.name for m in self.models]
        if len(set(names)) != len(names):
            raise CostStudyError(f"models: two models share a name ({', '.join(names)}); "
                                 "each model's results go to a folder named after it")
        for name in names:
            if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]*", name):
                raise CostStudyError(f"models: the name {name!r} cannot name a folder (letters, "
                                     "digits, '_', '.', '+', '-')")
        unknown = [c for c in self.costs if c not in ("paper", "work", "metabolic")]
        if unknown or not self.costs or len(set(self.costs)) != len(self.costs):
            raise CostStudyError(f"costs: {', '.join(self.costs) or 'none'}; allowed: each of "
                                 "paper, work, metabolic at most once, at least one")
        if "metabolic" in self.costs:
            if not self.resting_powers:
                raise CostStudyError("resting powers: at least one for the metabolic cost")
            for p in self.resting_powers:
                if not (math.isfinite(p) and p >= 0.0):
                    raise CostStudyError(f"resting powers: {p!r} W/kg; allowed: finite, >= 0")
            if len(set(self.resting_powers)) != len(self.resting_powers):
                raise CostStudyError("resting powers: each value at most once")
        if not (math.isfinite(self.regularization) and self.regularization >= 0.0):
            raise CostStudyError(f"regularization: {self.regularization!r}; allowed: >= 0")
        if self.swing_clearance is not None and not (math.isfinite(self.swing_clearance)
                                                     and self.swing_clearance >= 0.0):
            raise CostStudyError(f"swing clearance: {self.swing_clearance!r} m; allowed: >= 0")
        if self.formulation not in ("auto", *FORMULATIONS):
            raise CostStudyError(f"formulation: {self.formulation!r}; allowed: "
                                 f"{', '.join(('auto', *FORMULATIONS))}")
        if self.gait not in ("auto", "walk", "heel-toe"):
            raise CostStudyError(f"gait: {self.gait!r}; allowed: auto, walk, heel-toe")
        if self.variant not in VARIANTS:
            raise CostStudyError(f"variant: {self.variant!r}; allowed: {', '.join(VARIANTS)}")
        if self.strategy not in (AUTO_STRATEGY, *STRATEGIES):
            raise CostStudyError(f"strategy: {self.strategy!r}; allowed: "
                                 f"{', '.join((AUTO_STRATEGY, *STRATEGIES))}")
        if self.accuracy is not None and not (math.isfinite(self.accuracy)
                                              and 0.0 < self.accuracy < 1.0):
            raise CostStudyError(f"accuracy: {self.accuracy!r}; allowed: in (0, 1) (0.01 for "
                                 "1 %), or None for no accuracy pass")
        if self.accuracy_pass not in ACCURACY_PASSES:
            raise CostStudyError(f"accuracy_pass: {self.accuracy_pass!r}; allowed: "
                                 f"{', '.join(ACCURACY_PASSES)}")

    def accuracy_of(self, model: RobotModel | str) -> float | None:
        """The accuracy ``model``'s cases are refined to (by name or model), or None where
        the accuracy pass does not run: ``accuracy`` with ``accuracy_pass`` ``on``, or
        ``auto`` and the model's gait in :data:`AUTO_ACCURACY_GAITS`."""
        if isinstance(model, str):
            model = next(m for m in self.models if m.name == model)
        if self.accuracy is None or self.accuracy_pass == "off":
            return None
        if self.accuracy_pass == "auto" and self.gait_of(model) not in AUTO_ACCURACY_GAITS:
            return None
        return self.accuracy

    @property
    def refines(self) -> bool:
        """Whether the accuracy pass runs for any model."""
        return any(self.accuracy_of(m) is not None for m in self.models)

    @property
    def cases(self) -> tuple[CostCase, ...]:
        """The cases in study order: paper, work, then metabolic by ascending resting power."""
        out = [CostCase(c) for c in ("paper", "work") if c in self.costs]
        if "metabolic" in self.costs:
            out += [CostCase("metabolic", p) for p in sorted(self.resting_powers)]
        return tuple(out)

    def formulation_of(self, model: RobotModel) -> Formulation:
        """``reduced`` or ``full`` for ``model`` (see the module docstring)."""
        if self.formulation != "auto":
            return self.formulation
        return "reduced" if has_reduced_shape(model) else "full"

    def gait_of(self, model: RobotModel) -> str:
        """``walk`` or ``heel-toe`` for ``model``: with ``gait="auto"``, ``heel-toe`` when the
        link of the model's first contact carries two contact points (a foot with heel and
        toe), else the paper's ``walk``."""
        if self.gait != "auto":
            return self.gait
        link = model.contacts[0].link if model.contacts else None
        on_link = [c for c in model.contacts if c.link == link]
        return "heel-toe" if len(on_link) == 2 else "walk"

    def knots_of(self, model: RobotModel) -> tuple[int, int]:
        """The knots of ``model``'s cases: ``knots``, or by its gait (:data:`DEFAULT_KNOTS`)."""
        return self.knots if self.knots is not None else DEFAULT_KNOTS[self.gait_of(model)]

    def strategy_of(self, model: RobotModel) -> str:
        """``cold`` or ``continuation`` for ``model`` (:data:`STRATEGIES`): with
        ``strategy="auto"``, ``continuation`` for the heel-toe walk (a model with feet, whose
        cold staged solves of the costs of transport take 10-15 minutes each) and ``cold``
        for the paper's walk."""
        if self.strategy != AUTO_STRATEGY:
            return self.strategy
        return "continuation" if self.gait_of(model) == "heel-toe" else "cold"

    def solve_order(self, model: RobotModel) -> tuple[CostCase, ...]:
        """The cases of ``model`` in the order they are solved (with the automatic start the
        paper case is solved first, as the reference, and is not among them): ``cold``, the
        study order (:attr:`cases`); ``continuation``, the paper case, the metabolic cases
        by descending resting power (the largest walks fastest, nearest the start speed, the
        paper optimum's), then the work case (started from the metabolic case at the least
        resting power, the nearest in form: both price positive work)."""
        cases = [c for c in self.cases if not (self.auto_start and c.cost == "paper")]
        if self.strategy_of(model) == "cold":
            return tuple(cases)
        rank = {"paper": 0, "metabolic": 1, "work": 2}
        return tuple(sorted(cases, key=lambda c: (rank[c.cost], -(c.resting_power or 0.0))))

    @property
    def auto_start(self) -> bool:
        """Whether each model's start speed comes from its paper case's optimum."""
        return self.start_speed == AUTO_START

    def sweep_of(self, model: RobotModel, case: CostCase, start_speed: float) -> CostSweep:
        """The sweep of one (model, case): the walk at ``start_speed`` (m/s), solved cold, and
        the speed-free optimum warm-started from it."""
        extra: dict[str, Any] = ({"cost_regularization": self.regularization}
                                 if self.regularization > 0.0 and case.cost != "paper" else {})
        if self.swing_clearance is not None:
            extra["swing_clearance"] = self.swing_clearance
        if self.gait_of(model) != "walk":
            extra["gait"] = self.gait_of(model)
        formulation = self.formulation_of(model)
        base = GaitOptions(knots=self.knots_of(model), formulation=formulation,
                           knot_spacing=self.knot_spacing, max_iter=STUDY_MAX_ITER,
                           **case.options(), **extra)
        spec = SweepSpec(model=model, speeds=(start_speed,), variants=(self.variant,),
                         free_speed=True, base=base)
        return CostSweep(model=model.name, case=case, formulation=formulation,
                         subdir=f"{model.name}/{case.tag}", spec=spec)

    def reference_sweep(self, model: RobotModel) -> CostSweep:
        """With the automatic start: the paper case's sweep of ``model`` from 12 m/min, whose
        speed-free optimum sets the start of the model's other cases (solved first, also when
        the paper case is not among ``costs``; its row is then not in the table)."""
        return self.sweep_of(model, CostCase("paper"), START_SPEED)

    def start_of(self, model: RobotModel, case: CostCase,
                 starts: Mapping[str, StartChoice] | None) -> float:
        """The start speed (m/s) of one (model, case): ``start_speed``; with the automatic
        start 12 m/min for the paper case and ``starts[model.name]`` for the others."""
        if not self.auto_start:
            return float(self.start_speed)
        if case.cost == "paper":
            return START_SPEED
        if starts is None or model.name not in starts:
            raise CostStudyError(f"start_speed = {AUTO_START!r}: the start speed of model "
                                 f"{model.name!r} comes from its paper case, not solved yet")
        return starts[model.name].speed

    def sweeps(self, starts: Mapping[str, StartChoice] | None = None
               ) -> tuple[CostSweep, ...]:
        """Every (model, case) sweep (:meth:`sweep_of`) at its start speed (:meth:`start_of`;
        ``starts`` the automatic start of each model, :func:`start_choices`)."""
        return tuple(self.sweep_of(model, case, self.start_of(model, case, starts))
                     for model in self.models for case in self.cases)

    def settings(self, starts: Mapping[str, StartChoice] | None = None) -> dict[str, Any]:
        """The study's settings (``cost_study.json``). ``start_rule`` is ``auto`` or
        ``given`` (then ``start_speed_m_min``); ``starts`` the start speed each model's
        non-paper cases used, as far as known (:class:`StartChoice`), under
        ``models[i].start`` (None while unknown)."""
        models = []
        for m in self.models:
            choice = (given_start(float(self.start_speed)) if not self.auto_start
                      else None if starts is None else starts.get(m.name))
            models.append({"name": m.name, "content_hash": m.content_hash(),
                           "formulation": self.formulation_of(m), "gait": self.gait_of(m),
                           "knots": list(self.knots_of(m)),
                           "strategy": self.strategy_of(m),
                           "accuracy": self.accuracy_of(m),
                           "start": None if choice is None else choice.to_dict()})
        return {"format": COST_STUDY_FORMAT, "version": 1, "gaitopt_version": __version__,
                "models": models,
                "cases": [c.tag for c in self.cases], "regularization": self.regularization,
                "swing_clearance": self.swing_clearance,
                "variant": self.variant, "max_iter": STUDY_MAX_ITER,
                "knots": None if self.knots is None else list(self.knots),
                "start_rule": AUTO_START if self.auto_start else "given",
                "start_speed_m_min": (None if self.auto_start
                                      else float(self.start_speed) * 60.0),
                "knot_spacing": self.knot_spacing,
                "accuracy": self.accuracy, "accuracy_pass": self.accuracy_pass,
                "human": {"speed_m_min": HUMAN_OPTIMAL_SPEED_M_MIN,
                          "step_length": HUMAN_STEP_LENGTH,
                          "resting_power_w_kg": list(HUMAN_RESTING_POWER)}}


def write_settings(spec: CostStudySpec, directory: str | os.PathLike[str],
                   starts: Mapping[str, StartChoice] | None = None) -> Path:
    """Write ``cost_study.json`` atomically (it marks the folder as a cost study); ``starts``
    the start speeds known so far (:meth:`CostStudySpec.settings`)."""
    path = Path(directory) / COST_STUDY_FILE
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(spec.settings(starts), indent=2) + "\n")
    return path


def start_choice(spec: CostStudySpec, model: RobotModel,
                 directory: str | os.PathLike[str]) -> StartChoice:
    """The start speed of ``model``'s non-paper cases: the given one, or with the automatic
    start the one :func:`~gaitopt.study.cost_start.auto_start_speed` takes from the paper
    case's sweep in ``directory`` (its ``summary.csv``; 12 m/min if it is not there)."""
    if not spec.auto_start:
        return given_start(float(spec.start_speed))
    ref = spec.reference_sweep(model)
    try:
        rows = read_summary(Path(directory) / ref.subdir / SUMMARY_FILE)
    except SummaryError:
        rows = []
    return auto_start_speed(rows, spec.variant, ref.spec.base.speed_bounds[1])


def start_choices(spec: CostStudySpec,
                  directory: str | os.PathLike[str]) -> dict[str, StartChoice]:
    """:func:`start_choice` of every model, by name."""
    return {m.name: start_choice(spec, m, directory) for m in spec.models}


def direct_gait(sweep: CostSweep, directory: str | os.PathLike[str]) -> Gait | None:
    """The case's direct solve if its file exists, loads, converged and matches the case's
    options and model; else None (it is to be solved)."""
    path = Path(directory) / sweep.subdir / DIRECT_FILE
    if not path.exists():
        return None
    try:
        gait = Gait.load(path)
    except GaitFileError:
        return None
    task = sweep.direct_task()
    return None if gait_file_matches(gait, task.model, task.options) else gait


def save_direct(sweep: CostSweep, directory: str | os.PathLike[str],
                outcome: PointOutcome) -> Path | None:
    """Write a direct solve's gait file atomically (None, nothing written, if it failed)."""
    if not outcome.success or outcome.gait is None:
        return None
    path = Path(directory) / sweep.subdir / DIRECT_FILE
    Gait.from_dict(outcome.gait, source=str(path)).save(path)
    return path


DirectFn = Callable[[CostSweep, "PointOutcome | None", "Path | None"], None]


def direct_sweeps(spec: CostStudySpec, starts: Mapping[str, StartChoice] | None
                  ) -> tuple[CostSweep, ...]:
    """The cases that get a direct solve: those of the models of the ``cold`` strategy
    (:meth:`CostStudySpec.strategy_of`; a ``continuation`` model's second start is its
    neighbour's optimum instead, :mod:`gaitopt.study.cost_continuation`)."""
    cold = {m.name for m in spec.models if spec.strategy_of(m) == "cold"}
    return tuple(s for s in spec.sweeps(starts) if s.model in cold)


def winner_of(sweep: CostSweep, directory: str | os.PathLike[str], variant: str
              ) -> tuple[float, str, dict[str, Any], float] | None:
    """The lowest converged speed-free optimum of one case over all its starts: the case's
    sweep, its starts from neighbours (:func:`~gaitopt.study.cost_continuation.
    free_candidates`) and its direct solve; ``(cost, start, fields, other cost)`` with
    ``fields`` the row's status, speed (m/min), step (m), step time (s) and ``file``
    (relative to the study folder), ``other`` the next lowest cost (NaN if none); None
    when no start converged."""
    top = Path(directory)
    case_folder = top / sweep.subdir
    candidates: list[tuple[float, str, dict[str, Any]]] = []
    for cost, where, r in free_candidates(case_folder, variant):
        start = (STARTS[0].format(speed=round(sweep.spec.speeds[0] * 60.0, 2)) if not where
                 else f"from {where.removeprefix('from-')}")
        sub = f"{sweep.subdir}/{where}" if where else sweep.subdir
        candidates.append((cost, start, {
            "status": r.status, "speed_m_min": r.speed_m_min, "step_length": r.step_length,
            "step_time": r.step_time, "file": f"{sub}/{r.file}"}))
    gait = direct_gait(sweep, top)
    if gait is not None:
        candidates.append((gait.cost_value, STARTS[1], {
            "status": gait.status, "speed_m_min": gait.speed * 60.0,
            "step_length": gait.step_length, "step_time": gait.step_time,
            "file": f"{sweep.subdir}/{DIRECT_FILE}"}))
    if not candidates:
        return None
    candidates.sort(key=lambda c: c[0])
    value, start, fields = candidates[0]
    other = candidates[1][0] if len(candidates) > 1 else math.nan
    return value, start, fields, other


AccuracyFn = Callable[[CostSweep, "AccuracyOutcome | None", "Path | None"], None]


def accuracy_tasks(spec: CostStudySpec, directory: str | os.PathLike[str]
                   ) -> list[tuple[CostSweep, AccuracyTask]]:
    """The accuracy pass of every case whose optimum has no accurate gait yet
    (:mod:`gaitopt.study.cost_accuracy`) of the models it runs for
    (:meth:`CostStudySpec.accuracy_of`)."""
    top = Path(directory)
    out = []
    for sweep in spec.sweeps(start_choices(spec, top)):
        accuracy = spec.accuracy_of(sweep.model)
        if accuracy is None:
            continue
        found = winner_of(sweep, top, spec.variant)
        if found is None:
            continue
        value, _, fields, _ = found
        if accurate_gait(top / sweep.subdir, fields["file"], value) is not None:
            continue
        if smoothing_share(top / fields["file"]) > SMOOTHING_SETS_SPEED:
            continue  # no optimal speed of its own: a finer grid would refine the smoothing's
        try:
            text = (top / fields["file"]).read_text(encoding="utf-8")
        except OSError:
            continue
        options = sweep.spec.options(sweep.free_point).replace(accuracy=accuracy)
        out.append((sweep, AccuracyTask(key=sweep.subdir, model=sweep.spec.model_of(
            sweep.free_point), options=options, text=text, source=fields["file"],
            cost=value)))
    return out


def run_accuracy(spec: CostStudySpec, directory: str | os.PathLike[str], backend: Backend,
                 on_done: AccuracyFn | None = None) -> tuple[int, int]:
    """Run the accuracy pass of every case that needs one, all at once on ``backend`` (each
    gait written here, atomically, as it arrives); ``on_done(sweep, outcome, path)`` after
    each. Returns ``(solved, failed)``."""
    top = Path(directory)
    tasks = accuracy_tasks(spec, top)
    pending = {backend.submit(solve_accurate, task): (sweep, task) for sweep, task in tasks}
    solved = failed = 0
    while pending:
        future = backend.next_finished()
        if future is None or future not in pending:
            continue
        sweep, task = pending.pop(future)
        try:
            outcome: AccuracyOutcome | None = future.result()
        except Exception:  # noqa: BLE001  (a dead worker: the case keeps its grid's optimum)
            outcome = None
        path = save_accurate(top / sweep.subdir, task, outcome) if outcome else None
        solved, failed = (solved + 1, failed) if path is not None else (solved, failed + 1)
        if on_done is not None:
            on_done(sweep, outcome, path)
    return solved, failed


def run_direct_solves(spec: CostStudySpec, directory: str | os.PathLike[str],
                      backend: Backend, on_done: DirectFn | None = None) -> tuple[int, int, int]:
    """Solve every case's direct optimum not kept from an earlier run, all at once on
    ``backend`` (its workers write nothing; each gait file is written here, atomically, as it
    arrives). ``on_done(sweep, outcome, path)`` after each (``outcome`` None if the worker
    raised; ``path`` None if nothing was written). Returns ``(kept, solved, failed)``."""
    sweeps = direct_sweeps(spec, start_choices(spec, directory))
    todo = [s for s in sweeps if direct_gait(s, directory) is None]
    pending = {backend.submit(solve_point, s.direct_task()): s for s in todo}
    solved = failed = 0
    while pending:
        future = backend.next_finished()
        if future is None or future not in pending:
            continue
        sweep = pending.pop(future)
        try:
            outcome: PointOutcome | None = future.result()
        except Exception:  # noqa: BLE001  (a dead worker: the case keeps its sweep's optimum)
            outcome = None
        path = save_direct(sweep, directory, outcome) if outcome is not None else None
        solved, failed = (solved + 1, failed) if path is not None else (solved, failed + 1)
        if on_done is not None:
            on_done(sweep, outcome, path)
    return len(sweeps) - len(todo), solved, failed


#: How a row's status says that its speed-free optimum ended on a bound of the speed (an
#: optimum of the bounded problem only: the unbounded one lies at or beyond it).
SPEED_BOUND_NOTE = "at the speed bound {bound:g} m/min"


def speed_bound_reached(speed_m_min: float, bounds: tuple[float, float], *,
                        rtol: float = 1e-5) -> float | None:
    """The bound (m/min) of ``bounds`` (m/s, ``GaitOptions.speed_bounds``) that the speed
    ``speed_m_min`` lies on, within ``rtol`` relative; None when it lies inside them."""
    for bound in (b * 60.0 for b in bounds):
        if math.isfinite(speed_m_min) and abs(speed_m_min - bound) <= rtol * bound:
            return bound
    return None


#: The share of a speed-free optimum's cost above which the smoothing of the positive parts,
#: not the cost, sets its speed (:func:`smoothing_share`): measured 0.1-2.2 % with a resting
#: power and 20-51 % without one (the work cost, 0 W/kg), whose cost falls with the speed
#: while the smoothing's ``n_a eps / (2 W v)`` per metre grows (docs/costs.md, "How much of
#: the cost is the smoothing"). Such a case gets no accuracy pass and is not counted in the
#: study's "within the accuracy".
SMOOTHING_SETS_SPEED = 0.1
#: What the status of such a case says.
SMOOTHING_NOTE = ("no optimal speed of its own: the smoothing sets it (the cost falls with the "
                  "speed), no accuracy pass")


def smoothing_share(gait: Gait | Path) -> float:
    """The share of a gait's cost that is the smoothing of its positive parts (a gait or its
    file): the file's ``solver.accuracy.smoothing``, or for a file written before it
    :func:`~gaitopt.gait.formulations.cost.smoothing_record`; NaN for the paper's cost or a
    file that cannot be read."""
    try:
        loaded = gait if isinstance(gait, Gait) else Gait.load(gait)
        stored = (loaded.solver.get("accuracy") or {}).get("smoothing")
        record = stored if stored is not None else smoothing_record(loaded)
    except (OSError, ValueError, GaitFileError):
        return math.nan
    return math.nan if record is None else float(record["share"])


def collect_rows(spec: CostStudySpec, directory: str | os.PathLike[str]) -> list[CostRow]:
    """The speed-free optimum of every (model, case): the lowest over its starts
    (:func:`winner_of`), reported with the values of its accurate gait where the accuracy
    pass converged (:mod:`gaitopt.study.cost_accuracy`; ``other_cost_value`` stays the next
    start's cost on the study's grid); a case with no converged start gives a failed row."""
    top = Path(directory)
    rows = []
    for sweep in spec.sweeps(start_choices(spec, top)):
        rest = sweep.case.resting_power if sweep.case.resting_power is not None else math.nan
        common: dict[str, Any] = {"model": sweep.model, "formulation": sweep.formulation,
                                  "case": sweep.case.tag, "cost": sweep.case.cost,
                                  "resting_power": rest}
        found = winner_of(sweep, top, spec.variant)
        if found is None:
            try:
                summary = read_summary(top / sweep.subdir / SUMMARY_FILE)
            except SummaryError:
                summary = []
            free = rows_of(summary, spec.variant, speed_mode="free", success=None)
            status = free[0].status if free else "not solved"
            rows.append(CostRow(**common, success=False, status=status, speed_m_min=math.nan,
                                step_length=math.nan, step_time=math.nan,
                                cost_value=math.nan, file=""))
            continue
        value, start, fields, other = found
        accuracy: dict[str, Any] = {}
        target = spec.accuracy_of(sweep.model)
        winner_share = smoothing_share(top / fields["file"])
        smoothed = winner_share > SMOOTHING_SETS_SPEED
        accurate = (accurate_gait(top / sweep.subdir, fields["file"], value)
                    if target is not None and not smoothed else None)
        if smoothed:
            fields["status"] += f"; {SMOOTHING_NOTE}"
        elif accurate is None and target is not None:
            # Never passed silently: the grid's optimum, marked as not within the accuracy.
            failure = accuracy_failure(top / sweep.subdir, fields["file"], value)
            fields["status"] += (f"; not within {100 * target:g} %: "
                                 + (f"the accuracy pass failed ({failure})" if failure
                                    else "no accuracy pass"))
            accuracy = {"within_accuracy": False}
        if accurate is not None:
            worst, worst_of, within, knots = estimate_of(accurate)
            value = accurate.cost_value
            fields = {"status": accurate.status, "speed_m_min": accurate.speed * 60.0,
                      "step_length": accurate.step_length, "step_time": accurate.step_time,
                      "file": f"{sweep.subdir}/{ACCURATE_FILE}"}
            accuracy = {"estimate": worst, "estimate_of": worst_of, "knots": knots,
                        "within_accuracy": within}
            if within is False:
                fields["status"] += (f"; {worst_of.replace('_', ' ')} estimate "
                                     f"{100 * worst:.2g} % > {100 * target:g} %"
                                     if target is not None and math.isfinite(worst)
                                     else "; not within the accuracy")
                fields["status"] += diverging_text(accurate.solver.get("accuracy") or {})
        bound = speed_bound_reached(fields["speed_m_min"], sweep.spec.base.speed_bounds)
        if bound is not None:
            fields["status"] = f"{fields['status']}; {SPEED_BOUND_NOTE.format(bound=bound)}"
        share = smoothing_share(accurate) if accurate is not None else winner_share
        if target is not None and share > target:
            fields["status"] += (f"; the smoothing is {100 * share:.2g} % of the cost "
                                 f"(> {100 * target:g} %)")
        rows.append(CostRow(**common, success=True, cost_value=value, start=start,
                            other_cost_value=other, smoothing_share=share, **accuracy,
                            **fields))
    return rows
