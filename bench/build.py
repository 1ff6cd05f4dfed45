"""Build time of a transcription per mesh, this branch against a reference revision, one run.

Issue 27 item 1: a new grid (or a round of automatic refinement) should cost an evaluation,
not a derivation. For each model and mesh this measures, in fresh processes of this run, one
for this branch's sources and one for the reference revision's (``--reference``, default
``main``: its ``src`` extracted with ``git archive``, the same interpreter and packages):

* ``build``: :func:`gaitopt.gait.solve.transcriptions.transcription_for` of the walking problem on
  the mesh plus its IPOPT solver, in a process that has already built another grid of the
  same problem (the symbolic functions and the compiled point libraries loaded, as in a
  staged solve or a refinement round); best of ``--repeat``;
* the peak resident memory of each measuring process (``process_memory``);
* the solver functions' evaluation times on the finest mesh (ms per call at the naive
  guess), since a cheaper build must not cost the iterations more;
* with ``--solves``: whole ``gaitopt solve`` processes, new against reference: wall time,
  peak RSS, the cost and the iterations of every stage (the same NLP: the costs agree to the
  solver's accuracy and the iterations to rounding).

Times are CPU seconds of the measuring process (the machine is shared; wall times are
printed for the whole solves too). Run: ``python bench/build.py [--reference main]
[--repeat 3] [--rounds 2] [--solves]``. Set
``GAITOPT_CACHE`` to a private folder; the first run of a revision compiles its point
libraries (a warm-up process per model does that before anything is timed).
"""

from __future__ import annotations

import argparse
import ast
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
#: The meshes measured, per model: the warm-up grid first (built, not reported).
MESHES: dict[str, list[tuple[int, int]]] = {
    "five-link": [(8, 5), (16, 6), (40, 10), (80, 20)],
    "seven-link": [(12, 8), (24, 16), (36, 24), (54, 36)],
}
#: The whole-process solves compared (``gaitopt solve`` arguments).
SOLVES: list[tuple[str, list[str]]] = [
    ("five-link default", []),
    ("five-link full 40+10", ["--formulation", "full", "--knots", "40,10"]),
    ("seven-link 60 m/min 24+16", ["--model", "seven-link", "--speed", "60m/min", "--knots",
                                   "24,16"]),
    ("seven-link 60 m/min (refined)", ["--model", "seven-link", "--speed", "60m/min"]),
]


def child(model_name: str, meshes: list[tuple[int, int]], repeat: int) -> dict[str, Any]:
    """In a fresh process: build the first mesh (warm-up), then each other mesh ``repeat``
    times (the transcription cache emptied in between); the best times and the peak RSS."""
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.options.model_defaults import options_for_model
    from gaitopt.gait.solve import transcriptions
    from gaitopt.process_memory import peak_resident_bytes
    from gaitopt.robot import load_model

    model = load_model(model_name)
    options = options_for_model(model, GaitOptions(knots=meshes[0]))

    def build(knots: tuple[int, int]) -> float:
        start = time.process_time()
        tr = transcriptions.transcription_for(model, options, knots)
        tr.solver(tr.options)
        return time.process_time() - start

    out: dict[str, Any] = {"warm-up": build(meshes[0])}
    for knots in meshes[1:]:
        times = []
        for _ in range(repeat):
            transcriptions._CACHE.clear()
            times.append(build(knots))
        out[f"{knots[0]}+{knots[1]}"] = min(times)
    # The solver functions of the last mesh at its naive guess (ms per call, best of 5
    # batches of 20): the evaluations an IPOPT iteration pays.
    import numpy as np

    tr = transcriptions.transcription_for(model, options, meshes[-1])
    solver = tr.solver(tr.options)
    w = tr.initial_guess() / tr.nlp.d_w
    lam = np.ones(tr.nlp.lbg.size)
    for kind in ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l"):
        fn = solver.get_function(kind)
        args = [w, []] + ([0.7, lam] if kind == "nlp_hess_l" else [])
        best = math.inf
        for _ in range(7):
            start = time.process_time()
            for _ in range(20):
                fn(*args)
            best = min(best, (time.process_time() - start) / 20)
        out[kind] = 1e3 * best
    out["peak_rss_mb"] = peak_resident_bytes() / 2**20
    return out


