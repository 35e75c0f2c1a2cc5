"""Multiscale solver for any engine: hours of milling from seconds of mechanics (``solver = "averaged"``).

The motion does not depend on any temperature, and the thermal network sees the motion only through the heat
the contacts put into its nodes and each ball's Whitaker velocity term w = 0.4 Re^{1/2} + 0.06 Re^{2/3}
(MODEL.md §§6, 11). Impacts come every few milliseconds, the temperatures move over minutes. So:

1. The mechanics is integrated at full resolution, batch after batch of ``averaging_batch_periods`` drive periods,
   until the batch means of the heat rates and of w have converged (:func:`solvers.driver.measure_means`).
2. The thermal network is then integrated for the whole duration with these means and a stiff-capable solver
   (LSODA). Sutherland's factor is evaluated at the current ball temperatures, so the temperature dependence of
   the convection stays exact; only the velocity dependence is averaged, which is exact because Nu is linear in w.

A run no longer than the least mechanics averaging needs runs at full resolution from the start
(:func:`full_resolution_instead`): averaging would cost more than the run. Averaging is refused when the means do
not converge within ``averaging_max_time`` (or the duration, when shorter) or when a heated node's
thermal time constant is not well separated from the time between the impacts that heat it; the run then falls
back to full resolution (or fails, with ``averaging_fallback = "fail"``) and says why.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from shakermill.analysis.fit import fit_exponential
from shakermill.analysis.impacts import contacts_of
from shakermill.engines.budget import RunBudget, hours_or_minutes
from shakermill.engines.interface import (
    AveragedEngine,
    Averaging,
    Engine,
    ProgressCallback,
    Replicas,
    ReplicatedEngine,
)
from shakermill.engines.records import EnergyAudit
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.solvers.attractors import probe_attractors
from shakermill.solvers.driver import Means, least_rounds, measure_means, sample_times
from shakermill.solvers.full import concluded, simulate_full
from shakermill.solvers.replicas import replicas_of
from shakermill.solvers.result import (
    INTERRUPTED,
    INTERRUPTED_MESSAGE,
    MechanicsAverages,
    Result,
    RunOutput,
    conclude,
    counting_rules,
    summarize,
)

# The thermal time constant of each impact-heated node must exceed the mean time between the impacts that heat it
# by this factor, or its temperature follows single impacts and the average is not what drives it.
TIME_SCALE_SEPARATION = 20.0
# ... where brief contacts bring at least this share of its heat; the rest it gets in lasting contacts, all along.
IMPULSIVE_SHARE = 0.5
# Tolerances of the slow network: it is cheap, so it is solved far more accurately than it needs.
THERMAL_RTOL = 1e-9
THERMAL_ATOL = 1e-9

AVERAGING_FAILED = -10

Notice = Callable[[str], None]


@dataclass(frozen=True)
class Told:
    """Whom a run tells how far it is (``progress(done, total)``) and what it decided on the way (``notice(line)``)."""

    progress: ProgressCallback | None
    notice: Notice | None


@dataclass(frozen=True)
class Mechanics:
    """The mechanics phase of an averaged run: the engine after it, its means and its status. Runs whose parameters
    differ in the engine's ``thermal_only_keys`` alone can reuse it (:meth:`serves`)."""

    params: Parameters
    engine: AveragedEngine
    means: Means | None  # None when Ctrl-C ended the mechanics
    status: int

    @property
    def explanation(self) -> str:
        return INTERRUPTED_MESSAGE if self.status == INTERRUPTED else self.engine.explain(self.status)

    def serves(self, params: Parameters) -> bool:
        keys = self.engine.description.thermal_only_keys
        return params.replace(**{key: getattr(self.params, key) for key in keys}) == self.params


