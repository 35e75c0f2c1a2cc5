"""The thermal network in compiled form: its heat flows and the energy balance of its nodes.

A network is arrays (:class:`NetworkArrays`): each node's heat capacity and whether it is held at the room
temperature, and each heat path's model (:data:`WHITAKER`, :data:`CONSTANT`), its two ends (a node, or
:data:`ROOM`) and its coefficients. The flows are positive from a path's ``hot`` end to its ``cold`` end.
Every engine and solver evaluates the network through these functions: the 'dem' engine's stepping, the
averaged solvers' integration and the steady state. The 1-D engine's right-hand side keeps the three-node
network written out for speed (``engines.one_d.model.thermal_network``); a test holds it to these, term by term.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from shakermill.physics import thermal

# Path models. WHITAKER: a ball's convection to the air, Whitaker's correlation at the ball's own mean velocity
# term (MODEL.md §4); CONSTANT: a fixed conductance h·A (Newton cooling, MODEL.md §5).
WHITAKER, CONSTANT = 0, 1
# The cold end of a path that leaves the system: the surroundings at the ambient temperature.
ROOM = -1


class NetworkArrays(NamedTuple):
    """A network as the compiled functions read it. Per node: ``capacity`` (J/K), ``held`` (kept at the
    ambient temperature: a reservoir outside the balance). Per path: ``kind``, ``hot`` and ``cold`` ends,
    ``conductance`` (W/K, CONSTANT), ``radius`` (m) and ``ball`` (whose velocity term, WHITAKER)."""

    capacity: np.ndarray
    held: np.ndarray
    kind: np.ndarray
    hot: np.ndarray
    cold: np.ndarray
    conductance: np.ndarray
    radius: np.ndarray
    ball: np.ndarray
    beta: float
    prandtl: float
    mu_ref: float
    t_ref: float
    sutherland: float
    air_conductivity: float
    ambient: float


@njit(cache=True)
def whitaker_flow(theta_ball: float, theta_air: float, velocity_term: float, radius: float, net: NetworkArrays) -> float:
    """Q̇ = 4πR²·β·h·(θ_b − θ_a) (W) with Whitaker's h at the ball's velocity term, Sutherland's factor taken at
    the ball's temperature (MODEL.md §4)."""
    ratio = thermal.sutherland_viscosity(theta_ball, net.mu_ref, net.t_ref, net.sutherland) / net.mu_ref
    nusselt = thermal.nusselt_from_velocity_term(velocity_term, net.prandtl, ratio)
    h = thermal.heat_transfer_coefficient(nusselt, net.air_conductivity, radius)
    return thermal.ball_air_heat_flow(radius, net.beta, h, theta_ball, theta_air)


@njit(cache=True)
def path_flows(theta: np.ndarray, velocity_terms: np.ndarray, net: NetworkArrays, out: np.ndarray) -> None:
    """Each path's heat flow (W, hot end to cold end) into ``out``, at node temperatures ``theta`` (K) and each
    ball's mean Whitaker velocity term."""
    for p in range(net.kind.shape[0]):
        hot = theta[net.hot[p]]
        cold = net.ambient if net.cold[p] == ROOM else theta[net.cold[p]]
        if net.kind[p] == WHITAKER:
            out[p] = whitaker_flow(hot, cold, velocity_terms[net.ball[p]], net.radius[p], net)
        else:
            out[p] = net.conductance[p] * (hot - cold)


@njit(cache=True)
def balance(heat: np.ndarray, flows: np.ndarray, net: NetworkArrays, out: np.ndarray) -> float:
    """Heat into each node (``heat`` in, each path's flow out of its hot end and into its cold end) into
    ``out``, in the unit of ``heat`` and ``flows``; returns what leaves the system: the flows into the room or
    a held node, less those out of a held node, and the heat into held nodes. Held nodes get 0: they are
    reservoirs outside the balance."""
    lost = 0.0
    out[:] = heat
    for p in range(flows.shape[0]):
        hot, cold = net.hot[p], net.cold[p]
        if net.held[hot]:
            lost -= flows[p]
        else:
            out[hot] -= flows[p]
        if cold == ROOM or net.held[cold]:
            lost += flows[p]
        else:
            out[cold] += flows[p]
    for node in range(out.shape[0]):
        if net.held[node]:
            lost += heat[node]
            out[node] = 0.0
    return lost


@njit(cache=True)
def temperature_rates(theta: np.ndarray, heat: np.ndarray, velocity_terms: np.ndarray, net: NetworkArrays,
                      flows: np.ndarray, out: np.ndarray) -> float:
    """dθ/dt (K/s) of every node into ``out`` (held nodes: 0) with ``heat`` (W) into each; returns the heat
    leaving the system (W). ``flows`` is scratch of one entry per path."""
    path_flows(theta, velocity_terms, net, flows)
    lost = balance(heat, flows, net, out)
    for node in range(out.shape[0]):
        out[node] /= net.capacity[node]
    return lost


@njit(cache=True)
def advance(theta: np.ndarray, heat: np.ndarray, velocity_terms: np.ndarray, span: float, net: NetworkArrays,
            flows: np.ndarray, energy: np.ndarray) -> float:
    """One explicit Euler step of ``span`` (s) from ``theta`` in place, with ``heat`` (J) received in it and the
    flows at its start; returns the heat that left the system (J). Energy is conserved exactly."""
    path_flows(theta, velocity_terms, net, flows)
    for p in range(flows.shape[0]):
        flows[p] *= span
    lost = balance(heat, flows, net, energy)
    for node in range(theta.shape[0]):
        theta[node] += energy[node] / net.capacity[node]
    return lost
