"""What a sweep solves: the grid of points, their warm-start chains and the settings file.

A sweep is a grid: variants (ankle torques on/off x liftoff impulse on/off) x speeds, times
optional step lengths and single-support fractions, plus (optionally) the speed-free optimal
walk of every variant. Points of one *group* (same variant, step length and single-support
fraction) form continuation chains along the speed axis::

    3 <- 6 <- 9 <- [12] -> 15 -> 18 -> ... -> 60        (m/min)
                     |
                     +-> free (the speed-free optimum)

The point nearest the start speed (:attr:`SweepSpec.start`: for the five-link walk
:data:`START_SPEED`, 12 m/min, the paper's optimum; for the heel-toe walk of ``seven-link``
72.2 m/min) is solved cold; every other point is warm-started from its finished neighbour
toward that start (its *parent*). With ``impulse_from_no_impulse`` (the study with feet) the
start point of an impulse variant is warm-started from the same point of its variant without
the impulse.

Directory layout: with one combination of step length and single-support fraction the sweep
directory is a plain sweep (``summary.csv``, ``gaits/<variant>/...``, see
:mod:`gaitopt.study.summary`); with several, each combination is such a sub-sweep in a folder
named by :func:`axis_tag` (``single-support-0.85_step-free``). ``sweep.json`` at the top holds
the settings (:func:`sweep_settings`); a sweep refuses to resume into a directory made with
other settings.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

from gaitopt import __version__
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.gait.options.model_defaults import default_speed, options_for_model
from gaitopt.robot.model import RobotModel
from gaitopt.study.summary import (
    VARIANTS,
    SpeedMode,
    gait_relpath,
    variant_flags,
    variant_name,
)

#: Speed (m/s) of the cold start of each chain of the five-link walk: the paper's optimal
#: 12 m/min. Another model's or gait's chains start at its gait's default speed
#: (:func:`gaitopt.gait.options.model_defaults.default_speed`: 72.2 m/min for the heel-toe
#: walk of ``seven-link``), which is this for the five-link walk (:attr:`SweepSpec.start`).
START_SPEED = 0.2
SETTINGS_FILE = "sweep.json"
SETTINGS_FORMAT = "gaitopt.sweep"
SETTINGS_VERSION = 1
#: Options set per point (not part of the sweep's shared ``options``).
POINT_FIELDS = ("speed", "ankle", "impulse", "step_length", "step_time",
                "single_support_fraction", "knots")


class SweepSpecError(ValueError):
    """A sweep request is invalid (names the setting and what is allowed)."""


@dataclass(frozen=True, kw_only=True)
class SweepSpec:
    """The grid of a sweep (SI units).

    Attributes:
        model: the robot model.
        speeds: fixed speeds (m/s), ascending, no two with the same 0.01 m/min label.
        variants: subset of :data:`gaitopt.study.summary.VARIANTS`, in that order.
        free_speed: also solve the speed-free optimal walk of every group.
        step_lengths: step lengths (m), ``None`` meaning free (optimized).
        step_times: step times (s), ``None`` meaning free; with a fixed speed a step time
            fixes the step length, so give step lengths or step times, not both.
        single_support: single-support fractions of the step time.
        base: every other problem option (bounds, tolerances, grid ``knots``, ...); its
            per-point fields (:data:`POINT_FIELDS` but ``knots``) are ignored. The defaults
            that follow the model (gait, formulation, knots, Froude-scaled bounds;
            :func:`~gaitopt.gait.options.model_defaults.options_for_model`) are resolved for
            ``model`` here, so ``sweep.json``, the points and the saved gait files hold the
            values the points are solved with (for the five-link biped the same values).
        continuation: points warm-start from their neighbours along the speed axis; with
            False every point starts alone (cold, or from a seed file: the refinement sweep
            of :mod:`gaitopt.study.grid_error`), but see ``free_from_start``.
        free_from_start: with ``continuation`` False, each speed-free optimum still
            warm-starts from its group's fixed-speed point at the start speed (its values and
            multipliers; the check sweep with feet, :func:`gaitopt.cli.study.check_sweep`).
        impulse_from_no_impulse: with ``continuation``, the chain of a variant with the
            liftoff impulse starts from its variant without it (the same ankle torques) at
            the start speed, where that variant is in the sweep, instead of cold: that
            optimum is a feasible point of the impulse problem (the impulse at 0). The study
            with feet (:func:`gaitopt.cli.study.study_spec`): measured on the seven-link at
            72 m/min, the same optima as cold (2255.695 and 10504.669) in 53 and 41
            iterations instead of 611 and 413 (docs/studies.md).
        ankle_impulse_from_ankle: every point of the variant with ankle torques and the
            liftoff impulse starts from the same point of the variant with ankle torques only,
            where that is in the sweep (its Result: values and multipliers, the impulse's
            constraint rows at 0, :meth:`gaitopt.ocp.Transcription.carried_over`), in a sweep
            with chains or without. Where the ankles push off and the impulse stays at 0 that
            start is already the impulse problem's optimum: the study with feet
            (:func:`gaitopt.cli.study.study_spec`), the seven-link at 12-120 m/min, 15-22
            iterations instead of the chain's 14-230, and at 12 m/min the ankle variant's
            optimum instead of a dearer local one (docs/studies.md). Not for the variants
            without ankle torques, whose impulse does work: from the variant without it IPOPT
            stopped at dearer optima than the chain's (62506 against 32708 at 12 m/min).
        secant: a point two steps along its chain (a third fixed speed of its group) starts
            from the secant prediction through its parent's and grandparent's solutions
            (values and multipliers, :func:`gaitopt.ocp.secant_start`) instead of the
            parent's alone. The study with feet: on the seven-link four chain steps took 229,
            93, 16 and 25 iterations instead of 249, 190, 30 and 195, to the same optima
            (docs/studies.md).
        check_grid: every point solves its check grid after the answer, a warm-started one
            too (``solve_walking(check_warm_start=True)``), so that every gait file carries
            the cost's grid error estimate (``solver.accuracy.cost_error``); otherwise only
            the cold starts do (the walk-run study, :mod:`gaitopt.study.walk_run`).
        check_cold: a cold start solves its check grid after the answer (the cost's grid
            error estimate in its file, as ``gaitopt solve``). False: it does not (the
            answer is the same), as the warm-started points do not: the study with feet,
            whose check sweep estimates every point; there a cold start's check grid took
            4-123 s (the seven-link with ankle torques at 72 m/min, 530 iterations, on
            2026-12-04).
    """

    model: RobotModel
    speeds: tuple[float, ...]
    variants: tuple[str, ...] = VARIANTS
    free_speed: bool = True
    step_lengths: tuple[float | None, ...] = (None,)
    step_times: tuple[float | None, ...] = (None,)
    single_support: tuple[float, ...] = (0.85,)
    base: GaitOptions = field(default_factory=GaitOptions)
    continuation: bool = True
    free_from_start: bool = False
    impulse_from_no_impulse: bool = False
    ankle_impulse_from_ankle: bool = False
    secant: bool = False
    check_cold: bool = True
    check_grid: bool = False

    def __post_init__(self) -> None:
        try:
            base = options_for_model(self.model, self.base)
        except GaitOptionsError as exc:
            raise SweepSpecError(str(exc)) from None
        object.__setattr__(self, "base", base)
        check_spec(self)

    @property
    def start(self) -> float:
        """The speed (m/s) nearest which each chain starts cold: the default speed of the
        sweep's gait on its model (:data:`START_SPEED` for the five-link walk)."""
        return default_speed(self.model, self.base.gait)

    @property
    def knots(self) -> tuple[int, int]:
        return (self.base.knots[0], self.base.knots[1])

    @property
    def nested(self) -> bool:
        """Whether each (step length or time, single-support) combination has its own
        sub-sweep."""
        return len(self.step_lengths) * len(self.step_times) * len(self.single_support) > 1

    @cached_property
    def points(self) -> tuple[SweepPoint, ...]:
        """Every point, grouped (single support, step length or time, variant), speeds
        ascending, the speed-free point last in its group."""
        out = []
        for ss in self.single_support:
            for step in self.step_lengths:
                for period in self.step_times:
                    for variant in self.variants:
                        speeds: list[float | None] = list(self.speeds)
                        if self.free_speed:
                            speeds.append(None)
                        for v in speeds:
                            out.append(SweepPoint(variant=variant, speed=v, step_length=step,
                                                  step_time=period, single_support=ss,
                                                  nested=self.nested))
        return tuple(out)

    @cached_property
    def parents(self) -> Mapping[str, str | None]:
        """Point key -> the key of the point it is warm-started from (None: cold start)."""
        parents: dict[str, str | None] = {p.key: None for p in self.points}
        if self.continuation or self.free_from_start:
            parents |= self._chain_parents()
        if self.ankle_impulse_from_ankle:
            ankle_only = variant_name(ankle=True, impulse=False)
            for p in self.points:
                if variant_flags(p.variant) == (True, True):
                    twin = replace(p, variant=ankle_only).key
                    parents[p.key] = twin if twin in self._points_by_key else parents[p.key]
        return parents

    def secant_step(self, key: str) -> tuple[str, float] | None:
        """With :attr:`secant`, the point before ``key``'s parent on its chain and the step
        ratio ``(v - v_parent) / (v_parent - v_before)`` of :func:`gaitopt.ocp.secant_start`;
        None where ``key`` is not two fixed-speed steps along a chain of its own group."""
        parent = self.parents.get(key)
        before = self.parents.get(parent) if self.secant and parent is not None else None
        if parent is None or before is None:
            return None
        p, q, r = (self.point(k) for k in (key, parent, before))
        if p.speed is None or q.speed is None or r.speed is None or not (
                p.group == q.group == r.group) or q.speed == r.speed:
            return None
        return before, (p.speed - q.speed) / (q.speed - r.speed)

    def point(self, key: str) -> SweepPoint:
        """The point called ``key``."""
        return self._points_by_key[key]

    @cached_property
    def _points_by_key(self) -> dict[str, SweepPoint]:
        return {p.key: p for p in self.points}

    def _chain_parents(self) -> dict[str, str | None]:
        """The parents along the speed axis (with ``continuation``) and of the speed-free
        points (with it or ``free_from_start``); ``impulse_from_no_impulse``'s starts."""
        parents: dict[str, str | None] = {}
        groups: dict[tuple[Any, ...], list[SweepPoint]] = {}
        for p in self.points:
            groups.setdefault(p.group, []).append(p)
        starts: dict[tuple[Any, ...], SweepPoint] = {}  # each group's point at the start
        for group, members in groups.items():
            fixed = [p for p in members if p.speed is not None]
            free = [p for p in members if p.speed is None]
            start = start_index([p.speed for p in fixed if p.speed is not None], self.start)
            if fixed:
                starts[group] = fixed[start]
            for i, p in enumerate(fixed if self.continuation else ()):
                parents[p.key] = (None if i == start else
                                  fixed[i - 1].key if i > start else fixed[i + 1].key)
            for p in free:
                parents[p.key] = fixed[start].key if fixed else None
        if self.continuation and self.impulse_from_no_impulse:
            for (variant, *rest), first in starts.items():
                ankle, impulse = variant_flags(variant)
                without = starts.get((variant_name(ankle=ankle, impulse=False), *rest))
                if impulse and without is not None:
                    parents[first.key] = without.key
        return parents

    @cached_property
    def passive_model(self) -> RobotModel:
        """The model of the variants without ankle torques: :func:`passive_ankles`."""
        return passive_ankles(self.model)

    def model_of(self, point: SweepPoint) -> RobotModel:
        """The model a point is solved on: :attr:`model`, or for a variant without ankle
        torques on a model with feet, the model with its ankle joints unactuated
        (:func:`passive_ankles`; a point-foot model's ankle torques are its contact
        actuators, which ``GaitOptions.ankle`` switches off)."""
        ankle, _ = variant_flags(point.variant)
        return self.model if ankle else self.passive_model

    def options(self, point: SweepPoint) -> GaitOptions:
        """The full problem options of a point."""
        ankle, impulse = variant_flags(point.variant)
        return self.base.replace(speed=point.speed, ankle=ankle, impulse=impulse,
                                 step_length=point.step_length, step_time=point.step_time,
                                 single_support_fraction=point.single_support)


