"""The gait file: one solved gait as a self-describing JSON document (``*.gait.json``).

Format ``gaitopt.gait``, version 1 (field by field in ``docs/outputs.md``; units, frames and the
step in ``docs/conventions.md``). A :class:`Gait` holds one *step* of a symmetric periodic gait:

* phase 1 (single support on leg 1, contact ``tip_1``) starts when leg 2 lifts off and ends
  when leg 2 strikes the ground at x = step length; phase 2 (double support) ends when leg 1
  lifts off;
* the next step is the same motion with the legs' roles swapped (leg 1 <-> leg 2 coordinates,
  controls, contacts and points) and shifted forward by one step length
  (:meth:`Gait.stride_samples`).

Arrays (SI units, world frame: x forward, y up): per phase, at its K knots, ``t`` (K,) s,
``q``/``qd``/``qdd`` (K, nq), ``u`` (K, nu) N m, ``contact_forces[c]`` (K, 2) N (force of the
ground on tip ``c``), reduced states ``x``/``xdot`` (K, n); per event, ``impulses[c]`` (2,) N s
and ``qd_before``/``qd_after`` (nq,); dense ``samples`` on a uniform grid: ``t`` (N,),
``q``/``qd`` (N, nq), ``u`` (N, nu), ``points[name]`` (N, 2) m.

Only this module reads and writes gait files. Every problem with a file or with data given to
the constructors raises :class:`GaitFileError` naming the file and the field. The record's
parts (:class:`GaitPhase`, :class:`GaitEvent`, :class:`GaitSamples`) live in
:mod:`gaitopt.gait.record.parts`, the checks of the whole record in
:mod:`gaitopt.gait.record.checks` and those of single fields in :mod:`gaitopt.gait.record.fields`;
all are importable from here.
"""

from __future__ import annotations

import copy
import json
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from gaitopt import __version__
from gaitopt.fileio import write_text_atomic
from gaitopt.gait.record.checks import SOLVER_KEYS as SOLVER_KEYS
from gaitopt.gait.record.checks import check_consistency, check_solver, parse_model
from gaitopt.gait.record.fields import (
    Array,
    bad_field,
    frozen_copy,
    mapping_of,
    number_of,
    plain_json,
)
from gaitopt.gait.record.fields import GaitFileError as GaitFileError
from gaitopt.gait.record.parts import EVENT_NAMES as EVENT_NAMES
from gaitopt.gait.record.parts import POINT_NAMES as POINT_NAMES
from gaitopt.gait.record.parts import GaitEvent as GaitEvent
from gaitopt.gait.record.parts import GaitPhase as GaitPhase
from gaitopt.gait.record.parts import GaitSamples as GaitSamples
from gaitopt.robot import ModelError, RobotModel
from gaitopt.robot.symmetry import swap_matrices, swap_names
from gaitopt.views import gait_views

if TYPE_CHECKING:  # for annotations only
    from matplotlib.figure import Figure

FORMAT = "gaitopt.gait"
VERSION = 2
#: Versions this module reads: 1 (walks only, no contact sequence) and 2.
READABLE_VERSIONS: tuple[int, ...] = (1, 2)

PARAMETER_KEYS: tuple[str, ...] = ("step_length", "speed", "step_time", "single_support_time",
                                   "liftoff_impulse")
FAILED_WARNING = ("THIS GAIT DID NOT CONVERGE: the solver reported failure; the trajectories "
                  "are the last iterate and need not satisfy the dynamics or the constraints.")



