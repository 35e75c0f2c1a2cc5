"""One impact on its own: a ball against the vial's resting end face, or against an identical ball at
rest, run through the 'dem' engine (MODEL.md section 12) and measured as the DEM verification tests of
Chung & Ooi (Granular Matter 13 (2011) 643–656) measure it.

Geometry and signs. The impact happens in the lab's x–y plane (the plane of incidence). The normal
``n = +x`` points from the target into the incoming ball, which moves with ``(−V cos θ, V sin θ, 0)``;
the tangent is ``t = +y``. Spins are about ``n × t = +z``: positive is the sense of a ball rolling
along the target in the direction it came, so that the contact point slips at ``v_t − R ω`` and a
rolling ball has ``ω = v_t / R``. Against a ball the normal is the line of centres at first touch: it
turns a little while the balls pass each other (by about v_t·t_c/2R), so an oblique frictionless impact
of two balls moves some velocity from n to t; the end face's normal stays put.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from shakermill.parameters.engine_keys import reader_of, reads_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.groups import (
    GROUP_OF,
    GROUPS,
    BallPairs,
    Balls,
    ContactDamping,
    DemContacts,
    DemStepping,
    VialWall,
)
from shakermill.parameters.key_group import CONTACT_COATING
from shakermill.parameters.keys import PER_BALL_KEYS, Parameters

if TYPE_CHECKING:
    import numpy as np

    from shakermill.engines.dem.engine import DemEngine
    from shakermill.engines.interface import EngineDescription

TARGETS = ("wall", "ball")
# Faster than any mill or verification test; a ball this fast overlaps beyond what the engine allows anyway.
MAX_SPEED = 1000.0  # m/s
MAX_ANGLE = 90.0  # degrees, excluded: a grazing ball never arrives
# The ball starts this fraction of the Hertz maximum overlap away from its target: the approach then
# takes a few per cent of the contact time however slow the normal speed.
START_GAP_FRACTION = 0.1
# The engine advances in chunks of one Hertz contact time; an impact whose record has not appeared after
# this many has gone wrong (a damped contact lasts at most a few Hertz times).
MAX_CHUNKS = 100
# The largest overlap must span this many representable positions of the incoming ball's centre: fewer, and
# rounding moves the restitution by per mille to per cents (the 6.35-mm steel ball on the end face: 1e4 of them,
# 0.6987 for 0.7; 450, 0.713); far fewer, and the ball never moves and the engine steps in flight for ever
# (1e-20 m/s: 31 s).
MIN_OVERLAP_POSITIONS = 2e4
# A head-on impact at the vial's peak speed stands for a run's impacts, within speeds that mills reach.
GUARD_SPEEDS = (0.1, 20.0)  # m/s
RESTITUTION_TOLERANCE = 0.01  # relative

# What a lone impact reads: the 'dem' engine's contact law at its contact step (the balls and the vial's wall, the
# contacts' damping, friction and rolling, two balls' own pair, the coatings of contacts) and nothing of a run: it
# sets the rest itself (impact_parameters). A key of any other group, a new one included, is refused without anyone's
# edit.
READ_GROUPS = (Balls, VialWall, ContactDamping, DemContacts, BallPairs, DemStepping)
IMPACT_READS = reads_of(*READ_GROUPS, roles=(CONTACT_COATING,))
READ_TITLES = ", ".join(group.title for group in GROUPS if set(group.keys()) & IMPACT_READS)

# A ball on the end face touches the vial alone, a ball on a ball the other ball alone: each reads its own pair's
# restitution and friction (MODEL.md §14.1).
OTHER_PAIR_KEYS = {
    "wall": (("pair_restitution", "pair_friction"), "two balls' contacts; --target ball reads it"),
    "ball": (("restitution", "friction"), "a ball on the vial; --target ball reads pair_restitution and pair_friction"),
}


def check_keys_read(keys: Iterable[str], target: str) -> None:
    """Raise :class:`ParameterError` naming the first of ``keys`` (set explicitly) that a lone impact on ``target``
    does not read (a target that is none of them is refused by :func:`check_inputs`)."""
    other, applies = OTHER_PAIR_KEYS.get(target, ((), ""))
    for key in keys:
        if key not in IMPACT_READS:
            raise ParameterError(
                f"{key}: a lone impact does not read it: it reads the contact law alone ({READ_TITLES}); "
                f"{GROUP_OF[key].title} applies to runs"
            )
        if key in other:
            raise ParameterError(f"{key}: an impact on a {target} does not read it; it applies to {applies}")


def check_reads(keys: Iterable[str], params: Parameters, target: str) -> None:
    """:func:`check_keys_read`, then the rules by which a run reads a key, on the impact's own run of ``params``: a
    powder coats its contacts, and its restitution replaces the bare contacts' (parameters/groups/powder.py)."""
    chosen = list(keys)
    check_keys_read(chosen, target)
    problem = reader_of(impact_parameters(params, target)).unread_problem(chosen)
    if problem is not None:
        raise ParameterError(problem)


