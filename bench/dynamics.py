"""Benchmark: compiled planar dynamics against Pinocchio's numeric ABA on the same model.

Prints, in one run:

* the time to generate and compile C code for the dynamics Functions of a model (fresh cache)
  and to get them again from the on-disk cache (as a next run would);
* the time per evaluation of our forward dynamics, single- and double-support contact dynamics
  and impact map, compiled and evaluated in batch through a mapped compiled Function
  (``f.map(N)``), so Python overhead is paid once per N evaluations;
* Pinocchio's numeric ABA on the same model: per call from Python, and per call without
  Python overhead (a small C++ timing program compiled against the Pinocchio headers that the
  ``pin`` wheel ships under ``site-packages/cmeel.prefix``, with the Eigen headers that CasADi
  ships; cached next to the other compiled code);
* ratios against Pinocchio's ABA.

Run: ``PYTHONPATH=src python bench/dynamics.py [--model five-link] [--batch 20000]``.
Set ``GAITOPT_CACHE`` to choose the cache folder.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import casadi as ca
import numpy as np

from gaitopt import codegen
from gaitopt.dynamics import aba, functions
from gaitopt.robot import RobotModel, load_model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "dynamics"))

CPP_SOURCE = r"""
// Times pinocchio::aba on a planar model read from argv[1]; prints ns per call and a check.
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <chrono>
#include <fstream>
#include <iostream>
#include <vector>
using namespace pinocchio;
int main(int argc, char** argv) {
  std::ifstream in(argv[1]);
  int n_links, n_states, repeats; double gx, gy;
  in >> n_links >> gx >> gy >> n_states >> repeats;
  Model model;
  model.gravity.linear() << gx, gy, 0.0;
  JointIndex jx = model.addJoint(0, JointModelPX(), SE3::Identity(), "x");
  JointIndex jy = model.addJoint(jx, JointModelPY(), SE3::Identity(), "y");
  std::vector<JointIndex> joint(n_links);
  for (int i = 0; i < n_links; ++i) {
    int parent; double ox, oy, m, cx, cy, inertia;
    in >> parent >> ox >> oy >> m >> cx >> cy >> inertia;
    SE3 placement(Eigen::Matrix3d::Identity(), Eigen::Vector3d(ox, oy, 0.0));
    JointIndex p = parent < 0 ? jy : joint[parent];
    joint[i] = model.addJoint(p, JointModelRZ(), placement, "j" + std::to_string(i));
    model.appendBodyToJoint(joint[i], Inertia(m, Eigen::Vector3d(cx, cy, 0.0),
                                               Eigen::Matrix3d::Identity() * inertia));
  }
  Data data(model);
  const int nv = model.nv;
  std::vector<Eigen::VectorXd> q(n_states), v(n_states), tau(n_states);
  for (int k = 0; k < n_states; ++k) {
    q[k].resize(nv); v[k].resize(nv); tau[k].resize(nv);
    for (int j = 0; j < nv; ++j) in >> q[k][j];
    for (int j = 0; j < nv; ++j) in >> v[k][j];
    for (int j = 0; j < nv; ++j) in >> tau[k][j];
  }
  double best = 1e300, check = 0.0;
  for (int r = 0; r < repeats; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < n_states; ++k) {
      aba(model, data, q[k], v[k], tau[k]);
      check += data.ddq[nv - 1];
    }
    auto t1 = std::chrono::steady_clock::now();
    double ns = std::chrono::duration<double, std::nano>(t1 - t0).count() / n_states;
    if (ns < best) best = ns;
  }
  aba(model, data, q[0], v[0], tau[0]);
  std::cout.precision(17);
  std::cout << best << "\n";
  for (int j = 0; j < nv; ++j) std::cout << data.ddq[j] << " ";
  std::cout << "\n" << check << "\n";
  return 0;
}
"""


#: Repetitions of each timed burst; the minimum is kept (robust to other load on the host).
REPEATS = 200


def best_time(fn: Callable[[], object], repeats: int = 5) -> float:
    """Best wall time (s) of ``fn()`` over ``repeats`` runs."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def random_states(model: RobotModel, n: int, seed: int = 0) -> tuple[np.ndarray, ...]:
    """``(q, qd, tau, u)`` columns ``(nq, n)`` near a walking posture (double support valid)."""
    rng = np.random.default_rng(seed)
    q = np.zeros((model.nq, n))
    q[1] = 0.9
    q[2:] = rng.uniform(-0.3, 0.3, (model.nq - 2, n))
    qd = rng.normal(size=(model.nq, n))
    tau = 20.0 * rng.normal(size=(model.nq, n))
    u = 20.0 * rng.normal(size=(model.nu, n))
    return q, qd, tau, u


# -- code generation and compilation --------------------------------------------------------