def reference_sources(rev: str, into: Path) -> Path:
    """The ``src`` folder of git revision ``rev``, extracted into ``into``."""
    archive = subprocess.run(["git", "-C", str(REPO), "archive", rev, "src"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return into / "src"


def run(src: Path, *args: str
        ) -> tuple[subprocess.CompletedProcess[str], float, float, float]:
    """``python args`` with ``src`` first on the path: the process, its wall time, its peak
    RSS (MB) and its CPU time (s; both from a wrapper that reports them at exit)."""
    env = dict(os.environ, PYTHONPATH=str(src))
    with tempfile.NamedTemporaryFile(suffix=".rss") as rss:
        wrapper = ("import atexit, resource, runpy, sys; "
                   f"atexit.register(lambda: open({rss.name!r}, 'w').write("
                   "repr((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, "
                   "resource.getrusage(resource.RUSAGE_SELF).ru_utime + "
                   "resource.getrusage(resource.RUSAGE_SELF).ru_stime)))); "
                   "sys.argv = sys.argv[1:]; runpy.run_path(sys.argv[0], run_name='__main__')"
                   if args[0].endswith(".py") else
                   "import atexit, resource, runpy, sys; "
                   f"atexit.register(lambda: open({rss.name!r}, 'w').write("
                   "repr((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, "
                   "resource.getrusage(resource.RUSAGE_SELF).ru_utime + "
                   "resource.getrusage(resource.RUSAGE_SELF).ru_stime)))); "
                   "sys.argv = ['gaitopt', *sys.argv[1:]]; "
                   "runpy.run_module('gaitopt', run_name='__main__')")
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", wrapper, *args], env=env,
                              capture_output=True, text=True)
        wall = time.perf_counter() - start
        text = Path(rss.name).read_text()
        peak, cpu = ast.literal_eval(text) if text else (math.nan, math.nan)
    return proc, wall, peak / 1024, cpu


def builds(variants: dict[str, Path], repeat: int, rounds: int) -> None:
    """The build table: per model and mesh, reference and this branch, and the ratio (CPU
    seconds of the measuring process: the machine is shared)."""
    print("| model | mesh | reference build CPU s | this branch build CPU s | "
          "this / reference |")
    print("| --- | --- | --- | --- | --- |")
    peaks: dict[tuple[str, str], float] = {}
    evaluations: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {}
    for model, meshes in MESHES.items():
        results: dict[str, dict[str, Any]] = {}
        for _ in range(rounds):  # reference and this branch alternately, the best of each
            for name, src in variants.items():
                proc, *_ = run(src, str(Path(__file__).resolve()), "--child", model,
                                 *[f"{a},{b}" for a, b in meshes], "--repeat", str(repeat))
                if proc.returncode != 0:
                    raise RuntimeError(f"{name} {model} failed:\n{proc.stderr[-3000:]}")
                got = json.loads(proc.stdout.strip().splitlines()[-1])
                old = results.setdefault(name, got)
                results[name] = {k: min(v, old[k]) for k, v in got.items()}
                results[name]["peak_rss_mb"] = max(got["peak_rss_mb"], old["peak_rss_mb"])
            peaks[(model, "reference")] = results["reference"]["peak_rss_mb"]
            peaks[(model, "this branch")] = results["this branch"]["peak_rss_mb"]
        ref, new = results["reference"], results["this branch"]
        evaluations[model] = (ref, new)
        for key in ["warm-up", *[f"{a}+{b}" for a, b in meshes[1:]]]:
            label = f"{key} (first grid)" if key == "warm-up" else key
            print(f"| {model} | {label} | {ref[key]:.3f} | {new[key]:.3f} | "
                  f"{new[key] / ref[key]:.2f} |")
    print()
    print("| model | reference peak RSS MB | this branch peak RSS MB |")
    print("| --- | --- | --- |")
    for model in MESHES:
        print(f"| {model} | {peaks[(model, 'reference')]:.0f} | "
              f"{peaks[(model, 'this branch')]:.0f} |")
    print()
    print("| model, mesh | function | reference CPU ms | this branch CPU ms | "
          "this / reference |")
    print("| --- | --- | --- | --- | --- |")
    for model, meshes in MESHES.items():
        ref, new = evaluations[model]
        for kind in ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l"):
            print(f"| {model} {meshes[-1][0]}+{meshes[-1][1]} | `{kind}` | {ref[kind]:.3f} | "
                  f"{new[kind]:.3f} | {new[kind] / ref[kind]:.2f} |")


def solves(variants: dict[str, Path], repeat: int, only: str = "") -> None:
    """Whole ``gaitopt solve`` processes, reference against this branch, run alternately
    (reference, this branch, reference, ...): the best of ``repeat`` each."""
    print()
    print("| solve | variant | wall s (best) | CPU s (best) | peak RSS MB | cost | "
          "stages: iterations | relative cost difference |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory(prefix="gaitopt-build-") as tmp:
        for label, args in SOLVES:
            if only not in label:
                continue
            walls: dict[str, list[float]] = {name: [] for name in variants}
            cpus: dict[str, list[float]] = {name: [] for name in variants}
            peaks: dict[str, float] = dict.fromkeys(variants, 0.0)
            data: dict[str, Any] = {}
            for r in range(repeat):
                for name, src in variants.items():
                    out = Path(tmp) / f"{name.replace(' ', '_')}-{r}.gait.json"
                    proc, wall, rss, cpu = run(src, "solve", *args, "-o", str(out))
                    if proc.returncode not in (0, 3):
                        raise RuntimeError(f"{label} {name} failed:\n{proc.stderr[-3000:]}")
                    walls[name].append(wall)
                    cpus[name].append(cpu)
                    peaks[name] = max(peaks[name], rss)
                    data[name] = json.loads(out.read_text())
            ref_cost = data["reference"]["cost"]["value"]
            for name in variants:
                cost = data[name]["cost"]["value"]
                its = ",".join(str(st["iterations"]) for st in data[name]["solver"]["stages"])
                diff = ("" if name == "reference" else
                        f"{abs(cost - ref_cost) / abs(ref_cost):.1e}")
                print(f"| {label} | {name} | {min(walls[name]):.2f} | {min(cpus[name]):.2f} | "
                      f"{peaks[name]:.0f} | {cost:.6f} | {its} | {diff} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    parser.add_argument("--reference", default="main")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=2,
                        help="measuring processes per variant and model, alternately")
    parser.add_argument("--solves", action="store_true",
                        help="also time whole gaitopt solve processes")
    parser.add_argument("--solve-repeat", type=int, default=2)
    parser.add_argument("--no-builds", action="store_true")
    parser.add_argument("--only-solves", default="",
                        help="only the solves whose label contains this text")
    args = parser.parse_args()
    if args.child:
        meshes = [tuple(int(k) for k in m.split(",")) for m in args.child[1:]]
        print(json.dumps(child(args.child[0], meshes, args.repeat)))  # type: ignore[arg-type]
        return
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-") as tmp:
        ref = reference_sources(args.reference, Path(tmp))
        commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short",
                                 args.reference], capture_output=True, text=True).stdout.strip()
        here = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True).stdout.strip()
        print(f"reference {args.reference} ({commit}), this branch {here}, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores")
        variants = {"reference": ref, "this branch": REPO / "src"}
        if not args.no_builds:
            builds(variants, args.repeat, args.rounds)
        if args.solves:
            solves(variants, args.solve_repeat, args.only_solves)


if __name__ == "__main__":
    main()
