"""The result of a solve: always returned, converged or not.

Trajectories are per phase at the knots (``t`` (K,), ``x`` (K, n), ``u`` (K, m)) with
interpolants consistent with the transcription: cubic Hermite states for Hermite-Simpson, in
both its forms (through x_k with slope f_k), quadratic for trapezoidal, piecewise-linear
controls. The separated form also keeps its midpoint state variables (``x_mid``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from gaitopt.ocp.hermite_simpson import HermiteSimpson
from gaitopt.ocp.hermite_simpson_separated import HermiteSimpsonSeparated
from gaitopt.ocp.method import Method, control_at
from gaitopt.ocp.trapezoidal import Trapezoidal

Array = NDArray[np.float64]

METHODS: dict[str, Method] = {"hermite-simpson": HermiteSimpson(),
                               "hermite-simpson-separated": HermiteSimpsonSeparated(),
                               "trapezoidal": Trapezoidal()}


@dataclass(frozen=True)
class NlpSize:
    """NLP size in the paper's terms.

    ``variables``: entries of w; ``fixed_variables``: lb == ub; ``box_bounded_variables``:
    not fixed, with a finite lower or upper bound; ``equality_constraints``: rows of g with
    lbg == ubg; ``inequality_constraints``: other rows with a finite bound.
    """

    variables: int
    fixed_variables: int
    box_bounded_variables: int
    equality_constraints: int
    inequality_constraints: int


@dataclass(frozen=True)
class PhaseTrajectory:
    """One phase of a solution.

    Attributes: ``t`` (K,) s; ``x`` (K, n); ``u`` (K, m); ``xdot`` (K, n) the dynamics
    f(x_k, u_k, p, t_k); ``path`` path-constraint values at the knots by name, (K, r);
    ``error`` (N,) relative per-interval error estimate and ``error_by_state`` (N, n) the
    absolute integrated residuals (see :mod:`gaitopt.ocp.estimate`); ``x_mid`` (N, n) the
    midpoint state variables of the separated Hermite-Simpson form (at a converged point equal
    to ``x_at`` at the interval midpoints), ``None`` for the other methods.
    """

    name: str
    states: tuple[str, ...]
    controls: tuple[str, ...]
    method: str
    t: Array
    x: Array
    u: Array
    xdot: Array
    path: Mapping[str, Array]
    error: Array
    error_by_state: Array
    x_mid: Array | None = None

    @property
    def t0(self) -> float:
        """Start time (s)."""
        return float(self.t[0])

    @property
    def tf(self) -> float:
        """End time (s)."""
        return float(self.t[-1])

    @property
    def duration(self) -> float:
        """T = tf - t0 (s)."""
        return float(self.t[-1] - self.t[0])

    @property
    def tau(self) -> Array:
        """Normalised knot times in [0, 1], (K,)."""
        return (self.t - self.t[0]) / self.duration

    def state(self, name: str) -> Array:
        """State ``name`` at the knots, (K,)."""
        return self.x[:, self.states.index(name)]

    def control(self, name: str) -> Array:
        """Control ``name`` at the knots, (K,)."""
        return self.u[:, self.controls.index(name)]

    def _locate(self, t: ArrayLike) -> tuple[Array, NDArray[np.int64], Array, Array]:
        tq = np.atleast_1d(np.asarray(t, dtype=float))
        k = np.clip(np.searchsorted(self.t, tq, side="right") - 1, 0, self.t.size - 2)
        h = self.t[k + 1] - self.t[k]
        s = (tq - self.t[k]) / h
        return tq, k, s, h

    def x_at(self, t: ArrayLike) -> Array:
        """States at times ``t`` (M,) by the transcription's interpolant, (M, n)."""
        _, k, s, h = self._locate(t)
        m = METHODS[self.method]
        return np.asarray(m.state_at(s[:, None], self.x[k], self.x[k + 1], self.xdot[k],
                                     self.xdot[k + 1], h[:, None]))

    def xdot_at(self, t: ArrayLike) -> Array:
        """Time derivative of the state interpolant at ``t``, (M, n)."""
        _, k, s, h = self._locate(t)
        m = METHODS[self.method]
        return np.asarray(m.rate_at(s[:, None], self.x[k], self.x[k + 1], self.xdot[k],
                                    self.xdot[k + 1], h[:, None]))

    def u_at(self, t: ArrayLike) -> Array:
        """Piecewise-linear controls at ``t``, (M, m)."""
        _, k, s, _ = self._locate(t)
        return np.asarray(control_at(s[:, None], self.u[k], self.u[k + 1]))