def foot_links(model: RobotModel) -> tuple[str, ...]:
    """The links that carry two or more contact points (feet: heel and toe), model order."""
    counts: dict[str, int] = {}
    for c in model.contacts:
        counts[c.link] = counts.get(c.link, 0) + 1
    return tuple(link.name for link in model.links if counts.get(link.name, 0) >= 2)


def ankle_actuators(model: RobotModel) -> tuple[str, ...]:
    """The joint actuators of the ankles (the joints of :func:`foot_links`), model order."""
    ankles = {link.joint.name for link in model.links
              if link.name in foot_links(model) and link.joint is not None}
    return tuple(a.name for a in model.actuators if a.joint in ankles)


def passive_ankles(model: RobotModel) -> RobotModel:
    """``model`` with its ankle joints unactuated (:func:`ankle_actuators` removed; each joint
    keeps its damping, ``Joint.damping``: 2 N m s/rad on ``seven-link``), named
    ``<name>-passive-ankles``; ``model`` itself when it has none (point feet, whose ankle
    torques are contact actuators that ``GaitOptions.ankle = False`` leaves out).

    This is what "without ankle torques" means on a model with feet: the full formulation
    keeps every joint actuator whatever ``GaitOptions.ankle`` says (it switches the contact
    actuators of held points only, :func:`gaitopt.gait.formulations.full.physics.actuator_names`),
    so on ``seven-link`` the ankle variants and the others would be one problem solved twice.
    """
    removed = set(ankle_actuators(model))
    if not removed:
        return model
    return replace(model, name=f"{model.name}-passive-ankles",
                   actuators=tuple(a for a in model.actuators if a.name not in removed),
                   description=(f"{model.description} " if model.description else "")
                   + f"Ankles unactuated (passive, damped): {', '.join(sorted(removed))} "
                     "removed.")


