"""Constants and state of the 'dem' engine, derived once from :class:`Parameters` (MODEL.md section 12).

Frames: the lab frame has z up (gravity −z) and, for every motion but a planetary jar's (whose axis stands
along z), x along the vial's axis at rest; the vial frame moves with the vial (its axis is its x). Contacts
live in slots: ball i against the left end, the right end or the cylindrical side in slot ``3i + wall``; the pair
of entry e of the neighbour list (:class:`Neighbours`) in slot ``3N + e``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from shakermill.engines.dem import neighbours as neighbour_list
from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.air import air_constants
from shakermill.engines.thermal.network import ThermalNetwork, build_network
from shakermill.parameters.keys import Parameters
from shakermill.parameters.kinematic_models import motion_terms
from shakermill.parameters.motions import MOTION_COORDINATES
from shakermill.physics import contact
from shakermill.physics.kinematics import angular_velocity, fourier_coordinates, rotation_matrix

LEFT_END, RIGHT_END, SIDE = 0, 1, 2
WALL_NAMES = ("left", "right", "side")
N_WALLS = 3
STANDARD_GRAVITY = 9.81  # m/s², MODEL.md §12.1

# Running totals of a run, in J (the energy audit, MODEL.md §12.6) and s.
(
    WORK_VIAL,
    WORK_GRAVITY,
    DISSIPATED_NORMAL,
    DISSIPATED_TANGENTIAL,
    DISSIPATED_SLIDING,
    DISSIPATED_ROLLING,
    HEAT_GENERATED,
    HEAT_LOST,
    WORK_STIFFENING,
) = range(9)
TOTAL_NAMES = (
    "work_vial",
    "work_gravity",
    "dissipated_normal",
    "dissipated_tangential",
    "dissipated_sliding",
    "dissipated_rolling",
    "heat_generated",
    "heat_lost",
    # Energy the Mindlin springs gain as their stiffness k_t = 8G*√(R*ζ) grows with the overlap at a given
    # stretch, ½|δ_t|²·Δk_t: the Hertz–Mindlin model of DEM is not conservative there, so the audit books it
    # as a supply of its own rather than hide it in a dissipation channel.
    "work_stiffening",
)


class Constants(NamedTuple):
    """Everything the compiled stepping needs. Per-ball arrays have length N: a pair's effective values are formed
    from its two balls' when it touches (``contacts.pair_values``), so that nothing grows as N²."""

    n_balls: int
    radius: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    youngs_modulus: np.ndarray  # Pa
    poisson_ratio: np.ndarray
    # Ball-wall contacts (per ball, per wall kind)
    wall_modulus: np.ndarray  # E* with the vial, per ball
    wall_shear_modulus: np.ndarray
    wall_radius: np.ndarray  # (N, 3): R* against the left end, the right end, the side
    # Conduction through contacts (MODEL.md §13.1): each ball's and the vial's effusivity √(ρck) and conductivity
    effusivity: np.ndarray  # (N,) W·s^½/(m²·K)
    conductivity: np.ndarray  # (N,) W/(m·K)
    vial_effusivity: float
    vial_conductivity: float
    # Damping ratio and Coulomb coefficient of a ball on the vial (beta_e, friction) and of two balls (pair_*).
    beta_e: float
    pair_beta_e: float
    no_tension: bool
    friction: float
    pair_friction: float
    rolling_friction: float
    eta: float
    lam: float
    # Shares of each contact's heat deposited in nodes other than its two bodies (the powder; network.deposits):
    # their count, their nodes (m,) and shares over (contact kind: wall, pair; channel; deposit).
    deposit_count: int
    deposit_nodes: np.ndarray
    deposit_shares: np.ndarray
    # The vial
    half_length: float
    bore_radius: float
    omega: float
    phase: float
    harmonics: np.ndarray  # (6, K, 2): (cos, sin) of x, y, z, roll, pitch, yaw per harmonic k
    angular_speed_bound: float  # rad/s: the vial never turns faster
    wall_acceleration_bound: float  # m/s²: no point of the vial accelerates faster
    gravity: np.ndarray  # (3,), m/s², lab frame
    # Steps
    contact_step: float  # s: contact_step_fraction × the smallest Rayleigh time
    period_step_fraction: float  # an impact's step at most this fraction of its period (MODEL.md §12.6)
    enduring_step_fraction: float  # the same for a contact older than ENDURING_AFTER of its periods
    longest_contact_step: float  # s: 0.9 × the smallest Rayleigh time, MODEL.md §7's bound inside contacts
    max_flight_step: float  # s
    max_overlap: float  # m: beyond it the step control failed
    thermal_step: float  # s: the thermal network is advanced on this clock
    # The neighbour list (:class:`Neighbours`, ``neighbours.py``): pairs listed within r_i + r_j + skin of each other,
    # found through a grid of cubic cells that covers the cube of half-width ``grid_reach`` about the vial's centre.
    # An infinite skin lists every pair once and for all (a few balls: :func:`neighbour_skin`).
    skin: float  # m
    cell_size: float  # m
    cells_per_side: int
    grid_reach: float  # m
    # Convection (MODEL.md §§4, 12.5): each ball's Re. The thermal network it drives is an argument of its own:
    # every array in these constants costs a reference count at each use inside the compiled step (~10 % of its time).
    relative_convection: bool
    air_density: float
    viscosity_ambient: float


