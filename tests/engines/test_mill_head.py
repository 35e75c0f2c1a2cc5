"""The thermal network of a real mill (thermal_model = 'mill-head', MODEL.md section 13): its paths computed from
their correlations, its mill-head node warmed by the drive, conduction through contacts, and its energy balance."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.analysis.steady import steady_state
from shakermill.engines.dem import model
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.mill_head import vial_outer_convection, vial_rms_speed
from shakermill.engines.thermal.network import NetworkLoad
from shakermill.parameters.errors import ParameterError
from shakermill.physics import heat_paths


def mill_head(**settings):
    return sm.default_parameters("spex8000m-3d", thermal_model="mill-head", **settings)


def test_the_network_has_a_holder_node_and_every_path_of_a_real_mill():
    network = DemEngine.network_for(mill_head(n_balls=2, drive_heat=7.0))
    assert [node.name for node in network.nodes] == ["ball 0", "ball 1", "vial", "air", "holder"]
    assert [node.role for node in network.nodes] == ["ball", "ball", "vessel", "gas", "holder"]
    assert network.nodes[-1].title == "clamp and mill head"
    assert [path.name for path in network.paths] == [
        "ball 0 → air",
        "ball 1 → air",
        "vial → air",
        "vial → room, convection",
        "vial → room, radiation",
        "ball 0 → vial, contacts",
        "ball 1 → vial, contacts",
        "ball 0 → other balls, contacts",
        "ball 1 → other balls, contacts",
        "vial → holder",
        "holder → room",
    ]
    assert list(network.arrays.fixed_heat) == [0.0, 0.0, 0.0, 0.0, 7.0]
    assert all(path.correlation and path.source and path.validity for path in network.paths)


def test_the_vials_speed_and_outer_convection_follow_from_its_motion():
    params = mill_head(kinematics="axial")
    # x = X sin ωt: the rms speed is ωX/√2.
    assert vial_rms_speed(params) == pytest.approx(params.omega * params.amplitude / math.sqrt(2.0), rel=1e-12)
    outer = vial_outer_convection(params)
    assert outer.area == pytest.approx(math.pi * 0.05 * 0.07 + 2 * math.pi * 0.05**2 / 4)
    # Forced convection at ~2 m/s on Ø50 × 70 mm: tens of W/(m²·K), five times the natural convection of a vial at rest.
    assert 15.0 < outer.coefficient < 40.0
    faster = vial_outer_convection(params.replace(amplitude=2 * params.amplitude))
    assert faster.coefficient == pytest.approx(outer.coefficient * math.sqrt(2.0), rel=0.02)  # laminar: h ∝ √u


def test_each_ball_has_a_drive_for_its_contacts_with_the_vial_and_one_with_the_other_balls():
    """Issue 38: drives grow linearly with the balls (3 per ball), not with the pairs."""
    n = 5
    indices = [kernel.contact_drive(i, -1, n) for i in range(n)] + [
        kernel.contact_drive(i, (i + 1) % n, n) for i in range(n)
    ]
    assert sorted(indices) == list(range(n, kernel.drive_count(n))) and kernel.drive_count(n) == 3 * n
    assert kernel.contact_drive(3, 1, n) == kernel.contact_drive(3, 4, n) != kernel.contact_drive(1, 3, n)


def test_conduction_among_balls_conserves_energy_and_is_exact_for_two_balls_and_equal_couplings():
    """kernel.among_balls_mean: flows sum to zero; for balls that touch each other alike (G_ij = g, so G_i = (m−1)g)
    each ball's flow is the sum of its exact pair flows g·(θ_i − θ_j)."""
    params = mill_head(n_balls=4)
    network = DemEngine.network_for(params)
    theta = np.array([350.0, 340.0, 325.0, 301.0, 310.0, 305.0, 300.0])
    g = 2e-3
    drives = np.array([10.0] * 4 + [0.0] * 4 + [3 * g] * 4)
    flows = dict(zip((path.name for path in network.paths), network.flows(theta, drives)))
    among = [flows[f"ball {i} → other balls, contacts"] for i in range(4)]
    exact = [sum(g * (theta[i] - theta[j]) for j in range(4) if j != i) for i in range(4)]
    assert among == pytest.approx(exact, rel=1e-12)
    assert sum(among) == pytest.approx(0.0, abs=1e-15 * sum(abs(flow) for flow in among))
    # Unequal couplings: still no heat made or lost among the balls.
    drives[8:] = [1e-3, 4e-3, 2e-3, 0.5e-3]
    rates, lost = network.rates(theta, np.zeros(len(network.nodes)), drives)
    unequal = network.flows(theta, drives)
    stored = float(np.dot(network.arrays.capacity, rates))
    assert stored + lost == pytest.approx(0.0, abs=1e-9 * np.abs(unequal).sum())


