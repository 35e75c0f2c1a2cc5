"""What a run produced, from any engine and solver: :class:`Result` with its state histories, impacts and energy
audit (``engines/records.py``), its summary, and the conclusions every run gets (steady state, physical bounds,
warnings)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from shakermill.analysis.attractors import AttractorScan
from shakermill.analysis.fit import ExponentialFit, increment_ratio
from shakermill.analysis.impacts import Contacts, contacts_of
from shakermill.analysis.regime import ACTIVE, INTERMITTENT, Switching, charge_regime
from shakermill.analysis.sections import further_nodes
from shakermill.analysis.steady import SteadyState, fits_no_exponential, run_length_note, settled_rates, steady_state
from shakermill.analysis.stress_energy import stress_spectrum
from shakermill.engines.interface import EngineDescription
from shakermill.engines.records import (
    BALL_TEMPERATURES,
    EnergyAudit,
    StateHistory,
    kelvin_to_celsius,
)
from shakermill.engines.status import REACHED_STOP
from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork
from shakermill.engines.thermal.nodes import Node
from shakermill.parameters.defaults import FAST_IMPACT_SPEED, HIT_SPEED
from shakermill.parameters.keys import Parameters, unit_slip_warnings
from shakermill.solvers.summary import Summary
from shakermill.solvers.summary_sections import (
    Averaging,
    Charge,
    EndTemperatures,
    Heat,
    Impacts,
    Inputs,
    Numerics,
    Outcome,
)
from shakermill.support.presenters import present

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr

INTERRUPTED = 1
INTERRUPTED_MESSAGE = "Interrupted by the user; the results cover the time simulated so far."
# The run finished, but a temperature left the range where the model means anything.
OUT_OF_PHYSICAL_BOUNDS = -5
# The run finished, but its energy audit does not close within ENERGY_AUDIT_TOLERANCE.
ENERGY_AUDIT_FAILED = -6
# The run stayed in range, but what it answers beyond its end (a node's steady state, the fitted θ∞) is above
# PHYSICAL_CEILING: no charge gets there; its heat has (nearly) no way out. -7 is the 1-D engine's WINDOWS_FULL.
UNPHYSICAL_ANSWER = -8
# K, 2,000 °C: above it every node of a mill (steel, air, a metal powder) has melted or the model has no meaning.
PHYSICAL_CEILING = 2273.15
# Relative residual of the energy audit above which a run's heat and temperatures are not to be trusted.
# With the energy projection the balance closes to round-off (~1e-11 over the operating range, presets
# included); without it, it shows the contacts' truncation error: 0.2–0.8 % at the default rtol for
# e ≤ 0.7, 5 % at e = 0.95, 9 % at rtol 0.1. A ball so light (ball_density = 1e-6) that its energies fall
# below the temperature tolerance left 55–77 % of the heat unaccounted for.
ENERGY_AUDIT_TOLERANCE = 1e-2


@dataclass(frozen=True)
class MechanicsAverages:
    """Time averages of the settled motion, with standard errors from batch means."""

    heat_power: float  # W, mean irreversible heat rate
    heat_power_stderr: float
    dissipated_power: float  # W
    velocity_term: float  # mean of 0.4 Re^{1/2} + 0.06 Re^{2/3}
    velocity_term_stderr: float
    transient: float  # s cut from the start
    window: float  # s averaged over
    batches: int
    impact_interval: float  # s, mean time between impacts in the window (inf without impacts)
    converged: bool
    message: str
    # Independent replicas of the mechanics pooled (solvers/replicas.py); transient and window are the first's.
    replicas: int = 1
    # The batches after grouping to uncorrelated means (MODEL.md §14.2): their length (s) and the largest |lag-1
    # autocorrelation| of the total heat and mean velocity term, and the mean heat power of the transient cut (W).
    batch_length: float = math.nan
    batch_autocorrelation: float = math.nan
    transient_heat_power: float = math.nan
    # The regime of each base batch of the first replica after its first (MODEL.md §14.2), and whether an intermittent
    # charge whose target error was out of reach within its mechanics was averaged with its error as it stands.
    switching: Switching | None = None
    as_it_stands: bool = False

    def as_summary(self) -> Averaging:
        return Averaging(
            heat_power_W=self.heat_power,
            heat_power_stderr_W=self.heat_power_stderr,
            dissipated_power_W=self.dissipated_power,
            velocity_term=self.velocity_term,
            velocity_term_stderr=self.velocity_term_stderr,
            transient_s=self.transient,
            window_s=self.window,
            batches=self.batches,
            replicas=self.replicas,
            batch_s=self.batch_length,
            batch_autocorrelation=self.batch_autocorrelation,
            transient_heat_power_W=self.transient_heat_power,
            converged=self.converged,
            message=self.message,
        )


# What ``repr(result)`` shows of its summary, and the longest message it prints whole.
REPR_HEADLINES = {
    "ball_C": "ball °C",
    "vial_C": "vial °C",
    "air_C": "air °C",
    "heat_power_W": "heat W",
    "impact_rate_hz": "impacts/s",
}
REPR_MESSAGE = 160


@dataclass
class RunOutput:
    """What a solver gathered of a run from its engine, before the conclusions every run gets (:func:`conclude` makes
    the :class:`Result`). ``success`` is False when the integrator stopped early."""

    params: Parameters
    status: int
    message: str
    t_end: float
    history: StateHistory  # the sampled states; ``timeseries`` is its xarray view
    window_history: StateHistory  # the full-resolution states in the record windows; ``windows``
    impact_columns: dict[str, np.ndarray]  # one entry per impact; ``impacts`` is the table
    counters: dict[str, int]
    wall_time: float
    energy: EnergyAudit
    ball_fit: ExponentialFit
    # What its engine declares (engines/interface.py): the layers above read it here, not by the engine's name.
    description: EngineDescription
    solver: str = "full"
    impact_window: float | None = None  # s covered by ``impacts``; None means the whole run
    averages: MechanicsAverages | None = None

    @property
    def success(self) -> bool:
        return self.status == REACHED_STOP

    @property
    def impact_count(self) -> int:
        """The impacts among the contact records (MODEL.md §14.4: chatter merged, touches left out)."""
        return self.contacts().impact_count

    def contacts(self, since: float = -math.inf) -> Contacts:
        """The run's contacts by the rules of its engine (:func:`counting_rules`), merged over all its records, that
        began at ``since`` (s) or later."""
        contacts = contacts_of(self.impact_columns, *counting_rules(self.params))
        return contacts if since == -math.inf else contacts.since(since)


def counting_rules(params: Parameters) -> tuple[float, float]:
    """The touch speed (m/s) and chatter factor its engine counts impacts by (MODEL.md §14.4); 0 and 0, which count
    every record, for an engine that reads neither (the 1-D engine's ball bounces between two walls)."""
    if "touch_speed" not in params.engine_keys.reads:
        return 0.0, 0.0
    return params.touch_speed, params.chatter_factor


@dataclass(repr=False, kw_only=True)
class Result(RunOutput):
    """Everything a run produced, concluded (:func:`conclude`): its steady state, heat paths, warnings, notes and
    summary. The summary is made from the rest when the result is; a solver that changes a result after (a fall-back,
    the attractor probe) makes it again (:func:`summarize`)."""

    steady: SteadyState
    # The mean load of the network the steady state and the heat paths were computed with (of the settled second
    # half, for a full run), and each heat path's mean flow over the run (W, from its hot end to its cold end;
    # MODEL.md §13.1).
    load: NetworkLoad
    heat_paths: dict[str, float] = field(default_factory=dict)
    attractors: AttractorScan | None = None  # the settled motions of other starts, where they were probed
    # One line each, for things a user should know that do not stop the run (stderr and summary.json).
    warnings: list[str] = field(default_factory=list)
    # Sentences of advice that is not a problem (how the solver was chosen, a run shorter than its time to steady
    # state): they belong to the run's answer, not to its warnings.
    notes: list[str] = field(default_factory=list)
    # Every number of the run by key, with its unit (solvers/summary.py).
    summary: Summary = field(init=False)

    def __post_init__(self) -> None:
        self.summary = summarize(self)

    def __repr__(self) -> str:
        """A few lines, as xarray and pandas objects print: what ran and how it ended, its headline numbers and the
        sizes of its data; the data themselves are ``timeseries``, ``impacts``, ``windows`` and ``summary``."""
        summary = self.summary
        shown = [f"{label} {summary.number(key):.4g}" for key, label in REPR_HEADLINES.items()]
        impacts = next(iter(self.impact_columns.values()), np.zeros(0)).size
        lines = [
            f"<shakermill.Result: engine {self.params.engine!r}, solver {self.solver!r}, "
            f"{'success' if self.success else f'status {self.status}'}, {self.t_end:g} s simulated in "
            f"{self.wall_time:.3g} s>",
            f"  {self.message if len(self.message) <= REPR_MESSAGE else self.message[: REPR_MESSAGE - 1] + '…'}",
            f"  {', '.join(shown)}",
            f"  data: {self.history.times.size} samples of {len(self.history.variables)} series, {impacts} contact "
            f"records, {self.window_history.times.size} window samples, {len(summary)} summary keys",
            *(
                [f"  {len(self.warnings)} warning{'s' if len(self.warnings) != 1 else ''} (.warnings)"]
                if self.warnings
                else []
            ),
        ]
        return "\n".join(lines)

    def warn(self, *lines: str | None, first: bool = False) -> None:
        """Add each of ``lines`` (None is skipped) to the warnings once: a run concluded again, or a scan attached
        again, must not repeat one. ``first``: before the others."""
        _add_once(self.warnings, lines, first)

    def note(self, *lines: str | None, first: bool = False) -> None:
        """Add each of ``lines`` (None is skipped) to the notes once, as :meth:`warn` does the warnings."""
        _add_once(self.notes, lines, first)

    @cached_property
    def timeseries(self) -> xr.Dataset:
        """The sampled state history (units in the attributes, temperatures also in °C as ``theta_*_C``)."""
        return self.history.dataset()

    @cached_property
    def windows(self) -> xr.Dataset:
        """The full-resolution state inside the record windows."""
        return self.window_history.dataset()

    @cached_property
    def impacts(self) -> pd.DataFrame:
        """One row per contact record, SI units (its engine's ``description.impact_units``): every contact, chatter
        and touches included; :meth:`contacts` tells the impacts among them (MODEL.md §14.4)."""
        import pandas as pd

        return pd.DataFrame(self.impact_columns)

    def plot(self, *, impacts: bool = False) -> Any:
        """The paper's figures of this run (and the impact figures if asked), by name, as a
        :class:`~shakermill.views.notebook.FigureSet`; a notebook shows them."""
        return present("result figures", self, impacts=impacts)

    def _repr_html_(self) -> str:
        return present("result html", self)


def _add_once(said: list[str], lines: Sequence[str | None], first: bool) -> None:
    new = [line for line in _once(lines) if line not in said]
    position = 0 if first else len(said)
    said[position:position] = new


def _once(lines: Sequence[str | None]) -> list[str]:
    """``lines`` in order, each once, without the None."""
    return [line for line in dict.fromkeys(lines) if line is not None]


def conclude(output: RunOutput, network: ThermalNetwork, load: NetworkLoad) -> Result:
    """The result of ``output``: the steady state of ``network`` under ``load`` (MODEL.md §11), the mean flow of each
    heat path over the run, physical bounds, energy audit and warnings of a finished run, then its summary."""
    params = output.params
    steady = steady_state(network, load)
    status, message = output.status, output.message
    checks = (
        (OUT_OF_PHYSICAL_BOUNDS, lambda: physical_bounds_problem(output, network)),
        (ENERGY_AUDIT_FAILED, lambda: energy_audit_problem(output)),
        (UNPHYSICAL_ANSWER, lambda: unphysical_answer(output, network, steady)),
    )
    for code, problem_of in checks:
        problem = problem_of() if status == REACHED_STOP else None
        if problem is not None:
            status, message = code, problem
    gathered = {item.name: getattr(output, item.name) for item in fields(RunOutput)}
    warnings = [*unit_slip_warnings(params), steady_state_bound_warning(params, steady), fit_warning(output, steady)]
    return Result(
        **{**gathered, "status": status, "message": message},
        steady=steady,
        load=load,
        heat_paths=mean_path_flows(network, output.history, load.drives),
        warnings=_once(warnings),
        notes=_once([run_length_note(output.t_end, steady)]),
    )


def node_temperatures(network: ThermalNetwork, history: StateHistory) -> np.ndarray:
    """Every node's temperature (K) at the samples of ``history``, over (node, time)."""
    balls = (
        history[BALL_TEMPERATURES].T if BALL_TEMPERATURES in history.variables else np.atleast_2d(history["theta_ball"])
    )
    others = [history[f"theta_{node.name}"] for node in network.nodes[network.n_balls :]]
    return np.vstack([balls, *others])


def mean_path_flows(network: ThermalNetwork, history: StateHistory, drives: np.ndarray) -> dict[str, float]:
    """Each path's flow (W) averaged over the run: at the sampled temperatures and the motion's mean ``drives``,
    by the trapezoidal rule; for a run of no length, at its start."""
    theta = node_temperatures(network, history)
    flows = network.flows_over(theta, drives)
    times = history.times
    span = times[-1] - times[0]
    means = np.trapezoid(flows, times, axis=0) / span if span > 0 else flows[0]
    return {path.name: float(value) for path, value in zip(network.paths, means, strict=True)}


def physical_bounds_problem(result: RunOutput, network: ThermalNetwork) -> str | None:
    """Why the temperatures of a run cannot be physical, or None: a ball above ball_temperature_limit, any other node
    above :data:`PHYSICAL_CEILING`, any below absolute zero."""
    series = result.history
    balls = series[BALL_TEMPERATURES if BALL_TEMPERATURES in series.variables else "theta_ball"]
    # With no balls (an empty mill) there is nothing to reduce: the initial value keeps nanmax from raising.
    hottest_ball = float(np.nanmax(balls, initial=-np.inf))
    limit = result.params.ball_temperature_limit
    if hottest_ball > limit:
        return (
            f"The ball temperature reached {kelvin_to_celsius(hottest_ball):.4g} °C, above ball_temperature_limit "
            f"({kelvin_to_celsius(limit):.4g} °C): the model does not hold there. Check omega, amplitude and the "
            "units of the inputs (bare numbers are SI)."
        )
    for node in network.others:
        if f"theta_{node.name}" not in series.variables:
            continue
        peak = float(np.nanmax(series[f"theta_{node.name}"], initial=-np.inf))
        ceiling, what = node_ceiling(node)
        if peak > ceiling:
            return (
                f"The {node.name} temperature reached {kelvin_to_celsius(peak):.4g} °C, above {what}: the model does "
                "not hold there. Check the heat paths' coefficients and the units of the inputs."
            )
    coldest = min(float(np.nanmin(series[name], initial=np.inf)) for name in ("theta_ball", "theta_vial", "theta_air"))
    if coldest < 0.0:
        return f"A temperature fell to {coldest:.4g} K, below absolute zero: the thermal network is not physical here."
    return None


def node_ceiling(node: Node) -> tuple[float, str]:
    """The highest temperature (K) ``node`` may reach, and what it is in words: its material's melting point where
    known and lower, :data:`PHYSICAL_CEILING` otherwise."""
    ceiling = f"{kelvin_to_celsius(PHYSICAL_CEILING):.4g} °C"
    if node.melting_point is None or node.melting_point >= PHYSICAL_CEILING:
        return PHYSICAL_CEILING, ceiling
    melts = f"{kelvin_to_celsius(node.melting_point):.4g} °C"
    return node.melting_point, f"{melts}, the melting point of its material ({node.material})"


def unphysical_answer(result: RunOutput, network: ThermalNetwork, steady: SteadyState) -> str | None:
    """Why what a run answers beyond its end, the fitted θ∞ of the balls or a node's steady state, is no temperature
    a mill reaches (above :data:`PHYSICAL_CEILING`, or a node's melting point), or None."""
    # A fit of a run shorter than its network's time constants is an extrapolation the summary already marks as not
    # describing the run: its θ∞ is no answer of the run, and a short run must not fail on it.
    fit_answers = result.ball_fit.success and not fits_no_exponential(result.t_end, steady)
    everywhere = (PHYSICAL_CEILING, f"{kelvin_to_celsius(PHYSICAL_CEILING):.4g} °C")
    answers = {"the balls' fitted theta_inf": (result.ball_fit.theta_inf if fit_answers else math.nan, everywhere)}
    if steady.solved:
        nodes = {node.name: node for node in network.others}
        answers |= {
            "the ball's steady state": (steady.ball, everywhere),
            "the vial's steady state": (steady.vial, everywhere),
        }
        answers |= {
            f"the {name}'s steady state": (value, node_ceiling(nodes[name]) if name in nodes else everywhere)
            for name, value in steady.others
        }
    for what, (value, (ceiling, said)) in answers.items():
        if value > ceiling:
            return (
                f"The run is not physical: {what} is {kelvin_to_celsius(value):.4g} °C, above {said}, where no mill "
                "goes: its heat has almost no way out, or far more heat is made than a mill makes. "
                "Check the heat paths' coefficients (h_outer, h_inner, the powder's) and the units of the inputs."
            )
    return None


def energy_audit_problem(result: RunOutput) -> str | None:
    """Why the energy audit of a run says its heat cannot be trusted, or None."""
    residual = result.energy.relative_residual
    if residual <= ENERGY_AUDIT_TOLERANCE:
        return None
    projection = "leave energy_projection on" if result.params.energy_projection else "turn energy_projection on"
    return (
        f"The energy audit does not close: its relative residual is {residual:.3g}, above {ENERGY_AUDIT_TOLERANCE:g}, "
        "so the heat and the temperatures of this run cannot be trusted. Tighten rtol and the absolute tolerances "
        f"(atol_temperature where the energies are very small), {projection}, and check the inputs."
    )


def shorter_than_its_network(result: Result) -> bool:
    """Whether the run ended before its network's slowest time constant, so that no exponential was to be expected
    (:func:`~shakermill.analysis.steady.fits_no_exponential`)."""
    return fits_no_exponential(result.t_end, result.steady)


def fit_warning(output: RunOutput, steady: SteadyState) -> str | None:
    """A line when the exponential fit of the ball temperature failed: the summary's θ∞, τ and θ̇₀ then mean nothing."""
    fit = output.ball_fit
    if fit.success or output.params.n_balls == 0:  # an empty mill has no ball to fit
        return None
    if fits_no_exponential(output.t_end, steady):
        return None  # no exponential was to be expected: run_length_note says why
    return (
        f"the exponential fit of the ball temperature failed ({fit.message}): theta_inf_C, tau_min and "
        "rate0_C_per_min are not usable"
    )


def steady_state_bound_warning(params: Parameters, steady: SteadyState) -> str | None:
    """A line when the run stays in range but its steady state would not."""
    limit = params.ball_temperature_limit
    # Written as "not above" so that the NaN ball of an empty mill gives no warning.
    if not steady.solved or not steady.ball > limit:
        return None
    return (
        f"the ball's steady state ({kelvin_to_celsius(steady.ball):.4g} °C) is above ball_temperature_limit "
        f"({kelvin_to_celsius(limit):.4g} °C): a longer run would leave the model's range"
    )


def understood_inputs(params: Parameters) -> Inputs:
    """The inputs people most often give in other units, echoed in those units (guards against unit slips)."""
    cycles_per_second = params.frequency
    return Inputs(
        omega_rad_s=params.omega,
        omega_hz=cycles_per_second,
        omega_rpm=60.0 * cycles_per_second,
        amplitude_mm=params.amplitude * 1e3,
        ball_radius_mm=params.ball_radius * 1e3,
        vial_length_mm=params.vial_length * 1e3,
        vial_diameter_mm=params.vial_diameter * 1e3,
        ambient_temperature_C=kelvin_to_celsius(params.ambient_temperature),
        initial_temperature_C=kelvin_to_celsius(params.initial_temperature),
    )


def summarize(result: Result) -> Summary:
    """The run's :class:`~shakermill.solvers.summary.Summary` (``Result.summary``), printed by ``run --json`` and
    stored in ``summary.json``: each section built here or by what computed it, its keys declared with their units
    and meanings."""
    params = result.params
    duration = max(result.t_end, 1e-300)
    impact_window = result.impact_window if result.impact_window else duration
    dissipated_power = result.energy.dissipated / duration
    contacts = result.contacts()
    spectrum = stress_spectrum(
        contacts, impact_window, params.stress_energy_thresholds, dissipated_power, params.ball_masses()
    )
    impacts = impacts_section(result, contacts, impact_window)
    several = result.description.several_balls
    return Summary.compose(
        outcome=Outcome(
            status=result.status,
            success=result.success,
            message=result.message,
            solver=result.solver,
            simulated_s=result.t_end,
        ),
        fit=result.ball_fit.as_summary(describes_run=not shorter_than_its_network(result)),
        temperatures=end_temperatures_section(result),
        steady=result.steady.as_summary(each_ball=several),
        impacts=impacts,
        heat=heat_section(result, dissipated_power),
        charge=charge_section(result, settled_regime(result, contacts, dissipated_power)) if several else None,
        numerics=numerics_section(result),
        inputs=understood_inputs(params),
        stress=spectrum.as_summary(),
        averaging=result.averages.as_summary() if result.averages is not None else None,
        attractors=result.attractors.as_summary() if result.attractors is not None else None,
        warnings=result.warnings,
        notes=result.notes,
    )


def end_temperatures(history: StateHistory) -> dict[str, float]:
    """The temperature (°C) at the end of every node ``history`` holds as ``theta_<node>`` (K, over time alone), by the
    node's name: the ball (the balls' mean), the vial, the air and any further node of the network."""
    found = {}
    for name, (values, attributes) in history.variables.items():
        node = name.removeprefix("theta_")
        if node != name and attributes.get("units") == "K" and history.dims(name) == ("time",):
            found[node] = kelvin_to_celsius(float(values[-1]))
    return found


def end_temperatures_section(result: RunOutput) -> EndTemperatures:
    """Every node's temperature at the end of the run (a further node under its name in the summary: the holder for
    a clamp; one of no such name fails the summary), the vial's rise over the ball's, each ball's with several."""
    series = result.history
    ends = end_temperatures(series)
    main = ("ball", "vial", "air")
    holder, others = further_nodes({node: value for node, value in ends.items() if node not in main})
    balls = series[BALL_TEMPERATURES][-1] if result.description.several_balls else None
    return EndTemperatures(
        ball=ends["ball"],
        vial=ends["vial"],
        air=ends["air"],
        holder=holder,
        others=others,
        vial_ball_ratio=increment_ratio(
            float(series["theta_vial"][-1]), float(series["theta_ball"][-1]), result.params.initial_temperature
        ),
        each_ball_C=None if balls is None else [kelvin_to_celsius(float(value)) for value in balls],
        hottest_ball_C=None if balls is None else _hottest(balls),
    )


def _hottest(temperatures: np.ndarray) -> float:
    """The hottest of the balls' temperatures (K) in °C; NaN without balls."""
    return kelvin_to_celsius(float(np.nanmax(temperatures))) if temperatures.size else math.nan


def impacts_section(result: RunOutput, contacts: Contacts, window: float) -> Impacts:
    """The impacts of the table, which covers ``window`` seconds (the whole run, or the averaging window): their
    count over the whole run, rates, speeds, energy, and by kind with several balls; and the contact records and
    touches beside them (MODEL.md §14.4)."""
    impacts = contacts.impacts
    count = contacts.impact_count
    duration = max(result.t_end, 1e-300)
    scale = duration / window if window > 0 else math.nan
    speeds = impacts["impact_speed"]
    hits = speeds[speeds >= HIT_SPEED]
    on_walls = between_balls = None
    description = result.description
    if description.several_balls:
        wall = int(np.sum(impacts[description.impact_target] != "ball"))
        on_walls, between_balls = int(round(wall * scale)), int(round((count - wall) * scale))
    return Impacts(
        count=count if result.impact_window is None else int(round(count * scale)),
        rate_hz=_per_second(count, window),
        hit_rate_hz=_per_second(hits.size, window),
        mean_hit_speed_m_s=float(hits.mean()) if hits.size else math.nan,
        fast_rate_hz=_per_second(int(np.count_nonzero(speeds >= FAST_IMPACT_SPEED)), window),
        mean_speed_m_s=float(speeds.mean()) if count else math.nan,
        max_speed_m_s=float(speeds.max()) if count else math.nan,
        mean_dissipated_J=float(impacts["dissipated_energy"].mean()) if count else math.nan,
        on_walls=on_walls,
        between_balls=between_balls,
        records_hz=_per_second(contacts.record_count, window),
        touches_hz=_per_second(contacts.touch_count, window),
    )


def _per_second(count: int, window: float) -> float:
    return count / window if window > 0 else math.nan


def heat_section(result: Result, dissipated_power: float) -> Heat:
    """The mean heat and power of the contacts, the drive's heat, the heat paths' flows, and by dissipation channel
    (an engine that moves several balls splits its dissipation)."""
    duration = max(result.t_end, 1e-300)
    energy = result.energy
    by_channel = (
        {channel: dissipated / duration for channel, dissipated in energy.dissipated_by_channel.items()}
        if result.description.several_balls
        else {}
    )
    return Heat(
        heat_power_W=energy.heat_generated / duration,
        dissipated_power_W=dissipated_power,
        drive_heat_W=energy.drive_heat / duration,
        heat_paths_W=dict(result.heat_paths),
        dissipated_by_channel_W=by_channel,
        heat_by_channel_W={channel: result.params.eta * power for channel, power in by_channel.items()},
    )


@dataclass(frozen=True)
class SettledRegime:
    """The regime of a charge's settled motion and its measures (MODEL.md §14.2), over the window from ``start`` (s)
    to the end: the second half of a full run, the averaging window of an averaged one."""

    start: float
    lasting_share: float
    fast_impact_rate: float
    name: str | None
    switching: Switching | None = None


def settled_regime(result: RunOutput, contacts: Contacts, dissipated_power: float) -> SettledRegime:
    """The regime of ``result``'s settled motion, named from its ``contacts`` and the dissipation of that window alone,
    never the start-up's (MODEL.md §14.4); a full run's dissipated power over its window from its cumulative series.
    An averaged run whose batches switched back and forth is :data:`INTERMITTENT`."""
    if result.impact_window is None or result.averages is None:
        start = window = 0.5 * result.t_end
        dissipated_power = float(np.sum(settled_rates(result.history.times, result.history["dissipated"])))
        contacts = contacts.since(start)
    else:
        # The averaged solver's records begin with its window.
        start, window = result.averages.transient, result.impact_window
    share, fast, name = window_regime(result.params, contacts, window, dissipated_power)
    switching = result.averages.switching if result.averages is not None else None
    if switching is not None and switching.intermittent:
        name = INTERMITTENT
    return SettledRegime(start, share, fast, name, switching)


def window_regime(
    params: Parameters, contacts: Contacts, window: float, dissipated_power: float
) -> tuple[float, float, str | None]:
    """The share of the dissipation in lasting contacts, the impacts above 1 m/s a second and the regime they name
    (None where the share is not known) of ``contacts`` over ``window`` s, in which the contacts dissipated
    ``dissipated_power`` (W)."""
    share = stress_spectrum(contacts, window, dissipated_power=dissipated_power).lasting_share()
    fast = _per_second(int(np.count_nonzero(contacts.impacts["impact_speed"] >= FAST_IMPACT_SPEED)), window)
    name = charge_regime(share, fast, params.n_balls, params.frequency) if math.isfinite(share) else None
    return share, fast, name


def charge_section(result: RunOutput, regime: SettledRegime) -> Charge:
    """The balls of an engine that moves several: how many, how full the vial, the work of gravity and of the
    stiffening springs, and the regime of the charge's settled motion where the share of lasting contacts is
    known."""
    params, switching = result.params, regime.switching
    return Charge(
        engine=result.description.name,
        n_balls=params.n_balls,
        fill_fraction=params.fill_fraction,
        work_gravity_J=result.energy.work_by_gravity,
        work_stiffening_J=result.energy.work_by_stiffening,
        regime=regime.name,
        regime_from_s=regime.start,
        regime_lasting_share=regime.lasting_share,
        regime_fast_impact_rate_hz=regime.fast_impact_rate,
        regime_active_share=switching.share(ACTIVE) if switching is not None else math.nan,
        regime_switch_interval_s=switching.switch_interval if switching is not None else math.nan,
    )


def numerics_section(result: RunOutput) -> Numerics:
    """What the integration took (steps, rejected steps, evaluations, wall time) and how its energy audit closed."""
    counters, energy = result.counters, result.energy
    return Numerics(
        steps=counters["steps"],
        rejected_steps=counters.get("rejected_steps", 0),
        rhs_evaluations=counters.get("rhs_evaluations", counters["steps"]),
        wall_time_s=result.wall_time,
        energy_audit_residual=energy.relative_residual,
        energy_projection_relative=(energy.projection_correction / energy.dissipated if energy.dissipated > 0 else 0.0),
    )
