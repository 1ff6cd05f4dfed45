"""Full coordinates: the first pinned point of a phase places the base at the knots after the
first (``full_problem(..., place_base=True)``, the default) instead of stating its held-point
rows. Checked against the statement with the rows: at any point the two NLPs have the same
objective and constraints, the placed point's rows vanish, and the cold solves reach the
same optimum."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gaitopt.dynamics.kinematics import contact_position, contact_velocity
from gaitopt.gait.formulations.full import problem as full
from gaitopt.gait.formulations.select import contact_sequence
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve import transcriptions
from gaitopt.gait.solve.staged import solve_walking
from gaitopt.ocp import transcribe
from gaitopt.robot import load_model
from gaitopt.robot.model import RobotModel

SEPARATED = "hermite-simpson-separated"


@pytest.fixture(scope="module")
def model() -> RobotModel:
    return load_model("five-link")


def test_the_stance_tip_places_the_base_in_both_phases_of_the_walk(model: RobotModel) -> None:
    seq = contact_sequence(model, GaitOptions(formulation="full"))
    assert [full.base_point(model, ph.held) for ph in seq.phases] == ["tip_1", "tip_1"]
    assert full.base_point(model, ("tip_1:y",)) is None   # held along the normal only
    assert full.base_point(model, ()) is None


def test_both_statements_have_the_same_nlp_at_any_point(model: RobotModel) -> None:
    options = GaitOptions(formulation="full", knots=(4, 3))
    seq = contact_sequence(model, options)
    placed = transcribe(full.full_problem(model, options, seq), method=SEPARATED,
                        build_solver=False)
    stated = transcribe(full.full_problem(model, options, seq, place_base=False),
                        method=SEPARATED, build_solver=False)
    assert placed.layout.signature() == stated.layout.signature()
    # 4 values per knot after the first: 3 + 2 knots.
    assert placed.nlp.dependent.size == 4 * (3 + 2)
    assert stated.nlp.lbg.size - placed.nlp.lbg.size == 4 * (4 + 3)
    rng = np.random.default_rng(1)
    w = placed.initial_guess() * (1 + 0.05 * rng.standard_normal(placed.layout.size))
    w[placed.nlp.dependent] = np.asarray(placed.nlp.knot_states(w)).ravel()
    g_p, num_p, den_p, _ = (np.asarray(v).ravel() for v in placed.nlp.evaluate(w))
    g_s, num_s, den_s, _ = (np.asarray(v).ravel() for v in stated.nlp.evaluate(w))
    assert num_p == pytest.approx(num_s, rel=1e-13) and den_p == pytest.approx(den_s)
    blocks_s = {b.name: b for b in stated.nlp.constraints.blocks}
    compared = 0
    for b in placed.nlp.constraints.blocks:
        s = blocks_s[b.name]
        if b.shape == s.shape:
            assert np.allclose(g_p[b.rows], g_s[s.rows], rtol=1e-12, atol=1e-12), b.name
            compared += b.rows.stop - b.rows.start
    assert compared > 0.8 * g_p.size
    # The placed point stands at its ground point, at rest, at every knot after the first.
    nq = model.nq
    for ph, pl in zip(placed.problem.phases, placed.layout.phases, strict=True):
        x = w[pl.state_indices()].reshape(pl.knots, -1)
        ground = seq.ground_x("tip_1", w[placed.layout.parameter("step_length")])
        for k in range(1, pl.knots):
            pos = np.asarray(contact_position(model, x[k, :nq], "tip_1"), float).ravel()
            vel = np.asarray(contact_velocity(model, x[k, :nq], x[k, nq:], "tip_1"),
                             float).ravel()
            assert np.allclose(pos, [ground, 0.0], atol=1e-12), (ph.name, k)
            assert np.allclose(vel, 0.0, atol=1e-12), (ph.name, k)


@pytest.mark.slow
@pytest.mark.parametrize("ankle", [True, False], ids=["ankle+impulse", "plain"])
def test_cold_solves_reach_the_same_optimum(model: RobotModel, ankle: bool, tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    options = GaitOptions(formulation="full", knots=(8, 5), speed=0.4, ankle=ankle,
                          impulse=ankle)
    placed = solve_walking(model, options)
    # The same solve with the held-point rows stated (new transcriptions, not the cached).
    monkeypatch.setattr(transcriptions, "_CACHE", {})
    monkeypatch.setattr(transcriptions, "functions_file",
                        lambda key: tmp_path / f"{abs(hash(key))}.pickle")
    original = full.full_problem
    monkeypatch.setattr(full, "full_problem",
                        lambda m, o, s: original(m, o, s, place_base=False))
    stated = solve_walking(model, options)
    assert placed.success and stated.success
    assert (placed.result.nlp_size.equality_constraints
            < stated.result.nlp_size.equality_constraints)
    assert placed.result.objective == pytest.approx(stated.result.objective, rel=1e-5)