def test_each_new_path_flows_as_its_correlation_says():
    params = mill_head(n_balls=2, emissivity=0.3)
    network = DemEngine.network_for(params)
    theta = np.array([340.0, 330.0, 310.0, 305.0, 300.0])
    drives = np.array([10.0, 10.0, 0.004, 0.006, 0.001, 0.001])
    flows = dict(zip((path.name for path in network.paths), network.flows(theta, drives)))
    ambient = params.ambient_temperature
    outer = vial_outer_convection(params)
    assert flows["vial → room, convection"] == pytest.approx(
        outer.coefficient * outer.area * (310.0 - ambient), rel=1e-12
    )
    radiated = 0.3 * heat_paths.STEFAN_BOLTZMANN * outer.area * (310.0**4 - ambient**4)
    assert flows["vial → room, radiation"] == pytest.approx(radiated, rel=1e-12)
    assert flows["ball 0 → vial, contacts"] == pytest.approx(0.004 * 30.0)
    assert flows["ball 1 → vial, contacts"] == pytest.approx(0.006 * 20.0)
    assert flows["ball 0 → other balls, contacts"] == pytest.approx(0.001 * 10.0)
    assert flows["ball 1 → other balls, contacts"] == pytest.approx(-0.001 * 10.0)
    assert flows["vial → holder"] == pytest.approx(params.clamp_conductance * 10.0)
    assert flows["holder → room"] == pytest.approx(params.clamp_loss * (300.0 - ambient))


def test_the_balance_books_the_drives_heat():
    network = DemEngine.network_for(mill_head(n_balls=2, drive_heat=12.0))
    theta = np.array([340.0, 320.0, 310.0, 305.0, 300.0])
    heat = np.array([0.7, 1.3, 0.9, 0.0])
    drives = np.array([20.0, 30.0, 0.01, 0.02, 0.003])
    rates, lost = network.rates(theta, heat, drives)
    capacity = network.arrays.capacity
    assert np.dot(capacity, rates) + lost == pytest.approx(heat.sum() + 12.0, rel=1e-12)
    stepped = theta.copy()
    left = kernel.advance(
        stepped, np.append(heat, 0.0) * 0.01, drives, 0.01, network.arrays, np.empty(len(network.paths)), np.empty(5)
    )
    assert np.dot(capacity, stepped - theta) + left == pytest.approx((heat.sum() + 12.0) * 0.01, rel=1e-9)


