"""Whether the paper's findings (section 6) hold for a sweep, stated with numbers.

Input: the rows of a sweep's ``summary.csv`` (:class:`gaitopt.study.summary.SummaryRow`) and,
for the torque findings, some of its gaits keyed by the rows' ``file``. Each finding gets a
verdict: ``True`` (holds), ``False`` (does not hold) or ``None`` (the sweep cannot tell:
missing variants, too few points). The thresholds are module constants, stated in the
evidence text.

Each finding has a stable id (:data:`FINDING_IDS`, ``<subject>.<what>``): code, tests and
links into the report use it; the claim is prose for people and may be reworded. Its numbers
are keyed ``<quantity>.<variant>`` (e.g. ``r2.plain``). The ids are listed in
docs/studies.md.

Findings checked, in report order (paper sections 1, 6, 7):

1. ``optimum.speed``: the energy-optimal walk is much slower than the human optimum
   (80 m/min); the paper finds about 12 m/min. Holds if every variant's optimum is below
   :data:`SLOW_LIMIT_M_MIN`.
2. ``optimum.step_length``: its steps are shorter than human steps (0.75 m); paper: 0.1 m.
   Holds if every optimal step length is below :data:`SHORT_STEP_LIMIT`.
3. ``energy.hyperbolic_fit``: energy per metre against speed is hyperbolic like the human
   curve: a fit E = a/v + b v + c has R^2 >= :data:`MIN_R2`, a > 0, b > 0, and the grid
   minimum is inside the grid (decreasing, then increasing).
4. ``step_length.linear_fit``: the optimal step length grows roughly linearly with speed: a
   line fit has slope > 0 and R^2 >= :data:`MIN_R2`.
5. ``impulse.energy_saving``: the liftoff impulse lowers the energy at every speed
   (never worse by more than :data:`COST_TOLERANCE`, median saving >=
   :data:`MIN_IMPULSE_SAVING`).
6. ``impulse.optimal_speed``: with no noticeable change of the optimal speed (within
   :data:`SAME_SPEED_TOLERANCE` relative).
7. ``impulse.torque_saturation``: fast walks (near 50 m/min) reach the torque bounds, and
   the liftoff impulse reduces the fraction of knots at a bound.
8. ``ankle.energy_effect``: ankle torques change the energy little (median relative change
   <= :data:`SMALL_ANKLE_EFFECT`).
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from gaitopt.gait.record.file import Gait
from gaitopt.study.summary import VARIANTS, SummaryRow, rows_of

PAPER_OPTIMAL_SPEED_M_MIN = 12.0
PAPER_OPTIMAL_STEP_LENGTH = 0.1
HUMAN_OPTIMAL_SPEED_M_MIN = 80.0
HUMAN_STEP_LENGTH = 0.75
FAST_SPEED_M_MIN = 50.0
SLOW_LIMIT_M_MIN = HUMAN_OPTIMAL_SPEED_M_MIN / 2
SHORT_STEP_LIMIT = HUMAN_STEP_LENGTH / 2
MIN_R2 = 0.9
MIN_FIT_POINTS = 5
COST_TOLERANCE = 1e-3
MIN_IMPULSE_SAVING = 0.05
SAME_SPEED_TOLERANCE = 0.25
SMALL_ANKLE_EFFECT = 0.10
SATURATION_TOLERANCE = 0.01
#: (with, without) variant pairs for the impulse and ankle comparisons.
IMPULSE_PAIRS: tuple[tuple[str, str], ...] = (("ankle+impulse", "ankle"), ("impulse", "plain"))
ANKLE_PAIRS: tuple[tuple[str, str], ...] = (("ankle", "plain"), ("ankle+impulse", "impulse"))


#: The stable id of every finding, in report order (see the module docstring).
FINDING_IDS: tuple[str, ...] = (
    "optimum.speed", "optimum.step_length", "energy.hyperbolic_fit", "step_length.linear_fit",
    "impulse.energy_saving", "impulse.optimal_speed", "impulse.torque_saturation",
    "ankle.energy_effect")


@dataclass(frozen=True)
class Optimum:
    """The energy-optimal walk of a variant; ``source``: 'speed-free solve' or 'grid minimum'."""

    variant: str
    speed_m_min: float
    step_length: float
    cost: float
    source: str
    row: SummaryRow


@dataclass(frozen=True)
class Finding:
    """One finding of the paper: its stable ``id`` (one of :data:`FINDING_IDS`), its claim
    (prose), our verdict and the numbers behind it."""

    id: str
    claim: str
    holds: bool | None
    evidence: str
    numbers: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Findings:
    """Each variant's energy-optimal walk and the findings, in the order of
    :data:`FINDING_IDS`; ``findings["optimum.speed"]`` is a finding by its id."""

    optima: Mapping[str, Optimum]
    items: tuple[Finding, ...]

    def __getitem__(self, finding_id: str) -> Finding:
        for item in self.items:
            if item.id == finding_id:
                return item
        raise KeyError(f"no finding {finding_id!r}; the findings are "
                       + ", ".join(item.id for item in self.items))


# -- selection and fits ------------------------------------------------------------------------

def optimal_row(rows: Sequence[SummaryRow], variant: str) -> SummaryRow | None:
    """The variant's successful speed-free row (lowest cost if several), else the successful
    fixed-speed row of lowest cost; None if the variant has no successful row."""
    free = [r for r in rows_of(rows, variant, speed_mode="free") if math.isfinite(r.cost)]
    pool = free or [r for r in rows_of(rows, variant, speed_mode="fixed")
                    if math.isfinite(r.cost)]
    return min(pool, key=lambda r: r.cost) if pool else None


def row_near_speed(rows: Sequence[SummaryRow], variant: str,
                   speed_m_min: float) -> SummaryRow | None:
    """The successful fixed-speed row of the variant whose speed is nearest ``speed_m_min``."""
    pool = [r for r in rows_of(rows, variant, speed_mode="fixed") if math.isfinite(r.cost)]
    return min(pool, key=lambda r: abs(r.speed_m_min - speed_m_min)) if pool else None


def _r2(y: np.ndarray, fit: np.ndarray) -> float:
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    return 1.0 if ss_tot == 0.0 else 1.0 - float(np.sum((y - fit) ** 2)) / ss_tot


def fit_hyperbola(v: Sequence[float], e: Sequence[float]) -> tuple[float, float, float, float]:
    """Least-squares fit e = a / v + b v + c; returns (a, b, c, R^2)."""
    vv, ee = np.asarray(v, dtype=float), np.asarray(e, dtype=float)
    basis = np.stack([1.0 / vv, vv, np.ones_like(vv)], axis=1)
    (a, b, c), *_ = np.linalg.lstsq(basis, ee, rcond=None)
    return float(a), float(b), float(c), _r2(ee, basis @ np.array([a, b, c]))


def fit_line(v: Sequence[float], y: Sequence[float]) -> tuple[float, float, float]:
    """Least-squares line y = slope v + intercept; returns (slope, intercept, R^2)."""
    vv, yy = np.asarray(v, dtype=float), np.asarray(y, dtype=float)
    slope, intercept = np.polyfit(vv, yy, 1)
    return float(slope), float(intercept), _r2(yy, slope * vv + intercept)


def saturation_fraction(gait: Gait, *, tolerance: float = SATURATION_TOLERANCE) -> float:
    """Fraction of (knot, actuator) pairs whose torque is at a bound.

    A torque is at a bound if it is within ``tolerance`` x (upper - lower) / 2 of it.
    Actuators with equal bounds (switched off) are left out.
    """
    model = gait.model
    lo = np.array([a.limits[0] for a in model.actuators])
    hi = np.array([a.limits[1] for a in model.actuators])
    active = hi > lo
    u = np.concatenate([p.u for p in gait.phases])[:, active]
    margin = tolerance * (hi - lo)[active] / 2
    at = (u >= hi[active] - margin) | (u <= lo[active] + margin)
    return float(at.mean()) if at.size else 0.0


def _paired(rows: Sequence[SummaryRow], with_: str, without: str
            ) -> list[tuple[float, float, float]]:
    """(speed m/min, cost with, cost without) at speeds both variants solved."""
    a = {round(r.speed_m_min, 6): r.cost for r in rows_of(rows, with_, speed_mode="fixed")}
    b = {round(r.speed_m_min, 6): r.cost for r in rows_of(rows, without, speed_mode="fixed")}
    return [(v, a[v], b[v]) for v in sorted(set(a) & set(b))
            if math.isfinite(a[v]) and math.isfinite(b[v]) and b[v] > 0]


# -- the findings ----------------------------------------------------------------------------

def assess_findings(rows: Sequence[SummaryRow],
                    gaits: Mapping[str, Gait] | None = None) -> Findings:
    """Check the paper's findings on a sweep; ``gaits`` (by row ``file``) for the torques."""
    optima = {v: _optimum(rows, v) for v in VARIANTS}
    found = {v: o for v, o in optima.items() if o is not None}
    items = (_slow(found), _short(found), _hyperbolic(rows), _linear(rows),
             _impulse_energy(rows), _impulse_speed(found),
             _saturation(rows, gaits or {}), _ankle(rows))
    return Findings(optima=found, items=items)