def builders(model: RobotModel) -> dict[str, Callable[[bool], ca.Function]]:
    c = [cc.name for cc in model.contacts]
    return {
        "forward dynamics": lambda compiled: functions.forward_dynamics_function(
            model, compiled=compiled),
        f"contact dynamics ({c[0]})": lambda compiled: functions.contact_dynamics_function(
            model, c[:1], compiled=compiled),
        f"contact dynamics ({', '.join(c[:2])})": lambda compiled:
            functions.contact_dynamics_function(model, c[:2], compiled=compiled),
        f"impact ({c[1]} strikes, {c[0]} held)": lambda compiled: functions.impact_function(
            model, c[:2], compiled=compiled),
    }


def compile_times(model: RobotModel) -> list[tuple[str, float, float]]:
    """Per Function: (name, seconds with a fresh cache, seconds from the disk cache)."""
    out = []
    saved = os.environ.get("GAITOPT_CACHE")
    with tempfile.TemporaryDirectory(prefix="gaitopt-bench-") as tmp:
        os.environ["GAITOPT_CACHE"] = tmp
        try:
            for name, build in builders(model).items():
                functions.clear_cache()
                fresh = best_time(lambda b=build: b(True), repeats=1)
                functions.clear_cache()
                cached = best_time(lambda b=build: b(True), repeats=1)
                out.append((name, fresh, cached))
        finally:
            if saved is None:
                del os.environ["GAITOPT_CACHE"]
            else:
                os.environ["GAITOPT_CACHE"] = saved
            functions.clear_cache()
    return out


# -- our batch evaluation -------------------------------------------------------------------

def batch_time(model: RobotModel, f: ca.Function, args: list[np.ndarray], n: int) -> float:
    """Seconds per evaluation of ``f`` mapped over ``n`` columns, compiled to C."""
    mapped = f.map(n, "serial")
    lib = f"bench_{model.name}_{model.content_hash()}_{f.name()}_map{n}".replace("-", "_")
    compiled = codegen.compile_functions([mapped], lib)[mapped.name()]
    args_dm = [ca.DM(a) for a in args]  # convert once: NumPy -> DM costs ~30 ns per entry
    compiled.call(args_dm)  # warm up
    return best_time(lambda: compiled.call(args_dm), repeats=REPEATS) / n


# -- Pinocchio --------------------------------------------------------------------------------

def pinocchio_python_time(model: RobotModel, q: np.ndarray, qd: np.ndarray,
                          tau: np.ndarray) -> tuple[float, np.ndarray]:
    import pinocchio as pin
    from pinocchio_model import build

    ref = build(model)
    pm, pd = ref.model, ref.data()
    qs = [ref.to_pin(q[:, k]) for k in range(q.shape[1])]
    vs = [ref.to_pin(qd[:, k]) for k in range(q.shape[1])]
    ts = [ref.to_pin(tau[:, k]) for k in range(q.shape[1])]

    def run() -> None:
        for a, b, c in zip(qs, vs, ts, strict=True):
            pin.aba(pm, pd, a, b, c)

    first = ref.from_pin(pin.aba(pm, pd, qs[0], vs[0], ts[0]).copy())
    return best_time(run) / len(qs), first


def pinocchio_cpp_time(model: RobotModel, q: np.ndarray, qd: np.ndarray, tau: np.ndarray
                       ) -> tuple[float, np.ndarray] | str:
    """ns per pinocchio::aba call in C++, and qdd of the first state; or why not."""
    from pinocchio_model import build, depth_first

    site = Path(sysconfig.get_paths()["purelib"])
    prefix = site / "cmeel.prefix"
    eigen = site / "casadi" / "include" / "eigen3"
    if not (prefix / "include" / "pinocchio").is_dir():
        return "Pinocchio headers not found under site-packages/cmeel.prefix"
    if not (eigen / "Eigen").is_dir():
        return "Eigen headers not found (looked in casadi/include/eigen3)"
    cxx = shutil.which(os.environ.get("CXX", "g++"))
    if cxx is None:
        return "no C++ compiler (set CXX or install g++)"
    flags = ["-O3", "-DNDEBUG", "-std=c++17", "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
             "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30", "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
             "-DBOOST_FUSION_INVOKE_MAX_ARITY=12", f"-I{prefix / 'include'}",
             f"-I{prefix / 'include' / 'pinocchio' / 'deprecated'}", f"-I{eigen}"]
    key = hashlib.sha256("\0".join([CPP_SOURCE, cxx, *flags]).encode()).hexdigest()[:16]
    exe = codegen.cache_dir() / f"bench_pinocchio_aba-{key}"
    if not exe.exists():
        print(f"  (compiling the Pinocchio C++ timing program once, ~20 s: {exe.name})")
        with tempfile.TemporaryDirectory() as tmp:
            src = Path(tmp) / "aba.cpp"
            src.write_text(CPP_SOURCE)
            proc = subprocess.run([cxx, *flags, str(src), "-o", str(Path(tmp) / "aba")],
                                  capture_output=True, text=True)
            if proc.returncode != 0:
                return f"C++ compilation failed: {proc.stderr[-500:]}"
            shutil.copy(Path(tmp) / "aba", exe)
    order = depth_first(model)
    pos = {link: k for k, link in enumerate(order)}
    ref = build(model)
    lines = [f"{len(order)} {model.gravity[0]} {model.gravity[1]} {q.shape[1]} {REPEATS}"]
    for i in order:
        link = model.links[i]
        if i == 0:
            parent, offset = -1, (0.0, 0.0)
        else:
            p = model.parent_index(i)
            assert link.joint is not None
            parent, offset = pos[p], model.links[p].local_point(*link.joint.at)
        cx, cy = link.com_local
        lines.append(f"{parent} {offset[0]!r} {offset[1]!r} {link.mass!r} {cx!r} {cy!r} "
                     f"{link.inertia!r}")
    for k in range(q.shape[1]):
        for vec in (q[:, k], qd[:, k], tau[:, k]):
            lines.append(" ".join(repr(float(x)) for x in ref.to_pin(vec)))
    with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as fh:
        fh.write("\n".join(lines) + "\n")
        data_file = fh.name
    try:
        out = subprocess.run([str(exe), data_file], capture_output=True, text=True, check=True)
    finally:
        os.unlink(data_file)
    rows = out.stdout.split("\n")
    qdd_first = ref.from_pin(np.array([float(x) for x in rows[1].split()]))
    return float(rows[0]) * 1e-9, qdd_first


