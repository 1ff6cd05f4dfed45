"""One measurement of ``bench/gait.py --targets``, run in its own process (fresh imports,
fresh NLP caches) with whichever gaitopt sources are first on PYTHONPATH: this branch's or
the reference revision's. Only the public API is used, so both can run it. Prints one JSON
line.

    python bench/gait_child.py warm KNOTS TRANSCRIPTION REPEAT GAIT_FILE [FORMULATION]
    python bench/gait_child.py first-warm KNOTS TRANSCRIPTION GAIT_FILE [FORMULATION]
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

SPEED = 0.2        # m/s, the paper's 12 m/min
SPEED_STEP = 1.05  # the "small speed change" of the warm starts


def paper_options(options_class: Any) -> Any:
    """``GaitOptions.paper`` (the paper's control model with the given grid) where it exists,
    else ``GaitOptions`` (whose defaults were the paper's)."""
    return getattr(options_class, "paper", options_class)


def share(solution: Any) -> tuple[int, float, float]:
    """IPOPT iterations, time in the NLP functions and IPOPT's total time over the stages."""
    results = [r for _, r in solution.stage_results]
    return (sum(r.iterations for r in results),
            sum(r.times.get("evaluations", 0.0) for r in results),
            sum(r.times.get("total", 0.0) for r in results))


CPU: dict[int, float] = {}


def timed(run: Any) -> tuple[float, Any]:
    """Wall time of ``run()`` and its result; its CPU time (this process, all threads) is
    kept in ``CPU[id(result)]``."""
    start, cpu = time.perf_counter(), time.process_time()
    out = run()
    CPU[id(out)] = time.process_time() - cpu
    return time.perf_counter() - start, out


def warm(knots: tuple[int, int], transcription: str, repeat: int, path: str,
         formulation: str = "reduced") -> dict[str, Any]:
    """Cold solve (NLPs built in this process), the same again, the gait saved to ``path``,
    then the warm start from it at +5 % speed (best of ``repeat``)."""
    from gaitopt.gait.api import solve_staged_run
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.record.file import Gait
    from gaitopt.gait.solve.record import gait_from_run
    from gaitopt.robot import load_model

    model = load_model("five-link")
    options = paper_options(GaitOptions)(speed=SPEED, knots=knots,  # type: ignore[arg-type]
                                         transcription=transcription, formulation=formulation)
    out: dict[str, Any] = {}
    wall, sol = timed(lambda: solve_staged_run(model, options))
    out["cold_first_s"] = wall
    wall, sol = timed(lambda: solve_staged_run(model, options))
    it, ev, tot = share(sol)
    out.update(cold_cached_s=wall, cold_iterations=it, cold_eval_s=ev, cold_ipopt_s=tot,
               cost=sol.result.objective, success=sol.success)
    gait = gait_from_run(sol)
    gait.save(path)
    saved = Gait.from_dict(gait.to_dict())
    faster = options.replace(speed=SPEED * SPEED_STEP)
    best = None
    for _ in range(repeat):
        wall, moved = timed(lambda: solve_staged_run(model, faster, warm_start=saved))
        if best is None or wall < best[0]:
            best = (wall, moved)
    assert best is not None
    it, ev, tot = share(best[1])
    out.update(warm_s=best[0], warm_cpu_s=CPU[id(best[1])], warm_iterations=it,
               warm_eval_s=ev, warm_ipopt_s=tot,
               warm_cost=best[1].result.objective, warm_success=best[1].success,
               warm_stages=[name for name, _ in best[1].stage_results])
    return out


def first_warm(knots: tuple[int, int], transcription: str, path: str,
               formulation: str = "reduced") -> dict[str, Any]:
    """The first warm start in this process from the gait file ``path`` (+5 % speed)."""
    start = time.perf_counter()
    from gaitopt.gait.api import solve_staged_run
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.record.file import Gait
    from gaitopt.robot import load_model

    imports = time.perf_counter() - start
    model = load_model("five-link")
    options = paper_options(GaitOptions)(speed=SPEED * SPEED_STEP,  # type: ignore[arg-type]
                                         knots=knots, transcription=transcription,
                                         formulation=formulation)
    wall, sol = timed(lambda: solve_staged_run(model, options, warm_start=Gait.load(path)))
    it, ev, tot = share(sol)
    return dict(imports_s=imports, first_warm_s=wall, first_warm_cpu_s=CPU[id(sol)],
                iterations=it, eval_s=ev, ipopt_s=tot,
                success=sol.success, stages=[name for name, _ in sol.stage_results])


def main() -> None:
    task, knots_text, transcription = sys.argv[1:4]
    k = tuple(int(v) for v in knots_text.split(","))
    knots = (k[0], k[1])
    if task == "warm":
        out = warm(knots, transcription, int(sys.argv[4]), sys.argv[5], *sys.argv[6:7])
    elif task == "first-warm":
        out = first_warm(knots, transcription, sys.argv[4], *sys.argv[5:6])
    else:
        raise SystemExit(f"unknown task {task!r}")
    print(json.dumps(out))


if __name__ == "__main__":
    main()
