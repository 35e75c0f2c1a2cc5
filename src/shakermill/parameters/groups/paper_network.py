"""The paper's thermal network (MODEL.md §§3-6): the share η of a contact's dissipated energy that is heat and the
share λ of it that goes to the ball (read where there is a ball); the ball, vial and air that take it and their start;
the vial's loss to the room that only the 'paper' network reads; the choice of network; and the 'dem' engine's split
of a contact's heat by the bodies' effusivities and its conduction through contacts."""

from __future__ import annotations

from typing import Literal

from shakermill.parameters.fields import choice, quantity
from shakermill.parameters.geometry import end_faces_area
from shakermill.parameters.groups.contacts import WITH_A_BALL
from shakermill.parameters.key_group import KeyGroup, only_with_network
from shakermill.parameters.sources import PAPER


class ContactHeat(KeyGroup):
    """The heat of a contact (MODEL.md §3): the share η of its dissipation that is heat and the share λ of that heat
    that goes to the ball; read where there is a ball to touch."""

    title = "the contacts' heat"
    rule = WITH_A_BALL

    eta: float = quantity(
        "", "fraction η of dissipated power turned into heat", default=0.9, source=f"{PAPER}, Table 4 (η)", ge=0, le=1
    )
    lam: float = quantity(
        "", "fraction λ of the heat that goes to the ball", default=0.368, source=f"{PAPER}, Table 4 (λ)", ge=0, le=1
    )


class PaperNetwork(KeyGroup):
    """The paper's network of ball, vial and air (MODEL.md §§3-6, Tables 2-4): capacities, convection and exchange,
    and the temperatures at the start."""

    title = "the paper's thermal network"

    # The alternatives the spec allows (MODEL.md sections 2-4).
    model: Literal["three_node", "ball_only"] = choice(
        "'three_node': ball, vial and air (this paper); 'ball_only': air held at ambient and no vial "
        "reservoir, the author's 2023 predecessor",
        default="three_node",
        source=f"{PAPER}: ball, vial and inner air as three lumped reservoirs",
    )
    # 50 J/(kg·K): below the heaviest metals (lead, tungsten, gold ~130); 5000: above polymers (~2000)
    # and water (4186).
    ball_heat_capacity: float = quantity(
        "J/(kg*K)", "ball specific heat c_b", default=461.0, source=f"{PAPER}, Table 2", ge=50.0, le=5000.0
    )
    vial_heat_capacity: float = quantity(
        "J/(kg*K)",
        "vial specific heat c_v",
        default=461.0,
        source=f"{PAPER}, Table 2",
        ge=50.0,
        le=5000.0,
        thermal_only=True,
    )
    # 1 g: less steel than one 19-mm end face 0.5 mm thick; 1e-12 kg made the vial's time constant a
    # nanosecond and a run take hours. 100 kg: a heavy vial with its clamp, many times over.
    vial_mass: float = quantity(
        "kg",
        "thermally active vial mass m_v",
        default=0.05,
        source="assumption: not printed in the paper; the steel near the two end faces that exchanges heat with the "
        "inside and outside air. It sets the time constant, not the steady state; calibration fits it",
        ge=1e-3,
        le=100.0,
        thermal_only=True,
    )
    # The air (Table 3); the bounds cover the gases mills are filled with, from a rough vacuum to high pressure.
    # 0.01 kg/m³ (~10 mbar of air): below it the gas is no continuum for Whitaker's correlation and the
    # air node's time constant falls under a millisecond. 200: nitrogen at ~170 bar.
    air_density: float = quantity(
        "kg/m^3", "air density ρ_a", default=1.225, source=f"{PAPER}, Table 3", ge=0.01, le=200.0
    )
    # Gases at 0 °C: hydrogen 8.4e-6 to neon 3e-5 Pa·s, with room either way.
    air_viscosity_ref: float = quantity(
        "Pa*s",
        "air viscosity μ_r at the reference temperature",
        default=1.716e-5,
        source=f"{PAPER}, Table 3 (at 273.15 K)",
        ge=1e-6,
        le=1e-4,
    )
    # The reference of Sutherland's law: 50-2000 K covers every tabulated reference point.
    air_reference_temperature: float = quantity(
        "K",
        "reference temperature θ_r of Sutherland's law",
        default=273.15,
        source=f"{PAPER}, Table 3 footnote (0 °C)",
        ge=50.0,
        le=2000.0,
    )
    # Gases: xenon 0.005 to hydrogen 0.18 W/(m·K).
    air_conductivity: float = quantity(
        "W/(m*K)", "air thermal conductivity k_a", default=0.0241, source=f"{PAPER}, Table 3", ge=1e-3, le=1.0
    )
    # Gases: xenon 158 to hydrogen 14 300 J/(kg·K).
    air_cp: float = quantity(
        "J/(kg*K)",
        "air specific heat at constant pressure c_p,a",
        default=1003.5,
        source=f"{PAPER}, Table 3",
        ge=100.0,
        le=20_000.0,
    )
    # An ideal gas has 1 < γ <= 5/3 (monatomic).
    air_heat_capacity_ratio: float = quantity(
        "",
        "c_p/c_v of air",
        default=1.4,
        source="assumption: diatomic ideal gas; c_a = c_p,a/1.4 (MODEL.md section 6)",
        gt=1,
        le=5 / 3,
    )
    # Sutherland constants of gases: hydrogen 72 K, air 111, carbon dioxide 240; 1000 leaves room.
    sutherland: float = quantity(
        "K", "Sutherland constant S", default=111.0, source=f"{PAPER}, Table 3", ge=0, le=1000.0
    )
    # β scales Whitaker's correlation, defensible within 0.1-3 (calibrate.DEFENSIBLE_RANGES); 100 leaves
    # room for any hand tuning, and β = 1e12 made the ball's time constant a nanosecond.
    beta: float = quantity(
        "",
        "convection calibration factor β",
        default=0.3,
        source=f"{PAPER}, Table 4 (β, tuned by hand by the author)",
        ge=0,
        le=100.0,
        thermal_only=True,
    )
    convection_velocity: Literal["auto", "ball", "relative"] = choice(
        "velocity in Re: the ball's ('ball', as the paper) or relative to the vial, which carries "
        "the air ('relative'); 'auto': 'ball' for the 1-D engine, 'relative' for 'dem' (MODEL.md §12.5)",
        default="auto",
        source=f"{PAPER}, section 3.3 (Re from the ball's velocity) for the 1-D engine; relative to the vial for 'dem' "
        "(MODEL.md section 12.5)",
    )
    # 0 switches the exchange off; 1e4 W/(m²·K) is liquid cooling, far above gas convection (5-250).
    h_inner: float = quantity(
        "W/(m^2*K)",
        "vial-to-inner-air convection coefficient h_i",
        default=200.0,
        source=f"{PAPER}, Table 3",
        ge=0,
        le=1e4,
        thermal_only=True,
    )
    # 10 m²: the whole surface of a vial of 1 m, the largest allowed.
    inner_area: float = quantity(
        "m^2",
        "vial surface exchanging heat with the inner air A_i",
        default=end_faces_area(19e-3),
        source=f"{PAPER}, Table 1 (A_i = 567.06 mm²: the two end faces, MODEL.md §1)",
        gt=0,
        le=10.0,
        thermal_only=True,
    )
    # 50 K: below liquid-nitrogen cryomilling (77 K). 1000 K: a vial in a furnace at 700 °C.
    ambient_temperature: float = quantity(
        "K",
        "temperature of the surroundings θ_amb",
        default=293.15,
        source=f"{PAPER}, Table 3 footnote (ambient 20 °C)",
        ge=50.0,
        le=1000.0,
    )
    initial_temperature: float = quantity(
        "K",
        "initial temperature θ_0 of ball, vial and air",
        default=293.15,
        source=f"assumption: θ̇_0 of {PAPER} Table 5 implies θ_0 = 20 °C",
        ge=50.0,
        le=1000.0,
        thermal_only=True,
    )


