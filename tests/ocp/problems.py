"""Optimal control problems with known answers (shared by the tests and bench/ocp.py).

Each builder returns a :class:`gaitopt.ocp.Problem`; the analytic optimum is documented next to
it and given by a companion function.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
from numpy.typing import NDArray
from scipy.linalg import expm
from scipy.optimize import brentq

from gaitopt.ocp import (
    BoundaryConstraint,
    ControlLinkage,
    Duration,
    Guess,
    Linkage,
    Parameter,
    PathConstraint,
    Phase,
    PhaseGuess,
    Problem,
)

G = 9.81


def double_integrator_dynamics(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
    """s' = v, v' = a."""
    return ca.vertcat(x[1], u[0])


def energy(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
    """L = a^2."""
    return u[0] ** 2


# --- 1. minimum-energy rest-to-rest double integrator ---
# min int_0^1 a^2 dt, s(0)=0, s(1)=1, v(0)=v(1)=0. Optimum: a = 6 - 12 t, s = 3t^2 - 2t^3,
# v = 6t - 6t^2, J = 12. The states are cubic and the control linear: Hermite-Simpson is exact.
def double_integrator(intervals: int = 10) -> Problem:
    """Rest-to-rest double integrator (J* = 12)."""
    ph = Phase("move", ["s", "v"], ["a"], double_integrator_dynamics, 1.0,
               initial_state={"s": 0.0, "v": 0.0}, final_state={"s": 1.0, "v": 0.0},
               lagrange=energy, intervals=intervals)
    return Problem([ph])


# --- 2. brachistochrone ---
# x' = v cos(theta), y' = v sin(theta) (y downward), v' = g sin(theta), from rest at the origin
# to (xf, yf) in minimum time. Optimum: the cycloid x = R (phi - sin phi), y = R (1 - cos phi)
# with phi = t sqrt(g / R); phi_f solves (phi - sin phi) / (1 - cos phi) = xf / yf and
# T = phi_f sqrt(R / g).
def brachistochrone(xf: float = 1.0, yf: float = 0.6, intervals: int = 30) -> Problem:
    """Minimum-time slide to (xf, yf)."""
    def f(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        v, th = x[2], u[0]
        return ca.vertcat(v * ca.cos(th), v * ca.sin(th), G * ca.sin(th))

    ph = Phase("slide", ["x", "y", "v"], ["theta"], f, Duration.free(0.05, 5.0, guess=0.5),
               control_bounds={"theta": (-math.pi / 2, math.pi / 2)},
               initial_state={"x": 0.0, "y": 0.0, "v": 0.0},
               final_state={"x": xf, "y": yf}, intervals=intervals)
    return Problem([ph], mayer=lambda ends, p: ends["slide"].tf)


def brachistochrone_guess(xf: float = 1.0, yf: float = 0.6) -> Guess:
    """A straight-line slide guess (v = 0 everywhere is a degenerate start)."""
    tau = np.array([0.0, 1.0])
    return Guess(phases={"slide": PhaseGuess(
        x={"x": xf * tau, "y": yf * tau, "v": [1.0, 3.0]}, u={"theta": 0.5}, tau=tau,
        duration=0.6)})


def cycloid(xf: float, yf: float) -> tuple[float, float, float]:
    """``(R, phi_f, T)`` of the brachistochrone to (xf, yf)."""
    phi_f = brentq(lambda ph: (ph - math.sin(ph)) / (1 - math.cos(ph)) - xf / yf, 1e-6,
                   2 * math.pi - 1e-6)
    R = yf / (1 - math.cos(phi_f))
    return R, phi_f, phi_f * math.sqrt(R / G)


def brachistochrone_costates(t: NDArray[np.float64], xf: float = 1.0,
                             yf: float = 0.6) -> NDArray[np.float64]:
    """The exact costates ``(lambda_x, lambda_y, lambda_v)`` (M, 3) of :func:`brachistochrone`
    at times ``t`` (M,), with H = lambda^T f (L = 0, Mayer tf). Along the cycloid theta =
    pi/2 - phi/2 and v = 2 sqrt(g R) sin(phi/2). Free tf and autonomous dynamics: H = -1;
    x, y absent from f: lambda_x, lambda_y constant; v(tf) free: lambda_v(tf) = 0, so at tf
    H_theta = 0 and H = -1 give lambda_x = -cos(theta_f) / v_f, lambda_y = -sin(theta_f) / v_f;
    H_theta = 0 along the way gives lambda_v = v (lambda_x sin theta - lambda_y cos theta) /
    (g cos theta) = 2 sqrt(R / g) (lambda_x cos(phi/2) - lambda_y sin(phi/2))."""
    R, phi_f, _ = cycloid(xf, yf)
    theta_f = math.pi / 2 - phi_f / 2
    v_f = 2.0 * math.sqrt(G * R) * math.sin(phi_f / 2)
    lx, ly = -math.cos(theta_f) / v_f, -math.sin(theta_f) / v_f
    half = np.asarray(t, dtype=float) * math.sqrt(G / R) / 2
    lv = 2.0 * math.sqrt(R / G) * (lx * np.cos(half) - ly * np.sin(half))
    return np.stack([np.full_like(half, lx), np.full_like(half, ly), lv], axis=1)


# --- 3. free final time ---
# min T + int_0^T a^2 dt for the rest-to-rest double integrator over distance 1. For fixed T
# the energy is 12 / T^3, so J(T) = T + 12 / T^3, minimal at T^4 = 36: T* = sqrt(6),
# J* = 8 / sqrt(6).
def free_time(intervals: int = 10) -> Problem:
    """Free-final-time double integrator (T* = sqrt 6, J* = 8 / sqrt 6)."""
    ph = Phase("move", ["s", "v"], ["a"], double_integrator_dynamics,
               Duration.free(0.5, 10.0, guess=1.0),
               initial_state={"s": 0.0, "v": 0.0}, final_state={"s": 1.0, "v": 0.0},
               lagrange=energy, intervals=intervals)
    return Problem([ph], mayer=lambda ends, p: ends["move"].tf - ends["move"].t0)


# --- 4. two phases joined by a jump ---
# Phase "before" (T = 1): double integrator from rest at s = 0 to a free (s_m, v_m).
# Jump: s+ = s-, v+ = -v-/2 (a bounce that halves and reverses the velocity).
# Phase "after" (T = 1): from (s_m, -v_m/2) to rest at s = 1. Cost: int a^2 over both phases.
# For a double integrator from (s0, v0) to (s1, v1) in time T the least energy is
#   E = 12 (s1 - s0 - T (v0 + v1)/2)^2 / T^3 + (v1 - v0)^2 / T.
# So J(s, v) = 12 (s - v/2)^2 + v^2 + 12 (1 - s + v/4)^2 + v^2/4.
#   dJ/ds = 0:  24 (s - v/2) - 24 (1 - s + v/4) = 0  =>  s = 1/2 + 3 v / 8.
#   Then s - v/2 = 1 - s + v/4 = 1/2 - v/8, and
#   dJ/dv = 0:  -12 (1/2 - v/8) + 6 (1/2 - v/8) + 5 v / 2 = 0  =>  -3 + 13 v / 4 = 0.
# Optimum: v_m = 12/13, s_m = 11/13, J* = 24 (10/26)^2 + (5/4)(12/13)^2 = 60/13.
# Both phases have linear controls (cubic states), so Hermite-Simpson is exact.
def two_phase_jump(intervals: int = 6) -> Problem:
    """Two phases with a velocity jump (J* = 60/13, s_m = 11/13, v_m = 12/13)."""
    before = Phase("before", ["s", "v"], ["a"], double_integrator_dynamics, 1.0,
                   initial_state={"s": 0.0, "v": 0.0}, lagrange=energy, intervals=intervals)
    after = Phase("after", ["s", "v"], ["a"], double_integrator_dynamics, 1.0,
                  final_state={"s": 1.0, "v": 0.0}, lagrange=energy, intervals=intervals)
    bounce = Linkage("before", "after", jump=lambda xf, uf, p: ca.vertcat(xf[0], -0.5 * xf[1]),
                     name="bounce")
    return Problem([before, after], linkages=[bounce])


# --- 5. periodic motion with a ratio cost ---
# A cart with drag, s' = v, v' = a - v, moves periodically: two phases of durations
# T_i = D / (2 vbar) (expressions of the parameters: distance D and mean speed vbar), states
# and controls continuous between them and cyclic from the end of the second to the start of
# the first (for v and a), with s_end - s_start = D. Cost: energy plus a constant c per
# second, per unit distance:  J = int (a^2 + c) dt / D.
# With a = v' + v and periodic v:  int a^2 = int v'^2 + int v^2 (the cross term integrates
# 2 v v' to 0), and int v^2 >= (int v)^2 / T, so J >= (D^2/T + c T) / D = vbar + c / vbar,
# with equality for constant v = vbar. With vbar free the optimum is vbar = sqrt(c),
# J* = 2 sqrt(c); with vbar fixed, J = vbar + c / vbar.
def periodic_ratio(c: float = 4.0, intervals: int = 8) -> Problem:
    """Periodic drag cart, energy per distance (J* = 2 sqrt(c) at vbar = sqrt(c))."""
    def f(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        return ca.vertcat(x[1], u[0] - x[1])

    def lag(x: ca.SX, u: ca.SX, p: ca.SX, t: ca.SX) -> ca.SX:
        return u[0] ** 2 + c

    half = Duration.of_parameters(lambda p: 0.5 * p[0] / p[1])
    first = Phase("first", ["s", "v"], ["a"], f, half, initial_state={"s": 0.0},
                  state_bounds={"v": (-10.0, 10.0)}, lagrange=lag, intervals=intervals)
    second = Phase("second", ["s", "v"], ["a"], f, half,
                   state_bounds={"v": (-10.0, 10.0)}, lagrange=lag, intervals=intervals)
    return Problem(
        [first, second],
        parameters=[Parameter("D", 1.0, 1.0), Parameter("vbar", 0.2, 10.0, guess=1.0)],
        linkages=[Linkage("first", "second"), ControlLinkage("first", "second"),
                  Linkage("second", "first", states=["v"], name="cyclic v"),
                  ControlLinkage("second", "first", name="cyclic a")],
        boundary_constraints=[BoundaryConstraint(
            "distance", lambda ends, p: ends["second"].xf[0] - ends["first"].x0[0] - p[0])],
        cost_denominator=lambda ends, p: p[0])


# --- 6. a smooth problem for the order of accuracy ---
# min int_0^2 (x^2 + u^2) dt, x' = u, x(0) = 1, x(2) = 0. Euler-Lagrange: x'' = x, so
# x(t) = sinh(2 - t) / sinh(2), u = -cosh(2 - t) / sinh(2).
def smooth_lq(intervals: int = 8) -> Problem:
    """Linear-quadratic problem with an exponential (non-polynomial) solution."""
    ph = Phase("lq", ["x"], ["u"], lambda x, u, p, t: u[0], 2.0,
               initial_state={"x": 1.0}, final_state={"x": 0.0},
               lagrange=lambda x, u, p, t: x[0] ** 2 + u[0] ** 2, intervals=intervals)
    return Problem([ph])


def smooth_lq_state(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """The exact optimal state of :func:`smooth_lq`."""
    return np.sinh(2.0 - t) / np.sinh(2.0)


# --- 6b. a free final state, for costates ---
# min int_0^T (x^2 + u^2) / 2 dt, x' = a x + u, x(0) = x0, x(T) free. With H = L + lambda f:
# u = -lambda, lambda' = -x - a lambda, lambda(T) = 0, so z = (x, lambda) solves
# z' = A z, A = [[a, -1], [-1, -a]]: z(t) = expm(A t) z(0) with lambda(0) = -Phi_21 x0 / Phi_22,
# Phi = expm(A T) (equivalently lambda = P x with P the Riccati solution, P(T) = 0).
def free_end_lq(a: float = 0.5, x0: float = 1.0, T: float = 1.0, intervals: int = 8) -> Problem:
    """LQ problem with a free final state (costate 0 at T)."""
    ph = Phase("lq", ["x"], ["u"], lambda x, u, p, t: a * x[0] + u[0], T,
               initial_state={"x": x0},
               lagrange=lambda x, u, p, t: (x[0] ** 2 + u[0] ** 2) / 2, intervals=intervals)
    return Problem([ph])


def free_end_lq_solution(t: NDArray[np.float64], a: float = 0.5, x0: float = 1.0,
                         T: float = 1.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(x, lambda)`` (M,) each, the exact optimum of :func:`free_end_lq` at times ``t``."""
    A = np.array([[a, -1.0], [-1.0, -a]])
    phi = expm(A * T)
    z0 = np.array([x0, -phi[1, 0] * x0 / phi[1, 1]])
    z = np.stack([expm(A * tk) @ z0 for tk in np.atleast_1d(t)])
    return z[:, 0], z[:, 1]


