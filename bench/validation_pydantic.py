"""Prototype (throwaway, for ``bench/validation.py``): the walking options and one gait-file
phase as pydantic v2 models, with the checks of
:func:`gaitopt.gait.options.gait_options.validate_options`
and :class:`gaitopt.gait.record.parts.GaitPhase`, so that their messages, speed and length can
be compared with the hand-written ones. Not used by gaitopt (issue 26, item 5: the decision is
in docs/architecture.md, "Validation").

Two layers, counted separately by the bench:

* the models (:class:`OptionsModel`, :class:`PhaseModel`): pydantic's constraints (``gt``,
  ``ge``, ``Literal``, ``extra="forbid"``) for single fields, and field validators that read
  the fields declared before them (``info.data``) for the cross-field checks, so that every
  error keeps the path of the field it is about; the checks that need the legs' reach read
  it from the validation context (``context={"reach": ...}``);
* the message layer (:func:`one_line`): pydantic's ``ValidationError`` is several lines
  ("1 validation error for ...", the field, the message, the input and a URL) and says
  "Input should be greater than 0"; gaitopt's messages are one line, ``field = value: must be
  > 0``. :func:`one_line` rewrites the first error into gaitopt's form.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
)
from pydantic_core import PydanticCustomError

from gaitopt.units import format_speed

# -- the options ------------------------------------------------------------------------------


def _fail(kind: str, message: str, shown: str | None = None) -> PydanticCustomError:
    """An error whose message is ``message`` as it is (pydantic's templates take ``{name}``
    without format specs, so the numbers are formatted here); ``shown``: the value as the
    message shows it (with its unit), else its ``repr``."""
    return PydanticCustomError(kind, "{message}", {"message": message, "shown": shown})


def _ordered(value: tuple[float, float]) -> tuple[float, float]:
    if value[0] > value[1]:
        raise _fail("bounds", "lower bound must be <= upper bound")
    return value


Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
Fraction = Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)]
Bounds = Annotated[tuple[Finite, Finite], AfterValidator(_ordered)]
PositiveBounds = Annotated[tuple[Positive, Positive], AfterValidator(_ordered)]
Knots = tuple[Annotated[int, Field(ge=2, le=400, strict=True)],
              Annotated[int, Field(ge=1, le=400, strict=True)]]


class OptionsModel(BaseModel):
    """The 37 fields of :class:`gaitopt.gait.options.gait_options.GaitOptions` with their checks;
    field order matters: a cross-field check sits on the later field."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True)

    formulation: Literal["reduced", "full"] = "reduced"
    gait: Literal["walk", "run", "heel-toe"] = "walk"
    speed_bounds: PositiveBounds = (0.02, 1.5)
    speed: float | None = 0.2
    step_length_bounds: PositiveBounds = (0.02, 0.8)
    step_length: float | None = None
    step_time: float | None = None
    ankle: bool = True
    impulse: bool = True
    single_support_fraction_bounds: Bounds | None = None
    single_support_fraction: Annotated[float, Field(ge=0.05, le=1.0, allow_inf_nan=False)] = 0.85
    knots: Knots = (16, 6)
    transcription: Literal["hermite-simpson", "hermite-simpson-separated",
                           "trapezoidal"] = "hermite-simpson-separated"
    periodic_controls: bool = True
    friction: Positive | None = None
    unilateral_impulses: bool = True
    min_stance_knee_flexion: Annotated[float, Field(ge=0.0, lt=1.5, allow_inf_nan=False)] = 0.1
    torso_bounds: Bounds = (-0.8, 0.8)
    rate_bound: Positive = 15.0
    max_impulse: NonNegative = 30.0
    tol: Fraction = 1e-7
    max_iter: Annotated[int, Field(ge=1, strict=True)] = 1000
    continuation: bool = True
    multistart: bool = False
    contact_sequence: dict[str, Any] | None = None
    free_phase_fractions: bool = False
    stride: bool = False
    cost: Literal["paper", "work", "metabolic"] = "paper"
    efficiency_positive: Positive = 0.25
    efficiency_negative: Positive = 1.2
    resting_power: NonNegative = 1.2
    cost_smoothing: Positive = 0.01
    cost_regularization: NonNegative = 0.0
    mesh_tol: Fraction | None = None
    accuracy: Fraction | None = 0.01
    control_model: Literal["paper", "jumps"] = "jumps"
    swing_clearance: Positive | None = None
    clearance_profile: Literal["parabola", "quartic"] = "quartic"
    knot_spacing: Literal["uniform", "cosine"] = "cosine"

    @field_validator("speed")
    @classmethod
    def _speed(cls, v: float | None, info: ValidationInfo) -> float | None:
        if v is None:
            return v
        if not math.isfinite(v):
            raise _fail("finite", "must be a finite number")
        if v <= 0.0:
            raise _fail("speed", "must be > 0 (or free)", format_speed(v))
        lo, hi = info.data.get("speed_bounds", (v, v))
        if not lo <= v <= hi:
            raise _fail("speed", f"must lie in speed_bounds [{format_speed(lo)}, "
                        f"{format_speed(hi)}]", format_speed(v))
        return v

    @field_validator("step_length")
    @classmethod
    def _step_length(cls, v: float | None, info: ValidationInfo) -> float | None:
        if v is None:
            return v
        if not math.isfinite(v):
            raise _fail("finite", "must be a finite number")
        if v <= 0.0:
            raise _fail("positive", "must be > 0 (or free)")
        longest = 2.0 * (info.context or {}).get("reach", math.inf) * 0.97
        if v >= longest:
            raise _fail("reach", "longer than the legs can reach (both tips on the ground with "
                        f"the hip above them needs step_length < {longest:.3f} m)", f"{v:g} m")
        lo, hi = info.data.get("step_length_bounds", (v, v))
        if not lo <= v <= hi:
            raise _fail("range", f"must lie in step_length_bounds [{lo:g}, {hi:g}] m", f"{v:g} m")
        return v

    @field_validator("step_time")
    @classmethod
    def _step_time(cls, v: float | None, info: ValidationInfo) -> float | None:
        if v is None:
            return v
        if not math.isfinite(v):
            raise _fail("finite", "must be a finite number")
        if v <= 0.0:
            raise _fail("positive", "must be > 0 (or free)")
        if info.data.get("step_length") is not None:
            raise _fail("exclusive", "give at most one of them (with the speed they fix each "
                        "other)", f"{v:g} s and step_length = {info.data['step_length']:g} m")
        speed = info.data.get("speed")
        lo_v, hi_v = (speed, speed) if speed is not None else info.data["speed_bounds"]
        l_lo, l_hi = info.data["step_length_bounds"]
        longest = 2.0 * (info.context or {}).get("reach", math.inf) * 0.97
        if v * hi_v < l_lo or v * lo_v > min(l_hi, longest):
            what = (f"speed {format_speed(speed)}" if speed is not None else
                    f"speed_bounds [{format_speed(lo_v)}, {format_speed(hi_v)}]")
            steps = (f"{v * lo_v:.3g} m" if lo_v == hi_v else f"{v * lo_v:.3g}-{v * hi_v:.3g} m")
            raise _fail("range", f"with the {what} the step length {steps} would leave "
                        f"[{l_lo:g}, {min(l_hi, longest):.3f}] m (step_length_bounds and the "
                        "legs' reach)", f"{v:g} s")
        return v

    @field_validator("single_support_fraction_bounds")
    @classmethod
    def _fraction_bounds(cls, v: tuple[float, float] | None,
                         info: ValidationInfo) -> tuple[float, float] | None:
        if v is None:
            return v
        if info.data.get("formulation") != "full":
            raise _fail("formulation", "a free single-support fraction needs formulation "
                        "'full'")
        if v[0] < 0.05 or v[1] >= 1.0:
            raise _fail("range", "must lie in [0.05, 1) (1 is the single-support walk)")
        return v

    @field_validator("single_support_fraction")
    @classmethod
    def _fraction(cls, v: float, info: ValidationInfo) -> float:
        bounds = info.data.get("single_support_fraction_bounds")
        if bounds is not None and not bounds[0] <= v <= bounds[1]:
            raise _fail("range", f"must lie in single_support_fraction_bounds [{bounds[0]:g}, "
                        f"{bounds[1]:g}] (it is the first guess)")
        if info.data.get("gait") == "run" and v >= 1.0:
            raise _fail("run", "gait 'run' needs single_support_fraction < 1 (the stance share)")
        return v

    @field_validator("knots")
    @classmethod
    def _knots(cls, v: tuple[int, int], info: ValidationInfo) -> tuple[int, int]:
        if v[0] < 3 or (info.data.get("single_support_fraction", 0.85) < 1.0 and v[1] < 2):
            raise _fail("knots", "need >= 3 knots in single support and >= 2 in double "
                        "support")
        return v

    @field_validator("min_stance_knee_flexion")
    @classmethod
    def _flexion(cls, v: float, info: ValidationInfo) -> float:
        if info.data.get("formulation") == "reduced" and v == 0.0:
            raise _fail("range", "must lie in (0, 1.5) in the reduced formulation (its leg "
                        "inverse kinematics is singular at a straight knee; formulation "
                        "'full' allows 0)")
        return v

    @field_validator("torso_bounds")
    @classmethod
    def _torso(cls, v: tuple[float, float]) -> tuple[float, float]:
        if not v[0] <= 0.0 <= v[1]:
            raise _fail("upright", "must contain 0 (upright), or the biped cannot stand")
        return v

    @field_validator("contact_sequence")
    @classmethod
    def _sequence(cls, v: dict[str, Any] | None, info: ValidationInfo) -> dict[str, Any] | None:
        if v is not None and info.data.get("formulation") != "full":
            raise _fail("formulation", "a contact sequence needs formulation 'full'")
        if v is not None:
            from gaitopt.gait.sequence.contact_sequence import (
                ContactSequenceError,
                sequence_from_dict,
            )

            try:
                sequence_from_dict(v)
            except ContactSequenceError as exc:
                raise _fail("sequence", str(exc)) from None
        return v

    @field_validator("free_phase_fractions", "stride")
    @classmethod
    def _full_only(cls, v: bool, info: ValidationInfo) -> bool:
        if v and info.data.get("formulation") != "full":
            raise _fail("formulation", "needs formulation 'full'")
        if v and info.data.get("single_support_fraction_bounds") is not None:
            raise _fail("exclusive", "not with single_support_fraction_bounds (give "
                        "free_phase_fractions: it frees every phase)")
        return v

    @field_validator("swing_clearance")
    @classmethod
    def _clearance(cls, v: float | None, info: ValidationInfo) -> float | None:
        reach = (info.context or {}).get("reach", math.inf)
        if v is not None and not v < reach:
            raise _fail("range", f"must lie in (0, {reach:.3f}) m (above the ground, below the "
                        "leg's reach; or None)", f"{v:g} m")
        return v

    @field_validator("gait")
    @classmethod
    def _gait(cls, v: str, info: ValidationInfo) -> str:
        if v != "walk" and info.data.get("formulation") != "full":
            raise _fail("formulation", f"gait {v!r} needs formulation 'full'")
        return v

    @field_validator("impulse")
    @classmethod
    def _impulse(cls, v: bool, info: ValidationInfo) -> bool:
        if v and info.data.get("gait") == "run":
            raise _fail("run", "gait 'run' needs impulse off (no liftoff impulse in a run)")
        return v


