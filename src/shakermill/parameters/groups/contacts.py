"""A ball's contacts as Hertz contacts with damping (MODEL.md §2): the vial wall's elastic constants, the
restitution the contacts are damped to and whether they may pull, the 'dem' engine's friction and rolling
resistance, and its own restitution and friction of two balls (MODEL.md §§12.3, 14.1)."""

from __future__ import annotations

from shakermill.parameters.fields import material_name, quantity, switch
from shakermill.parameters.key_group import KeyGroup, ReadRule, When
from shakermill.parameters.sources import PAPER


class VialWall(KeyGroup):
    """The vial wall's elastic constants, the other body of a ball's contact on it (a named material fills them)."""

    title = "the vial's wall"

    vial_material: str = material_name(
        "the vial",
        "vial_density, vial_youngs_modulus, vial_poisson_ratio, vial_heat_capacity, vial_conductivity",
        default="",
        source="no material: the keys' own values (the paper's steel)",
    )
    vial_youngs_modulus: float = quantity(
        "Pa", "vial Young's modulus E_v", default=200e9, source=f"{PAPER}, Table 2", ge=1e5, le=1.2e12
    )
    vial_poisson_ratio: float = quantity(
        "", "vial Poisson ratio ν_v", default=0.3, source=f"{PAPER}, Table 2", ge=-0.5, lt=0.5
    )


# With no ball there is no contact: the keys of a contact's law and of its heat are no input of the run.
WITH_A_BALL: ReadRule = When(
    "n_balls",
    lambda balls: balls >= 1,
    "with n_balls = {value} there is no contact; it applies to n_balls >= 1",
)


class ContactDamping(KeyGroup):
    """The restitution a ball's contact on the vial is damped to and whether its force may pull."""

    title = "contact damping"
    rule = WITH_A_BALL

    # A perfectly plastic contact (0) has no damping ratio. Towards 0 the ball chatters on the face and a
    # run takes more steps (20 times at 0.05, 40 at 1e-6), but it stays correct and finishes.
    restitution: float = quantity(
        "",
        "coefficient of restitution e of a ball on the vial (every contact of the 1-D engine)",
        default=0.7,
        source=f"{PAPER}, Table 4 (e)",
        gt=0,
        le=1,
    )
    no_tension: bool = switch(
        "clip the contact force at zero (no adhesion)",
        default=False,
        source="MODEL.md section 2: the total force is not clipped by default",
    )


class DemContacts(KeyGroup):
    """The 'dem' engine's contacts beyond the 1-D law: Coulomb friction and rolling resistance (MODEL.md §12.3)."""

    title = "friction and rolling"
    rule = WITH_A_BALL

    # Coulomb coefficients of dry solids stay below ~1.5; 5 leaves room for rough or adhesive pairs.
    friction: float = quantity(
        "",
        "Coulomb friction coefficient μ of a ball on the vial (engine = 'dem')",
        default=0.3,
        source="assumption: a common choice for dry steel-on-steel contacts in DEM mill studies; not measured for SPEX "
        "media (docs/notes/dem-references.md, section 3), so results should be checked against it",
        ge=0,
        le=5.0,
    )
    rolling_friction: float = quantity(
        "",
        "rolling resistance coefficient μ_r (engine = 'dem')",
        default=0.0,
        source="MODEL.md section 12.3: no rolling resistance by default",
        ge=0,
        le=1.0,
    )


# One ball, or none, touches no other: a pair's own keys are no input of its run.
WITH_TWO_BALLS: ReadRule = When(
    "n_balls",
    lambda balls: balls >= 2,
    "with n_balls = {value} no two balls touch; it applies to n_balls >= 2",
)


class BallPairs(KeyGroup):
    """Two balls' own restitution and friction (ball-ball and ball-wall contacts are different pairs of bodies,
    MODEL.md §14.1): read where there are two balls to touch."""

    title = "ball pairs"
    rule = WITH_TWO_BALLS

    pair_friction: float = quantity(
        "",
        "Coulomb friction coefficient μ of two balls (engine = 'dem')",
        default=0.3,
        source="assumption: the ball-on-vial friction's common choice for steel on steel, no source of its own",
        ge=0,
        le=5.0,
    )
    pair_restitution: float = quantity(
        "",
        "coefficient of restitution e of two balls (engine = 'dem')",
        default=0.7,
        source=f"{PAPER}, Table 4 (e): the paper's one e, for two balls too (no source of its own)",
        gt=0,
        le=1,
    )
