"""bench/linear_solver.py: its option sets reach IPOPT (and only while asked), and its
command-line sets parse or fail with a clear message. The figures are in
docs/results/benchmarks-gait.md, sections "MUMPS scaling" and "MUMPS ordering and IPOPT's step
options"."""

from __future__ import annotations

import argparse
import gc
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest
from problems import double_integrator

from gaitopt.ocp import Transcription, transcribe

BENCH = Path(__file__).resolve().parents[2] / "bench"


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("bench_linear_solver",
                                                  BENCH / "linear_solver.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


#: An option value IPOPT refuses (the permuting scaling is 0..7): a solve fails if, and only
#: if, the option reached its solver.
INVALID = {"ipopt.mumps_permuting_scaling": 99}


def test_sets_reach_every_solver_and_only_inside(bench: ModuleType) -> None:
    tr = transcribe(double_integrator(4))
    original = Transcription.solver
    assert tr.solve().success
    with bench.extra_options(INVALID):
        inside = tr.solve()
        # another solver of the same transcription (other options) gets the set too
        other = tr.solve(options={"ipopt.tol": 1e-6})
    assert not inside.success and not other.success
    assert Transcription.solver is original
    after = tr.solve()
    assert after.success and abs(after.objective - 12.0) < 1e-8


def test_valid_sets_give_the_same_optimum(bench: ModuleType) -> None:
    tr = transcribe(double_integrator(6))
    objectives = []
    for options in bench.DEFAULT_SETS.values():
        with bench.extra_options(options):
            res = tr.solve()
        assert res.success
        objectives.append(res.objective)
    assert abs(objectives[0] - 12.0) < 1e-8 and abs(objectives[1] - objectives[0]) < 1e-10


def test_fine_only_leaves_coarse_grids_alone(bench: ModuleType) -> None:
    # double_integrator(n): n intervals, n + 1 knots
    coarse = transcribe(double_integrator(bench.COARSE_KNOTS - 1))
    fine = transcribe(double_integrator(bench.COARSE_KNOTS))
    bench.FINE_ONLY[0] = True
    try:
        with bench.extra_options(INVALID):
            assert coarse.solve().success
            assert not fine.solve().success
    finally:
        bench.FINE_ONLY[0] = False


def test_parse_set(bench: ModuleType) -> None:
    assert bench.parse_set("off:mumps_permuting_scaling=0,ipopt.mumps_pivtol=1e-8") == (
        "off", {"ipopt.mumps_permuting_scaling": 0, "ipopt.mumps_pivtol": 1e-8})
    assert bench.parse_set("as is:") == ("as is", {})
    assert bench.parse_set("order:mumps_pivot_order=amd") == (
        "order", {"ipopt.mumps_pivot_order": "amd"})
    for bad in ("no colon", ":x=1", "a:x"):
        with pytest.raises(argparse.ArgumentTypeError, match="--set"):
            bench.parse_set(bad)


def test_fine_stages_sum_the_fine_grids_only(bench: ModuleType) -> None:
    stages = (("coarse", 50, 0.5), ("target grid", 30, 0.25), ("check grid", 17, 0.5))
    fine = frozenset({"target grid", "check grid"})
    runs = [bench.Run(True, (1.0,), 97, 1.25, 1.5, stages, fine),
            bench.Run(True, (1.0,), 97, 1.25, 1.5,
                      tuple((n, i, 3 * s) for n, i, s in stages), fine),
            bench.Run(True, (1.0,), 97, 1.25, 1.5,
                      tuple((n, i, 2 * s) for n, i, s in stages), fine)]
    # iterations of the first repetition, the median (here the third) of the summed seconds
    assert bench.fine_stages(runs) == (47, 1.5)
    assert bench.fine_stages([bench.Run(True, (1.0,), 97, 1.25, 1.5, stages)]) == (0, 0.0)
    assert bench.ratio(1.5, 0.0) == "-" and bench.ratio(1.5, 1.0) == "1.500"


@pytest.mark.parametrize(("asked", "used", "matching", "scaling", "scaled"),
                         [(0, 0, 0, 8, 8), (4, 2, 5, 77, -2)])
def test_mumps_choices_read_what_mumps_used(bench: ModuleType, asked: int, used: int,
                                            matching: int, scaling: int, scaled: int) -> None:
    # AMD (0) is built in; PORD (4) is not in CasADi's MUMPS, which falls back to AMF (2).
    # The scaling asked for (8) is used as such; the automatic one (77) after the matching
    # (job 5) is the matching's, computed during the analysis (-2).
    tr = transcribe(double_integrator(5))
    size = tr.nlp_size()
    # IPOPT's augmented system: free variables, equality rows, inequality rows and slacks
    rows = (size.variables - size.fixed_variables + size.equality_constraints
            + 2 * size.inequality_constraints)
    with bench.captured_fd1() as out:
        res = tr.solve(options={"ipopt.mumps_pivot_order": asked, "ipopt.mumps_scaling": scaling,
                                "ipopt.mumps_permuting_scaling": matching,
                                "ipopt.mumps_print_level": 2})
        del tr  # its solver's MUMPS instance reports its termination while captured
        gc.collect()
    assert res.success and abs(res.objective - 12.0) < 1e-8
    assert bench.mumps_choices(out[0]) == {"ordering": [used], "permuting scaling": [matching],
                                           "scaling": [scaled], "rows": [rows]}
    assert bench.mumps_choices("no report") == {"ordering": [], "permuting scaling": [],
                                                "scaling": [], "rows": []}


def test_sets_keep_the_stage_options_they_do_not_name(bench: ModuleType) -> None:
    # as FULL_WALK_FINE_GRID_OPTIONS reaches the full walk's fine stages: a set without the
    # key keeps the stage's value (here an invalid one, so the solve fails), one naming it wins
    tr = transcribe(double_integrator(4))
    with bench.extra_options({"ipopt.fast_step_computation": "yes"}):
        assert not tr.solve(options=INVALID).success
    with bench.extra_options({"ipopt.mumps_permuting_scaling": 0}):
        res = tr.solve(options=INVALID)
    assert res.success and abs(res.objective - 12.0) < 1e-8