def settle_mechanics(
    params: Parameters,
    engine_class: type[Engine],
    progress: ProgressCallback | None = None,
    budget: RunBudget | None = None,
) -> Mechanics:
    """Run the mechanics until its means converge; Ctrl-C ends it with the status INTERRUPTED and keeps the engine,
    so that what it integrated can still be returned. Only the start is sampled; the record windows are kept, by
    the first of the replicas that an engine with a ``replicas_key`` runs (solvers/replicas.py) alone. Raises
    :class:`ParameterError` for an engine without the capabilities this needs (:func:`averaging_engine`)."""
    engine = averaging_engine(engine_class)(params, budget, np.zeros(1), params.averaging_max_time)
    count, others = replica_count(params), []
    if count > 1:
        replicated = replicated_engine(engine_class)
        others = [replicated(params, budget, np.zeros(1), 0.0, replica=number) for number in range(1, count)]
    replicas, threads = replicas_of(engine, others)
    try:
        means, status = measure_means(params, replicas, progress, threads)
    except KeyboardInterrupt:
        means, status = None, INTERRUPTED
    return Mechanics(params, engine, means, status)


def simulate_averaged(
    params: Parameters,
    engine_class: type[Engine],
    progress: ProgressCallback | None = None,
    budget: RunBudget | None = None,
    mechanics: Mechanics | None = None,
    notice: Notice | None = None,
) -> Result:
    """Run ``params`` with the multiscale solver (module docstring); the same :class:`Result` as a full run.

    ``mechanics`` measured before serves parameters that differ from its own in the engine's thermal-only keys.
    One ``budget`` (``params``' own if None) covers the mechanics, a fall-back and the attractor probe, which an
    engine whose runs start as one ball on the axis gets when ``attractor_starts`` > 1: the summary then counts
    the attractors, and a warning names every one whose heat power differs from the configured start's by more
    than 1 %. ``progress(done, total)`` is told the simulated seconds of each phase in turn; ``notice(line)``, before
    a fall-back to full resolution starts, why and what it will take (it may take minutes where averaging took
    seconds).
    """
    averaging_engine(engine_class)
    budget = budget if budget is not None else RunBudget.of(params)
    reason = full_resolution_instead(params)
    if reason is not None and mechanics is None:
        result = simulate_full(params, engine_class, progress, budget)
        result.message = f"{reason} {result.message}"
        result.note(reason, first=True)
        result.summary = summarize(result)
        return result
    started = time.perf_counter()
    if mechanics is None:
        mechanics = settle_mechanics(params, engine_class, progress, budget)
    elif not mechanics.serves(params):
        raise ValueError("mechanics: measured for parameters that differ in more than the engine's thermal-only keys")
    result = _from_mechanics(params, engine_class, mechanics, Told(progress, notice), budget, started)
    stopped_by_the_user_or_the_budget = result.status in (INTERRUPTED, BUDGET_EXCEEDED)
    if (
        engine_class.description.attractor_starts
        and params.attractor_starts > 1
        and not stopped_by_the_user_or_the_budget
    ):
        probe_attractors(result, budget, progress)
    return result


def averaging_engine(engine_class: type[Engine]) -> type[AveragedEngine]:
    """``engine_class``, which the averaged solver drives through the capability Averaging (engines/interface.py);
    :class:`ParameterError` in one line where the engine has it not."""
    if not issubclass(engine_class, Averaging):
        raise ParameterError(
            "solver: the averaged solver needs an engine that measures the means it averages (the capability "
            f"Averaging, engines/interface.py); engine = {engine_class.description.name!r} has not; allowed solver = "
            "'full'"
        )
    return engine_class


def replicated_engine(engine_class: type[Engine]) -> type[ReplicatedEngine]:
    """``engine_class``, of which the averaged solver runs replicas (the capability Replicas besides Averaging);
    :class:`ParameterError` in one line where the engine has it not."""
    averaging = averaging_engine(engine_class)
    if not issubclass(averaging, Replicas):
        key = averaging.description.replicas_key or "replicas"
        raise ParameterError(
            f"{key}: the averaged solver runs replicas of an engine that builds them (the capability Replicas, "
            f"engines/interface.py); engine = {averaging.description.name!r} has not; allowed {key} = 1"
        )
    return averaging


