"""Solve, inspect, verify, plot and save one energy-optimal walking gait (the Python API).

The same steps work in a Jupyter notebook, one section per cell: there a gait shows its
summary table when it is the value of a cell, ``gait.plot()`` is drawn inline and
``gait.animate()`` plays inline.

Run: ``python examples/walking.py [--speed 12] [--out walk] [--no-ankle] [--animate]``
(speed in m/min; writes ``<out>/walk.gait.json``, ``<out>/overview.png`` and, with
``--animate``, ``<out>/walk.gif``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gaitopt import Gait, GaitOptions, load_model, solve_gait, verify_gait


def main(argv: list[str] | None = None) -> Gait:
    """Run every section; returns the solved gait."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--speed", type=float, default=12.0, help="average speed, m/min")
    parser.add_argument("--out", type=Path, default=Path("walk"), help="output folder")
    parser.add_argument("--no-ankle", dest="ankle", action="store_false",
                        help="without ankle torques")
    parser.add_argument("--animate", action="store_true", help="also write walk.gif")
    args = parser.parse_args(argv)

    # -- model: the paper's five-link biped (or a model file: load_model("my-biped.yaml")) ----
    model = load_model("five-link")
    print(f"model {model.name}: q = {list(model.coordinate_names)}, "
          f"u = {[a.name for a in model.actuators]}, mass {model.total_mass:g} kg")

    # -- options: the variant, the speed (m/s; None = free); the default grid is 16 + 6 knots
    # with torques free to jump at the events (GaitOptions.paper(...): the paper's 8 + 5) -----
    options = GaitOptions(speed=args.speed / 60.0, ankle=args.ankle, impulse=True)
    print(f"options: {options.variant} at {args.speed:g} m/min, knots {options.knots}, "
          f"control model {options.control_model}")

    # -- solve: from a naive guess through the continuation stages ----------------------------
    gait = solve_gait(model, options)
    if not gait.success:
        raise SystemExit(f"the solve failed: {gait.status}")

    # -- inspect: parameters, the phases at their knots, the dense samples --------------------
    print(f"speed {gait.speed * 60:.2f} m/min, step length {gait.step_length:.4f} m, "
          f"step time {gait.step_time:.4f} s, cost {gait.cost_value:.2f} N^2 m s")
    actuators = [a.name for a in model.actuators]
    for phase in gait.phases:
        peak = dict(zip(actuators, abs(phase.u).max(axis=0).round(1).tolist(), strict=True))
        print(f"  {phase.name}: {phase.t.size} knots, contacts {list(phase.contacts)}, "
              f"peak torques {peak} N m")
    for event in gait.events:
        print(f"  {event.name} at t = {event.t:.4f} s: impulses "
              f"{ {c: v.round(4).tolist() for c, v in event.impulses.items()} } N s")

    # -- verify: independent checks of every field, by stable id -----------------------------
    report = verify_gait(gait)
    print(f"verify: {'passed' if report.passed else 'FAILED'} ({len(report.checks)} checks); "
          f"largest EOM residual {report.check('eom.residual').value:.1e}")
    if not report.passed:
        raise SystemExit(f"verify failed: {', '.join(report.failed_ids)}")

    # -- plot: angles, hip, torques over the step (gait.plot("torques"), "hip", ...) ----------
    args.out.mkdir(parents=True, exist_ok=True)
    figure = gait.plot()
    figure.savefig(args.out / "overview.png", dpi=90)
    if args.animate:
        gait.animate(args.out / "walk.gif", steps=2, fps=15)

    # -- save: the gait file (readable with Gait.load, gaitopt verify, gaitopt plot) ----------
    path = gait.save(args.out / "walk.gait.json")
    print(f"wrote {path} and {args.out / 'overview.png'}")
    return gait


if __name__ == "__main__":
    main()
