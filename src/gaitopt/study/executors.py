"""Where sweep points run: local processes, a Dask cluster, or this process.

All three give the sweep driver the same two operations, ``submit(fn, arg) -> future`` and a
stream of finished futures (each future's done-callback puts it on a queue: this works alike
for :mod:`concurrent.futures` and :class:`distributed.Future`). Nothing here distributes jobs
itself: that is the executor's (or the Dask scheduler's) work.

* :func:`local_backend`: a :class:`~concurrent.futures.ProcessPoolExecutor` whose processes
  start from a *forkserver* that has imported the solver (spawn where forkserver does not
  exist). Forking the driver itself is avoided: CasADi/IPOPT state is not fork-safe in
  general, and a forkserver starts a worker about as fast (0.4 s against 0.7 s for spawn on
  the reference machine, see docs/studies.md).
* :func:`dask_backend`: a ``distributed.Client`` connected to a scheduler address
  (``tcp://host:8786``); the workers need gaitopt installed, nothing else: they return each
  solved gait to the driver, which writes the sweep directory (no shared filesystem).
* :func:`inline_backend`: runs each point at once in this process (``--workers 0``; handy for
  debugging and tests: the process's transcription cache is reused across sweeps).
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import threading
import time
from collections.abc import Callable
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from typing import Any

#: Modules the forkserver imports once, so that each worker starts with them loaded.
PRELOAD = ("gaitopt.study.worker",)


class BackendError(RuntimeError):
    """The executor cannot be started or reached (e.g. a wrong scheduler address)."""


@dataclass
class Backend:
    """An executor with a queue of finished futures.

    ``slots`` is how many points run at once (the driver keeps that many in flight and picks
    the next point itself, so that chains that unlock the most work go first).
    """

    name: str
    slots: int
    submit_fn: Callable[[Callable[..., Any], Any], Any]
    close_fn: Callable[[bool], None]
    restart_fn: Callable[[], None] | None = None
    finished: queue.Queue[Any] = field(default_factory=queue.Queue)

    def submit(self, fn: Callable[..., Any], arg: Any) -> Any:
        """Start ``fn(arg)``; the future is put on :attr:`finished` when it is done."""
        future = self.submit_fn(fn, arg)
        future.add_done_callback(self.finished.put)
        return future

    def next_finished(self, timeout: float = 0.5) -> Any | None:
        """The next finished future, or None after ``timeout`` s (keeps Ctrl-C responsive)."""
        try:
            return self.finished.get(timeout=timeout)
        except queue.Empty:
            return None

    def restart(self) -> None:
        """Replace a broken executor (a worker process died) with a fresh one."""
        if self.restart_fn is None:
            raise BackendError(f"{self.name}: cannot restart")
        self.restart_fn()

    def close(self, *, wait: bool = True) -> None:
        """Stop the executor; ``wait=False`` (after Ctrl-C) does not wait for running points:
        local worker processes are ended (:func:`stop_workers`), a Dask client is closed."""
        self.close_fn(wait)


def mp_context(method: str | None = None) -> multiprocessing.context.BaseContext:
    """The multiprocessing context of local workers: ``method`` or forkserver (preloaded
    with the solver) where it exists, else spawn."""
    available = multiprocessing.get_all_start_methods()
    chosen = method or ("forkserver" if "forkserver" in available else "spawn")
    if chosen not in available:
        raise BackendError(f"start method {chosen!r} is not available here; use one of "
                           f"{', '.join(available)}")
    ctx = multiprocessing.get_context(chosen)
    if chosen == "forkserver":
        ctx.set_forkserver_preload(list(PRELOAD))
    return ctx


def local_backend(workers: int, *, start_method: str | None = None) -> Backend:
    """``workers`` local processes (>= 1)."""
    if workers < 1:
        raise BackendError(f"workers = {workers}: need at least 1 process (0 = inline)")
    ctx = mp_context(start_method)
    state: dict[str, ProcessPoolExecutor] = {}

    def start() -> None:
        state["pool"] = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                            initializer=end_with_driver,
                                            initargs=(os.getpid(),))

    def restart() -> None:
        state["pool"].shutdown(wait=False, cancel_futures=True)
        start()

    def close(wait: bool) -> None:
        if wait:
            state["pool"].shutdown(wait=True, cancel_futures=True)
        else:
            stop_workers(state["pool"])

    start()
    return Backend(name=f"{workers} local process{'es' if workers > 1 else ''} "
                        f"({ctx.get_start_method()})",
                   slots=workers, submit_fn=lambda fn, arg: state["pool"].submit(fn, arg),
                   close_fn=close, restart_fn=restart)


#: Seconds a stopped worker process is given to end after SIGTERM, before SIGKILL.
STOP_GRACE_S = 5.0
#: Seconds between a local worker's checks that the driver process is still there
#: (:func:`end_with_driver`).
DRIVER_CHECK_S = 1.0


def end_with_driver(driver: int) -> None:
    """The initializer of each local worker process: a daemon thread ends the worker
    (``os._exit``) within :data:`DRIVER_CHECK_S` once the driver process ``driver`` (PID) is
    gone, whatever ended it (SIGKILL, a crash, a closed terminal's SIGHUP) and whatever the
    worker is doing (IPOPT runs without the GIL).

    Without it a driver killed by SIGKILL left its worker processes and their forkserver
    running without a parent: each worker finished its point for nobody, then waited for
    work forever (measured: still there minutes later). POSIX only (``os.kill(pid, 0)``
    tests a process there; on Windows it would end it)."""
    if os.name != "posix":
        return

    def watch() -> None:
        while True:
            time.sleep(DRIVER_CHECK_S)
            if not process_exists(driver):
                os._exit(1)

    threading.Thread(target=watch, name="gaitopt-driver-watch", daemon=True).start()


def process_exists(pid: int) -> bool:
    """Whether process ``pid`` runs (POSIX; a zombie, ended but not yet reaped by its
    parent, counts as ended where /proc says so)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: it exists
        return True
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:  # the name in it may be any bytes
            stat = fh.read()
    except OSError:
        return True
    return stat.rsplit(b")", 1)[-1].split()[0] != b"Z"


def stop_workers(pool: ProcessPoolExecutor) -> None:
    """Shut ``pool`` down without waiting for its running points: cancel the queued ones and
    end its processes (SIGTERM, then SIGKILL after :data:`STOP_GRACE_S`).

    ``shutdown(wait=False)`` alone leaves every running point running, and the interpreter
    joins the pool's processes at exit, so after Ctrl-C the command went on until each
    running solve ended. A worker does not stop by itself either: the terminal's SIGINT
    reaches it, but CasADi turns a KeyboardInterrupt inside IPOPT into a failed solve
    (``NonIpopt_Exception_Thrown``) and the staged solve goes on with its next stage."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    deadline = time.monotonic() + STOP_GRACE_S
    for process in processes:
        process.join(timeout=max(0.0, deadline - time.monotonic()))
        if process.is_alive():
            process.kill()
            process.join(timeout=STOP_GRACE_S)


class InlineExecutor(Executor):
    """Runs each call at once in this process; its futures are done when returned."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future[Any]:
        future: Future[Any] = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001  (delivered through the future)
            if isinstance(exc, KeyboardInterrupt | SystemExit):
                raise
            future.set_exception(exc)
        return future


def inline_backend() -> Backend:
    executor = InlineExecutor()
    return Backend(name="this process", slots=1,
                   submit_fn=lambda fn, arg: executor.submit(fn, arg),
                   close_fn=lambda wait: None)


def dask_backend(address: str, *, timeout_s: float = 30.0) -> Backend:
    """A Dask cluster at ``address`` (``tcp://host:8786``); one slot per worker thread."""
    try:
        from distributed import Client
    except ImportError as exc:  # pragma: no cover  (a dependency of gaitopt)
        raise BackendError(f"--scheduler needs dask.distributed: {exc}") from None
    try:
        client = Client(address, timeout=timeout_s)
    except (OSError, TimeoutError) as exc:
        raise BackendError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
    try:
        client.wait_for_workers(1, timeout=timeout_s)
    except (OSError, TimeoutError):
        client.close()
        raise BackendError(f"the Dask scheduler at {address} has no worker after "
                           f"{timeout_s:g} s") from None
    slots = max(1, sum(client.nthreads().values()))
    return Backend(name=f"Dask cluster {address} ({slots} worker threads)", slots=slots,
                   submit_fn=lambda fn, arg: client.submit(fn, arg, pure=False),
                   close_fn=lambda wait: client.close())


BROKEN_ERRORS: tuple[type[BaseException], ...] = (BrokenProcessPool,)