# -- main -----------------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--model", default="five-link")
    parser.add_argument("--batch", type=int, default=1000,
                        help="evaluations per mapped call (short bursts: robust on busy hosts)")
    parser.add_argument("--rounds", type=int, default=3,
                        help="measurement rounds, interleaving ours and Pinocchio's; the "
                             "best of all rounds is reported")
    args = parser.parse_args(argv)
    model = load_model(args.model)
    n = args.batch
    print(f"model {model.name}: nq = {model.nq}, links = {len(model.links)}, batch N = {n}, "
          f"cache {codegen.cache_dir()}")

    print("\nCode generation + C compilation per Function (s):")
    print(f"  {'function':42s} {'fresh cache':>12s} {'disk cache':>11s}")
    for name, fresh, cached in compile_times(model):
        print(f"  {name:42s} {fresh:12.3f} {cached:11.3f}")

    q, qd, tau, _u = random_states(model, n)
    fns = {name: build(False) for name, build in builders(model).items()}
    fd_single = functions.forward_dynamics_function(model, compiled=True)
    k = min(n, 1000)
    kp = min(k, 200)
    best: dict[str, float] = {}
    note = ""
    qdd_ours = fns["forward dynamics"].call([q[:, 0], qd[:, 0], tau[:, 0]])[0].full().ravel()

    def record(name: str, t: float) -> None:
        best[name] = min(best.get(name, float("inf")), t)

    for _ in range(args.rounds):  # interleaved rounds; the best of each is kept
        for name, f in fns.items():
            inputs = [q, qd, tau][: f.n_in()]
            record(f"ours, compiled, batch: {name}", batch_time(model, f, inputs, n))
        record("ours, compiled, one call from Python: forward dynamics",
               best_time(lambda: [fd_single.call([q[:, j], qd[:, j], tau[:, j]])
                                  for j in range(k)]) / k)
        record("ours, not compiled: gaitopt.dynamics.aba on NumPy floats (pure Python)",
               best_time(lambda: [aba(model, q[:, j], qd[:, j], tau[:, j])
                                  for j in range(kp)], repeats=3) / kp)
        t_py, qdd_py = pinocchio_python_time(model, q[:, :k], qd[:, :k], tau[:, :k])
        assert np.allclose(qdd_py, qdd_ours), "Pinocchio (Python) and our ABA disagree"
        record("Pinocchio aba, one call from Python", t_py)
        cpp = pinocchio_cpp_time(model, q, qd, tau)
        if isinstance(cpp, str):
            note = cpp
        else:
            t_cpp, qdd_cpp = cpp
            agree = float(np.max(np.abs(qdd_cpp - qdd_ours)))
            assert agree < 1e-9, f"Pinocchio (C++) and our ABA disagree by {agree}"
            record("Pinocchio aba, C++ loop (no Python overhead)", t_cpp)
    rows = list(best.items())
    t_py = best["Pinocchio aba, one call from Python"]
    t_ref = best.get("Pinocchio aba, C++ loop (no Python overhead)", t_py)
    if note:
        print(f"\nPinocchio C++ timing unavailable: {note}")
    print(f"\nTime per evaluation (ratio = Pinocchio aba {'C++' if t_ref != t_py else 'Python'}"
          " time / this time; > 1 means faster than Pinocchio):")
    print(f"  {'what':76s} {'us':>9s} {'ratio':>7s}")
    for name, t in rows:
        print(f"  {name:76s} {t * 1e6:9.3f} {t_ref / t:7.2f}")
    fd_batch = rows[0][1]
    print(f"\nTarget: compiled forward dynamics >= 2x faster than Pinocchio's numeric ABA: "
          f"{t_ref / fd_batch:.2f}x ({'met' if t_ref / fd_batch >= 2 else 'NOT met'}).")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
