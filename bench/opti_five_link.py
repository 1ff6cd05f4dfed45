"""A plain CasADi ``Opti`` script: one periodic step of a five-link biped, written directly with
CasADi (no gaitopt import), as a reader of Kelly's tutorial would write it.

The problem (Kelly 2017, "An introduction to trajectory optimization: how to do your own direct
collocation", SIAM Review 59(4), section 7: the five-link biped) on the five-link model that
gaitopt ships (``five-link``: Hardt, Kreutz-Delgado and Helton's parameters, torso 20 kg
0.72 m, thighs 7 kg 0.5 m, shanks 4 kg 0.5 m, uniform ellipsoids):

* single support only, on tip 1 pinned at the origin, for the step time ``T = L / v``; then a
  plastic impact of tip 2 at ``(L, 0)`` (tip 1 leaves the ground) and the legs relabelled;
* periodic: the state after the impact is the state at the start;
* the step length ``L = 0.5`` m and the step time ``T = 0.7`` s fixed (Kelly's figures);
* cost ``J = int_0^T u'u dt / L`` (N^2 m s): torque squared, per metre (``L`` is fixed, so this
  is Kelly's torque-squared cost divided by a constant);
* torques at both hips and knees and at the stance ankle (between the ground and the stance
  shank): ``|u| <= 50`` N m, ``|u_ankle| <= 25`` N m.

The constraints are gaitopt's for this step (``gaitopt solve --single-support 1``), stated in
the same coordinates (the paper's reduced coordinates) so that both NLPs discretise the same
functions: ``z = [r, alpha, torso, hip_2, knee_2]``, the hip's polar coordinates about the
stance tip (``p_hip = r (-sin alpha, cos alpha)``; ``r`` the hip-to-tip distance in m,
``alpha`` the hip-to-tip line's angle from straight down, CCW positive), the torso angle and
the swing leg's joint angles (rad); the state ``x = [z, zd]`` (10), the controls
``u = [hip_1, knee_1, ankle_1, hip_2, knee_2]`` (N m):

* boxes: ``r`` within the stance leg's reach with the knee bent by 0.1 to 2.5 rad,
  ``|alpha| <= 1.3``, ``|torso| <= 0.8``, swing hip in ``[-2, 2]``, swing knee in
  ``[-2.5, 0]`` (rad), every rate within 15 rad/s (``r_rate`` 15 m/s), on knots and midpoints;
* path (knots and midpoints): the ground's normal force on the stance tip ``>= 0``, the swing
  tip's height ``>= 0``, the stance hip in ``[-2, 2]`` rad;
* at the impact: tip 2 at ``(L, 0)``, its normal impulse ``>= 0``, tip 1's vertical velocity
  after the impact ``>= 0``.

Transcription: separated Hermite-Simpson on 40 uniform knots (39 intervals; the midpoint states
are variables, the midpoint controls the knot controls' average, Simpson quadrature of the
cost); exact Hessian; IPOPT with MUMPS. First guess: the stance leg swinging linearly from
``alpha = +a0`` to ``-a0`` (the tip half a step ahead of the hip, then behind), the swing leg
its mirror image, zero torques.

Dynamics by Lagrange's equations in ``z``: link angles and centres of mass are explicit
functions of ``z`` (the stance knee from the law of cosines, bent backwards), ``M(z) zdd +
c(z, zd) + g(z) = B(z)' u`` with ``B = d(joint angles)/dz``; the impact in the seven
coordinates ``[x_tip1, y_tip1, five absolute link angles]``.

Run alone: ``python bench/opti_five_link.py`` prints the cost, IPOPT's status and the times;
``bench/opti_side_by_side.py`` runs it beside gaitopt.
"""

from __future__ import annotations

import json
import math
import sys
import time
from typing import Any

# -- the model (gaitopt's five-link.yaml) ------------------------------------------------------
G = 9.81
THIGH, SHANK, TORSO = 0.5, 0.5, 0.72                     # lengths (m)
M_TORSO, M_THIGH, M_SHANK = 20.0, 7.0, 4.0               # masses (kg)
C_TORSO, C_THIGH, C_SHANK = 0.36, 0.25, 0.25             # centres of mass from the proximal joint
# uniform ellipsoids: I = m (a^2 + b^2) / 5 with a = length / 2, b the radius
I_TORSO = M_TORSO * (0.36 ** 2 + 0.12 ** 2) / 5
I_THIGH = M_THIGH * (0.25 ** 2 + 0.07 ** 2) / 5
I_SHANK = M_SHANK * (0.25 ** 2 + 0.05 ** 2) / 5
U_MAX = [50.0, 50.0, 25.0, 50.0, 50.0]                   # hip_1, knee_1, ankle_1, hip_2, knee_2

