"""The paper's findings, checked on synthetic sweeps whose truth is known (both ways)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
import pytest

from gaitopt.gait.record.file import Gait
from gaitopt.study.findings import (
    FINDING_IDS,
    assess_findings,
    findings_html,
    findings_text,
    fit_hyperbola,
    fit_line,
    optimal_row,
    row_near_speed,
    saturation_fraction,
)
from gaitopt.study.summary import SummaryRow, failed_row, variant_name
from tests.viz.synthetic import synthetic_cost, synthetic_gait, synthetic_step_length

SPEEDS = tuple(float(v) for v in range(3, 61, 3))
Cost = Callable[[float, bool, bool], float]


def _row(v: float, ankle: bool, impulse: bool, cost: float, step: float, *,
         mode: str = "fixed") -> SummaryRow:
    name = variant_name(ankle=ankle, impulse=impulse)
    return SummaryRow(variant=name, ankle=ankle, impulse=impulse,
                      speed_mode=mode,  # type: ignore[arg-type]
                      speed_m_s=v / 60, speed_m_min=v, step_length=step, step_time=1.0,
                      cost=cost, status="ok", success=True, iterations=1, wall_time_s=0.1,
                      file=f"gaits/{name}/{mode}-{v:g}.gait.json")


def _sweep(cost: Cost = lambda v, a, i: synthetic_cost(v, ankle=a, impulse=i),
           step: Callable[[float], float] = synthetic_step_length,
           free: bool = True) -> list[SummaryRow]:
    rows = [_row(v, a, i, cost(v, a, i), step(v)) for a in (True, False) for i in (True, False)
            for v in SPEEDS]
    if free:
        v = math.sqrt(150.0)
        rows += [_row(v, a, i, cost(v, a, i), step(v), mode="free")
                 for a in (True, False) for i in (True, False)]
    return rows


def test_fits_recover_exact_coefficients() -> None:
    v = np.array(SPEEDS)
    a, b, c, r2 = fit_hyperbola(v, 300 / v + 2 * v + 10)
    assert (a, b, c, r2) == pytest.approx((300, 2, 10, 1.0))
    slope, intercept, r2 = fit_line(v, 0.05 + 0.008 * v)
    assert (slope, intercept, r2) == pytest.approx((0.008, 0.05, 1.0))


def test_all_findings_hold_on_a_paper_like_sweep() -> None:
    findings = assess_findings(_sweep())
    for key in ("optimum.speed", "optimum.step_length", "energy.hyperbolic_fit",
                "step_length.linear_fit", "impulse.energy_saving", "impulse.optimal_speed",
                "ankle.energy_effect"):
        assert findings[key].holds is True, findings[key]
    assert findings["impulse.torque_saturation"].holds is None  # needs gait files
    opt = findings.optima["plain"]
    assert opt.source == "speed-free solve" and opt.speed_m_min == pytest.approx(12.247, 1e-3)
    assert findings["energy.hyperbolic_fit"].numbers["r2.plain"] == pytest.approx(1.0)
    assert findings["impulse.energy_saving"].numbers["median_saving.impulse"] == \
        pytest.approx(0.30)
    assert findings["ankle.energy_effect"].numbers["median_change.ankle"] == pytest.approx(0.05)


def test_optimum_falls_back_to_the_grid_minimum() -> None:
    rows = _sweep(free=False)
    rows.append(failed_row(ankle=False, impulse=False, speed_mode="free", status="failed"))
    best = optimal_row(rows, "plain")
    assert best is not None and best.speed_mode == "fixed" and best.speed_m_min == 12.0
    assert assess_findings(rows).optima["plain"].source == "grid minimum"
    near = row_near_speed(rows, "plain", 50.0)
    assert near is not None and near.speed_m_min == 51.0
    assert optimal_row([], "plain") is None


def test_fast_optimum_and_long_steps_fail_the_first_findings() -> None:
    # energy minimal at 60 m/min: monotone decreasing over the grid -> not hyperbolic-looking
    rows = _sweep(cost=lambda v, a, i: 3000 / v + 0.01 * v, step=lambda v: 0.2 + 0.01 * v,
                  free=False)
    findings = assess_findings(rows)
    assert findings["optimum.speed"].holds is False
    assert findings["optimum.step_length"].holds is False  # 0.8 m at 60 m/min
    assert findings["energy.hyperbolic_fit"].holds is False
    assert "minimum at the grid's last speed 60" in findings["energy.hyperbolic_fit"].evidence


def test_nonlinear_step_length_and_costly_impulse_fail() -> None:
    rows = _sweep(cost=lambda v, a, i: synthetic_cost(v, ankle=a, impulse=False) *
                  (1.2 if i and v > 30 else (0.5 if a else 1.0)),
                  step=lambda v: 0.3 + 0.2 * math.sin(v / 4))
    findings = assess_findings(rows)
    assert findings["step_length.linear_fit"].holds is False
    assert findings["impulse.energy_saving"].holds is False
    assert findings["ankle.energy_effect"].holds is False  # ankles halve the cost


def test_fixed_step_length_cannot_tell() -> None:
    findings = assess_findings(_sweep(step=lambda v: 0.1))
    assert findings["step_length.linear_fit"].holds is None
    assert "fixed at 0.1 m" in findings["step_length.linear_fit"].evidence


def test_missing_variants_cannot_tell() -> None:
    rows = [r for r in _sweep() if r.variant == "plain"]
    findings = assess_findings(rows)
    assert findings["impulse.energy_saving"].holds is None
    assert findings["ankle.energy_effect"].holds is None
    assert findings["energy.hyperbolic_fit"].holds is True
    empty = assess_findings([])
    assert all(item.holds is None for item in empty.items)


def test_saturation_fraction_counts_knots_at_the_bounds() -> None:
    assert saturation_fraction(synthetic_gait(torque_amplitude=0.0)) == 0.0
    gait = synthetic_gait(torque_amplitude=1e6)  # every nonzero torque is clipped to a bound
    u = np.concatenate([p.u for p in gait.phases])
    expected = np.mean(np.abs(u) > 1.0)
    assert saturation_fraction(gait) == pytest.approx(expected)
    assert 0.5 < expected < 1.0


def _gaits_for(rows: list[SummaryRow], amplitude: Callable[[bool], float]) -> dict[str, Gait]:
    out = {}
    for r in rows:
        if r.speed_mode == "fixed" and r.speed_m_min == 51.0:
            out[r.file] = synthetic_gait(torque_amplitude=amplitude(r.impulse), ankle=r.ankle)
    return out


def test_saturation_finding_both_ways() -> None:
    rows = _sweep()
    holds = assess_findings(rows, _gaits_for(rows, lambda imp: 20.0 if imp else 80.0))
    assert holds["impulse.torque_saturation"].holds is True
    assert holds["impulse.torque_saturation"].numbers["saturation.impulse"] == 0.0
    fails = assess_findings(rows, _gaits_for(rows, lambda imp: 100.0 if imp else 70.0))
    assert fails["impulse.torque_saturation"].holds is False


def test_renderings_state_verdicts_and_escape_html() -> None:
    findings = assess_findings(_sweep(step=lambda v: 0.1))
    text = findings_text(findings)
    assert "[holds]" in text and "[cannot tell]" in text and "12.2 m/min" in text
    item = dataclasses.replace(findings.items[0], evidence="a < b & c")
    html = findings_html(dataclasses.replace(findings, items=(item,)))
    assert "a &lt; b &amp; c" in html and "<table" in html


def test_every_finding_has_its_stable_id_in_report_order() -> None:
    # the ids are a public contract (docs/studies.md): spelled out here, not taken from the code
    ids = ("optimum.speed", "optimum.step_length", "energy.hyperbolic_fit",
           "step_length.linear_fit", "impulse.energy_saving", "impulse.optimal_speed",
           "impulse.torque_saturation", "ankle.energy_effect")
    assert ids == FINDING_IDS
    for rows in (_sweep(), [], [r for r in _sweep() if r.variant == "plain"]):
        findings = assess_findings(rows)  # every finding, whatever its verdict
        assert tuple(item.id for item in findings.items) == ids
    with pytest.raises(KeyError, match=r"no finding 'slow_optimum'; the findings are "
                                       r"optimum\.speed, optimum\.step_length"):
        assess_findings(_sweep())["slow_optimum"]


def test_renderings_name_each_finding_by_its_id() -> None:
    findings = assess_findings(_sweep())
    text = findings_text(findings)
    page = findings_html(findings)
    for item in findings.items:
        assert f"{item.claim}  ({item.id})" in text
        assert f'<tr id="finding-{item.id}"><td>{item.claim}' in page
        assert f"<code>{item.id}</code>" in page
