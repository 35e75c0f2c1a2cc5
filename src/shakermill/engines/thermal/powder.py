"""The powder of a charge as a node of the thermal network (``powder_mass > 0``): one lumped heat capacity, a layer
on the vessel's inner wall and on the balls, coupled to both through ``powder_contact_coefficient`` and to the gas
as the bare wall is (``h_inner``, ``inner_area``); a share ``powder_heat_share`` of every contact's heat is
deposited in it, the powder caught between the bodies taking part of the deformation and friction as its own, and
the contacts it coats rebound with ``powder_restitution``. Every
value but its heat capacity is an assumption with a stated range (the preset's sources); an extension of the network
(:data:`network.NODE_EXTENSIONS`)."""

from __future__ import annotations

import math

from shakermill.engines.thermal.nodes import (
    BALL,
    CONTACT_KINDS,
    GAS,
    HEAT_CHANNELS,
    VESSEL,
    Deposit,
    NetworkDraft,
    Node,
    Restitution,
)
from shakermill.engines.thermal.paths import newton_cooling
from shakermill.parameters.groups.powder import PowderCoating, PowderHeat
from shakermill.parameters.materials import material

# The role of the node (engines/thermal/nodes.py).
POWDER = "powder"
LAYER_SOURCE = "powder_contact_coefficient (an assumption; see its source) over the surface the layer coats"
LAYER_VALIDITY = (
    "the powder as one layer at one temperature on every surface it coats: the vessel's whole inner wall and every "
    "ball's surface; a powder that cakes on the ends alone, or flies as dust, couples otherwise"
)


def add_node(draft: NetworkDraft) -> None:
    """The powder node, its paths to the vessel, the balls and the gas, and its share of each contact's heat."""
    params = draft.params
    coating, heat = PowderCoating.of(params), PowderHeat.of(params)
    if coating.powder_mass <= 0.0:
        return
    vial, air = draft.one_of_role(VESSEL), draft.one_of_role(GAS)
    keys = ("powder_mass", "powder_heat_capacity", "powder_contact_coefficient")
    capacity = coating.powder_mass * heat.powder_heat_capacity
    melting = material(heat.powder_material).melting_point if heat.powder_material else None
    powder = draft.add(
        Node(
            "powder",
            POWDER,
            capacity,
            "powder",
            keys=keys,
            melting_point=float(melting.value) if melting is not None else None,  # type: ignore[arg-type]
            material=heat.powder_material,
        )
    )
    wall = wall_area(params.vial_diameter, params.vial_length)
    coefficient = heat.powder_contact_coefficient
    draft.paths += [
        newton_cooling("powder → vial", powder, vial, coefficient, wall, LAYER_SOURCE, LAYER_VALIDITY),
        *(
            newton_cooling(
                f"powder → {draft.nodes[ball].name}",
                powder,
                ball,
                coefficient,
                4.0 * math.pi * draft.radii[index] ** 2,
                LAYER_SOURCE,
                LAYER_VALIDITY,
            )
            for index, ball in enumerate(draft.of_role(BALL))
        ),
        newton_cooling(
            "powder → air",
            powder,
            air,
            params.h_inner,
            params.inner_area,
            "h_inner, inner_area: the layer's free surface meets the gas where the bare wall does (vial → air)",
        ),
    ]
    restitution = coating.powder_restitution
    draft.restitution = Restitution(restitution, restitution, "powder_restitution", "powder_restitution")
    share = heat.powder_heat_share
    draft.deposits.append(
        Deposit(
            powder,
            {kind: dict.fromkeys(HEAT_CHANNELS, share) for kind in CONTACT_KINDS},
            "powder_heat_share of every channel of every contact (an assumption; see its source)",
        )
    )


def wall_area(diameter: float, length: float) -> float:
    """The inner wall of a cylindrical vessel (m²): its side and its two ends."""
    return math.pi * diameter * length + 2.0 * math.pi * diameter**2 / 4.0