@dataclass(frozen=True)
class ImpactOutcome:
    """What one impact did, in SI units, with the module's signs; the incoming ball's values after it."""

    normal_speed_in: float  # m/s, closing speed along the normal, V cos θ
    tangential_speed_in: float  # m/s, the incoming centre's velocity along t, V sin θ
    normal_restitution: float  # normal separation speed after over the closing speed before
    tangential_velocity_out_m_s: float  # the incoming centre's velocity along t after
    angular_velocity_rad_s: float  # the incoming ball's spin about n × t after
    contact_time_s: float  # resolved to one contact step
    max_overlap_m: float
    max_normal_force_N: float
    dissipated_normal_J: float
    dissipated_tangential_J: float
    dissipated_sliding_J: float
    dissipated_rolling_J: float
    kinetic_energy_in_J: float  # of both balls, translation and rotation
    kinetic_energy_out_J: float
    # What the tangential spring gained by stiffening with the load (engines.dem.model.TOTAL_NAMES): the
    # kinetic energy lost is dissipated_J less this.
    work_stiffening_J: float
    # The key and value of the restitution the contact was configured with: the powder's where it coats the contact.
    configured_restitution: tuple[str, float]

    @property
    def dissipated_J(self) -> float:
        return (
            self.dissipated_normal_J
            + self.dissipated_tangential_J
            + self.dissipated_sliding_J
            + self.dissipated_rolling_J
        )

    def as_dict(self) -> dict[str, float]:
        """The JSON object of ``shakermill impact --json``."""
        return {
            "normal_restitution": self.normal_restitution,
            "tangential_velocity_out_m_s": self.tangential_velocity_out_m_s,
            "angular_velocity_rad_s": self.angular_velocity_rad_s,
            "contact_time_s": self.contact_time_s,
            "max_overlap_m": self.max_overlap_m,
            "max_normal_force_N": self.max_normal_force_N,
            "dissipated_J": self.dissipated_J,
            "dissipated_normal_J": self.dissipated_normal_J,
            "dissipated_tangential_J": self.dissipated_tangential_J,
            "dissipated_sliding_J": self.dissipated_sliding_J,
            "dissipated_rolling_J": self.dissipated_rolling_J,
        }


def check_inputs(speed: float, angle_deg: float, target: str, spin: float, radius: float) -> None:
    """Raise :class:`ParameterError` naming the first input outside its range, by its command-line option."""
    if not 0.0 < speed <= MAX_SPEED:
        raise ParameterError(f"--speed: {speed:g} m/s is out of range; allowed 0 < speed <= {MAX_SPEED:g} m/s")
    if not 0.0 <= angle_deg < MAX_ANGLE:
        raise ParameterError(
            f"--angle: {angle_deg:g}° is out of range; allowed 0 <= angle < {MAX_ANGLE:g}° (0 is head-on)"
        )
    if target not in TARGETS:
        raise ParameterError(f"--target: {target!r} is not allowed; allowed one of {', '.join(map(repr, TARGETS))}")
    if not abs(spin) * radius <= MAX_SPEED:
        raise ParameterError(
            f"--spin: {spin:g} rad/s is out of range; allowed |spin|·ball_radius <= {MAX_SPEED:g} m/s, "
            f"|spin| <= {MAX_SPEED / radius:.4g} rad/s here"
        )


def impact_parameters(params: Parameters, target: str) -> Parameters:
    """``params`` as the engine runs a lone impact: the 'dem' engine, a resting vial without gravity, one ball
    (``wall``) or two identical ones (``ball``, from the scalar keys: per-ball lists are dropped), and a vial
    large enough that nothing but the target is ever touched."""
    radius = params.ball_radius
    return params.replace(
        **{key: () for key in PER_BALL_KEYS},
        ball_materials=(),
        engine="dem",
        n_balls=1 if target == "wall" else 2,
        gravity=False,
        kinematics="fourier",
        motion="x:0:0:0",
        vial_length=max(params.vial_length, 6.0 * radius),
        vial_diameter=max(params.vial_diameter, 4.0 * radius),
    )