class State(NamedTuple):
    """The mutable state of a run; the compiled stepping updates these arrays in place."""

    clock: np.ndarray  # [t, time since the last thermal update]
    position: np.ndarray  # (N, 3) m, lab frame
    velocity: np.ndarray  # (N, 3) m/s
    spin: np.ndarray  # (N, 3) rad/s, angular velocity
    force: np.ndarray  # (N, 3) N: contact forces of the last evaluation (gravity apart)
    torque: np.ndarray  # (N, 3) N·m
    temperature: np.ndarray  # (nodes,) K: the thermal network's nodes (the balls, the vial, the air, then the others)
    pending_heat: np.ndarray  # (nodes,) J from the contacts into each node since the last thermal update
    # The network's drives (engines.thermal.kernel): each ball's Whitaker term integral ∫w dt (s), then the heat per
    # kelvin of the contacts (J/K) of each ball with the vial and with the other balls, since the last thermal update...
    pending_drives: np.ndarray  # (D,)
    totals: np.ndarray  # (len(TOTAL_NAMES),) J
    heat_into: np.ndarray  # (nodes,) J: all heat from the contacts into each node so far
    drive_integrals: np.ndarray  # (D,) ...and since the start
    contacts: Contacts
    neighbours: Neighbours


class Contacts(NamedTuple):
    """Per-slot contact memory: forces of the last evaluation (for the step's mean work), the tangential
    spring, stored elastic energies and what the impact record of a running contact has gathered."""

    active: np.ndarray  # (S,) bool
    normal_force: np.ndarray  # (S, 3) on ball i
    tangential_force: np.ndarray  # (S, 3) on ball i
    lever_torque_i: np.ndarray  # (S, 3): torque of the tangential force on ball i
    lever_torque_j: np.ndarray  # (S, 3): on ball j (zero for a wall)
    rolling_torque: np.ndarray  # (S, 3) on ball i (−it on j or the vial)
    wall_velocity: np.ndarray  # (S, 3): the vial's velocity at the contact point
    spring: np.ndarray  # (S, 3) m: tangential displacement δ_t
    elastic_energy: np.ndarray  # (S,) J: Hertz normal energy
    stiffness: np.ndarray  # (S,) N/m: k_t
    stretch: np.ndarray  # (S,) m²: |δ_t|²
    slip_loss: np.ndarray  # (S,) J: energy the Coulomb limit took in this step, μF_n⁺·|slip|
    period: np.ndarray  # (S,) s: shortest oscillation period of the contact at its last evaluation
    impact_period: np.ndarray  # (S,) s: that period at its first evaluation, the shortest of its impact
    release: np.ndarray  # (S,) s: time its overlap takes to open at its rate at the last evaluation (inf: closing)
    started: np.ndarray  # (S,) s
    normal_speed_in: np.ndarray  # (S,) m/s: closing speed at first touch
    tangential_speed_in: np.ndarray  # (S,) m/s: sliding speed of the contact points at first touch
    dissipated: np.ndarray  # (S, 4) J by channel so far
    peak_force: np.ndarray  # (S,) N
    max_overlap: np.ndarray  # (S,) m