@dataclass(frozen=True, kw_only=True, eq=False, repr=False)
class Gait:
    """One solved step of a symmetric periodic gait (see the module docstring).

    ``model_data`` is the model in the model-file schema (:attr:`model` builds the
    :class:`RobotModel`); ``parameters`` holds :data:`PARAMETER_KEYS` (m, m/s, s, s, N s);
    ``cost`` has ``value`` and ``formula``; ``solver`` holds :data:`SOLVER_KEYS`
    (``evaluations``: function evaluations by kind). ``options`` is free-form JSON data.
    """

    model_data: Mapping[str, Any]
    options: Mapping[str, Any]
    parameters: Mapping[str, float]
    cost: Mapping[str, Any]
    solver: Mapping[str, Any]
    phases: tuple[GaitPhase, ...]
    events: tuple[GaitEvent, ...]
    samples: GaitSamples
    created: str = field(default_factory=lambda: datetime.now(UTC).isoformat(timespec="seconds"))
    gaitopt_version: str = __version__
    format: str = FORMAT
    version: int = VERSION
    contact_sequence: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        try:
            model = parse_model(self.model_data)
        except ModelError as exc:
            raise bad_field(f"model.{exc.path}" if exc.path else "model",
                            f"{exc.value!r} is invalid: {exc.allowed}") from None
        if self.format != FORMAT:
            raise bad_field("format", f"expected {FORMAT!r}, got {self.format!r}")
        if self.version not in READABLE_VERSIONS:
            raise bad_field("version", f"expected one of {READABLE_VERSIONS}, got {self.version!r}")
        set_ = object.__setattr__
        if self.contact_sequence is not None:
            seq = mapping_of("contact_sequence", self.contact_sequence,
                             required=("name", "phases", "events"))
            if seq.get("steps", 1) not in (1, 2) or isinstance(seq.get("steps"), bool):
                raise bad_field("contact_sequence.steps", f"expected 1 (one step) or 2 (a "
                                f"stride), got {seq['steps']!r}")
            set_(self, "contact_sequence", frozen_copy(plain_json("contact_sequence", seq)))
        set_(self, "model_data", frozen_copy(self.model_data))
        options = mapping_of("options", self.options)
        set_(self, "options", frozen_copy(plain_json("options", options)))
        params = mapping_of("parameters", self.parameters, required=PARAMETER_KEYS)
        set_(self, "parameters", MappingProxyType(
            {k: number_of(f"parameters.{k}", v, minimum=0.0) for k, v in params.items()}))
        cost = mapping_of("cost", self.cost, required=("value", "formula"))
        cost["value"] = number_of("cost.value", cost["value"])
        if not isinstance(cost["formula"], str):
            raise bad_field("cost.formula", "expected a string (the cost formula in words)")
        set_(self, "cost", frozen_copy(plain_json("cost", cost)))
        set_(self, "solver", frozen_copy(plain_json("solver", check_solver(self.solver))))
        set_(self, "phases", tuple(self.phases))
        set_(self, "events", tuple(self.events))
        check_consistency(model, self.parameters, self.phases, self.events, self.samples,
                          self.period_steps)

    def __repr__(self) -> str:
        phases = "+".join(f"{p.name}({p.t.size})" for p in self.phases)
        return (f"Gait(model={self.model_data.get('name')!r}, speed={self.speed:.4g} m/s, "
                f"step_length={self.step_length:.4g} m, cost={self.cost_value:.6g}, "
                f"status={self.status!r}, phases={phases})")

    # -- convenience ------------------------------------------------------------------------
    @cached_property
    def model(self) -> RobotModel:
        """The robot model the gait was solved for."""
        return parse_model(self.model_data)

    @property
    def speed(self) -> float:
        """Average forward speed, m/s."""
        return float(self.parameters["speed"])

    @property
    def step_length(self) -> float:
        """Step length (distance between the tips at heel strike), m."""
        return float(self.parameters["step_length"])

    @property
    def step_time(self) -> float:
        """One step's time ``L / v``, s (a stride's period is two)."""
        return float(self.parameters["step_time"])

    @property
    def period_steps(self) -> int:
        """Steps in the solved period: 1 (one step, periodic through the leg swap) or 2 (a
        stride: two steps, periodic without swap; ``contact_sequence.steps``)."""
        if self.contact_sequence is None:
            return 1
        return int(self.contact_sequence.get("steps", 1))

    @property
    def cost_value(self) -> float:
        """The objective as solved (paper eq. 4/5, energy per metre)."""
        return float(self.cost["value"])

    @property
    def success(self) -> bool:
        """Whether the solve converged (``solver.success``)."""
        return bool(self.solver["success"])

    @property
    def status(self) -> str:
        """IPOPT's status of the final solve (``solver.status``)."""
        return str(self.solver["status"])

    @property
    def stages(self) -> tuple[Mapping[str, Any], ...]:
        """Every stage of the solve in order (``solver.stages``: each stage's ``name``,
        ``knots``, ``status``, ``success``, ``iterations``, ``objective``, ``violation``,
        ``parameters``, ``wall_time_s``); empty if the file keeps none."""
        return tuple(self.solver.get("stages", ()))

    @property
    def diagnosis(self) -> str | None:
        """Why the solve failed and what to change, as lines of text (``solver.diagnosis``:
        the failed stage, the most likely cause, the largest violation, the binding bounds
        and advice); None for a converged gait or a file that keeps none."""
        text = self.solver.get("diagnosis")
        return None if text is None else str(text)

    def stride_samples(self, n_steps: int = 2) -> GaitSamples:
        """Samples of ``n_steps`` consecutive steps (a stride is 2), legs labelled physically.

        Step k (k = 0, 1, ...) is this step's samples with time shifted by k * step_time, x
        (the ``x`` coordinate and every point) shifted by k * step_length, and, for odd k, the
        legs swapped (coordinates, controls and points of leg 1 <-> leg 2), so that
        ``points["tip_1"]`` follows the same physical leg throughout. A sample repeated at a
        step boundary is kept once. A stride file (:attr:`period_steps` 2) repeats its
        stride, shifted by two step times and lengths and never swapped, until it covers
        ``n_steps`` steps (``ceil(n_steps / 2)`` strides).
        """
        if isinstance(n_steps, bool) or not isinstance(n_steps, int) or n_steps < 1:
            raise ValueError(f"n_steps: expected an integer >= 1, got {n_steps!r}")
        s = self.samples

        steps = self.period_steps
        if steps == 1:
            s_q, s_u = swap_matrices(self.model)  # q' = S_q q, u' = S_u u
            names = swap_names(self.model)
        else:  # a stride: no swap
            s_q, s_u, names = np.eye(self.model.nq), np.eye(self.model.nu), {}
        period, shift = steps * self.step_time, steps * self.step_length
        n_steps = -(-n_steps // steps)  # periods
        x_index = self.model.coordinate_names.index("x")
        duplicate = abs((s.t[-1] - s.t[0]) - period) <= 1e-9 * max(1.0, period)
        parts: dict[str, list[Array]] = {"t": [], "q": [], "qd": [], "u": []}
        point_parts: dict[str, list[Array]] = {p: [] for p in s.points}
        for k in range(n_steps):
            sl = slice(1 if (k > 0 and duplicate) else 0, None)
            swap = k % 2 == 1
            q = (s.q @ s_q.T if swap else s.q.copy())[sl]
            q[:, x_index] += k * shift
            parts["t"].append(s.t[sl] + k * period)
            parts["q"].append(q)
            parts["qd"].append((s.qd @ s_q.T if swap else s.qd)[sl])
            parts["u"].append((s.u @ s_u.T if swap else s.u)[sl])
            for name in s.points:
                source = names.get(name, name) if swap else name
                if source not in s.points:
                    source = name
                p = s.points[source][sl].copy()
                p[:, 0] += k * shift
                point_parts[name].append(p)
        return GaitSamples(t=np.concatenate(parts["t"]), q=np.concatenate(parts["q"]),
                           qd=np.concatenate(parts["qd"]), u=np.concatenate(parts["u"]),
                           points={p: np.concatenate(v) for p, v in point_parts.items()})

    # -- (de)serialisation -------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The gait as plain JSON data (lists, numbers, strings) in the file schema."""
        out: dict[str, Any] = {"format": self.format, "version": self.version}
        if not self.success:
            out["WARNING"] = FAILED_WARNING
        out.update({
            "created": self.created, "gaitopt_version": self.gaitopt_version,
            "model": copy.deepcopy(dict(self.model_data)),
            "options": copy.deepcopy(dict(self.options)),
            "parameters": dict(self.parameters),
            "cost": copy.deepcopy(dict(self.cost)),
            "solver": copy.deepcopy(dict(self.solver)),
            "phases": [_phase_to_dict(p) for p in self.phases],
            "events": [{"name": e.name, "t": e.t, "leg": e.leg,
                        "impulses": {c: v.tolist() for c, v in e.impulses.items()},
                        "qd_before": e.qd_before.tolist(), "qd_after": e.qd_after.tolist()}
                       for e in self.events],
            "samples": {"t": self.samples.t.tolist(), "q": self.samples.q.tolist(),
                        "qd": self.samples.qd.tolist(), "u": self.samples.u.tolist(),
                        "points": {p: v.tolist() for p, v in self.samples.points.items()}},
        })
        if self.contact_sequence is not None:
            out["contact_sequence"] = copy.deepcopy(dict(self.contact_sequence))
        return out

    @classmethod
    def from_dict(cls, data: Any, *, source: str = "<dict>") -> Gait:
        """Validate plain data in the file schema and build a :class:`Gait`."""
        try:
            return _gait_from_dict(data)
        except GaitFileError as exc:
            raise GaitFileError(source, exc.path, exc.message) from None

    def save(self, path: str | os.PathLike[str], *, allow_failed: bool = False) -> Path:
        """Write the gait atomically as JSON; refuses a failed solve unless ``allow_failed``.

        A failed gait written with ``allow_failed=True`` carries a top-level ``WARNING``.
        """
        target = Path(path)
        if not self.success and not allow_failed:
            raise GaitFileError(str(target), "solver.success",
                                f"refusing to save a gait whose solve failed (status "
                                f"{self.status!r}); pass allow_failed=True to keep it anyway")
        write_text_atomic(target, _dumps(self.to_dict()) + "\n")
        return target

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Gait:
        """Read and validate a gait file."""
        source = str(path)
        try:
            text = Path(path).read_text(encoding="utf-8")
        except FileNotFoundError:
            raise GaitFileError(source, "", "no such file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise GaitFileError(source, "", f"cannot read the file ({exc})") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise GaitFileError(source, f"line {exc.lineno}, column {exc.colno}",
                                f"not valid JSON ({exc.msg})") from None
        return cls.from_dict(data, source=source)

    # -- notebook use: gaitopt.viz.notebook, found through gaitopt.views (gait/ is below viz/)
    def _repr_html_(self) -> str:
        """Jupyter's view: a table of speed, step length and time, cost, solver status, largest
        violation and the verify verdict (:func:`gaitopt.viz.notebook.summary_html`)."""
        return gait_views().summary_html(self)

    def plot(self, kind: str = "overview") -> Figure:
        """A Matplotlib figure: ``overview`` (angles, hip, torques over the step), ``torques``,
        ``hip``, ``heights``, ``poses`` or ``costates``
        (:func:`gaitopt.viz.notebook.gait_figure`)."""
        figure: Figure = gait_views().gait_figure(self, kind)
        return figure

    def animate(self, path: str | os.PathLike[str] | None = None, *, steps: int = 4,
                fps: int = 30) -> Any:
        """``steps`` steps of the walk in real time: written to ``path`` (.gif or .mp4; returns
        the path) or, without a path, an animated GIF that Jupyter shows inline (a
        :class:`gaitopt.viz.notebook.GifAnimation`)."""
        return gait_views().animate(self, path, steps=steps, fps=fps)


# -- validation helpers ------------------------------------------------------------------------

def _gait_from_dict(data: Any) -> Gait:
    top = mapping_of("", data, required=("format", "version"))
    if top["format"] != FORMAT:
        raise bad_field("format", f"expected {FORMAT!r}, got {top['format']!r} (not a gait file)")
    version = top["version"]
    major = _major_version(version)
    if major not in READABLE_VERSIONS:
        raise bad_field("version", f"major version {version!r} is not supported: this gaitopt "
                        f"({__version__}) reads {FORMAT} versions "
                        f"{', '.join(map(str, READABLE_VERSIONS))}")
    for key in ("created", "gaitopt_version", "model", "options", "parameters", "cost",
                "solver", "phases", "events", "samples"):
        if key not in top:
            raise bad_field("", f"missing required key {key!r}")
    phases = []
    if not isinstance(top["phases"], list):
        raise bad_field("phases", "expected a list of phases")
    for i, raw in enumerate(top["phases"]):
        ph = mapping_of(f"phases[{i}]", raw, required=(
            "name", "contacts", "t", "q", "qd", "qdd", "u", "contact_forces", "state_names",
            "x", "xdot", "interpolation"))
        phases.append(_with_path(f"phases[{i}]", GaitPhase, ph))
    if not isinstance(top["events"], list):
        raise bad_field("events", "expected a list of events")
    events = []
    for i, raw in enumerate(top["events"]):
        ev = mapping_of(f"events[{i}]", raw, required=(
            "name", "t", "leg", "impulses", "qd_before", "qd_after"))
        events.append(_with_path(f"events[{i}]", GaitEvent, ev))
    sm = mapping_of("samples", top["samples"], required=("t", "q", "qd", "u", "points"))
    samples = _with_path("samples", GaitSamples, sm)
    return Gait(model_data=mapping_of("model", top["model"]), options=top["options"],
                parameters=top["parameters"], cost=top["cost"], solver=top["solver"],
                phases=tuple(phases), events=tuple(events), samples=samples,
                created=str(top["created"]), gaitopt_version=str(top["gaitopt_version"]),
                version=int(major), contact_sequence=top.get("contact_sequence"))


def _major_version(version: Any) -> int | None:
    if isinstance(version, int) and not isinstance(version, bool):
        return version
    if isinstance(version, str) and (m := re.fullmatch(r"(\d+)(\.\d+)*", version)):
        return int(m.group(1))
    return None


def _with_path(prefix: str, cls: Any, fields: dict[str, Any]) -> Any:
    known = {k: v for k, v in fields.items() if k in cls.__dataclass_fields__}
    if cls is GaitPhase:
        known["contacts"] = _strings(f"{prefix}.contacts", known["contacts"])
        known["state_names"] = _strings(f"{prefix}.state_names", known["state_names"])
    try:
        return cls(**known)
    except GaitFileError as exc:
        raise bad_field(f"{prefix}.{exc.path}", exc.message) from None


def _strings(path: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise bad_field(path, "expected a list of strings")
    return tuple(value)


def _phase_to_dict(p: GaitPhase) -> dict[str, Any]:
    return {"name": p.name, "contacts": list(p.contacts), "t": p.t.tolist(), "q": p.q.tolist(),
            "qd": p.qd.tolist(), "qdd": p.qdd.tolist(), "u": p.u.tolist(),
            "contact_forces": {c: v.tolist() for c, v in p.contact_forces.items()},
            "state_names": list(p.state_names), "x": p.x.tolist(), "xdot": p.xdot.tolist(),
            "interpolation": dict(p.interpolation),
            **({} if p.error_estimate is None else {"error_estimate": p.error_estimate.tolist()}),
            **({} if p.costates is None else {"costates": p.costates.tolist()})}


def _dumps(value: Any, indent: int = 0) -> str:
    """JSON text with objects indented and every list of numbers on one line."""
    pad, inner = " " * indent, " " * (indent + 2)
    if isinstance(value, Mapping):
        if not value:
            return "{}"
        items = [f"{inner}{json.dumps(str(k))}: {_dumps(v, indent + 2)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list) and value and all(isinstance(v, list) for v in value):
        rows = [f"{inner}{_dumps(v, indent + 2)}" for v in value]
        return "[\n" + ",\n".join(rows) + "\n" + pad + "]"
    if isinstance(value, list) and any(isinstance(v, Mapping) for v in value):
        rows = [f"{inner}{_dumps(v, indent + 2)}" for v in value]
        return "[\n" + ",\n".join(rows) + "\n" + pad + "]"
    return json.dumps(value, allow_nan=False)
