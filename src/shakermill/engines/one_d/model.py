"""State layout and right-hand side of the one-ball model (MODEL.md section 6).

State vector (SI)::

    0 x        ball centre (m)             }
    1 p        ball momentum (kg·m/s)      }  dynamic: error-controlled
    2 θ_b      ball temperature (K)        }
    3 θ_v      vial temperature (K)        }
    4 θ_a      inner-air temperature (K)   }
    5 W_vial   work done by the vial on the ball (J)      }
    6 E_diss   energy dissipated in contacts, ∫P_d dt (J)  }  quadratures: integrated
    7 Q_irr    irreversible heat generated, ∫Q̇_irr dt (J)  }  with the same stages,
    8 Q_out    heat lost to the surroundings, ∫Q̇_vo dt (J) }  not error-controlled
    9 ∫w dt    integral of Whitaker's velocity term w = 0.4 Re^{1/2} + 0.06 Re^{2/3} (s);
               its time average drives the averaged solver's convection

Temperatures are used instead of the paper's internal energies (U = m·c·θ with
constant c, so the two are equivalent); they are better scaled for the error
control. The quadratures are linear in the right-hand side, so the thermal part
of the energy audit is preserved by any Runge–Kutta step to round-off.

For N balls the dynamic block becomes N positions, N momenta, N ball
temperatures, then θ_v and θ_a; the quadratures stay per system.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import njit

from shakermill.engines.thermal.air import air_constants
from shakermill.engines.thermal.network import ThermalNetwork, build_network
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.physics import contact, kinematics, thermal

X, P, THETA_BALL, THETA_VIAL, THETA_AIR, WORK_VIAL, DISSIPATED, HEAT_GENERATED, HEAT_LOST, VELOCITY_TERM = range(10)
N_DYNAMIC = 5
N_STATE = 10

NO_WALL, LEFT_WALL, RIGHT_WALL = 0, 1, 2


class Constants(NamedTuple):
    """Everything the compiled right-hand side needs, derived once from :class:`Parameters`."""

    ball_mass: float
    radius: float
    half_length: float
    amplitude: float
    omega: float
    period: float  # s, 2π/ω
    phase: float
    e_star: float
    beta_e: float
    no_tension: bool
    eta: float
    lam: float
    paper_heat: bool
    relative_convection: bool
    air_density: float
    viscosity_ambient: float
    prandtl: float
    mu_ref: float
    t_ref: float
    sutherland: float
    air_conductivity: float
    beta: float
    inner_conductance: float  # W/K: the network's "vial → air"
    outer_conductance: float  # W/K: its "vial → room"
    capacity_ball: float
    capacity_vial: float
    capacity_air: float
    t_ambient: float
    ball_only: bool


def _network_constants(params: Parameters, network: ThermalNetwork) -> dict[str, Any]:
    """The three-node network's fields of :class:`Constants`, by name (MODEL.md §§4–6), read from ``network``: the
    one network (``engines.thermal``) written out for the right-hand side. A network it cannot write out (another
    node, a path or a deposit beyond the paper's three nodes) is refused."""
    paths = {path.name: path for path in network.paths}
    if len(network.nodes) != 3 or network.deposits or set(paths) != {"ball → air", "vial → air", "vial → room"}:
        raise ParameterError(
            "engine: the 1-D engine writes out the paper's network of ball, vial and air alone; this run's has "
            f"{', '.join(node.name for node in network.nodes)} (allowed: engine = 'dem' for another network)"
        )
    return {
        **air_constants(params),
        "relative_convection": params.relative_convection,
        "air_density": params.air_density,
        "mu_ref": network.arrays.mu_ref,
        "t_ref": network.arrays.t_ref,
        "sutherland": network.arrays.sutherland,
        "air_conductivity": network.arrays.air_conductivity,
        "beta": network.arrays.beta,
        "inner_conductance": paths["vial → air"].conductance,
        "outer_conductance": paths["vial → room"].conductance,
        "capacity_ball": network.nodes[0].capacity,
        "capacity_vial": network.nodes[network.vial].capacity,
        "capacity_air": network.nodes[network.air].capacity,
        "lam": network.split.wall_ball_share,
        "t_ambient": network.ambient,
    }


def network_of(params: Parameters) -> ThermalNetwork:
    """The network of the one ball on the axis: the paper's (MODEL.md §§4–6)."""
    capacity = params.ball_mass * params.ball_heat_capacity
    return build_network(params, [params.ball_radius], [capacity], ("ball",), "λ of each impact's heat")


def constants_from(params: Parameters, network: ThermalNetwork | None = None) -> Constants:
    """Everything the right-hand side needs, its network's part from ``network`` (:func:`network_of` when None)."""
    e_star = contact.effective_modulus(
        params.ball_youngs_modulus, params.ball_poisson_ratio, params.vial_youngs_modulus, params.vial_poisson_ratio
    )
    return Constants(
        **_network_constants(params, network if network is not None else network_of(params)),
        ball_mass=params.ball_mass,
        radius=params.ball_radius,
        half_length=0.5 * params.vial_length,
        amplitude=params.amplitude,
        omega=params.omega,
        period=params.period,
        phase=params.phase,
        e_star=e_star,
        beta_e=contact.damping_ratio(params.restitution),
        no_tension=params.no_tension,
        eta=params.eta,
        paper_heat=params.heat_model == "paper",
        ball_only=params.model == "ball_only",
    )


def initial_state(params: Parameters) -> np.ndarray:
    y = np.zeros(N_STATE)
    y[X] = kinematics.vial_position(0.0, params.amplitude, params.omega, params.phase) + params.ball_position
    y[P] = params.ball_momentum
    y[THETA_BALL] = y[THETA_VIAL] = y[THETA_AIR] = params.initial_temperature
    if params.model == "ball_only":
        # The predecessor model has no vial reservoir and keeps the air at ambient.
        y[THETA_VIAL] = y[THETA_AIR] = params.ambient_temperature
    return y


@njit(cache=True)
def wall_contact(t: float, x: float, velocity: float, k: Constants) -> tuple[int, float, float, float]:
    """(wall, ζ, ζ̇, vial velocity) for the wall the ball touches; wall = NO_WALL in flight (MODEL.md §2)."""
    centre = kinematics.vial_position(t, k.amplitude, k.omega, k.phase)
    vial_velocity = kinematics.vial_velocity(t, k.amplitude, k.omega, k.phase)
    overlap = contact.overlap_left(x, kinematics.left_face(centre, 2.0 * k.half_length), k.radius)
    if overlap > 0.0:
        return LEFT_WALL, overlap, vial_velocity - velocity, vial_velocity
    overlap = contact.overlap_right(x, kinematics.right_face(centre, 2.0 * k.half_length), k.radius)
    if overlap > 0.0:
        return RIGHT_WALL, overlap, velocity - vial_velocity, vial_velocity
    return NO_WALL, 0.0, 0.0, vial_velocity


@njit(cache=True)
def contact_forces(overlap: float, overlap_rate: float, k: Constants) -> tuple[float, float]:
    """(applied force magnitude, elastic part) of a contact with the given overlap and rate, in N."""
    elastic = contact.hertz_force(overlap, k.e_star, k.radius)
    damping = contact.damping_coefficient(overlap, k.ball_mass, k.radius, k.e_star, k.beta_e)
    return contact.contact_force(elastic, damping, overlap_rate, k.no_tension), elastic


@njit(cache=True)
def gap(t: float, x: float, wall: int, k: Constants) -> float:
    """Distance between the ball surface and ``wall`` (m); negative means overlap."""
    centre = kinematics.vial_position(t, k.amplitude, k.omega, k.phase)
    if wall == LEFT_WALL:
        return x - kinematics.left_face(centre, 2.0 * k.half_length) - k.radius
    return kinematics.right_face(centre, 2.0 * k.half_length) - x - k.radius


@njit(cache=True)
def thermal_network(
    t_ball: float, t_vial: float, t_air: float, heat_generated: float, velocity_term: float, k: Constants
) -> tuple[float, float, float, float]:
    """(θ̇_b, θ̇_v, θ̇_a, heat lost) of the three-node network (MODEL.md §§4–6).

    ``heat_generated`` is Q̇_irr (W), split λ : (1 − λ) between ball and vial;
    ``velocity_term`` is the velocity-dependent part of Whitaker's correlation,
    0.4 Re^{1/2} + 0.06 Re^{2/3}, so that the temperature dependence through
    Sutherland's law is evaluated here, at the current ball temperature. The
    heat lost is Q̇_vo; in the ``ball_only`` model (air held at ambient, no vial
    reservoir, the paper's 2023 predecessor) it is everything that leaves the
    ball plus the vial's share of the impact heat.
    """
    viscosity_ratio = thermal.sutherland_viscosity(t_ball, k.mu_ref, k.t_ref, k.sutherland) / k.mu_ref
    nusselt = thermal.nusselt_from_velocity_term(velocity_term, k.prandtl, viscosity_ratio)
    h_ball = thermal.heat_transfer_coefficient(nusselt, k.air_conductivity, k.radius)
    if k.ball_only:
        ball_to_ambient = thermal.ball_air_heat_flow(k.radius, k.beta, h_ball, t_ball, k.t_ambient)
        rate_ball = (k.lam * heat_generated - ball_to_ambient) / k.capacity_ball
        return rate_ball, 0.0, 0.0, ball_to_ambient + (1.0 - k.lam) * heat_generated
    ball_to_air = thermal.ball_air_heat_flow(k.radius, k.beta, h_ball, t_ball, t_air)
    vial_to_air = k.inner_conductance * (t_vial - t_air)
    vial_to_outside = k.outer_conductance * (t_vial - k.t_ambient)
    rate_ball, rate_vial, rate_air = thermal.temperature_rates(
        k.lam * heat_generated,
        (1.0 - k.lam) * heat_generated,
        ball_to_air,
        vial_to_air,
        vial_to_outside,
        k.capacity_ball,
        k.capacity_vial,
        k.capacity_air,
    )
    return rate_ball, rate_vial, rate_air, vial_to_outside


@njit(cache=True)
def rhs(t: float, y: np.ndarray, k: Constants, dydt: np.ndarray) -> None:
    """Write dy/dt of the state (module docstring) into ``dydt`` (MODEL.md §§2–6; paper Eqs. 32–36)."""
    velocity = y[P] / k.ball_mass
    wall, overlap, overlap_rate, vial_velocity = wall_contact(t, y[X], velocity, k)
    force_on_ball = 0.0
    power_dissipated = 0.0
    heat_generated = 0.0
    if wall != NO_WALL:
        force, elastic = contact_forces(overlap, overlap_rate, k)
        normal = 1.0 if wall == LEFT_WALL else -1.0
        force_on_ball = normal * force
        power_dissipated = contact.dissipated_power(force, elastic, overlap_rate)
        if k.paper_heat:
            # The paper's Eqs. 10-11 (η·F_d·v, lab frame), made non-negative as MODEL.md §3 allows
            # for comparison; not frame invariant, so never the default.
            heat_generated = k.eta * abs(normal * (force - elastic) * velocity)
        else:
            heat_generated = k.eta * power_dissipated

    convection_speed = velocity - vial_velocity if k.relative_convection else velocity
    reynolds = thermal.reynolds_number(k.radius, k.air_density, convection_speed, k.viscosity_ambient)
    velocity_term = thermal.whitaker_velocity_term(reynolds)
    rate_ball, rate_vial, rate_air, heat_lost = thermal_network(
        y[THETA_BALL], y[THETA_VIAL], y[THETA_AIR], heat_generated, velocity_term, k
    )
    dydt[X] = velocity
    dydt[P] = force_on_ball
    dydt[THETA_BALL] = rate_ball
    dydt[THETA_VIAL] = rate_vial
    dydt[THETA_AIR] = rate_air
    dydt[WORK_VIAL] = force_on_ball * vial_velocity
    dydt[DISSIPATED] = power_dissipated
    dydt[HEAT_GENERATED] = heat_generated
    dydt[HEAT_LOST] = heat_lost
    dydt[VELOCITY_TERM] = velocity_term


@njit(cache=True)
def mechanical_energy(t: float, y: np.ndarray, k: Constants) -> float:
    """Kinetic plus elastic energy of the ball, p²/2m + V(ζ), in J (energy audit)."""
    wall, overlap, _, _ = wall_contact(t, y[X], y[P] / k.ball_mass, k)
    elastic = contact.elastic_energy(overlap, k.e_star, k.radius) if wall != NO_WALL else 0.0
    return 0.5 * y[P] * y[P] / k.ball_mass + elastic


def rhs_numpy(t: float, y: np.ndarray, k: Constants) -> np.ndarray:
    """The same right-hand side as a plain function returning dy/dt, for SciPy's solvers."""
    dydt = np.empty_like(y)
    rhs(t, y, k, dydt)
    return dydt
