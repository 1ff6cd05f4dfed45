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
the constructors raises :class:`GaitFileError` naming the file and the field.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from gaitopt import __version__
from gaitopt.fileio import write_text_atomic
from gaitopt.robot import ModelError, RobotModel, model_from_dict

if TYPE_CHECKING:  # for annotations only: no viz import at run time
    from matplotlib.figure import Figure

    from gaitopt.viz.notebook import GifAnimation

FORMAT = "gaitopt.gait"
VERSION = 2
#: Versions this module reads: 1 (walks only, no contact sequence) and 2.
READABLE_VERSIONS: tuple[int, ...] = (1, 2)

#: World points every gait's samples carry (leg numbers as in the step: leg 1 stands).
POINT_NAMES: tuple[str, ...] = ("hip", "torso_top")
PARAMETER_KEYS: tuple[str, ...] = ("step_length", "speed", "step_time", "single_support_time",
                                   "liftoff_impulse")
SOLVER_KEYS: tuple[str, ...] = ("status", "success", "iterations", "wall_time_s", "variables",
                                "equality_constraints", "inequality_constraints", "evaluations",
                                "max_violation")
#: Events of the built-in contact sequences: a walk's heel strike (touchdown) and liftoff
#: (release, with the liftoff impulse); a run's toe-off (release) and touchdown.
EVENT_NAMES: tuple[str, ...] = ("heel_strike", "liftoff", "toe_off", "touchdown")
#: Interpolation rules gaitopt can evaluate (:mod:`gaitopt.gait.interpolation`).
STATE_INTERPOLATIONS: tuple[str, ...] = ("cubic_hermite",)
CONTROL_INTERPOLATIONS: tuple[str, ...] = ("piecewise_linear",)
DEFAULT_INTERPOLATION: Mapping[str, str] = MappingProxyType({
    "states": "cubic_hermite",
    "controls": "piecewise_linear",
    "description": "reduced states x: cubic Hermite between knots using xdot; controls u: "
                   "piecewise linear between knots; q and qd are functions of x",
})
FAILED_WARNING = ("THIS GAIT DID NOT CONVERGE: the solver reported failure; the trajectories "
                  "are the last iterate and need not satisfy the dynamics or the constraints.")

Array = NDArray[np.float64]


class GaitFileError(ValueError):
    """A gait file or gait data is invalid: names the source, the field path and the problem."""

    def __init__(self, source: str, path: str, message: str) -> None:
        self.source, self.path, self.message = source, path, message
        where = f"{path}: " if path else ""
        super().__init__(f"{source}: {where}{message}")


def _fail(path: str, message: str) -> GaitFileError:
    return GaitFileError("<Gait>", path, message)