def _optimum(rows: Sequence[SummaryRow], variant: str) -> Optimum | None:
    row = optimal_row(rows, variant)
    if row is None:
        return None
    source = "speed-free solve" if row.speed_mode == "free" else "grid minimum"
    return Optimum(variant=variant, speed_m_min=row.speed_m_min, step_length=row.step_length,
                   cost=row.cost, source=source, row=row)


def _slow(optima: Mapping[str, Optimum]) -> Finding:
    claim = (f"The energy-optimal walk is much slower than the human optimum "
             f"({HUMAN_OPTIMAL_SPEED_M_MIN:g} m/min): about {PAPER_OPTIMAL_SPEED_M_MIN:g} m/min.")
    if not optima:
        return Finding("optimum.speed", claim, None, "no successful solve")
    speeds = {v: o.speed_m_min for v, o in optima.items()}
    text = "; ".join(f"{v}: {s:.1f} m/min ({optima[v].source})" for v, s in speeds.items())
    holds = all(s < SLOW_LIMIT_M_MIN for s in speeds.values())
    return Finding("optimum.speed", claim, holds,
                   f"optimal speeds {text}; limit for 'much slower': < {SLOW_LIMIT_M_MIN:g} "
                   f"m/min", {f"speed_m_min.{v}": s for v, s in speeds.items()})


