"""One entry point for every engine and solver: ``simulate(params)`` runs the engine ``params.engine`` names
(``engines/registry.py``) with the solver ``params.solver`` names."""

from __future__ import annotations

from typing import Callable

from shakermill.engines.budget import BudgetExceeded, RunBudget
from shakermill.engines.interface import ProgressCallback
from shakermill.engines.registry import engine_named
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.parameters.keys import Parameters
from shakermill.solvers.averaged import Mechanics, full_resolution_instead, settle_mechanics, simulate_averaged
from shakermill.solvers.full import simulate_full
from shakermill.solvers.result import INTERRUPTED, Result


def simulate(params: Parameters, progress: ProgressCallback | None = None, budget: RunBudget | None = None) -> Result:
    """Run ``params`` with the engine and solver it names, within ``budget`` (``params``' own if None): see
    :func:`~shakermill.solvers.full.simulate_full` and :func:`~shakermill.solvers.averaged.simulate_averaged`."""
    engine = engine_named(params.engine)
    if params.solver == "averaged":
        return simulate_averaged(params, engine, progress, budget)
    return simulate_full(params, engine, progress, budget)


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


def thermal_variants(params: Parameters) -> Callable[[Parameters], Result]:
    """:func:`simulate_whole` for runs that differ from ``params`` in the engine's thermal-only keys alone (a fit of
    the vial's heat loss). Where the engine has such keys and the solver averages, the mechanics is measured once,
    here, and each run then integrates only its network: a three-dimensional run's means take tens of seconds,
    its network milliseconds."""
    engine = engine_named(params.engine)
    # A run too short to average is at full resolution, each variant its own.
    if not engine.description.thermal_only_keys or params.solver != "averaged" or full_resolution_instead(params):
        return simulate_whole
    mechanics = next((settled for settled in _SETTLED.values() if settled.serves(params)), None)
    if mechanics is None:
        budget = RunBudget.of(params)
        mechanics = settle_mechanics(params, engine, budget=budget)
        if mechanics.status != REACHED_STOP:
            _whole(simulate_averaged(params, engine, None, budget, mechanics), budget)  # raises for Ctrl-C and the budget
        else:
            while len(_SETTLED) >= _SETTLED_KEPT:
                _SETTLED.pop(next(iter(_SETTLED)))
            _SETTLED[params] = mechanics

    def run(variant: Parameters) -> Result:
        variant_budget = RunBudget.of(variant)
        return _whole(simulate_averaged(variant, engine, None, variant_budget, mechanics), variant_budget)

    return run
