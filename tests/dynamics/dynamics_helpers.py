"""Helpers shared by the dynamics tests: random planar trees, random states, comparisons.

(A module with a unique name, so ``import dynamics_helpers`` cannot pick up another test
folder's ``conftest``.)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gaitopt.robot import RobotModel, model_from_dict


def random_tree(seed: int, n_links: int | None = None) -> RobotModel:
    """A random planar tree: random parents, joint points, directions, masses, centres of
    mass off the axis, inertias, gravity, and two to three contacts on random non-base links.
    """
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 8)) if n_links is None else n_links
    links: list[dict[str, Any]] = []
    for i in range(n):
        length = float(rng.uniform(0.2, 1.0))
        entry: dict[str, Any] = {
            "name": f"l{i}", "parent": None if i == 0 else f"l{int(rng.integers(0, i))}",
            "direction": str(rng.choice(["up", "down"])), "length": length,
            "mass": float(rng.uniform(0.5, 10.0)),
            "com": [float(rng.uniform(0.0, length)), float(rng.uniform(-0.1, 0.1))],
            "inertia": float(rng.uniform(0.01, 1.0)),
        }
        if i > 0:
            entry["joint"] = {"name": f"j{i}", "limits": [-3.0, 3.0],
                              "at": [float(rng.uniform(-0.3, 0.8)),
                                     float(rng.uniform(-0.2, 0.2))]}
        links.append(entry)
    n_contacts = min(n - 1, int(rng.integers(2, 4)))
    carriers = rng.choice(np.arange(1, n), size=n_contacts, replace=False)
    contacts = [{"name": f"c{k}", "link": f"l{int(i)}",
                 "at": [float(rng.uniform(0.1, 1.0)), float(rng.uniform(-0.1, 0.1))]}
                for k, i in enumerate(carriers)]
    actuators: list[dict[str, Any]] = [
        {"name": f"a{i}", "joint": f"j{i}", "limits": [-100, 100]} for i in range(1, n)]
    actuators += [{"name": f"ankle_{c['name']}", "contact": c["name"], "limits": [-50, 50]}
                  for c in contacts]
    gravity = [float(rng.uniform(-2.0, 2.0)), float(rng.uniform(-12.0, -5.0))]
    return model_from_dict({"name": f"random-{seed}", "gravity": gravity, "links": links,
                            "contacts": contacts, "actuators": actuators})


def random_state(rng: np.random.Generator, nq: int, scale: float = 1.0
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random ``q`` (angles in [-pi, pi], positions in [-2, 2]), ``qd`` and ``qdd``."""
    q = rng.uniform(-np.pi, np.pi, nq)
    q[:2] = rng.uniform(-2.0, 2.0, 2)
    return q, scale * rng.normal(size=nq), scale * rng.normal(size=nq)


def assert_close(actual: Any, expected: Any, rtol: float = 1e-9, what: str = "") -> None:
    """``|actual - expected| <= rtol * max(1, |expected|)`` entrywise-max."""
    a, e = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert a.shape == e.shape, f"{what}: shape {a.shape} != {e.shape}"
    err = float(np.max(np.abs(a - e))) if a.size else 0.0
    scale = max(1.0, float(np.max(np.abs(e)))) if e.size else 1.0
    assert err <= rtol * scale, f"{what}: max error {err:.3g} > {rtol:g} * {scale:.3g}"


def well_conditioned(model: RobotModel, q: np.ndarray, contacts: Any,
                     limit: float = 1e7) -> bool:
    """False at near-singular contact configurations (cond(J M^-1 J^T) > limit), where any
    constrained solution is only accurate to about cond * machine epsilon."""
    from gaitopt.dynamics import contact_jacobian, crba

    jac = contact_jacobian(model, q, contacts)
    return bool(np.linalg.cond(jac @ np.linalg.solve(crba(model, q), jac.T)) < limit)