def _short(optima: Mapping[str, Optimum]) -> Finding:
    claim = (f"Optimal steps are shorter than human steps ({HUMAN_STEP_LENGTH:g} m): about "
             f"{PAPER_OPTIMAL_STEP_LENGTH:g} m.")
    if not optima:
        return Finding("optimum.step_length", claim, None, "no successful solve")
    lengths = {v: o.step_length for v, o in optima.items()}
    text = "; ".join(f"{v}: {s:.3f} m" for v, s in lengths.items())
    holds = all(s < SHORT_STEP_LIMIT for s in lengths.values())
    return Finding("optimum.step_length", claim, holds, f"optimal step lengths {text}; limit "
                   f"for 'shorter': < {SHORT_STEP_LIMIT:g} m",
                   {f"step_length.{v}": s for v, s in lengths.items()})


def _hyperbolic(rows: Sequence[SummaryRow]) -> Finding:
    claim = ("Energy per metre against speed has the hyperbolic shape of the human curve "
             "(decreasing, then increasing).")
    parts, numbers, verdicts = [], {}, []
    for v in VARIANTS:
        fixed = [r for r in rows_of(rows, v, speed_mode="fixed") if math.isfinite(r.cost)]
        if len(fixed) < MIN_FIT_POINTS:
            continue
        speeds = [r.speed_m_min for r in fixed]
        costs = [r.cost for r in fixed]
        a, b, c, r2 = fit_hyperbola(speeds, costs)
        i_min = int(np.argmin(costs))
        interior = 0 < i_min < len(costs) - 1
        ok = r2 >= MIN_R2 and a > 0 and b > 0 and interior
        verdicts.append(ok)
        numbers.update({f"a.{v}": a, f"b.{v}": b, f"c.{v}": c, f"r2.{v}": r2})
        where = (f"minimum inside the grid at {speeds[i_min]:g} m/min" if interior else
                 f"minimum at the grid's {'first' if i_min == 0 else 'last'} speed "
                 f"{speeds[i_min]:g} m/min")
        parts.append(f"{v}: E = {a:.4g}/v + {b:.4g} v + {c:.4g}, R² = {r2:.3f}, {where}")
    if not verdicts:
        return Finding("energy.hyperbolic_fit", claim, None,
                       f"fewer than {MIN_FIT_POINTS} solved fixed speeds per variant")
    return Finding("energy.hyperbolic_fit", claim, all(verdicts), "; ".join(parts) +
                   f" (holds if R² ≥ {MIN_R2}, a > 0, b > 0, interior minimum)", numbers)