class Neighbours(NamedTuple):
    """The pairs of balls near enough to touch before the list is next built (a Verlet list built through a cell grid,
    Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed. (2017) §5.3): entry e pairs ``first_ball[e]`` <
    ``second_ball[e]``; ball i's entries are ``first[i]`` to ``first[i + 1]``. It is rebuilt once a ball has moved
    a quarter of the skin relative to the vial's centre since the last build, and no step lets a ball move half of
    it (``stepper._flight_step``), so that no pair left out can touch. The contacts of listed pairs that touch are
    carried to their new entries through ``carried``."""

    first_ball: np.ndarray  # (P,) int64
    second_ball: np.ndarray  # (P,) int64
    first: np.ndarray  # (N + 1,) int64
    entries: np.ndarray  # (1,) int64: entries in use (a field named count would hide tuple.count)
    reference: np.ndarray  # (N, 3) m: each ball's centre relative to the vial's at the last build
    cell_head: np.ndarray  # (cells,) int64: a ball in each cell (−1: none), the others chained by cell_next
    cell_next: np.ndarray  # (N,) int64
    carried_first: np.ndarray  # (P,) int64: the pairs of the touching contacts being carried
    carried_second: np.ndarray  # (P,) int64
    carried: Contacts  # (P slots)


def slot_count(n_balls: int, pair_capacity: int) -> int:
    return N_WALLS * n_balls + pair_capacity


# A finite skin of this fraction of the smallest radius; a few balls list every pair instead (:func:`neighbour_skin`).
SKIN_FRACTION = 0.3
# The grid has at most this many cells a side: a small ball in a large bowl gets cells larger than it needs.
MOST_CELLS_PER_SIDE = 128


def pair_capacity(radius: np.ndarray, skin: float) -> int:
    """Entries the neighbour list can need for balls of ``radius`` (m) with ``skin`` (m; inf: every pair).

    A bound, not an estimate: balls overlap by at most MAX_OVERLAP_FRACTION of the smallest radius, so spheres of
    0.95 of each radius are disjoint; those of ball i's neighbours lie within r_i + 1.95·r_max + skin of its centre,
    and there are at most (that distance / (0.95·r_min))³ of them. Each pair counts for its two balls."""
    n = radius.size
    all_pairs = n * (n - 1) // 2
    if not math.isfinite(skin) or n < 2:
        return all_pairs
    core = (1.0 - MAX_OVERLAP_FRACTION) * float(radius.min())
    reach = radius + (2.0 - MAX_OVERLAP_FRACTION) * float(radius.max()) + skin
    return min(all_pairs, int(np.ceil(np.sum(np.floor((reach / core) ** 3)) / 2.0)))


def neighbour_skin(radius: np.ndarray) -> float:
    """The skin of the neighbour list (m): SKIN_FRACTION of the smallest radius, or infinite (every pair listed,
    never rebuilt) where the bound on a finite list's entries holds every pair anyway, as for a few balls."""
    if radius.size < 2:
        return math.inf
    skin = SKIN_FRACTION * float(radius.min())
    return math.inf if pair_capacity(radius, skin) >= radius.size * (radius.size - 1) // 2 else skin


