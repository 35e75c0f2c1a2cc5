"""Where the tasks of many runs run: in this process, on a local pool of worker processes, or on a Dask distributed
cluster; each gives back the tasks' outcomes as they finish. A task is its id and its values; what is done with them
is the ``work`` the executor was given (a sweep's :func:`~.points.run_point`, a calibration's training member): a
function of the values alone, picklable (a module's function, or a ``functools.partial`` of one), so that a worker
process or a cluster's worker can run it."""

from __future__ import annotations

import ast
import logging
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any, Protocol

from shakermill.parameters.defaults import DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.errors import ParameterError
from shakermill.studies.sweeps.points import PointInterrupted
from shakermill.support.limits import in_one_line

if TYPE_CHECKING:
    from distributed import Client


Task = tuple[str, Mapping[str, Any]]
# What a task does with its values; its outcome is what the executor stores.
Work = Callable[[Mapping[str, Any]], Any]
Outcomes = Iterator[tuple[str, Any]]


class Backend(Protocol):
    """Where tasks run: ``slots`` of them at once; their outcomes (or what each raised) as they finish; ``stop``
    drops the tasks not finished."""

    slots: int

    def outcomes(self, work: Work, tasks: Sequence[Task]) -> Outcomes: ...

    def stop(self) -> None: ...


@dataclass
class _InProcess:
    slots: int = 1

    def outcomes(self, work: Work, tasks: Sequence[Task]) -> Outcomes:
        for identifier, values in tasks:
            try:
                yield identifier, work(values)
            except PointInterrupted:
                raise KeyboardInterrupt from None

    def stop(self) -> None:
        """Nothing runs elsewhere: the interrupted point stopped with this process's own run."""


# How long a terminated worker may take to exit before it is killed (s); the sweep promises to stop within 2 s.
WORKER_EXIT_WAIT_S = 0.5


@dataclass
class _LocalPool:
    slots: int
    executor: Any = field(default=None)

    def stop(self) -> None:
        """Terminate the workers rather than wait for their points: those results would be thrown away, and a
        3-D point can run for minutes. Workers only compute (the sweep's process stores every point), so nothing
        of theirs is left half-written."""
        # No public handle on the workers before Python 3.14 (ProcessPoolExecutor.terminate_workers).
        processes = list((self.executor._processes or {}).values())
        for process in processes:
            process.terminate()
        self.executor.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.join(WORKER_EXIT_WAIT_S)
            if process.is_alive():
                process.kill()

    def outcomes(self, work: Work, tasks: Sequence[Task]) -> Outcomes:
        from concurrent.futures import as_completed

        futures = {self.executor.submit(work, values): identifier for identifier, values in tasks}
        for future in as_completed(futures):
            error = future.exception()
            yield futures[future], error if error is not None else future.result()


# How long a wait on the cluster sleeps before it looks again: Ctrl-C is answered within it.
POLL_S = 0.2
# How often a wait for the cluster says that it still waits (s).
WAITING_LINE_S = 5.0


class ClusterStalled(ParameterError):
    """The cluster finished no task within a round's bound: its workers left, or hang (one line, as the scheduler's
    other failures)."""


@dataclass
class _Cluster:
    client: Client
    slots: int
    # The longest a task may take (a run's max_wall_time) plus the scheduler's timeout: no task finished within it
    # means the cluster lost its tasks. None: no bound.
    round_limit_s: float | None = None
    submitted: list[Any] = field(default_factory=list)

    def outcomes(self, work: Work, tasks: Sequence[Task]) -> Outcomes:
        import time

        # pure=False: a point is a computation to run, not a value Dask may deduplicate or cache.
        futures = {self.client.submit(work, values, pure=False): identifier for identifier, values in tasks}
        self.submitted = list(futures)
        pending = dict(futures)
        last = time.monotonic()
        while pending:
            # Futures know their state without a call to the scheduler: looking every POLL_S answers Ctrl-C at once.
            done = [future for future in pending if future.done()]
            for future in done:
                del pending[future]
                yield futures[future], future.result() if future.status == "finished" else _cluster_error(future)
            now = time.monotonic()
            if done:
                last = now
            elif self.round_limit_s is not None and now - last > self.round_limit_s:
                raise ClusterStalled(
                    f"scheduler: no task finished on the cluster for {now - last:.0f} s, longer than a run may take "
                    f"(max_wall_time and --scheduler-timeout); {len(pending)} unfinished: its workers left or hang"
                )
            else:
                time.sleep(POLL_S)

    def stop(self) -> None:
        """Cancel the points not yet finished: the cluster's workers drop them instead of computing them for nobody."""
        pending = [future for future in self.submitted if not future.done()]
        if pending:
            with suppress(Exception):  # a scheduler already gone has nothing left to cancel
                self.client.cancel(pending)


def _cluster_error(future: Any) -> BaseException:
    """Why the cluster did not finish a point: the worker's exception, or the future's state (cancelled, lost)."""
    if future.status == "error":
        return future.exception()
    return RuntimeError(f"the cluster reports the point as {future.status}")


