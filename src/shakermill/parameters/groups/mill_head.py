"""The thermal network of a real mill (``thermal_model = 'mill-head'``, MODEL.md §13): the vial's outside, whose
convection and radiation it computes at the vial's own speed, and the holder (a shaker's clamp and mill head, a
planetary mill's jar holder) with its joint, its loss and the drive's heat. Its node is
``engines/thermal/mill_head.py``; the keys keep the names of the clamp they were first written for (``clamp_*``),
which the calibrated presets and their posteriors use."""

from __future__ import annotations

from shakermill.parameters.fields import quantity
from shakermill.parameters.key_group import NETWORK_NODE, KeyGroup, only_with_network


class MillHead(KeyGroup):
    """The vial's outside and the holder of a real mill (MODEL.md §13), read with ``thermal_model = 'mill-head'``; every
    key enters the thermal network alone."""

    title = "the mill head"
    rule = only_with_network("mill-head")
    role = NETWORK_NODE

    # 1 mm to 1 m as the bore; the outside must hold the bore (consistency.outside_holds_the_bore).
    outer_diameter: float = quantity(
        "m",
        "outer diameter of the vial D_o (thermal_model = 'mill-head')",
        default=50e-3,
        source="estimate: walls ~6 mm round a Ø38 mm bore (the SPEX 8001 vial's outside is not published, "
        "docs/notes/dem-references.md §2.3); thermal_model = 'mill-head' only",
        ge=1e-3,
        le=1.0,
        thermal_only=True,
    )
    outer_length: float = quantity(
        "m",
        "outer length of the vial L_o (thermal_model = 'mill-head')",
        default=70e-3,
        source="estimate: ends ~6 mm beyond a 58 mm bore, as outer_diameter; thermal_model = 'mill-head' only",
        ge=1e-3,
        le=1.0,
        thermal_only=True,
    )
    # Polished metal ~0.05, oxidised steel ~0.8, black paint ~0.95.
    emissivity: float = quantity(
        "",
        "emissivity ε of the vial's outside (thermal_model = 'mill-head')",
        default=0.2,
        source="assumption: machined, lightly oxidised steel, 0.1-0.3 (Incropera & DeWitt, Table A.11: stainless steel "
        "0.17-0.30, polished 0.07-0.1); thermal_model = 'mill-head' only",
        ge=0,
        le=1,
        thermal_only=True,
    )
    # Up to ~50 kg of steel in a clamp and mill head; 0 is refused: the node needs a heat capacity. The joint and the
    # loss up to a soldered joint over 10 cm² (0 decouples); the drive's heat up to a mill's whole motor (~0.1-1 kW).
    clamp_heat_capacity: float = quantity(
        "J/K",
        "heat capacity C_k of the clamp and mill head ('mill-head')",
        default=2000.0,
        source="assumption: ~4 kg of steel in the clamp, its arm and the mill head (not published); a free parameter "
        "of calibrations with thermal_model = 'mill-head'",
        gt=0,
        le=1e5,
        thermal_only=True,
    )
    clamp_conductance: float = quantity(
        "W/K",
        "vial-to-clamp contact conductance G_vk ('mill-head')",
        default=10.0,
        source="order of magnitude: steel-on-steel contact conductance 10³-10⁴ W/(m²·K) under clamping pressure "
        "(Madhusudana, Thermal Contact Conductance, 1996) over ~10⁻³ m² at each clamped end",
        ge=0,
        le=1e3,
        thermal_only=True,
    )
    clamp_loss: float = quantity(
        "W/K",
        "clamp-to-room conductance G_k (thermal_model = 'mill-head')",
        default=3.0,
        source="assumption: ~0.1 m² of clamp and head at ~25 W/(m²·K) of forced convection, plus conduction into the "
        "frame (not measured)",
        ge=0,
        le=1e3,
        thermal_only=True,
    )
    drive_heat: float = quantity(
        "W",
        "heat Q_m the drive puts into the clamp whatever the balls do ('mill-head')",
        default=0.0,
        source="none unless measured or fitted (thermal_model = 'mill-head')",
        ge=0,
        le=1e3,
        thermal_only=True,
    )