@dataclass(frozen=True)
class Result:
    """The outcome of one solve (see the module docstring).

    Attributes:
        status: IPOPT's return status (e.g. ``Solve_Succeeded``,
            ``Infeasible_Problem_Detected``, ``Maximum_Iterations_Exceeded``) or
            ``Solver_Exception`` when the solver raised (``message`` says why).
        success: converged to a (locally) optimal point.
        iterations: IPOPT iterations.
        objective: J (unscaled, the ratio if a denominator is given).
        constraint_violation: largest violation of any constraint or variable bound (unscaled).
        evaluations: calls by kind (``nlp_f, nlp_g, nlp_grad_f, nlp_jac_g, nlp_hess_l``).
        times: wall times in seconds: ``total`` (the solver call), ``evaluations`` (sum of the
            function evaluations) and each kind.
        nlp_size: see :class:`NlpSize`.
        phases: one :class:`PhaseTrajectory` per phase.
        parameters: parameter values by name.
        w, lam_x, lam_g: unscaled primal vector and multipliers (for warm starts).
        method: transcription method name; mesh: normalised knots per phase.
        layout_signature: identifies the variable layout (multipliers are reused only when the
            layouts match).
        constraint_blocks: ``(name, rows)`` of each block of ``g`` in order (empty for a
            Result made without a transcription): multipliers carry over by block name to a
            problem with the same variables and other constraint blocks
            (:meth:`gaitopt.ocp.Transcription.carried_over`).
    """

    status: str
    success: bool
    iterations: int
    objective: float
    constraint_violation: float
    evaluations: Mapping[str, int]
    times: Mapping[str, float]
    nlp_size: NlpSize
    phases: tuple[PhaseTrajectory, ...]
    parameters: Mapping[str, float]
    w: Array
    lam_x: Array
    lam_g: Array
    method: str
    mesh: tuple[Array, ...]
    layout_signature: tuple[object, ...]
    message: str = ""
    constraint_blocks: tuple[tuple[str, int], ...] = ()
    stats: Mapping[str, object] = field(default_factory=dict, repr=False)

    def phase(self, key: int | str) -> PhaseTrajectory:
        """A phase's trajectory by position or name."""
        if isinstance(key, int):
            return self.phases[key]
        for ph in self.phases:
            if ph.name == key:
                return ph
        raise KeyError(f"no phase {key!r} (phases: {[ph.name for ph in self.phases]})")

    @property
    def max_error(self) -> float:
        """Largest per-interval error estimate over all phases."""
        return max(float(np.max(ph.error)) if ph.error.size else 0.0 for ph in self.phases)

    def errors_by_phase(self) -> dict[str, float]:
        """Largest per-interval error estimate of each phase, by phase name."""
        return {ph.name: float(np.max(ph.error)) if ph.error.size else 0.0
                for ph in self.phases}

    @property
    def infeasible(self) -> bool:
        """IPOPT found the constraints (locally) infeasible."""
        return self.status == "Infeasible_Problem_Detected"

    def summary(self) -> str:
        """One line: status, objective, iterations, violation, time."""
        return (f"{self.status}: J = {self.objective:.10g}, {self.iterations} iterations, "
                f"violation {self.constraint_violation:.2e}, {self.times.get('total', 0.0):.3f} s")


def point_values(point: ca.Function, t: Array, x: Array, u: Array,
                 p: Array) -> tuple[Array, Array, Array]:
    """Evaluate a phase point function at K knots: ``(xdot (K, n), path (K, r), L (K,))``."""
    K = t.size
    out = point.map(K)(x.T, u.T, np.asarray(p, dtype=float).reshape(-1, 1), t.reshape(1, K))
    xdot, path, lag = (np.asarray(o, dtype=float) for o in out)
    return xdot.T.copy(), path.T.copy(), lag.reshape(K)