def neighbour_grid(radius: np.ndarray, skin: float, reach: float) -> tuple[float, int]:
    """Cell size (m) and cells a side of a grid over the cube of half-width ``reach`` (m): a cell holds no pair
    farther apart than the list takes unless the grid would exceed MOST_CELLS_PER_SIDE."""
    if not math.isfinite(skin):
        return 2.0 * reach, 1
    cell = max(2.0 * float(radius.max()) + skin, 2.0 * reach / MOST_CELLS_PER_SIDE)
    return cell, max(1, int(math.ceil(2.0 * reach / cell)))


def harmonics_of(params: Parameters) -> np.ndarray:
    """The vial's motion as Fourier data (MODEL.md §12.2): the terms of the model ``params.kinematics``
    names (parameters/kinematic_models.py) as ``harmonics[coordinate, k] = (cos, sin)``, m and rad."""
    terms = motion_terms(params.kinematics, params)
    highest = max(k for _, k, _, _ in terms)
    harmonics = np.zeros((len(MOTION_COORDINATES), highest + 1, 2))
    for coordinate, k, cosine, sine in terms:
        harmonics[MOTION_COORDINATES.index(coordinate), k] += (cosine, sine)
    return harmonics


def _motion_bounds(harmonics: np.ndarray, omega: float, reach: float) -> tuple[float, float]:
    """Upper bounds of the vial's angular speed and of the acceleration of any vial point within ``reach``
    of its centre.

    Each coordinate's Fourier series bounds its rate by |s|ω + Σ kω(|a|+|b|) (s its steady rate) and its second
    rate by Σ (kω)²(|a|+|b|); a rotating point adds (|Ω̇| + |Ω|²)·r. Ω̇ of the composed turns holds each angle's
    second rate and a product of the rates of every two of them (a jar spinning about an axis that itself turns).
    """
    k = np.arange(harmonics.shape[1])
    size = np.abs(harmonics).sum(axis=2)
    rate = size @ (k * omega) + np.abs(harmonics[:, 0, 1]) * omega
    second = size @ (k * omega) ** 2
    angular_rate, angular_second = rate[3:].sum(), second[3:].sum()
    turns_of_turns = 0.5 * (angular_rate**2 - float(np.sum(rate[3:] ** 2)))
    acceleration = float(np.linalg.norm(second[:3]) + (angular_second + turns_of_turns + angular_rate**2) * reach)
    return float(angular_rate), acceleration


def _masses(params: Parameters) -> np.ndarray:
    """Each ball's mass ρ·4/3·π R³ (kg)."""
    return np.array(params.ball_masses(), dtype=float)


def network_of(params: Parameters) -> ThermalNetwork:
    """The thermal network of ``params``' balls, vial and air (MODEL.md §12.5)."""
    radius = params.ball_values("ball_radius")
    capacity = _masses(params) * np.array(params.ball_values("ball_heat_capacity"))
    names = [f"ball {i}" for i in range(params.n_balls)]
    share = (
        "λ of the heat of its contacts with the vial, its effusivity share of those with other balls (MODEL.md §12.4)"
    )
    return build_network(params, radius, capacity, names, share)


def thermal_step(network: ThermalNetwork) -> float:
    """The clock the stepping advances ``network`` on (s): THERMAL_STEP, or a tenth of its fastest node's time
    constant at rest where that is shorter; a node too stiff to step is refused (``check_not_stiff``)."""
    time_constants = network.time_constants_at_rest()
    network.check_not_stiff(time_constants)
    return min(THERMAL_STEP, THERMAL_STEP_FRACTION * min(time_constants.values(), default=math.inf))