# -- the message layer ------------------------------------------------------------------------

#: pydantic's error types of single-field constraints -> gaitopt's wording of the rule.
_RULES: dict[str, str] = {
    "greater_than": "must be > {gt:g}", "greater_than_equal": "must be >= {ge:g}",
    "less_than": "must be < {lt:g}", "less_than_equal": "must be <= {le:g}",
    "finite_number": "must be a finite number", "float_parsing": "must be a number",
    "float_type": "must be a number", "int_type": "must be an integer",
    "literal_error": "must be one of {expected}", "extra_forbidden": "unknown option",
    "tuple_type": "must be a pair (lower, upper)", "too_short": "must be a pair",
    "too_long": "must be a pair", "bool_type": "must be true or false",
    "bool_parsing": "must be true or false", "missing": "missing required key",
}


def path_of(loc: tuple[int | str, ...]) -> str:
    """``('phases', 0, 'q')`` -> ``phases[0].q``."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


_INTERVALS: dict[str, str] = {}


def _interval(model: type[BaseModel], name: str) -> str | None:
    """``[0.05, 1]``, ``(0, 1)``: the range of a field bounded on both sides, from the model's
    JSON schema (pydantic's error names only the side that was crossed)."""
    if not _INTERVALS:
        for key, prop in model.model_json_schema()["properties"].items():
            for s in [prop, *prop.get("anyOf", [])]:
                lo = s.get("minimum", s.get("exclusiveMinimum"))
                hi = s.get("maximum", s.get("exclusiveMaximum"))
                if lo is not None and hi is not None:
                    _INTERVALS[key] = (f"{'(' if 'exclusiveMinimum' in s else '['}{lo:g}, "
                                       f"{hi:g}{')' if 'exclusiveMaximum' in s else ']'}")
    return _INTERVALS.get(name)


def one_line(exc: ValidationError, model: type[BaseModel] = BaseModel) -> str:
    """The first error of ``exc`` in gaitopt's form, one line: ``path = value: rule``, the
    rule with the allowed range (both ends where the field has two)."""
    err = exc.errors(include_url=False)[0]
    ctx, path = err.get("ctx", {}), path_of(err["loc"])
    rule = _RULES.get(err["type"])
    interval = _interval(model, path) if model is not BaseModel else None
    if err["type"] in ("greater_than", "greater_than_equal", "less_than", "less_than_equal") \
            and interval:
        text = f"must lie in {interval}"
    else:
        text = rule.format(**ctx) if rule else str(ctx.get("message", err["msg"]))
    shown = ctx.get("shown") or repr(err["input"])
    return f"{path} = {shown}: {text}"


def default_line(exc: ValidationError) -> str:
    """pydantic's own message of the first error, without the title and the URL."""
    err = exc.errors(include_url=False)[0]
    return f"{path_of(err['loc'])}: {err['msg']} [input_value={err['input']!r}]"


# -- a gait-file phase ------------------------------------------------------------------------


def _array(value: Any) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise _fail("array", "expected numbers in an array") from None
    if not np.all(np.isfinite(arr)):
        raise _fail("finite", "contains NaN or infinite values")
    arr.setflags(write=False)
    return arr


def _shape(arr: np.ndarray, shape: tuple[int | None, ...]) -> np.ndarray:
    if arr.ndim != len(shape) or any(n is not None and n != m for n, m in zip(shape, arr.shape,
                                                                             strict=True)):
        text = "(" + ", ".join("N" if n is None else str(n) for n in shape) + ")"
        raise _fail("shape", f"expected shape {text}, got {arr.shape}")
    return arr


Arr = Annotated[Any, BeforeValidator(_array)]


class Interpolation(BaseModel):
    """A phase's interpolation rules (``states``, ``controls``, free text)."""

    model_config = ConfigDict(extra="allow", frozen=True)
    states: str
    controls: str


class PhaseModel(BaseModel):
    """One phase of the gait file, as :class:`gaitopt.gait.record.parts.GaitPhase` checks it;
    a shape that depends on another field (K knots, nq columns) is checked on the later
    field from ``info.data``."""

    model_config = ConfigDict(frozen=True, extra="ignore", arbitrary_types_allowed=True)

    name: Annotated[str, Field(min_length=1, strict=True)]
    contacts: tuple[Annotated[str, Field(strict=True)], ...]
    state_names: tuple[Annotated[str, Field(strict=True)], ...]
    t: Arr
    q: Arr
    qd: Arr
    qdd: Arr
    u: Arr
    x: Arr
    xdot: Arr
    contact_forces: dict[str, Arr]
    interpolation: Interpolation
    error_estimate: Arr | None = None
    costates: Arr | None = None

    @field_validator("t")
    @classmethod
    def _t(cls, t: np.ndarray) -> np.ndarray:
        _shape(t, (None,))
        if t.size < 2:
            raise _fail("knots", f"a phase needs at least 2 knots, got {t.size}")
        if np.any(np.diff(t) <= 0.0):
            raise _fail("increasing", "times must be strictly increasing")
        return t

    @field_validator("q", "qd", "qdd", "u", "x", "xdot", "costates")
    @classmethod
    def _rows(cls, v: np.ndarray | None, info: ValidationInfo) -> np.ndarray | None:
        if v is None or "t" not in info.data:
            return v
        k = info.data["t"].size
        cols = {"qd": "q", "qdd": "q"}.get(info.field_name or "")
        n = (info.data[cols].shape[1] if cols and cols in info.data else
             len(info.data["state_names"]) if info.field_name in ("x", "xdot", "costates")
             else None)
        return _shape(v, (k, n))

    @field_validator("contact_forces")
    @classmethod
    def _forces(cls, v: dict[str, np.ndarray], info: ValidationInfo) -> dict[str, np.ndarray]:
        contacts = info.data.get("contacts", ())
        if set(v) != set(contacts):
            raise _fail("keys", f"keys {sorted(v)} must be the contacts on the ground "
                        f"{sorted(contacts)}")
        if "t" in info.data:
            for arr in v.values():
                _shape(arr, (info.data["t"].size, 2))
        return v

    @field_validator("error_estimate")
    @classmethod
    def _estimate(cls, v: np.ndarray | None, info: ValidationInfo) -> np.ndarray | None:
        if v is None or "t" not in info.data:
            return v
        _shape(v, (info.data["t"].size - 1,))
        if np.any(v < 0.0):
            raise _fail("range", "expected numbers >= 0")
        return v


def phase_line(exc: ValidationError, prefix: str) -> tuple[str, str]:
    """(path, message) of the first error, as :class:`gaitopt.gait.record.fields.GaitFileError`
    carries them."""
    err = exc.errors(include_url=False)[0]
    rule = _RULES.get(err["type"])
    text = rule.format(**err.get("ctx", {})) if rule else err["msg"]
    return path_of((prefix, *err["loc"])), text
