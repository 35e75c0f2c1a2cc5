"""The air's properties at the ambient temperature that every convection path of the network reads (MODEL.md §4)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from shakermill.physics import thermal

if TYPE_CHECKING:
    from shakermill.parameters.keys import Parameters


def air_constants(params: Parameters) -> dict[str, float]:
    """The air's viscosity at the ambient temperature (Pa·s) and its Prandtl number: Re and Nu of MODEL.md §4."""
    viscosity = thermal.sutherland_viscosity(
        params.ambient_temperature, params.air_viscosity_ref, params.air_reference_temperature, params.sutherland
    )
    return {
        "viscosity_ambient": viscosity,
        "prandtl": thermal.prandtl_number(params.air_cp, viscosity, params.air_conductivity),
    }
