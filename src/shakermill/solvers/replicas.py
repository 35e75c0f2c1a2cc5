"""Independent replicas of an averaged run's mechanics, advanced side by side on the cores.

The several balls' motion is chaotic, so its means converge as 1/sqrt(T) whatever the start: R replicas
that each run T/R seconds of settled motion know the means as well as one that runs T, and on R cores they
take a fraction of its wall time (each pays its own start-up transient). Each replica's start is the
configured one with a seeded kick (the engine's ``replica`` argument), so the replicas and what they measure
depend on the configuration alone. They advance in rounds to the same simulated time, and their compiled
loops release the GIL, so threads share the cores; the number of threads changes how fast a round goes,
never its numbers.
"""

from __future__ import annotations

import contextvars
import os
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_EXCEPTION, Future, ThreadPoolExecutor, wait
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from shakermill.engines.budget import RunBudget
from shakermill.engines.calls import CALL_SECONDS
from shakermill.engines.interface import AveragedEngine, EngineDescription, Measured, ReplicatedEngine
from shakermill.engines.thermal.network import NetworkLoad
from shakermill.parameters.environment import threads_cap

if TYPE_CHECKING:
    from distributed import Client


# Times a round is sent before its cancellation is taken as the cluster's answer (future.result() then raises it).
ROUND_ATTEMPTS = 3
_CLUSTER: contextvars.ContextVar[Client | None] = contextvars.ContextVar("shakermill_replica_cluster", default=None)


@contextmanager
def replicas_on(client: Client) -> Iterator[None]:
    """Inside this block, the replicas of an averaged run after its first advance as tasks of ``client``'s Dask cluster
    (:class:`RemoteReplica`); the first stays here, with its record windows and impacts. Same numbers as threads."""
    token = _CLUSTER.set(client)
    try:
        yield
    finally:
        _CLUSTER.reset(token)


def replica_cluster() -> Client | None:
    """The Dask client replicas are sent to (:func:`replicas_on`), or None: threads of this process."""
    return _CLUSTER.get()


def _advance_elsewhere(engine: Any, t_stop: float) -> tuple[Any, int, np.ndarray]:
    """A Dask task: ``engine`` advanced to ``t_stop``, its status and the start times of the impacts it recorded. Its
    budget here is unlimited: the run's own is counted where the run is (:meth:`RemoteReplica.advance`)."""
    engine.budget = RunBudget.unlimited()
    status = engine.advance(t_stop)
    return engine, status, engine.take_impact_times()


class Replica(Protocol):
    """What the averaged solver's driver (solvers/driver.py) asks of each replica of a run's mechanics: an engine with
    the capability Averaging here, or a :class:`RemoteReplica` advanced on a cluster."""

    @property
    def description(self) -> EngineDescription: ...

    @property
    def t(self) -> float: ...

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int: ...

    def explain(self, status: int) -> str: ...

    def measured(self) -> Measured: ...

    def impact_columns(self, since: float = -np.inf) -> dict[str, np.ndarray]: ...

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: ArrayLike = ()) -> NetworkLoad: ...


class RemoteReplica:
    """A replica advanced as one Dask task per round: the task takes the engine as the last round left it and gives it
    back advanced, with the times of its impacts (the only records the averaged solver reads of a replica after the
    first). The numbers are those of the same engine advanced here, to the same round ends. A worker lost in a round
    loses that round alone: the scheduler runs the task again elsewhere from the same engine, to the same numbers."""

    def __init__(self, engine: ReplicatedEngine, client: Client) -> None:
        self._engine = engine
        self._budget = engine.budget
        self._client = client
        self._impact_times: list[np.ndarray] = []
        self.description = engine.description

    @property
    def t(self) -> float:
        return self._engine.t

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        """Advance to ``t_stop`` on the cluster; ``heartbeat(t)`` is called while it runs (its exception cancels the
        task: this replica stays where the last round left it). A round the cluster cancels (a client that lost its
        scheduler for a moment on a busy machine cancels its futures) is sent again, from the same engine."""
        for _ in range(ROUND_ATTEMPTS):
            future = self._client.submit(_advance_elsewhere, self._engine, t_stop, pure=False)
            finished = threading.Event()
            # Bound now: a cancelled round's callback, run late, must not wake the wait of the round sent after it.
            future.add_done_callback(lambda _, event=finished: event.set())
            try:
                # Polled through the callback's event, not future.result(timeout=...): distributed answers a future
                # cancelled while that waits with an UnboundLocalError of its own.
                while not finished.wait(CALL_SECONDS):
                    if heartbeat is not None:
                        heartbeat(self.t)
            except BaseException:
                future.cancel()
                raise
            if future.status != "cancelled":
                break
        engine, status, times = future.result()
        self._budget.count_steps(engine.steps_taken() - self._engine.steps_taken())
        engine.budget = self._budget
        self._engine = engine
        self._impact_times.append(times)
        return status

    def measured(self) -> Measured:
        return self._engine.measured()

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: ArrayLike = ()) -> NetworkLoad:
        return self._engine.load(heat_rates, term_means, conductances)

    def explain(self, status: int) -> str:
        return self._engine.explain(status)

    def impact_columns(self, since: float = -np.inf) -> dict[str, np.ndarray]:
        """The start times of its impacts from ``since`` (s): what is counted of a replica's impacts."""
        times = np.concatenate([np.empty(0), *self._impact_times])
        return {"time": times[times >= since]}


