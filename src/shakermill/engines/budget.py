"""The wall-clock and step budget of one run (keys ``max_wall_time`` and ``max_steps``).

Some inputs make the integrator take tiny steps: a stiff thermal node, an extreme drive. Such a run
would go on for hours; the budget stops it with a status of its own and keeps what it computed. One
budget covers every integration a run does (the averaged solver's mechanics phase, its fall-back to
full resolution and its attractor probe), and the integrators check it each time the compiled loop
hands control back to Python, several times a second.
"""

from __future__ import annotations

import math
import signal
import sys
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import FrameType
from typing import TYPE_CHECKING

from shakermill.engines.status import BUDGET_EXCEEDED

if TYPE_CHECKING:
    from shakermill.parameters.keys import Parameters


class BudgetExceeded(Exception):
    """A run of a scan or a fit used up its budget: a partial run must not stand in for a whole one."""


@dataclass
class RunBudget:
    """What one run may spend: ``max_wall_time`` seconds of wall-clock time and ``max_steps`` accepted steps."""

    max_wall_time: float  # s
    max_steps: int
    steps: int = 0  # accepted steps of all the run's integrations so far
    started: float = field(default_factory=time.monotonic)
    # Set once, by the first check that finds the budget spent: which limit, and how to raise it.
    reason: str | None = None
    # Wall clock (monotonic) and simulated time when the pace began to be measured (:meth:`outpaced`).
    paced_from: tuple[float, float] | None = None
    # The replicas of an averaged run count their steps into one budget from several threads.
    _counting: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)

    @classmethod
    def of(cls, params: Parameters) -> RunBudget:
        """A fresh budget for a run of ``params``, its clock started now."""
        return cls(params.max_wall_time, params.max_steps)

    @classmethod
    def unlimited(cls) -> RunBudget:
        return cls(float("inf"), sys.maxsize)

    def __getstate__(self) -> dict:
        """A copy for another process (a replica advanced on a Dask worker): everything but the lock."""
        return {name: value for name, value in vars(self).items() if name != "_counting"}

    def __setstate__(self, state: dict) -> None:
        vars(self).update(state)
        self._counting = threading.Lock()

    def count_steps(self, steps: int) -> None:
        with self._counting:
            self.steps += steps

    @property
    def steps_left(self) -> int:
        return max(self.max_steps - self.steps, 0)

    def spent(self) -> bool:
        """Whether the run must stop now; the first time it must, ``reason`` says why."""
        if self.reason is None:
            self.reason = self._overrun()
        return self.reason is not None

    def explain(self, status: int, messages: Mapping[int, str]) -> str:
        """The message of an engine's ``status`` from its ``messages``; for BUDGET_EXCEEDED, which limit was reached
        and how to raise it."""
        return str(self.reason) if status == BUDGET_EXCEEDED else messages[status]

    def outpaced(self, t: float, end: float) -> bool:
        """Whether a run at ``t`` (s) on its way to ``end`` would, at its pace since this was first asked, spend more
        than PACE_MARGIN x ``max_wall_time`` in all; the first time it would, ``reason`` says so, with the estimate
        and how to ask for less or allow more. Ask after each compiled call: the first answer only starts the clock,
        as the first call may have loaded or compiled the engine's code."""
        now = time.monotonic()
        if self.paced_from is None:
            self.paced_from = (now, t)
        wall, simulated = now - self.paced_from[0], t - self.paced_from[1]
        if self.reason is not None or wall < PACE_JUDGED_AFTER_S or simulated <= 0.0:
            return self.reason is not None
        needed = now - self.started + wall * (end - t) / simulated
        if needed <= PACE_MARGIN * self.max_wall_time:
            return False
        self.reason = (
            f"The run was stopped early: at its pace so far ({simulated:.3g} s simulated in {wall:.3g} s) it would "
            "need "
            f"~{hours_or_minutes(needed)} of computing to reach t = {end:g} s, beyond its wall-clock budget "
            f"(max_wall_time = {self.max_wall_time:g} s). Ask for less work (a shorter duration, fewer balls, "
            f"solver = 'averaged') or allow it, e.g. --set max_wall_time={math.ceil(needed * PACE_MARGIN):d}."
        )
        return True

    def _overrun(self) -> str | None:
        if self.steps >= self.max_steps:
            return (
                f"The run used up its step budget (max_steps = {self.max_steps} integrator steps; a default 60-min run "
                f"takes ~3.4 million, so many more mean tiny steps). If the run is meant to take that many, raise it, "
                f"e.g. --set max_steps={2 * self.max_steps}."
            )
        elapsed = time.monotonic() - self.started
        if elapsed > self.max_wall_time:
            return (
                f"The run used up its wall-clock budget (max_wall_time = {self.max_wall_time:g} s, {elapsed:.3g} s "
                "elapsed). If the run is meant to take that long, raise it, e.g. --set "
                f"max_wall_time={2 * self.max_wall_time:g}."
            )
        return None


# A run's pace is judged only after this much wall time (s) past its first compiled call, which may load or compile
# the engine's code: earlier, the pace of a few calls says little.
PACE_JUDGED_AFTER_S = 10.0
# A run is stopped once its pace so far says it needs more than this many times its max_wall_time to reach its end:
# unless its pace then quickens more than that, its budget would stop it anyway, only hours later (a 3-D hour at
# full resolution takes ~8 h here, benchmarks/README.md).
PACE_MARGIN = 1.5


def hours_or_minutes(seconds: float) -> str:
    """A span of wall time in the unit a reader expects of it: seconds under 1.5 min, hours from 1.5 h."""
    if seconds < 90:
        return f"{seconds:.2g} s"
    return f"{seconds / 3600:.2g} h" if seconds >= 5400 else f"{seconds / 60:.2g} min"


@contextmanager
def interrupts_held(deliver: bool = True) -> Iterator[list[FrameType | None]]:
    """Hold a SIGINT that arrives inside the block; deliver it to the previous handler afterwards (``deliver``), or
    leave it in the list the block is given, for the caller to act on.

    Two uses. A KeyboardInterrupt raised inside a Numba call surfaces as ``SystemError: CPUDispatcher(...) returned a
    result with an exception set``, which no caller can tell from a crash. And a finished run's data files must be
    written whole however Ctrl-C falls. Only the main thread can set handlers; elsewhere, and where SIGINT is ignored
    (sweep workers) or default, nothing is held.
    """
    previous = signal.getsignal(signal.SIGINT)
    received: list[FrameType | None] = []
    if threading.current_thread() is not threading.main_thread() or not callable(previous):
        yield received
        return
    signal.signal(signal.SIGINT, lambda signum, frame: received.append(frame))
    try:
        yield received
    finally:
        signal.signal(signal.SIGINT, previous)
    if received and deliver:
        previous(signal.SIGINT, received[0])
