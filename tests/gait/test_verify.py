"""``verify_gait`` / ``gaitopt verify``: passes on a solved gait and fails, naming the check by
its stable id, on copies with one user-read field corrupted at one knot by a small amount."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner
from numpy.typing import NDArray

from gaitopt.analysis.checks.knots import full_state_function
from gaitopt.analysis.checks.samples import points_function
from gaitopt.analysis.verify import CHECKS, VerifyReport, verify_gait
from gaitopt.cli import cli
from gaitopt.gait.formulations.reduced.physics import DOUBLE, SINGLE
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.record.file import Gait
from gaitopt.gait.record.interpolation import phase_controls_at, phase_states_at
from gaitopt.gait.record.parts import GaitSamples
from tests.gait.conftest import (
    Reference,
    SolveFn,
    contact_forces,
    eom_residuals,
    lowest_sample_normal_force,
)

Array = NDArray[np.float64]
RefFn = Callable[..., Reference]
Corruption = Callable[[dict[str, Any]], None]

KNOT = 3  # the single-support knot the corruptions touch
SAMPLE = 17  # a dense sample inside single support


def _add(row: list[float], j: int, delta: float) -> None:
    row[j] += delta


def _scale(row: list[float], j: int, factor: float) -> None:
    row[j] *= factor


# Each corruption: what it does to the file data, and the checks (by id) that must fail.
CORRUPTIONS: dict[str, tuple[Corruption, set[str]]] = {
    "torso angle + 2 mrad (q)": (
        lambda d: _add(d["phases"][0]["q"][KNOT], 2, 2e-3),
        {"eom.residual", "contacts.position", "states.values"}),
    "stance hip angle + 2 mrad (q, not a reduced state)": (
        lambda d: _add(d["phases"][0]["q"][KNOT], 3, 2e-3),
        {"eom.residual", "contacts.position"}),
    "hip_1 torque + 5 % (u)": (
        lambda d: _scale(d["phases"][0]["u"][KNOT], 0, 1.05),
        {"eom.residual", "samples.controls", "cost.recomputed"}),
    "ankle torque + 5 % in double support (u)": (
        lambda d: _scale(d["phases"][1]["u"][2], 2, 1.05),
        {"eom.residual", "samples.controls", "cost.recomputed"}),
    "normal contact force + 1 % (contact_forces)": (
        lambda d: _scale(d["phases"][1]["contact_forces"]["tip_1"][2], 1, 1.01),
        {"eom.residual"}),
    "stance knee rate + 0.01 rad/s (qd)": (
        lambda d: _add(d["phases"][0]["qd"][KNOT], 4, 0.01),
        {"eom.residual", "contacts.velocity"}),
    "torso acceleration + 0.05 rad/s^2 (qdd)": (
        lambda d: _add(d["phases"][0]["qdd"][KNOT], 2, 0.05),
        {"eom.residual", "contacts.acceleration", "states.rates"}),
    "reduced state r + 0.1 mm (x)": (
        lambda d: _add(d["phases"][0]["x"][KNOT], 0, 1e-4),
        {"states.values"}),
    "heel-strike normal impulse + 0.01 N s (event impulse)": (
        lambda d: _add(d["events"][0]["impulses"]["tip_2"], 1, 0.01),
        {"events.impulses"}),
    "liftoff impulse + 0.01 N s (event impulse)": (
        lambda d: _add(d["events"][1]["impulses"]["tip_1"], 1, 0.01),
        {"events.impulses", "parameters.consistency"}),
    "torso rate after the heel strike + 0.05 rad/s (event qd_after)": (
        lambda d: _add(d["events"][0]["qd_after"], 2, 0.05),
        {"events.maps", "events.continuity"}),
    "torso rate at the first double-support knot (qd)": (
        lambda d: _add(d["phases"][1]["qd"][0], 2, 0.05),
        {"events.continuity", "eom.residual"}),
    "torso angle of a sample + 2 mrad (samples.q)": (
        lambda d: _add(d["samples"]["q"][SAMPLE], 2, 2e-3),
        {"samples.states", "samples.points"}),
    "stance knee rate of a sample + 0.01 rad/s (samples.qd)": (
        lambda d: _add(d["samples"]["qd"][SAMPLE], 4, 0.01),
        {"samples.states"}),
    "hip_1 torque of a sample + 5 % (samples.u)": (
        lambda d: _scale(d["samples"]["u"][SAMPLE], 0, 1.05),
        {"samples.controls"}),
    "knee point of a sample + 1 mm (samples.points)": (
        lambda d: _add(d["samples"]["points"]["knee_1"][SAMPLE], 1, 1e-3),
        {"samples.points"}),
    "step length parameter + 5 %": (
        lambda d: _scale(d["parameters"], "step_length", 1.05),  # type: ignore[arg-type]
        {"contacts.position", "events.periodicity", "cost.recomputed",
         "parameters.consistency"}),
    "speed parameter + 0.1 %": (
        lambda d: _scale(d["parameters"], "speed", 1.001),  # type: ignore[arg-type]
        {"parameters.consistency"}),
}


def _corrupted_data(gait: Gait, name: str) -> dict[str, Any]:
    data = copy.deepcopy(gait.to_dict())
    CORRUPTIONS[name][0](data)
    return data


def _failed(report: VerifyReport) -> set[str]:
    return set(report.failed_ids)


def test_verify_passes_on_the_default_gait(default_gait: Gait) -> None:
    report = verify_gait(default_gait)
    assert report.passed, [(c.id, c.value, c.where) for c in report.checks if not c.passed]
    ids = [c.id for c in report.checks]
    # Every check but the friction cone (the default gait has no friction coefficient) runs
    # once, in the documented order.
    assert ids == [i for i in CHECKS if i != "contacts.friction"]
    # What the record evaluates exactly holds to rounding.
    for exact in ("eom.residual", "contacts.position", "contacts.velocity", "states.values",
                  "samples.states", "events.maps", "events.impulses", "cost.recomputed"):
        assert report.check(exact).value < 1e-9, report.check(exact)
    assert report.check("events.periodicity").value < 1e-6  # 10 x the solve's tol
    assert 0.0 < report.check("integration.interval").value < 10.0


@pytest.mark.parametrize("name", list(CORRUPTIONS))
def test_verify_names_the_failing_check_of_a_corrupted_copy(default_gait: Gait,
                                                             name: str) -> None:
    report = verify_gait(Gait.from_dict(_corrupted_data(default_gait, name)))
    assert not report.passed
    expected = CORRUPTIONS[name][1]
    assert expected <= _failed(report), (expected, report.failed_ids)


def test_the_eom_check_agrees_with_pinocchio(default_gait: Gait, reference: RefFn) -> None:
    """The EOM residual of a corrupted torque, recomputed with Pinocchio: both see the change
    of B u (5 % of hip_1's torque, N m) and nothing else."""
    data = _corrupted_data(default_gait, "hip_1 torque + 5 % (u)")
    gait = Gait.from_dict(data)
    delta = abs(default_gait.phases[0].u[KNOT, 0] * 0.05)
    model = gait.model
    scale = model.total_mass * float(np.hypot(*model.gravity)) * 1.0  # leg length 1 m
    value = verify_gait(gait).check("eom.residual").value
    assert value == pytest.approx(delta / scale, rel=1e-6)
    # Pinocchio's residual at that knot (relative to its largest term) is non-zero there only.
    res = eom_residuals(reference(model), gait.phases[0])
    assert res[KNOT] > 1e-4 and np.delete(res, KNOT).max() < 1e-9


def test_verify_without_error_estimates_uses_the_fixed_limit(default_gait: Gait) -> None:
    """A file written before the error estimate was stored still verifies (fixed 0.05)."""
    data = copy.deepcopy(default_gait.to_dict())
    for ph in data["phases"]:
        del ph["error_estimate"]
    gait = Gait.from_dict(data)
    assert all(ph.error_estimate is None for ph in gait.phases)
    report = verify_gait(gait)
    assert report.passed
    check = report.check("integration.interval")
    assert check.limit == 0.05 and "fixed" in check.where


def test_the_error_estimate_round_trips(default_gait: Gait, tmp_path: Path) -> None:
    est = default_gait.phases[0].error_estimate
    assert est is not None and est.shape == (default_gait.phases[0].t.size - 1,)
    back = Gait.load(default_gait.save(tmp_path / "g.gait.json"))
    np.testing.assert_array_equal(back.phases[0].error_estimate, est)


def test_a_negative_error_estimate_is_refused(default_gait: Gait) -> None:
    data = copy.deepcopy(default_gait.to_dict())
    data["phases"][1]["error_estimate"][0] = -1.0
    with pytest.raises(ValueError, match=r"phases\[1\]\.error_estimate: expected numbers >= 0"):
        Gait.from_dict(data)


def test_the_integration_check_fails_on_a_loose_tolerance_scale(default_gait: Gait) -> None:
    """The interval check compares with the estimate: at 1 % of the limit it fails."""
    report = verify_gait(default_gait, tolerance_scale=0.01)
    assert "integration.interval" in report.failed_ids


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_verify_rejects_a_bad_tolerance_scale(default_gait: Gait, bad: float) -> None:
    with pytest.raises(ValueError, match="tolerance_scale"):
        verify_gait(default_gait, tolerance_scale=bad)


# -- the command line ---------------------------------------------------------------------------

def test_cli_verify_passes_on_the_saved_default_gait(default_gait_file: Path) -> None:
    result = CliRunner().invoke(cli, ["verify", str(default_gait_file)])
    assert result.exit_code == 0, result.output
    assert "checks passed" in result.output and "FAIL" not in result.output


def test_cli_verify_json_lists_every_check_by_id(default_gait_file: Path) -> None:
    result = CliRunner().invoke(cli, ["verify", "--json", str(default_gait_file)])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert out["passed"] is True
    assert {c["id"] for c in out["checks"]} == set(CHECKS) - {"contacts.friction"}
    assert all(c["passed"] and c["value"] <= c["limit"] for c in out["checks"] if c["required"])


@pytest.mark.parametrize("name", ["hip_1 torque + 5 % (u)",
                                  "heel-strike normal impulse + 0.01 N s (event impulse)"])
def test_cli_verify_exits_nonzero_on_a_corrupted_file(default_gait_file: Path, tmp_path: Path,
                                                      name: str) -> None:
    data = json.loads(default_gait_file.read_text())
    CORRUPTIONS[name][0](data)
    bad = tmp_path / "corrupted.gait.json"
    bad.write_text(json.dumps(data))
    result = CliRunner().invoke(cli, ["verify", str(bad)])
    assert result.exit_code == 1, result.output
    summary = " ".join(result.output.split()).split(" check(s) FAILED: ")  # lines may wrap
    assert len(summary) == 2
    for check in CORRUPTIONS[name][1]:
        assert check in summary[1]
    result = CliRunner().invoke(cli, ["verify", "--json", str(bad)])
    assert result.exit_code == 1
    failed = {c["id"] for c in json.loads(result.output)["checks"] if not c["passed"]}
    assert CORRUPTIONS[name][1] <= failed


def test_cli_verify_rejects_a_file_that_is_not_a_gait(tmp_path: Path) -> None:
    bad = tmp_path / "x.gait.json"
    bad.write_text('{"format": "something else", "version": 1}')
    result = CliRunner().invoke(cli, ["verify", str(bad)])
    assert result.exit_code == 2
    assert "format" in result.stderr and "Traceback" not in result.output


def test_cli_verify_rejects_a_bad_tolerance(default_gait_file: Path) -> None:
    result = CliRunner().invoke(cli, ["verify", "--tolerance", "-1", str(default_gait_file)])
    assert result.exit_code == 2
    assert "--tolerance" in result.stderr and "Traceback" not in result.output


# -- samples at, just before and just after the heel strike ------------------------------------
#
# A dense sample that falls on the heel strike, or a rounding error on either side of it, is the
# floating-point edge case of the phase assignment (module docstring of
# gaitopt.analysis.checks.samples). Whether a solve's uniform sample grid happens to produce
# one depends on the last bits of the solution, which differ between CPUs and BLAS kernels, so
# the cases are built on purpose: the samples are re-evaluated at chosen times from the
# phases' own interpolants, each by the phase the documented rule gives it.

FAST = GaitOptions.paper(speed=0.5)  # 30 m/min
SIDES = {"before": -np.inf, "at": None, "after": np.inf}


def _times_around(t: Array, strike: float) -> tuple[Array, dict[str, int]]:
    """``t`` with the three samples nearest ``strike`` replaced by ``nextafter(strike, -inf)``,
    ``strike`` and ``nextafter(strike, +inf)``; their indices by side."""
    chosen = {side: strike if to is None else float(np.nextafter(strike, to))
              for side, to in SIDES.items()}
    near = np.argsort(np.abs(t - strike))[:3]
    out = np.sort(np.concatenate([np.delete(t, near), list(chosen.values())]))
    return out, {side: int(np.flatnonzero(out == v)[0]) for side, v in chosen.items()}


def _resampled(gait: Gait, t: Array) -> Gait:
    """``gait`` with its samples re-evaluated at times ``t`` (sorted): sample k by the first
    phase whose last knot time is >= t[k] (exact comparison), from that phase's state and
    control interpolants and the forward kinematics."""
    model, step = gait.model, gait.parameters["step_length"]
    q = np.zeros((t.size, model.nq))
    qd = np.zeros((t.size, model.nq))
    u = np.zeros((t.size, model.nu))
    taken = np.zeros(t.size, dtype=bool)
    for ph in gait.phases:
        mask = (t <= ph.t[-1]) & ~taken
        taken |= mask
        if not mask.any():
            continue
        full = full_state_function(model, tuple(ph.state_names)).map(int(mask.sum()))(
            phase_states_at(ph, t[mask]).T, step)
        q[mask], qd[mask] = (np.asarray(v, dtype=float).T for v in full)
        u[mask] = phase_controls_at(ph, t[mask])
    names = tuple(gait.samples.points)
    pts = np.asarray(points_function(model, names).map(t.size)(q.T), dtype=float)
    pts = pts.reshape(2, t.size, len(names))  # (xy, sample, point)
    points = {name: pts[:, :, j].T for j, name in enumerate(names)}
    return replace(gait, samples=GaitSamples(t=t, q=q, qd=qd, u=u, points=points))


def test_time_rounding_around_the_heel_strike_is_built_on_purpose() -> None:
    t, at = _times_around(np.linspace(0.0, 1.0, 11), 0.5)
    assert t.size == 11 and np.all(np.diff(t) > 0.0)
    assert t[at["at"]] == 0.5
    assert t[at["before"]] < 0.5 < t[at["after"]]
    assert t[at["after"]] - 0.5 < 1e-15 and 0.5 - t[at["before"]] < 1e-15


@pytest.mark.parametrize("options", [FAST, GaitOptions.paper(speed=0.9)],
                         ids=["30 m/min", "54 m/min"])
def test_samples_at_and_a_rounding_error_around_the_heel_strike(solved: SolveFn,
                                                                options: GaitOptions) -> None:
    """A sample at the heel-strike instant, and one a rounding error before it, hold the
    pre-impact velocity (single support); one a rounding error after it holds the post-impact
    velocity (double support). verify assigns them so and passes."""
    gait = solved(options).gait
    strike = next(e for e in gait.events if e.name == "heel_strike")
    assert gait.phases[0].t[-1] == strike.t
    t, at = _times_around(gait.samples.t, strike.t)
    resampled = _resampled(gait, t)
    s = resampled.samples
    for side in ("before", "at"):
        np.testing.assert_allclose(s.qd[at[side]], strike.qd_before, atol=1e-6)
    np.testing.assert_allclose(s.qd[at["after"]], strike.qd_after, atol=1e-6)
    assert np.max(np.abs(strike.qd_after - strike.qd_before)) > 0.01  # a real jump
    report = verify_gait(resampled)
    assert report.passed, [(c.id, c.value, c.where) for c in report.checks if not c.passed]


def test_fast_gait_forces_between_knots_are_non_negative(solved: SolveFn,
                                                         reference: RefFn) -> None:
    """The 30 m/min gait's normal forces, recomputed with Pinocchio on the dense samples of
    each phase (single support: t <= heel strike; double support: t > heel strike), are
    non-negative, with a sample placed exactly at the heel-strike instant (it holds the
    pre-impact velocity and belongs to single support)."""
    gait = solved(FAST).gait
    assert gait.success
    ref = reference(gait.model)
    strike = next(e for e in gait.events if e.name == "heel_strike")
    t, at = _times_around(gait.samples.t, strike.t)
    resampled = _resampled(gait, t)
    s = resampled.samples
    lowest = lowest_sample_normal_force(ref, resampled)
    assert lowest >= -1e-3
    # Double-support forces at the pre-impact sample are what a check must not use.
    wrong = contact_forces(ref, s.q[at["at"]], s.qd[at["at"]], s.u[at["at"]],
                           ("tip_1", "tip_2"))
    assert np.min(wrong[:, 1]) < -100.0
    assert {ph.name for ph in gait.phases} == {SINGLE, DOUBLE}


def test_verify_passes_on_the_fast_gait(solved: SolveFn) -> None:
    report = verify_gait(solved(FAST).gait)
    assert report.passed, [(c.id, c.value, c.where) for c in report.checks if not c.passed]
    # Between knots the normal forces may dip by the solve's interior-point leftover (about
    # 1e-5 N); 1 mN is far from it and far below the check's limit.
    assert report.check("samples.normal_force").value < 1e-3


# -- the ids are documented and used ------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[2]


def test_every_check_id_is_documented() -> None:
    text = (ROOT / "docs" / "outputs.md").read_text(encoding="utf-8")
    section = text.split("## 5. Verify", 1)[1]
    documented = [line.split("`")[1] for line in section.splitlines()
                  if line.startswith("| `")]
    assert documented == list(CHECKS)


def test_the_benchmark_looks_checks_up_by_known_ids() -> None:
    """bench/gait_grid.py labels checks by id: a renamed or removed id fails here instead of
    silently disabling a branch of the benchmark."""
    import importlib.util
    import sys

    spec = importlib.util.spec_from_file_location("gait_grid", ROOT / "bench" / "gait_grid.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass needs its module registered
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[spec.name]
    assert set(module.SHORT) <= set(CHECKS)
    assert "samples.normal_force" in module.SHORT  # the force@strike branch's check


def test_a_check_passes_only_within_its_limit() -> None:
    from gaitopt.analysis.verify import Check

    assert Check("eom.residual", 1e-7, 1e-6).passed
    assert not Check("eom.residual", 2e-6, 1e-6).passed
    assert not Check("eom.residual", float("nan"), 1e-6).passed  # NaN never passes
    assert Check("integration.phase", 5.0, 0.05).passed  # information only
    assert Check("integration.phase", 5.0, 0.05).limit_text.endswith("information)")
    with pytest.raises(KeyError, match="unknown check id 'eom'"):
        Check("eom", 0.0, 1.0)
    assert Check("eom.residual", float("inf"), 1.0).to_dict()["value"] is None  # valid JSON


def test_an_unbounded_joint_has_no_excess_over_its_limits(default_gait: Gait) -> None:
    """A joint without limits (null in the model file: a URDF continuous joint or Inf limits)
    is never beyond them: the bound checks report 0 for it, not an infinite excess."""
    data = copy.deepcopy(default_gait.to_dict())
    for link in data["model"]["links"]:
        if link.get("joint") and link["joint"]["name"] == "hip_1":
            link["joint"]["limits"] = [None, None]
    gait = Gait.from_dict(data)
    assert next(j for j in gait.model.joints if j.name == "hip_1").limits == (-np.inf, np.inf)
    report = verify_gait(gait)
    for key in ("bounds.joints_knots", "bounds.joints_samples"):
        assert report.check(key).passed and np.isfinite(report.check(key).value), key


def test_a_verifier_verifies_a_gait_once(default_solved: Any, default_gait: Gait,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    # `gaitopt solve` judges the released gait and then writes it: the Verifier keeps the
    # report, and returns it for the same motion with another solver record or time of
    # writing; a gait that differs in what verify reads is verified again.
    import gaitopt.analysis.plausible as plausible

    calls: list[Gait] = []

    def counted(gait: Gait, **kwargs: Any) -> VerifyReport:
        calls.append(gait)
        return verify_gait(gait, **kwargs)

    monkeypatch.setattr(plausible, "verify_gait", counted)
    verifier = plausible.Verifier()
    assert verifier(default_solved.solution) is None
    rewritten = replace(default_gait, created="2000-01-01T00:00:00+00:00",
                        solver={**default_gait.solver, "note": "written later"})
    assert verifier.report(rewritten).passed
    assert len(calls) == 1
    moved = copy.deepcopy(default_gait.to_dict())
    moved["phases"][0]["u"][3][0] += 5.0
    report = verifier.report(Gait.from_dict(moved))
    assert len(calls) == 2 and not report.passed