@contextmanager
def backend_for(
    workers: int | None,
    scheduler: str | None,
    timeout: float,
    pending: int,
    *,
    round_limit_s: float | None = None,
    announce: Callable[[str], None] | None = None,
) -> Iterator[Backend]:
    if scheduler is not None:
        client = connect(scheduler, timeout)
        try:
            threads = wait_for_workers(client, scheduler, timeout, announce or (lambda _: None))
        except BaseException:
            client.close()
            raise
        limit = None if round_limit_s is None else round_limit_s + timeout
        cluster = _Cluster(client, threads, limit)
        try:
            yield cluster
        except BaseException:
            cluster.stop()
            raise
        finally:
            client.close()
        return
    size = min(workers or os.cpu_count() or 1, pending)
    if size <= 1:
        yield _InProcess()
        return
    context = _start_context()
    if context is None:
        warnings.warn(
            'sweep: called from the top level of a script without an `if __name__ == "__main__":` guard, where '
            "worker processes cannot start on this platform; the points run one after another in this process",
            stacklevel=4,
        )
        yield _InProcess()
        return
    executor = _process_pool(size, context)
    pool = _LocalPool(size, executor)
    try:
        yield pool
    except BaseException:
        # Ctrl-C or an error while storing: queued points are dropped, running ones stopped.
        pool.stop()
        raise
    executor.shutdown()


def _process_pool(size: int, context: Any) -> Any:
    """A process pool of ``context`` whose workers ignore Ctrl-C; the sweep's own process handles it and stops the
    pool."""
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(max_workers=size, mp_context=context, initializer=_start_worker, initargs=(os.getpid(),))


def _start_context() -> Any:
    """How to start the workers: None when no worker could start, and the points must run in this process.

    forkserver, where the platform has it: its workers import shakermill once, from a clean
    single-threaded server, whereas fork from a process with threads (a progress bar, a Dask client)
    can deadlock, and spawn re-imports everything in every worker. But forkserver and spawn also run
    the main script again in each worker; called from a script's top level without a
    ``__main__`` guard, each worker would start a sweep of its own and fail. There, Linux forks (the
    script has no threads of shakermill's, and Numba's compiled code survives a fork); elsewhere,
    where fork is unsafe, there is no way to start workers.
    """
    import multiprocessing

    methods = multiprocessing.get_all_start_methods()
    if _called_from_unguarded_main():
        return multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None
    context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if "forkserver" in methods:
        context.set_forkserver_preload([__name__])
    return context


def _called_from_unguarded_main() -> bool:
    """Whether this call comes from the top level of the main script, outside ``if __name__ == "__main__":``.

    A notebook's or the interpreter's ``__main__`` has no file and is not run again by the workers.
    """
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if main is None or path is None or getattr(main, "__spec__", None) is not None:
        return False  # run with -m, the workers import it under its own name with the guard honoured
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and not (frame.f_globals is vars(main) and frame.f_code.co_name == "<module>"):
        frame = frame.f_back
    if frame is None:
        return False
    line = frame.f_lineno
    try:
        tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    except (OSError, SyntaxError, ValueError):
        return True
    return not any(
        _is_main_guard(node) and node.lineno <= line <= (node.end_lineno or node.lineno) for node in tree.body
    )


def _is_main_guard(node: ast.stmt) -> bool:
    if not isinstance(node, ast.If) or not isinstance(node.test, ast.Compare):
        return False
    operands = [node.test.left, *node.test.comparators]
    names = {operand.id for operand in operands if isinstance(operand, ast.Name)}
    constants = {operand.value for operand in operands if isinstance(operand, ast.Constant)}
    return names == {"__name__"} and constants == {"__main__"}


# How often a pool worker checks that the sweep that started it is still alive.
PARENT_CHECK_INTERVAL_S = 1.0


def _start_worker(sweep_pid: int) -> None:
    """Ignore Ctrl-C (the sweep handles it), run each point's replicas on one thread, and exit when the sweep's
    process is gone.

    A sweep killed with SIGKILL (by the user, or the out-of-memory killer) cannot stop its pool;
    without this, its workers would wait for more points forever. A thread watches the sweep's
    process and ends the worker once that process is gone or a zombie: killed, but not yet reaped
    by its own parent (a shell or a job runner may take its time), when it still has its process id.

    Why not ``prctl(PR_SET_PDEATHSIG)``, or watching ``os.getppid()``: a worker's parent is the
    forkserver, not the sweep, and the forkserver lives on as long as its workers hold their end of
    its "alive" pipe, so neither ever fires. psutil tells a zombie from a live process on every
    platform, and compares start times, so a process id reused by another process is not taken
    for the sweep. The thread runs between compiled chunks, so a worker ends within seconds.
    """
    import signal
    import threading
    import time

    import psutil

    from shakermill.parameters.environment import THREADS_VARIABLE

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # The pool gives every core a point already: a point's replicas take turns on its worker's core.
    os.environ.setdefault(THREADS_VARIABLE, "1")
    try:
        sweep_process = psutil.Process(sweep_pid)
    except psutil.NoSuchProcess:
        os._exit(1)

    def alive() -> bool:
        try:
            return sweep_process.is_running() and sweep_process.status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    def exit_with_the_sweep() -> None:
        while alive():
            time.sleep(PARENT_CHECK_INTERVAL_S)
        os._exit(1)

    threading.Thread(target=exit_with_the_sweep, name="exit-with-the-sweep", daemon=True).start()


