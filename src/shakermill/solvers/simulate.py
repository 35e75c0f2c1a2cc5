"""One entry point for every engine and solver: ``simulate(params)`` runs the engine ``params.engine`` names
(``engines/registry.py``) with the solver ``params.solver`` names."""

from __future__ import annotations

import math
from collections.abc import Callable

from shakermill.engines.budget import BudgetExceeded, RunBudget
from shakermill.engines.interface import MemoryBound, ProgressCallback, StepBound
from shakermill.engines.registry import engine_named
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.solvers.averaged import (
    Mechanics,
    Notice,
    averaging_engine,
    full_resolution_instead,
    least_mechanics,
    replica_count,
    replicated_engine,
    settle_mechanics,
    simulate_averaged,
)
from shakermill.solvers.driver import sample_times
from shakermill.solvers.full import simulate_full
from shakermill.solvers.impact import restitution_warning
from shakermill.solvers.result import INTERRUPTED, Result, summarize


def simulate(
    params: Parameters,
    progress: ProgressCallback | None = None,
    budget: RunBudget | None = None,
    notice: Notice | None = None,
) -> Result:
    """Run ``params`` with the engine and solver it names, within ``budget`` (``params``' own if None): see
    :func:`~shakermill.solvers.full.simulate_full` and :func:`~shakermill.solvers.averaged.simulate_averaged`
    (which tells ``notice`` of a fall-back to full resolution before it starts).
    Raises :class:`ParameterError` before anything is allocated for a run that would not fit (:func:`preflight`)."""
    preflight(params)
    engine = engine_named(params.engine)
    # Measured before the run, so that a Ctrl-C is not kept waiting for it (its first call loads compiled code).
    caution = restitution_warning(params, engine.description)
    if params.solver == "averaged":
        result = simulate_averaged(params, engine, progress, budget, notice=notice)
    else:
        result = simulate_full(params, engine, progress, budget)
    if caution is not None:
        result.warn(caution)
        result.summary = summarize(result)
    return result


# Of the memory the machine has free, what a run's records may take: the rest is for the run itself and the OS.
MEMORY_SHARE = 0.8


def preflight(params: Parameters) -> None:
    """Raise :class:`ParameterError` in one line where the run's engine lacks a capability its solver needs
    (``engines.interface``: Averaging, and Replicas for several replicas), where a run of ``params`` could not end
    within its step budget, or where the records and windows it allocates at its start exceed the memory free on this
    machine (an engine with the capabilities StepBound and MemoryBound; the 1-D engine's work and windows are capped
    instead). Its wall-clock budget is judged by the run's pace once it runs (``RunBudget.outpaced``)."""
    engine = engine_named(params.engine)
    if params.solver == "averaged":
        averaging_engine(engine)
        if replica_count(params) > 1:
            replicated_engine(engine)
    engine.network_for(params).check_heat_leaves()
    if issubclass(engine, StepBound):
        _check_step_budget(params, engine.least_steps)
    if issubclass(engine, MemoryBound):
        _check_memory(params, engine.memory_needed)


def _check_step_budget(params: Parameters, least_steps: Callable[[Parameters, float], float]) -> None:
    at_full_resolution = params.solver == "full" or full_resolution_instead(params) is not None
    simulated = params.duration if at_full_resolution else least_mechanics(params)
    steps = least_steps(params, simulated)
    if steps > params.max_steps:
        what, or_less = (
            ("the run", ", a shorter duration or solver = 'averaged'")
            if at_full_resolution
            else ("the least mechanics of the averaged solver", "")
        )
        raise ParameterError(
            f"max_steps: {simulated:.4g} s of {what} at full resolution take at least {steps:.3g} steps of engine = "
            f"{params.engine!r} (none is longer than max_flight_step = {params.max_flight_step:g} s), more than "
            f"max_steps = {params.max_steps}; allowed max_steps >= {math.ceil(steps)}{or_less}"
        )


def _check_memory(params: Parameters, needed_by: Callable[[Parameters, int], int]) -> None:
    import psutil

    needed = needed_by(params, sample_times(params).size)
    free = psutil.virtual_memory().available
    if needed > MEMORY_SHARE * free:
        raise ParameterError(
            f"record_windows: the run would keep {needed / 2**30:.3g} GiB of records and contacts ({params.n_balls} "
            "balls, "
            f"{sum(length for _, length in params.record_windows):g} s of record windows, a sample every "
            f"{params.output_interval:g} s), more than the {MEMORY_SHARE * free / 2**30:.3g} GiB it may take of the "
            f"{free / 2**30:.3g} GiB free; allowed shorter record_windows or a longer output_interval"
        )


def simulate_whole(params: Parameters) -> Result:
    """:func:`simulate` for callers built on many runs (scans, fits): Ctrl-C raises ``KeyboardInterrupt``
    and a spent budget :class:`~shakermill.engines.budget.BudgetExceeded` (saying which limit) instead of
    returning a partial result they would use as if it were whole."""
    budget = RunBudget.of(params)
    return _whole(simulate(params, budget=budget), budget)


def _whole(result: Result, budget: RunBudget) -> Result:
    if result.status == INTERRUPTED:
        raise KeyboardInterrupt
    if result.status == BUDGET_EXCEEDED:
        raise BudgetExceeded(str(budget.reason))
    return result


# The mechanics of the last few thermal_variants bases: the mechanics are deterministic, so a study that
# fits several free sets to one base, or compares thermal models on it (validate's, the README's), measures them once.
_SETTLED: dict[Parameters, Mechanics] = {}
_SETTLED_KEPT = 2


def thermal_variants(params: Parameters, progress: ProgressCallback | None = None) -> Callable[[Parameters], Result]:
    """:func:`simulate_whole` for runs that differ from ``params`` in the engine's thermal-only keys alone (a fit of
    the vial's heat loss). Where the engine has such keys and the solver averages, the mechanics is measured once,
    here, and each run then integrates only its network: a three-dimensional run's means take tens of seconds,
    its network milliseconds. ``progress(done, total)`` is told the simulated seconds of that mechanics."""
    engine = engine_named(params.engine)
    # A run too short to average is at full resolution, each variant its own.
    if not engine.description.thermal_only_keys or params.solver != "averaged" or full_resolution_instead(params):
        return simulate_whole
    mechanics = next((settled for settled in _SETTLED.values() if settled.serves(params)), None)
    if mechanics is None:
        budget = RunBudget.of(params)
        mechanics = settle_mechanics(params, engine, progress, budget)
        if mechanics.status != REACHED_STOP:
            _whole(
                simulate_averaged(params, engine, None, budget, mechanics), budget
            )  # raises for Ctrl-C and the budget
        else:
            while len(_SETTLED) >= _SETTLED_KEPT:
                _SETTLED.pop(next(iter(_SETTLED)))
            _SETTLED[params] = mechanics

    def run(variant: Parameters) -> Result:
        variant_budget = RunBudget.of(variant)
        return _whole(simulate_averaged(variant, engine, None, variant_budget, mechanics), variant_budget)

    return run
