"""Heat paths of a real mill with published correlations (MODEL.md section 13.1): the vial's outside to the
room (forced convection at the vial's own speed, natural convection, radiation) and conduction through the
contacts of balls. Pure functions, SI units; temperatures in K."""

from __future__ import annotations

import math

from numba import njit

STEFAN_BOLTZMANN = 5.670374419e-8  # W/(m²·K⁴), CODATA 2018
STANDARD_GRAVITY = 9.80665  # m/s²


def flat_plate_nusselt(reynolds: float, prandtl: float) -> float:
    """Mean Nu = 0.664·Re_L^{1/2}·Pr^{1/3} of a plate of length L along a laminar flow (Pohlhausen; Incropera &
    DeWitt, Fundamentals of Heat and Mass Transfer, Eq. 7.30: Re_L < 5·10⁵, Pr ≥ 0.6). The vial's side in the
    flow along its axis."""
    return 0.664 * math.sqrt(reynolds) * prandtl ** (1.0 / 3.0)


def disk_nusselt(reynolds: float, prandtl: float) -> float:
    """Mean Nu = 1.05·Re_D^{1/2}·Pr^{0.36} of a disk facing a uniform flow (Sparrow & Geiger, J. Heat Transfer
    107 (1985) 321; measured for 5·10³ < Re_D < 5·10⁴). The vial's end faces, which meet the flow head on."""
    return 1.05 * math.sqrt(reynolds) * prandtl**0.36


def churchill_bernstein_nusselt(reynolds: float, prandtl: float) -> float:
    """Mean Nu = 0.3 + 0.62·Re_D^{1/2}·Pr^{1/3}/[1 + (0.4/Pr)^{2/3}]^{1/4}·[1 + (Re_D/282000)^{5/8}]^{4/5} of a
    cylinder across a uniform flow (Churchill & Bernstein, J. Heat Transfer 99 (1977) 300; Incropera & DeWitt,
    Eq. 7.54: Re_D·Pr > 0.2). A planetary jar's side, carried round the sun wheel across its axis."""
    correction = (1.0 + (reynolds / 282000.0) ** 0.625) ** 0.8
    return (
        0.3
        + 0.62
        * math.sqrt(reynolds)
        * prandtl ** (1.0 / 3.0)
        / (1.0 + (0.4 / prandtl) ** (2.0 / 3.0)) ** 0.25
        * correction
    )


def churchill_chu_cylinder_nusselt(rayleigh: float, prandtl: float) -> float:
    """Mean Nu = {0.60 + 0.387·Ra_D^{1/6}/[1 + (0.559/Pr)^{9/16}]^{8/27}}² of a long horizontal cylinder in
    natural convection (Churchill & Chu, Int. J. Heat Mass Transfer 18 (1975) 1049; Ra_D < 10¹²)."""
    return (0.60 + 0.387 * rayleigh ** (1.0 / 6.0) / (1.0 + (0.559 / prandtl) ** (9.0 / 16.0)) ** (8.0 / 27.0)) ** 2


def rayleigh_number(
    length: float,
    temperature_difference: float,
    film_temperature: float,
    viscosity: float,
    density: float,
    conductivity: float,
    cp: float,
) -> float:
    """Ra_L = g·β_T·ΔT·L³/(ν·α) of an ideal gas (β_T = 1/θ_film)."""
    kinematic = viscosity / density
    diffusivity = conductivity / (density * cp)
    return STANDARD_GRAVITY * abs(temperature_difference) / film_temperature * length**3 / (kinematic * diffusivity)


def mixed_convection_coefficient(forced: float, natural: float) -> float:
    """h = (h_F³ + h_N³)^{1/3}: Churchill's combination of forced and natural convection (Incropera & DeWitt,
    Eq. 9.64, n = 3 for cylinders and spheres), which leaves the larger one where the other is small."""
    return (forced**3 + natural**3) ** (1.0 / 3.0)


def radiation_coefficient(emissivity: float, surface: float, surroundings: float) -> float:
    """h_r = ε·σ·(θ_s² + θ_∞²)(θ_s + θ_∞) in W/(m²·K): a grey surface seen by large surroundings, so that the
    radiated heat is h_r·A·(θ_s − θ_∞) (Incropera & DeWitt, Eq. 1.9)."""
    return emissivity * STEFAN_BOLTZMANN * (surface**2 + surroundings**2) * (surface + surroundings)


@njit(cache=True)
def hertz_contact_radius(effective_radius: float, overlap: float) -> float:
    """a = √(R*·δ) (m) of a Hertz contact at overlap δ (Johnson, Contact Mechanics, Eq. 4.23)."""
    return math.sqrt(effective_radius * overlap)


@njit(cache=True)
def impact_conduction(contact_radius: float, duration: float, effusivity_1: float, effusivity_2: float) -> float:
    """Heat through one short impact per kelvin between the bodies (J/K): Q/ΔT = 0.87·π·a²·√t_c/(1/e₁ + 1/e₂)
    with each body's effusivity e = √(ρck) (Sun & Chen, Int. J. Heat Mass Transfer 31 (1988) 969, for
    Fourier numbers of the contact well below 1: both bodies semi-infinite for the impact's heat)."""
    return (
        0.87
        * math.pi
        * contact_radius
        * contact_radius
        * math.sqrt(duration)
        / (1.0 / effusivity_1 + 1.0 / effusivity_2)
    )


@njit(cache=True)
def constriction_conductance(contact_radius: float, conductivity_1: float, conductivity_2: float) -> float:
    """G = 4a/(1/k₁ + 1/k₂) (W/K): steady conduction through a circular contact of radius a between two
    half-spaces, each a constriction resistance 1/(4ka) (Holm; Yovanovich; 2ka for equal conductivities)."""
    return 4.0 * contact_radius / (1.0 / conductivity_1 + 1.0 / conductivity_2)


@njit(cache=True)
def contact_conduction(
    contact_radius: float,
    duration: float,
    effusivity_1: float,
    effusivity_2: float,
    conductivity_1: float,
    conductivity_2: float,
) -> float:
    """Heat through one contact per kelvin (J/K): the larger of the impact's transient conduction (Sun & Chen,
    growing as √t_c) and the steady constriction conductance held for the contact's duration (growing as t_c).
    The first holds for impacts (tens of µs), the second for lasting contacts (a ball resting or rolling);
    they cross where the contact's own Fourier number is of order one."""
    transient = impact_conduction(contact_radius, duration, effusivity_1, effusivity_2)
    steady = constriction_conductance(contact_radius, conductivity_1, conductivity_2) * duration
    return max(transient, steady)
