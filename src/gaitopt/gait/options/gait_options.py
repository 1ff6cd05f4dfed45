"""Options of the walking problem: the variant, the targets and every bound, validated.

:class:`GaitOptions` holds six groups (:class:`Targets`, :class:`SequenceOptions`,
:class:`Limits`, :class:`CostOptions`, :class:`Discretisation`, :class:`SolverOptions`; the
table in its docstring), takes every field also as a flat keyword and reads it as a flat
read-only shorthand (``options.speed`` for ``options.targets.speed``), so the code written
against the flat options of before reads the same. The gait file keeps the flat names
(:meth:`GaitOptions.to_dict`); :func:`validate_options` names each field by its grouped path
(``targets.speed = ...``).

(One concept, kept whole at about 900 lines: the options, their groups and shorthands, and
the check of each; half of the length is the documentation of the fields.)

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
from collections.abc import Mapping
from dataclasses import dataclass, field
from operator import attrgetter
from typing import TYPE_CHECKING, Any, Generic, Literal, TypedDict, TypeVar, Unpack, cast, overload

from gaitopt.gait.formulations.traits import FORMULATION_TRAITS
from gaitopt.gait.sequence.knots import BUILTIN_PHASES, KnotsError, knots_in_order
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
#: The forms of ``knots`` (:mod:`gaitopt.gait.sequence.knots`): counts ``(first, others)`` or
#: one per phase, or a mapping phase name -> count.
Knots = tuple[int, ...] | Mapping[str, int]
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
    five-link biped's), and :func:`gaitopt.gait.options.model_defaults.options_for_model` replaces
    it with the model's (:mod:`gaitopt.gait.options.model_scale`). A number given by the caller is
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
class Targets:
    """What the gait must achieve: its speed and step, given or free within bounds
    (``GaitOptions.targets``; SI units).

    Attributes:
        speed: average forward speed (m/s), or ``None`` for free (the optimal walk). Default:
            the gait's at equal Froude number (0.2 m/s for the five-link walk;
            :data:`gaitopt.gait.options.model_defaults.DEFAULT_SPEEDS`).
        speed_bounds: bounds (m/s) when the speed is free (default 0.02-1.5 m/s on 1 m legs,
            times ``sqrt(g l / (9.81 * 1 m))``). A given ``speed`` is not checked against
            them: they bound a free speed only (docs/running.md).
        step_length: step length (m), or ``None`` for free.
        step_length_bounds: bounds (m) when the step length is free (default 0.02-0.8 m on
            1 m legs, times ``l / 1 m``; a run's 0.02-3 m,
            :data:`gaitopt.gait.options.model_defaults.RUN_STEP_LENGTH_BOUNDS`).
        step_time: step time ``L / v`` (s), or ``None`` for free. With a given speed it
            fixes the step length; with the speed free, the optimal walk of that step time.
            Give at most one of ``step_length`` and ``step_time``.
    """

    speed: float | None = from_model(0.2)
    speed_bounds: tuple[float, float] = from_model((0.02, 1.5))
    step_length: float | None = None
    step_length_bounds: tuple[float, float] = from_model((0.02, 0.8))
    step_time: float | None = None


@dataclass(frozen=True, kw_only=True)
class SequenceOptions:
    """The contact sequence of a step and what acts in it: the gait (built in or
    given as data), its phases' shares of the step, a stride, the ankle torques and the
    liftoff impulse (``GaitOptions.sequence``).

    Attributes:
        gait: ``"walk"`` (single support on leg 1, then double support, or the single-support
            walk when ``single_support_fraction = 1``) or ``"run"`` (stance on leg 1 for
            ``single_support_fraction`` of the step, then flight; full formulation only, no
            liftoff impulse) or ``"heel-toe"`` (feet with heel and toe points: foot flat,
            heel off, double support, heel rocker; full formulation; see
            :func:`gaitopt.gait.sequence.builtin.heel_toe_sequence`). Default: what the
            model's contact points allow, the walk with one per leg, the heel-toe walk with
            two (:func:`gaitopt.gait.options.model_defaults.default_gait`).
        contact_sequence: a contact sequence as plain data (the gait file's
            ``contact_sequence``;
            :func:`gaitopt.gait.sequence.contact_sequence.sequence_from_dict`),
            which replaces ``gait``; full formulation only. A phase fraction is a number
            (fixed) or ``{guess, min, max}`` (free within the bounds).
        stride: solve a stride, two steps (leg 1's, then leg 2's) periodic with ``x``
            moved on by two step lengths and no leg swap, instead of one step periodic
            through the swap: for legs that are no mirror of each other (one heavier leg, a
            prosthesis). The contact sequence is doubled with the contact points renamed by
            the leg pairing (:func:`gaitopt.gait.sequence.contact_sequence.stride_sequence`; both
            steps share ``L`` and ``P``, each phase keeps its share of its step unless the
            fractions are free); the cost is per metre of the stride. Full formulation, not
            with ``single_support_fraction_bounds``.
        single_support_fraction: phase-1 share of the step time, in (0, 1]; 1 gives the
            single-support gait (no double support, the trailing leg leaves at heel strike).
            Default 0.85; a run's stance share is free by default
            (:data:`gaitopt.gait.options.model_defaults.RUN_STANCE_BOUNDS`, from a guess that falls
            with the speed, :func:`~gaitopt.gait.options.model_defaults.run_stance_guess`).
        single_support_fraction_bounds: ``None`` (the fraction is ``single_support_fraction``)
            or ``(lower, upper)``: the fraction is free within them, a decision parameter
            (``single_support_fraction`` is its first guess); full formulation, with double
            support (a walk) or a flight (a run).
        free_phase_fractions: ``True``: every phase fraction of the contact sequence (built
            in or given) that is fixed becomes free from the first stage on, a decision
            parameter within ``[s / 2, min(2 s, 0.95)]`` around its share ``s`` (which is its
            first guess); full formulation, two phases or more. Not with
            ``single_support_fraction_bounds``. See
            :func:`gaitopt.gait.sequence.phase_fractions.fraction_parameters`. ``False``: the
            shares stay fixed. ``None`` (the default): left to the sequence; where they are
            guesses (a built-in sequence of more than two phases) and the caller can judge
            the gait (``plausible``), solved free first, the fixed shares solved too only
            where the free optimum is not kept (converged, lower, plausible)
            (:mod:`gaitopt.gait.solve.share_release`).
        phase_shares: ``None``, or each phase's share of the step (one per phase of the
            contact sequence, in (0, 1)): the first guess of the free fractions instead of the
            sequence's own, and what the knots per phase follow
            (:func:`gaitopt.gait.sequence.contact_sequence.phase_knots`). A refinement round of a
            solve with free fractions sets it to the shares it solved for
            (:mod:`gaitopt.gait.solve.refinement`), so a phase that grew gets more knots.
        ankle: ankle torques on (at the tips on the ground).
        impulse: liftoff impulse on.
    """

    gait: GaitKind = from_model("walk")
    contact_sequence: dict[str, Any] | None = None
    stride: bool = False
    single_support_fraction: float = from_model(0.85)
    single_support_fraction_bounds: tuple[float, float] | None = None
    free_phase_fractions: bool | None = None
    phase_shares: tuple[float, ...] | None = None
    ankle: bool = True
    impulse: bool = True


@dataclass(frozen=True, kw_only=True)
class Limits:
    """Bounds and constraints on the motion: the stance knee's bend, the torso, the rates,
    the liftoff impulse, the ground's pushes and friction, the swing clearance
    (``GaitOptions.limits``; SI units).

    Attributes:
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
        unilateral_impulses: the ground only pushes at the heel strike and the liftoff (normal
            impulses >= 0 on every held tip). ``False`` uses the paper's maps as they are, in
            which the held tip may be pulled (the liftoff impulse along the trailing leg lifts
            the front tip unless the ground pulls it down; see docs/walking.md).
        friction: a friction coefficient for an optional friction-cone constraint, or None.
        swing_clearance: ``c`` (m), the least mid-swing height of the swing tip: over single
            support ``y >= c (4 s (1 - s))^2`` (``clearance_profile="quartic"``) or
            ``y >= c 4 s (1 - s)`` (``"parabola"``), ``s`` the normalised phase time (a
            run's: over the stance); ``0`` (the paper: ``y >= 0`` only); or ``None``, the
            default: 0, except for a run on point feet, which gets ``RUN_SWING_CLEARANCE``
            times the leg length (``gaitopt.gait.options.model_defaults``).
        clearance_profile: ``"quartic"`` or ``"parabola"`` (see ``swing_clearance``). The
            parabola's slope at the ends is a least vertical tip velocity ``4 c / T1`` at the
            liftoff and the heel strike, which makes its cost grow with the grid (measured in
            docs/walking.md); the quartic has zero slope there.
    """

    min_stance_knee_flexion: float = 0.1
    torso_bounds: tuple[float, float] = (-0.8, 0.8)
    rate_bound: float = from_model(15.0)
    max_impulse: float = from_model(30.0)
    unilateral_impulses: bool = True
    friction: float | None = None
    swing_clearance: float | None = None
    clearance_profile: ClearanceProfile = "quartic"


@dataclass(frozen=True, kw_only=True)
class CostOptions:
    """The cost of transport that is minimised and its terms (``GaitOptions.objective``:
    named so because ``GaitOptions.cost`` is the shorthand of ``objective.cost``).

    Attributes:
        cost: ``"paper"`` (torque squared per metre), ``"work"`` (mechanical cost of
            transport) or ``"metabolic"`` (with efficiencies and a resting power); formulas in
            :mod:`gaitopt.gait.formulations.cost` and docs/costs.md.
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
            W sqrt(g l) int sum (u' / u_max)^2 dt``;
            :func:`gaitopt.gait.formulations.cost.torque_rate_weights`).
            It prices torque changes faster than about ``1 / (2 pi tau)`` Hz, as a muscle's
            activation time or a motor's bandwidth does (default 0: none; docs/feet.md,
            "Flapping feet", measures it against the seven-link model's flapping feet).
    """

    cost: CostName = "paper"
    efficiency_positive: float = 0.25
    efficiency_negative: float = 1.2
    resting_power: float = 1.2
    cost_smoothing: float = from_model(0.01)
    cost_regularization: float = 0.0
    torque_rate_time: float = 0.0


@dataclass(frozen=True, kw_only=True)
class Discretisation:
    """The grid and the transcription: knots per phase, their spacing, the
    collocation scheme, the control model, mesh refinement and the accuracy a solve refines
    itself to (``GaitOptions.discretisation``).

    Attributes:
        knots: grid points per phase, in one of three forms
            (:mod:`gaitopt.gait.sequence.knots`): a mapping phase name -> count naming
            every phase of the step (``{"single_support": 16, "double_support": 6}`` for
            the walk; ``foot_flat``, ``heel_off``, ``double_support``, ``heel_rocker`` for
            the heel-toe walk; ``stance``, ``flight`` for the run; a given sequence's own
            names; :data:`gaitopt.gait.sequence.knots.BUILTIN_PHASES`); two integers
            ``(first, others)``: the first phase's and at least every later phase's (the
            walk's single and double support; a longer phase of a longer step gets more,
            :func:`gaitopt.gait.sequence.contact_sequence.phase_knots`); or one integer per
            phase of the step, in phase order. 16 + 6 by default (the cost within 0.1 % of
            the fine-grid limit with ``control_model="jumps"``); the paper's 8 + 5 with
            :meth:`GaitOptions.paper`; 24 + 16 for steps of more than two phases
            (:data:`gaitopt.gait.options.model_defaults.MULTI_PHASE_KNOTS`). The first phase
            has at least 3 knots, every later one at least 2, none more than 400. A gait file
            stores the form given (:meth:`GaitOptions.to_dict`); ``GaitOptions.knots`` reads
            the counts in phase order.
        knot_spacing: ``"cosine"`` (the default since 2026-12-02; the paper's preset:
            ``"uniform"``) or ``"uniform"``: the knots of the target grid (``knots``, not the
            coarse stages) at ``tau_k = (1 - cos(pi k / (N - 1))) / 2`` in each phase,
            clustered at the events, where fast walks have a boundary layer before the heel
            strike that a uniform grid resolves at first order only (docs/walking.md,
            section 6).
        transcription: ``"hermite-simpson-separated"`` (the default: the midpoint states
            as NLP variables, bounded like the knots; derivatives assembled from compiled
            functions of one grid point, several times faster per iteration),
            ``"hermite-simpson"`` (DIRCOL's compressed form, the paper's NLP and
            :meth:`GaitOptions.paper`'s: the same scheme and fine-grid limit; its states may
            leave their bounds between knots, so on a coarse grid its optimum is a little
            lower) or ``"trapezoidal"``.
        control_model: ``"jumps"`` (the default: no control linkages, the torques may jump
            at both events; the problem is then well posed and converges on coarse grids) or
            ``"paper"`` (controls continuous at the heel strike and, with
            ``periodic_controls``, periodic at the liftoff; its cost falls at first order as
            the grid is refined).
        periodic_controls: controls periodic (paper) as well as the states.
        mesh_tol: refine the mesh after the fixed-grid stages until every interval's
            collocation error estimate is <= mesh_tol (``None``: the fixed grid ``knots``).
        accuracy: the relative accuracy a solve refines itself to (0.01: 1 %): while the
            estimates of the cost, the speed or the step length (from the check grid) exceed
            it, the gait is solved again on the check grid, up to
            :data:`gaitopt.gait.solve.refinement.MAX_ROUNDS` times; ``None``, or knots given by
            the caller, keeps the one grid (its estimate reported).
    """

    knots: Knots = from_model((16, 6))
    knot_spacing: KnotSpacing = "cosine"
    transcription: Transcription = "hermite-simpson-separated"
    control_model: ControlModel = "jumps"
    periodic_controls: bool = True
    mesh_tol: float | None = None
    accuracy: float | None = 0.01

    def __post_init__(self) -> None:
        if isinstance(self.knots, Mapping):  # a copy: the caller's dict may change later
            object.__setattr__(self, "knots", dict(self.knots))


@dataclass(frozen=True, kw_only=True)
class SolverOptions:
    """How the problem is posed to IPOPT and solved: the formulation (coordinates),
    the tolerance, the iteration limit, the continuation and the multistart
    (``GaitOptions.solver``).

    Attributes:
        formulation: ``"reduced"`` (the paper's: polar hip coordinates and leg inverse
            kinematics, the five-link biped only) or ``"full"`` (the whole tree's ``q, qd``
            with the held contact points as constraints: any model with two legs; a knee may
            straighten fully, ``min_stance_knee_flexion = 0``). See docs/walking.md. Default:
            reduced for the walk of a five-link-shaped biped, else full.
        tol: IPOPT tolerance.
        max_iter: IPOPT iteration limit per stage.
        continuation: use the automatic continuation from a naive start (else one solve).
        multistart: solve the coarse problem from every naive guess and, away from 12 m/min,
            by continuation in speed, take every distinct coarse optimum through the
            remaining stages and keep the lowest final one (3-4x the time; a cold solve
            can otherwise end in a worse local optimum: at 57 and 60 m/min on 16 + 6 knots
            the long-step branch, 19-25 % above the sweep's optimum). ``gaitopt solve`` turns
            it on by default at speeds 15 m/min or more from 12 m/min.
    """

    formulation: Formulation = from_model("reduced")
    tol: float = 1e-7
    max_iter: int = 1000
    continuation: bool = True
    multistart: bool = False


if TYPE_CHECKING:
    class _Alias(Generic[_T]):
        """The type of a shorthand: reads ``_T`` on an instance (see below)."""

        def __init__(self, path: str) -> None: ...
        @overload
        def __get__(self, obj: None, owner: type | None = None) -> _Alias[_T]: ...
        @overload
        def __get__(self, obj: object, owner: type | None = None) -> _T: ...
        def __get__(self, obj: object | None, owner: type | None = None) -> _Alias[_T] | _T:
            ...
else:
    class _Alias(property):
        """A read-only flat attribute of :class:`GaitOptions`: ``speed =
        _Alias[float | None]("targets.speed")`` reads ``options.targets.speed`` (a property
        whose getter is an :func:`operator.attrgetter`: as fast as a plain property)."""

        def __init__(self, path: str) -> None:
            super().__init__(attrgetter(path), doc=f"Shorthand of ``{path}`` (read-only).")

        def __class_getitem__(cls, item: object) -> type:
            return cls


#: The groups of :class:`GaitOptions`: attribute name -> group class.
GROUPS: dict[str, type[Any]] = {"targets": Targets, "sequence": SequenceOptions,
                                "limits": Limits, "objective": CostOptions,
                                "discretisation": Discretisation, "solver": SolverOptions}
#: Every option by its flat name -> the group that holds it (``"speed": "targets"``), in the
#: order of the groups and their fields: the names of :meth:`GaitOptions.to_dict`, of the
#: flat keywords and of the shorthands.
FIELD_GROUPS: dict[str, str] = {f.name: group for group, cls in GROUPS.items()
                                for f in dataclasses.fields(cls)}
_DEFAULT_GROUPS: dict[str, Any] = {group: cls() for group, cls in GROUPS.items()}


def field_path(name: str) -> str:
    """The grouped path of an option, ``"targets.speed"`` for ``"speed"`` (the name of the
    field in the messages of :func:`validate_options`)."""
    return f"{FIELD_GROUPS[name]}.{name}"


class FlatOptions(TypedDict, total=False):
    """The flat keywords of :class:`GaitOptions` and :meth:`GaitOptions.replace`: every
    field of every group by its own name (each documented in its group)."""

    speed: float | None
    speed_bounds: tuple[float, float]
    step_length: float | None
    step_length_bounds: tuple[float, float]
    step_time: float | None
    gait: GaitKind
    contact_sequence: dict[str, Any] | None
    stride: bool
    single_support_fraction: float
    single_support_fraction_bounds: tuple[float, float] | None
    free_phase_fractions: bool | None
    phase_shares: tuple[float, ...] | None
    ankle: bool
    impulse: bool
    min_stance_knee_flexion: float
    torso_bounds: tuple[float, float]
    rate_bound: float
    max_impulse: float
    unilateral_impulses: bool
    friction: float | None
    swing_clearance: float | None
    clearance_profile: ClearanceProfile
    cost: CostName
    efficiency_positive: float
    efficiency_negative: float
    resting_power: float
    cost_smoothing: float
    cost_regularization: float
    torque_rate_time: float
    knots: Knots
    knot_spacing: KnotSpacing
    transcription: Transcription
    control_model: ControlModel
    periodic_controls: bool
    mesh_tol: float | None
    accuracy: float | None
    formulation: Formulation
    tol: float
    max_iter: int
    continuation: bool
    multistart: bool

@dataclass(frozen=True, init=False)
class GaitOptions:
    """Every option of the walking problem (SI units), in six groups.

    ============================  ========================================================
    group (class)                 fields
    ============================  ========================================================
    ``targets``                   ``speed``, ``speed_bounds``, ``step_length``,
    (:class:`Targets`)            ``step_length_bounds``, ``step_time``
    ``sequence``                  ``gait``, ``contact_sequence``, ``stride``,
    (:class:`SequenceOptions`)    ``single_support_fraction``,
                                  ``single_support_fraction_bounds``,
                                  ``free_phase_fractions``, ``phase_shares``, ``ankle``,
                                  ``impulse``
    ``limits``                    ``min_stance_knee_flexion``, ``torso_bounds``,
    (:class:`Limits`)             ``rate_bound``, ``max_impulse``, ``unilateral_impulses``,
                                  ``friction``, ``swing_clearance``, ``clearance_profile``
    ``objective``                 ``cost``, ``efficiency_positive``, ``efficiency_negative``,
    (:class:`CostOptions`)        ``resting_power``, ``cost_smoothing``,
                                  ``cost_regularization``, ``torque_rate_time``
    ``discretisation``            ``knots``, ``knot_spacing``, ``transcription``,
    (:class:`Discretisation`)     ``control_model``, ``periodic_controls``, ``mesh_tol``,
                                  ``accuracy``
    ``solver``                    ``formulation``, ``tol``, ``max_iter``, ``continuation``,
    (:class:`SolverOptions`)      ``multistart``
    ============================  ========================================================

    Each field's meaning, units and default are documented in its group's class.

    Construction: the groups (``GaitOptions(targets=Targets(speed=0.2))``), the fields by
    their own names (``GaitOptions(speed=0.2, knots={"single_support": 16,
    "double_support": 6})``, each into its group; :class:`FlatOptions`), or both (a flat
    keyword changes the given group's field). :meth:`replace` (and ``dataclasses.replace``)
    take the same keywords. Every field of a group is also readable as a flat attribute:
    ``options.speed`` is a read-only shorthand of ``options.targets.speed`` (``knots`` gives
    the counts per phase, :attr:`knots`). :meth:`to_dict` writes the flat names (the gait
    file's ``options``).

    Defaults that follow the model (:func:`from_model`: ``speed``, ``speed_bounds``,
    ``step_length_bounds``, ``rate_bound``, ``max_impulse``, ``cost_smoothing``, ``knots``,
    ``formulation``, ``gait``) hold the five-link biped's values here; a solve replaces each
    one the caller did not give with the model's
    (:func:`gaitopt.gait.options.model_defaults.options_for_model`: the gait its contact points
    allow, Froude-scaled speeds and bounds), which for the five-link biped are the same
    values exactly. A value given by the caller always stays.
    """

    targets: Targets = field(default_factory=Targets)
    sequence: SequenceOptions = field(default_factory=SequenceOptions)
    limits: Limits = field(default_factory=Limits)
    objective: CostOptions = field(default_factory=CostOptions)
    discretisation: Discretisation = field(default_factory=Discretisation)
    solver: SolverOptions = field(default_factory=SolverOptions)

    def __init__(self, *, targets: Targets | None = None, sequence: SequenceOptions | None = None,
                 limits: Limits | None = None, objective: CostOptions | None = None,
                 discretisation: Discretisation | None = None,
                 solver: SolverOptions | None = None, **flat: Unpack[FlatOptions]) -> None:
        given: dict[str, Any] = {"targets": targets, "sequence": sequence, "limits": limits,
                                 "objective": objective, "discretisation": discretisation,
                                 "solver": solver}
        changes: dict[str, dict[str, Any]] = {}
        for name, value in flat.items():
            if name not in FIELD_GROUPS:
                raise TypeError(f"GaitOptions: unknown option {name!r}; known: "
                                f"{', '.join(sorted(FIELD_GROUPS))}")
            changes.setdefault(FIELD_GROUPS[name], {})[name] = value
        for group, cls in GROUPS.items():
            value = given[group]
            if value is None:
                value = _DEFAULT_GROUPS[group]
            elif not isinstance(value, cls):
                raise TypeError(f"GaitOptions: {group} = {value!r}: must be a {cls.__name__}")
            if group in changes:
                value = dataclasses.replace(value, **changes[group])
            object.__setattr__(self, group, value)

    # -- the shorthands (read-only) ------------------------------------------------------------
    speed = _Alias[float | None]("targets.speed")
    speed_bounds = _Alias[tuple[float, float]]("targets.speed_bounds")
    step_length = _Alias[float | None]("targets.step_length")
    step_length_bounds = _Alias[tuple[float, float]]("targets.step_length_bounds")
    step_time = _Alias[float | None]("targets.step_time")
    gait = _Alias[GaitKind]("sequence.gait")
    contact_sequence = _Alias[dict[str, Any] | None]("sequence.contact_sequence")
    stride = _Alias[bool]("sequence.stride")
    single_support_fraction = _Alias[float]("sequence.single_support_fraction")
    single_support_fraction_bounds = _Alias[tuple[float, float] | None](
        "sequence.single_support_fraction_bounds")
    free_phase_fractions = _Alias[bool | None]("sequence.free_phase_fractions")
    phase_shares = _Alias[tuple[float, ...] | None]("sequence.phase_shares")
    ankle = _Alias[bool]("sequence.ankle")
    impulse = _Alias[bool]("sequence.impulse")
    min_stance_knee_flexion = _Alias[float]("limits.min_stance_knee_flexion")
    torso_bounds = _Alias[tuple[float, float]]("limits.torso_bounds")
    rate_bound = _Alias[float]("limits.rate_bound")
    max_impulse = _Alias[float]("limits.max_impulse")
    unilateral_impulses = _Alias[bool]("limits.unilateral_impulses")
    friction = _Alias[float | None]("limits.friction")
    swing_clearance = _Alias[float | None]("limits.swing_clearance")
    clearance_profile = _Alias[ClearanceProfile]("limits.clearance_profile")
    cost = _Alias[CostName]("objective.cost")
    efficiency_positive = _Alias[float]("objective.efficiency_positive")
    efficiency_negative = _Alias[float]("objective.efficiency_negative")
    resting_power = _Alias[float]("objective.resting_power")
    cost_smoothing = _Alias[float]("objective.cost_smoothing")
    cost_regularization = _Alias[float]("objective.cost_regularization")
    torque_rate_time = _Alias[float]("objective.torque_rate_time")
    knot_spacing = _Alias[KnotSpacing]("discretisation.knot_spacing")
    transcription = _Alias[Transcription]("discretisation.transcription")
    control_model = _Alias[ControlModel]("discretisation.control_model")
    periodic_controls = _Alias[bool]("discretisation.periodic_controls")
    mesh_tol = _Alias[float | None]("discretisation.mesh_tol")
    accuracy = _Alias[float | None]("discretisation.accuracy")
    formulation = _Alias[Formulation]("solver.formulation")
    tol = _Alias[float]("solver.tol")
    max_iter = _Alias[int]("solver.max_iter")
    continuation = _Alias[bool]("solver.continuation")
    multistart = _Alias[bool]("solver.multistart")

    @property
    def knots(self) -> tuple[int, ...]:
        """The knots per phase as counts: ``discretisation.knots`` when it is counts (the
        default's :func:`from_model` mark kept), a mapping by phase name in the order of the
        step's phases (:func:`phase_names`).

        Raises:
            GaitOptionsError: the mapping names a phase the step lacks or leaves one out.
        """
        knots = self.discretisation.knots
        if not isinstance(knots, dict):  # a mapping is kept as a dict (Discretisation)
            return cast(tuple[int, ...], knots)
        try:
            return knots_in_order(knots, phase_names(self), "discretisation.knots")
        except KnotsError as exc:
            raise GaitOptionsError(str(exc)) from None

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
        default, then ``changes`` (flat keywords). At 12 m/min it gives J = 487.94 N^2 m s;
        speed free, 11.1 m/min with 0.107 m steps and 486.3."""
        return GaitOptions(**{**PAPER_GRID, **changes})

    @property
    def paper_grid(self) -> bool:
        """Whether these options solve on the paper's grid and control model."""
        knots = self.discretisation.knots
        return (not isinstance(knots, Mapping) and tuple(knots) == PAPER_GRID["knots"]
                and self.control_model == PAPER_GRID["control_model"])

    def replace(self, *, targets: Targets | None = None, sequence: SequenceOptions | None = None,
                limits: Limits | None = None, objective: CostOptions | None = None,
                discretisation: Discretisation | None = None,
                solver: SolverOptions | None = None,
                **changes: Unpack[FlatOptions]) -> GaitOptions:
        """A copy with some groups and fields changed (flat keywords as the constructor's;
        validated again by the caller)."""
        return GaitOptions(targets=targets or self.targets, sequence=sequence or self.sequence,
                           limits=limits or self.limits, objective=objective or self.objective,
                           discretisation=discretisation or self.discretisation,
                           solver=solver or self.solver, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain data for the gait file: every field by its flat name (:data:`FIELD_GROUPS`;
        ``None`` means free; ``knots`` a list, or a mapping when given by phase name)."""
        return {name: _plain(getattr(getattr(self, group), name))
                for name, group in FIELD_GROUPS.items()}

    @staticmethod
    def saved_defaults() -> dict[str, Any]:
        """What a field missing from saved options (a gait file, ``sweep.json``) stands for:
        today's default, or its :data:`LEGACY_DEFAULTS` value (plain data, as
        :meth:`to_dict`)."""
        return {**GaitOptions().to_dict(), **LEGACY_DEFAULTS}

    @staticmethod
    def from_dict(data: dict[str, Any]) -> GaitOptions:
        """Options from saved data (:meth:`to_dict`: flat names, as every gait file has
        them); a missing field takes its :meth:`saved_defaults` value."""
        unknown = sorted(set(data) - FIELD_GROUPS.keys())
        if unknown:
            raise GaitOptionsError(f"unknown gait option(s) {', '.join(unknown)}; known: "
                                   f"{', '.join(sorted(FIELD_GROUPS))}")
        clean: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v
                                 for k, v in {**LEGACY_DEFAULTS, **data}.items()}
        return GaitOptions(**clean)


def phase_names(options: GaitOptions) -> tuple[str, ...]:
    """The phase names of one step of the options' contact sequence, without the model: the
    given sequence's (the first step's of a stride written as two), else the built-in gait's
    (:data:`~gaitopt.gait.sequence.knots.BUILTIN_PHASES`). A gait still to follow the model
    (:func:`from_model`) is the built-in one whose phases ``knots`` names, if one is."""
    o = options
    if o.contact_sequence is not None:
        phases = o.contact_sequence.get("phases")
        if not isinstance(phases, list):
            return ()
        names = tuple(str(p.get("name")) if isinstance(p, dict) else "?" for p in phases)
        steps = o.contact_sequence.get("steps", 1)
        if isinstance(steps, int) and steps > 1 and len(names) % steps == 0:
            names = names[:len(names) // steps]
        return names
    gait = str(o.gait)
    knots = o.discretisation.knots
    if follows_model(o.gait) and isinstance(knots, Mapping):
        gait = next((g for g in GAITS if set(BUILTIN_PHASES[g]) == set(knots)), gait)
    if gait == "walk" and o.single_support_fraction >= 1.0:
        gait = "walk-single-support"
    return BUILTIN_PHASES.get(gait, ())


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


def _check_knots(o: GaitOptions) -> None:
    """The ``knots`` of :func:`validate_options`: its form (:mod:`gaitopt.gait.sequence.knots`),
    then >= 3 knots in the first phase, >= 2 in every other, at most 400 in any."""
    given, path = o.discretisation.knots, "discretisation.knots"
    named = isinstance(given, dict)  # a mapping is kept as a dict (Discretisation)
    counts: Any = o.knots if named else given  # a mapping's names checked against the phases
    if (not named and isinstance(given, tuple | list) and len(given) != 2
            and not len(given) == len(phase_names(o)) > 2):
        counts = None
    if (not isinstance(counts, tuple | list) or not counts
            or not all(isinstance(k, int) and not isinstance(k, bool) for k in counts)):
        phases = phase_names(o)
        form = ("two integers (single support, double support)" if len(phases) <= 2 else
                f"two integers (first phase, every later phase), one per phase or a mapping "
                f"phase name -> count ({', '.join(phases)})")
        raise GaitOptionsError(f"{path} = {_knots_shown(given)}: must be {form}")
    if counts[0] < 3 or (o.double_support and len(counts) > 1 and min(counts[1:]) < 2):
        where = ("in single support and >= 2 in double support" if len(counts) <= 2 and not named
                 else "in the first phase and >= 2 in every other")
        raise GaitOptionsError(f"{path} = {_knots_shown(given)}: need >= 3 knots {where}")
    if max(counts) > 400:
        raise GaitOptionsError(f"{path} = {_knots_shown(given)}: at most 400 per phase")


def _knots_shown(given: Any) -> str:
    if isinstance(given, Mapping):
        return "{" + ", ".join(f"{k}: {v!r}" for k, v in given.items()) + "}"
    return str(tuple(given)) if isinstance(given, tuple | list) else repr(given)


def validate_options(options: GaitOptions, biped: Biped | None) -> None:
    """Check every option before any solve; raise :class:`GaitOptionsError` naming the field,
    the bad value and the allowed range. ``biped``: the legs, for the reach checks (None for a
    model without thigh-shank legs in the full formulation: no reach check)."""
    o = options
    v_lo, v_hi = _bounds("targets.speed_bounds", o.speed_bounds, positive=True)
    if o.speed is not None:
        speed = _finite("targets.speed", o.speed)
        if speed <= 0.0:
            raise GaitOptionsError(f"targets.speed = {format_speed(speed)}: must be > 0 (or free)")
        # A given speed is not checked against speed_bounds, which bound a free speed only
        # (a run at 240 m/min is asked for directly; docs/running.md).
    l_lo, l_hi = _bounds("targets.step_length_bounds", o.step_length_bounds, positive=True)
    if o.formulation not in FORMULATIONS:
        raise GaitOptionsError(f"solver.formulation = {o.formulation!r}: must be one of "
                               f"{', '.join(FORMULATIONS)}")
    traits = FORMULATION_TRAITS[o.formulation]
    if o.cost not in ("paper", "work", "metabolic"):
        raise GaitOptionsError(f"objective.cost = {o.cost!r}: must be one of paper, work, "
                               "metabolic")
    costs = o.objective
    for name, value, lo, strict in (("efficiency_positive", costs.efficiency_positive, 0.0, True),
                                    ("efficiency_negative", costs.efficiency_negative, 0.0, True),
                                    ("resting_power", costs.resting_power, 0.0, False),
                                    ("cost_smoothing", costs.cost_smoothing, 0.0, True),
                                    ("cost_regularization", costs.cost_regularization, 0.0, False),
                                    ("torque_rate_time", costs.torque_rate_time, 0.0, False)):
        name = field_path(name)
        v = _finite(name, value)
        if v < lo or (strict and v == lo):
            raise GaitOptionsError(f"{name} = {v:g}: must be {'>' if strict else '>='} {lo:g}")
    if o.single_support_fraction_bounds is not None:
        f_lo, f_hi = _bounds("sequence.single_support_fraction_bounds",
                             o.single_support_fraction_bounds)
        if not traits.contact_sequences:
            raise GaitOptionsError("sequence.single_support_fraction_bounds: a free single-support "
                                   "fraction needs formulation 'full'")
        if f_lo < 0.05 or f_hi >= 1.0:
            raise GaitOptionsError(f"sequence.single_support_fraction_bounds = ({f_lo:g}, "
                                   f"{f_hi:g}): must lie in [0.05, 1) (1 is the single-support "
                                   "walk)")
        if not f_lo <= o.single_support_fraction <= f_hi:
            raise GaitOptionsError("sequence.single_support_fraction = "
                                   f"{o.single_support_fraction:g}: must lie in "
                                   f"sequence.single_support_fraction_bounds [{f_lo:g}, {f_hi:g}] "
                                   "(it is the first guess)")
    if o.free_phase_fractions:
        if not traits.contact_sequences:
            raise GaitOptionsError("sequence.free_phase_fractions: free phase fractions need "
                                   "formulation 'full'")
        if o.single_support_fraction_bounds is not None:
            raise GaitOptionsError("sequence.free_phase_fractions and "
                                   "sequence.single_support_fraction_bounds: give one of them "
                                   "(free_phase_fractions frees every phase)")
    if o.phase_shares is not None and not all(
            isinstance(v, int | float) and 0.0 < float(v) < 1.0 for v in o.phase_shares):
        raise GaitOptionsError(f"sequence.phase_shares = {tuple(o.phase_shares)!r}: each must lie "
                               "in (0, 1)")
    if o.stride:
        if not traits.contact_sequences:
            raise GaitOptionsError("sequence.stride: a two-step stride needs formulation 'full' "
                                   "(the reduced coordinates describe one step of the five-link "
                                   "biped, periodic through the leg swap)")
        if o.single_support_fraction_bounds is not None:
            raise GaitOptionsError("sequence.stride and sequence.single_support_fraction_bounds: "
                                   "give free_phase_fractions instead (it frees every phase of "
                                   "both steps)")
    if o.gait not in GAITS:
        raise GaitOptionsError(f"sequence.gait = {o.gait!r}: must be one of {', '.join(GAITS)}")
    if (o.gait == "heel-toe" or o.contact_sequence is not None) and not traits.contact_sequences:
        raise GaitOptionsError("sequence.gait = 'heel-toe' and sequence.contact_sequence need "
                               "formulation 'full'")
    if o.contact_sequence is not None:
        from gaitopt.gait.sequence.contact_sequence import ContactSequenceError, sequence_from_dict

        try:
            sequence_from_dict(o.contact_sequence)
        except ContactSequenceError as exc:
            raise GaitOptionsError(str(exc)) from None
    if o.gait == "run" and o.impulse:
        raise GaitOptionsError(
            "sequence.gait = 'run' with impulse on: a run leaves the ground from single support "
            "into a flight, with no double support for a liftoff impulse to act from; turn it off "
            "(impulse=False; gaitopt solve --gait run has it off unless --impulse is given)")
    if o.gait == "run" and (not traits.contact_sequences or o.single_support_fraction >= 1.0):
        raise GaitOptionsError(
            "sequence.gait = 'run': needs formulation 'full' and sequence.single_support_fraction "
            "< 1 (the stance share of the step)")
    flex = _finite("limits.min_stance_knee_flexion", o.min_stance_knee_flexion)
    if traits.straight_stance_knee and not 0.0 <= flex < 1.5:
        raise GaitOptionsError(f"limits.min_stance_knee_flexion = {flex:g} rad: must lie in [0, "
                               "1.5) (full formulation)")
    if not traits.straight_stance_knee and not 0.0 < flex < 1.5:
        raise GaitOptionsError(f"limits.min_stance_knee_flexion = {flex:g} rad: must lie in (0, "
                               "1.5) in the reduced formulation (its leg inverse kinematics is "
                               "singular at a straight knee; formulation 'full' allows 0)")
    reach = min(leg.reach(-flex) for leg in biped.legs) if biped is not None else math.inf
    longest = 2.0 * reach * 0.97
    if o.step_length is not None:
        step = _finite("targets.step_length", o.step_length)
        if step <= 0.0:
            raise GaitOptionsError(f"targets.step_length = {step:g} m: must be > 0 (or free)")
        if step >= longest:
            raise GaitOptionsError(
                f"targets.step_length = {step:g} m: longer than the legs can reach (both tips on "
                f"the ground with the hip above them needs step_length < {longest:.3f} m)")
        if not l_lo <= step <= l_hi:
            raise GaitOptionsError(f"targets.step_length = {step:g} m: must lie in "
                                   f"targets.step_length_bounds [{l_lo:g}, {l_hi:g}] m")
    if o.step_time is not None:
        period = _finite("targets.step_time", o.step_time)
        if period <= 0.0:
            raise GaitOptionsError(f"targets.step_time = {period:g} s: must be > 0 (or free)")
        if o.step_length is not None:
            raise GaitOptionsError(f"targets.step_time = {period:g} s and targets.step_length = "
                                   f"{o.step_length:g} m: give at most one of them (with the speed "
                                   "they fix each other)")
        lo_v, hi_v = (o.speed, o.speed) if o.speed is not None else (v_lo, v_hi)
        if period * hi_v < l_lo or period * lo_v > min(l_hi, longest):
            what = (f"speed {format_speed(o.speed)}" if o.speed is not None else
                    f"targets.speed_bounds [{format_speed(v_lo)}, {format_speed(v_hi)}]")
            steps = (f"{period * lo_v:.3g} m" if lo_v == hi_v else
                     f"{period * lo_v:.3g}-{period * hi_v:.3g} m")
            raise GaitOptionsError(
                f"targets.step_time = {period:g} s: with the {what} the step length {steps} would "
                f"leave [{l_lo:g}, {min(l_hi, longest):.3f}] m (targets.step_length_bounds and the "
                "legs' reach)")
    if l_lo >= longest:
        raise GaitOptionsError(f"targets.step_length_bounds = ({l_lo:g}, {l_hi:g}) m: the legs "
                               f"reach steps shorter than {longest:.3f} m only")
    f = _finite("sequence.single_support_fraction", o.single_support_fraction)
    if not 0.05 <= f <= 1.0:
        raise GaitOptionsError(f"sequence.single_support_fraction = {f:g}: must lie in [0.05, 1]")
    _check_knots(o)
    if o.transcription not in TRANSCRIPTIONS:
        raise GaitOptionsError(f"discretisation.transcription = {o.transcription!r}: must be one "
                               f"of {', '.join(repr(t) for t in TRANSCRIPTIONS)}")
    if o.friction is not None and not _finite("limits.friction", o.friction) > 0.0:
        raise GaitOptionsError(f"limits.friction = {o.friction!r}: must be > 0 (leave it unset for "
                               "no friction cone)")
    t_lo, t_hi = _bounds("limits.torso_bounds", o.torso_bounds)
    if not t_lo <= 0.0 <= t_hi:
        raise GaitOptionsError(f"limits.torso_bounds = ({t_lo:g}, {t_hi:g}) rad: must contain 0 "
                               "(upright), or the biped cannot stand")
    if not _finite("limits.rate_bound", o.rate_bound) > 0.0:
        raise GaitOptionsError(f"limits.rate_bound = {o.rate_bound!r}: must be > 0")
    if not _finite("limits.max_impulse", o.max_impulse) >= 0.0:
        raise GaitOptionsError(f"limits.max_impulse = {o.max_impulse!r}: must be >= 0")
    if not 0.0 < _finite("solver.tol", o.tol) < 1.0:
        raise GaitOptionsError(f"solver.tol = {o.tol!r}: must lie in (0, 1)")
    if not isinstance(o.max_iter, int) or o.max_iter < 1:
        raise GaitOptionsError(f"solver.max_iter = {o.max_iter!r}: must be a positive integer")
    if o.accuracy is not None and not 0.0 < _finite("discretisation.accuracy", o.accuracy) < 1.0:
        raise GaitOptionsError(f"discretisation.accuracy = {o.accuracy!r}: must lie in (0, 1) (a "
                               "relative accuracy, 0.01 for 1 %), or None for no refinement")
    if o.mesh_tol is not None and not 0.0 < _finite("discretisation.mesh_tol", o.mesh_tol) < 1.0:
        raise GaitOptionsError(f"discretisation.mesh_tol = {o.mesh_tol!r}: must lie in (0, 1) (or "
                               "None for the fixed grid)")
    if o.control_model not in CONTROL_MODELS:
        raise GaitOptionsError(f"discretisation.control_model = {o.control_model!r}: must be one "
                               f"of {', '.join(repr(m) for m in CONTROL_MODELS)}")
    if o.swing_clearance is not None:
        c = _finite("limits.swing_clearance", o.swing_clearance)
        if not 0.0 <= c < reach:
            raise GaitOptionsError(f"limits.swing_clearance = {c:g} m: must lie in [0, "
                                   f"{reach:.3f}) m (above the ground, below the leg's reach; 0 "
                                   "or None: y >= 0 only)")
    if o.clearance_profile not in CLEARANCE_PROFILES:
        raise GaitOptionsError(f"limits.clearance_profile = {o.clearance_profile!r}: must be one "
                               f"of {', '.join(repr(m) for m in CLEARANCE_PROFILES)}")
    if o.knot_spacing not in KNOT_SPACINGS:
        raise GaitOptionsError(f"discretisation.knot_spacing = {o.knot_spacing!r}: must be one of "
                               f"{', '.join(repr(m) for m in KNOT_SPACINGS)}")