def single_impact(
    params: Parameters, speed: float, angle_deg: float = 0.0, target: str = "wall", spin: float = 0.0
) -> ImpactOutcome:
    """One impact at ``speed`` (m/s, relative to the target) and ``angle_deg`` from the normal, the incoming
    ball spinning at ``spin`` (rad/s) about n × t, against the vial's left end face or a ball at rest.

    Materials, restitution, friction, rolling friction, ball radius and contact step come from ``params``
    (:func:`impact_parameters`). Raises :class:`ParameterError` for inputs out of range and when the engine
    stops (an overlap beyond 5 % of R: too fast for the materials, or too coarse a contact step).
    """
    check_inputs(speed, angle_deg, target, spin, params.ball_radius)
    # Imported when first used: the command line reads this module's bounds when it starts.
    import numpy as np

    from shakermill.engines.dem.engine import DemEngine

    engine = DemEngine(impact_parameters(params, target), None, np.zeros(1), 0.0)
    _check_resolved(engine, target, speed, angle_deg)
    contact_time, gap = _hertz_scales(engine, target, speed * math.cos(math.radians(angle_deg)))
    incoming = _launch(engine, target, speed, math.radians(angle_deg), spin, gap)
    kinetic_in = engine.kinetic_energy()
    record = _first_record(engine, contact_time)
    return _outcome(engine, record, incoming, speed, math.radians(angle_deg), kinetic_in)


def restitution_warning(params: Parameters, description: EngineDescription) -> str | None:
    """A warning where the contact step of a run of ``params`` on the engine ``description`` describes misses the
    restitution its contact is configured with (the powder's where it coats it, not the bare ``restitution``) by more
    than :data:`RESTITUTION_TOLERANCE`, measured on one head-on impact of a ball on the end face at the vial's peak
    speed (within :data:`GUARD_SPEEDS`) in the 'dem' engine, whose contact law it is;
    None for an engine whose contacts are not that law (``description.contact_step_guard``), or where the impact is
    within it."""
    if not description.contact_step_guard:
        return None
    low, high = GUARD_SPEEDS
    speed = min(max(params.amplitude * params.omega, low), high)
    try:
        outcome = single_impact(params, speed)
    except ParameterError:
        return None  # too fast for the materials: the run's own status says so
    achieved, (key, configured) = outcome.normal_restitution, outcome.configured_restitution
    error = abs(achieved - configured) / configured
    if error <= RESTITUTION_TOLERANCE:
        return None
    return (
        f"contact_step_fraction = {params.contact_step_fraction:g} resolves a head-on impact at {speed:.3g} m/s with a "
        f"restitution of {achieved:.3f}, {100 * error:.1f} % off the configured {key} = {configured:g}; "
        f"a smaller contact_step_fraction ({_default_step_fraction():g} is the default) keeps it within "
        f"{100 * RESTITUTION_TOLERANCE:g} %"
    )


def _default_step_fraction() -> float:
    from shakermill.parameters.presets import default_parameters

    return default_parameters().contact_step_fraction


def _check_resolved(engine: DemEngine, target: str, speed: float, angle_deg: float) -> None:
    """Raise :class:`ParameterError` where the impact's largest overlap spans fewer than
    :data:`MIN_OVERLAP_POSITIONS` representable positions of the incoming ball's centre, with the least speed."""
    import numpy as np

    from shakermill.physics.contact import hertz_max_overlap

    k = engine.constants
    mass, radius, modulus = _effective(engine, target)
    where = k.half_length if target == "wall" else 0.0
    # Scaled from 1 m/s, as the overlap grows as v^(4/5): computed at 1e-300 m/s it would underflow to 0.
    per_speed = hertz_max_overlap(mass, radius, modulus, 1.0)
    normal_speed = speed * math.cos(math.radians(angle_deg))
    overlap = per_speed * normal_speed**0.8
    resolution = float(np.spacing(where + k.radius[0]))
    if overlap >= MIN_OVERLAP_POSITIONS * resolution:
        return
    least = (MIN_OVERLAP_POSITIONS * resolution / per_speed) ** 1.25
    head_on = "" if angle_deg == 0.0 else f" (the normal speed, speed·cos(angle), is {normal_speed:.3g} m/s)"
    raise ParameterError(
        f"--speed: {speed:.3g} m/s{head_on} is too slow to resolve: its largest overlap, {overlap:.3g} m, spans "
        f"{overlap / resolution:.3g} of the {resolution:.3g}-m steps in which the engine places the ball, fewer than "
        f"the {MIN_OVERLAP_POSITIONS:g} an impact needs; allowed speed·cos(angle) >= {least:.3g} m/s here"
    )


