"""The same code evaluated on CasADi SX/MX symbols gives the numeric results; derivatives of
the CasADi Functions agree with finite differences; compiled Functions equal uncompiled."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np
import pytest
from dynamics_helpers import assert_close, random_state

import gaitopt.dynamics as dyn
from gaitopt.dynamics import functions
from gaitopt.robot import RobotModel


def _api_calls(model: RobotModel) -> dict[str, Callable[..., Any]]:
    """Every public function as f(q, qd, w) -> list of outputs (w: a third nq vector)."""
    c = [cc.name for cc in model.contacts]
    link = len(model.links) - 1
    p = (0.3, -0.05)
    return {
        "point_position": lambda q, qd, w: [dyn.point_position(model, q, link, p)],
        "point_velocity": lambda q, qd, w: [dyn.point_velocity(model, q, qd, link, p)],
        "point_acceleration": lambda q, qd, w: [dyn.point_acceleration(model, q, qd, w, link,
                                                                       p)],
        "point_jacobian": lambda q, qd, w: [dyn.point_jacobian(model, q, link, p)],
        "contact_jacobian": lambda q, qd, w: [dyn.contact_jacobian(model, q, c)],
        "link_angles": lambda q, qd, w: [dyn.link_angles(model, q)],
        "rnea": lambda q, qd, w: [dyn.rnea(model, q, qd, w, tau_ext=w)],
        "crba": lambda q, qd, w: [dyn.crba(model, q)],
        "aba": lambda q, qd, w: [dyn.aba(model, q, qd, w)],
        "contact_dynamics": lambda q, qd, w: list(
            vars(dyn.contact_dynamics(model, q, qd, w, c[:2])).values()),
        "impact": lambda q, qd, w: list(vars(dyn.impact(model, q, qd, c[:1])).values()),
        "liftoff": lambda q, qd, w: list(
            vars(dyn.liftoff_impulse(model, q, qd, c[0], 3.0, c[1:2])).values()),
        "energy": lambda q, qd, w: [dyn.total_energy(model, q, qd),
                                    dyn.angular_momentum(model, q, qd, (0.2, 0.1)),
                                    dyn.center_of_mass(model, q)],
    }


@pytest.mark.parametrize("sym", [ca.SX, ca.MX])
def test_symbolic_equals_numeric(model: RobotModel, sym: Any) -> None:
    rng = np.random.default_rng(50)
    q_s, qd_s, w_s = (sym.sym(n, model.nq) for n in ("q", "qd", "w"))
    calls = _api_calls(model)
    u_s = sym.sym("u", model.nu)
    held = [model.contacts[0].name]
    for name, call in calls.items():
        f = ca.Function(name, [q_s, qd_s, w_s, u_s], call(q_s, qd_s, w_s))
        for _ in range(3):
            q, qd, w = random_state(rng, model.nq)
            u = rng.normal(size=model.nu)
            for got, want in zip(f.call([q, qd, w, u]), call(q, qd, w), strict=True):
                assert_close(np.asarray(got.full()).reshape(np.shape(want)), want, rtol=1e-12,
                             what=f"{name} ({sym.__name__})")
    g = ca.Function("g", [q_s, u_s], [dyn.generalized_forces(model, q_s, u_s, held)])
    q, _, _ = random_state(rng, model.nq)
    u = rng.normal(size=model.nu)
    assert_close(g(q, u).full().ravel(), dyn.generalized_forces(model, q, u, held))


def _finite_difference_check(f: ca.Function, args: list[np.ndarray], rtol: float) -> None:
    jac = f.jacobian()
    values = jac.call([*args, *f.call(args)])
    h = 1e-6
    n_out = f.n_out()
    for i, arg in enumerate(args):
        for o in range(n_out):
            analytic = np.asarray(values[o * len(args) + i].full())
            fd = np.zeros_like(analytic)
            for k in range(arg.size):
                plus, minus = [a.copy() for a in args], [a.copy() for a in args]
                plus[i].flat[k] += h
                minus[i].flat[k] -= h
                diff = (np.asarray(f.call(plus)[o].full()) - np.asarray(f.call(minus)[o].full()))
                fd[:, k] = diff.reshape(-1, order="F") / (2 * h)
            assert_close(analytic, fd, rtol=rtol,
                         what=f"{f.name()} d{f.name_out(o)}/d{f.name_in(i)}")


def test_derivatives_match_finite_differences(five_link: RobotModel) -> None:
    model = five_link
    rng = np.random.default_rng(51)
    q = np.array([0.05, 0.92, 0.1, 0.35, -0.3, -0.25, -0.1])
    qd = rng.normal(size=model.nq)
    u = 20.0 * rng.normal(size=model.nu)
    _finite_difference_check(functions.forward_dynamics_function(model, inputs="u"),
                             [q, qd, u], 1e-6)
    _finite_difference_check(functions.contact_dynamics_function(model, ["tip_1", "tip_2"],
                                                                 inputs="u"),
                             [q, qd, u], 1e-6)
    _finite_difference_check(functions.impact_function(model, ["tip_2", "tip_1"]), [q, qd],
                             1e-6)
    _finite_difference_check(functions.liftoff_function(model, "tip_1", ["tip_2"]),
                             [q, qd, np.array([4.0])], 1e-6)


def test_functions_equal_direct_calls(five_link: RobotModel) -> None:
    model = five_link
    rng = np.random.default_rng(52)
    q, qd, _ = random_state(rng, model.nq)
    u = rng.normal(size=model.nu)
    tau = dyn.generalized_forces(model, q, u, ["tip_1"])
    f = functions.contact_dynamics_function(model, ["tip_1"], inputs="u")
    out = f(q=q, qd=qd, u=u)
    ref = dyn.contact_dynamics(model, q, qd, tau, ["tip_1"])
    assert_close(out["qdd"].full().ravel(), ref.qdd)
    assert_close(out["forces"].full().ravel(), ref.forces)
    assert f is functions.contact_dynamics_function(model, ["tip_1"], inputs="u")  # cached
    fd = functions.forward_dynamics_function(model)
    assert_close(fd(q, qd, tau).full().ravel(), dyn.aba(model, q, qd, tau))
    assert functions.forward_dynamics_function(model, inputs="u").name_in() == ["q", "qd", "u"]


def test_compiled_functions_equal_uncompiled(five_link: RobotModel, tmp_path: Any,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    functions.clear_cache()
    model = five_link
    rng = np.random.default_rng(53)
    builders: list[tuple[Callable[..., ca.Function], int]] = [
        (lambda compiled: functions.forward_dynamics_function(model, compiled=compiled), 3),
        (lambda compiled: functions.contact_dynamics_function(model, ["tip_1", "tip_2"],
                                                              compiled=compiled), 3),
        (lambda compiled: functions.impact_function(model, ["tip_2"], compiled=compiled), 2),
        (lambda compiled: functions.liftoff_function(model, "tip_2", ["tip_1"],
                                                     compiled=compiled), 3),
    ]
    try:
        for build, n_in in builders:
            plain, compiled = build(False), build(True)
            assert "External" in str(compiled) or compiled.class_name() == "External"
            for _ in range(5):
                q, qd, tau = random_state(rng, model.nq)
                args = [q, qd, tau][:n_in]
                if plain.name_in()[-1] == "magnitude":
                    args[-1] = np.array([2.5])
                for a, b in zip(plain.call(args), compiled.call(args), strict=True):
                    assert_close(b.full(), a.full(), rtol=1e-13, what=plain.name())
        assert list(tmp_path.glob("*.so"))
    finally:
        functions.clear_cache()
