"""The thermal network in compiled form: its heat flows and the energy balance of its nodes.

A network is arrays (:class:`NetworkArrays`): each node's heat capacity, whether it is held at the room
temperature and the heat it receives whatever the balls do (the drive's, into a mill head), and each heat
path's model (:data:`WHITAKER`, :data:`CONSTANT`, :data:`CONTACT`, :data:`RADIATION`, :data:`AMONG_BALLS`), its
two ends (a node, :data:`ROOM` or :data:`BALLS`) and its coefficients. Paths that depend on the motion read it from
``drives``: each ball's mean Whitaker velocity term, then the mean conductances of each ball's contacts with the
vial and with the other balls (:func:`drive_count`). The flows are positive from a path's ``hot`` end to its
``cold`` end. Every engine and solver evaluates the network through these functions: the 'dem' engine's stepping,
the averaged solvers' integration and the steady state. The 1-D engine's right-hand side keeps the three-node
network written out for speed (``engines.one_d.model.thermal_network``); a test holds it to these, term by term.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from shakermill.physics import thermal

# Path models. WHITAKER: a ball's convection to the air, Whitaker's correlation at the ball's own mean velocity
# term (MODEL.md §4); CONSTANT: a fixed conductance h·A (Newton cooling, MODEL.md §5); CONTACT: conduction
# through contacts at their measured mean conductance; RADIATION: ε·σ·A·(θ_hot⁴ − θ_cold⁴) (MODEL.md §13.1);
# AMONG_BALLS: conduction through a ball's contacts with the other balls (:func:`among_balls_flows`).
WHITAKER, CONSTANT, CONTACT, RADIATION, AMONG_BALLS = 0, 1, 2, 3, 4
# The cold end of a path that leaves the system: the surroundings at the ambient temperature.
ROOM = -1
# The cold end of an AMONG_BALLS path: the other balls, whose flows in sum to nothing.
BALLS = -2


class NetworkArrays(NamedTuple):
    """A network as the compiled functions read it. Per node: ``capacity`` (J/K), ``held`` (kept at the
    ambient temperature: a reservoir outside the balance), ``fixed_heat`` (W, whatever the balls do). Per path:
    ``kind``, ``hot`` and ``cold`` ends, ``conductance`` (W/K for CONSTANT, ε·σ·A in W/K⁴ for RADIATION),
    ``radius`` (m, WHITAKER) and ``drive`` (the index into ``drives`` of its velocity term or contact
    conductance, WHITAKER and CONTACT)."""

    capacity: np.ndarray
    held: np.ndarray
    fixed_heat: np.ndarray
    kind: np.ndarray
    hot: np.ndarray
    cold: np.ndarray
    conductance: np.ndarray
    radius: np.ndarray
    drive: np.ndarray
    beta: float
    prandtl: float
    mu_ref: float
    t_ref: float
    sutherland: float
    air_conductivity: float
    ambient: float


def drive_count(n_balls: int) -> int:
    """Entries of ``drives`` for ``n_balls``: per ball a velocity term, a contact conductance with the vial and one
    with the other balls. Linear in the balls: a charge of thousands has no per-pair entry."""
    return 3 * n_balls


@njit(cache=True)
def contact_drive(ball: int, other: int, n_balls: int) -> int:
    """Index into ``drives`` of the contact conductance of ``ball`` with the vial (``other`` < 0) or with the other
    balls (``other`` ≥ 0: any ball; a pair's conduction counts for both of its balls)."""
    return n_balls + ball if other < 0 else 2 * n_balls + ball


@njit(cache=True)
def whitaker_flow(
    theta_ball: float, theta_air: float, velocity_term: float, radius: float, net: NetworkArrays
) -> float:
    """Q̇ = 4πR²·β·h·(θ_b − θ_a) (W) with Whitaker's h at the ball's velocity term, Sutherland's factor taken at
    the ball's temperature (MODEL.md §4)."""
    ratio = thermal.sutherland_viscosity(theta_ball, net.mu_ref, net.t_ref, net.sutherland) / net.mu_ref
    nusselt = thermal.nusselt_from_velocity_term(velocity_term, net.prandtl, ratio)
    h = thermal.heat_transfer_coefficient(nusselt, net.air_conductivity, radius)
    return thermal.ball_air_heat_flow(radius, net.beta, h, theta_ball, theta_air)


@njit(cache=True)
def among_balls_mean(theta: np.ndarray, drives: np.ndarray, net: NetworkArrays) -> tuple[float, float]:
    """The balls' temperature that AMONG_BALLS paths conduct toward, their mean weighted by each ball's conductance
    with the others (K), and the factor m/(m − 1) of m such paths (0 for fewer than two).

    Ball i conducts G_i·m/(m − 1)·(θ_i − θ̄) (G_i the mean conductance of its contacts with any ball, each pair's
    counted for both): the flows sum to zero, so energy is conserved exactly; the flow is exact for two balls and
    for balls that touch each other alike (G_ij = g), and a mean-field one otherwise, O(N) where per-pair paths
    would be O(N²) (MODEL.md §13.1 leaves the network's form of ball-ball conduction open)."""
    weighted = total = 0.0
    among = 0
    for p in range(net.kind.shape[0]):
        if net.kind[p] == AMONG_BALLS:
            conductance = drives[net.drive[p]]
            weighted += conductance * theta[net.hot[p]]
            total += conductance
            among += 1
    if among < 2 or total <= 0.0:
        return 0.0, 0.0
    return weighted / total, among / (among - 1.0)


@njit(cache=True)
def path_flows(theta: np.ndarray, drives: np.ndarray, net: NetworkArrays, out: np.ndarray) -> None:
    """Each path's heat flow (W, hot end to cold end) into ``out``, at node temperatures ``theta`` (K) and the
    motion's ``drives``."""
    balls_mean, among_factor = among_balls_mean(theta, drives, net)
    for p in range(net.kind.shape[0]):
        out[p] = path_flow(p, theta[net.hot[p]], cold_end(p, theta, balls_mean, net), among_factor, drives, net)


@njit(cache=True)
def cold_end(p: int, theta: np.ndarray, balls_mean: float, net: NetworkArrays) -> float:
    """The temperature (K) at path ``p``'s cold end: a node's, the room's or the other balls' mean."""
    if net.cold[p] == ROOM:
        return net.ambient
    return balls_mean if net.cold[p] == BALLS else theta[net.cold[p]]


@njit(cache=True)
def path_flow(p: int, hot: float, cold: float, among_factor: float, drives: np.ndarray, net: NetworkArrays) -> float:
    """Path ``p``'s heat flow (W) with its ends at ``hot`` and ``cold`` (K)."""
    kind = net.kind[p]
    if kind == AMONG_BALLS:
        return among_factor * drives[net.drive[p]] * (hot - cold)
    if kind == WHITAKER:
        return whitaker_flow(hot, cold, drives[net.drive[p]], net.radius[p], net)
    if kind == CONTACT:
        return drives[net.drive[p]] * (hot - cold)
    if kind == RADIATION:
        return net.conductance[p] * (hot**4 - cold**4)
    return net.conductance[p] * (hot - cold)


@njit(cache=True)
def path_slopes(
    theta: np.ndarray, drives: np.ndarray, net: NetworkArrays, step: float, by_hot: np.ndarray, by_cold: np.ndarray
) -> None:
    """Each path's ∂flow/∂θ (W/K) at its hot end into ``by_hot`` and at its cold end into ``by_cold``, by central
    differences of ``step`` (K): a flow depends on its two ends alone, so the network's Jacobian is assembled from
    these in O(paths) evaluations where differencing the whole network takes O(nodes × paths)."""
    balls_mean, among_factor = among_balls_mean(theta, drives, net)
    for p in range(net.kind.shape[0]):
        hot, cold = theta[net.hot[p]], cold_end(p, theta, balls_mean, net)
        by_hot[p] = (
            path_flow(p, hot + step, cold, among_factor, drives, net)
            - path_flow(p, hot - step, cold, among_factor, drives, net)
        ) / (2.0 * step)
        by_cold[p] = (
            path_flow(p, hot, cold + step, among_factor, drives, net)
            - path_flow(p, hot, cold - step, among_factor, drives, net)
        ) / (2.0 * step)


@njit(cache=True)
def node_conductances(drives: np.ndarray, net: NetworkArrays, out: np.ndarray) -> None:
    """The conductance (W/K) of all paths at each node into ``out``: the sum of the flows' magnitudes on the paths
    that end at it when it alone is 1 K above the ambient (the other balls' mean, an AMONG_BALLS path's cold end,
    moving by its own weight in it). One pass over the paths, not one per node: thousands of balls."""
    weights = np.zeros(out.shape[0])
    total = 0.0
    for p in range(net.kind.shape[0]):
        if net.kind[p] == AMONG_BALLS:
            weights[net.hot[p]] += drives[net.drive[p]]
            total += drives[net.drive[p]]
    if total > 0.0:
        weights /= total
    _, among_factor = among_balls_mean(np.full(out.shape[0], net.ambient), drives, net)
    out[:] = 0.0
    ambient = net.ambient
    for p in range(net.kind.shape[0]):
        hot, cold = net.hot[p], net.cold[p]
        raised_cold = ambient + weights[hot] if cold == BALLS else ambient
        out[hot] += abs(path_flow(p, ambient + 1.0, raised_cold, among_factor, drives, net))
        if cold >= 0:
            out[cold] += abs(path_flow(p, ambient, ambient + 1.0, among_factor, drives, net))


@njit(cache=True)
def path_flows_over(samples: np.ndarray, drives: np.ndarray, net: NetworkArrays, out: np.ndarray) -> None:
    """:func:`path_flows` at each row of ``samples`` (time, node) into the rows of ``out`` (time, path): a run's
    thousands of samples in one call."""
    for sample in range(samples.shape[0]):
        path_flows(samples[sample], drives, net, out[sample])


@njit(cache=True)
def balance(heat: np.ndarray, flows: np.ndarray, span: float, net: NetworkArrays, out: np.ndarray) -> float:
    """Heat into each node (``heat`` and the fixed heat over ``span`` in, each path's flow out of its hot end and
    into its cold end) into ``out``, in the unit of ``heat`` and ``flows`` (W with ``span`` = 1, or J over
    ``span`` seconds); returns what leaves the system: the flows into the room or a held node, less those out of
    a held node, and the heat into held nodes. Held nodes get 0: they are reservoirs outside the balance."""
    lost = 0.0
    for node in range(out.shape[0]):
        out[node] = heat[node] + net.fixed_heat[node] * span
    for p in range(flows.shape[0]):
        hot, cold = net.hot[p], net.cold[p]
        if net.held[hot]:
            lost -= flows[p]
        else:
            out[hot] -= flows[p]
        if cold == BALLS:
            continue  # the other balls receive these flows, which sum to zero
        if cold == ROOM or net.held[cold]:
            lost += flows[p]
        else:
            out[cold] += flows[p]
    for node in range(out.shape[0]):
        if net.held[node]:
            lost += out[node]
            out[node] = 0.0
    return lost


@njit(cache=True)
def temperature_rates(
    theta: np.ndarray, heat: np.ndarray, drives: np.ndarray, net: NetworkArrays, flows: np.ndarray, out: np.ndarray
) -> float:
    """dθ/dt (K/s) of every node into ``out`` (held nodes: 0) with ``heat`` (W) into each from the contacts;
    returns the heat leaving the system (W). ``flows`` receives each path's flow (W)."""
    path_flows(theta, drives, net, flows)
    lost = balance(heat, flows, 1.0, net, out)
    for node in range(out.shape[0]):
        out[node] /= net.capacity[node]
    return lost


@njit(cache=True)
def advance(
    theta: np.ndarray,
    heat: np.ndarray,
    drives: np.ndarray,
    span: float,
    net: NetworkArrays,
    flows: np.ndarray,
    energy: np.ndarray,
) -> float:
    """One explicit Euler step of ``span`` (s) from ``theta`` in place, with ``heat`` (J) received from the contacts
    in it and the flows at its start; returns the heat that left the system (J), and leaves in ``flows`` the
    heat through each path (J). Energy is conserved exactly."""
    path_flows(theta, drives, net, flows)
    for p in range(flows.shape[0]):
        flows[p] *= span
    lost = balance(heat, flows, span, net, energy)
    for node in range(theta.shape[0]):
        theta[node] += energy[node] / net.capacity[node]
    return lost
