"""The balls: their size and the material of their contacts, where one ball on the axis starts, and the balls of
an engine of several (how many, or the fill that makes them, and each ball's own values)."""

from __future__ import annotations

from shakermill.parameters.fields import count, listed, material_name, per_ball, quantity
from shakermill.parameters.geometry import DENSEST_PACKING
from shakermill.parameters.key_group import KeyGroup
from shakermill.parameters.sources import PAPER
from shakermill.support.limits import MAX_BALLS


class Balls(KeyGroup):
    """The balls' radius and the elastic constants and density of their contacts (MODEL.md §§1-2, Table 2); a named
    material fills them (``with_materials``)."""

    title = "the balls"

    # 25 µm: the finest beads of bead mills (50 µm across); 0.1 m: larger than any milling ball (~50 mm).
    ball_radius: float = quantity(
        "m",
        "milling ball radius R (or give ball_diameter, twice it)",
        default=6.35e-3,
        source=f"{PAPER}, Table 1",
        ge=2.5e-5,
        le=0.1,
    )
    # A named material fills in the keys below (with_materials); '' leaves them as they are.
    ball_material: str = material_name(
        "the balls",
        "ball_density, ball_youngs_modulus, ball_poisson_ratio, ball_heat_capacity, ball_conductivity",
        default="",
        source="no material: the keys' own values (the paper's steel)",
    )
    # 500 kg/m³: below every solid milling medium (polyethylene ~950); 25 000: above osmium (22 590), the
    # densest element. A ball of 1e-6 kg/m³ has no heat capacity and made a run take hours.
    ball_density: float = quantity(
        "kg/m^3", "ball density ρ_b", default=7800.0, source=f"{PAPER}, Table 2", ge=500.0, le=25_000.0
    )
    # 0.1 MPa: softer than rubber; such contacts overlap past what the integrator allows and the run stops
    # with its status. 1.2 TPa: diamond, the stiffest solid.
    ball_youngs_modulus: float = quantity(
        "Pa", "ball Young's modulus E_b", default=200e9, source=f"{PAPER}, Table 2", ge=1e5, le=1.2e12
    )
    # Dense solids lie in 0-0.5 (diamond 0.07, steel 0.3, rubber 0.5); -0.5 leaves room for auxetic
    # materials. As ν -> -1 the shear modulus, and the Rayleigh time that bounds contact steps, vanish.
    ball_poisson_ratio: float = quantity(
        "", "ball Poisson ratio ν_b", default=0.3, source=f"{PAPER}, Table 2", ge=-0.5, lt=0.5
    )


class OneBallStart(KeyGroup):
    """Where one ball on the vial's axis starts: its position and momentum."""

    title = "one ball's start"

    # Half the longest vial; the ball must also start inside this vial (consistency.ball_fits_vial).
    ball_position: float = quantity(
        "m",
        "initial ball centre, relative to the vial centre",
        default=0.0,
        source="assumption: ball starts at the vial centre",
        ge=-0.5,
        le=0.5,
    )
    # A 100-g ball at 1000 m/s; faster starts only end in an overlap the integrator refuses.
    ball_momentum: float = quantity(
        "kg*m/s", "initial ball momentum", default=0.0, source="assumption: ball starts at rest", ge=-100.0, le=100.0
    )


class SeveralBalls(KeyGroup):
    """Balls of their own (an engine of several): how many, or the fill that makes them, and each ball's values, in ball
    order; an empty list: every ball takes the scalar key's value."""

    title = "several balls"

    # MAX_BALLS: the contact search (a neighbour list) and the memory grow linearly with the balls.
    n_balls: int = count(
        "number of balls (engine = 'dem', 0: an empty mill; the 1-D engine has one)",
        default=1,
        source=f"{PAPER}: one ball",
        ge=0,
        le=MAX_BALLS,
    )
    fill: float = quantity(
        "",
        "fraction of the vial's inner volume the balls take (engine = 'dem'): > 0 sets n_balls = max(1, "
        "round(fill·V_vial/V_ball)) equal balls; 0: n_balls as given",
        default=0.0,
        source="unused: n_balls gives the number of balls",
        ge=0,
        le=DENSEST_PACKING,
    )
    # Each ball's own radius and material, in ball order; empty: every ball takes the scalar key's value.
    ball_radii: tuple[float, ...] = per_ball("ball_radius")
    ball_densities: tuple[float, ...] = per_ball("ball_density")
    ball_youngs_moduli: tuple[float, ...] = per_ball("ball_youngs_modulus")
    ball_poisson_ratios: tuple[float, ...] = per_ball("ball_poisson_ratio")
    ball_heat_capacities: tuple[float, ...] = per_ball("ball_heat_capacity")
    ball_conductivities: tuple[float, ...] = per_ball("ball_conductivity")
    ball_materials: tuple[str, ...] = listed(
        "",
        "per-ball material (engine = 'dem'): fills the per-ball lists of density, Young's modulus, Poisson ratio, heat "
        "capacity and conductivity unless they are set with it or later",
        default=(),
        source="every ball takes ball_material, or the scalar keys' values",
        most=MAX_BALLS,
        material=True,
    )

    def ball_values(self, scalar_key: str) -> tuple[float, ...]:
        """Each ball's value of ``scalar_key`` (e.g. 'ball_radius'): its per-ball list, or the scalar for all."""
        values = getattr(self, PER_BALL_KEY_OF[scalar_key])
        return tuple(values) if values else (getattr(self, scalar_key),) * self.n_balls


# The per-ball list keys and the scalar key each one refines.
PER_BALL_KEY_OF: dict[str, str] = {
    str(extra["per_ball"]): key
    for key, field in SeveralBalls.model_fields.items()
    if isinstance(extra := field.json_schema_extra, dict) and "per_ball" in extra
}