def start_index(speeds: Sequence[float], start: float = START_SPEED) -> int:
    """Index of the speed nearest ``start`` (m/s; the lower one on a tie)."""
    if not speeds:
        return 0
    return min(range(len(speeds)),  # distances compared in m/min to 1e-6: ties are ties
               key=lambda i: (round(abs(speeds[i] - start) * 60.0, 6), speeds[i]))


def axis_tag(single_support: float, step_length: float | None,
             step_time: float | None = None) -> str:
    """The sub-sweep folder of a (single-support fraction, step length or step time)
    combination."""
    if step_time is not None:
        return f"single-support-{single_support:g}_step-time-{step_time:g}s"
    step = "free" if step_length is None else f"{step_length:g}m"
    return f"single-support-{single_support:g}_step-{step}"


@dataclass(frozen=True, kw_only=True)
class SweepPoint:
    """One point of the grid; ``speed`` in m/s or ``None`` for the speed-free walk."""

    variant: str
    speed: float | None
    step_length: float | None
    single_support: float
    step_time: float | None = None
    nested: bool = False

    @property
    def speed_mode(self) -> SpeedMode:
        return "free" if self.speed is None else "fixed"

    @property
    def subdir(self) -> str:
        """The sub-sweep folder ("" for a plain sweep)."""
        return (axis_tag(self.single_support, self.step_length, self.step_time)
                if self.nested else "")

    @property
    def relfile(self) -> str:
        """The gait file, relative to the sub-sweep folder (the summary's ``file``)."""
        ankle, impulse = variant_flags(self.variant)
        return gait_relpath(ankle=ankle, impulse=impulse, speed_mode=self.speed_mode,
                            speed_m_s=self.speed)

    @property
    def key(self) -> str:
        """Unique name of the point: its gait file relative to the sweep directory."""
        return f"{self.subdir}/{self.relfile}" if self.subdir else self.relfile

    @property
    def group(self) -> tuple[str, float | None, float | None, float]:
        """Points of a group share a continuation chain."""
        return (self.variant, self.step_length, self.step_time, self.single_support)

    @property
    def structure(self) -> str:
        """Points with the same structure share a transcription (built once per process)."""
        return (f"ankle={'ankle' in self.variant} single_support={self.single_support:g}"
                + (" step_time" if self.step_time is not None else ""))

    def label(self) -> str:
        speed = "free" if self.speed is None else f"{self.speed * 60:.2f} m/min"
        extra = f"  [{self.subdir}]" if self.subdir else ""
        return f"{self.variant:<13} {speed:>12}{extra}"