def replica_count(params: Parameters) -> int:
    """How many replicas of the mechanics an averaged run of ``params`` runs: the value of its engine's
    ``replicas_key``, or 1."""
    key = params.engine_keys.replicas_key
    return int(getattr(params, key)) if key else 1


def least_mechanics(params: Parameters) -> float:
    """The least mechanics (s) an averaged run can end with, all its replicas together: each runs
    :func:`~solvers.driver.least_rounds` batches of ``averaging_batch_periods`` drive periods."""
    replicas = replica_count(params)
    return replicas * least_rounds(params, replicas) * params.averaging_batch_periods * params.period


def full_resolution_instead(params: Parameters) -> str | None:
    """Why an averaged run of ``params`` runs at full resolution from the start, or None: its duration is no longer
    than the least mechanics averaging needs, so averaging could only cost more (a user's 10-s run would otherwise
    take two minutes of mechanics and then fall back)."""
    needed = least_mechanics(params)
    if params.solver != "averaged" or params.duration > needed:
        return None
    replicas = replica_count(params)
    each = f" in each of {replicas} replicas" if replicas > 1 else ""
    return (
        f"Full resolution instead of the averaged solver: duration = {params.duration:g} s is no longer than the "
        f"{needed:.3g} s of mechanics that averaging needs at least ({least_rounds(params, replicas)} batches of "
        f"averaging_batch_periods drive periods{each})."
    )


def _from_mechanics(
    params: Parameters,
    engine_class: type[Engine],
    mechanics: Mechanics,
    told: Told,
    budget: RunBudget,
    started: float,
) -> Result:
    if mechanics.status != REACHED_STOP or mechanics.means is None:
        return _stopped(mechanics, mechanics.status, mechanics.explanation, started)
    # The mechanics may have been measured for parameters that differ in thermal-only keys: the network is params',
    # the heat measured into each node moved onto it by name.
    network = engine_class.network_for(params)
    measured = mechanics.means
    means = replace(measured, load=measured.load.moved(mechanics.engine.network, network))
    usable = means.averages.converged or means.averages.as_it_stands
    problem = means.averages.message if not usable else time_scale_problem(mechanics.engine, network, means)
    if problem is not None:
        return _refuse(params, engine_class, mechanics, _not_valid(means.averages, problem), told, budget, started)
    thermal = integrate_network(network, means.load, params)
    if told.progress is not None:
        told.progress(params.duration, params.duration)
    if not thermal.success:
        averages = _not_valid(means.averages, f"the thermal network solver failed: {thermal.message}")
        return _refuse(params, engine_class, mechanics, averages, told, budget, started)
    return _averaged_result(params, network, mechanics.engine, means, thermal, started)


def _averaged_result(
    params: Parameters, network: ThermalNetwork, engine: AveragedEngine, means: Means, thermal: Any, started: float
) -> Result:
    """The result of a valid averaged run: the network's temperatures for the whole duration, the motion and
    impacts of the averaging window, the audit of the mean rates."""
    averages, load = means.averages, means.load
    history = engine.averaged_history(
        thermal.t, thermal.y[:-1], thermal.y[-1], load, averages.dissipated_power, network
    )
    impacts = engine.impact_columns(since=averages.transient)
    note = "" if math.isfinite(averages.impact_interval) else engine.no_impact_note()
    output = RunOutput(
        params=params,
        status=REACHED_STOP,
        message=f"Averaged solver: {averages.message}; thermal network integrated to {params.duration:g} s." + note,
        t_end=params.duration,
        history=history,
        window_history=engine.window_history(),
        impact_columns=impacts,
        counters={**engine.counters(), "thermal_rhs_evaluations": int(thermal.nfev)},
        wall_time=time.perf_counter() - started,
        energy=averaged_energy(engine, network, means, thermal, impacts, params.duration),
        ball_fit=fit_exponential(thermal.t, history["theta_ball"], params.initial_temperature),
        description=engine.description,
        solver="averaged",
        impact_window=averages.window,
        averages=averages,
    )
    result = conclude(output, network, load)
    if averages.as_it_stands:
        result.warn(f"averaging: {averages.message}; a longer averaging_max_time narrows it")
        result.summary = summarize(result)
    return result


