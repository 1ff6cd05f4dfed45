"""Bad statements give clear errors; failing solves return a Result, never raise."""

from __future__ import annotations

import math
from dataclasses import replace

import casadi as ca
import problems as P
import pytest

from gaitopt.ocp import (
    BoundaryConstraint,
    ControlLinkage,
    Duration,
    Linkage,
    PathConstraint,
    Phase,
    Problem,
    ProblemError,
    transcribe,
)


def base_phase(**changes: object) -> Phase:
    ph = P.double_integrator(4).phases[0]
    return replace(ph, **changes)  # type: ignore[arg-type]


@pytest.mark.parametrize(("phase_changes", "message"), [
    ({"dynamics": lambda x, u, p, t: x[1]}, r"phase 'move' dynamics: returned 1 values.*2 states"),
    ({"state_bounds": {"v": (1.0, -1.0)}}, r"phase 'move' state_bounds 'v'.*lower bound 1.0 > "),
    ({"state_bounds": {"w": (0.0, 1.0)}}, r"phase 'move' state_bounds: unknown name 'w'"),
    ({"final_control": {"a": (2.0, 1.0)}}, r"phase 'move' final_control 'a'"),
    ({"states": ["s", "s"]}, r"phase 'move' states: duplicate name 's'"),
    ({"duration": -1.0}, r"phase 'move' duration"),
    ({"duration": (2.0, 1.0)}, r"phase 'move' duration.*lower bound 2.0 > upper"),
    ({"intervals": 0}, r"phase 'move': intervals must be >= 1"),
    ({"dynamics": lambda x, u, p, t: 1 / 0}, r"phase 'move' dynamics raised ZeroDivisionError"),
    ({"dynamics": lambda x, u, p, t: ca.MX.sym("q", 2)}, r"phase 'move' dynamics.*MX"),
    ({"lagrange": lambda x, u, p, t: ca.vertcat(u[0], u[0])}, r"lagrange: must return a scalar"),
    ({"path_constraints": [PathConstraint("c", lambda x, u, p, t: x, lower=[0, 0, 0])]},
     r"path constraint 'c' lower: expected 1 or 2 values, got 3"),
    ({"path_constraints": [PathConstraint("c", lambda x, u, p, t: x[0], lower=1, upper=0)]},
     r"path constraint 'c': lower bound > upper bound"),
    ({"path_constraints": [PathConstraint("c", lambda x, u, p, t: x[0], at="middle")]},  # type: ignore[arg-type]
     r"path constraint 'c': at must be"),
])
def test_bad_phase_statement(phase_changes: dict[str, object], message: str) -> None:
    with pytest.raises(ProblemError, match=message):
        transcribe(Problem([base_phase(**phase_changes)]))


def test_linkage_to_missing_phase() -> None:
    prob = Problem([base_phase()], linkages=[Linkage("move", "stance")])
    with pytest.raises(ProblemError, match=r"linkage move->stance: to_phase 'stance' is not a"):
        transcribe(prob)


def test_linkage_errors_name_the_linkage() -> None:
    a = base_phase(name="a")
    b = base_phase(name="b", states=["s", "w"], initial_state={}, final_state={"s": 1.0})
    with pytest.raises(ProblemError, match=r"linkage a->b: continuity of state 'w'"):
        transcribe(Problem([a, b], linkages=[Linkage("a", "b")]))
    bad_jump = Linkage("a", "b", jump=lambda xf, uf, p: xf[0], name="impact")
    with pytest.raises(ProblemError, match=r"impact: returned 1 values but links 2 states"):
        transcribe(Problem([a, b], linkages=[bad_jump]))
    with pytest.raises(ProblemError, match=r"control linkage a->b: control 'z' is not"):
        transcribe(Problem([a, b], linkages=[ControlLinkage("a", "b", controls=["z"])]))


def test_other_statement_errors() -> None:
    ph = base_phase()
    with pytest.raises(ProblemError, match=r"problem phases: duplicate name 'move'"):
        transcribe(Problem([ph, ph]))
    with pytest.raises(ProblemError, match=r"method must be one of"):
        transcribe(Problem([ph]), method="euler")
    with pytest.raises(ProblemError, match=r"intervals: 'walk' is not a phase"):
        transcribe(Problem([ph]), intervals={"walk": 3})
    with pytest.raises(ProblemError, match=r"boundary constraint 'b' raised KeyError"):
        transcribe(Problem([ph], boundary_constraints=[
            BoundaryConstraint("b", lambda ends, p: ends["nowhere"].tf)]))
    with pytest.raises(ProblemError, match=r"phase 'move' duration raised"):
        transcribe(Problem([replace(ph, duration=Duration.of_parameters(lambda p: p[3]))]))


def test_solve_argument_errors() -> None:
    tr = transcribe(P.periodic_ratio())
    with pytest.raises(ProblemError, match=r"no parameter 'speed'"):
        tr.solve(parameters={"speed": 1.0})
    with pytest.raises(ProblemError, match=r"parameter 'vbar': lower bound 2.0 > upper"):
        tr.solve(parameters={"vbar": (2.0, 1.0)})


def test_infeasible_problem_reports_infeasibility() -> None:
    res = transcribe(P.infeasible()).solve()
    assert not res.success
    assert res.infeasible and res.status == "Infeasible_Problem_Detected"
    assert res.constraint_violation > 0.1


def test_invalid_numbers_and_bad_options_return_a_result() -> None:
    ph = base_phase(dynamics=lambda x, u, p, t: ca.vertcat(x[1], ca.log(x[0] - 5.0) + u[0]))
    res = transcribe(Problem([ph])).solve()
    assert not res.success and res.status != "Solve_Succeeded"
    tr = transcribe(P.double_integrator(4))
    bad = tr.solve(options={"ipopt.no_such_option": 1})
    assert not bad.success and bad.status == "Solver_Exception" and bad.message
    limited = tr.solve(options={"ipopt.max_iter": 0})
    assert limited.status == "Maximum_Iterations_Exceeded" and not limited.success
    assert math.isfinite(limited.objective)
