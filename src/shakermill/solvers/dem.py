"""Parameters in, :class:`~shakermill.solvers.result.Result` out, for the 'dem' engine (MODEL.md section 12):
a full-resolution run, and the averaged run (mechanics until its per-ball means converge, then the N + 2
node thermal network for the whole duration, as :mod:`shakermill.solvers.averaged` does for one ball)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from shakermill.analysis.batch_means import batch_rates, mser_truncation, normalised, relative_error, standard_error
from shakermill.analysis.fit import fit_exponential
from shakermill.analysis.steady import SteadyState, network_steady_state, settled_rates
from shakermill.engines.budget import RunBudget
from shakermill.engines.dem import model, network, stepper
from shakermill.engines.dem.engine import Engine, impact_columns
from shakermill.engines.one_d.setup import ProgressCallback, sample_times
from shakermill.engines.status import REACHED_STOP
from shakermill.parameters.schema import Parameters
from shakermill.physics.kinematics import fourier_coordinates
from shakermill.solvers.result import (
    BALL_TEMPERATURES,
    CELSIUS_VARIABLES,
    INTERRUPTED,
    INTERRUPTED_MESSAGE,
    EnergyAudit,
    MechanicsAverages,
    Result,
    StateHistory,
    conclude,
    kelvin_to_celsius,
)

# The record windows hold the motion at this interval (10 kHz): a drive period in ~570 points.
WINDOW_INTERVAL = 1e-4
# Simulated seconds between progress reports (tiny steps hand back control sooner: engine.CALL_SECONDS).
CHUNK_SECONDS = 10.0
THERMAL_RTOL = 1e-9
THERMAL_ATOL = 1e-9


def simulate_dem(params: Parameters, progress: ProgressCallback | None = None, budget: RunBudget | None = None) -> Result:
    """Run the 'dem' engine with the solver ``params.solver`` names, within ``budget`` (``params``' if None).
    Ctrl-C, a spent budget and engine failures end the run early with their status; what was computed stays."""
    budget = budget if budget is not None else RunBudget.of(params)
    if params.solver == "averaged":
        return simulate_dem_averaged(params, progress, budget)
    return simulate_dem_full(params, progress, budget)


def _marks(params: Parameters, samples: np.ndarray, end: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times up to ``end`` at which the run is recorded, in order, and whether each is one of the output
    ``samples`` and whether it lies in a record window."""
    points = [
        np.arange(start, min(start + length, end) + 0.5 * WINDOW_INTERVAL, WINDOW_INTERVAL)
        for start, length in params.record_windows
        if start < end
    ]
    window = np.unique(np.concatenate(points)) if points else np.empty(0)
    times = np.union1d(samples[samples <= end], window)
    return times, np.isin(times, samples), np.isin(times, window)


def simulate_dem_full(params: Parameters, progress: ProgressCallback | None, budget: RunBudget) -> Result:
    """Every contact for the whole run (MODEL.md §12.6)."""
    marks, is_sample, in_window = _marks(params, sample_times(params), params.duration)
    engine = Engine(params, budget, marks[1:])  # the start is recorded before the first step
    start = engine.row_now()
    heartbeat = None if progress is None else lambda t: progress(t, params.duration)
    started = time.perf_counter()
    status = REACHED_STOP
    try:
        while engine.t < params.duration and status == REACHED_STOP:
            status = engine.advance(min(params.duration, engine.t + CHUNK_SECONDS), heartbeat)
            if heartbeat is not None:
                heartbeat(engine.t)
    except KeyboardInterrupt:
        status = INTERRUPTED
    rows = np.vstack([start, engine.rows])
    samples = rows[is_sample[: len(rows)]]
    if samples[-1, 0] < engine.t:
        samples = np.vstack([samples, engine.row_now()])  # a stopped run shows its last state
    windows = rows[in_window[: len(rows)]]
    message = INTERRUPTED_MESSAGE if status == INTERRUPTED else engine.explain(status)
    if status < 0 or status == INTERRUPTED:
        message = f"{message} Stopped at t = {engine.t:.6g} s; results up to then are kept."
    result = _result(params, engine, start, samples, windows, status, message, time.perf_counter() - started)
    steady = _settled_steady_state(params, engine.constants, result.history)
    return conclude(result, steady.heat_power, steady.velocity_term, steady)


def _result(params: Parameters, engine: Engine, start: np.ndarray, samples: np.ndarray, windows: np.ndarray,
            status: int, message: str, wall_time: float, impacts_since: float = -math.inf, **extra: object) -> Result:
    k = engine.constants
    history = dem_history(samples, k)
    return Result(
        params=params,
        status=status,
        message=message,
        t_end=engine.t,
        history=history,
        window_history=dem_history(windows, k),
        impact_columns=impact_columns(engine.records, since=impacts_since),
        counters=_counters(engine),
        wall_time=wall_time,
        energy=energy_audit(engine, start),
        ball_fit=fit_exponential(history.times, history["theta_ball"], params.initial_temperature),
        **extra,
    )


def energy_audit(engine: Engine, start: np.ndarray) -> EnergyAudit:
    """Where the work of the vial and of gravity went (MODEL.md §12.6), from the state row ``start`` to now."""
    k, s = engine.constants, engine.state
    n = k.n_balls
    initial = {name: values[0] for name, values in model.unpack_rows(start, n)[1].items()}
    kinetic_start = 0.5 * float(
        np.sum(k.mass * np.sum(initial["velocity"] ** 2, axis=1)) + np.sum(k.inertia * np.sum(initial["angular_velocity"] ** 2, axis=1))
    )
    warming = s.temperature - initial["temperature"]
    totals = s.totals - initial["totals"]
    channels = dict(zip(model.CHANNELS, totals[model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1], strict=True))
    dissipated = float(sum(channels.values()))
    heat = float(totals[model.HEAT_GENERATED])
    return EnergyAudit(
        work_by_vial=float(totals[model.WORK_VIAL]),
        kinetic_energy_change=engine.kinetic_energy() - kinetic_start,
        elastic_energy_change=engine.stored_contact_energy(),
        dissipated=dissipated,
        heat_generated=heat,
        heat_to_ball=float(np.sum(s.heat_into[:n] - initial["heat_into"][:n])),
        heat_to_vial=float(s.heat_into[n] - initial["heat_into"][n]),
        not_converted_to_heat=dissipated - heat,
        stored_ball=float(np.dot(k.capacity_ball, warming[:n])),
        stored_vial=float(k.capacity_vial * warming[n]),
        stored_air=float(k.capacity_air * warming[n + 1]),
        heat_lost_to_surroundings=float(totals[model.HEAT_LOST]),
        projection_correction=0.0,
        work_by_gravity=float(totals[model.WORK_GRAVITY]),
        work_by_stiffening=float(totals[model.WORK_STIFFENING]),
        dissipated_by_channel={name: float(value) for name, value in channels.items()},
    )


_PER_BALL = ("time", "ball")
_VECTORS = ("time", "ball", "axis")


def dem_history(rows: np.ndarray, k: model.Constants) -> StateHistory:
    """Recorded state rows (:func:`model.row_fields`) as a history (:func:`history_of`)."""
    return history_of(*model.unpack_rows(rows, k.n_balls), k)


def history_of(times: np.ndarray, fields: dict[str, np.ndarray], k: model.Constants) -> StateHistory:
    """The states with units: temperatures of each ball (and their mean, ``theta_ball``), vial and air, the
    balls' motion in the lab frame (axis x, y, z; z up), the vial's pose and the running totals."""
    n = k.n_balls
    theta, totals, heat_into = fields["temperature"], fields["totals"], fields["heat_into"]
    terms, vial = fields["velocity_term_integral"], fields["vial"]
    variables: dict[str, tuple[np.ndarray, dict[str, str]]] = {
        "theta_ball": (theta[:, :n].mean(axis=1), _attributes("K", "mean ball temperature")),
        "theta_vial": (theta[:, n], _attributes("K", "vial temperature")),
        "theta_air": (theta[:, n + 1], _attributes("K", "inner air temperature")),
        BALL_TEMPERATURES: (theta[:, :n], _attributes("K", "temperature of each ball")),
    }
    for name in (*CELSIUS_VARIABLES, BALL_TEMPERATURES):
        kelvin, attributes = variables[name]
        variables[f"{name}_C"] = (kelvin_to_celsius(kelvin), _attributes("degC", attributes["long_name"]))
    for name, units, long_name in (
        ("position", "m", "ball centre, lab frame"),
        ("velocity", "m s-1", "ball velocity, lab frame"),
        ("angular_velocity", "rad s-1", "ball angular velocity, lab frame"),
    ):
        variables[name] = (fields[name], _attributes(units, long_name))
    variables["vial_centre"] = (vial[:, :3], _attributes("m", "vial centre, lab frame"))
    variables["vial_angles"] = (vial[:, 3:], _attributes("rad", "vial roll, pitch and yaw"))
    for index, name in enumerate(model.TOTAL_NAMES):
        variables[name] = (totals[:, index], _attributes("J", f"cumulative {name.replace('_', ' ')}"))
    dissipated = totals[:, model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1].sum(axis=1)
    variables["dissipated"] = (dissipated, _attributes("J", "cumulative energy dissipated in contacts"))
    variables["heat_into_balls"] = (heat_into[:, :n], _attributes("J", "cumulative impact heat into each ball"))
    variables["heat_into_vial"] = (heat_into[:, n], _attributes("J", "cumulative impact heat into the vial"))
    variables["velocity_term_integrals"] = (terms, _attributes("s", "time integral of each ball's Whitaker velocity term"))
    variables["velocity_term_integral"] = (terms.mean(axis=1), _attributes("s", "the balls' mean of velocity_term_integrals"))
    dimensions = {name: _PER_BALL for name in (BALL_TEMPERATURES, f"{BALL_TEMPERATURES}_C", "heat_into_balls", "velocity_term_integrals")}
    dimensions.update({name: _VECTORS for name in ("position", "velocity", "angular_velocity")})
    dimensions.update(vial_centre=("time", "axis"), vial_angles=("time", "angle"))
    return StateHistory(times, variables, dimensions)


def _attributes(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


def _settled_steady_state(params: Parameters, k: model.Constants, history: StateHistory) -> SteadyState:
    """The steady state (MODEL.md §11) for the means of the run's second half: its settled motion."""
    times = history.times
    heat = np.append(settled_rates(times, history["heat_into_balls"]), settled_rates(times, history["heat_into_vial"]))
    return _network_steady_state(params, k, heat, settled_rates(times, history["velocity_term_integrals"]))


def _network_steady_state(params: Parameters, k: model.Constants, heat: np.ndarray, terms: np.ndarray) -> SteadyState:
    return network_steady_state(
        params, lambda theta: network.rates(theta, heat, terms, k), float(heat.sum()), float(terms.mean()), k.n_balls
    )


AVERAGING_FAILED = -10
# As the 1-D averaged solver: a node's thermal time constant over the time between the impacts that heat it.
TIME_SCALE_SEPARATION = 20.0


@dataclass(frozen=True)
class Means:
    """Means of the settled motion: heat power into each ball and the vial (W), each ball's Whitaker term."""

    heat: np.ndarray
    terms: np.ndarray
    averages: MechanicsAverages


def measure_means(params: Parameters, engine: Engine, progress: ProgressCallback | None) -> tuple[Means, int]:
    """Run the mechanics batch by batch until the per-ball means converge (or averaging_max_time); returns
    the means and the engine's last status."""
    batch = params.averaging_batch_periods * 2.0 * math.pi / params.omega
    n = params.n_balls
    cumulative = [np.concatenate([engine.state.heat_into, engine.state.velocity_term_integral, [_dissipated(engine)]])]
    heartbeat = None if progress is None else lambda t: progress(t, params.averaging_max_time)
    status, converged, cut, message = REACHED_STOP, False, 0, ""
    while True:
        status = engine.advance(engine.t + batch, heartbeat)
        if status != REACHED_STOP:
            message = f"the mechanics failed: {engine.explain(status)}"
            break
        cumulative.append(np.concatenate([engine.state.heat_into, engine.state.velocity_term_integral, [_dissipated(engine)]]))
        rates = batch_rates(np.array(cumulative), batch)  # (batches, N + 1 heat, N terms, dissipated)
        if len(rates) >= 2 * params.averaging_min_batches:
            totals = np.column_stack([rates[:, : n + 1].sum(axis=1), rates[:, n + 1 : 2 * n + 1].mean(axis=1)])
            cut = max(mser_truncation(normalised(column)) for column in totals.T)
            kept = rates[cut:]
            if len(kept) >= params.averaging_min_batches and _settled(kept, totals[cut:], n, params.dem_averaging_rel_error):
                converged = True
                message = f"converged after {engine.t:.3g} s of mechanics ({len(kept)} batches of {batch:.3g} s)"
                break
        if engine.t + batch > params.averaging_max_time:
            message = (
                f"the per-ball averages did not converge to a relative standard error of {params.dem_averaging_rel_error:g} within averaging_max_time = {params.averaging_max_time:g} s "
                "(irregular or slowly settling motion)"
            )
            break
    rates = batch_rates(np.array(cumulative), batch)[cut:] if len(cumulative) > 1 else np.full((1, 2 * n + 2), np.nan)
    return _means(rates, n, cut * batch, batch, engine, converged, message), status


def _dissipated(engine: Engine) -> float:
    return float(engine.state.totals[model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1].sum())


def _settled(kept: np.ndarray, totals: np.ndarray, n: int, target: float) -> bool:
    """Whether the totals and each ball's (and the vial's) means are known to ``target`` relative error."""
    columns = np.column_stack([totals, kept[:, : 2 * n + 1]])
    return all(relative_error(column) <= target for column in columns.T)


def _means(rates: np.ndarray, n: int, transient: float, batch: float, engine: Engine, converged: bool, message: str) -> Means:
    heat, terms = rates[:, : n + 1].mean(axis=0), rates[:, n + 1 : 2 * n + 1].mean(axis=0)
    total_heat = rates[:, : n + 1].sum(axis=1)
    mean_terms = rates[:, n + 1 : 2 * n + 1].mean(axis=1)
    window = len(rates) * batch
    impacts = int(np.sum(engine.records[:, 0] >= transient)) if len(engine.records) else 0
    averages = MechanicsAverages(
        heat_power=float(total_heat.mean()),
        heat_power_stderr=standard_error(total_heat),
        dissipated_power=float(rates[:, -1].mean()),
        velocity_term=float(mean_terms.mean()),
        velocity_term_stderr=standard_error(mean_terms),
        transient=transient,
        window=window,
        batches=len(rates),
        impact_interval=window / impacts if impacts else math.inf,
        converged=converged,
        message=message,
    )
    return Means(heat, terms, averages)


# Keys that enter only the thermal network, never a force or the heat a contact makes (λ, η and the
# balls' effusivities split that heat inside the stepper, and the air's properties set the Whitaker term):
# runs that differ in these alone share their mechanics, so a fit of the vial's heat loss measures it once.
THERMAL_ONLY_KEYS = (
    "h_inner", "h_outer", "inner_area", "outer_area", "vial_mass", "vial_heat_capacity", "beta",
    "ambient_temperature", "initial_temperature", "duration", "output_interval",
)


@dataclass(frozen=True)
class Mechanics:
    """The mechanics phase of an averaged run: the engine after it, its first row, which recorded rows lie in
    a record window, the means, and the engine's status. Reusable by runs that differ in THERMAL_ONLY_KEYS."""

    params: Parameters
    engine: Engine
    start: np.ndarray
    in_window: np.ndarray
    means: Means | None  # None when the mechanics stopped early
    status: int

    @property
    def explanation(self) -> str:
        return INTERRUPTED_MESSAGE if self.status == INTERRUPTED else self.engine.explain(self.status)

    def serves(self, params: Parameters) -> bool:
        return params.replace(**{key: getattr(self.params, key) for key in THERMAL_ONLY_KEYS}) == self.params


def settle_mechanics(params: Parameters, progress: ProgressCallback | None = None, budget: RunBudget | None = None) -> Mechanics:
    """Run the mechanics until the per-ball means converge; Ctrl-C ends it with the status INTERRUPTED and
    keeps the engine, so that what it integrated can still be returned."""
    marks, _, in_window = _marks(params, np.zeros(1), params.averaging_max_time)
    budget = budget if budget is not None else RunBudget.of(params)
    engine = Engine(params, budget, marks[1:] if marks.size and marks[0] == 0.0 else marks)
    start = engine.row_now()
    try:
        means, status = measure_means(params, engine, progress)
    except KeyboardInterrupt:
        means, status = None, INTERRUPTED
    return Mechanics(params, engine, start, in_window, means, status)


def simulate_dem_averaged(params: Parameters, progress: ProgressCallback | None, budget: RunBudget,
                          mechanics: Mechanics | None = None) -> Result:
    """Mechanics until the per-ball means converge (or ``mechanics`` measured before, for parameters that
    differ in THERMAL_ONLY_KEYS alone), then the N + 2 node network for the whole duration."""
    started = time.perf_counter()
    if mechanics is None:
        mechanics = settle_mechanics(params, progress, budget)
    elif not mechanics.serves(params):
        raise ValueError("mechanics: measured for parameters that differ in more than the thermal-only keys")
    if mechanics.status != REACHED_STOP or mechanics.means is None:
        return _stopped(params, mechanics, mechanics.status, mechanics.explanation, started)
    engine, start, means = mechanics.engine, mechanics.start, mechanics.means
    k = model.constants_from(params)
    problem = None if not means.averages.converged else _time_scales_problem(engine, k, means)
    if not means.averages.converged or problem is not None:
        if problem is not None:
            means = Means(means.heat, means.terms, _with_message(means.averages, problem))
        return _refuse(params, mechanics, means, progress, budget, started)
    times = sample_times(params)
    thermal = _integrate_network(params, k, means, times)
    if progress is not None:
        progress(params.duration, params.duration)
    if not thermal.success:
        means = Means(means.heat, means.terms, _with_message(means.averages, f"the thermal network solver failed: {thermal.message}"))
        return _refuse(params, mechanics, means, progress, budget, started)
    in_window = mechanics.in_window
    windows = np.vstack([start, engine.rows])[in_window[: len(engine.rows) + 1]] if in_window.size else start[:0]
    impacts = impact_columns(engine.records, since=means.averages.transient)
    result = Result(
        params=params,
        status=REACHED_STOP,
        message=f"Averaged solver: {means.averages.message}; thermal network integrated to {params.duration:g} s.",
        t_end=params.duration,
        history=history_of(thermal.t, _averaged_fields(thermal, means, k, params), k),
        window_history=dem_history(windows, k),
        impact_columns=impacts,
        counters=_counters(engine, thermal_rhs_evaluations=int(thermal.nfev)),
        wall_time=time.perf_counter() - started,
        energy=_averaged_energy(params, k, means, thermal, impacts),
        ball_fit=fit_exponential(thermal.t, thermal.y[: k.n_balls].mean(axis=0), params.initial_temperature),
        solver="averaged",
        impact_window=means.averages.window,
        averages=means.averages,
    )
    steady = _network_steady_state(params, k, means.heat, means.terms)
    return conclude(result, steady.heat_power, steady.velocity_term, steady)


def _time_scales_problem(engine: Engine, k: model.Constants, means: Means) -> str | None:
    """Why averaging is not valid, or None: every ball's and the vial's thermal time constant (``k``'s) must
    exceed the time between the impacts that heat it by TIME_SCALE_SEPARATION, or its temperature follows
    single impacts."""
    n = k.n_balls
    window = means.averages.window
    records = impact_columns(engine.records, since=means.averages.transient)
    # Conductances (W/K) as the heat flows of 1 K excess of each ball over the air, at ambient temperature
    # (Sutherland's factor changes them by a few percent only).
    theta = np.full(n + 2, k.t_ambient)
    theta[:n] += 1.0
    flow = np.empty(n + 2)
    network.flows(theta, means.terms, k, flow)
    constants = [k.capacity_ball[ball] / flow[ball] if flow[ball] > 0 else math.inf for ball in range(n)]
    vial_conductance = k.h_inner * k.inner_area + k.h_outer * k.outer_area
    constants.append(k.capacity_vial / vial_conductance if vial_conductance > 0 else math.inf)
    hits = [int(np.sum(records["ball"] == ball) + np.sum(records["other_ball"] == ball)) for ball in range(n)]
    hits.append(int(np.sum(records["target"] != "ball")))
    for node, (constant, count) in enumerate(zip(constants, hits, strict=True)):
        if count and constant < TIME_SCALE_SEPARATION * window / count:
            name = f"ball {node}" if node < n else "vial"
            return (
                f"the {name}'s thermal time constant ({constant:.3g} s) is not well separated from the time between "
                f"the impacts that heat it ({window / count:.3g} s): its temperature follows single impacts"
            )
    return None


def _with_message(averages: MechanicsAverages, message: str) -> MechanicsAverages:
    return MechanicsAverages(**{**averages.__dict__, "converged": False, "message": message})


def _counters(engine: Engine, **extra: int) -> dict[str, int]:
    counters = {name: int(value) for name, value in zip(stepper.COUNTER_NAMES, engine.counters)}
    counters.update(rejected_steps=0, rhs_evaluations=counters["steps"], **extra)
    return counters


def _integrate_network(params: Parameters, k: model.Constants, means: Means, times: np.ndarray):
    """The N + 2 node network with the means of the mechanics, and the heat it loses (LSODA, as the 1-D
    averaged solver: the air node is ~10⁴ times faster than the vial)."""
    n = k.n_balls
    flow = np.empty(n + 2)

    def rates(t: float, state: np.ndarray) -> np.ndarray:
        theta = state[:-1]
        network.flows(theta, means.terms, k, flow)
        return np.append(network.rates(theta, means.heat, means.terms, k), flow[n + 1])

    initial = np.append(model.initial_state(params, k).temperature, 0.0)
    return solve_ivp(rates, (0.0, params.duration), initial, method="LSODA", t_eval=times, rtol=THERMAL_RTOL, atol=THERMAL_ATOL)


def _averaged_fields(thermal, means: Means, k: model.Constants, params: Parameters) -> dict[str, np.ndarray]:
    """Recorded-state fields of the averaged run: the temperatures, and the mean flows times time; the
    motion (not computed) is NaN, the vial's pose is its prescribed motion."""
    n, times = k.n_balls, thermal.t
    count = times.size
    totals = np.zeros((count, len(model.TOTAL_NAMES)))
    dissipated = means.averages.dissipated_power
    totals[:, model.WORK_VIAL] = dissipated * times  # on average the balls' kinetic energy does not change
    totals[:, model.HEAT_GENERATED] = means.heat.sum() * times
    totals[:, model.HEAT_LOST] = thermal.y[-1]
    totals[:, model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1] = np.nan  # the split is in the window's impacts
    vial = np.zeros((count, 6))
    rates = np.zeros(6)
    for row, t in enumerate(times):
        fourier_coordinates(t, k.omega, k.phase, k.harmonics, vial[row], rates)
    motion = np.full((count, n, 3), np.nan)
    return {
        "position": motion,
        "velocity": motion,
        "angular_velocity": motion,
        "temperature": thermal.y[:-1].T,
        "totals": totals,
        "heat_into": np.outer(times, means.heat),
        "velocity_term_integral": np.outer(times, means.terms),
        "vial": vial,
    }


def _averaged_energy(params: Parameters, k: model.Constants, means: Means, thermal, impacts: dict) -> EnergyAudit:
    """The audit of the averaged run: mean rates times the duration; the split by channel is that of the
    contacts of the averaging window."""
    n = k.n_balls
    heat = float(means.heat.sum() * params.duration)
    dissipated = means.averages.dissipated_power * params.duration
    warming = thermal.y[:-1, -1] - thermal.y[:-1, 0]
    by_channel = np.array([float(np.sum(impacts[f"dissipated_{name}"])) for name in model.CHANNELS])
    shares = by_channel / by_channel.sum() if by_channel.sum() > 0 else np.zeros(len(model.CHANNELS))
    return EnergyAudit(
        work_by_vial=dissipated,
        kinetic_energy_change=0.0,
        elastic_energy_change=0.0,
        dissipated=dissipated,
        heat_generated=heat,
        heat_to_ball=float(means.heat[:n].sum() * params.duration),
        heat_to_vial=float(means.heat[n] * params.duration),
        not_converted_to_heat=dissipated - heat,
        stored_ball=float(np.dot(k.capacity_ball, warming[:n])),
        stored_vial=float(k.capacity_vial * warming[n]),
        stored_air=float(k.capacity_air * warming[n + 1]),
        heat_lost_to_surroundings=float(thermal.y[-1, -1]),
        projection_correction=0.0,
        dissipated_by_channel={name: float(share * dissipated) for name, share in zip(model.CHANNELS, shares)},
    )


def _stopped(params: Parameters, mechanics: Mechanics, status: int, message: str, started: float) -> Result:
    """The mechanics phase ended early (Ctrl-C, budget, engine failure) or averaging is refused: what it
    integrated, as a full run of that stretch."""
    engine, start = mechanics.engine, mechanics.start
    samples = np.vstack([start, engine.row_now()])
    message = f"{message} Stopped in the averaged solver's mechanics phase at t = {engine.t:.6g} s; the motion and impacts up to then are kept."
    result = _result(params, engine, start, samples, start[:0], status, message, time.perf_counter() - started, solver="averaged")
    steady = _settled_steady_state(params, engine.constants, result.history)
    return conclude(result, steady.heat_power, steady.velocity_term, steady)


def _refuse(params: Parameters, mechanics: Mechanics, means: Means, progress: ProgressCallback | None,
            budget: RunBudget, started: float) -> Result:
    """Averaging is not valid: fall back to full resolution, or fail, as ``averaging_fallback`` says."""
    problem = means.averages.message
    if params.averaging_fallback == "fail":
        reason = f"Averaging is not valid: {problem}. Set averaging_fallback = 'full' to run at full resolution."
        result = _stopped(params, mechanics, AVERAGING_FAILED, reason, started)
        result.message, result.averages = reason, means.averages
        return result
    result = simulate_dem_full(params, progress, budget)
    result.message = f"Averaging is not valid ({problem}); ran at full resolution instead. {result.message}"
    result.averages = means.averages
    result.wall_time = time.perf_counter() - started
    return conclude(result, result.steady.heat_power, result.steady.velocity_term, result.steady)