# -- the problem ------------------------------------------------------------------------------
STEP_LENGTH = 0.5        # m
STEP_TIME = 0.7          # s
KNOTS = 40
MIN_KNEE_FLEXION = 0.1   # rad, the stance knee's least bend
KNEE_RANGE = (-2.5, 0.0)
HIP_RANGE = (-2.0, 2.0)
ALPHA_BOUND, TORSO_BOUND, RATE_BOUND = 1.3, 0.8, 15.0
#: Opti's options (command line): ``--expand`` expands the MX graph into SX before the solve;
#: ``--explicit`` solves ``M zdd = B'u - c - g`` symbolically (a 5 x 5 solve in SX) instead
#: of the default implicit form (``zdd`` variables at every knot and midpoint, the equations of
#: motion as equality constraints, Kelly's advice for multibody models).
EXPAND = "--expand" in sys.argv
IMPLICIT = "--explicit" not in sys.argv


def reach(knee: float) -> float:
    """Hip-to-tip distance (m) of a leg with the knee at ``knee`` (rad)."""
    return math.sqrt(THIGH ** 2 + SHANK ** 2 + 2 * THIGH * SHANK * math.cos(knee))


def build_model(ca: Any) -> dict[str, Any]:
    """The CasADi functions of the step: ``f(x, u) -> [xdot, path]`` (path = [normal force,
    swing tip height, stance hip angle]), ``impact(x) -> [x_next, tip 2 (x, y), normal
    impulse, tip 1 vertical velocity]``."""
    def down(phi: Any) -> Any:          # unit vector of a leg link at absolute angle phi
        return ca.vertcat(ca.sin(phi), -ca.cos(phi))

    def up(phi: Any) -> Any:            # the torso's
        return ca.vertcat(-ca.sin(phi), ca.cos(phi))

    z = ca.SX.sym("z", 5)
    zd = ca.SX.sym("zd", 5)
    u = ca.SX.sym("u", 5)
    r, alpha, torso, hip2, knee2 = (z[i] for i in range(5))
    # the stance leg by the law of cosines, the knee bent backwards (knee_1 <= 0)
    knee1 = -ca.acos((r ** 2 - THIGH ** 2 - SHANK ** 2) / (2 * THIGH * SHANK))
    thigh1 = alpha + ca.atan2(-SHANK * ca.sin(knee1), THIGH + SHANK * ca.cos(knee1))
    shank1 = thigh1 + knee1
    thigh2 = torso + hip2
    shank2 = thigh2 + knee2
    hip = r * up(alpha)
    knee_1 = hip + THIGH * down(thigh1)
    knee_2 = hip + THIGH * down(thigh2)
    bodies = [  # (mass, inertia, centre of mass, angle)
        (M_SHANK, I_SHANK, knee_1 + C_SHANK * down(shank1), shank1),
        (M_THIGH, I_THIGH, hip + C_THIGH * down(thigh1), thigh1),
        (M_TORSO, I_TORSO, hip + C_TORSO * up(torso), torso),
        (M_THIGH, I_THIGH, hip + C_THIGH * down(thigh2), thigh2),
        (M_SHANK, I_SHANK, knee_2 + C_SHANK * down(shank2), shank2)]
    kinetic, potential = 0, 0
    for m, inertia, p, phi in bodies:
        v = ca.jtimes(p, z, zd)
        w = ca.jtimes(phi, z, zd)
        kinetic += 0.5 * m * ca.dot(v, v) + 0.5 * inertia * w ** 2
        potential += m * G * p[1]
    dT_dzd = ca.gradient(kinetic, zd)
    mass = ca.jacobian(dT_dzd, zd)
    bias = ca.jtimes(dT_dzd, z, zd) - ca.gradient(kinetic, z) + ca.gradient(potential, z)
    joints = ca.vertcat(thigh1 - torso, knee1, shank1, hip2, knee2)   # the actuated angles
    generalized = ca.mtimes(ca.jacobian(joints, z).T, u)
    a = ca.SX.sym("a", 5)      # the accelerations zdd, as variables (implicit dynamics)
    zdd = a if IMPLICIT else ca.solve(mass, generalized - bias)
    # the ground's force on the stance tip: sum of m a minus the weight
    acc = 0
    for m, _, p, _ in bodies:
        acc += m * (ca.jtimes(p, z, zdd) + ca.jtimes(ca.jtimes(p, z, zd), z, zd))
    normal_force = acc[1] + (M_TORSO + 2 * M_THIGH + 2 * M_SHANK) * G
    tip2 = knee_2 + SHANK * down(shank2)
    x = ca.vertcat(z, zd)
    path = ca.vertcat(normal_force, tip2[1], thigh1 - torso)
    if IMPLICIT:  # f(x, u, a) -> [xdot, path, the equations of motion' residual]
        f = ca.Function("f", [x, u, a], [ca.vertcat(zd, a), path,
                                         ca.mtimes(mass, a) + bias - generalized])
    else:         # f(x, u) -> [xdot, path]
        f = ca.Function("f", [x, u], [ca.vertcat(zd, zdd), path])

    # the impact in q = [x_tip1, y_tip1, shank1, thigh1, torso, thigh2, shank2]
    q = ca.SX.sym("q", 7)
    tip1_e = q[0:2]
    knee1_e = tip1_e - SHANK * down(q[2])
    hip_e = knee1_e - THIGH * down(q[3])
    knee2_e = hip_e + THIGH * down(q[5])
    tip2_e = knee2_e + SHANK * down(q[6])
    bodies_e = [(M_SHANK, I_SHANK, knee1_e + C_SHANK * down(q[2]), 2),
                (M_THIGH, I_THIGH, hip_e + C_THIGH * down(q[3]), 3),
                (M_TORSO, I_TORSO, hip_e + C_TORSO * up(q[4]), 4),
                (M_THIGH, I_THIGH, hip_e + C_THIGH * down(q[5]), 5),
                (M_SHANK, I_SHANK, knee2_e + C_SHANK * down(q[6]), 6)]
    mass_e = ca.SX.zeros(7, 7)
    for m, inertia, p, i in bodies_e:
        jac = ca.jacobian(p, q)
        mass_e += m * ca.mtimes(jac.T, jac)
        mass_e[i, i] += inertia
    jac2 = ca.jacobian(tip2_e, q)
    angles = ca.vertcat(shank1, thigh1, torso, thigh2, shank2)
    q_before = ca.vertcat(0, 0, angles)
    qd_before = ca.vertcat(0, 0, ca.jtimes(angles, z, zd))
    kkt = ca.blockcat([[mass_e, -jac2.T], [jac2, ca.SX.zeros(2, 2)]])
    sol = ca.solve(kkt, ca.vertcat(ca.mtimes(mass_e, qd_before), 0, 0))
    sol = ca.substitute(sol, q, q_before)
    qd_after, impulse = sol[0:7], sol[7:9]
    # relabelled: leg 2 stands (its tip at p_tip2), leg 1 swings
    p_hip = ca.substitute(hip_e, q, q_before)
    p_tip2 = ca.substitute(tip2_e, q, q_before)
    v_hip = ca.substitute(ca.jtimes(hip_e, q, qd_after), q, q_before)
    d = p_hip - p_tip2
    r_next = ca.norm_2(d)
    x_next = ca.vertcat(
        r_next, ca.atan2(-d[0], d[1]), torso, thigh1 - torso, shank1 - thigh1,
        (d[0] * v_hip[0] + d[1] * v_hip[1]) / r_next,
        (-d[1] * v_hip[0] + d[0] * v_hip[1]) / r_next ** 2,
        qd_after[4], qd_after[3] - qd_after[4], qd_after[2] - qd_after[3])
    impact = ca.Function("impact", [x], [x_next, p_tip2, impulse[1], qd_after[1]])
    return {"f": f, "impact": impact}