def replicas_of(first: AveragedEngine, others: Sequence[ReplicatedEngine]) -> tuple[list[Replica], int]:
    """The replicas of a run, the first here and the others on the cluster of :func:`replicas_on` if any, and the
    threads that advance them: one per replica with a cluster (they wait on it), else :func:`replica_threads`."""
    client = replica_cluster()
    if client is None:
        return [first, *others], replica_threads(1 + len(others))
    return [first, *(RemoteReplica(engine, client) for engine in others)], 1 + len(others)


def replica_threads(replicas: int) -> int:
    """The threads ``replicas`` replicas share: one per replica, at most the cores this process may use or
    THREADS_VARIABLE, if set (refused in one line where it is not a number of threads)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    cap = threads_cap()
    return max(1, min(replicas, cap if cap is not None else cores))


class _Stopped(Exception):
    """Raised in a replica's heartbeat, between two compiled calls, once another part of the run has stopped it."""


class ReplicaSet:
    """Engines advanced together to the same times, on ``threads`` threads (use as a context manager)."""

    def __init__(self, engines: Sequence[Replica], threads: int) -> None:
        self.engines = list(engines)
        self.threads = max(1, min(threads, len(self.engines)))
        self._stop = threading.Event()
        self._pool: ThreadPoolExecutor | None = None

    def __enter__(self) -> ReplicaSet:
        if self.threads > 1:
            self._pool = ThreadPoolExecutor(self.threads, thread_name_prefix="shakermill-replica")
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._stop.set()
        if self._pool is not None:
            self._pool.shutdown(wait=True)

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None) -> list[int]:
        """Advance every replica to ``t_stop`` (s); their statuses, in order. ``heartbeat(t)`` hears the first
        replica's time, from this thread. Ctrl-C, or an exception in any replica, stops them all within one compiled
        call each and is raised here, every engine whole at its last step."""
        if self._pool is None:
            return [
                engine.advance(t_stop, heartbeat if index == 0 else None) for index, engine in enumerate(self.engines)
            ]
        futures = [self._pool.submit(engine.advance, t_stop, self._check_stop) for engine in self.engines]
        try:
            while True:
                done, running = wait(futures, timeout=CALL_SECONDS, return_when=FIRST_EXCEPTION)
                if not running or any(future.exception() is not None for future in done):
                    break
                if heartbeat is not None:
                    heartbeat(self.engines[0].t)
        except BaseException:
            self._stop_all(futures)
            raise
        self._stop_all(futures)
        errors = [future.exception() for future in futures if future.exception() is not None]
        first_cause = next((error for error in errors if not isinstance(error, _Stopped)), None)
        if first_cause is not None:
            raise first_cause
        return [future.result() for future in futures]

    def _check_stop(self, t: float) -> None:
        if self._stop.is_set():
            raise _Stopped

    def _stop_all(self, futures: list[Future]) -> None:
        """Stop the replicas still running and wait until each has returned; a replica's own exception is kept in its
        future for ``result()`` to raise."""
        if all(future.done() for future in futures):
            return
        self._stop.set()
        wait(futures)
        self._stop.clear()
