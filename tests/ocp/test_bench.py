"""bench/ocp.py runs (smoke test on the smallest case; the figures are in docs/ocp.md)."""

from __future__ import annotations

import importlib.util
from pathlib import Path


def test_bench_smoke() -> None:
    path = Path(__file__).resolve().parents[2] / "bench" / "ocp.py"
    spec = importlib.util.spec_from_file_location("bench_ocp", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.main(["--problems", "double_integrator", "two_phase_jump", "--sizes", "4",
                        "--modes", "sx", "mx", "--repeat", "1"])
    assert len(rows) == 4
    assert all(r["status"] == "Solve_Succeeded" and r["err"] < 1e-9 for r in rows)
