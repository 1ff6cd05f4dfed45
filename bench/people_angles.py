"""People's joint angles (issue 28, item 3): the seven-link model's optimum at people's speed
under each cost, its sagittal hip, knee and ankle angles over one stride against published
values of people walking at natural cadence (docs/feet.md, "People's joint angles").

For each cost (default: paper, work, metabolic) it solves, one at a time,
``gaitopt solve --model seven-link --speed 80m/min --cost COST [extra] -o DIR/COST.gait.json``
(skipped when the file exists, unless ``--resolve``), runs ``gaitopt verify`` on it, then
computes the four measures of :mod:`gaitopt.analysis.joint_angles` (stance knee flexion peak,
swing knee flexion peak, hip and ankle excursions, deg) and their distance from people's (the
sum of the relative errors), prints a Markdown table, and draws
:func:`gaitopt.viz.joint_angles.joint_angles_figure`.

Run: ``python bench/people_angles.py [-o out/angles] [--costs paper work metabolic]
[--speed 80m/min] [--extra COST=ARGS ...] [--figure docs/figures/people_joint_angles.png]
[--resolve] [--max-iter COST=N ...]``, or on gait files already solved: ``python
bench/people_angles.py --gait LABEL=FILE ...`` (no solve, no verify).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from gaitopt.analysis.joint_angles import (
    MEASURES,
    PEOPLE,
    distance_from_people,
    joint_angle_stride,
    people_measures,
    relative_errors,
)
from gaitopt.gait.record.file import Gait
from gaitopt.viz.joint_angles import joint_angles_figure
from gaitopt.viz.style import png_bytes


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def gaitopt(*args: str) -> tuple[int, float, str]:
    """Run ``python -m gaitopt ARGS``; exit status, wall time (s) and the output's tail."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "gaitopt", *args], capture_output=True,
                          text=True, check=False)
    tail = "\n".join((done.stdout + done.stderr).strip().splitlines()[-3:])
    return done.returncode, time.perf_counter() - start, tail


def solve_api(path: Path, cost: str, speed: str, clearance: float | None, max_iter: int
              ) -> tuple[int, float, str]:
    """The solve of ``gaitopt solve --model seven-link --speed SPEED --cost COST
    [--clearance C]`` through the Python API, with IPOPT's limit per stage ``max_iter``
    (the CLI has 1000; the cost study 3000, ``gaitopt.study.cost_study.STUDY_MAX_ITER``):
    :class:`GaitOptions` left to the model's defaults otherwise, as the CLI leaves them."""
    from gaitopt.gait.api import solve_staged_run
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.solve.record import gait_from_run
    from gaitopt.units import parse_speed

    start = time.perf_counter()
    options = GaitOptions(speed=parse_speed(speed), cost=cost,  # type: ignore[arg-type]
                          swing_clearance=clearance, max_iter=max_iter)
    solution = solve_staged_run("seven-link", options)
    wall = time.perf_counter() - start
    lines = [f"stage {st.line()}" for st in solution.stages]
    if not solution.success:
        return 1, wall, "\n".join(lines[-2:])
    gait_from_run(solution).save(path)
    return 0, wall, "\n".join(lines[-2:])


def solve_and_verify(out: Path, cost: str, speed: str, extra: list[str], resolve: bool,
                     max_iter: int | None = None) -> dict[str, object]:
    """One cost's solve (unless its file exists) and its verify; with ``max_iter``, through
    :func:`solve_api` (``extra`` then may hold only ``--clearance C``)."""
    path = out / f"{cost}.gait.json"
    row: dict[str, object] = {"cost": cost, "file": str(path),
                              "command": shlex.join(["gaitopt", "solve", "--model", "seven-link",
                                                     "--speed", speed, "--cost", cost, *extra,
                                                     "-o", str(path)])}
    if max_iter is not None:
        row["command"] = f"{row['command']}  (through the API, max_iter={max_iter})"
    if resolve or not path.exists():
        print(f"$ {row['command']}   (load {load_average()})", flush=True)
        if max_iter is None:
            status, wall, tail = gaitopt("solve", "--model", "seven-link", "--speed", speed,
                                         "--cost", cost, *extra, "-o", str(path))
        else:
            clearance = None
            if extra:
                if len(extra) != 2 or extra[0] != "--clearance":
                    raise SystemExit(f"--max-iter takes only --clearance C as extra, got {extra}")
                clearance = float(extra[1])
            status, wall, tail = solve_api(path, cost, speed, clearance, max_iter)
        row.update(solve_status=status, solve_wall_s=round(wall, 1), solve_tail=tail)
        print(f"  exit {status}, {wall:.0f} s\n{tail}", flush=True)
    status, wall, tail = gaitopt("verify", str(path))
    row.update(verify_status=status, verify="pass" if status == 0 else f"fails: {tail}")
    print(f"  verify: {row['verify']}", flush=True)
    return row


