"""Options of the walking problem: the variant, the targets and every bound, validated.

(One concept, kept whole at about 430 lines: the options and the check of each; a third of
the length is the documentation of the fields.)

Defaults follow the paper's problem (ankle torques and the liftoff impulse on, single support
85 % of the step, the speed given at 12 m/min, the paper's globally optimal speed, and the step
length free) on a grid whose cost is converged to well within 1 %: 16 + 6 knots with the
torques free to jump at the events (``control_model="jumps"``), transcribed by separated
Hermite-Simpson (derivatives compiled per grid point). The paper's own setting, 8 + 5 knots
with continuous and periodic controls in DIRCOL's compressed Hermite-Simpson form (the paper's
NLP), is :meth:`GaitOptions.paper` (CLI: ``--paper-grid``). The measurements behind the
choices are in ``docs/walking.md`` (section 6) and ``docs/results/benchmarks-gait.md``; every field
is documented there.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Literal, TypeVar, cast

from gaitopt.gait.formulation_traits import FORMULATION_TRAITS
from gaitopt.robot.biped import Biped
from gaitopt.units import format_speed

Transcription = Literal["hermite-simpson", "hermite-simpson-separated", "trapezoidal"]
#: The accepted values of ``GaitOptions.transcription`` (the literal above, for validation).
TRANSCRIPTIONS: tuple[str, ...] = ("hermite-simpson", "hermite-simpson-separated",
                                   "trapezoidal")
Formulation = Literal["reduced", "full"]
GaitKind = Literal["walk", "run", "heel-toe"]
#: The built-in gaits (``GaitOptions.gait``).
GAITS = ("walk", "run", "heel-toe")
CostName = Literal["paper", "work", "metabolic"]
FORMULATIONS: tuple[str, ...] = tuple(FORMULATION_TRAITS)
ControlModel = Literal["paper", "jumps"]
#: The control models (see ``docs/walking.md``, "Control model").
CONTROL_MODELS = ("paper", "jumps")
ClearanceProfile = Literal["parabola", "quartic"]
#: The swing clearance profiles (see ``docs/walking.md``, "Swing clearance").
CLEARANCE_PROFILES = ("parabola", "quartic")
KnotSpacing = Literal["uniform", "cosine"]
#: The knot spacings of the target grid (see ``docs/walking.md``, section 6).
KNOT_SPACINGS = ("uniform", "cosine")
#: The paper's grid, control model and NLP (8 + 5 knots, controls continuous at the heel
#: strike and periodic, DIRCOL's compressed Hermite-Simpson form): :meth:`GaitOptions.paper`
#: and ``--paper-grid``. Its cost is about 13 % above the fine-grid limit (docs/walking.md,
#: section 6); it is kept to reproduce the paper.
PAPER_GRID: dict[str, Any] = {"knots": (8, 5), "control_model": "paper",
                              "transcription": "hermite-simpson", "knot_spacing": "uniform"}
#: Fields whose default changed, with the value they had before: a gait file or sweep written
#: before the field existed was solved with it (the control model arrived while the paper's
#: was the default, the transcription field while the compressed form was), so data that
#: lacks the field means this value, not today's default. (Knots were uniform before the
#: knot spacing became a field and its default until 2026-12-02.)
LEGACY_DEFAULTS: dict[str, Any] = {"control_model": "paper", "transcription": "hermite-simpson",
                                   "knot_spacing": "uniform", "accuracy": None}


class GaitOptionsError(ValueError):
    """A walking-problem option is out of range (names the field and what is allowed)."""


class ModelFloat(float):
    """A default number that follows the model: its value is the reference biped's (the
    five-link biped's), and :func:`gaitopt.gait.model_defaults.options_for_model` replaces
    it with the model's (:mod:`gaitopt.gait.model_scale`). A number given by the caller is
    a plain ``float`` and stays."""

    __slots__ = ()


class ModelTuple(tuple):
    """A default pair (bounds, knots) that follows the model, as :class:`ModelFloat`."""

    __slots__ = ()


class ModelStr(str):
    """A default choice (gait, formulation) that follows the model, as :class:`ModelFloat`."""

    __slots__ = ()


_T = TypeVar("_T")


def from_model(value: _T) -> _T:
    """``value`` marked as a default that follows the model (:class:`ModelFloat`,
    :class:`ModelTuple`, :class:`ModelStr`)."""
    if isinstance(value, float):
        return cast(_T, ModelFloat(value))
    if isinstance(value, tuple):
        return cast(_T, ModelTuple(value))
    if isinstance(value, str):
        return cast(_T, ModelStr(value))
    raise TypeError(f"no model default of {type(value).__name__}")


def follows_model(value: object) -> bool:
    """Whether ``value`` is a default still to be chosen from the model (:func:`from_model`)."""
    return isinstance(value, ModelFloat | ModelTuple | ModelStr)


def _plain(value: Any) -> Any:
    if isinstance(value, ModelFloat):
        return float(value)
    if isinstance(value, ModelStr):
        return str(value)
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return copy.deepcopy(value)
    return value


@dataclass(frozen=True, kw_only=True)
class GaitOptions:
    """Every option of the walking problem (SI units).

    Defaults that follow the model (:func:`from_model`: ``speed``, ``speed_bounds``,
    ``step_length_bounds``, ``rate_bound``, ``max_impulse``, ``cost_smoothing``, ``knots``,
    ``formulation``, ``gait``) hold the five-link biped's values here; a solve replaces each
    one the caller did not give with the model's
    (:func:`gaitopt.gait.model_defaults.options_for_model`: the gait its contact points
    allow, Froude-scaled speeds and bounds), which for the five-link biped are the same
    values exactly. A value given by the caller always stays.

    Attributes:
        speed: average forward speed (m/s), or ``None`` for free (the optimal walk). Default:
            the gait's at equal Froude number (0.2 m/s for the five-link walk;
            :data:`gaitopt.gait.model_defaults.DEFAULT_SPEEDS`).
        speed_bounds: bounds (m/s) when the speed is free (default 0.02-1.5 m/s on 1 m legs,
            times ``sqrt(g l / (9.81 * 1 m))``). A given ``speed`` is not checked against
            them: they bound a free speed only (docs/running.md).
        step_length: step length (m), or ``None`` for free.
        step_length_bounds: bounds (m) when the step length is free (default 0.02-0.8 m on
            1 m legs, times ``l / 1 m``; a run's 0.02-3 m,
            :data:`gaitopt.gait.model_defaults.RUN_STEP_LENGTH_BOUNDS`).
        step_time: step time ``L / v`` (s), or ``None`` for free. With a given speed it
            fixes the step length; with the speed free, the optimal walk of that step time.
            Give at most one of ``step_length`` and ``step_time``.
        ankle: ankle torques on (at the tips on the ground).
        impulse: liftoff impulse on.
        single_support_fraction: phase-1 share of the step time, in (0, 1]; 1 gives the
            single-support gait (no double support, the trailing leg leaves at heel strike).
            Default 0.85; a run's stance share is free by default
            (:data:`gaitopt.gait.model_defaults.RUN_STANCE_BOUNDS`, from a guess that falls
            with the speed, :func:`~gaitopt.gait.model_defaults.run_stance_guess`).
        knots: grid points per phase (single support, double support): 16 + 6 by default
            (the cost within 0.1 % of the fine-grid limit with ``control_model="jumps"``);
            the paper's 8 + 5 with :meth:`paper`; 24 + 16 for steps of more than two phases
            (:data:`gaitopt.gait.model_defaults.MULTI_PHASE_KNOTS`).
        transcription: ``"hermite-simpson-separated"`` (the default: the midpoint states
            as NLP variables, bounded like the knots; derivatives assembled from compiled
            functions of one grid point, several times faster per iteration),
            ``"hermite-simpson"`` (DIRCOL's compressed form, the paper's NLP and
            :meth:`paper`'s: the same scheme and fine-grid limit; its states may leave their
            bounds between knots, so on a coarse grid its optimum is a little lower) or
            ``"trapezoidal"``.
        periodic_controls: controls periodic (paper) as well as the states.
        friction: a friction coefficient for an optional friction-cone constraint, or None.
        unilateral_impulses: the ground only pushes at the heel strike and the liftoff (normal
            impulses >= 0 on every held tip). ``False`` uses the paper's maps as they are, in
            which the held tip may be pulled (the liftoff impulse along the trailing leg lifts
            the front tip unless the ground pulls it down; see docs/walking.md).
        min_stance_knee_flexion: smallest knee bend (rad) of a leg on the ground; it sets
            the largest hip-to-tip distance, the polar box ``r <= r_max`` (paper section 3.5),
            and keeps the leg inverse kinematics away from its singularity at a straight knee
            (> 0 in the reduced formulation; >= 0 in the full one, where 0 lets the stance
            knee straighten up to its joint limit).
        torso_bounds: torso angle bounds (rad; angles need no scaling between models).
        rate_bound: bound on every joint rate (rad/s) and on the hip's polar rates (default
            15 rad/s on 1 m legs, times ``sqrt(l_ref / l)``; the radial and base rates, in
            m/s, are this times ``l / l_ref``).
        max_impulse: upper bound of the liftoff impulse (N s; default 30 N s for 42 kg on
            1 m legs, times ``m sqrt(g l) / (m_ref sqrt(g_ref l_ref))``).
        tol: IPOPT tolerance.
        max_iter: IPOPT iteration limit per stage.
        continuation: use the automatic continuation from a naive start (else one solve).
        formulation: ``"reduced"`` (the paper's: polar hip coordinates and leg inverse
            kinematics, the five-link biped only) or ``"full"`` (the whole tree's ``q, qd``
            with the held contact points as constraints: any model with two legs; a knee may
            straighten fully, ``min_stance_knee_flexion = 0``). See docs/walking.md. Default:
            reduced for the walk of a five-link-shaped biped, else full.
        single_support_fraction_bounds: ``None`` (the fraction is ``single_support_fraction``)
            or ``(lower, upper)``: the fraction is free within them, a decision parameter
            (``single_support_fraction`` is its first guess); full formulation, with double
            support (a walk) or a flight (a run).
        free_phase_fractions: every phase fraction of the contact sequence (built in or
            given) that is fixed becomes free, a decision parameter within ``[s / 2,
            min(2 s, 0.95)]`` around its share ``s`` (which is its first guess); full
            formulation, two phases or more. Not with ``single_support_fraction_bounds``.
            See :func:`gaitopt.gait.phase_fractions.fraction_parameters`.
        phase_shares: ``None``, or each phase's share of the step (one per phase of the
            contact sequence, in (0, 1)): the first guess of the free fractions instead of the
            sequence's own, and what the knots per phase follow
            (:func:`gaitopt.gait.contact_sequence.phase_knots`). A refinement round of a
            solve with free fractions sets it to the shares it solved for
            (:mod:`gaitopt.gait.refinement`), so a phase that grew gets more knots.
        gait: ``"walk"`` (single support on leg 1, then double support, or the single-support
            walk when ``single_support_fraction = 1``) or ``"run"`` (stance on leg 1 for
            ``single_support_fraction`` of the step, then flight; full formulation only, no
            liftoff impulse) or ``"heel-toe"`` (feet with heel and toe points: foot flat,
            heel off, double support, heel rocker; full formulation; see
            :func:`gaitopt.gait.builtin_sequences.heel_toe_sequence`). Default: what the
            model's contact points allow, the walk with one per leg, the heel-toe walk with
            two (:func:`gaitopt.gait.model_defaults.default_gait`).
        contact_sequence: a contact sequence as plain data (the gait file's
            ``contact_sequence``; :func:`gaitopt.gait.contact_sequence.sequence_from_dict`),
            which replaces ``gait``; full formulation only. A phase fraction is a number
            (fixed) or ``{guess, min, max}`` (free within the bounds).
        cost: ``"paper"`` (torque squared per metre), ``"work"`` (mechanical cost of
            transport) or ``"metabolic"`` (with efficiencies and a resting power); formulas in
            :mod:`gaitopt.gait.cost` and docs/costs.md.
        efficiency_positive: muscle efficiency of positive work (> 0; 0.25) of the metabolic
            cost.
        efficiency_negative: muscle efficiency of negative work (> 0; 1.2) of the metabolic
            cost.
        resting_power: resting metabolic power (W/kg, >= 0) of the metabolic cost.
        cost_smoothing: ``eps`` (W, > 0) of the smooth positive part in the work costs
            (default 0.01 W for 42 kg on 1 m legs, carried over as a power).
        cost_regularization: weight (>= 0) of an added ``int sum (u / u_max)^2 dt / T``.
        torque_rate_time: ``tau`` (s, >= 0) of an added torque-rate term ``tau^2 int sum
            u'(t)^2 dt`` in the numerator of the paper's cost (the costs of transport: ``tau^2
            W sqrt(g l) int sum (u' / u_max)^2 dt``; :func:`gaitopt.gait.cost.torque_rate_weights`).
            It prices torque changes faster than about ``1 / (2 pi tau)`` Hz, as a muscle's
            activation time or a motor's bandwidth does (default 0: none; docs/feet.md,
            "Flapping feet", measures it against the seven-link model's flapping feet).
        multistart: solve the coarse problem from every naive guess and, away from 12 m/min,
            by continuation in speed, take every distinct coarse optimum through the
            remaining stages and keep the lowest final one (3-4x the time; a cold solve
            can otherwise end in a worse local optimum: at 57 and 60 m/min on 16 + 6 knots
            the long-step branch, 19-25 % above the sweep's optimum). ``gaitopt solve`` turns
            it on by default at speeds 15 m/min or more from 12 m/min.
        mesh_tol: refine the mesh after the fixed-grid stages until every interval's
            collocation error estimate is <= mesh_tol (``None``: the fixed grid ``knots``).
        accuracy: the relative accuracy a solve refines itself to (0.01: 1 %): while the
            estimates of the cost, the speed or the step length (from the check grid) exceed
            it, the gait is solved again on the check grid, up to
            :data:`gaitopt.gait.refinement.MAX_ROUNDS` times; ``None``, or knots given by
            the caller, keeps the one grid (its estimate reported).
        control_model: ``"jumps"`` (the default: no control linkages, the torques may jump
            at both events; the problem is then well posed and converges on coarse grids) or
            ``"paper"`` (controls continuous at the heel strike and, with
            ``periodic_controls``, periodic at the liftoff; its cost falls at first order as
            the grid is refined).
        swing_clearance: ``c`` (m), the least mid-swing height of the swing tip: over single
            support ``y >= c (4 s (1 - s))^2`` (``clearance_profile="quartic"``) or
            ``y >= c 4 s (1 - s)`` (``"parabola"``), ``s`` the normalised phase time; or
            ``None`` (the paper: ``y >= 0``).
        clearance_profile: ``"quartic"`` or ``"parabola"`` (see ``swing_clearance``). The
            parabola's slope at the ends is a least vertical tip velocity ``4 c / T1`` at the
            liftoff and the heel strike, which makes its cost grow with the grid (measured in
            docs/walking.md); the quartic has zero slope there.
        knot_spacing: ``"cosine"`` (the default since 2026-12-02; the paper's preset:
            ``"uniform"``) or ``"uniform"``: the knots of the target grid (``knots``, not the
            coarse stages) at ``tau_k = (1 - cos(pi k / (N - 1))) / 2`` in each phase,
            clustered at the events, where fast walks have a boundary layer before the heel
            strike that a uniform grid resolves at first order only (docs/walking.md,
            section 6).
        stride: solve a stride, two steps (leg 1's, then leg 2's) periodic with ``x``
            moved on by two step lengths and no leg swap, instead of one step periodic
            through the swap: for legs that are no mirror of each other (one heavier leg, a
            prosthesis). The contact sequence is doubled with the contact points renamed by
            the leg pairing (:func:`gaitopt.gait.contact_sequence.stride_sequence`; both
            steps share ``L`` and ``P``, each phase keeps its share of its step unless the
            fractions are free); the cost is per metre of the stride. Full formulation, not
            with ``single_support_fraction_bounds``.
    """

    speed: float | None = from_model(0.2)
    speed_bounds: tuple[float, float] = from_model((0.02, 1.5))
    step_length: float | None = None
    step_length_bounds: tuple[float, float] = from_model((0.02, 0.8))
    step_time: float | None = None
    ankle: bool = True
    impulse: bool = True
    single_support_fraction: float = from_model(0.85)
    knots: tuple[int, int] = from_model((16, 6))
    transcription: Transcription = "hermite-simpson-separated"
    periodic_controls: bool = True
    friction: float | None = None
    unilateral_impulses: bool = True
    min_stance_knee_flexion: float = 0.1
    torso_bounds: tuple[float, float] = (-0.8, 0.8)
    rate_bound: float = from_model(15.0)
    max_impulse: float = from_model(30.0)
    tol: float = 1e-7
    max_iter: int = 1000
    continuation: bool = True
    multistart: bool = False
    formulation: Formulation = from_model("reduced")
    gait: GaitKind = from_model("walk")
    contact_sequence: dict[str, Any] | None = None
    single_support_fraction_bounds: tuple[float, float] | None = None
    free_phase_fractions: bool = False
    phase_shares: tuple[float, ...] | None = None
    cost: CostName = "paper"
    efficiency_positive: float = 0.25
    efficiency_negative: float = 1.2
    resting_power: float = 1.2
    cost_smoothing: float = from_model(0.01)
    cost_regularization: float = 0.0
    torque_rate_time: float = 0.0
    mesh_tol: float | None = None
    accuracy: float | None = 0.01
    control_model: ControlModel = "jumps"
    swing_clearance: float | None = None
    clearance_profile: ClearanceProfile = "quartic"
    knot_spacing: KnotSpacing = "cosine"
    stride: bool = False

    # -- derived -------------------------------------------------------------------------------
    @property
    def double_support(self) -> bool:
        """Whether the step has a double-support phase (fraction < 1)."""
        return self.single_support_fraction < 1.0

    @property
    def variant(self) -> str:
        """``ankle+impulse``, ``ankle``, ``impulse`` or ``plain``."""
        parts = [name for name, on in (("ankle", self.ankle), ("impulse", self.impulse)) if on]
        return "+".join(parts) or "plain"

    @staticmethod
    def paper(**changes: Any) -> GaitOptions:
        """The paper's setting: :data:`PAPER_GRID` (8 + 5 knots, controls continuous at the
        heel strike and periodic, the compressed Hermite-Simpson form) with every other
        default, then ``changes``. At 12 m/min it gives J = 487.94 N^2 m s; speed free,
        11.1 m/min with 0.107 m steps and 486.3."""
        return GaitOptions(**{**PAPER_GRID, **changes})

    @property
    def paper_grid(self) -> bool:
        """Whether these options solve on the paper's grid and control model."""
        return (tuple(self.knots) == PAPER_GRID["knots"]
                and self.control_model == PAPER_GRID["control_model"])

    def replace(self, **changes: Any) -> GaitOptions:
        """A copy with some fields changed (validated again by the caller)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain data for the gait file (``None`` means free)."""
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    @staticmethod
    def saved_defaults() -> dict[str, Any]:
        """What a field missing from saved options (a gait file, ``sweep.json``) stands for:
        today's default, or its :data:`LEGACY_DEFAULTS` value (plain data, as
        :meth:`to_dict`)."""
        return {**GaitOptions().to_dict(), **LEGACY_DEFAULTS}

    @staticmethod
    def from_dict(data: dict[str, Any]) -> GaitOptions:
        """Options from saved data (:meth:`to_dict`); a missing field takes its
        :meth:`saved_defaults` value."""
        fields = {f.name for f in dataclasses.fields(GaitOptions)}
        unknown = sorted(set(data) - fields)
        if unknown:
            raise GaitOptionsError(f"unknown gait option(s) {', '.join(unknown)}; known: "
                                   f"{', '.join(sorted(fields))}")
        clean: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v
                                 for k, v in {**LEGACY_DEFAULTS, **data}.items()}
        return GaitOptions(**clean)


def _finite(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise GaitOptionsError(f"{name} = {value!r}: must be a finite number")
    return float(value)


def _bounds(name: str, value: Any, *, positive: bool = False) -> tuple[float, float]:
    if not isinstance(value, tuple | list) or len(value) != 2:
        raise GaitOptionsError(f"{name} = {value!r}: must be a pair (lower, upper)")
    lo, hi = _finite(f"{name}[0]", value[0]), _finite(f"{name}[1]", value[1])
    if lo > hi:
        raise GaitOptionsError(f"{name} = ({lo:g}, {hi:g}): lower bound must be <= upper bound")
    if positive and lo <= 0.0:
        raise GaitOptionsError(f"{name} = ({lo:g}, {hi:g}): bounds must be > 0")
    return lo, hi


def validate_options(options: GaitOptions, biped: Biped | None) -> None:
    """Check every option before any solve; raise :class:`GaitOptionsError` naming the field,
    the bad value and the allowed range. ``biped``: the legs, for the reach checks (None for a
    model without thigh-shank legs in the full formulation: no reach check)."""
    o = options
    v_lo, v_hi = _bounds("speed_bounds", o.speed_bounds, positive=True)
    if o.speed is not None:
        speed = _finite("speed", o.speed)
        if speed <= 0.0:
            raise GaitOptionsError(f"speed = {format_speed(speed)}: must be > 0 (or free)")
        # A given speed is not checked against speed_bounds, which bound a free speed only
        # (a run at 240 m/min is asked for directly; docs/running.md).
    l_lo, l_hi = _bounds("step_length_bounds", o.step_length_bounds, positive=True)
    if o.formulation not in FORMULATIONS:
        raise GaitOptionsError(f"formulation = {o.formulation!r}: must be one of "
                               f"{', '.join(FORMULATIONS)}")
    traits = FORMULATION_TRAITS[o.formulation]
    if o.cost not in ("paper", "work", "metabolic"):
        raise GaitOptionsError(f"cost = {o.cost!r}: must be one of paper, work, metabolic")
    for name, value, lo, strict in (("efficiency_positive", o.efficiency_positive, 0.0, True),
                                    ("efficiency_negative", o.efficiency_negative, 0.0, True),
                                    ("resting_power", o.resting_power, 0.0, False),
                                    ("cost_smoothing", o.cost_smoothing, 0.0, True),
                                    ("cost_regularization", o.cost_regularization, 0.0, False),
                                    ("torque_rate_time", o.torque_rate_time, 0.0, False)):
        v = _finite(name, value)
        if v < lo or (strict and v == lo):
            raise GaitOptionsError(f"{name} = {v:g}: must be {'>' if strict else '>='} {lo:g}")
    if o.single_support_fraction_bounds is not None:
        f_lo, f_hi = _bounds("single_support_fraction_bounds", o.single_support_fraction_bounds)
        if not traits.contact_sequences:
            raise GaitOptionsError("single_support_fraction_bounds: a free single-support "
                                   "fraction needs formulation 'full'")
        if f_lo < 0.05 or f_hi >= 1.0:
            raise GaitOptionsError(f"single_support_fraction_bounds = ({f_lo:g}, {f_hi:g}): "
                                   "must lie in [0.05, 1) (1 is the single-support walk)")
        if not f_lo <= o.single_support_fraction <= f_hi:
            raise GaitOptionsError(f"single_support_fraction = {o.single_support_fraction:g}: "
                                   f"must lie in single_support_fraction_bounds "
                                   f"[{f_lo:g}, {f_hi:g}] (it is the first guess)")
    if o.free_phase_fractions:
        if not traits.contact_sequences:
            raise GaitOptionsError("free_phase_fractions: free phase fractions need "
                                   "formulation 'full'")
        if o.single_support_fraction_bounds is not None:
            raise GaitOptionsError("free_phase_fractions and single_support_fraction_bounds: "
                                   "give one of them (free_phase_fractions frees every phase)")
    if o.phase_shares is not None and not all(
            isinstance(v, int | float) and 0.0 < float(v) < 1.0 for v in o.phase_shares):
        raise GaitOptionsError(f"phase_shares = {tuple(o.phase_shares)!r}: each must lie in "
                               "(0, 1)")
    if o.stride:
        if not traits.contact_sequences:
            raise GaitOptionsError("stride: a two-step stride needs formulation 'full' (the "
                                   "reduced coordinates describe one step of the five-link "
                                   "biped, periodic through the leg swap)")
        if o.single_support_fraction_bounds is not None:
            raise GaitOptionsError("stride and single_support_fraction_bounds: give "
                                   "free_phase_fractions instead (it frees every phase of "
                                   "both steps)")
    if o.gait not in GAITS:
        raise GaitOptionsError(f"gait = {o.gait!r}: must be one of {', '.join(GAITS)}")
    if (o.gait == "heel-toe" or o.contact_sequence is not None) and not traits.contact_sequences:
        raise GaitOptionsError("gait = 'heel-toe' and contact_sequence need formulation "
                               "'full'")
    if o.contact_sequence is not None:
        from gaitopt.gait.contact_sequence import ContactSequenceError, sequence_from_dict

        try:
            sequence_from_dict(o.contact_sequence)
        except ContactSequenceError as exc:
            raise GaitOptionsError(str(exc)) from None
    if o.gait == "run" and o.impulse:
        raise GaitOptionsError(
            "gait = 'run' with impulse on: a run leaves the ground from single support into "
            "a flight, with no double support for a liftoff impulse to act from; turn it off "
            "(impulse=False; gaitopt solve --gait run has it off unless --impulse is given)")
    if o.gait == "run" and (not traits.contact_sequences or o.single_support_fraction >= 1.0):
        raise GaitOptionsError(
            "gait = 'run': needs formulation 'full' and single_support_fraction < 1 (the "
            "stance share of the step)")
    flex = _finite("min_stance_knee_flexion", o.min_stance_knee_flexion)
    if traits.straight_stance_knee and not 0.0 <= flex < 1.5:
        raise GaitOptionsError(f"min_stance_knee_flexion = {flex:g} rad: must lie in [0, 1.5) "
                               "(full formulation)")
    if not traits.straight_stance_knee and not 0.0 < flex < 1.5:
        raise GaitOptionsError(f"min_stance_knee_flexion = {flex:g} rad: must lie in (0, 1.5) "
                               "in the reduced formulation (its leg inverse kinematics is "
                               "singular at a straight knee; formulation 'full' allows 0)")
    reach = min(leg.reach(-flex) for leg in biped.legs) if biped is not None else math.inf
    longest = 2.0 * reach * 0.97
    if o.step_length is not None:
        step = _finite("step_length", o.step_length)
        if step <= 0.0:
            raise GaitOptionsError(f"step_length = {step:g} m: must be > 0 (or free)")
        if step >= longest:
            raise GaitOptionsError(
                f"step_length = {step:g} m: longer than the legs can reach (both tips on the "
                f"ground with the hip above them needs step_length < {longest:.3f} m)")
        if not l_lo <= step <= l_hi:
            raise GaitOptionsError(f"step_length = {step:g} m: must lie in step_length_bounds "
                                   f"[{l_lo:g}, {l_hi:g}] m")
    if o.step_time is not None:
        period = _finite("step_time", o.step_time)
        if period <= 0.0:
            raise GaitOptionsError(f"step_time = {period:g} s: must be > 0 (or free)")
        if o.step_length is not None:
            raise GaitOptionsError(f"step_time = {period:g} s and step_length = "
                                   f"{o.step_length:g} m: give at most one of them (with the "
                                   "speed they fix each other)")
        lo_v, hi_v = (o.speed, o.speed) if o.speed is not None else (v_lo, v_hi)
        if period * hi_v < l_lo or period * lo_v > min(l_hi, longest):
            what = (f"speed {format_speed(o.speed)}" if o.speed is not None else
                    f"speed_bounds [{format_speed(v_lo)}, {format_speed(v_hi)}]")
            steps = (f"{period * lo_v:.3g} m" if lo_v == hi_v else
                     f"{period * lo_v:.3g}-{period * hi_v:.3g} m")
            raise GaitOptionsError(
                f"step_time = {period:g} s: with the {what} the step length {steps} would "
                f"leave [{l_lo:g}, {min(l_hi, longest):.3f}] m (step_length_bounds and the "
                "legs' reach)")
    if l_lo >= longest:
        raise GaitOptionsError(f"step_length_bounds = ({l_lo:g}, {l_hi:g}) m: the legs reach "
                               f"steps shorter than {longest:.3f} m only")
    f = _finite("single_support_fraction", o.single_support_fraction)
    if not 0.05 <= f <= 1.0:
        raise GaitOptionsError(f"single_support_fraction = {f:g}: must lie in [0.05, 1]")
    if (not isinstance(o.knots, tuple | list) or len(o.knots) != 2
            or not all(isinstance(k, int) and not isinstance(k, bool) for k in o.knots)):
        raise GaitOptionsError(f"knots = {o.knots!r}: must be two integers "
                               "(single support, double support)")
    if o.knots[0] < 3 or (o.double_support and o.knots[1] < 2):
        raise GaitOptionsError(f"knots = {tuple(o.knots)}: need >= 3 knots in single support "
                               "and >= 2 in double support")
    if max(o.knots) > 400:
        raise GaitOptionsError(f"knots = {tuple(o.knots)}: at most 400 per phase")
    if o.transcription not in TRANSCRIPTIONS:
        raise GaitOptionsError(f"transcription = {o.transcription!r}: must be one of "
                               f"{', '.join(repr(t) for t in TRANSCRIPTIONS)}")
    if o.friction is not None and not _finite("friction", o.friction) > 0.0:
        raise GaitOptionsError(f"friction = {o.friction!r}: must be > 0 "
                               "(leave it unset for no friction cone)")
    t_lo, t_hi = _bounds("torso_bounds", o.torso_bounds)
    if not t_lo <= 0.0 <= t_hi:
        raise GaitOptionsError(f"torso_bounds = ({t_lo:g}, {t_hi:g}) rad: must contain 0 "
                               "(upright), or the biped cannot stand")
    if not _finite("rate_bound", o.rate_bound) > 0.0:
        raise GaitOptionsError(f"rate_bound = {o.rate_bound!r}: must be > 0")
    if not _finite("max_impulse", o.max_impulse) >= 0.0:
        raise GaitOptionsError(f"max_impulse = {o.max_impulse!r}: must be >= 0")
    if not 0.0 < _finite("tol", o.tol) < 1.0:
        raise GaitOptionsError(f"tol = {o.tol!r}: must lie in (0, 1)")
    if not isinstance(o.max_iter, int) or o.max_iter < 1:
        raise GaitOptionsError(f"max_iter = {o.max_iter!r}: must be a positive integer")
    if o.accuracy is not None and not 0.0 < _finite("accuracy", o.accuracy) < 1.0:
        raise GaitOptionsError(f"accuracy = {o.accuracy!r}: must lie in (0, 1) (a relative "
                               "accuracy, 0.01 for 1 %), or None for no refinement")
    if o.mesh_tol is not None and not 0.0 < _finite("mesh_tol", o.mesh_tol) < 1.0:
        raise GaitOptionsError(f"mesh_tol = {o.mesh_tol!r}: must lie in (0, 1) "
                               "(or None for the fixed grid)")
    if o.control_model not in CONTROL_MODELS:
        raise GaitOptionsError(f"control_model = {o.control_model!r}: must be one of "
                               f"{', '.join(repr(m) for m in CONTROL_MODELS)}")
    if o.swing_clearance is not None:
        c = _finite("swing_clearance", o.swing_clearance)
        if not 0.0 < c < reach:
            raise GaitOptionsError(f"swing_clearance = {c:g} m: must lie in (0, {reach:.3f}) m "
                                   "(above the ground, below the leg's reach; or None)")
    if o.clearance_profile not in CLEARANCE_PROFILES:
        raise GaitOptionsError(f"clearance_profile = {o.clearance_profile!r}: must be one of "
                               f"{', '.join(repr(m) for m in CLEARANCE_PROFILES)}")
    if o.knot_spacing not in KNOT_SPACINGS:
        raise GaitOptionsError(f"knot_spacing = {o.knot_spacing!r}: must be one of "
                               f"{', '.join(repr(m) for m in KNOT_SPACINGS)}")