def time_scale_problem(engine: AveragedEngine, network: ThermalNetwork, means: Means) -> str | None:
    """Why averaging is not valid, or None: a node heated mostly by brief contacts (its heat in them, counted whole on
    each body they touch, at least IMPULSIVE_SHARE of its heat) must have a thermal time constant TIME_SCALE_SEPARATION
    times the time between them, or its temperature follows single impacts. A node heated mostly in lasting contacts
    (a ball rolling on the wall, MODEL.md §14.4) is heated all along; the air, only by convection, is smooth between
    impacts, and its linear response to the fluctuating convection averages exactly."""
    window = means.averages.window
    contacts = contacts_of(engine.impact_columns(since=means.averages.transient), *counting_rules(engine.params))
    brief = {name: values[~contacts.lasting] for name, values in contacts.columns.items()}
    hits = engine.node_hits(brief)
    impulsive = engine.node_hits(brief, brief["heat_generated"]) / window if window > 0 else np.zeros(hits.size)
    conductances = network.node_conductances(means.load.drives)
    for node, count in enumerate(hits):
        if not count or impulsive[node] < IMPULSIVE_SHARE * means.load.heat[node]:
            continue
        capacity = network.nodes[node].capacity
        constant = capacity / conductances[node] if conductances[node] > 0 else math.inf
        if constant < TIME_SCALE_SEPARATION * window / count:
            return (
                f"the {network.nodes[node].name}'s thermal time constant ({constant:.3g} s) is not well separated from "
                f"the time between the impacts that heat it ({window / count:.3g} s): its temperature follows single "
                "impacts"
            )
    return None


def integrate_network(network: ThermalNetwork, load: NetworkLoad, params: Parameters) -> Any:
    """``network`` driven by the mechanics' mean ``load``, and the heat it loses (the last component), sampled on the
    run's output grid. LSODA switches to BDF where the network is stiff (the air is ~10⁴ times faster than the vial)."""

    def rates(t: float, state: np.ndarray) -> np.ndarray:
        node_rates, lost = network.rates(state[:-1], load.heat, load.drives)
        return np.append(node_rates, lost)

    initial = np.append(network.initial_temperatures(params.initial_temperature), 0.0)
    return solve_ivp(
        rates,
        (0.0, params.duration),
        initial,
        method="LSODA",
        t_eval=sample_times(params),
        rtol=THERMAL_RTOL,
        atol=THERMAL_ATOL,
    )


def averaged_energy(
    engine: Engine, network: ThermalNetwork, means: Means, thermal: Any, impacts: dict[str, np.ndarray], duration: float
) -> EnergyAudit:
    """The audit of an averaged run: mean rates times the duration; the split by channel is that of the contacts of
    the averaging window."""
    load = means.load
    capacity = network.arrays.capacity
    heat = load.heat_power * duration
    dissipated = means.averages.dissipated_power * duration
    warming = thermal.y[:-1, -1] - thermal.y[:-1, 0]
    by_channel = {
        name: float(np.sum(impacts[f"dissipated_{name}"]))
        for name in engine.description.channels
        if f"dissipated_{name}" in impacts
    }
    total = sum(by_channel.values())
    return EnergyAudit(
        work_by_vial=dissipated,
        kinetic_energy_change=0.0,
        elastic_energy_change=0.0,
        dissipated=dissipated,
        heat_generated=heat,
        heat_into=network.grouped(load.heat * duration),
        not_converted_to_heat=dissipated - heat,
        stored=network.grouped(capacity * warming),
        drive_heat=network.fixed_heat * duration,
        heat_lost_to_surroundings=float(thermal.y[-1, -1]),
        projection_correction=engine.projection_correction,
        dissipated_by_channel={
            name: value / total * dissipated if total > 0 else 0.0 for name, value in by_channel.items()
        },
    )