def connect(address: str, timeout: float = DEFAULT_SCHEDULER_TIMEOUT_S) -> Client:
    """A Dask client of the scheduler at ``address``, or :class:`ParameterError` with one line saying why not."""
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("scheduler: dask.distributed is not installed (pip install 'dask[distributed]')") from None
    from distributed.security import Security

    # The environment's TLS settings (distributed.comm.tls.* in Dask's configuration, or the
    # DASK_DISTRIBUTED__COMM__TLS__* variables): the same for the handshake as for the client.
    security = Security()
    with _quiet_dask_logging():
        _check_scheduler_answers(address, timeout, security)
        try:
            return Client(address, timeout=timeout, set_as_default=False, security=security)
        except Exception as exc:  # noqa: BLE001 - whatever Dask raises, the user gets one line
            raise ParameterError(f"scheduler: cannot connect to {address}: {in_one_line(exc)}") from None


def wait_for_workers(client: Client, address: str, timeout: float, announce: Callable[[str], None]) -> int:
    """The threads of the cluster's workers, once it has one, waited for up to ``timeout`` (s) and saying so every
    WAITING_LINE_S; :class:`ParameterError` in one line if none joins. A scheduler without workers would leave
    every task queued forever."""
    import time

    started = time.monotonic()
    said = started
    while True:
        # The client's copy of the scheduler's state, refreshed by Dask in the background: no call to wait on.
        workers = client.scheduler_info().get("workers", {})
        if workers:
            return max(1, sum(int(worker.get("nthreads", 1)) for worker in workers.values()))
        now = time.monotonic()
        if now - started > timeout:
            raise ParameterError(
                f"scheduler: {address} has no workers (waited {timeout:g} s, --scheduler-timeout); start some "
                f"(dask worker {address}) or allow longer with --scheduler-timeout"
            )
        if now - said >= WAITING_LINE_S:
            said = now
            announce(f"waiting for a worker to join {address}, {_minutes(now - started)}")
        time.sleep(POLL_S)


def _minutes(seconds: float) -> str:
    return f"{int(seconds // 60)} min {int(seconds % 60):02d} s"


def _check_scheduler_answers(address: str, timeout: float, security: Any) -> None:
    """Open one connection to ``address`` and complete Dask's handshake, within ``timeout`` for each.

    Done before a :class:`~distributed.Client` is made, because a Client waits for the handshake
    without limit (a server that never speaks first, such as the HTTP dashboard on port 8787, keeps
    it waiting forever), and a Client whose start failed hangs the interpreter's exit closing itself.
    The probe runs on its own event loop in its own thread, so it works inside a running loop (Jupyter).
    """
    import asyncio
    import threading
    from concurrent.futures import Future, wait

    from distributed.comm import connect as open_comm

    async def handshake() -> None:
        # open_comm bounds the connection by ``timeout`` but not the handshake; wait_for bounds both.
        comm = await open_comm(address, timeout=timeout, **security.get_connection_args("client"))
        await comm.close()

    probe: Future[None] = Future()

    def run_probe() -> None:
        try:
            probe.set_result(asyncio.run(asyncio.wait_for(handshake(), 2 * timeout)))
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread, which says it in one line
            probe.set_exception(exc)

    # A daemon thread, waited for in slices: Ctrl-C while connecting is answered at once, and neither the command
    # nor the interpreter's exit waits out the handshake's timeout.
    threading.Thread(target=run_probe, name="scheduler-probe", daemon=True).start()
    while not probe.done():
        wait([probe], timeout=POLL_S)
    try:
        probe.result()
    except TimeoutError:
        raise ParameterError(
            f"scheduler: {address} accepted the connection but did not answer as a Dask scheduler "
            f"(waited {2 * timeout:g} s); give the scheduler's address (tcp://HOST:8786), not the dashboard's"
        ) from None
    except (OSError, ValueError, TypeError) as exc:
        # OSError: refused or timed out; ValueError/TypeError: an address Dask cannot parse.
        raise ParameterError(f"scheduler: cannot connect to {address}: {in_one_line(exc)}") from None
    except Exception as exc:  # noqa: BLE001 - a peer speaking another protocol can make Dask raise anything
        raise ParameterError(
            f"scheduler: {address} does not answer as a Dask scheduler ({type(exc).__name__} in the handshake)"
        ) from None


@contextmanager
def _quiet_dask_logging() -> Iterator[None]:
    # Dask logs each failed connection attempt; the user gets one line from connect() instead.
    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)
