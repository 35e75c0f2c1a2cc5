"""The heat paths of the thermal network, each named, with its correlation, its source and where it holds
(MODEL.md sections 4, 5 and 13.1). A path joins two nodes, or a node and the room; its flow is positive from
its ``hot`` end to its ``cold`` end, and the compiled kernel (``kernel.path_flows``) evaluates it from the
coefficients it carries. A new path model is a constructor here and a branch of the kernel."""

from __future__ import annotations

from dataclasses import dataclass

from shakermill.engines.thermal.kernel import AMONG_BALLS, BALLS, CONSTANT, CONTACT, RADIATION, WHITAKER
from shakermill.physics.heat_paths import STEFAN_BOLTZMANN

# The paper whose Tables 1 and 3 give the constant coefficients of the vessel's paths.
PAPER_PATHS = "Son 2025 (Mathematics 13, 446)"

WHITAKER_CORRELATION = (
    "Q = 4πR²·β·h·(θ_b − θ_a), h = Nu·k_a/(2R), Nu = 2 + (0.4 Re^1/2 + 0.06 Re^2/3)·Pr^0.4·(μ(θ_b)/μ_r)^(−1/4), "
    "Re = 2R·ρ_a·|u|/μ_∞ at the ball's mean velocity term"
)
WHITAKER_SOURCE = (
    "Whitaker, AIChE J. 18 (1972) 361-371, as Son 2025 (Mathematics 13, 446) Eqs. 12-15 print it; β a "
    "calibration factor (Table 4: 0.3)"
)
# Whitaker's own range for flow past a sphere. A milling ball's Re (~10²-10³) lies inside; Pr of air (0.7) at its
# lower edge.
WHITAKER_VALIDITY = "3.5 < Re < 7.6e4, 0.71 < Pr < 380, 1 < μ_∞/μ_s < 3.2 (Whitaker 1972)"
NEWTON_CORRELATION = "Q = h·A·(θ_hot − θ_cold), h constant"


@dataclass(frozen=True)
class HeatPath:
    """One way for heat to flow: its name, its ends (node indices, or ``kernel.ROOM``), its model (``kernel``'s
    WHITAKER or CONSTANT) and coefficients, and what it rests on."""

    name: str
    hot: int
    cold: int
    kind: int
    correlation: str
    source: str
    validity: str
    conductance: float = 0.0  # W/K, CONSTANT; ε·σ·A (W/K⁴), RADIATION
    radius: float = 0.0  # m, WHITAKER: the ball's radius
    drive: int = -1  # WHITAKER, CONTACT: the index of its velocity term or contact conductance in the drives


def ball_convection(name: str, hot: int, cold: int, ball: int, radius: float) -> HeatPath:
    """A ball's convection to the air around it (MODEL.md §4)."""
    return HeatPath(
        name, hot, cold, WHITAKER, WHITAKER_CORRELATION, WHITAKER_SOURCE, WHITAKER_VALIDITY, radius=radius, drive=ball
    )


def newton_cooling(
    name: str,
    hot: int,
    cold: int,
    h: float,
    area: float,
    source: str,
    validity: str = "h and A as given: no dependence on speed or temperature",
) -> HeatPath:
    """Heat through ``area`` (m²) at a constant coefficient ``h`` (W/(m²·K)) (MODEL.md §5)."""
    return HeatPath(name, hot, cold, CONSTANT, NEWTON_CORRELATION, source, validity, conductance=h * area)


def fixed_conductance(name: str, hot: int, cold: int, conductance: float, source: str, validity: str) -> HeatPath:
    """Heat through a fixed conductance (W/K): a joint or a loss known as a whole, not per area."""
    return HeatPath(
        name, hot, cold, CONSTANT, "Q = G·(θ_hot − θ_cold), G constant", source, validity, conductance=conductance
    )


CONTACT_HEAT_PER_KELVIN = (
    "each contact's heat per kelvin: the larger of 0.87·π·a²·√t_c/(1/e₁ + 1/e₂) (an impact) and "
    "4a·t_c/(1/k₁ + 1/k₂) (a lasting contact), a = √(R*·δ_max)"
)
CONTACT_CORRELATION = f"Q = G·(θ_hot − θ_cold), G the mean over the motion of {CONTACT_HEAT_PER_KELVIN}"
CONTACT_SOURCE = (
    "Sun & Chen, Int. J. Heat Mass Transfer 31 (1988) 969 (impacts); Holm's constriction resistance 1/(4ka) of each "
    "half-space (lasting contacts); the contacts' radii and durations from the 'dem' engine's records"
)
CONTACT_VALIDITY = (
    "smooth elastic contacts, no interstitial gas or powder; the impact form for contact Fourier numbers ≪ 1, the "
    "steady one ≫ 1; a lasting contact is counted when it ends"
)


def contact_conduction(name: str, hot: int, cold: int, drive: int) -> HeatPath:
    """Conduction through the contacts of a ball with the vial or another ball, at their measured mean conductance."""
    return HeatPath(name, hot, cold, CONTACT, CONTACT_CORRELATION, CONTACT_SOURCE, CONTACT_VALIDITY, drive=drive)


AMONG_BALLS_CORRELATION = (
    "Q_i = G_i·m/(m − 1)·(θ_i − θ̄), G_i the mean over the motion of the sum of ball i's contacts with any other "
    f"ball, of {CONTACT_HEAT_PER_KELVIN}; "
    "θ̄ the balls' temperatures weighted by G, m the balls: the flows sum to zero; exact for two balls and for balls "
    "that touch each other alike, a mean field otherwise"
)


def among_balls_conduction(name: str, ball: int, drive: int) -> HeatPath:
    """Conduction through the contacts of ``ball`` with the other balls (``kernel.among_balls_mean``): one path per
    ball, however many balls it touches."""
    return HeatPath(
        name, ball, BALLS, AMONG_BALLS, AMONG_BALLS_CORRELATION, CONTACT_SOURCE, CONTACT_VALIDITY, drive=drive
    )


def radiation(name: str, hot: int, cold: int, emissivity: float, area: float) -> HeatPath:
    """A grey surface of ``area`` (m²) radiating to large surroundings: Q = ε·σ·A·(θ_hot⁴ − θ_cold⁴)."""
    return HeatPath(
        name,
        hot,
        cold,
        RADIATION,
        "Q = ε·σ·A·(θ_hot⁴ − θ_cold⁴)",
        "Stefan-Boltzmann law for a small grey body in large isothermal surroundings (Incropera & DeWitt, Eq. 1.7)",
        "ε the key emissivity, the room's walls at the ambient temperature",
        conductance=emissivity * STEFAN_BOLTZMANN * area,
    )