def check_spec(spec: SweepSpec) -> None:
    """Raise :class:`SweepSpecError` for an empty or malformed grid."""
    if not spec.speeds:
        raise SweepSpecError("speeds: at least one speed is needed")
    for v in spec.speeds:
        if not (isinstance(v, float | int) and math.isfinite(v) and v > 0):
            raise SweepSpecError(f"speeds: {v!r} m/s is not a positive speed")
    if list(spec.speeds) != sorted(spec.speeds):
        raise SweepSpecError("speeds: must be ascending")
    labels = [f"{v * 60:06.2f}" for v in spec.speeds]
    for first, second in zip(labels, labels[1:], strict=False):
        if first == second:
            raise SweepSpecError(f"speeds: two speeds round to the same file name "
                                 f"({first} m/min); keep speeds at least 0.01 m/min apart")
    if not spec.variants:
        raise SweepSpecError(f"variants: at least one of {', '.join(VARIANTS)} is needed")
    for name in spec.variants:
        if name not in VARIANTS:
            raise SweepSpecError(f"variants: unknown variant {name!r}; expected one of "
                                 f"{', '.join(VARIANTS)} (or 'all')")
    if len(set(spec.variants)) != len(spec.variants):
        raise SweepSpecError("variants: each variant at most once")
    if not spec.step_lengths or len(set(spec.step_lengths)) != len(spec.step_lengths):
        raise SweepSpecError("step lengths: at least one, each at most once")
    if not spec.step_times or len(set(spec.step_times)) != len(spec.step_times):
        raise SweepSpecError("step times: at least one, each at most once")
    for period in spec.step_times:
        if period is not None and not (isinstance(period, float | int)
                                       and math.isfinite(period) and period > 0):
            raise SweepSpecError(f"step times: {period!r} s is not a positive time")
    if any(x is not None for x in spec.step_lengths) and any(
            x is not None for x in spec.step_times):
        raise SweepSpecError("step lengths and step times: give one of them (with the speed "
                             "each fixes the other)")
    if not spec.single_support or len(set(spec.single_support)) != len(spec.single_support):
        raise SweepSpecError("single-support fractions: at least one, each at most once")