def constants_from(params: Parameters, network: ThermalNetwork | None = None) -> Constants:
    """Everything the stepping needs but the thermal network's compiled form: of ``network`` (:func:`network_of`
    when None), where the contacts' heat goes and its fastest time constant."""
    network = network if network is not None else network_of(params)
    deposit_nodes, deposit_shares = network.deposit_arrays()
    n = params.n_balls
    radius = np.array(params.ball_values("ball_radius"))
    density = np.array(params.ball_values("ball_density"))
    youngs = np.array(params.ball_values("ball_youngs_modulus"))
    poisson = np.array(params.ball_values("ball_poisson_ratio"))
    heat_capacity = np.array(params.ball_values("ball_heat_capacity"))
    conductivity = np.array(params.ball_values("ball_conductivity"))
    mass = _masses(params)
    effusivity = np.sqrt(conductivity * density * heat_capacity)
    vial_effusivity = math.sqrt(params.vial_conductivity * params.vial_density * params.vial_heat_capacity)
    bore = 0.5 * params.vial_diameter
    wall_radius = np.column_stack([radius, radius, [contact.concave_radius(r, bore) for r in radius]])
    e_v, nu_v = params.vial_youngs_modulus, params.vial_poisson_ratio
    harmonics = harmonics_of(params)
    reach = math.hypot(0.5 * params.vial_length, bore)
    angular_bound, acceleration_bound = _motion_bounds(harmonics, params.omega, reach)
    skin = neighbour_skin(radius)
    cell_size, cells_per_side = neighbour_grid(radius, skin, reach)
    rayleigh = min(
        (contact.rayleigh_time(r, rho, e, nu) for r, rho, e, nu in zip(radius, density, youngs, poisson, strict=True)),
        # An empty mill (n_balls = 0) has no contact to resolve: it takes flight steps, short for its thermal network.
        default=params.max_flight_step / params.contact_step_fraction,
    )
    impact_fraction = params.contact_step_fraction * IMPACT_STEP_SCALE
    return Constants(
        relative_convection=params.relative_convection,
        air_density=params.air_density,
        viscosity_ambient=air_constants(params)["viscosity_ambient"],
        n_balls=n,
        radius=radius,
        mass=mass,
        inertia=0.4 * mass * radius**2,
        youngs_modulus=youngs,
        poisson_ratio=poisson,
        wall_modulus=np.array([contact.effective_modulus(e, nu, e_v, nu_v) for e, nu in zip(youngs, poisson)]),
        wall_shear_modulus=np.array(
            [contact.effective_shear_modulus(e, nu, e_v, nu_v) for e, nu in zip(youngs, poisson)]
        ),
        wall_radius=wall_radius,
        effusivity=effusivity,
        conductivity=conductivity,
        vial_effusivity=vial_effusivity,
        vial_conductivity=params.vial_conductivity,
        beta_e=contact.damping_ratio(network.restitution.wall),
        pair_beta_e=contact.damping_ratio(network.restitution.pair),
        no_tension=params.no_tension,
        friction=params.friction,
        pair_friction=params.pair_friction,
        rolling_friction=params.rolling_friction,
        eta=params.eta,
        lam=network.split.wall_ball_share,
        deposit_count=deposit_nodes.size,
        deposit_nodes=deposit_nodes,
        deposit_shares=deposit_shares,
        half_length=0.5 * params.vial_length,
        bore_radius=bore,
        omega=params.omega,
        phase=params.phase,
        harmonics=harmonics,
        angular_speed_bound=angular_bound,
        wall_acceleration_bound=acceleration_bound,
        gravity=np.array([0.0, 0.0, -STANDARD_GRAVITY if params.gravity else 0.0]),
        contact_step=params.contact_step_fraction * rayleigh,
        period_step_fraction=impact_fraction,
        enduring_step_fraction=max(params.enduring_step_fraction, impact_fraction),
        longest_contact_step=0.9 * rayleigh,
        max_flight_step=params.max_flight_step,
        max_overlap=MAX_OVERLAP_FRACTION * float(radius.min(initial=math.inf)),
        thermal_step=thermal_step(network),
        skin=skin,
        cell_size=cell_size,
        cells_per_side=cells_per_side,
        grid_reach=reach,
    )


