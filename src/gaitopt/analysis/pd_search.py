"""PD gains that minimise the spectral radius of a gait's return map (``--pd auto``).

The spectral radius ``rho(kp, kd)`` is :func:`gaitopt.analysis.stability.gait_stability` with
PD tracking, at the gait's start state, without the finite-difference check and with the
integrator's tolerance :data:`SEARCH_RTOL` (1e-6: on the seven-link walk at 60 m/min and the
five-link walk at 12 m/min it agrees with the default 1e-10 to 2e-7). The search:

1. a log grid of 4 x 4, ``kp`` in :data:`KP_GRID` (300 to 10000 N m/rad) times ``kd`` in
   :data:`KD_GRID` (15 to 500 N m s/rad); lower gains did not hold any gait here (the
   seven-link walk at 60 m/min: 5 to 7.6 at kp 100) and their steps are the slowest to
   simulate;
2. a local refinement from the best grid point: a compass search in ``(log kp, log kd)``,
   steps of a factor :data:`REFINE_FACTOR` (at most :data:`MOVES_PER_ROUND` moves), then
   halved in the log, :data:`REFINE_ROUNDS` rounds, within :data:`KP_BOX` x :data:`KD_BOX`
   (larger gains keep lowering the radius of some gaits, but they are not a robot's).

The radius is far from smooth in the gains (the five-link walk: 0.91 at kp 1000, 1.02 at
1100, kd 60; the seven-link walk: 0.20 at 1000, 150 and 1.6 at 2154, 137), so the search
finds a good pair, not the best one.

A pair whose simulated step fails (it never lands) counts as ``rho = inf``. Each evaluation
prints a line through ``progress``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gaitopt.analysis.return_map import StepSimulationError
from gaitopt.analysis.stability import StabilityError, gait_stability
from gaitopt.gait.record.file import Gait

KP_GRID: tuple[float, ...] = (300.0, 1000.0, 3000.0, 10000.0)
KD_GRID: tuple[float, ...] = (15.0, 50.0, 150.0, 500.0)
#: The box of the refinement: (kp, kd) bounds.
KP_BOX: tuple[float, float] = (100.0, 10000.0)
KD_BOX: tuple[float, float] = (10.0, 500.0)
REFINE_FACTOR = 1.7
REFINE_ROUNDS = 2
MOVES_PER_ROUND = 2
SEARCH_RTOL = 1e-6


@dataclass(frozen=True)
class GainSearch:
    """The best gains ``pd = (kp, kd)``, their spectral radius and verdict, and every
    evaluated ``(kp, kd, rho)``."""

    pd: tuple[float, float]
    spectral_radius: float
    stable: bool
    evaluations: tuple[tuple[float, float, float], ...]


def spectral_radius(gait: Gait, pd: tuple[float, float], *, rtol: float = SEARCH_RTOL) -> float:
    """``rho`` of the return map with PD gains ``pd`` at the gait's start (inf if the
    simulated step fails)."""
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            report = gait_stability(gait, pd=pd, check=False, rtol=rtol)
    except (StepSimulationError, StabilityError, np.linalg.LinAlgError):
        return math.inf
    rho = report.spectral_radius
    return rho if np.isfinite(rho) else math.inf


def search_gains(gait: Gait, *, kp_grid: tuple[float, ...] = KP_GRID,
                 kd_grid: tuple[float, ...] = KD_GRID, rounds: int = REFINE_ROUNDS,
                 margin: float = 1e-3,
                 progress: Callable[[str], None] | None = None) -> GainSearch:
    """The gains that minimise the spectral radius (module docstring); ``stable`` if it is
    below ``1 - margin``."""
    seen: dict[tuple[float, float], float] = {}

    def rho(kp: float, kd: float) -> float:
        key = (round(kp, 6), round(kd, 6))
        if key not in seen:
            seen[key] = spectral_radius(gait, key)
            if progress is not None:
                progress(f"  PD {key[0]:.4g},{key[1]:.4g}: spectral radius {seen[key]:.4g}")
        return seen[key]

    for kp in kp_grid:
        for kd in kd_grid:
            rho(kp, kd)
    best = min(seen, key=lambda k: seen[k])
    factor = math.log(REFINE_FACTOR)
    for _ in range(rounds):
        for _ in range(MOVES_PER_ROUND):
            kp, kd = best
            moves = [(float(np.clip(kp * math.exp(a * factor), *KP_BOX)),
                      float(np.clip(kd * math.exp(b * factor), *KD_BOX)))
                     for a, b in ((1, 0), (-1, 0), (0, 1), (0, -1))]
            for m in moves:
                rho(*m)
            candidate = min(seen, key=lambda k: seen[k])
            if seen[candidate] < seen[best]:
                best = candidate
                continue
            break
        factor /= 2.0
    value = seen[best]
    return GainSearch(pd=best, spectral_radius=value, stable=value < 1.0 - margin,
                      evaluations=tuple((k[0], k[1], v) for k, v in seen.items()))
