"""Parameters in, :class:`~shakermill.solvers.result.Result` out: a full-resolution run of the 1-D engine."""

from __future__ import annotations

import time

import numpy as np

from shakermill.analysis.fit import fit_exponential
from shakermill.analysis.steady import settled_means
from shakermill.engines.budget import RunBudget
from shakermill.engines.one_d import model
from shakermill.engines.one_d.integrator import COUNTER_NAMES, Integrator
from shakermill.engines.one_d.setup import ProgressCallback, impact_columns, integrator_for, sample_times
from shakermill.engines.status import REACHED_STOP
from shakermill.parameters.schema import Parameters
from shakermill.solvers.result import (
    INTERRUPTED,
    INTERRUPTED_MESSAGE,
    EnergyAudit,
    Result,
    conclude,
    no_impact_note,
    state_history,
)

# Simulated seconds per chunk: the granularity of progress reports (tiny steps hand back control sooner,
# see integrate.CALL_SECONDS). Chunk ends shorten a step, so this is part of what makes a run's numbers.
CHUNK_SECONDS = 10.0


def simulate_full(params: Parameters, progress: ProgressCallback | None = None, budget: RunBudget | None = None) -> Result:
    """Run the full-resolution model for ``params.duration`` seconds, within ``budget`` (``params``' if None).

    ``progress(t, duration)`` is called after every chunk of simulated time, and
    more often when steps are tiny. A ``KeyboardInterrupt`` ends the run early
    with status ``INTERRUPTED`` and keeps everything computed so far; a spent
    budget (``BUDGET_EXCEEDED``) and numerical failures are reported through
    ``status`` and ``message`` likewise, never raised.
    """
    integrator = integrator_for(params, sample_times(params), budget)
    y0 = integrator.y.copy()
    started = time.perf_counter()
    status = REACHED_STOP
    heartbeat = None if progress is None else lambda t: progress(t, params.duration)
    try:
        while integrator.t < params.duration and status == REACHED_STOP:
            status = integrator.advance(min(params.duration, integrator.t + CHUNK_SECONDS), heartbeat)
            if heartbeat is not None:
                heartbeat(integrator.t)
    except KeyboardInterrupt:
        status = INTERRUPTED
    wall_time = time.perf_counter() - started
    message = INTERRUPTED_MESSAGE if status == INTERRUPTED else integrator.explain(status)
    if status < 0:
        message = f"{message} Stopped at t = {integrator.t:.6g} s; results up to then are kept."
    return assemble(params, integrator.constants, y0, integrator, status, message, wall_time)

def assemble(
    params: Parameters,
    constants: model.Constants,
    y0: np.ndarray,
    integrator: Integrator,
    status: int,
    message: str,
    wall_time: float,
) -> Result:
    """The result of a full-resolution integration from ``y0`` to where ``integrator`` stands."""
    t_end = integrator.t
    written = integrator.samples_written
    times = integrator.sample_times[:written]
    samples = integrator.samples[:written]
    if written == 0 or times[-1] < t_end:
        # Close the series with the state where the run stopped, so a failed run shows its last state.
        times = np.append(times, t_end)
        samples = np.vstack([samples, integrator.y])
    history = state_history(times, samples, constants, params)
    window_points = integrator.window_points
    window_history = state_history(window_points[:, 0], window_points[:, 1:], constants, params)
    impacts = impact_columns(integrator.impacts, params.lam)
    counters = {name: int(integrator.counters[i]) for i, name in enumerate(COUNTER_NAMES)}
    energy = energy_audit(y0, integrator.y, constants, t_end, params, integrator.energy_correction)
    theta_0 = params.initial_temperature
    ball_fit = fit_exponential(times, history["theta_ball"], theta_0)
    result = Result(
        params=params,
        status=status,
        message=message + no_impact_note(params, impacts["time"].size),
        t_end=t_end,
        history=history,
        window_history=window_history,
        impact_columns=impacts,
        counters=counters,
        wall_time=wall_time,
        energy=energy,
        ball_fit=ball_fit,
    )
    heat_power, velocity_term = settled_means(times, history["heat_generated"], history["velocity_term_integral"])
    return conclude(result, heat_power, velocity_term)

def energy_audit(
    y0: np.ndarray,
    y1: np.ndarray,
    constants: model.Constants,
    t_end: float,
    params: Parameters,
    projection_correction: float,
) -> EnergyAudit:
    mechanical_change = model.mechanical_energy(t_end, y1, constants) - model.mechanical_energy(0.0, y0, constants)
    kinetic_change = 0.5 * (y1[model.P] ** 2 - y0[model.P] ** 2) / constants.ball_mass
    heat = y1[model.HEAT_GENERATED] - y0[model.HEAT_GENERATED]
    dissipated = y1[model.DISSIPATED] - y0[model.DISSIPATED]

    def stored(index: int, capacity: float) -> float:
        return capacity * (y1[index] - y0[index])

    return EnergyAudit(
        work_by_vial=y1[model.WORK_VIAL] - y0[model.WORK_VIAL],
        kinetic_energy_change=kinetic_change,
        elastic_energy_change=mechanical_change - kinetic_change,
        dissipated=dissipated,
        heat_generated=heat,
        heat_to_ball=params.lam * heat,
        heat_to_vial=(1.0 - params.lam) * heat,
        not_converted_to_heat=dissipated - heat,
        stored_ball=stored(model.THETA_BALL, constants.capacity_ball),
        stored_vial=stored(model.THETA_VIAL, constants.capacity_vial),
        stored_air=stored(model.THETA_AIR, constants.capacity_air),
        heat_lost_to_surroundings=y1[model.HEAT_LOST] - y0[model.HEAT_LOST],
        projection_correction=projection_correction,
    )