def measure_rows(gaits: list[tuple[str, Gait]]) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    for label, gait in gaits:
        m = people_measures(joint_angle_stride(gait))
        accuracy = gait.solver.get("accuracy") or {}
        rows.append({"label": label, "success": gait.success, "step_length": gait.step_length,
                     "estimate": accuracy.get("worst_estimate"),
                     "within_target": accuracy.get("within_target"),
                     "cost_smoothing": gait.options.get("cost_smoothing"),
                     "speed_m_min": 60 * gait.speed, "cost_value": gait.cost_value,
                     **m, "relative_errors": relative_errors(m),
                     "distance": distance_from_people(m)})
    return rows


def markdown(rows: list[dict[str, Any]]) -> str:
    head = ("| cost | stance knee flexion [deg] (at % of stride) | swing knee flexion [deg] "
            "| hip excursion [deg] | ankle excursion [deg] | distance | step | stance [% of "
            "stride] | largest estimate |")
    lines = [head, "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        cells = [f"{r[n]:.1f}" for n in MEASURES]
        cells[0] += f" ({r['stance_knee_flexion_percent']:.0f} %)"
        lines.append(f"| {r['label']} | " + " | ".join(cells) + f" | {r['distance']:.2f} | "
                     f"{r['step_length']:.3f} m | {r['stance_percent']:.1f} | "
                     + ("none" if r["estimate"] is None else f"{100 * r['estimate']:.2g} %")
                     + " |")
    people = [f"{lo:g}-{hi:g}" if hi > lo else f"about {lo:g}" for lo, hi in
              (PEOPLE[n] for n in MEASURES)]
    lines.append("| people (Winter 2009; Perry and Burnfield 2010) | " + " | ".join(people)
                 + " | 0 | | | |")
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("-o", "--out", default="out/angles", help="folder of the gait files")
    p.add_argument("--costs", nargs="+", default=["paper", "work", "metabolic"])
    p.add_argument("--speed", default="80m/min")
    p.add_argument("--extra", action="append", default=[], metavar="COST=ARGS",
                   help="more gaitopt solve arguments for one cost, e.g. "
                        "'work=--clearance 0.02'")
    p.add_argument("--gait", action="append", default=[], metavar="LABEL=FILE",
                   help="measure these gait files instead of solving")
    p.add_argument("--figure", default="docs/figures/people_joint_angles.png")
    p.add_argument("--json", help="write the rows here")
    p.add_argument("--resolve", action="store_true", help="solve even if the file exists")
    p.add_argument("--max-iter", metavar="COST=N", action="append", default=[],
                   help="COST=N: solve this cost through the API with IPOPT's limit N per "
                        "stage (the CLI's is 1000), e.g. metabolic=3000")
    a = p.parse_args()
    info = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "machine": f"{platform.node()}, {os.cpu_count()} cores, {platform.processor()}",
            "load_before": load_average()}
    runs: list[dict[str, object]] = []
    if a.gait:
        pairs = [g.split("=", 1) for g in a.gait]
    else:
        extra = {k: shlex.split(v) for k, v in (e.split("=", 1) for e in a.extra)}
        limits = {k: int(v) for k, v in (e.split("=", 1) for e in a.max_iter)}
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        for cost in a.costs:
            runs.append(solve_and_verify(out, cost, a.speed, extra.get(cost, []), a.resolve,
                                         limits.get(cost)))
        pairs = [[str(r["cost"]), str(r["file"])] for r in runs
                 if Path(str(r["file"])).exists()]  # a failed solve writes no file
    gaits = [(label, Gait.load(path)) for label, path in pairs]
    rows = measure_rows(gaits)
    info["load_after"] = load_average()
    print(markdown(rows))
    print(json.dumps(info))
    fig = joint_angles_figure(gaits, title=f"seven-link optimum at {a.speed} per cost: "
                                           "sagittal joint angles over one stride of leg 1")
    Path(a.figure).parent.mkdir(parents=True, exist_ok=True)
    Path(a.figure).write_bytes(png_bytes(fig))
    print(f"wrote {a.figure}")
    if a.json:
        Path(a.json).write_text(json.dumps({"info": info, "runs": runs, "rows": rows},
                                           indent=1))


if __name__ == "__main__":
    main()
