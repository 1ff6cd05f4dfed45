"""Ctrl-C during an IPOPT solve raises KeyboardInterrupt (CasADi alone returns a failed solve,
and the staged solve went on with its next stage); so does SIGTERM in a process that installed
:func:`gaitopt.interrupts.terminate_as_interrupt` (as Terminated)."""

from __future__ import annotations

import os
import signal
import threading
import time

import casadi as ca
import numpy as np
import pytest

from gaitopt.interrupts import Terminated, raise_terminated, terminate_as_interrupt, terminated
from gaitopt.ocp.solver import call_solver


def slow_solver() -> ca.Function:
    """A problem IPOPT works on for many seconds (an unreachable tolerance, a CPU-time cap)."""
    n = 2000
    x = ca.MX.sym("x", n)
    f = 100 * ca.sumsqr(x[1:] - x[:-1] ** 2) + ca.sumsqr(1 - x[:-1])
    g = ca.sin(x[1:]) * ca.cos(x[:-1])
    return ca.nlpsol("slow", "ipopt", {"x": x, "f": f, "g": g},
                     {"ipopt.max_iter": 10**6, "ipopt.tol": 1e-30, "ipopt.max_cpu_time": 60.0,
                      "ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False,
                      "ipopt.hessian_approximation": "limited-memory"})


def solve_until(signum: int, raised: type[BaseException]) -> float:
    """Send ``signum`` to this process 1 s into a long solve; check that ``call_solver``
    raises ``raised``; return the seconds the call took."""
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signum))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(raised):
            call_solver(slow_solver(), {"x0": np.full(2000, 0.5), "lbg": -0.1, "ubg": 0.1})
    finally:
        timer.cancel()
    return time.monotonic() - start


def test_ctrl_c_during_a_solve_raises_and_restores_the_handler() -> None:
    # Python's own handler, as in an interactive command: a test worker (pytest-xdist) or a
    # process started in the background may ignore SIGINT, and then the call leaves it so.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        took = solve_until(signal.SIGINT, KeyboardInterrupt)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)
    assert took < 30.0  # stopped at the signal, not at the CPU-time cap


def test_a_process_that_ignores_sigint_keeps_ignoring_it() -> None:
    x = ca.MX.sym("x")
    solver = ca.nlpsol("quick", "ipopt", {"x": x, "f": (x - 2.0) ** 2},
                       {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False})
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        out = call_solver(solver, {"x0": 1.0})
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, previous)
    assert out.error is None
    assert abs(out.x[0] - 2.0) < 1e-6


def test_sigterm_during_a_solve_raises_terminated_where_installed() -> None:
    """With :func:`terminate_as_interrupt` installed (the ``gaitopt`` command), SIGTERM stops
    IPOPT like Ctrl-C and is raised as Terminated, a KeyboardInterrupt, after the call;
    the handler is back afterwards and the signal is noted for the exit status."""
    previous = signal.getsignal(signal.SIGTERM)
    terminate_as_interrupt()
    try:
        took = solve_until(signal.SIGTERM, Terminated)
        assert signal.getsignal(signal.SIGTERM) is raise_terminated
        assert terminated()
    finally:
        terminate_as_interrupt()  # forgets the signal: other tests call main() here
        signal.signal(signal.SIGTERM, previous)
    assert not terminated()
    assert took < 30.0  # stopped at the signal, not at the CPU-time cap
    assert issubclass(Terminated, KeyboardInterrupt)


def test_sigterm_keeps_a_handler_the_process_installed_itself() -> None:
    """Without :func:`terminate_as_interrupt`, a process's own SIGTERM handler is left
    alone by the solver call."""
    x = ca.MX.sym("x")
    solver = ca.nlpsol("quick", "ipopt", {"x": x, "f": (x - 2.0) ** 2},
                       {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False})

    def own(signum: int, frame: object) -> None:
        pass

    previous = signal.signal(signal.SIGTERM, own)
    try:
        out = call_solver(solver, {"x0": 1.0})
        assert signal.getsignal(signal.SIGTERM) is own
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert out.error is None
