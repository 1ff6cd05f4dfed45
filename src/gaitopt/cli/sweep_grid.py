"""Parsing the grid of ``gaitopt sweep`` and ``study`` (:mod:`gaitopt.cli.study`): speeds in
m/min (``3:60:3``, ``3,12,60``), variants, step lengths and times (``free`` or values), single-
support fractions, and the :class:`~gaitopt.study.plan.SweepSpec` they make. A bad value is a
:class:`~gaitopt.cli.base.UserError` naming the option and the allowed range.
"""

from __future__ import annotations

import math
from typing import Any

from gaitopt.cli.base import UserError, parse_free_or_value, parse_knots
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.study.plan import SweepSpec, SweepSpecError
from gaitopt.study.summary import VARIANTS

MAX_SPEEDS = 2000


def parse_speeds(text: str) -> tuple[float, ...]:
    """Speeds in m/s from m/min text: ``3:60:3`` (start:stop:step, stop included), a list
    ``3,6,12.5`` or both (``3:30:3,45,60``); sorted, duplicates removed."""
    values: list[float] = []
    for item in text.replace("m/min", "").split(","):
        item = item.strip()
        if not item:
            continue
        parts = item.split(":")
        try:
            numbers = [float(p) for p in parts]
        except ValueError:
            raise UserError(f"--speeds: {item!r} is not a speed in m/min or a range "
                            "start:stop:step (m/min), e.g. 3:60:3 or 3,12,60") from None
        if not all(math.isfinite(x) for x in numbers):
            raise UserError(f"--speeds: {item!r}: speeds must be finite")
        if len(numbers) == 1:
            values.append(numbers[0])
        elif len(numbers) == 3:
            start, stop, step = numbers
            if step <= 0 or stop < start:
                raise UserError(f"--speeds: range {item!r} needs start <= stop and step > 0 "
                                "(start:stop:step in m/min, stop included)")
            n = math.floor((stop - start) / step + 1e-9) + 1
            if n > MAX_SPEEDS:
                raise UserError(f"--speeds: range {item!r} has {n} speeds; at most "
                                f"{MAX_SPEEDS}")
            values.extend(round(start + i * step, 9) for i in range(n))
        else:
            raise UserError(f"--speeds: {item!r} must be a speed or start:stop:step (m/min)")
    if not values:
        raise UserError("--speeds: no speed given (e.g. 3:60:3)")
    bad = [v for v in values if v <= 0]
    if bad:
        raise UserError(f"--speeds: speeds must be > 0 m/min, got {bad[0]:g}")
    unique = sorted(set(values))
    if len(unique) > MAX_SPEEDS:
        raise UserError(f"--speeds: {len(unique)} speeds; at most {MAX_SPEEDS}")
    return tuple(v / 60.0 for v in unique)


def parse_variants(text: str) -> tuple[str, ...]:
    """``all`` or a comma list of variant names, returned in the canonical order."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if names == ["all"]:
        return VARIANTS
    unknown = [n for n in names if n not in VARIANTS]
    if unknown or not names:
        raise UserError(f"--variants: unknown variant {unknown[0] if unknown else text!r}; use "
                        f"'all' or a comma list of {', '.join(VARIANTS)}")
    return tuple(v for v in VARIANTS if v in names)


def parse_step_lengths(text: str, *, option: str = "--step-length", unit: str = "m",
                       quantity: str = "length") -> tuple[float | None, ...]:
    """``free`` or a comma list of step lengths in m (``free`` may be one of them); with
    ``option="--step-time", unit="s", quantity="time"``, of step times in s."""
    out: list[float | None] = []
    for item in (i.strip() for i in text.split(",")):
        value = parse_free_or_value(item, option, unit, quantity)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise UserError(f"{option}: {item!r} must be > 0 {unit} (or 'free')")
        out.append(value)
    return tuple(dict.fromkeys(out))


def parse_fractions(text: str) -> tuple[float, ...]:
    """A comma list of single-support fractions in (0, 1]."""
    out = []
    for item in (i.strip() for i in text.split(",")):
        try:
            value = float(item)
        except ValueError:
            raise UserError(f"--single-support: {item!r} is not a number in (0, 1]") from None
        if not 0.0 < value <= 1.0:
            raise UserError(f"--single-support: {item!r} must lie in (0, 1]")
        out.append(value)
    return tuple(dict.fromkeys(out))


def make_spec(*, model_name: str, speeds: str, variants: str, free: bool, step_length: str,
              single_support: str, knots: str | None = None, step_time: str = "free",
              problem: dict[str, Any] | None = None) -> SweepSpec:
    """The sweep of the CLI's options; ``problem`` holds further :class:`GaitOptions` fields
    shared by every point (formulation, cost, control model, ...); ``knots`` None keeps
    the default grid (or ``problem``'s)."""
    from gaitopt.gait.api import as_model

    model = as_model(model_name)
    try:
        return SweepSpec(model=model, speeds=parse_speeds(speeds),
                         variants=parse_variants(variants), free_speed=free,
                         step_lengths=parse_step_lengths(step_length),
                         step_times=parse_step_lengths(step_time, option="--step-time",
                                                       unit="s", quantity="time"),
                         single_support=parse_fractions(single_support),
                         base=GaitOptions(**{**(problem or {}), **(
                             {} if knots is None else {"knots": parse_knots(knots)})}))
    except SweepSpecError as exc:
        raise UserError(str(exc)) from None