class RoomLoss(KeyGroup):
    """The vial's loss to the room through a constant h_outer·outer_area (MODEL.md §5): the 'paper' network's own keys;
    the 'mill-head' network computes that loss from the vial's outside and its speed instead."""

    title = "the paper network's loss to the room"
    rule = only_with_network("paper")

    h_outer: float = quantity(
        "W/(m^2*K)",
        "vial-to-surroundings convection coefficient h_o",
        default=45.0,
        source=f"{PAPER}, Table 3",
        ge=0,
        le=1e4,
        thermal_only=True,
    )
    outer_area: float = quantity(
        "m^2",
        "vial surface exchanging heat with the surroundings A_o",
        default=end_faces_area(19e-3),
        source=f"{PAPER}, Table 1 (A_o = 567.06 mm²: the two end faces only; a real vial also loses heat through its "
        "side, MODEL.md §11)",
        gt=0,
        le=10.0,
        thermal_only=True,
    )


class NetworkChoice(KeyGroup):
    """Which thermal network a run takes (MODEL.md §13), read by an engine that has more than one."""

    title = "the thermal network"

    thermal_model: Literal["paper", "mill-head"] = choice(
        "'paper': ball, vial and air, the vial losing h_outer·outer_area to the room (MODEL.md §5); 'mill-head': the "
        "vial's outer convection and radiation at its own speed, conduction through contacts, a clamp warmed "
        "by the drive (§13)",
        default="paper",
        source=f"{PAPER}, section 2.3: ball, vial and air (MODEL.md section 13)",
        thermal_only=True,
    )


class HeatSplit(KeyGroup):
    """The 'dem' engine's split of a contact's heat between the bodies by their effusivities √(kρc) and its conduction
    through contacts (MODEL.md §12.4): the conductivities and the vial's density."""

    title = "the split of a contact's heat"

    # Only the ratio of two balls' effusivities √(kρc) matters (the split of ball-ball heat, MODEL.md §12.4):
    # from aerogel-like 0.01 to diamond's 2000 W/(m·K).
    ball_conductivity: float = quantity(
        "W/(m*K)",
        "ball thermal conductivity k_b",
        default=46.6,
        source="AISI 52100 bearing steel at room temperature (ASM data sheet); only ratios between balls matter",
        ge=0.01,
        le=2000.0,
    )
    # Gases' 0.005 to diamond's 2000, as the balls'.
    vial_conductivity: float = quantity(
        "W/(m*K)",
        "vial thermal conductivity k_v",
        default=46.6,
        source="as ball_conductivity: hardened steel (AISI 52100, ASM data sheet)",
        ge=0.01,
        le=2000.0,
    )
    vial_density: float = quantity(
        "kg/m^3", "vial density ρ_v", default=7800.0, source=f"{PAPER}, Table 2", ge=500.0, le=25_000.0
    )
