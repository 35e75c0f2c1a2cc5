"""Multiscale solver: hours of milling from seconds of mechanics (``solver = "averaged"``).

The ball's motion does not depend on any temperature, and the thermal network
sees the motion only through the heat generated at impacts and Whitaker's
velocity term w = 0.4 Re^{1/2} + 0.06 Re^{2/3} (MODEL.md §6). Impacts come every
~20 ms, the temperatures move over ~15 min. So:

1. The mechanics is integrated at full resolution, batch after batch of
   ``averaging_batch_periods`` drive periods, until the batch means of the heat
   rate and of w have converged: the start-up transient is cut by the MSER rule
   (White 1997) and the standard error of the remaining batch means must fall
   below ``averaging_rel_error`` of the mean. Both are chosen from the data.
2. The three-node thermal network is then integrated for the whole duration
   with these averages and a stiff-capable solver (LSODA). Sutherland's factor is
   evaluated at the current ball temperature, so the temperature dependence of
   the convection stays exact; only the velocity dependence is averaged, which
   is exact because Nu is linear in w.

Averaging is refused when the statistics do not converge within
``averaging_max_time`` or when the fastest thermal time constant is not well
separated from the time between impacts; the run then falls back to full
resolution (or fails, with ``averaging_fallback = "fail"``) and says why.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from shakermill.analysis.attractors import find_attractors
from shakermill.analysis.batch_means import batch_rates, mser_truncation, normalised, relative_error, standard_error
from shakermill.analysis.fit import fit_exponential
from shakermill.engines.budget import RunBudget
from shakermill.engines.one_d import model
from shakermill.engines.one_d.integrator import COUNTER_NAMES, Integrator
from shakermill.engines.one_d.setup import ProgressCallback, impact_columns, integrator_for, sample_times
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.parameters.schema import Parameters
from shakermill.solvers.full import assemble, simulate_full
from shakermill.solvers.result import (
    EnergyAudit,
    MechanicsAverages,
    Result,
    attach,
    conclude,
    no_impact_note,
    state_history,
    summarize,
)

# The thermal time constants of the impact-heated nodes must exceed the mean time between impacts by
# this factor, or their temperatures follow single impacts and the average is not what drives them.
TIME_SCALE_SEPARATION = 20.0
# Tolerances of the slow network: it is cheap, so it is solved far more accurately than it needs.
THERMAL_RTOL = 1e-9
THERMAL_ATOL = 1e-9

AVERAGING_FAILED = -10


@dataclass(frozen=True)
class MechanicsWindow:
    """What the full-resolution phase produced: the averages and the impacts it saw."""

    averages: MechanicsAverages
    integrator: Integrator
    wall_time: float
    status: int


def measure_mechanics(params: Parameters, integrator: Integrator, progress: ProgressCallback | None = None) -> MechanicsWindow:
    """Integrate the mechanics batch by batch until the averages converge (or the time bound is hit).

    Returns the averages with the integrator, which holds the impacts and windows of that stretch.
    ``progress(t, averaging_max_time)`` is told how far the mechanics has got.
    """
    batch_length = params.averaging_batch_periods * 2.0 * math.pi / params.omega
    heat = [float(integrator.y[model.HEAT_GENERATED])]
    dissipated = [float(integrator.y[model.DISSIPATED])]
    velocity_term = [float(integrator.y[model.VELOCITY_TERM])]
    started = time.perf_counter()
    status = REACHED_STOP
    converged, message = False, ""
    heat_rates = term_rates = np.empty(0)
    cut = 0
    heartbeat = None if progress is None else lambda t: progress(t, params.averaging_max_time)
    while True:
        status = integrator.advance(integrator.t + batch_length, heartbeat)
        if status != REACHED_STOP:
            message = f"the mechanics failed: {integrator.explain(status)}"
            break
        if heartbeat is not None:
            heartbeat(integrator.t)
        heat.append(float(integrator.y[model.HEAT_GENERATED]))
        dissipated.append(float(integrator.y[model.DISSIPATED]))
        velocity_term.append(float(integrator.y[model.VELOCITY_TERM]))
        heat_rates = batch_rates(np.array(heat), batch_length)
        term_rates = batch_rates(np.array(velocity_term), batch_length)
        if heat_rates.size >= 2 * params.averaging_min_batches:
            cut = max(mser_truncation(normalised(heat_rates)), mser_truncation(normalised(term_rates)))
            kept = heat_rates.size - cut
            if kept >= params.averaging_min_batches and relative_error(heat_rates[cut:]) <= params.averaging_rel_error and relative_error(term_rates[cut:]) <= params.averaging_rel_error:
                converged = True
                message = f"converged after {integrator.t:.3g} s of mechanics ({kept} batches of {batch_length:.3g} s)"
                break
        if integrator.t + batch_length > params.averaging_max_time:
            message = (
                f"the averages did not converge to a relative standard error of {params.averaging_rel_error:g} "
                f"within averaging_max_time = {params.averaging_max_time:g} s (irregular or slowly settling motion)"
            )
            break
    kept_heat, kept_term = heat_rates[cut:], term_rates[cut:]
    window = kept_heat.size * batch_length
    dissipated_rates = batch_rates(np.array(dissipated), batch_length)[cut:]
    impacts_in_window = int(np.sum(integrator.impacts[:, 0] >= cut * batch_length)) if kept_heat.size else 0
    averages = MechanicsAverages(
        heat_power=float(kept_heat.mean()) if kept_heat.size else math.nan,
        heat_power_stderr=standard_error(kept_heat),
        dissipated_power=float(dissipated_rates.mean()) if dissipated_rates.size else math.nan,
        velocity_term=float(kept_term.mean()) if kept_term.size else math.nan,
        velocity_term_stderr=standard_error(kept_term),
        transient=cut * batch_length,
        window=window,
        batches=int(kept_heat.size),
        impact_interval=window / impacts_in_window if impacts_in_window else math.inf,
        converged=converged,
        message=message,
    )
    return MechanicsWindow(averages, integrator, time.perf_counter() - started, status)


def impact_heated_time_constants(params: Parameters, averages: MechanicsAverages) -> dict[str, float]:
    """Time constants (s) of the two nodes that receive heat at each impact: the ball and the vial.

    The air node is left out on purpose: it only exchanges heat by convection, which is smooth
    between impacts, and its linear response to the fluctuating convection averages exactly.
    """
    k = model.constants_from(params)
    viscosity_ratio = 1.0  # at θ_r; Sutherland's factor changes h by a few percent only
    nusselt = 2.0 + averages.velocity_term * k.prandtl**0.4 / viscosity_ratio**0.25
    h_ball = nusselt * k.air_conductivity / (2.0 * k.radius)
    ball_conductance = 4.0 * math.pi * k.radius**2 * k.beta * h_ball
    vial_conductance = k.h_inner * k.inner_area + k.h_outer * k.outer_area
    return {
        "ball": k.capacity_ball / ball_conductance if ball_conductance > 0 else math.inf,
        "vial": k.capacity_vial / vial_conductance if vial_conductance > 0 else math.inf,
    }


def validity_problem(params: Parameters, averages: MechanicsAverages) -> str | None:
    """Why averaging is not valid for this run, or None when it is."""
    if not averages.converged:
        return averages.message
    if math.isfinite(averages.impact_interval):
        for node, time_constant in impact_heated_time_constants(params, averages).items():
            if time_constant < TIME_SCALE_SEPARATION * averages.impact_interval:
                return (
                    f"the {node}'s thermal time constant ({time_constant:.3g} s) is not well separated from the time "
                    f"between impacts ({averages.impact_interval:.3g} s): its temperature follows single impacts"
                )
    return None


def integrate_thermal_network(params: Parameters, averages: MechanicsAverages, times: np.ndarray):
    """Solve the slow three-node network with the averaged heat rate and velocity term.

    LSODA switches to BDF when the network is stiff (the air node is ~10⁴ times faster than the vial);
    it was the fastest of SciPy's stiff-capable methods here at this accuracy.
    """
    k = model.constants_from(params)

    def rates(t: float, state: np.ndarray) -> list[float]:
        rate_ball, rate_vial, rate_air, vial_to_outside = model.thermal_network(
            state[0], state[1], state[2], averages.heat_power, averages.velocity_term, k
        )
        return [rate_ball, rate_vial, rate_air, vial_to_outside]

    initial = [*model.initial_state(params)[model.THETA_BALL : model.THETA_AIR + 1], 0.0]
    return solve_ivp(
        rates,
        (0.0, params.duration),
        initial,
        method="LSODA",
        t_eval=times,
        rtol=THERMAL_RTOL,
        atol=THERMAL_ATOL,
    )


def averaged_states(params: Parameters, averages: MechanicsAverages, times: np.ndarray, thermal: np.ndarray) -> np.ndarray:
    """Full state rows for the averaged run: temperatures and mean cumulative flows; no within-impact detail."""
    states = np.full((times.size, model.N_STATE), np.nan)
    states[:, model.THETA_BALL] = thermal[0]
    states[:, model.THETA_VIAL] = thermal[1]
    states[:, model.THETA_AIR] = thermal[2]
    states[:, model.HEAT_LOST] = thermal[3]
    states[:, model.HEAT_GENERATED] = averages.heat_power * times
    states[:, model.DISSIPATED] = averages.dissipated_power * times
    # On average the ball's kinetic energy does not change: the vial's work is all dissipated.
    states[:, model.WORK_VIAL] = averages.dissipated_power * times
    states[:, model.VELOCITY_TERM] = averages.velocity_term * times
    return states


def simulate_averaged(params: Parameters, progress: ProgressCallback | None = None, budget: RunBudget | None = None) -> Result:
    """Run ``params`` with the multiscale solver (module docstring); same :class:`Result` as a full run.

    The run follows the configured start. With ``attractor_starts`` > 1 the other starts are settled
    too (:mod:`shakermill.attractors`, ~0.02 s each): the summary counts the attractors, and a warning
    names every one whose heat power differs from the configured start's by more than 1 %. The
    result's wall time is the solver's own: the probe is an analysis beside it, as in a full run.
    One ``budget`` (``params``' own if None) covers the mechanics, a fall-back and the probe.
    ``progress(done, total)`` is told the simulated seconds of each phase in turn.
    """
    budget = budget if budget is not None else RunBudget.of(params)
    result = _simulate_configured_start(params, progress, budget)
    if params.attractor_starts > 1 and result.status != BUDGET_EXCEEDED:
        _probe_attractors(result, budget, progress)
    return result


def _probe_attractors(result: Result, budget: RunBudget, progress: ProgressCallback | None) -> None:
    """Attach the attractors of the run's parameters; a probe that used up the budget makes the run stopped."""
    scan = find_attractors(result.params, budget, progress)
    attach(result, scan)
    if budget.reason is not None and result.success:
        result.status = BUDGET_EXCEEDED
        result.message = (
            f"{budget.reason} It ran out while probing attractors ({len(scan.failed)} of {len(scan.settled)} starts "
            "not settled); the run itself finished."
        )
        result.summary = summarize(result)


def _simulate_configured_start(params: Parameters, progress: ProgressCallback | None, budget: RunBudget) -> Result:
    started = time.perf_counter()
    # The start's state as a sample: a run stopped in the mechanics phase then shows where it began.
    integrator = integrator_for(params, sample_times=np.zeros(1), budget=budget)
    mechanics = measure_mechanics(params, integrator, progress)
    if mechanics.status == BUDGET_EXCEEDED:
        return _stopped_in_mechanics(params, mechanics)
    averages = mechanics.averages
    problem = validity_problem(params, averages)
    if problem is not None:
        return _refuse(params, mechanics, problem, progress, budget, started)
    times = sample_times(params)
    thermal = integrate_thermal_network(params, averages, times)
    if progress is not None:
        progress(params.duration, params.duration)
    if not thermal.success:
        problem = f"the thermal network solver failed: {thermal.message}"
        return _refuse(params, mechanics, problem, progress, budget, started)
    constants = integrator.constants
    states = averaged_states(params, averages, thermal.t, thermal.y)
    window_points = integrator.window_points
    capacities = (constants.capacity_ball, constants.capacity_vial, constants.capacity_air)
    heat = averages.heat_power * params.duration
    dissipated = averages.dissipated_power * params.duration
    stored = [capacity * (thermal.y[i, -1] - thermal.y[i, 0]) for i, capacity in enumerate(capacities)]
    energy = EnergyAudit(
        work_by_vial=dissipated,
        kinetic_energy_change=0.0,
        elastic_energy_change=0.0,
        dissipated=dissipated,
        heat_generated=heat,
        heat_to_ball=params.lam * heat,
        heat_to_vial=(1.0 - params.lam) * heat,
        not_converted_to_heat=dissipated - heat,
        stored_ball=stored[0],
        stored_vial=stored[1],
        stored_air=stored[2],
        heat_lost_to_surroundings=float(thermal.y[3, -1]),
        projection_correction=integrator.energy_correction,
    )
    counters = {name: int(integrator.counters[i]) for i, name in enumerate(COUNTER_NAMES)}
    counters["thermal_rhs_evaluations"] = int(thermal.nfev)
    result = Result(
        params=params,
        status=REACHED_STOP,
        message=f"Averaged solver: {averages.message}; thermal network integrated to {params.duration:g} s."
        + no_impact_note(params, int(np.isfinite(averages.impact_interval))),
        t_end=params.duration,
        history=state_history(thermal.t, states, constants, params),
        window_history=state_history(window_points[:, 0], window_points[:, 1:], constants, params),
        impact_columns=impact_columns(integrator.impacts, params.lam, since=averages.transient),
        counters=counters,
        wall_time=time.perf_counter() - started,
        energy=energy,
        ball_fit=fit_exponential(thermal.t, thermal.y[0], params.initial_temperature),
        solver="averaged",
        impact_window=averages.window,
        averages=averages,
    )
    return conclude(result, averages.heat_power, averages.velocity_term)


def _stopped_in_mechanics(params: Parameters, mechanics: MechanicsWindow) -> Result:
    """The budget ran out in the mechanics phase: what it integrated, as a full run of that stretch."""
    integrator = mechanics.integrator
    message = (
        f"{integrator.explain(BUDGET_EXCEEDED)} Stopped in the averaged solver's mechanics phase at t = "
        f"{integrator.t:.6g} s; the motion and impacts up to then are kept."
    )
    y0 = model.initial_state(params)
    result = assemble(params, integrator.constants, y0, integrator, BUDGET_EXCEEDED, message, mechanics.wall_time)
    result.solver, result.averages = "averaged", mechanics.averages
    result.summary = summarize(result)
    return result


def _refuse(
    params: Parameters,
    mechanics: MechanicsWindow,
    problem: str,
    progress: ProgressCallback | None,
    budget: RunBudget,
    started: float,
) -> Result:
    """Averaging is not valid: fall back to full resolution, or fail, as ``averaging_fallback`` says."""
    if params.averaging_fallback == "fail":
        reason = f"Averaging is not valid: {problem}. Set averaging_fallback = 'full' to run at full resolution."
        result = simulate_full(params.replace(duration=mechanics.integrator.t), progress=None, budget=budget)
        result.status, result.message = AVERAGING_FAILED, reason
        result.solver, result.averages = "averaged", mechanics.averages
        result.summary = summarize(result)
        return result
    result = simulate_full(params, progress, budget)
    result.message = f"Averaging is not valid ({problem}); ran at full resolution instead. {result.message}"
    result.averages = mechanics.averages
    result.wall_time = time.perf_counter() - started
    result.summary = summarize(result)
    return result
