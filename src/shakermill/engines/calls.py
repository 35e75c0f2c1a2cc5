"""Advancing a compiled loop in calls of about a tenth of a second of wall time, within the run's budget.

Every engine's compiled loop takes at most the steps it is allowed and hands control back to Python, so that
Ctrl-C, the budget and progress are heard several times a second however small its steps are. The steps a call
may take adapt to the last call's pace: a step costs under a microsecond in flight but up to a millisecond in
a hard contact search, so no fixed count keeps Ctrl-C prompt. Where a call ends never changes the numbers:
each engine's loop resumes bit for bit where it paused.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import ClassVar

from shakermill.engines.budget import RunBudget, interrupts_held
from shakermill.engines.status import BUDGET_EXCEEDED

# Not outcomes, what a call returns besides a status: it took the steps it was allowed (PAUSED), or it stopped
# for Python to grow a buffer and must be called again at once (CALL_AGAIN).
PAUSED = 2
CALL_AGAIN = 3
# Wall time (s) a compiled call aims at before it hands control back.
CALL_SECONDS = 0.1


class CompiledRun:
    """A run whose compiled loop :meth:`compiled_call` advances; :meth:`advance` drives it within ``budget``."""

    # Steps of the first call, before any pace is known, and the most of any call.
    first_steps_per_call: ClassVar[int]
    most_steps_per_call: ClassVar[int]
    budget: RunBudget
    # Steps per call at the last call's pace (None before the first call).
    _pace: int | None = None

    @property
    def t(self) -> float:
        raise NotImplementedError

    def steps_taken(self) -> int:
        """Accepted steps of the run so far."""
        raise NotImplementedError

    def compiled_call(self, t_stop: float, steps_allowed: int) -> int:
        """Advance towards ``t_stop`` by at most ``steps_allowed`` steps: a status, PAUSED or CALL_AGAIN."""
        raise NotImplementedError

    def limit_reached(self) -> int | None:
        """A status that stops the run before the next call (the budget spent, a buffer full), or None."""
        return BUDGET_EXCEEDED if self.budget.spent() else None

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        """Advance to ``t_stop`` (s); returns the loop's status, or what :meth:`limit_reached` says.

        ``heartbeat(t)`` is called after each call that stopped short of ``t_stop``. Ctrl-C during a call raises
        ``KeyboardInterrupt`` once it has returned, the state consistent at its last step.
        """
        while (limit := self.limit_reached()) is None:
            before = self.steps_taken()
            started = time.perf_counter()
            with interrupts_held():
                status = self.compiled_call(
                    t_stop, min(self._pace or self.first_steps_per_call, self.budget.steps_left)
                )
            steps = self.steps_taken() - before
            self.budget.count_steps(steps)
            if status == CALL_AGAIN:
                continue
            if status != PAUSED:
                return status
            rate = steps / max(time.perf_counter() - started, 1e-9)
            self._pace = int(min(max(rate * CALL_SECONDS, 1.0), self.most_steps_per_call))
            if heartbeat is not None:
                heartbeat(self.t)
        return limit
