"""Constants of the thermal network every engine shares: the air, the vial's exchange with it and with the
surroundings, and their heat capacities (MODEL.md §§4–6). An engine adds its balls' own."""

from __future__ import annotations

from typing import Any

from shakermill.parameters.schema import Parameters
from shakermill.physics import thermal


def network_constants(params: Parameters) -> dict[str, Any]:
    """The shared fields of an engine's ``Constants``, by name."""
    viscosity_ambient = thermal.sutherland_viscosity(
        params.ambient_temperature, params.air_viscosity_ref, params.air_reference_temperature, params.sutherland
    )
    return {
        "relative_convection": params.relative_convection,
        "air_density": params.air_density,
        "viscosity_ambient": viscosity_ambient,
        "prandtl": thermal.prandtl_number(params.air_cp, viscosity_ambient, params.air_conductivity),
        "mu_ref": params.air_viscosity_ref,
        "t_ref": params.air_reference_temperature,
        "sutherland": params.sutherland,
        "air_conductivity": params.air_conductivity,
        "beta": params.beta,
        "h_inner": params.h_inner,
        "h_outer": params.h_outer,
        "inner_area": params.inner_area,
        "outer_area": params.outer_area,
        "capacity_vial": params.vial_mass * params.vial_heat_capacity,
        "capacity_air": params.air_mass * params.air_heat_capacity,
        "t_ambient": params.ambient_temperature,
    }