def _linear(rows: Sequence[SummaryRow]) -> Finding:
    claim = "The optimal step length grows roughly linearly with speed."
    parts, numbers, verdicts = [], {}, []
    for v in VARIANTS:
        fixed = [r for r in rows_of(rows, v, speed_mode="fixed") if math.isfinite(r.step_length)]
        if len(fixed) < MIN_FIT_POINTS:
            continue
        lengths = [r.step_length for r in fixed]
        if np.ptp(lengths) < 1e-9:
            parts.append(f"{v}: step length fixed at {lengths[0]:g} m in the sweep")
            continue
        slope, intercept, r2 = fit_line([r.speed_m_min for r in fixed], lengths)
        verdicts.append(slope > 0 and r2 >= MIN_R2)
        numbers.update({f"slope.{v}": slope, f"intercept.{v}": intercept, f"r2.{v}": r2})
        parts.append(f"{v}: L = {intercept:.3g} m + {slope * 1000:.3g} mm per m/min × v, "
                     f"R² = {r2:.3f}")
    if not verdicts:
        return Finding("step_length.linear_fit", claim, None,
                       "; ".join(parts) or f"fewer than {MIN_FIT_POINTS} solved fixed speeds")
    return Finding("step_length.linear_fit", claim, all(verdicts), "; ".join(parts) +
                   f" (holds if slope > 0 and R² ≥ {MIN_R2})", numbers)


def _impulse_energy(rows: Sequence[SummaryRow]) -> Finding:
    claim = "The liftoff impulse lowers the energy needed at every speed, significantly."
    parts, numbers, verdicts = [], {}, []
    for with_, without in IMPULSE_PAIRS:
        pairs = _paired(rows, with_, without)
        if not pairs:
            continue
        savings = np.array([1.0 - a / b for _, a, b in pairs])
        worst = int(np.argmin(savings))
        ok = savings.min() >= -COST_TOLERANCE and float(np.median(savings)) >= MIN_IMPULSE_SAVING
        verdicts.append(ok)
        numbers.update({f"median_saving.{with_}": float(np.median(savings)),
                        f"min_saving.{with_}": float(savings.min())})
        parts.append(f"{with_} vs {without} at {len(pairs)} speeds: median saving "
                     f"{np.median(savings):.1%}, range {savings.min():.1%} (at "
                     f"{pairs[worst][0]:g} m/min) to {savings.max():.1%}")
    if not verdicts:
        return Finding("impulse.energy_saving", claim, None,
                       "no speed solved both with and without the impulse")
    return Finding("impulse.energy_saving", claim, all(verdicts), "; ".join(parts) +
                   f" (holds if never worse by more than {COST_TOLERANCE:.1%} and median "
                   f"saving ≥ {MIN_IMPULSE_SAVING:.0%})", numbers)


def _impulse_speed(optima: Mapping[str, Optimum]) -> Finding:
    claim = "The liftoff impulse does not noticeably change the optimal walking speed."
    parts, numbers, verdicts = [], {}, []
    for with_, without in IMPULSE_PAIRS:
        if with_ in optima and without in optima:
            a, b = optima[with_].speed_m_min, optima[without].speed_m_min
            change = abs(a - b) / b
            verdicts.append(change <= SAME_SPEED_TOLERANCE)
            numbers[f"relative_change.{with_}"] = change
            parts.append(f"{with_} {a:.1f} vs {without} {b:.1f} m/min ({change:.0%})")
    if not verdicts:
        return Finding("impulse.optimal_speed", claim, None,
                       "optima with and without the impulse are not both available")
    return Finding("impulse.optimal_speed", claim, all(verdicts), "; ".join(parts) +
                   f" (holds if within {SAME_SPEED_TOLERANCE:.0%})", numbers)


