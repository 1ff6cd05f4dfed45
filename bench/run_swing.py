"""The swing of a run: its distal joint's angle over one swing, as ``swing.reversals`` counts it.

For each gait file given (``LABEL=FILE``), every leg's swing joined across the period's end
(:func:`gaitopt.analysis.checks.swing.swings`: a run's swing is its own flight, the other
leg's stance and the next flight), plotted against the time since the swing began (deg), with
the turns the check counts (2 degree hysteresis) and the foot's lowest height over the swing.
Prints one line per file: the turns, the joint's range and the swing foot's lowest point
between its own liftoff and landing (the first and last 10 % of the swing left out, where
the foot leaves and meets the ground).

Run: ``python bench/run_swing.py -o docs/figures/run_swing.png "five-link 120, y >= 0=a.gait.json"
"five-link 120, default=b.gait.json" ...`` (docs/running.md, "The swing of a run").
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gaitopt.analysis.checks.swing import swings  # noqa: E402
from gaitopt.gait.record.file import Gait  # noqa: E402


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gaits", nargs="+", help="LABEL=FILE of a gait file")
    parser.add_argument("-o", "--output", required=True, help="the figure (PNG)")
    args = parser.parse_args(argv)
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    for item in args.gaits:
        label, _, path = item.rpartition("=")
        gait = Gait.load(path)
        # the longest swing: the one joined across the period's end
        swing = max(swings(gait), key=lambda s: s.t.size)
        t = swing.t - swing.t[0]
        angle = np.degrees(swing.angle)
        inner = slice(t.size // 10, t.size - t.size // 10)
        lowest = float(np.min(swing.height[inner]))
        print(f"{label}: {swing.joint} {swing.reversals} turns over {t[-1]:.3f} s, range "
              f"{angle.min():.1f} to {angle.max():.1f} deg, foot's lowest point "
              f"{1000 * lowest:.1f} mm")
        ax = axes[0] if swing.joint.startswith("knee") else axes[1]
        ax.plot(t / t[-1], angle, label=f"{label}: {swing.reversals} turns")
    for ax, joint in zip(axes, ("swing knee (five-link)", "swing ankle (seven-link)"),
                         strict=True):
        ax.set_title(joint)
        ax.set_xlabel("time since the swing began / the swing's duration")
        ax.set_ylabel("angle [deg]")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.output, dpi=90)


if __name__ == "__main__":
    main()