# An impact steps at contact_step_fraction × IMPACT_STEP_SCALE of its own period T₀ (contact.contact_period at its
# first evaluation, the tangential one with the balls' spin, taken at the peak overlap its approach will reach: the
# shortest period of the impact), 1/100 of it at the default 0.025; its start (the flight step shrinks to
# contact_step as the gap closes) and its release (stepper._contact_limit) at the contact step. Verlet's restitution
# error is then the same at every speed: head-on steel, e = 0.7, 0.1–5 m/s, 40 speeds, it is at most 8e-4 on the
# end face (first order in the step: the damper) and 7e-4 between balls, where the contact step throughout (1/380 of
# T at 0.1 m/s, 1/170 at 5 m/s), which stepped impacts before, left 6.4e-4 at two to four times the steps
# (benchmarks/README.md, "An impact at its own pace"). A finer contact_step_fraction refines every impact alike.
IMPACT_STEP_SCALE = 0.4
# An impact is over within about one of its periods (T above is the tangential period, ~0.6 of the normal one, and a
# Hertz impact lasts about half a normal period, ~0.85 T); a contact that has lasted ENDURING_AFTER periods rolls,
# slides or rests. Its restitution is no longer at stake, only its forces and the heat of its slip, which Verlet
# resolves at enduring_step_fraction of T (20 steps a period at the default, stable below 1/π), still within 0.9 t_R.
ENDURING_AFTER = 2.0
# A contact overlap beyond this fraction of the smallest radius means the step control failed.
MAX_OVERLAP_FRACTION = 0.05
# The thermal network moves over ~0.1 s (the air) to hours (the vial): explicit Euler steps of a millisecond,
# and never more than a tenth of the fastest node's time constant at rest, keep it stable and accurate.
THERMAL_STEP = 1e-3
THERMAL_STEP_FRACTION = 0.1


# A replica of a run starts with every ball given this speed (m/s) in a seeded direction: a few thousandths of the
# vial's speed, which the balls' chaotic hits on each other and the bore magnify into a motion of its own.
REPLICA_KICK = 0.01


def kick_for_replica(state: State, replica: int) -> None:
    """Give each ball of ``state`` REPLICA_KICK in a direction drawn by a generator seeded with ``replica`` (> 0):
    a replica's start depends on the configuration and its number alone."""
    directions = np.random.default_rng(replica).normal(size=state.velocity.shape)
    state.velocity[:] += REPLICA_KICK * directions / np.linalg.norm(directions, axis=1, keepdims=True)


def initial_state(params: Parameters, k: Constants, network: ThermalNetwork) -> State:
    """Balls where :meth:`Parameters.initial_positions` puts them, at rest (one ball: ``ball_position`` and
    ``ball_momentum`` along the axis, as the 1-D engine) or, in a vial that rotates steadily (a planetary jar),
    carried with it; every node of ``network`` at the initial temperature (held ones at the ambient)."""
    n = params.n_balls
    centre = np.zeros(6)
    rates = np.zeros(6)
    fourier_coordinates(0.0, k.omega, k.phase, k.harmonics, centre, rates)
    orientation = np.empty((3, 3))
    rotation_matrix(centre[3], centre[4], centre[5], orientation)
    placed = params.initial_positions()
    if placed is None:  # parameters/consistency.py refuses a charge that does not fit before a run is built
        raise ValueError(f"n_balls: {n} balls do not fit side by side in the vial")
    position = centre[:3] + placed @ orientation.T
    velocity = np.zeros((n, 3))
    spin = np.zeros((n, 3))
    if np.any(k.harmonics[3:, 0, 1] != 0.0):
        # A jar turning steadily at full speed and hitting balls at rest would begin with an impact at metres per
        # second that no mill makes (the mill spins up over seconds): the balls start as if stuck to the jar.
        turning = np.empty(3)
        angular_velocity(centre[4], centre[5], rates[3], rates[4], rates[5], turning)
        velocity[:] = rates[:3] + np.cross(turning, position - centre[:3])
        spin[:] = turning
    elif n == 1:
        velocity[0, 0] = params.ball_momentum / k.mass[0]
    drives = kernel.drive_count(n)
    neighbours = neighbours_of(k, position, centre[:3])
    capacity = neighbours.first_ball.size
    return State(
        clock=np.zeros(2),
        position=position,
        velocity=velocity,
        spin=spin,
        force=np.zeros((n, 3)),
        torque=np.zeros((n, 3)),
        temperature=network.initial_temperatures(params.initial_temperature),
        pending_heat=np.zeros(len(network.nodes)),
        pending_drives=np.zeros(drives),
        totals=np.zeros(len(TOTAL_NAMES)),
        heat_into=np.zeros(len(network.nodes)),
        drive_integrals=np.zeros(drives),
        contacts=empty_contacts(slot_count(n, capacity)),
        neighbours=neighbours,
    )