def _effective(engine: DemEngine, target: str) -> tuple[float, float, float]:
    """m* (kg), R* (m) and E* (Pa) of the impact: ball 0 on the left end, or balls 0 and 1."""
    from shakermill.engines.dem.contacts import pair_values
    from shakermill.engines.dem.model import LEFT_END

    k = engine.constants
    if target == "wall":
        return float(k.mass[0]), float(k.wall_radius[0, LEFT_END]), float(k.wall_modulus[0])
    modulus, _, radius, mass, _ = pair_values(0, 1, k)
    return mass, radius, modulus


def _hertz_scales(engine: DemEngine, target: str, normal_speed: float) -> tuple[float, float]:
    """The Hertz contact time (s) and the start gap (m) of an impact at ``normal_speed``."""
    from shakermill.physics.contact import hertz_contact_time, hertz_max_overlap

    mass, radius, modulus = _effective(engine, target)
    overlap = hertz_max_overlap(mass, radius, modulus, normal_speed)
    return hertz_contact_time(mass, radius, modulus, normal_speed), START_GAP_FRACTION * overlap


def _launch(engine: DemEngine, target: str, speed: float, angle: float, spin: float, gap: float) -> int:
    """Place the balls so that the first touch is on the vial's axis with the normal along +x, set the
    incoming ball's velocity and spin; returns the incoming ball's index."""
    k, s = engine.constants, engine.state
    radius = k.radius[0]
    # Aimed so that the contact begins with the centres on the axis: the ball starts that far back along y.
    offset = -gap * math.tan(angle)
    if target == "wall":
        incoming, contact_x = 0, -k.half_length
    else:
        incoming, contact_x = 1, 0.0
        s.position[0] = (-radius, 0.0, 0.0)
    s.position[incoming] = (contact_x + radius + gap, offset, 0.0)
    s.velocity[:] = 0.0
    s.velocity[incoming] = (-speed * math.cos(angle), speed * math.sin(angle), 0.0)
    s.spin[:] = 0.0
    s.spin[incoming, 2] = spin
    return incoming


def _first_record(engine: DemEngine, contact_time: float) -> np.ndarray:
    """Advance ``engine`` a Hertz contact time at a time until its first contact has ended; its record row."""
    from shakermill.engines.status import REACHED_STOP

    for _ in range(MAX_CHUNKS):
        status = engine.advance(engine.t + contact_time)
        if status != REACHED_STOP:
            raise ParameterError(f"impact: the engine stopped: {engine.explain(status)}")
        records = engine.records
        if len(records):
            return records[0]
    raise ParameterError(
        f"impact: no contact ended within {MAX_CHUNKS} Hertz contact times ({MAX_CHUNKS * contact_time:.3g} s)"
    )


def _outcome(
    engine: DemEngine, record: np.ndarray, incoming: int, speed: float, angle: float, kinetic_in: float
) -> ImpactOutcome:
    from shakermill.engines.dem.model import WORK_STIFFENING
    from shakermill.engines.dem.stepper import RECORD_COLUMNS

    column = {name: float(record[index]) for index, name in enumerate(RECORD_COLUMNS)}
    velocity = engine.state.velocity
    normal_in = speed * math.cos(angle)
    # Relative to the target: the vial's end face is at rest, the ball target moves after the impact.
    normal_out = velocity[incoming, 0] - (velocity[1 - incoming, 0] if engine.constants.n_balls == 2 else 0.0)
    return ImpactOutcome(
        normal_speed_in=normal_in,
        tangential_speed_in=speed * math.sin(angle),
        normal_restitution=float(normal_out / normal_in),
        tangential_velocity_out_m_s=float(velocity[incoming, 1]),
        angular_velocity_rad_s=float(engine.state.spin[incoming, 2]),
        contact_time_s=column["duration"],
        max_overlap_m=column["max_overlap"],
        max_normal_force_N=column["peak_force"],
        dissipated_normal_J=column["dissipated_normal"],
        dissipated_tangential_J=column["dissipated_tangential"],
        dissipated_sliding_J=column["dissipated_sliding"],
        dissipated_rolling_J=column["dissipated_rolling"],
        kinetic_energy_in_J=kinetic_in,
        kinetic_energy_out_J=engine.kinetic_energy(),
        work_stiffening_J=float(engine.state.totals[WORK_STIFFENING]),
        configured_restitution=_configured(engine),
    )


def _configured(engine: DemEngine) -> tuple[str, float]:
    """The key and value of the restitution the impact's contact was configured with: a ball on the end face (one
    ball) or on a ball (two)."""
    restitution = engine.network.restitution
    if engine.constants.n_balls == 1:
        return restitution.wall_key, restitution.wall
    return restitution.pair_key, restitution.pair
