"""Parameters in, :class:`~shakermill.solvers.result.Result` out, at full resolution, for any engine: every
impact of the whole run, the steady state from the means of its settled second half."""

from __future__ import annotations

import time

import numpy as np

from shakermill.analysis.fit import fit_exponential
from shakermill.analysis.steady import settled_rates
from shakermill.engines.budget import RunBudget
from shakermill.engines.interface import Engine, ProgressCallback
from shakermill.engines.records import StateHistory
from shakermill.engines.thermal.network import NetworkLoad
from shakermill.parameters.keys import Parameters
from shakermill.solvers.driver import run_until, sample_times, stop_message
from shakermill.solvers.result import MechanicsAverages, Result, RunOutput, conclude


def simulate_full(
    params: Parameters,
    engine_class: type[Engine],
    progress: ProgressCallback | None = None,
    budget: RunBudget | None = None,
) -> Result:
    """Run ``params`` at full resolution for ``params.duration`` seconds, within ``budget`` (``params``' if None):
    any engine, through its core alone (``engines.interface.Engine``).

    ``progress(t, duration)`` is called after every chunk of simulated time, and more often when steps are tiny.
    Ctrl-C ends the run early with status ``INTERRUPTED`` and keeps everything computed so far; a spent budget
    (``BUDGET_EXCEEDED``) and numerical failures are reported through ``status`` and ``message`` likewise, never
    raised.
    """
    engine = engine_class(params, budget, sample_times(params), params.duration)
    started = time.perf_counter()
    status = run_until(engine, params.duration, progress)
    return concluded(engine, status, stop_message(engine, status), time.perf_counter() - started)


def concluded(
    engine: Engine,
    status: int,
    message: str,
    wall_time: float,
    solver: str = "full",
    averages: MechanicsAverages | None = None,
) -> Result:
    """The result of what ``engine`` has integrated, concluded with the steady state of its settled means; ``solver``
    and ``averages`` say what ran it (the averaged solver's mechanics, stopped)."""
    output = output_of(engine, status, message, wall_time, solver, averages)
    return conclude(output, engine.network, settled_load(engine, output.history))


def output_of(
    engine: Engine,
    status: int,
    message: str,
    wall_time: float,
    solver: str = "full",
    averages: MechanicsAverages | None = None,
) -> RunOutput:
    """``engine``'s history, windows, impacts, counters and energy audit, for :func:`conclude`."""
    history = engine.history()
    impacts = engine.impact_columns()
    return RunOutput(
        params=engine.params,
        status=status,
        message=message + ("" if impacts["time"].size else engine.no_impact_note()),
        t_end=engine.t,
        history=history,
        window_history=engine.window_history(),
        impact_columns=impacts,
        counters=engine.counters(),
        wall_time=wall_time,
        energy=engine.energy_audit(),
        ball_fit=fit_exponential(history.times, history["theta_ball"], engine.params.initial_temperature),
        description=engine.description,
        solver=solver,
        averages=averages,
    )


def settled_load(engine: Engine, history: StateHistory) -> NetworkLoad:
    """The network's load from the second half of ``history``: the settled motion of a full run."""
    description = engine.description

    def rates(names: tuple[str, ...]) -> np.ndarray:
        return np.concatenate(
            [np.atleast_1d(settled_rates(history.times, history[name])) for name in names] or [np.zeros(0)]
        )

    return engine.load(
        *(
            rates(names)
            for names in (description.heat_variables, description.term_variables, description.conduction_variables)
        )
    )