# Contacts' fields by shape per slot (the rest are one number per slot).
CONTACT_VECTORS = (
    "normal_force",
    "tangential_force",
    "lever_torque_i",
    "lever_torque_j",
    "rolling_torque",
    "wall_velocity",
    "spring",
)


def empty_contacts(slots: int) -> Contacts:
    """The memory of ``slots`` contacts, none touching."""
    numbers = set(Contacts._fields) - {"active", "dissipated", *CONTACT_VECTORS}
    return Contacts(
        active=np.zeros(slots, dtype=np.bool_),
        dissipated=np.zeros((slots, 4)),
        **{name: np.zeros((slots, 3)) for name in CONTACT_VECTORS},
        **{name: np.zeros(slots) for name in sorted(numbers)},
    )


def contact_memory(k: Constants, record_columns: int) -> int:
    """Bytes the contacts of balls of ``k`` hold whatever the run's length: each slot's memory and scratch, the
    neighbour list and the carried contacts of each of its entries, its grid, and the impact buffer's least size
    (a row of ``record_columns`` per slot, the stepping's margin, doubled as it grows)."""
    capacity = pair_capacity(k.radius, k.skin)
    slots = slot_count(k.n_balls, capacity)
    per_slot = sum(array.nbytes for array in empty_contacts(1)) + sum(
        array.nbytes for array in scratch_for(0, 1) if array.shape[:1] == (1,)
    )
    per_entry = 4 * 8 + sum(array.nbytes for array in empty_contacts(1))
    per_ball = 8 * (1 + 3 + 1)
    return (
        slots * (per_slot + 2 * 8 * record_columns)
        + capacity * per_entry
        + k.n_balls * per_ball
        + 8 * k.cells_per_side**3
    )


def neighbours_of(k: Constants, position: np.ndarray, centre: np.ndarray) -> Neighbours:
    """The neighbour list of balls at ``position`` in a vial centred at ``centre`` (m), built."""
    n = k.n_balls
    capacity = pair_capacity(k.radius, k.skin)
    listed = Neighbours(
        first_ball=np.zeros(capacity, dtype=np.int64),
        second_ball=np.zeros(capacity, dtype=np.int64),
        first=np.zeros(n + 1, dtype=np.int64),
        entries=np.zeros(1, dtype=np.int64),
        reference=np.zeros((n, 3)),
        cell_head=np.zeros(k.cells_per_side**3, dtype=np.int64),
        cell_next=np.zeros(n, dtype=np.int64),
        carried_first=np.zeros(capacity, dtype=np.int64),
        carried_second=np.zeros(capacity, dtype=np.int64),
        carried=empty_contacts(capacity),
    )
    if not neighbour_list.build(k, position, centre, listed):
        raise ValueError("the balls start deeper in each other than a run allows: no neighbour list holds their pairs")
    return listed


def row_fields(n_balls: int, nodes: int) -> tuple[tuple[str, tuple[int, ...]], ...]:
    """Layout of a recorded state row (after its time) of ``n_balls`` and a network of ``nodes``: each field's
    name and shape."""
    return (
        ("position", (n_balls, 3)),
        ("velocity", (n_balls, 3)),
        ("angular_velocity", (n_balls, 3)),
        ("temperature", (nodes,)),
        ("totals", (len(TOTAL_NAMES),)),
        ("heat_into", (nodes,)),
        ("drive_integrals", (kernel.drive_count(n_balls),)),
        ("vial", (6,)),
    )


