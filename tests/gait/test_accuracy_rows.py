"""The summary rows ``gaitopt solve`` prints from a gait file's ``solver.accuracy`` (no solve):
the estimate says whether the cost is within 1 %, from which grids, and how far speed and step
length move, relative to the gait's values."""

from __future__ import annotations

from typing import Any

from gaitopt.cli.gait_summary import accuracy_rows

BASE: dict[str, Any] = {
    "collocation_error": {"single_support": 3.2e-4, "double_support": 2.8e-4},
    "knots": {"single_support": 16, "double_support": 6}, "mesh_tol": None,
    "mesh_converged": None, "previous_knots": {"single_support": 8, "double_support": 5},
    "previous_cost": 436.365, "speed_error": None, "step_length_error": None}


def test_a_check_grid_estimate_says_within_one_percent_and_how_far_the_optimum_moves() -> None:
    accuracy = {**BASE, "cost_error": 1.013, "cost_error_relative": 1.013 / 429.31,
                "cost_error_factor": 3.0,
                "check_knots": {"single_support": 24, "double_support": 8},
                "check_cost": 428.972, "speed_change": -0.024 / 60, "step_length_change": -1e-4,
                "speed_error": 0.072 / 60, "step_length_error": 3e-4}
    rows = dict(accuracy_rows(accuracy, speed=13.27 / 60, step_length=0.1176))
    assert rows["cost error estimate"] == (
        "+1.013 N^2 m s = 0.24 % of J: within 1 % (3 x the change to 24+8 knots, J 428.972)")
    assert rows["change to 24+8 knots"] == (
        "speed -0.024 m/min, step length -0.0001 m; estimate 3 x: speed 0.072 m/min "
        f"({100 * 0.072 / 13.27:.2f} %), step length 0.0003 m ({100 * 3e-4 / 0.1176:.2f} %)")


def test_an_estimate_above_one_percent_says_what_to_do() -> None:
    accuracy = {**BASE, "cost_error": -25.0, "cost_error_relative": 25.0 / 1955.0,
                "cost_error_factor": 3.0,
                "check_knots": {"single_support": 24, "double_support": 8},
                "check_cost": 1963.3, "speed_change": 0.0, "step_length_change": 0.0}
    text = dict(accuracy_rows(accuracy))["cost error estimate"]
    assert "= 1.28 % of J: above 1 % (a finer --knots or --mesh-tol 1e-4)" in text


def test_a_refined_mesh_gives_the_change_from_the_mesh_before_and_one_grid_none() -> None:
    refined = {**BASE, "mesh_tol": 1e-4, "mesh_converged": True, "cost_error": 0.2507,
               "cost_error_relative": 0.2507 / 431.385, "cost_error_factor": 1.0,
               "check_knots": None, "check_cost": None,
               "previous_knots": {"single_support": 24, "double_support": 8},
               "previous_cost": 431.135, "speed_change": 0.0, "step_length_change": 1e-4}
    rows = dict(accuracy_rows(refined))
    assert rows["cost error estimate"].endswith("(change from 24+8 knots, J 431.135)")
    assert rows["change from 24+8 knots"] == "speed +0.000 m/min, step length +0.0001 m"
    alone = {**BASE, "cost_error": None}
    assert dict(accuracy_rows(alone))["cost error estimate"] == (
        "n/a (one grid; solve with --mesh-tol)")


def test_a_large_smoothing_share_is_shown_above_the_accuracy() -> None:
    smoothing = {"cost_smoothing": 0.01, "unsmoothed_cost": 0.0011742, "share": 0.346}
    rows = dict(accuracy_rows({**BASE, "cost_error": None, "smoothing": smoothing}))
    assert rows["cost smoothing"] == (
        "35 % of J at eps 0.01 W (the motion's cost unsmoothed: 0.0011742); above 1 %: the "
        "smoothing, not only the motion, sets this optimum (docs/costs.md)")
    small = {**smoothing, "share": 0.0022}
    rows = dict(accuracy_rows({**BASE, "cost_error": None, "smoothing": small}))
    assert rows["cost smoothing"].startswith("0.22 % of J") and "above" not in rows[
        "cost smoothing"]
    assert "cost smoothing" not in dict(accuracy_rows({**BASE, "cost_error": None}))


def test_a_cost_of_transport_error_has_no_paper_units() -> None:
    accuracy = {**BASE, "cost_error": -1.2e-5, "cost_error_relative": 0.004,
                "cost_error_factor": 3.0,
                "check_knots": {"single_support": 24, "double_support": 8},
                "check_cost": 0.00308, "speed_change": 0.0, "step_length_change": 0.0}
    text = dict(accuracy_rows(accuracy, unit=""))["cost error estimate"]
    assert text.startswith("-1.2e-05 = 0.40 % of J") and "N^2" not in text
