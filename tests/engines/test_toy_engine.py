"""A third engine, registered through the registry alone, runs through simulate (both solvers), storage, the summary
and a figure with no other module touched: the engine interface is the only seam (docs/ARCHITECTURE.md).

The toy is a point ball that crosses the vial's free gap at the vial's peak speed and bounces rigidly off each end
face, the vial handing back the kinetic energy the bounce's restitution took: each hit makes η·½·m·u²·(1 − e²) of
heat, λ of it into the ball. Its thermal network is the one every engine shares, integrated with the hits' mean
heat rate; its numbers are hand-computable, so the test checks them, not only that files appear."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

import shakermill as sm
from shakermill.cli.commands import app
from shakermill.engines.budget import RunBudget
from shakermill.engines.interface import ENGINE_CORE, Averaging, EngineDescription, Measured, capabilities_of
from shakermill.engines.records import CELSIUS_VARIABLES, EnergyAudit, StateHistory, attributes, with_celsius
from shakermill.engines.registry import describe, engine_named, engine_names, register, unregister
from shakermill.engines.status import BUDGET_EXCEEDED, REACHED_STOP
from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork, air_constants, build_network
from shakermill.io.runs import load_run, write_run
from shakermill.parameters.config import load_config
from shakermill.parameters.engine_keys import EngineKeys, reads_of
from shakermill.parameters.groups import AveragedSolver, Drive, PaperNetwork, RoomLoss, RunControl, Stroke, Vial
from shakermill.parameters.keys import FIELD_NAMES, Parameters
from shakermill.physics import thermal
from shakermill.views.figures.run import temperature_figure

IMPACT_UNITS = {
    "time": "s",
    "wall": "",
    "impact_speed": "m/s",
    "dissipated_energy": "J",
    "heat_generated": "J",
    "peak_force": "N",
    "max_overlap": "m",
    "duration": "s",
}
DESCRIPTION = EngineDescription(
    keys=EngineKeys(
        name="toy",
        title="the toy engine",
        summary="a point ball bouncing rigidly between the end faces",
        kinematics=("axial",),
        most_balls=1,
        thermal_models=("three_node",),
        networks=("paper",),
        air_moves_with_vial=False,
        # It keeps no record windows, and its ball starts at the gap's end whatever the drive's phase.
        reads=reads_of(RunControl, AveragedSolver, Vial, Drive, Stroke, PaperNetwork, RoomLoss)
        - {"record_windows", "phase"}
        | {"averaging_rel_error", "ball_radius", "restitution", "ball_density", "ball_material", "vial_material"},
    ),
    channels=("normal",),
    impact_units=IMPACT_UNITS,
    impact_target="wall",
    per_ball=(),
    read_back=("time", "x", "theta_ball", "theta_vial", "theta_air"),
    motion=("x", "velocity"),
    averaged_flows=("heat_generated", "velocity_term_integral"),
    heat_variables=("heat_generated",),
    term_variables=("velocity_term_integral",),
    status_messages={REACHED_STOP: "The toy reached the end."},
    averaging_error_key="averaging_rel_error",
    attractor_starts=False,
)
# The toy's core alone, registered under a name of its own: an engine without the capability Averaging.
CORE_DESCRIPTION = dataclasses.replace(
    DESCRIPTION, keys=dataclasses.replace(DESCRIPTION.keys, name="toy-core", title="the core of the toy engine")
)


class CoreToy:
    """The engine core (engines/interface.py, Engine), implemented for the toy (module docstring): all the full
    solver needs."""

    description: ClassVar[EngineDescription] = CORE_DESCRIPTION

    def __init__(
        self,
        params: Parameters,
        budget: RunBudget | None = None,
        samples: Sequence[float] = (0.0,),
        horizon: float = 0.0,
    ) -> None:
        self.params = params
        self.budget = budget if budget is not None else RunBudget.of(params)
        self.network = self.network_for(params)
        self.speed = params.amplitude * params.omega
        self.gap = params.vial_length / 2.0 - params.ball_radius
        self.hit_heat = params.eta * 0.5 * params.ball_mass * self.speed**2 * (1.0 - params.restitution**2)
        reynolds = thermal.reynolds_number(
            params.ball_radius, params.air_density, self.speed, air_constants(params)["viscosity_ambient"]
        )
        self.term = thermal.whitaker_velocity_term(reynolds)
        self.samples = np.asarray(samples, dtype=float)
        self.clock = 0.0
        self.temperatures = [self.network.initial_temperatures(params.initial_temperature)]
        self.lost = [0.0]
        self.times = [0.0]

    @classmethod
    def network_for(cls, params: Parameters) -> ThermalNetwork:
        return build_network(
            params,
            [params.ball_radius],
            [params.ball_mass * params.ball_heat_capacity],
            ("ball",),
            "λ of each hit's heat",
        )

    @property
    def heat_power(self) -> float:
        return self.hit_heat * self.speed / (2.0 * self.gap)

    @property
    def t(self) -> float:
        return self.clock

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        if self.budget.spent():
            return BUDGET_EXCEEDED
        grid = self.samples[(self.samples > self.clock) & (self.samples <= t_stop)]
        load = self.load(np.array([self.heat_power]), np.array([self.term]))

        def rates(t: float, state: np.ndarray) -> np.ndarray:
            node_rates, lost = self.network.rates(state[:-1], load.heat, load.terms)
            return np.append(node_rates, lost)

        start = np.append(self.temperatures[-1], self.lost[-1])
        solution = solve_ivp(
            rates, (self.clock, t_stop), start, method="LSODA", t_eval=np.union1d(grid, [t_stop]), rtol=1e-9, atol=1e-9
        )
        for time, state in zip(solution.t, solution.y.T):
            self.times.append(float(time))
            self.temperatures.append(state[:-1])
            self.lost.append(float(state[-1]))
        self.clock = t_stop
        return REACHED_STOP

    def explain(self, status: int) -> str:
        return self.budget.explain(status, DESCRIPTION.status_messages)

    def _states(self, times: np.ndarray, theta: np.ndarray, lost: np.ndarray) -> StateHistory:
        """The history at ``times`` (s) of the temperatures ``theta`` (time, node) and the heat ``lost`` (J)."""
        # The ball's position on its sawtooth path across the gap.
        phase = (self.speed * times + self.gap) % (4.0 * self.gap)
        x = np.where(phase < 2.0 * self.gap, phase - self.gap, 3.0 * self.gap - phase)
        variables = {
            "x": (x, attributes("m", "ball centre position")),
            "velocity": (
                np.where(phase < 2.0 * self.gap, self.speed, -self.speed),
                attributes("m s-1", "ball velocity"),
            ),
            "theta_ball": (theta[:, 0], attributes("K", "ball temperature")),
            "theta_vial": (theta[:, 1], attributes("K", "vial temperature")),
            "theta_air": (theta[:, 2], attributes("K", "inner air temperature")),
            "heat_generated": (self.heat_power * times, attributes("J", "cumulative heat generated")),
            "heat_lost": (lost, attributes("J", "cumulative heat lost")),
            "velocity_term_integral": (self.term * times, attributes("s", "integral of Whitaker's velocity term")),
        }
        with_celsius(variables, CELSIUS_VARIABLES)
        return StateHistory(times, variables)

    def history(self) -> StateHistory:
        times = np.asarray(self.times)
        keep = np.isin(times, self.samples) | (times == self.clock)
        return self._states(times[keep], np.asarray(self.temperatures)[keep], np.asarray(self.lost)[keep])

    def window_history(self) -> StateHistory:
        return self._states(np.empty(0), np.empty((0, 3)), np.empty(0))

    def impact_columns(self, since: float = -math.inf) -> dict[str, np.ndarray]:
        first = self.gap / self.speed
        times = first + 2.0 * self.gap / self.speed * np.arange(
            int(max(self.clock - first, 0.0) * self.speed / (2.0 * self.gap)) + 1
        )
        times = times[(times <= self.clock) & (times >= since)]
        count = times.size
        return {
            "time": times,
            "wall": np.where(np.arange(count) % 2 == 0, "right", "left"),
            "impact_speed": np.full(count, self.speed),
            "dissipated_energy": np.full(count, self.hit_heat / self.params.eta),
            "heat_generated": np.full(count, self.hit_heat),
            "peak_force": np.full(count, math.inf),  # a rigid bounce
            "max_overlap": np.zeros(count),
            "duration": np.zeros(count),
        }

    def counters(self) -> dict[str, int]:
        impacts = len(self.impact_columns()["time"])
        return {"steps": impacts, "rejected_steps": 0, "rhs_evaluations": 0, "impacts": impacts}

    def energy_audit(self) -> EnergyAudit:
        """The vial restores the speed each hit takes: its work is what the hits dissipate."""
        capacity = self.network.arrays.capacity
        warming = self.temperatures[-1] - self.temperatures[0]
        heat = self.heat_power * self.clock
        dissipated = heat / self.params.eta
        return EnergyAudit(
            work_by_vial=dissipated,
            kinetic_energy_change=0.0,
            elastic_energy_change=0.0,
            dissipated=dissipated,
            heat_generated=heat,
            heat_into=self.network.grouped(self.network.wall_contact_heat(heat)),
            not_converted_to_heat=dissipated - heat,
            stored=self.network.grouped(capacity * warming),
            heat_lost_to_surroundings=self.lost[-1],
            projection_correction=0.0,
        )

    @property
    def projection_correction(self) -> float:
        return 0.0

    def no_impact_note(self) -> str:
        return ""

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: np.ndarray = ()) -> NetworkLoad:
        power, lam = float(heat_rates[0]), self.params.lam
        return NetworkLoad(
            np.array([lam * power, (1.0 - lam) * power, 0.0]),
            np.array(term_means, dtype=float),
            power,
            float(term_means[0]),
        )


class ToyEngine(CoreToy, Averaging):
    """The toy with the capability Averaging: the averaged solver drives it too."""

    description: ClassVar[EngineDescription] = DESCRIPTION

    def measured(self) -> Measured:
        return Measured(
            np.array([self.heat_power * self.clock]),
            np.array([self.term * self.clock]),
            self.heat_power / self.params.eta * self.clock,
        )

    def node_hits(self, impacts: Mapping[str, np.ndarray], weights: np.ndarray | None = None) -> np.ndarray:
        count = len(impacts["time"]) if weights is None else float(np.sum(weights))
        return np.array([count, count, 0])

    def averaged_history(
        self,
        times: np.ndarray,
        temperatures: np.ndarray,
        heat_lost: np.ndarray,
        load: NetworkLoad,
        dissipated_power: float,
        network: ThermalNetwork,
    ) -> StateHistory:
        return self._states(times, temperatures.T, heat_lost)


@pytest.fixture(name="toy")
def toy_fixture():
    register(ToyEngine)
    yield sm.default_parameters(engine="toy", duration=600.0, output_interval=10.0, record_windows=())
    unregister("toy")


def test_the_toy_is_only_in_the_registry_while_registered(toy):
    assert describe("toy") is DESCRIPTION
    unregister("toy")
    with pytest.raises(sm.ParameterError, match=r"^engine: input should be '1d' or 'dem' \(got 'toy'\)"):
        toy.replace(duration=60.0)
    register(ToyEngine)


def test_a_built_in_engine_can_be_neither_replaced_nor_taken_out():
    built_in = describe("1d")
    with pytest.raises(ValueError, match="'1d' is built in"):
        register(type("Impostor", (ToyEngine,), {"description": dataclasses.replace(DESCRIPTION, keys=built_in.keys)}))
    with pytest.raises(ValueError, match="'dem' is built in"):
        unregister("dem")
    assert describe("1d") is built_in
    assert describe("dem").name == "dem"
    assert engine_named("dem").__name__ == "DemEngine"


@pytest.mark.slow
def test_a_registered_engine_runs_through_simulate_storage_the_summary_and_a_figure(toy, tmp_path):
    result = sm.simulate(toy)
    assert result.success, result.message
    hits = result.impact_count
    engine = ToyEngine(toy)
    # A hit every crossing of the free gap, the first after half of one.
    assert hits == math.floor((600.0 - engine.gap / engine.speed) * engine.speed / (2 * engine.gap)) + 1
    assert result.summary.impacts.rate_hz == pytest.approx(hits / 600.0)
    assert result.summary.impacts.mean_speed_m_s == pytest.approx(toy.amplitude * toy.omega)
    assert result.summary.heat_power_W == pytest.approx(engine.heat_power, rel=1e-12)
    # The steady state of the shared network: all the heat leaves through h_o·A_o.
    assert result.summary.vial_steady_C == pytest.approx(
        toy.ambient_temperature + engine.heat_power / (toy.h_outer * toy.outer_area) - 273.15, rel=1e-9
    )
    assert result.energy.relative_residual < 1e-6
    folder = write_run(result, tmp_path / "run", preset="spex8000m")
    stored = load_run(folder)
    assert stored.params.engine == "toy"
    assert stored.summary.heat_power_W == result.summary.heat_power_W
    np.testing.assert_array_equal(stored.timeseries["theta_ball"].values, result.history["theta_ball"])
    assert stored.impact_units == IMPACT_UNITS
    figure = temperature_figure(stored)
    lines = {line.get_label(): line for line in figure.axes[0].get_lines()}
    np.testing.assert_allclose(lines["ball"].get_ydata(), result.history["theta_ball"] - 273.15)


def test_the_averaged_solver_drives_a_registered_engine_too(toy, tmp_path):
    result = sm.simulate(toy.replace(solver="averaged"))
    assert result.success, result.message
    assert result.solver == "averaged" and result.averages.converged
    engine = ToyEngine(toy)
    assert result.averages.heat_power == pytest.approx(engine.heat_power, rel=1e-12)
    full = sm.simulate(toy)
    np.testing.assert_allclose(result.history["theta_ball"], full.history["theta_ball"], rtol=1e-6)
    # Its files say what the averaged run did not compute, and what it extended from the window, as it declares.
    with xr.open_dataset(
        write_run(result, tmp_path / "averaged", preset="spex8000m") / "timeseries.nc", engine="h5netcdf"
    ) as series:
        assert "x, velocity are NaN" in series.attrs["coverage"]
        assert "heat_generated, velocity_term_integral are the averaging window's mean" in series.attrs["coverage"]
        assert "mean rate times time" in series["velocity_term_integral"].attrs["coverage"]
        assert "not computed" in series["x"].attrs["coverage"] and "coverage" not in series["theta_air"].attrs


@pytest.fixture(name="core_toy")
def core_toy_fixture():
    register(CoreToy)
    yield sm.default_parameters(engine="toy-core", duration=60.0, output_interval=10.0, record_windows=())
    unregister("toy-core")


@pytest.mark.parametrize(
    ("setting", "applies"),
    [
        ("friction=0.5", "it applies to engine = 'dem'"),
        ("rtol=1e-4", "it applies to engine = '1d'"),
        ("phase=1", "it applies to another engine"),
        ("record_windows=0:1", "it applies to another engine"),
    ],
)
def test_a_key_the_toy_does_not_read_is_refused_in_one_line(toy, setting, applies):
    key = setting.partition("=")[0]
    assert key not in DESCRIPTION.keys.reads
    with pytest.raises(sm.ParameterError) as raised:
        load_config(overrides=["engine=toy", setting])
    assert str(raised.value) == (
        f"{key}: set explicitly, but the toy engine (engine = 'toy') does not read it; {applies}"
    )
    # The keys it reads are taken: those of the shared groups and its own.
    assert load_config(overrides=["engine=toy", "solver=averaged", "restitution=0.5", "averaging_fallback=fail"])


def test_the_keys_the_toy_reads_are_those_it_lists_and_the_command_line_refuses_the_others(toy):
    listed = CliRunner().invoke(app, ["keys", "--engine", "toy"], terminal_width=200)
    assert listed.exit_code == 0, listed.output
    assert f"read by the toy engine: {len(DESCRIPTION.keys.reads)} of {len(FIELD_NAMES)}" in listed.output
    assert DESCRIPTION.keys.reads < set(FIELD_NAMES)
    refused = CliRunner().invoke(app, ["run", "--set", "engine=toy", "--set", "gravity=false", "--no-plots"])
    assert refused.exit_code == 2, refused.output
    assert (
        refused.output.strip()
        .splitlines()[-1]
        .startswith("error: gravity: set explicitly, but the toy engine (engine = 'toy') does not read it")
    )


def test_an_engine_without_averaging_runs_the_full_solver_and_the_averaged_one_refuses_it(core_toy, tmp_path):
    """The core alone serves the full solver; the averaged solver asks for the capability Averaging and refuses, in
    one line, an engine without it (exit code 2 from the command line, before anything runs)."""
    assert capabilities_of(CoreToy) == () and capabilities_of(ToyEngine) == ("Averaging",)
    full = sm.simulate(core_toy)
    assert full.success, full.message
    assert full.description is CORE_DESCRIPTION and full.summary.heat_power_W == pytest.approx(
        CoreToy(core_toy).heat_power, rel=1e-12
    )
    refusal = (
        "solver: the averaged solver needs an engine that measures the means it averages (the capability Averaging, "
        "engines/interface.py); engine = 'toy-core' has not; allowed solver = 'full'"
    )
    with pytest.raises(sm.ParameterError) as raised:
        sm.simulate(core_toy.replace(solver="averaged", duration=3600.0))
    assert str(raised.value) == refusal
    outcome = CliRunner().invoke(
        app,
        ["run", "--set", "engine=toy-core", "--set", "solver=averaged", "--out", str(tmp_path / "run"), "--no-plots"],
    )
    assert outcome.exit_code == 2 and outcome.output.strip().splitlines()[-1] == f"error: {refusal}"
    assert not (tmp_path / "run").exists()


def test_registering_checks_the_engine_core_and_the_keys_it_says_it_reads():
    without_load = type("NoLoad", (), {name: getattr(CoreToy, name) for name in ENGINE_CORE if name != "load"})
    without_load.description = dataclasses.replace(
        CORE_DESCRIPTION, keys=dataclasses.replace(CORE_DESCRIPTION.keys, name="no-load")
    )
    with pytest.raises(ValueError, match=r"^engine 'no-load': lacks load of the engine core"):
        register(without_load)
    misspelt = dataclasses.replace(
        CORE_DESCRIPTION,
        keys=dataclasses.replace(CORE_DESCRIPTION.keys, name="misspelt", reads=CORE_DESCRIPTION.keys.reads | {"omgea"}),
    )
    with pytest.raises(ValueError, match=r"^engine 'misspelt': reads 'omgea', which Parameters has no key of"):
        register(type("Misspelt", (CoreToy,), {"description": misspelt}))
    replicated = dataclasses.replace(
        DESCRIPTION, keys=dataclasses.replace(DESCRIPTION.keys, name="replicated", replicas_key="dem_replicas")
    )
    with pytest.raises(ValueError, match=r"^engine 'replicated': names replicas_key = 'dem_replicas' without"):
        register(type("Replicated", (ToyEngine,), {"description": replicated}))
    assert "no-load" not in engine_names() and "misspelt" not in engine_names()
