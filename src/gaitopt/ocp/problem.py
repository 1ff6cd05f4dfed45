"""The statement of a multi-phase optimal control problem (data only, no transcription).

A problem is a sequence of phases run one after the other in time, static parameters ``p``
shared by all phases, linkages between phase ends, boundary (event) constraints and costs::

    minimise   J = (sum_i int_{phase i} [L_i(x, u, p, t) + sum_j r_ij u_j'(t)^2] dt
                    + M(ends, p) + P(p)) / D(ends, p)
    subject to x_i' = f_i(x_i, u_i, p, t)                  in every phase i
               c_lo <= c_i(x_i, u_i, p, t) <= c_hi          path constraints
               b_lo <= b(ends, p) <= b_hi                   boundary/event constraints
               x_j(t0_j)[S] = Delta(x_i(tf_i), u_i(tf_i), p) linkages (continuity or jumps)
               box bounds on x, u, p and phase durations

``ends`` gives each phase's end values ``t0, tf, x0, xf, u0, uf`` by phase name. The
denominator ``D`` is 1 unless a ratio cost is asked for (e.g. energy / step length).

Every user function is a Python callable of CasADi ``SX`` symbols returning an ``SX``
expression (or a list of scalar expressions); it may call ``SX`` ``casadi.Function`` objects.
The vectors passed are columns: ``x`` (n, 1) in the order of ``Phase.states``, ``u`` (m, 1) in
the order of ``Phase.controls``, ``p`` (n_p, 1) in the order of ``Problem.parameters``, ``t``
(1, 1). Use :func:`named` to refer to entries by name. Phase start times are sequential:
``t0_0 = Problem.t0`` and ``t0_{i+1} = t0_i + T_i``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import casadi as ca

Bound = tuple[float, float]
PointFn = Callable[[ca.SX, ca.SX, ca.SX, ca.SX], Any]
"""``fn(x, u, p, t) -> SX``: a function of the state, control, parameters and time."""
EndsFn = Callable[[Mapping[str, "PhaseEnds"], ca.SX], Any]
"""``fn(ends, p) -> SX``: a function of the phase end values (by phase name) and parameters."""

Where = Literal["knots", "knots+midpoints"]

INF = math.inf


def named(vector: ca.SX, names: Sequence[str]) -> dict[str, ca.SX]:
    """The entries of a symbolic column ``vector`` (len(names), 1) by name."""
    if vector.shape[0] != len(names):
        raise ValueError(f"vector has {vector.shape[0]} entries but {len(names)} names")
    return {name: vector[i] for i, name in enumerate(names)}


@dataclass(frozen=True)
class PhaseEnds:
    """The symbolic end values of one phase: times (1, 1), states (n, 1), controls (m, 1)."""

    t0: ca.SX
    tf: ca.SX
    x0: ca.SX
    xf: ca.SX
    u0: ca.SX
    uf: ca.SX
    states: tuple[str, ...]
    controls: tuple[str, ...]

    def x0_named(self) -> dict[str, ca.SX]:
        """Initial states by name."""
        return named(self.x0, self.states)

    def xf_named(self) -> dict[str, ca.SX]:
        """Final states by name."""
        return named(self.xf, self.states)


@dataclass(frozen=True)
class KnotStates:
    """States given by the others at every knot of a phase after the first (not variables).

    At knot ``k >= 1`` the states ``names`` are ``fn(x_k, p)`` (``len(names)`` values): an
    explicit solution of equality constraints the problem would otherwise state there, e.g. a
    floating base placed by a contact point held on the ground. ``fn`` must not read the
    entries ``names`` of ``x``. The NLP then has neither those variables (they stay in ``w``,
    fixed, and a result holds their values from ``fn``) nor the constraints they solve: the
    same optimum with fewer unknowns and rows, provided the box bounds of ``names``, which the
    NLP no longer imposes at those knots, are inactive (a result reports their violation).
    The first knot keeps its variables (linkages and initial bounds set them).
    """

    names: tuple[str, ...]
    fn: Callable[[ca.SX, ca.SX], Any]


@dataclass(frozen=True)
class Parameter:
    """A static decision parameter shared by all phases, ``lower <= p <= upper``.

    ``lower == upper`` fixes it (it stays a variable, so a re-solve can change the value through
    the bounds without rebuilding). ``guess`` defaults to the midpoint of finite bounds (or the
    finite bound, or 0). ``scale`` defaults to the largest finite bound magnitude.
    """

    name: str
    lower: float = -INF
    upper: float = INF
    guess: float | None = None
    scale: float | None = None


@dataclass(frozen=True)
class Duration:
    """A phase duration T (s): fixed, free within ``[lower, upper]``, or an expression of p.

    Build with :meth:`fixed`, :meth:`free` or :meth:`of_parameters`. For an expression,
    ``lower``/``upper`` (if finite) add the constraint ``lower <= T(p) <= upper``.
    """

    lower: float
    upper: float
    guess: float | None = None
    expression: Callable[[ca.SX], Any] | None = None
    scale: float | None = None

    @staticmethod
    def fixed(value: float) -> Duration:
        """A known duration ``T = value`` (no decision variable)."""
        return Duration(lower=value, upper=value, guess=value)

    @staticmethod
    def free(lower: float, upper: float, guess: float | None = None,
             scale: float | None = None) -> Duration:
        """A decision variable ``lower <= T <= upper``."""
        return Duration(lower=lower, upper=upper, guess=guess, scale=scale)

    @staticmethod
    def of_parameters(expression: Callable[[ca.SX], Any], lower: float = -INF,
                      upper: float = INF) -> Duration:
        """``T = expression(p)`` with p the (n_p, 1) parameter column (no decision variable)."""
        return Duration(lower=lower, upper=upper, expression=expression)

    @property
    def kind(self) -> Literal["fixed", "free", "expression"]:
        """How T is determined."""
        if self.expression is not None:
            return "expression"
        return "fixed" if self.lower == self.upper else "free"


@dataclass(frozen=True)
class PathConstraint:
    """``lower <= fn(x, u, p, t) <= upper`` along a phase (equality where lower == upper).

    ``fn`` returns r values; ``lower``/``upper`` are scalars (applied to all r) or length-r
    sequences. ``at`` chooses the points: knots only, or knots and collocation midpoints
    (default). ``scale`` divides the constraint rows (default: largest finite bound magnitude).
    """

    name: str
    fn: PointFn
    lower: float | Sequence[float] = 0.0
    upper: float | Sequence[float] = 0.0
    at: Where = "knots+midpoints"
    scale: float | Sequence[float] | None = None


@dataclass(frozen=True)
class BoundaryConstraint:
    """``lower <= fn(ends, p) <= upper``: an event/boundary constraint on phase end values."""

    name: str
    fn: EndsFn
    lower: float | Sequence[float] = 0.0
    upper: float | Sequence[float] = 0.0
    scale: float | Sequence[float] | None = None


@dataclass(frozen=True)
class Linkage:
    """Join the end of phase ``from_phase`` to the start of phase ``to_phase``.

    ``x_to(t0)[states] = jump(x_from(tf), u_from(tf), p)``; without ``jump`` it is continuity,
    ``x_to(t0)[s] = x_from(tf)[s]`` for each name ``s`` in ``states`` (which must exist in both
    phases). ``states`` defaults to all states of ``to_phase``. A linkage from the last phase to
    the first is a cyclic (periodicity) linkage.
    """

    from_phase: str
    to_phase: str
    jump: Callable[[ca.SX, ca.SX, ca.SX], Any] | None = None
    states: Sequence[str] | None = None
    name: str | None = None

    def label(self) -> str:
        """A name for messages and constraint rows."""
        return self.name or f"linkage {self.from_phase}->{self.to_phase}"


@dataclass(frozen=True)
class ControlLinkage:
    """``u_to(t0)[controls] = fn(u_from(tf), p)`` (continuity by name without ``fn``)."""

    from_phase: str
    to_phase: str
    fn: Callable[[ca.SX, ca.SX], Any] | None = None
    controls: Sequence[str] | None = None
    name: str | None = None

    def label(self) -> str:
        """A name for messages and constraint rows."""
        return self.name or f"control linkage {self.from_phase}->{self.to_phase}"


@dataclass(frozen=True)
class Phase:
    """One phase: its states, controls, dynamics x' = f(x, u, p, t), bounds and constraints.

    Attributes:
        name: unique phase name.
        states: state names (n); controls: control names (m, may be empty).
        dynamics: ``f(x, u, p, t) -> SX (n, 1)``.
        duration: a :class:`Duration`, a float (fixed) or a ``(lower, upper)`` pair (free).
        state_bounds / control_bounds: path box bounds by name (default unbounded).
        initial_state / final_state: box bounds (or a value) on the first/last knot by name;
            they replace the path bound at that knot.
        initial_control / final_control: the same for controls.
        path_constraints: :class:`PathConstraint` list.
        lagrange: integrand ``L(x, u, p, t) -> SX scalar`` of the running cost.
        control_rate_weights: weights ``r_j >= 0`` by control name of the control-rate term
            ``r_j int u_j'(t)^2 dt`` of the cost's numerator (units of the numerator per
            (control unit / s)^2 s). The controls are piecewise linear between knots, so the
            term is exactly ``r_j sum_k (u_j[k+1] - u_j[k])^2 / h_k`` over the phase's
            intervals; a jump between phases is not counted.
        state_scales / control_scales: variable scales by name (default from bounds).
        intervals: default number of mesh intervals (a transcription may override it).
        knot_states: states given by the others at every knot after the first
            (:class:`KnotStates`), or None.
    """

    name: str
    states: Sequence[str]
    controls: Sequence[str]
    dynamics: PointFn
    duration: Duration | float | tuple[float, float]
    state_bounds: Mapping[str, Bound] = field(default_factory=dict)
    control_bounds: Mapping[str, Bound] = field(default_factory=dict)
    initial_state: Mapping[str, Bound | float] = field(default_factory=dict)
    final_state: Mapping[str, Bound | float] = field(default_factory=dict)
    initial_control: Mapping[str, Bound | float] = field(default_factory=dict)
    final_control: Mapping[str, Bound | float] = field(default_factory=dict)
    path_constraints: Sequence[PathConstraint] = ()
    lagrange: PointFn | None = None
    control_rate_weights: Mapping[str, float] = field(default_factory=dict)
    state_scales: Mapping[str, float] = field(default_factory=dict)
    control_scales: Mapping[str, float] = field(default_factory=dict)
    intervals: int = 20
    knot_states: KnotStates | None = None

    @property
    def n_states(self) -> int:
        """n."""
        return len(self.states)

    @property
    def n_controls(self) -> int:
        """m."""
        return len(self.controls)

    def duration_spec(self) -> Duration:
        """The duration as a :class:`Duration` (floats and pairs converted)."""
        d = self.duration
        if isinstance(d, Duration):
            return d
        if isinstance(d, tuple | list):
            if len(d) != 2:
                raise ValueError(f"phase {self.name!r}: duration pair must be (lower, upper)")
            return Duration.free(float(d[0]), float(d[1]))
        return Duration.fixed(float(d))


@dataclass(frozen=True)
class Problem:
    """A multi-phase optimal control problem (see the module docstring for the equations).

    Attributes:
        phases: the phases in time order.
        parameters: static parameters (shared by all phases).
        linkages: :class:`Linkage` and :class:`ControlLinkage` items.
        boundary_constraints: :class:`BoundaryConstraint` items.
        mayer: end-point cost ``M(ends, p)``; parameter_cost: ``P(p)``.
        cost_denominator: ``D(ends, p)``: the objective becomes a ratio (numerator / D).
        t0: start time of the first phase (s).
        objective_scale: the NLP minimises ``J / objective_scale``.
    """

    phases: Sequence[Phase]
    parameters: Sequence[Parameter] = ()
    linkages: Sequence[Linkage | ControlLinkage] = ()
    boundary_constraints: Sequence[BoundaryConstraint] = ()
    mayer: EndsFn | None = None
    parameter_cost: Callable[[ca.SX], Any] | None = None
    cost_denominator: EndsFn | None = None
    t0: float = 0.0
    objective_scale: float = 1.0

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Parameter names in vector order."""
        return tuple(par.name for par in self.parameters)

    def phase_index(self, name: str) -> int:
        """Position of the phase called ``name``."""
        for i, ph in enumerate(self.phases):
            if ph.name == name:
                return i
        raise KeyError(f"no phase named {name!r} (phases: {[ph.name for ph in self.phases]})")
