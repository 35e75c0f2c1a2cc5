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

import os
import threading
from concurrent.futures import FIRST_EXCEPTION, Future, ThreadPoolExecutor, wait
from typing import Callable, Sequence

from shakermill.engines.calls import CALL_SECONDS
from shakermill.engines.interface import Engine
from shakermill.parameters.environment import threads_cap

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

    def __init__(self, engines: Sequence[Engine], threads: int) -> None:
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
            return [engine.advance(t_stop, heartbeat if index == 0 else None) for index, engine in enumerate(self.engines)]
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