# -- the settings file ---------------------------------------------------------------------------

def sweep_settings(spec: SweepSpec) -> dict[str, Any]:
    """The settings that define a sweep's results (written to ``sweep.json``): the model
    (name and content hash), the grid and every shared problem option."""
    shared = {k: v for k, v in spec.base.to_dict().items()
              if k not in POINT_FIELDS or k == "knots"}
    return {
        "model": {"name": spec.model.name, "content_hash": spec.model.content_hash()},
        "variants": list(spec.variants),
        "speeds_m_min": [round(v * 60.0, 9) for v in spec.speeds],
        "free_speed": spec.free_speed,
        "step_lengths": list(spec.step_lengths),
        "single_support_fractions": list(spec.single_support),
        "options": shared,
    } | ({"step_times": list(spec.step_times)} if spec.step_times != (None,) else {}) | (
        {} if spec.continuation else {"continuation": False}) | (
        {"free_from_start": True} if spec.free_from_start else {}) | (
        {"impulse_from_no_impulse": True}
        if spec.continuation and spec.impulse_from_no_impulse else {}) | (
        {"ankle_impulse_from_ankle": True} if spec.ankle_impulse_from_ankle else {}) | (
        {"secant": True} if spec.continuation and spec.secant else {}) | (
        {"check_grid": True} if spec.check_grid else {}) | (
        {} if spec.check_cold else {"check_cold": False})


def settings_document(spec: SweepSpec) -> dict[str, Any]:
    """The whole ``sweep.json`` document: format, version, writer and the settings."""
    return {"format": SETTINGS_FORMAT, "version": SETTINGS_VERSION,
            "gaitopt_version": __version__, "settings": sweep_settings(spec)}


def with_option_defaults(settings: Mapping[str, Any]) -> dict[str, Any]:
    """``settings`` (of ``sweep.json``) with every problem option it lacks at its default: a
    sweep written before an option existed was solved with that option's default."""
    out = dict(settings)
    if isinstance(out.get("options"), Mapping):
        defaults = {k: v for k, v in GaitOptions.saved_defaults().items()
                    if k not in POINT_FIELDS}
        out["options"] = {**defaults, **out["options"]}
    return out


def settings_differences(saved: Mapping[str, Any], wanted: Mapping[str, Any]) -> list[str]:
    """Human-readable differences between two settings dicts (empty when equal)."""
    out = []
    for key in sorted(set(saved) | set(wanted)):
        a, b = saved.get(key, "<missing>"), wanted.get(key, "<missing>")
        if isinstance(a, Mapping) and isinstance(b, Mapping):
            out += [f"{key}.{d}" for d in settings_differences(a, b)]
        elif a != b:
            out.append(f"{key}: directory has {_short(a)}, this run asks {_short(b)}")
    return out


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 70 else text[:67] + "..."
