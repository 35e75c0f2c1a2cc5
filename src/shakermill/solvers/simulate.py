"""One entry point for both solvers: ``simulate(params)`` runs the one ``params.solver`` names."""

from __future__ import annotations

from typing import Callable

from shakermill.engines.budget import BudgetExceeded, RunBudget
from shakermill.engines.one_d.setup import ProgressCallback
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.parameters.schema import Parameters
from shakermill.solvers.averaged import simulate_averaged
from shakermill.solvers.dem import Mechanics, settle_mechanics, simulate_dem, simulate_dem_averaged
from shakermill.solvers.full import simulate_full
from shakermill.solvers.result import INTERRUPTED, Result


def simulate(params: Parameters, progress: ProgressCallback | None = None, budget: RunBudget | None = None) -> Result:
    """Run ``params`` with the engine and solver it names (``params.engine``, ``params.solver``), within ``budget``
    (``params``' own if None): see :func:`simulate_full`, :func:`shakermill.solvers.averaged.simulate_averaged`
    and :func:`shakermill.solvers.dem.simulate_dem`."""
    if params.engine == "dem":
        return simulate_dem(params, progress, budget)
    if params.solver == "averaged":
        return simulate_averaged(params, progress, budget)
    return simulate_full(params, progress, budget)

def simulate_whole(params: Parameters) -> Result:
    """:func:`simulate` for callers built on many runs (scans, fits): Ctrl-C raises ``KeyboardInterrupt``
    and a spent budget :class:`~shakermill.budget.BudgetExceeded` (saying which limit) instead of
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
# fits several free sets to one base (validate's, the README's) measures them once.
_SETTLED: dict[Parameters, Mechanics] = {}
_SETTLED_KEPT = 2


def thermal_variants(params: Parameters) -> Callable[[Parameters], Result]:
    """:func:`simulate_whole` for runs that differ from ``params`` in ``THERMAL_ONLY_KEYS`` alone (a fit of
    the vial's heat loss). The averaged ``dem`` solver measures the mechanics once, here, and each run then
    integrates only its network: a three-dimensional run's means take tens of seconds, its network milliseconds."""
    if params.engine != "dem" or params.solver != "averaged":
        return simulate_whole
    mechanics = _SETTLED.get(params)
    if mechanics is None:
        budget = RunBudget.of(params)
        mechanics = settle_mechanics(params, budget=budget)
        if mechanics.status != REACHED_STOP:
            _whole(simulate_dem_averaged(params, None, budget, mechanics), budget)  # raises for Ctrl-C and the budget
        else:
            while len(_SETTLED) >= _SETTLED_KEPT:
                _SETTLED.pop(next(iter(_SETTLED)))
            _SETTLED[params] = mechanics

    def run(variant: Parameters) -> Result:
        variant_budget = RunBudget.of(variant)
        return _whole(simulate_dem_averaged(variant, None, variant_budget, mechanics), variant_budget)

    return run
