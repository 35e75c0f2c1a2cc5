"""The attractor probe: ``attractor_starts`` starts of one ball on the axis settled at full resolution, the motion
each reaches measured and the starts grouped into attractors (``analysis.attractors``), and the scan attached to a
run's result. For engines whose runs start as one ball on the axis (``description.attractor_starts``)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from shakermill.analysis.attractors import (
    BATCH_PERIODS,
    FAILED,
    MEASURE_PERIODS,
    SETTLE_PERIODS,
    AttractorScan,
    SettledStart,
    group,
    initial_states,
    settle_span,
)
from shakermill.analysis.regime import classify_impacts
from shakermill.engines.budget import RunBudget
from shakermill.engines.interface import ProgressCallback
from shakermill.engines.registry import engine_named
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.parameters.keys import Parameters
from shakermill.solvers.result import INTERRUPTED, Result, summarize


def settle(
    params: Parameters,
    start: int = 0,
    budget: RunBudget | None = None,
    heartbeat: Callable[[float], None] | None = None,
) -> SettledStart:
    """Settle the mechanics of ``params`` from its initial state and measure the motion it reached.

    The whole state is integrated, but only the motion is used (temperatures do not act back on it).
    A spent ``budget`` (``params``' own if None) makes the start ``FAILED`` with the budget's message;
    ``heartbeat(t)`` is called while steps are tiny. Ctrl-C raises ``KeyboardInterrupt``.
    """
    period = params.period
    settled_at = SETTLE_PERIODS * period
    boundaries = settled_at + period * np.arange(MEASURE_PERIODS + 1)
    engine = engine_named(params.engine)(params.replace(record_windows=()), budget, boundaries, boundaries[-1])
    status = engine.advance(boundaries[-1], heartbeat)
    if status != REACHED_STOP:
        return SettledStart(
            start,
            params.ball_position,
            params.ball_momentum,
            FAILED,
            None,
            math.nan,
            math.nan,
            math.nan,
            {"time": np.empty(0), "wall": np.empty(0, dtype=str)},
            engine.explain(status),
        )
    impacts = engine.impact_columns(since=settled_at)
    regime, cycle = classify_impacts(impacts, params.omega, params.phase)
    # Whole cycles of a periodic motion, so that its heat and rate carry no part-cycle bias.
    measured = MEASURE_PERIODS - MEASURE_PERIODS % cycle if cycle else MEASURE_PERIODS
    heat = engine.history()["heat_generated"]
    span = measured * period
    count = int(np.count_nonzero(impacts["time"] < boundaries[measured]))
    return SettledStart(
        start,
        params.ball_position,
        params.ball_momentum,
        regime,
        cycle,
        count / span,
        (heat[measured] - heat[0]) / span,
        _batch_standard_error(heat, period),
        impacts,
    )


def _batch_standard_error(heat: np.ndarray, period: float) -> float:
    """Standard error of the mean heat power from batches of BATCH_PERIODS drive periods (cumulative ``heat``)."""
    means = np.diff(heat[::BATCH_PERIODS]) / (BATCH_PERIODS * period)
    return float(means.std(ddof=1) / math.sqrt(means.size))


def find_attractors(
    params: Parameters, budget: RunBudget | None = None, progress: ProgressCallback | None = None
) -> AttractorScan:
    """Settle ``params.attractor_starts`` initial states and group them into attractors.

    One ``budget`` (``params``' own if None) covers all the starts; once it is spent, the remaining
    starts fail at once. ``progress(done, total)`` is told the simulated seconds settled, over all starts.
    """
    budget = budget if budget is not None else RunBudget.of(params)
    starts = initial_states(params, params.attractor_starts)
    span = settle_span(params)
    total = len(starts) * span
    settled = []
    for index, (position, momentum) in enumerate(starts):
        heartbeat = None if progress is None else lambda t, before=index * span: progress(before + t, total)
        settled.append(settle(params.replace(ball_position=position, ball_momentum=momentum), index, budget, heartbeat))
        if heartbeat is not None:
            heartbeat(span)
    return AttractorScan(tuple(settled), group(tuple(settled), params.omega, params.phase))


def probe_attractors(result: Result, budget: RunBudget, progress: ProgressCallback | None) -> None:
    """Attach the attractors of the run's parameters; a probe that used up the budget makes the run stopped, and one
    that Ctrl-C stopped makes it interrupted, with everything the run itself computed kept."""
    try:
        scan = find_attractors(result.params, budget, progress)
    except KeyboardInterrupt:
        result.status = INTERRUPTED
        result.message = (
            "Interrupted by the user while probing attractors; the run itself finished, its attractors were not probed."
        )
        result.summary = summarize(result)
        return
    attach(result, scan)
    if budget.reason is not None and result.success:
        result.status = BUDGET_EXCEEDED
        result.message = (
            f"{budget.reason} It ran out while probing attractors ({len(scan.failed)} of {len(scan.settled)} starts "
            "not settled); the run itself finished."
        )
        result.summary = summarize(result)


def probed(result: Result) -> AttractorScan:
    """The attractors at ``result``'s parameters: those its solver probed, or found now and attached."""
    scan = result.attractors
    if scan is None:
        scan = find_attractors(result.params)
        attach(result, scan)
    return scan


def attach(result: Result, scan: AttractorScan) -> None:
    """Give ``result`` the scan, its warnings, and its summary keys (``n_attractors``, ``heat_power_spread_W``, ...)."""
    result.attractors = scan
    result.warn(*scan.warnings())
    result.summary = summarize(result)