def _saturation(rows: Sequence[SummaryRow], gaits: Mapping[str, Gait]) -> Finding:
    claim = ("Fast walks reach the torque bounds; the liftoff impulse greatly reduces the "
             "torque saturation.")
    parts, numbers, verdicts = [], {}, []
    for with_, without in IMPULSE_PAIRS:
        ra = row_near_speed(rows, with_, FAST_SPEED_M_MIN)
        rb = row_near_speed(rows, without, FAST_SPEED_M_MIN)
        if ra is None or rb is None or ra.file not in gaits or rb.file not in gaits:
            continue
        sa, sb = saturation_fraction(gaits[ra.file]), saturation_fraction(gaits[rb.file])
        verdicts.append(sb > 0 and sa < sb)
        numbers.update({f"saturation.{with_}": sa, f"saturation.{without}": sb})
        parts.append(f"knots at a bound: {with_} {sa:.1%} at {ra.speed_m_min:g} m/min vs "
                     f"{without} {sb:.1%} at {rb.speed_m_min:g} m/min")
    if not verdicts:
        return Finding("impulse.torque_saturation", claim, None,
                       "no gait files near the fast speed for both impulse settings")
    return Finding("impulse.torque_saturation", claim, all(verdicts), "; ".join(parts) +
                   " (holds if the no-impulse walk saturates and the impulse walk less)",
                   numbers)


def _ankle(rows: Sequence[SummaryRow]) -> Finding:
    claim = "Ankle torques change the energy little."
    parts, numbers, verdicts = [], {}, []
    for with_, without in ANKLE_PAIRS:
        pairs = _paired(rows, with_, without)
        if not pairs:
            continue
        change = np.array([1.0 - a / b for _, a, b in pairs])
        median = float(np.median(np.abs(change)))
        verdicts.append(median <= SMALL_ANKLE_EFFECT)
        numbers[f"median_change.{with_}"] = median
        parts.append(f"{with_} vs {without} at {len(pairs)} speeds: median |change| "
                     f"{median:.1%}, saving from {change.min():.1%} to {change.max():.1%}")
    if not verdicts:
        return Finding("ankle.energy_effect", claim, None,
                       "no speed solved both with and without ankle torques")
    return Finding("ankle.energy_effect", claim, all(verdicts), "; ".join(parts) +
                   f" (holds if the median change ≤ {SMALL_ANKLE_EFFECT:.0%})", numbers)


# -- rendering -------------------------------------------------------------------------------

VERDICT_WORDS = {True: "holds", False: "does not hold", None: "cannot tell"}


def findings_text(findings: Findings) -> str:
    """Plain-text rendering: the optima, then one paragraph per finding (verdict, claim,
    id; the evidence indented)."""
    lines = ["Energy-optimal walk per variant (paper: about "
             f"{PAPER_OPTIMAL_SPEED_M_MIN:g} m/min, {PAPER_OPTIMAL_STEP_LENGTH:g} m):"]
    for v, o in findings.optima.items():
        lines.append(f"  {v:14s} {o.speed_m_min:6.1f} m/min  step {o.step_length:.3f} m  "
                     f"cost {o.cost:.4g}  ({o.source})")
    for item in findings.items:
        lines.append(f"[{VERDICT_WORDS[item.holds]}] {item.claim}  ({item.id})\n"
                     f"    {item.evidence}")
    return "\n".join(lines)


def findings_html(findings: Findings, *, heading: str = "paper finding",
                  anchor_prefix: str = "finding-") -> str:
    """An HTML table (no external resources): claim and id, verdict, evidence; each row's
    HTML id is ``finding-<id>`` (a link target: ``report.html#finding-optimum.speed``);
    ``heading`` names the first column, ``anchor_prefix`` replaces ``finding-``."""
    colors = {True: "#1a7f37", False: "#b3261e", None: "#6b6b6b"}
    rows = []
    for item in findings.items:
        rows.append(f'<tr id="{html.escape(anchor_prefix + item.id)}"><td>'
                    f'{html.escape(item.claim)}'
                    f'<br><code>{html.escape(item.id)}</code></td><td style="color:'
                    f'{colors[item.holds]};font-weight:bold;white-space:nowrap">'
                    f"{VERDICT_WORDS[item.holds]}</td><td>{html.escape(item.evidence)}</td></tr>")
    return (f'<table class="findings"><thead><tr><th>{html.escape(heading)}</th><th>ours</th>'
            "<th>evidence</th></tr></thead><tbody>" + "".join(rows) + "</tbody></table>")
