"""The heat paths of the thermal network, each named, with its correlation, its source and where it holds
(MODEL.md sections 4, 5 and 13.1). A path joins two nodes, or a node and the room; its flow is positive from
its ``hot`` end to its ``cold`` end, and the compiled kernel (``kernel.path_flows``) evaluates it from the
coefficients it carries. A new path model is a constructor here and a branch of the kernel."""

from __future__ import annotations

from dataclasses import dataclass

from shakermill.engines.thermal.kernel import CONSTANT, WHITAKER

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
    conductance: float = 0.0  # W/K, CONSTANT
    radius: float = 0.0  # m, WHITAKER: the ball's radius
    ball: int = -1  # WHITAKER: whose velocity term


def ball_convection(name: str, hot: int, cold: int, ball: int, radius: float) -> HeatPath:
    """A ball's convection to the air around it (MODEL.md §4)."""
    return HeatPath(name, hot, cold, WHITAKER, WHITAKER_CORRELATION, WHITAKER_SOURCE, WHITAKER_VALIDITY, radius=radius, ball=ball)


def newton_cooling(name: str, hot: int, cold: int, h: float, area: float, source: str) -> HeatPath:
    """Heat through ``area`` (m²) at a constant coefficient ``h`` (W/(m²·K)) (MODEL.md §5)."""
    validity = "h and A as given: no dependence on speed or temperature"
    return HeatPath(name, hot, cold, CONSTANT, NEWTON_CORRELATION, source, validity, conductance=h * area)