def _array(path: str, value: Any, shape: tuple[int | None, ...]) -> Array:
    """A read-only float array of the given shape (None = any length), finite."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise _fail(path, f"expected numbers in an array of shape {_shape_text(shape)}") from None
    if arr.ndim != len(shape) or any(n is not None and n != m for n, m in zip(shape, arr.shape,
                                                                             strict=True)):
        raise _fail(path, f"expected shape {_shape_text(shape)}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise _fail(path, "contains NaN or infinite values")
    arr.setflags(write=False)
    return arr


def _shape_text(shape: tuple[int | None, ...]) -> str:
    return "(" + ", ".join("N" if n is None else str(n) for n in shape) + ")"


def _number(path: str, value: Any, *, minimum: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.number):
        raise _fail(path, f"expected a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise _fail(path, f"expected a finite number, got {value!r}")
    if minimum is not None and x < minimum:
        raise _fail(path, f"expected a number >= {minimum:g}, got {x:g}")
    return x


def _mapping(path: str, value: Any, required: Sequence[str] = ()) -> dict[str, Any]:
    if not isinstance(value, Mapping):
        raise _fail(path, f"expected an object (mapping), got {type(value).__name__}")
    for key in required:
        if key not in value:
            raise _fail(path, f"missing required key {key!r}")
    return dict(value)


def _plain_json(path: str, value: dict[str, Any]) -> dict[str, Any]:
    """``value`` if it is plain JSON data (no NaN, no numpy or other objects)."""
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise _fail(path, f"must be plain JSON data: strings, finite numbers, booleans, "
                    f"null, lists and objects ({exc})") from None
    return value


def _frozen(value: Mapping[str, Any]) -> Mapping[str, Any]:
    return MappingProxyType(copy.deepcopy(dict(value)))


def _increasing(path: str, t: Array) -> None:
    if t.size and np.any(np.diff(t) <= 0.0):
        raise _fail(path, "times must be strictly increasing")


@dataclass(frozen=True, kw_only=True, eq=False)
class GaitPhase:
    """One phase at its K knots: time (s), coordinates, controls, contact forces, states.

    ``contacts`` are the contact names on the ground; ``contact_forces`` maps each of them to
    the (K, 2) world-frame force of the ground on the tip (N). ``x``/``xdot`` (K, n) are the
    phase's reduced (independent) states and their time derivatives, named by
    ``state_names``; ``interpolation`` says how the transcription interpolates between knots.
    """

    name: str
    contacts: tuple[str, ...]
    t: Array
    q: Array
    qd: Array
    qdd: Array
    u: Array
    contact_forces: Mapping[str, Array]
    state_names: tuple[str, ...]
    x: Array
    xdot: Array
    interpolation: Mapping[str, str] = field(default_factory=lambda: dict(DEFAULT_INTERPOLATION))
    #: Optional (K-1,) per-interval error estimate of the transcription (relative, >= 0; see
    #: :mod:`gaitopt.ocp.estimate`); ``None`` in files written before it existed.
    error_estimate: Array | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise _fail("name", "expected a non-empty string")
        set_ = object.__setattr__
        set_(self, "contacts", tuple(self.contacts))
        set_(self, "state_names", tuple(self.state_names))
        t = _array("t", self.t, (None,))
        if t.size < 2:
            raise _fail("t", f"a phase needs at least 2 knots, got {t.size}")
        _increasing("t", t)
        k, n = t.size, len(self.state_names)
        set_(self, "t", t)
        q = _array("q", self.q, (k, None))
        set_(self, "q", q)
        for name in ("qd", "qdd"):
            set_(self, name, _array(name, getattr(self, name), (k, q.shape[1])))
        set_(self, "u", _array("u", self.u, (k, None)))
        set_(self, "x", _array("x", self.x, (k, n)))
        set_(self, "xdot", _array("xdot", self.xdot, (k, n)))
        forces = _mapping("contact_forces", self.contact_forces)
        if set(forces) != set(self.contacts):
            raise _fail("contact_forces", f"keys {sorted(forces)} must be the contacts on the "
                        f"ground {sorted(self.contacts)}")
        set_(self, "contact_forces", MappingProxyType(
            {c: _array(f"contact_forces.{c}", forces[c], (k, 2)) for c in self.contacts}))
        interp = _mapping("interpolation", self.interpolation, required=("states", "controls"))
        set_(self, "interpolation", MappingProxyType({str(a): str(b) for a, b in interp.items()}))
        if self.error_estimate is not None:
            est = _array("error_estimate", self.error_estimate, (k - 1,))
            if np.any(est < 0.0):
                raise _fail("error_estimate", "expected numbers >= 0")
            set_(self, "error_estimate", est)

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])


@dataclass(frozen=True, kw_only=True, eq=False)
class GaitEvent:
    """A contact event: ``heel_strike`` (inelastic impact) or ``liftoff`` (with its impulse).

    ``leg`` is the contact that strikes or lifts off; ``impulses`` maps each contact receiving
    an impulse to its (2,) world-frame impulse of the ground on the tip (N s); ``qd_before``
    and ``qd_after`` are the (nq,) velocities just before and after the event.
    """

    name: str
    t: float
    leg: str
    impulses: Mapping[str, Array]
    qd_before: Array
    qd_after: Array

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise _fail("name", f"expected an event name (letters, digits, '_'; the built-in "
                        f"sequences use {', '.join(EVENT_NAMES)}), got {self.name!r}")
        set_ = object.__setattr__
        set_(self, "t", _number("t", self.t))
        imp = _mapping("impulses", self.impulses)
        set_(self, "impulses", MappingProxyType(
            {str(c): _array(f"impulses.{c}", v, (2,)) for c, v in imp.items()}))
        before = _array("qd_before", self.qd_before, (None,))
        set_(self, "qd_before", before)
        set_(self, "qd_after", _array("qd_after", self.qd_after, before.shape))


@dataclass(frozen=True, kw_only=True, eq=False)
class GaitSamples:
    """Dense samples: ``t`` (N,) s, ``q``/``qd`` (N, nq), ``u`` (N, nu), ``points`` name ->
    (N, 2) world positions (m) of at least :data:`POINT_NAMES` (the recorded points are
    those of :func:`gaitopt.gait.record.sample_points`: for the five-link biped also
    ``knee_1, knee_2, tip_1, tip_2``)."""

    t: Array
    q: Array
    qd: Array
    u: Array
    points: Mapping[str, Array]

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        t = _array("t", self.t, (None,))
        if t.size < 2:
            raise _fail("t", f"need at least 2 samples, got {t.size}")
        _increasing("t", t)
        n = t.size
        set_(self, "t", t)
        q = _array("q", self.q, (n, None))
        set_(self, "q", q)
        set_(self, "qd", _array("qd", self.qd, (n, q.shape[1])))
        set_(self, "u", _array("u", self.u, (n, None)))
        points = _mapping("points", self.points, required=POINT_NAMES)
        set_(self, "points", MappingProxyType(
            {str(p): _array(f"points.{p}", v, (n, 2)) for p, v in points.items()}))


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
            model = _parse_model(self.model_data)
        except ModelError as exc:
            raise _fail(f"model.{exc.path}" if exc.path else "model",
                        f"{exc.value!r} is invalid: {exc.allowed}") from None
        if self.format != FORMAT:
            raise _fail("format", f"expected {FORMAT!r}, got {self.format!r}")
        if self.version not in READABLE_VERSIONS:
            raise _fail("version", f"expected one of {READABLE_VERSIONS}, got {self.version!r}")
        set_ = object.__setattr__
        if self.contact_sequence is not None:
            seq = _mapping("contact_sequence", self.contact_sequence,
                           required=("name", "phases", "events"))
            set_(self, "contact_sequence", _frozen(_plain_json("contact_sequence", seq)))
        set_(self, "model_data", _frozen(self.model_data))
        set_(self, "options", _frozen(_plain_json("options", _mapping("options", self.options))))
        params = _mapping("parameters", self.parameters, required=PARAMETER_KEYS)
        set_(self, "parameters", MappingProxyType(
            {k: _number(f"parameters.{k}", v, minimum=0.0) for k, v in params.items()}))
        cost = _mapping("cost", self.cost, required=("value", "formula"))
        cost["value"] = _number("cost.value", cost["value"])
        if not isinstance(cost["formula"], str):
            raise _fail("cost.formula", "expected a string (the cost formula in words)")
        set_(self, "cost", _frozen(_plain_json("cost", cost)))
        set_(self, "solver", _frozen(_plain_json("solver", _check_solver(self.solver))))
        set_(self, "phases", tuple(self.phases))
        set_(self, "events", tuple(self.events))
        _check_consistency(self, model)

    def __repr__(self) -> str:
        phases = "+".join(f"{p.name}({p.t.size})" for p in self.phases)
        return (f"Gait(model={self.model_data.get('name')!r}, speed={self.speed:.4g} m/s, "
                f"step_length={self.step_length:.4g} m, cost={self.cost_value:.6g}, "
                f"status={self.status!r}, phases={phases})")

    # -- convenience ------------------------------------------------------------------------
    @cached_property
    def model(self) -> RobotModel:
        """The robot model the gait was solved for."""
        return _parse_model(self.model_data)

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
        return float(self.parameters["step_time"])

    @property
    def cost_value(self) -> float:
        """The objective (paper eq. 4/5: energy per metre) as solved."""
        return float(self.cost["value"])

    @property
    def success(self) -> bool:
        return bool(self.solver["success"])

    @property
    def status(self) -> str:
        return str(self.solver["status"])

    def stride_samples(self, n_steps: int = 2) -> GaitSamples:
        """Samples of ``n_steps`` consecutive steps (a stride is 2), legs labelled physically.

        Step k (k = 0, 1, ...) is this step's samples with time shifted by k * step_time, x
        (the ``x`` coordinate and every point) shifted by k * step_length, and, for odd k, the
        legs swapped (coordinates, controls and points of leg 1 <-> leg 2), so that
        ``points["tip_1"]`` follows the same physical leg throughout. A sample repeated at a
        step boundary is kept once.
        """
        if isinstance(n_steps, bool) or not isinstance(n_steps, int) or n_steps < 1:
            raise ValueError(f"n_steps: expected an integer >= 1, got {n_steps!r}")
        s = self.samples
        from gaitopt.robot.symmetry import swap_names, swap_permutations

        q_swap, u_swap = swap_permutations(self.model)
        names = swap_names(self.model)
        period, shift = self.step_time, self.step_length
        x_index = self.model.coordinate_names.index("x")
        duplicate = abs((s.t[-1] - s.t[0]) - period) <= 1e-9 * max(1.0, period)
        parts: dict[str, list[Array]] = {"t": [], "q": [], "qd": [], "u": []}
        point_parts: dict[str, list[Array]] = {p: [] for p in s.points}
        for k in range(n_steps):
            sl = slice(1 if (k > 0 and duplicate) else 0, None)
            swap = k % 2 == 1
            q = (s.q[:, q_swap] if swap else s.q.copy())[sl]
            q[:, x_index] += k * shift
            parts["t"].append(s.t[sl] + k * period)
            parts["q"].append(q)
            parts["qd"].append((s.qd[:, q_swap] if swap else s.qd)[sl])
            parts["u"].append((s.u[:, u_swap] if swap else s.u)[sl])
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

    # -- notebook use (gaitopt.viz.notebook, imported on first use) -------------------------
    def _repr_html_(self) -> str:
        """Jupyter's view: a table of speed, step length and time, cost, solver status, largest
        violation and the verify verdict (:func:`gaitopt.viz.notebook.summary_html`)."""
        from gaitopt.viz.notebook import summary_html

        return summary_html(self)

    def plot(self, kind: str = "overview") -> Figure:
        """A Matplotlib figure: ``overview`` (angles, hip, torques over the step), ``torques``,
        ``hip``, ``heights`` or ``poses`` (:func:`gaitopt.viz.notebook.gait_figure`)."""
        from gaitopt.viz.notebook import gait_figure

        return gait_figure(self, kind)

    def animate(self, path: str | os.PathLike[str] | None = None, *, steps: int = 4,
                fps: int = 30) -> Path | GifAnimation:
        """``steps`` steps of the walk in real time: written to ``path`` (.gif or .mp4; returns
        the path) or, without a path, an animated GIF that Jupyter shows inline."""
        from gaitopt.viz.notebook import animate

        return animate(self, path, steps=steps, fps=fps)


# -- validation helpers ------------------------------------------------------------------------

def _parse_model(data: Any) -> RobotModel:
    """The model of a gait's ``model`` field (model-file schema).

    A link giving both ``inertia`` and ``shape`` is read by its explicit inertia (older
    loaders wrote both but accepted only one).
    """
    if isinstance(data, Mapping) and isinstance(data.get("links"), list):
        data = dict(data)
        data["links"] = [
            {k: v for k, v in link.items() if k != "shape"}
            if isinstance(link, Mapping) and "inertia" in link and "shape" in link else link
            for link in data["links"]]
    return model_from_dict(data, source="model")


def _check_solver(value: Any) -> dict[str, Any]:
    solver = _mapping("solver", value, required=SOLVER_KEYS)
    if not isinstance(solver["status"], str):
        raise _fail("solver.status", "expected a string")
    if isinstance(solver["success"], np.bool_):
        solver["success"] = bool(solver["success"])
    if not isinstance(solver["success"], bool):
        raise _fail("solver.success", f"expected true or false, got {solver['success']!r}")
    for key in ("iterations", "variables", "equality_constraints", "inequality_constraints"):
        v = solver[key]
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
            raise _fail(f"solver.{key}", f"expected an integer >= 0, got {v!r}")
        solver[key] = int(v)
    for key in ("wall_time_s", "max_violation"):
        solver[key] = _number(f"solver.{key}", solver[key], minimum=0.0)
    evaluations = _mapping("solver.evaluations", solver["evaluations"])
    for kind, count in evaluations.items():
        if isinstance(count, bool) or not isinstance(count, int | np.integer) or count < 0:
            raise _fail(f"solver.evaluations.{kind}", f"expected an integer >= 0, got {count!r}")
    solver["evaluations"] = {str(k): int(v) for k, v in evaluations.items()}
    return solver


def _check_consistency(gait: Gait, model: RobotModel) -> None:
    nq, nu = model.nq, model.nu
    contacts = [c.name for c in model.contacts]
    p = gait.parameters
    if p["step_time"] <= 0.0:
        raise _fail("parameters.step_time", f"expected > 0, got {p['step_time']:g}")
    if p["single_support_time"] > p["step_time"] * (1 + 1e-9):
        raise _fail("parameters.single_support_time",
                    f"{p['single_support_time']:g} s exceeds the step time {p['step_time']:g} s")
    if not gait.phases:
        raise _fail("phases", "expected at least one phase")
    for i, phase in enumerate(gait.phases):
        where = f"phases[{i}]"
        if not isinstance(phase, GaitPhase):
            raise _fail(where, f"expected a GaitPhase, got {type(phase).__name__}")
        if phase.q.shape[1] != nq or phase.u.shape[1] != nu:
            raise _fail(f"{where}.q", f"the model has nq={nq}, nu={nu}; the phase has "
                        f"q with {phase.q.shape[1]} and u with {phase.u.shape[1]} columns")
        for c in phase.contacts:
            if c not in contacts:
                raise _fail(f"{where}.contacts", f"{c!r} is not a contact of the model "
                            f"({', '.join(contacts)})")
        if i > 0 and not math.isclose(phase.t[0], gait.phases[i - 1].t[-1], abs_tol=1e-9):
            raise _fail(f"{where}.t", f"starts at {phase.t[0]:g} s but the previous phase ends "
                        f"at {gait.phases[i - 1].t[-1]:g} s")
    span = gait.phases[-1].t[-1] - gait.phases[0].t[0]
    if not math.isclose(span, p["step_time"], rel_tol=1e-6, abs_tol=1e-9):
        raise _fail("parameters.step_time", f"{p['step_time']:g} s differs from the phases' "
                    f"span {span:g} s")
    t0, t1 = gait.phases[0].t[0] - 1e-9, gait.phases[-1].t[-1] + 1e-9
    for i, event in enumerate(gait.events):
        where = f"events[{i}]"
        if not isinstance(event, GaitEvent):
            raise _fail(where, f"expected a GaitEvent, got {type(event).__name__}")
        if event.leg not in contacts:
            raise _fail(f"{where}.leg", f"{event.leg!r} is not a contact of the model")
        if not t0 <= event.t <= t1:
            raise _fail(f"{where}.t", f"{event.t:g} s is outside the step [{t0:g}, {t1:g}] s")
        if event.qd_before.size != nq:
            raise _fail(f"{where}.qd_before", f"expected {nq} entries (nq)")
        for c in event.impulses:
            if c not in contacts:
                raise _fail(f"{where}.impulses", f"{c!r} is not a contact of the model")
    s = gait.samples
    if not isinstance(s, GaitSamples):
        raise _fail("samples", f"expected GaitSamples, got {type(s).__name__}")
    if s.q.shape[1] != nq or s.u.shape[1] != nu:
        raise _fail("samples.q", f"the model has nq={nq}, nu={nu}; the samples have "
                    f"{s.q.shape[1]} and {s.u.shape[1]} columns")
    if s.t[0] < t0 or s.t[-1] > t1:
        raise _fail("samples.t", f"[{s.t[0]:g}, {s.t[-1]:g}] s is outside the step")


def _gait_from_dict(data: Any) -> Gait:
    top = _mapping("", data, required=("format", "version"))
    if top["format"] != FORMAT:
        raise _fail("format", f"expected {FORMAT!r}, got {top['format']!r} (not a gait file)")
    version = top["version"]
    major = _major_version(version)
    if major not in READABLE_VERSIONS:
        raise _fail("version", f"major version {version!r} is not supported: this gaitopt "
                    f"({__version__}) reads {FORMAT} versions "
                    f"{', '.join(map(str, READABLE_VERSIONS))}")
    for key in ("created", "gaitopt_version", "model", "options", "parameters", "cost",
                "solver", "phases", "events", "samples"):
        if key not in top:
            raise _fail("", f"missing required key {key!r}")
    phases = []
    if not isinstance(top["phases"], list):
        raise _fail("phases", "expected a list of phases")
    for i, raw in enumerate(top["phases"]):
        ph = _mapping(f"phases[{i}]", raw, required=(
            "name", "contacts", "t", "q", "qd", "qdd", "u", "contact_forces", "state_names",
            "x", "xdot", "interpolation"))
        phases.append(_with_path(f"phases[{i}]", GaitPhase, ph))
    if not isinstance(top["events"], list):
        raise _fail("events", "expected a list of events")
    events = []
    for i, raw in enumerate(top["events"]):
        ev = _mapping(f"events[{i}]", raw, required=(
            "name", "t", "leg", "impulses", "qd_before", "qd_after"))
        events.append(_with_path(f"events[{i}]", GaitEvent, ev))
    sm = _mapping("samples", top["samples"], required=("t", "q", "qd", "u", "points"))
    samples = _with_path("samples", GaitSamples, sm)
    return Gait(model_data=_mapping("model", top["model"]), options=top["options"],
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
        raise _fail(f"{prefix}.{exc.path}", exc.message) from None


def _strings(path: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(path, "expected a list of strings")
    return tuple(value)


def _phase_to_dict(p: GaitPhase) -> dict[str, Any]:
    return {"name": p.name, "contacts": list(p.contacts), "t": p.t.tolist(), "q": p.q.tolist(),
            "qd": p.qd.tolist(), "qdd": p.qdd.tolist(), "u": p.u.tolist(),
            "contact_forces": {c: v.tolist() for c, v in p.contact_forces.items()},
            "state_names": list(p.state_names), "x": p.x.tolist(), "xdot": p.xdot.tolist(),
            "interpolation": dict(p.interpolation),
            **({} if p.error_estimate is None else {"error_estimate": p.error_estimate.tolist()})}


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