# --- 7. a boundary layer for error estimates and mesh refinement ---
# min int_0^1 (x^2 + eps^2 u^2) dt, x' = -x + u, x(0) = 1, x(1) free: x decays like
# exp(-t sqrt(1 + 1/eps^2)), steep near t = 0, so the largest errors are in the first intervals.
def boundary_layer(eps: float = 0.05, intervals: int = 10) -> Problem:
    """A problem whose solution is steep at the start."""
    ph = Phase("layer", ["x"], ["u"], lambda x, u, p, t: -x[0] + u[0], 1.0,
               initial_state={"x": 1.0},
               lagrange=lambda x, u, p, t: x[0] ** 2 + eps**2 * u[0] ** 2,
               intervals=intervals)
    return Problem([ph])


# --- 8. an infeasible problem ---
# |a| <= 1 for one second from rest cannot reach s = 10 (at most 0.25 with v(1) = 0... and at
# most 0.5 with v free).
def infeasible() -> Problem:
    """Reach s = 10 in 1 s with |a| <= 1 (impossible)."""
    ph = Phase("move", ["s", "v"], ["a"], double_integrator_dynamics, 1.0,
               control_bounds={"a": (-1.0, 1.0)}, initial_state={"s": 0.0, "v": 0.0},
               final_state={"s": 10.0}, lagrange=energy, intervals=10)
    return Problem([ph])


# --- 9. an active path constraint ---
# The rest-to-rest double integrator peaks at v = 1.5; capping v <= 1.2 makes the cap active.
def with_path_constraint(intervals: int = 20, limit: float = 1.2) -> Problem:
    """Rest-to-rest double integrator with the path constraint v <= limit (active)."""
    ph = Phase("move", ["s", "v"], ["a"], double_integrator_dynamics, 1.0,
               initial_state={"s": 0.0, "v": 0.0}, final_state={"s": 1.0, "v": 0.0},
               lagrange=energy, intervals=intervals,
               path_constraints=[PathConstraint("speed", lambda x, u, p, t: x[1],
                                                lower=-math.inf, upper=limit)])
    return Problem([ph])


# --- 10. an active state bound (a box bound, at the knots) ---
def with_state_bound(intervals: int = 10, limit: float = 1.2) -> Problem:
    """Rest-to-rest double integrator with the state bound v <= limit (active)."""
    ph = Phase("move", ["s", "v"], ["a"], double_integrator_dynamics, 1.0,
               initial_state={"s": 0.0, "v": 0.0}, final_state={"s": 1.0, "v": 0.0},
               state_bounds={"v": (-math.inf, limit)}, lagrange=energy, intervals=intervals)
    return Problem([ph])