def first_guess(knots: int) -> tuple[list[list[float]], list[list[float]]]:
    """States (10 x knots) and midpoint states (10 x knots-1): the stance leg at the reach of
    a 0.3 rad knee bend, ``alpha`` from ``+a0`` to ``-a0`` with ``r sin a0 = L / 2``, the torso
    upright, the swing leg the stance leg's mirror image; rates of that motion."""
    r0 = reach(-0.3)
    a0 = math.asin(STEP_LENGTH / 2 / r0)
    beta = math.atan2(SHANK * math.sin(0.3), THIGH + SHANK * math.cos(0.3))

    def state(s: float) -> list[float]:
        alpha = a0 * (1 - 2 * s)
        rate = -2 * a0 / STEP_TIME
        return [r0, alpha, 0.0, -alpha + beta, -0.3, 0.0, rate, 0.0, -rate, 0.0]

    xs = [state(k / (knots - 1)) for k in range(knots)]
    xm = [state((k + 0.5) / (knots - 1)) for k in range(knots - 1)]
    return xs, xm


def solve(knots: int = KNOTS, verbose: bool = False) -> dict[str, Any]:
    """Build and solve the NLP; return the cost, IPOPT's status, iterations and times (s: wall
    times of the import of CasADi, the build and the solve; ``cpu_s`` the CPU time of the
    build and the solve)."""
    start = time.perf_counter()
    import casadi as ca

    imported, cpu = time.perf_counter(), time.process_time()
    model = build_model(ca)
    f, impact = model["f"], model["impact"]
    opti = ca.Opti()
    n, m, intervals = 10, 5, knots - 1
    h = STEP_TIME / intervals
    X = opti.variable(n, knots)
    XM = opti.variable(n, intervals)
    U = opti.variable(m, knots)

    UM = (U[:, :-1] + U[:, 1:]) / 2                  # midpoint controls: the knots' average
    points = knots + intervals                       # every knot, then every midpoint
    P, PU = ca.horzcat(X, XM), ca.horzcat(U, UM)
    F = f.map(points)                                # one call of f over all the points
    if IMPLICIT:
        A = opti.variable(5, points)                 # zdd at every point
        xdot, path, residual = F(P, PU, A)
        opti.subject_to(ca.vec(residual) == 0)
    else:
        xdot, path = F(P, PU)
    fk, fm = xdot[:, :knots], xdot[:, knots:]

    # the boxes on the states, at the knots and the midpoints
    lower = [reach(KNEE_RANGE[0]), -ALPHA_BOUND, -TORSO_BOUND, HIP_RANGE[0], KNEE_RANGE[0]] \
        + [-RATE_BOUND] * 5
    upper = [reach(-MIN_KNEE_FLEXION), ALPHA_BOUND, TORSO_BOUND, HIP_RANGE[1], KNEE_RANGE[1]] \
        + [RATE_BOUND] * 5
    opti.subject_to(opti.bounded(ca.repmat(ca.DM(lower), 1, points), P,
                                 ca.repmat(ca.DM(upper), 1, points)))
    opti.subject_to(opti.bounded(ca.repmat(-ca.DM(U_MAX), 1, knots), U,
                                 ca.repmat(ca.DM(U_MAX), 1, knots)))
    # path: normal force >= 0, swing tip height >= 0, stance hip within its range
    opti.subject_to(ca.vec(path[0:2, :]) >= 0)
    opti.subject_to(opti.bounded(HIP_RANGE[0], path[2, :], HIP_RANGE[1]))
    # separated Hermite-Simpson: midpoint and Simpson defects
    opti.subject_to(XM - (X[:, :-1] + X[:, 1:]) / 2 - h * (fk[:, :-1] - fk[:, 1:]) / 8 == 0)
    opti.subject_to(X[:, 1:] == X[:, :-1] + h * (fk[:, :-1] + 4 * fm + fk[:, 1:]) / 6)
    cost = h * (ca.sumsqr(U[:, :-1]) + 4 * ca.sumsqr(UM) + ca.sumsqr(U[:, 1:])) / 6
    x_next, tip2, impulse, tip1_up = impact(X[:, -1])
    opti.subject_to(X[:, 0] == x_next)
    opti.subject_to(tip2 == ca.vertcat(STEP_LENGTH, 0))
    opti.subject_to(impulse >= 0)
    opti.subject_to(tip1_up >= 0)
    opti.minimize(cost / STEP_LENGTH)

    xs, xm = first_guess(knots)
    opti.set_initial(X, ca.DM(xs).T)
    opti.set_initial(XM, ca.DM(xm).T)
    if IMPLICIT:
        opti.set_initial(A, 0)
    opti.set_initial(U, 0)
    opti.solver("ipopt", {"print_time": False, "expand": EXPAND},
                {"linear_solver": "mumps", "tol": 1e-8, "max_iter": 3000,
                 "print_level": 5 if verbose else 0, "sb": "yes"})
    built = time.perf_counter()
    try:
        sol = opti.solve()
        stats = sol.stats()
        value = float(sol.value(opti.f))
    except RuntimeError:
        stats = opti.stats()
        value = float(opti.debug.value(opti.f))
    done = time.perf_counter()
    return {"cost": value, "status": stats["return_status"], "success": stats["success"],
            "iterations": stats["iter_count"], "import_s": imported - start,
            "build_s": built - imported, "solve_s": done - built, "total_s": done - start,
            "cpu_s": time.process_time() - cpu,
            "variables": int(opti.nx), "constraints": int(opti.ng),
            "calls": {k[len("n_call_"):]: v for k, v in stats.items() if k.startswith("n_call_")},
            "function_times_s": {k[len("t_wall_"):]: round(v, 4) for k, v in stats.items()
                                 if k.startswith("t_wall_") and v > 0}}


if __name__ == "__main__":
    print(json.dumps(solve(verbose="-v" in sys.argv[1:]), indent=1))
