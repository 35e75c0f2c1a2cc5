"""The thermal network of a real mill (MODEL.md §13, ``thermal_model = 'mill-head'``): the vessel's outside by
convection at its own speed and by radiation, conduction through the contacts, and the holder, a node warmed by the
drive; an extension of the network (:data:`network.NODE_EXTENSIONS`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.air import air_constants
from shakermill.engines.thermal.nodes import BALL, VESSEL, NetworkDraft, Node
from shakermill.engines.thermal.paths import (
    among_balls_conduction,
    contact_conduction,
    fixed_conductance,
    newton_cooling,
    radiation,
)
from shakermill.parameters.groups.mill_head import MillHead
from shakermill.parameters.keys import Parameters
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS, motion_terms
from shakermill.parameters.motions import MOTION_COORDINATES
from shakermill.physics import heat_paths, thermal

# The role of the node it adds (engines/thermal/nodes.py): what holds the vessel.
HOLDER = "holder"


def add_node(draft: NetworkDraft) -> None:
    """Under ``thermal_model = 'mill-head'``, the paths of a real mill beyond the paper's (MODEL.md §13.1): the
    vessel's outside to the room by convection at its own speed and by radiation, conduction through the contacts of
    each ball with the vessel and with the other balls, and the holder (a shaker's clamp and mill head, a planetary
    mill's jar holder) joined to the vessel and losing heat to the room, warmed by the drive whatever the balls do."""
    params = draft.params
    if params.thermal_model != "mill-head":
        return
    head = MillHead.of(params)
    vial, balls = draft.one_of_role(VESSEL), draft.of_role(BALL)
    names, n = [draft.nodes[ball].name for ball in balls], len(balls)
    title = "jar holder" if KINEMATIC_MODELS[params.kinematics].axis_upright else "clamp and mill head"
    holder = draft.add(Node("holder", HOLDER, head.clamp_heat_capacity, title), fixed_heat=head.drive_heat)
    outer = vial_outer_convection(params)
    draft.paths += [
        newton_cooling(
            "vial → room, convection", vial, kernel.ROOM, outer.coefficient, outer.area, outer.source, outer.validity
        ),
        radiation("vial → room, radiation", vial, kernel.ROOM, head.emissivity, outer.area),
        *(
            contact_conduction(f"{names[i]} → vial, contacts", i, vial, kernel.contact_drive(i, -1, n))
            for i in range(n)
        ),
        *(
            among_balls_conduction(f"{names[i]} → other balls, contacts", i, kernel.contact_drive(i, i, n))
            for i in range(n)
            if n > 1
        ),
        fixed_conductance(
            "vial → holder",
            vial,
            holder,
            head.clamp_conductance,
            "clamp_conductance (see its source)",
            "a steady joint: the vial's and the holder's own conduction are fast beside it",
        ),
        fixed_conductance(
            "holder → room",
            holder,
            kernel.ROOM,
            head.clamp_loss,
            "clamp_loss (see its source)",
            f"the {title} lumped at one temperature",
        ),
    ]


@dataclass(frozen=True)
class OuterConvection:
    """The vial's outside to the room: the mean coefficient over its faces (W/(m²·K)), their area (m²), the speed it
    is taken at (m/s) and what it rests on."""

    coefficient: float
    area: float
    speed: float
    source: str
    validity: str


# Natural convection depends on the vial's rise itself (as ΔT^1/4): it is taken at a rise typical of a milling
# hour. Beside forced convection at metres per second it changes the outer coefficient by under 1 %.
NATURAL_CONVECTION_RISE_K = 20.0


def vial_outer_convection(params: Parameters) -> OuterConvection:
    """Convection from the vial's outside (a cylinder of ``outer_diameter`` × ``outer_length``) at the rms speed of
    its motion, each face combined with natural convection (Churchill's rule); air properties at the ambient
    temperature. A shaken vial meets the air along its axis (:func:`_along_the_axis`), a planetary jar across it
    (:func:`_across_the_axis`)."""
    constants = air_constants(params)
    viscosity, prandtl = constants["viscosity_ambient"], constants["prandtl"]
    speed = vial_rms_speed(params)
    head = MillHead.of(params)
    diameter, length, k_air = head.outer_diameter, head.outer_length, params.air_conductivity
    side_area, end_area = math.pi * diameter * length, 2.0 * math.pi * diameter**2 / 4.0
    rayleigh = heat_paths.rayleigh_number(
        diameter,
        NATURAL_CONVECTION_RISE_K,
        params.ambient_temperature + NATURAL_CONVECTION_RISE_K / 2,
        viscosity,
        params.air_density,
        k_air,
        params.air_cp,
    )
    natural = heat_paths.churchill_chu_cylinder_nusselt(rayleigh, prandtl) * k_air / diameter
    faces = _across_the_axis if KINEMATIC_MODELS[params.kinematics].axis_upright else _along_the_axis
    h_side, h_end, correlations, validity = faces(params, speed, viscosity, prandtl)
    area = side_area + end_area
    return OuterConvection(
        coefficient=(
            heat_paths.mixed_convection_coefficient(h_side, natural) * side_area
            + heat_paths.mixed_convection_coefficient(h_end, natural) * end_area
        )
        / area,
        area=area,
        speed=speed,
        source=(
            f"{correlations}; each with natural convection (Churchill & Chu 1975, horizontal cylinder, at a "
            f"{NATURAL_CONVECTION_RISE_K:g} K rise) by Churchill's rule; at the vial's rms speed {speed:.3g} m/s"
        ),
        validity=validity,
    )


def _reynolds(length: float, params: Parameters, speed: float, viscosity: float) -> float:
    return thermal.reynolds_number(length, params.air_density, speed, viscosity)


def _along_the_axis(
    params: Parameters, speed: float, viscosity: float, prandtl: float
) -> tuple[float, float, str, str]:
    """The forced coefficients (W/(m²·K)) of a vial shaken along its axis: the side a plate along the flow, each end
    a disk facing it; what they rest on and where they hold."""
    head = MillHead.of(params)
    diameter, length, k_air = head.outer_diameter, head.outer_length, params.air_conductivity
    side = heat_paths.flat_plate_nusselt(_reynolds(length / 2, params, speed, viscosity), prandtl) * k_air / length
    end = heat_paths.disk_nusselt(_reynolds(diameter / 2, params, speed, viscosity), prandtl) * k_air / diameter
    return (
        side,
        end,
        (
            "side: laminar flat plate, Nu = 0.664 Re_L^1/2 Pr^1/3 (Incropera & DeWitt Eq. 7.30); ends: disk facing the "
            "flow, Nu = 1.05 Re_D^1/2 Pr^0.36 (Sparrow & Geiger 1985, recalled, not re-read)"
        ),
        (
            "quasi-steady flow: the vial's stroke is ~3 diameters (Keulegan-Carpenter number ~3), so steady "
            "correlations at the rms speed are a ±30 % estimate; Re_L < 5e5 (laminar), the disk measured for "
            "5e3 < Re_D < 5e4"
        ),
    )


def _across_the_axis(
    params: Parameters, speed: float, viscosity: float, prandtl: float
) -> tuple[float, float, str, str]:
    """The forced coefficients (W/(m²·K)) of a jar carried across its axis: the side a cylinder in cross flow, each
    end a plate along the flow, as long as the jar is wide; what they rest on and where they hold."""
    diameter, k_air = MillHead.of(params).outer_diameter, params.air_conductivity
    reynolds = _reynolds(diameter, params, speed, viscosity)
    side = heat_paths.churchill_bernstein_nusselt(reynolds, prandtl) * k_air / diameter
    end = heat_paths.flat_plate_nusselt(reynolds, prandtl) * k_air / diameter
    return (
        side,
        end,
        (
            "side: cylinder in cross flow, Churchill & Bernstein 1977 (Incropera & DeWitt Eq. 7.54); ends: laminar "
            "flat "
            "plate along the flow, Nu = 0.664 Re_D^1/2 Pr^1/3 (Eq. 7.30)"
        ),
        (
            "the jar's speed round the sun wheel taken as the air's speed past it: the air inside a mill's housing "
            "turns "
            "with the wheel and the jar's own spin adds (1 + k)·ω·D_o/2 at its surface, so this is a ±50 % estimate; "
            "Re_D·Pr > 0.2"
        ),
    )


def vial_rms_speed(params: Parameters) -> float:
    """The rms speed (m/s) of the vial's centre over a drive cycle, from the Fourier terms of its motion."""
    amplitudes: dict[tuple[str, int], np.ndarray] = {}
    for coordinate, k, cosine, sine in motion_terms(params.kinematics, params):
        if coordinate in MOTION_COORDINATES[:3]:
            amplitudes[(coordinate, k)] = amplitudes.get((coordinate, k), np.zeros(2)) + (cosine, sine)
    mean_square = sum(0.5 * (k * params.omega) ** 2 * float(np.sum(pair**2)) for (_, k), pair in amplitudes.items())
    return math.sqrt(mean_square)