def row_width(n_balls: int, nodes: int) -> int:
    return 1 + sum(int(np.prod(shape)) for _, shape in row_fields(n_balls, nodes))


def unpack_rows(rows: np.ndarray, n_balls: int, nodes: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Times and named fields (each over (time, *shape)) of recorded state rows."""
    fields, offset = {}, 1
    for name, shape in row_fields(n_balls, nodes):
        size = int(np.prod(shape))
        fields[name] = rows[:, offset : offset + size].reshape(len(rows), *shape)
        offset += size
    return rows[:, 0], fields


class Scratch(NamedTuple):
    """Arrays of one call, allocated once so that the compiled loop allocates nothing per step."""

    coordinates: np.ndarray  # (6,) the vial's x, y, z, roll, pitch, yaw
    rates: np.ndarray  # (6,) their time derivatives
    orientation: np.ndarray  # (3, 3) vial frame to lab frame
    angular: np.ndarray  # (3,) the vial's angular velocity now
    angular_before: np.ndarray  # (3,) at the step's start
    half_velocity: np.ndarray  # (N, 3) after the first half kick
    half_spin: np.ndarray  # (N, 3)
    velocity_before: np.ndarray  # (N, 3) at the step's start
    spin_before: np.ndarray  # (N, 3)
    pushed: np.ndarray  # (N,) twice each ball's contact acceleration |F|/m, the flight step's bound on it
    wall_gaps: np.ndarray  # (N·N_WALLS,) m: each ball's gap to each wall at the last evaluation, by wall slot
    normal_force: np.ndarray  # (S, 3) new forces and torques on ball i per slot
    tangential_force: np.ndarray
    lever_torque_i: np.ndarray
    lever_torque_j: np.ndarray
    rolling_torque: np.ndarray
    wall_velocity: np.ndarray  # (S, 3) the vial's velocity at the contact point
    elastic_energy: np.ndarray  # (S,)
    stiffness: np.ndarray  # (S,) tangential k_t
    stretch: np.ndarray  # (S,) |δ_t|²
    live: np.ndarray  # (S,) slots touching now or at the step's start
    touching: np.ndarray  # (S,) bool: touching at the step's end
    normal: np.ndarray  # (3,) vectors of the contact being evaluated
    point_velocity: np.ndarray
    other_velocity: np.ndarray
    lever: np.ndarray
    relative_spin: np.ndarray


def scratch_for(n_balls: int, slots: int) -> Scratch:
    return Scratch(
        coordinates=np.zeros(6),
        rates=np.zeros(6),
        orientation=np.zeros((3, 3)),
        angular=np.zeros(3),
        angular_before=np.zeros(3),
        half_velocity=np.zeros((n_balls, 3)),
        half_spin=np.zeros((n_balls, 3)),
        velocity_before=np.zeros((n_balls, 3)),
        spin_before=np.zeros((n_balls, 3)),
        pushed=np.zeros(n_balls),
        wall_gaps=np.zeros(N_WALLS * n_balls),
        normal_force=np.zeros((slots, 3)),
        tangential_force=np.zeros((slots, 3)),
        lever_torque_i=np.zeros((slots, 3)),
        lever_torque_j=np.zeros((slots, 3)),
        rolling_torque=np.zeros((slots, 3)),
        wall_velocity=np.zeros((slots, 3)),
        elastic_energy=np.zeros(slots),
        stiffness=np.zeros(slots),
        stretch=np.zeros(slots),
        live=np.zeros(slots, dtype=np.int64),
        touching=np.zeros(slots, dtype=np.bool_),
        normal=np.zeros(3),
        point_velocity=np.zeros(3),
        other_velocity=np.zeros(3),
        lever=np.zeros(3),
        relative_spin=np.zeros(3),
    )
