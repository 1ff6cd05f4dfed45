"""The least hip and knee torque bound with which a model runs at a given speed (issue 28).

The five-link biped's run is infeasible from 150 m/min on with the paper's 50 N m hip and knee
bounds (docs/running.md). For each speed this bisects on a factor ``f`` of the hip and knee
torque bounds (every actuator on a joint whose name starts with ``hip`` or ``knee``; the
ankle bounds are kept): a model file is written from the built-in model with those bounds
times ``f`` (:func:`scaled_model_file`), and the default command

    gaitopt solve --model FILE --gait run --speed V -o FILE.gait.json

is run on it. A factor *runs* when that solve converges (a gait file is written with
``success``; exit status 0, or 3 where only the 1 % accuracy was not reached, which the
table says). The bracket starts at ``[1, 2]`` and doubles its upper end until it runs; then
``--steps`` bisections (the bracket halves each time; 5 steps: to 1/32 of its width). The
answer is the bracket ``[f_lo, f_hi]``: ``f_lo`` failed, ``f_hi`` ran, with ``gaitopt verify``
on ``f_hi``'s gait. A local solver's failure is no proof of infeasibility: bisection assumes
that a larger bound never fails where a smaller one ran, which the printed trail lets one
check.

Run: ``python bench/run_torque_bounds.py [--model five-link] [--speeds 150 240] [--steps 5]
[-o out/run-torque] [--json FILE]`` (speeds in m/min). Prints one line per solve (factor,
exit status, wall time, the last stage) and a Markdown table, with the load average.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from gaitopt.gait.record.file import Gait
from gaitopt.robot import load_model
from gaitopt.robot.loader import model_to_yaml
from gaitopt.robot.model import RobotModel

#: Joint-name prefixes of the actuators whose bounds are scaled.
SCALED = ("hip", "knee")


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def scaled_model(model: RobotModel, factor: float) -> RobotModel:
    """``model`` with the bounds of its hip and knee actuators (:data:`SCALED`) times
    ``factor`` and the name ``<name>-hk<factor>``."""
    actuators = tuple(
        dataclasses.replace(a, limits=(a.limits[0] * factor, a.limits[1] * factor))
        if a.joint is not None and a.joint.startswith(SCALED) else a
        for a in model.actuators)
    return dataclasses.replace(model, name=f"{model.name}-hk{factor:.4f}", actuators=actuators)


def scaled_model_file(model: RobotModel, factor: float, folder: Path) -> Path:
    """Write :func:`scaled_model` to ``folder/<name>.yaml`` and return the path."""
    scaled = scaled_model(model, factor)
    path = folder / f"{scaled.name}.yaml"
    path.write_text(model_to_yaml(scaled))
    return path


def gaitopt(*args: str) -> tuple[int, float, str]:
    """Run ``python -m gaitopt ARGS``: exit status, wall time (s), the output's last lines."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "gaitopt", *args], capture_output=True,
                          text=True, check=False)
    lines = (done.stdout + done.stderr).strip().splitlines()
    return done.returncode, time.perf_counter() - start, "\n".join(lines[-2:])


def runs(model: RobotModel, factor: float, speed: float, folder: Path,
         trail: list[dict[str, Any]]) -> bool:
    """Whether the default run command converges with the bounds times ``factor``."""
    path = scaled_model_file(model, factor, folder)
    out = folder / f"{path.stem}-{speed:g}.gait.json"
    out.unlink(missing_ok=True)
    status, wall, tail = gaitopt("solve", "--model", str(path), "--gait", "run", "--speed",
                                 f"{speed:g}m/min", "-o", str(out))
    ok = out.exists() and Gait.load(out).success
    trail.append({"speed_m_min": speed, "factor": factor, "exit": status, "wall_s": wall,
                  "ran": ok, "file": str(out)})
    print(f"  {speed:g} m/min, factor {factor:.4f} ({factor * 50:.1f} N m): exit {status}, "
          f"{'runs' if ok else 'fails'}, {wall:.0f} s (load {load_average()})\n    "
          + tail.replace("\n", "\n    "), flush=True)
    return ok


def least_factor(model: RobotModel, speed: float, steps: int, folder: Path,
                 trail: list[dict[str, Any]]) -> tuple[float, float]:
    """The bracket ``(f_lo, f_hi)`` of the least factor that runs at ``speed`` (m/min)."""
    lo, hi = 1.0, 2.0
    if runs(model, lo, speed, folder, trail):
        return 0.0, lo
    while not runs(model, hi, speed, folder, trail):
        lo, hi = hi, 2.0 * hi
        if hi > 64:
            raise SystemExit(f"no factor up to {lo:g} runs at {speed:g} m/min")
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if runs(model, mid, speed, folder, trail):
            hi = mid
        else:
            lo = mid
    return lo, hi


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--model", default="five-link")
    p.add_argument("--speeds", type=float, nargs="+", default=[150.0, 240.0],
                   help="m/min")
    p.add_argument("--steps", type=int, default=5, help="bisections per speed")
    p.add_argument("-o", "--out", default="out/run-torque")
    p.add_argument("--json", help="write the trail and the table here")
    a = p.parse_args()
    folder = Path(a.out)
    folder.mkdir(parents=True, exist_ok=True)
    model = load_model(a.model)
    base = {act.name: act.limits[1] for act in model.actuators}
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    print(f"{a.model}: torque bounds {base}; {when}, load {load_average()}", flush=True)
    trail: list[dict[str, Any]] = []
    rows = []
    for speed in a.speeds:
        lo, hi = least_factor(model, speed, a.steps, folder, trail)
        last = next(t for t in reversed(trail) if t["ran"] and t["factor"] == hi)
        status, _, tail = gaitopt("verify", last["file"])
        gait = Gait.load(last["file"])
        rows.append({"speed_m_min": speed, "factor_lo": lo, "factor_hi": hi,
                     "verify": "pass" if status == 0 else tail.splitlines()[-1],
                     "step_length": gait.step_length, "cost": gait.cost_value,
                     "exit": last["exit"]})
    hk = max(abs(act.limits[1]) for act in model.actuators
             if act.joint is not None and act.joint.startswith(SCALED))
    print(f"\nload {load_average()}\n")
    print("| speed [m/min] | least factor (bracket) | hip/knee bound [N m] | step [m] | cost "
          "| exit | verify |")
    print("| ---: | --- | --- | ---: | ---: | ---: | --- |")
    for r in rows:
        print(f"| {r['speed_m_min']:g} | {r['factor_lo']:.3f}-{r['factor_hi']:.3f} | "
              f"{hk * r['factor_lo']:.1f}-{hk * r['factor_hi']:.1f} | {r['step_length']:.3f} | "
              f"{r['cost']:.1f} | {r['exit']} | {r['verify']} |")
    if a.json:
        Path(a.json).write_text(json.dumps({"trail": trail, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
