"""The one thermal network of every engine (MODEL.md sections 4-6, 12.5): its named paths against hand-computed flows,
its energy balance, and the 1-D engine's written-out network held to it term by term."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.one_d import model
from shakermill.engines.one_d.engine import OneDimensionalEngine
from shakermill.engines.thermal import kernel
from shakermill.physics import thermal

RNG = np.random.default_rng(20261125)
# Temperatures (K), impact heat (W) and velocity terms drawn over what runs see, and beyond.
CASES = [(RNG.uniform(250.0, 700.0, 3), RNG.uniform(0.0, 20.0), RNG.uniform(0.0, 200.0)) for _ in range(50)]


@pytest.mark.parametrize("thermal_model", ["three_node", "ball_only"])
def test_the_one_d_engines_written_out_network_is_the_one_network_term_by_term(thermal_model):
    params = sm.default_parameters(model=thermal_model, h_outer=33.0, beta=1.7)
    constants = model.constants_from(params)
    engine = OneDimensionalEngine(params)
    for theta, heat, term in CASES:
        if thermal_model == "ball_only":
            theta = np.array([theta[0], params.ambient_temperature, params.ambient_temperature])
        load = engine.load(np.array([heat]), np.array([term]))
        rates, lost = engine.network.rates(theta, load.heat, load.terms)
        written = model.thermal_network(theta[0], theta[1], theta[2], heat, term, constants)
        # Bit for bit: the averaged solver and the steady state of the 1-D engine use the one network.
        assert tuple(rates) == written[:3]
        assert lost == written[3]


def test_each_path_flows_as_its_correlation_says():
    params = sm.default_parameters(engine="dem", n_balls=2, vial_diameter="38 mm", ball_radii="5 mm, 6 mm", beta=0.8)
    network = DemEngine.network_for(params)
    assert [path.name for path in network.paths] == ["ball 0 → air", "ball 1 → air", "vial → air", "vial → room"]
    theta = np.array([330.0, 350.0, 310.0, 300.0])
    terms = np.array([12.0, 40.0])
    flows = network.flows(theta, terms)
    prandtl = (
        params.air_cp
        * thermal.sutherland_viscosity(
            params.ambient_temperature, params.air_viscosity_ref, params.air_reference_temperature, params.sutherland
        )
        / params.air_conductivity
    )
    for ball, radius in enumerate((5e-3, 6e-3)):
        mu = params.air_viscosity_ref * (theta[ball] / 273.15) ** 1.5 * (273.15 + 111.0) / (theta[ball] + 111.0)
        nusselt = 2.0 + terms[ball] * prandtl**0.4 * (mu / params.air_viscosity_ref) ** -0.25
        h = nusselt * params.air_conductivity / (2.0 * radius)
        assert flows[ball] == pytest.approx(4.0 * math.pi * radius**2 * 0.8 * h * (theta[ball] - theta[3]), rel=1e-12)
    assert flows[2] == pytest.approx(params.h_inner * params.inner_area * (theta[2] - theta[3]), rel=1e-14)
    assert flows[3] == pytest.approx(
        params.h_outer * params.outer_area * (theta[2] - params.ambient_temperature), rel=1e-14
    )


def test_every_path_and_deposit_says_what_it_rests_on():
    params = sm.default_parameters(engine="dem", n_balls=3, vial_diameter="38 mm", powder_mass=0.002)
    network = DemEngine.network_for(params)
    for path in network.paths:
        assert path.correlation and path.source and path.validity
    assert "Whitaker" in network.paths[0].source and "Re" in network.paths[0].validity
    assert "effusivity" in network.split.description and network.split.wall_ball_share == params.lam
    (deposit,) = network.deposits
    assert network.nodes[deposit.node].role == "powder" and "powder_heat_share" in deposit.source


def test_the_balance_conserves_energy_and_counts_what_leaves():
    network = DemEngine.network_for(sm.default_parameters(engine="dem", n_balls=2, vial_diameter="38 mm"))
    theta = np.array([340.0, 320.0, 310.0, 300.0])
    heat = np.array([0.7, 1.3, 0.9, 0.0])
    rates, lost = network.rates(theta, heat, np.array([20.0, 30.0]))
    capacity = network.arrays.capacity
    assert np.dot(capacity, rates) + lost == pytest.approx(heat.sum(), rel=1e-12)
    assert lost == pytest.approx(network.flows(theta, np.array([20.0, 30.0]))[-1], rel=1e-15)
    # An explicit Euler step books exactly what it moves: heat in = heat stored + heat lost.
    stepped = theta.copy()
    energy_in = heat * 0.01
    left = kernel.advance(stepped, energy_in, np.array([20.0, 30.0]), 0.01, network.arrays, np.empty(4), np.empty(4))
    assert np.dot(capacity, stepped - theta) + left == pytest.approx(energy_in.sum(), rel=1e-9)


def test_held_nodes_stay_at_the_ambient_and_their_heat_leaves():
    params = sm.default_parameters(model="ball_only")
    network = OneDimensionalEngine.network_for(params)
    assert [node.held for node in network.nodes] == [False, True, True]
    assert list(network.free) == [0]
    theta = network.with_free(np.array([330.0]))
    rates, lost = network.rates(theta, np.array([0.4, 0.6, 0.0]), np.array([25.0]))
    assert rates[1] == rates[2] == 0.0
    assert lost == pytest.approx(network.flows(theta, np.array([25.0]))[0] + 0.6, rel=1e-15)


def test_node_conductances_are_the_paths_at_each_node():
    params = sm.default_parameters()
    network = OneDimensionalEngine.network_for(params)
    conductances = network.node_conductances(np.array([0.0]))
    at_rest = (
        4.0 * math.pi * params.ball_radius**2 * params.beta * params.air_conductivity / (2.0 * params.ball_radius) * 2.0
    )
    assert conductances[0] == pytest.approx(at_rest, rel=0.02)  # Nu = 2 at rest, Sutherland's factor aside
    assert conductances[1] == pytest.approx(
        params.h_inner * params.inner_area + params.h_outer * params.outer_area, rel=1e-9
    )


def _charge_network(**overrides):
    """The network of 20 balls in a planetary bowl, with the powder and the mill head's nodes, and drives drawn over
    what runs see (velocity terms, contact conductances with the vial and among the balls)."""
    params = sm.default_parameters("pulverisette7", n_balls=20, ball_radius=2.5e-3, **overrides)
    network = DemEngine.network_for(params)
    drives = np.random.default_rng(7).uniform(0.05, 3.0, kernel.drive_count(network.n_balls))
    theta = network.with_free(np.random.default_rng(8).uniform(290.0, 420.0, network.free.size))
    return network, drives, theta


def _whole_network_differences(network, drives, theta, step):
    """The Jacobian of dθ/dt over the free nodes by central differences of the whole network, node by node."""
    free = network.free
    heat = np.zeros(len(network.nodes))
    columns = []
    for node in free:
        up, down = theta.copy(), theta.copy()
        up[node] += step
        down[node] -= step
        columns.append((network.rates(up, heat, drives)[0] - network.rates(down, heat, drives)[0])[free] / (2 * step))
    return np.column_stack(columns)


@pytest.mark.parametrize("overrides", [{}, {"powder_mass": 2e-3}], ids=["bare", "powder"])
def test_the_assembled_jacobian_is_the_whole_networks_differences(overrides):
    network, drives, theta = _charge_network(**overrides)
    assembled = network.jacobian(theta, drives, 0.5)
    whole = _whole_network_differences(network, drives, theta, 0.5)
    assert assembled.shape == (network.free.size, network.free.size)
    # Every path and the balls' mean among them: the largest entry sets the scale of round-off.
    assert np.max(np.abs(assembled - whole)) <= 1e-9 * np.max(np.abs(whole))
    assert np.count_nonzero(np.abs(whole) > 0) == np.count_nonzero(np.abs(assembled) > 0)


@pytest.mark.parametrize("overrides", [{}, {"powder_mass": 2e-3}], ids=["bare", "powder"])
def test_node_conductances_in_one_pass_are_those_node_by_node(overrides):
    network, drives, _ = _charge_network(**overrides)
    expected = []
    theta = np.full(len(network.nodes), network.ambient)
    for node in range(len(network.nodes)):
        theta[node] += 1.0
        flows = network.flows(theta, drives)
        theta[node] = network.ambient
        ends = (network.arrays.hot == node) | (network.arrays.cold == node)
        expected.append(np.abs(flows[ends]).sum())
    assert network.node_conductances(drives) == pytest.approx(expected, rel=1e-12)