def test_with_the_drive_alone_the_steady_state_is_the_hand_solved_network():
    params = mill_head(emissivity=0.0, drive_heat=10.0, clamp_loss=2.0, clamp_conductance=8.0)
    network = DemEngine.network_for(params)
    load = NetworkLoad(np.zeros(3), np.zeros(1), 0.0, 0.0, np.zeros(1))
    steady = steady_state(network, load)
    outer = vial_outer_convection(params)
    room = outer.coefficient * outer.area
    # Δ_clamp = Q/(G_k + G_vo·G_vk/(G_vk + G_vo)); Δ_vial = G_vk·Δ_clamp/(G_vk + G_vo); ball and air follow the vial.
    clamp_rise = 10.0 / (2.0 + room * 8.0 / (8.0 + room))
    vial_rise = 8.0 * clamp_rise / (8.0 + room)
    assert dict(steady.others)["holder"] - params.ambient_temperature == pytest.approx(clamp_rise, rel=1e-9)
    assert steady.vial - params.ambient_temperature == pytest.approx(vial_rise, rel=1e-9)
    assert steady.ball == pytest.approx(steady.vial, rel=1e-12)
    assert steady.as_summary().holder == pytest.approx(params.ambient_temperature - 273.15 + clamp_rise)


def test_a_contact_records_what_it_conducted():
    params = mill_head(gravity=False, friction=0.0, kinematics="axial", ball_momentum=0.0, duration=0.05, solver="full")
    engine = DemEngine(params)
    engine.advance(0.05)
    impacts = engine.impact_columns()
    assert impacts["time"].size > 0
    k = engine.constants
    for index in range(impacts["time"].size):
        radius = heat_paths.hertz_contact_radius(k.wall_radius[0, 0], impacts["max_overlap"][index])
        expected = heat_paths.contact_conduction(
            radius,
            impacts["duration"][index],
            k.effusivity[0],
            k.vial_effusivity,
            k.conductivity[0],
            k.vial_conductivity,
        )
        assert impacts["conduction"][index] == pytest.approx(expected, rel=1e-12)
    n = params.n_balls
    assert engine.state.drive_integrals[kernel.contact_drive(0, -1, n)] == pytest.approx(
        impacts["conduction"].sum(), rel=1e-12
    )


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"outer_diameter": "30 mm"}, "outer_diameter: the vial's outside must be larger than its bore"),
        ({"outer_length": "50 mm"}, "outer_length: the vial's outside must be larger than its bore"),
        ({"model": "ball_only"}, "model: thermal_model = 'mill-head'"),
    ],
)
def test_a_mill_head_needs_an_outside_larger_than_the_bore(settings, message):
    with pytest.raises(ParameterError, match=message):
        mill_head(**settings)


def test_the_one_d_engine_takes_the_papers_network_only():
    with pytest.raises(ParameterError, match="thermal_model: the 1-D engine has no 'mill-head' network"):
        sm.default_parameters(thermal_model="mill-head")


@pytest.mark.slow
def test_an_averaged_mill_head_run_reports_each_paths_heat_and_closes_its_balance():
    # The 3-D engine's 1-D limit settles in seconds; the paths are the mill-head's all the same.
    params = mill_head(
        drive_heat=6.0,
        record_windows=(),
        duration=600.0,
        vial_diameter="19 mm",
        kinematics="axial",
        gravity=False,
        friction=0.0,
    )
    result = sm.simulate(params)
    assert result.success, result.message
    paths = result.summary.heat_paths_W
    assert set(paths) == {path.name for path in DemEngine.network_for(params).paths}
    assert paths["ball 0 → vial, contacts"] > 0.0  # the ball is warmer than the vial it touches
    assert result.summary.drive_heat_W == pytest.approx(6.0)
    assert (
        math.isfinite(result.summary.temperatures.holder)
        and result.summary.steady.holder > result.summary.temperatures.holder
    )
    assert abs(result.energy.thermal_residual) < 1e-6 * (result.energy.heat_generated + result.energy.drive_heat)
    # What leaves to the room, by the paths' means, is what the run lost, to the trapezoidal rule's error.
    lost = sum(value for name, value in paths.items() if "room" in name) * params.duration
    assert lost == pytest.approx(result.energy.heat_lost_to_surroundings, rel=1e-3)
    # A node adds two numbers to each recorded row: its temperature and the contacts' heat into it so far.
    assert model.row_width(1, 4) == model.row_width(1, 3) + 2
