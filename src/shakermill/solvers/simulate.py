"""One entry point for both solvers: ``simulate(params)`` runs the one ``params.solver`` names."""

from __future__ import annotations

from shakermill.engines.budget import BudgetExceeded, RunBudget
from shakermill.engines.one_d.integrator import BUDGET_EXCEEDED
from shakermill.engines.one_d.setup import ProgressCallback
from shakermill.parameters.schema import Parameters
from shakermill.solvers.averaged import simulate_averaged
from shakermill.solvers.dem import simulate_dem
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
    result = simulate(params, budget=budget)
    if result.status == INTERRUPTED:
        raise KeyboardInterrupt
    if result.status == BUDGET_EXCEEDED:
        raise BudgetExceeded(str(budget.reason))
    return result