def _not_valid(averages: MechanicsAverages, message: str) -> MechanicsAverages:
    return MechanicsAverages(**{**averages.__dict__, "converged": False, "message": message})


def _stopped(mechanics: Mechanics, status: int, message: str, started: float) -> Result:
    """The mechanics phase ended early (Ctrl-C, budget, engine failure) or averaging is refused: what it integrated,
    as a full run of that stretch."""
    engine = mechanics.engine
    message = (
        f"{message} Stopped in the averaged solver's mechanics phase at t = {engine.t:.6g} s; the motion and impacts "
        "up to then are kept."
    )
    averages = mechanics.means.averages if mechanics.means is not None else None
    return concluded(engine, status, message, time.perf_counter() - started, solver="averaged", averages=averages)


def _full_resolution_cost(params: Parameters, mechanics: Mechanics, started: float) -> tuple[float, float]:
    """The steps and the wall time (s) a full-resolution run of ``params`` would take at the pace of the mechanics
    just run (steps and wall time per simulated second); zero where no mechanics ran to judge it by."""
    engine = mechanics.engine
    simulated = engine.t
    if simulated <= 0:
        return 0.0, 0.0
    replicas = replica_count(params)
    steps = engine.counters()["steps"] / simulated * params.duration
    wall = (time.perf_counter() - started) / (replicas * simulated) * params.duration
    return steps, wall


def _out_of_reach(params: Parameters, steps: float, wall: float) -> str | None:
    """Why a fall-back to full resolution taking ``steps`` and ``wall`` s could not end within the run's budget, or
    None: a three-dimensional hour at full resolution takes a billion steps, and running it to learn that would take
    hours."""
    if steps <= params.max_steps and wall <= params.max_wall_time:
        return None
    return (
        f"A full-resolution run instead (averaging_fallback = 'full') would take ~{steps:.2g} steps and "
        f"~{hours_or_minutes(wall)} at the mechanics' pace, beyond max_steps = {params.max_steps} or "
        f"max_wall_time = {params.max_wall_time:g} s: "
        "not started. Allow the averaging more time (averaging_max_time) or ask for a shorter duration."
    )


def _refuse(
    params: Parameters,
    engine_class: type[Engine],
    mechanics: Mechanics,
    averages: MechanicsAverages,
    told: Told,
    budget: RunBudget,
    started: float,
) -> Result:
    """Averaging is not valid: fall back to full resolution, or fail, as ``averaging_fallback`` says."""
    steps, wall = _full_resolution_cost(params, mechanics, started)
    out_of_reach = None if params.averaging_fallback == "fail" else _out_of_reach(params, steps, wall)
    if params.averaging_fallback == "fail" or out_of_reach is not None:
        advice = out_of_reach or "Set averaging_fallback = 'full' to run at full resolution."
        reason = f"Averaging is not valid: {averages.message}. {advice}"
        result = _stopped(mechanics, AVERAGING_FAILED, reason, started)
        result.message, result.averages = reason, averages
    else:
        fell_back = f"Averaging is not valid ({averages.message}); ran at full resolution instead."
        if told.notice is not None:
            pace = f", ~{steps:.2g} steps and ~{hours_or_minutes(wall)} at the mechanics' pace" if steps > 0 else ""
            told.notice(f"averaging is not valid ({averages.message}); running at full resolution instead{pace}")
        result = simulate_full(params, engine_class, told.progress, budget)
        result.message = f"{fell_back} {result.message}"
        result.warn(fell_back, first=True)
        result.averages = averages
        result.wall_time = time.perf_counter() - started
    result.summary = summarize(result)
    return result
