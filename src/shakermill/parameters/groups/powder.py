"""The powder of a charge (MODEL.md §13.5), with ``powder_mass > 0``: what its layer does to the contacts it coats,
and its node in the thermal network (``engines/thermal/powder.py``): its heat capacity, its share of each contact's
heat and its layer's coupling to the vial and the balls. Every value but its heat capacity is an assumption with a
stated range (``[assumed]`` tables of the presets)."""

from __future__ import annotations

from typing import Any

from shakermill.parameters.fields import material_name, quantity
from shakermill.parameters.key_group import CONTACT_COATING, NETWORK_NODE, KeyGroup, ReadRule, When

# Without powder (its mass 0) the network has no powder node and the contacts are bare.
WITH_POWDER: ReadRule = When(
    "powder_mass",
    lambda mass: float(mass) > 0.0,
    "a run without powder (powder_mass = 0) does not read it; it applies to powder_mass > 0",
)


class PowderCoating(KeyGroup):
    """How much powder there is, and the restitution of the contacts its layer coats, on the vial and between balls:
    with powder they replace the bare contacts' restitution."""

    title = "the powder's coating"
    rule = WITH_POWDER
    role = CONTACT_COATING
    supersedes = frozenset({"restitution", "pair_restitution"})
    superseded_because = "the powder coats every contact (powder_mass > 0): powder_restitution applies instead"

    # Up to 1 kg, far beyond a planetary bowl's charge; 0 leaves the network without a powder node.
    powder_mass: float = quantity(
        "kg",
        "mass m_p of powder in the vial (engine = 'dem'); 0: none",
        default=0.0,
        source="none: the paper's runs are of balls alone; set it for a charge with powder",
        ge=0,
        le=1.0,
    )
    powder_restitution: float = quantity(
        "",
        "coefficient of restitution of powder-coated contacts, on the vial and between balls",
        default=0.5,
        source="assumption, range 0.2-0.8: a powder layer makes impacts less elastic than bare steel's 0.7 (no "
        "measured value for coated milling media found)",
        gt=0,
        le=1,
    )


class PowderHeat(KeyGroup):
    """The powder's node: its heat capacity (from its material), its share φ of each contact's heat and the coefficient
    h_p of its layer to the vial and the balls."""

    title = "the powder's heat"
    rule = WITH_POWDER
    role = NETWORK_NODE

    powder_material: str = material_name(
        "the powder",
        "powder_heat_capacity",
        default="iron",
        source="assumption: iron, a common powder of mechanical alloying; set the charge's",
    )
    powder_heat_capacity: float = quantity(
        "J/(kg*K)",
        "powder specific heat c_p (powder_mass > 0)",
        default=449.0,
        source="material iron (CRC Handbook; recalled, not re-read)",
        ge=50,
        le=5000,
        thermal_only=True,
    )
    powder_heat_share: float = quantity(
        "",
        "share φ of each contact's heat deposited in the powder between the bodies (powder_mass > 0)",
        default=0.5,
        source="assumption, range 0.2-0.8: powder caught between colliding bodies takes part of the impact's "
        "deformation and friction as its own (Suryanarayana, Prog. Mater. Sci. 46 (2001) 1, §5: the powder is "
        "trapped, deformed and heated at each collision; recalled); no measured share found",
        ge=0,
        le=1,
    )
    # The coefficient spans a loose layer millimetres thick (2k/ℓ with k ~0.05 W/(m·K)) to a thin, compacted one; 0
    # decouples the layer.
    powder_contact_coefficient: float = quantity(
        "W/(m^2*K)",
        "h_p through the powder layer to the vial's wall and the balls it coats",
        default=300.0,
        source="assumption, range 50-2000: 2k/ℓ of a powder layer ℓ ≈ 0.3 mm thick with a bed conductivity k ≈ 0.05 "
        "W/(m·K) (loose metal powder in air, Zehner-Schlünder order of magnitude; recalled)",
        ge=0,
        le=1e5,
        thermal_only=True,
    )

    @classmethod
    def check_across(cls, params: Any) -> None:
        """The powder's solid volume (its mass over its material's density: the least it can take, packed to no voids)
        and the balls' fit the vial together."""
        if params.powder_mass <= 0.0 or not params.powder_material:
            return
        from shakermill.parameters.geometry import ball_volume
        from shakermill.parameters.materials import material

        density = float(material(params.powder_material).density.value)  # type: ignore[arg-type]
        balls = sum(ball_volume(radius) for radius in params.ball_values("ball_radius"))
        room = params.vial_volume - balls
        powder = params.powder_mass / density
        if powder > room:
            raise ValueError(
                f"powder_mass: {params.powder_mass * 1e3:g} g of {params.powder_material} ({density:g} kg/m^3) is "
                f"{powder * 1e6:.4g} ml of solid, more than the {room * 1e6:.4g} ml the balls leave of the "
                f"{params.vial_volume * 1e6:.4g}-ml vial; allowed powder_mass "
                f"<= {max(room, 0.0) * density * 1e3:.4g} g here"
            )
