"""Right-hand side of the one-ball model (MODEL.md §§1–6) against hand computations.

Every expected value here is recomputed from the formulas of MODEL.md with plain arithmetic on the
raw parameter fields (never with the functions of shakermill.physics.contact or shakermill.physics.thermal).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shakermill.engines.one_d import model
from shakermill.parameters.keys import Parameters
from shakermill.parameters.presets import default_parameters

# The thermal state used throughout (K)
THETA_B, THETA_V, THETA_A = 320.0, 300.0, 305.0


# --- hand computations from MODEL.md --------------------------------------------------------------


class Hand:
    """Derived constants of MODEL.md §§1–6, written out again from the raw parameter fields."""

    def __init__(self, p: Parameters) -> None:
        self.p = p
        self.R = p.ball_radius
        self.m = p.ball_density * 4.0 / 3.0 * math.pi * self.R**3
        self.e_star = 1.0 / (
            (1.0 - p.ball_poisson_ratio**2) / p.ball_youngs_modulus
            + (1.0 - p.vial_poisson_ratio**2) / p.vial_youngs_modulus
        )
        log_e = math.log(p.restitution)
        self.beta_e = log_e / math.sqrt(log_e**2 + math.pi**2)
        self.mu_inf = self.mu(p.ambient_temperature)
        self.prandtl = p.air_cp * self.mu_inf / p.air_conductivity
        self.area = 2.0 * math.pi * p.vial_diameter**2 / 4.0
        air_mass = p.air_density * (
            math.pi * p.vial_diameter**2 / 4.0 * p.vial_length - 4.0 / 3.0 * math.pi * self.R**3
        )
        self.cap_ball = self.m * p.ball_heat_capacity
        self.cap_vial = p.vial_mass * p.vial_heat_capacity
        self.cap_air = air_mass * p.air_cp / p.air_heat_capacity_ratio

    def mu(self, theta: float) -> float:
        p = self.p
        theta_r = p.air_reference_temperature
        return p.air_viscosity_ref * (theta / theta_r) ** 1.5 * (theta_r + p.sutherland) / (theta + p.sutherland)

    def vial(self, t: float) -> tuple[float, float]:
        p = self.p
        return p.amplitude * math.sin(p.omega * t + p.phase), p.omega * p.amplitude * math.cos(p.omega * t + p.phase)

    def elastic(self, overlap: float) -> float:
        return 4.0 / 3.0 * self.e_star * math.sqrt(self.R) * overlap**1.5

    def damping(self, overlap: float) -> float:
        return -math.sqrt(20.0 / 3.0) * self.beta_e * (self.m**2 * self.R * self.e_star**2 * overlap) ** 0.25

    def potential(self, overlap: float) -> float:
        return 8.0 / 15.0 * self.e_star * math.sqrt(self.R) * overlap**2.5

    def flows(self, speed: float) -> tuple[float, float, float]:
        """(Q̇_ba, Q̇_va, Q̇_vo) in W for the module's thermal state and convection speed |u|."""
        p = self.p
        reynolds = 2.0 * self.R * p.air_density * abs(speed) / self.mu_inf
        nusselt = 2.0 + (0.4 * reynolds**0.5 + 0.06 * reynolds ** (2.0 / 3.0)) * self.prandtl**0.4 * (
            self.mu(THETA_B) / p.air_viscosity_ref
        ) ** (-0.25)
        h = nusselt * p.air_conductivity / (2.0 * self.R)
        q_ba = 4.0 * math.pi * self.R**2 * p.beta * h * (THETA_B - THETA_A)
        q_va = p.h_inner * self.area * (THETA_V - THETA_A)
        q_vo = p.h_outer * self.area * (THETA_V - p.ambient_temperature)
        return q_ba, q_va, q_vo

    def rates(self, speed: float, heat: float) -> tuple[float, float, float]:
        """(θ̇_b, θ̇_v, θ̇_a) of MODEL.md §6 for Q̇_irr = ``heat``."""
        q_ba, q_va, q_vo = self.flows(speed)
        lam = self.p.lam
        return (
            (lam * heat - q_ba) / self.cap_ball,
            ((1.0 - lam) * heat - q_va - q_vo) / self.cap_vial,
            (q_ba + q_va) / self.cap_air,
        )


def _rates(params: Parameters, t: float, y: np.ndarray) -> np.ndarray:
    dydt = np.empty(model.N_STATE)
    model.rhs(t, y, model.constants_from(params), dydt)
    return dydt


def _state(x: float, p: float) -> np.ndarray:
    y = np.zeros(model.N_STATE)
    y[model.X], y[model.P] = x, p
    y[model.THETA_BALL], y[model.THETA_VIAL], y[model.THETA_AIR] = THETA_B, THETA_V, THETA_A
    return y


@pytest.fixture(scope="module")
def params() -> Parameters:
    return default_parameters()


@pytest.fixture(scope="module")
def hand(params: Parameters) -> Hand:
    return Hand(params)


def _right_contact(hand: Hand, t: float, overlap: float, speed: float) -> np.ndarray:
    centre, _ = hand.vial(t)
    return _state(centre + 0.5 * hand.p.vial_length - hand.R + overlap, hand.m * speed)


def _left_contact(hand: Hand, t: float, overlap: float, speed: float) -> np.ndarray:
    centre, _ = hand.vial(t)
    return _state(centre - 0.5 * hand.p.vial_length + hand.R - overlap, hand.m * speed)


# --- constants and initial state ------------------------------------------------------------------


def test_constants_from_default_parameters(params: Parameters, hand: Hand) -> None:
    k = model.constants_from(params)
    assert k.ball_mass == pytest.approx(8.36574e-3, rel=1e-5)  # 7800·4/3·π·(6.35e-3)³
    assert k.e_star == pytest.approx(1.0989011e11, rel=1e-7)  # 200e9/(2·0.91)
    assert k.beta_e == pytest.approx(-0.1128085, rel=1e-6)  # ln 0.7/√(ln² 0.7 + π²)
    assert k.viscosity_ambient == pytest.approx(1.81346e-5, rel=1e-5)  # Sutherland at 293.15 K
    assert k.prandtl == pytest.approx(0.75511, rel=1e-4)  # 1003.5·1.81346e-5/0.0241
    # h·A of Table 3 over Table 1's A_i = A_o = 567.06 mm²
    assert k.inner_conductance == pytest.approx(200.0 * 567.06e-6, rel=1e-4)
    assert k.outer_conductance == pytest.approx(45.0 * 567.06e-6, rel=1e-4)
    assert k.half_length == pytest.approx(0.029, rel=1e-12)
    assert k.capacity_ball == pytest.approx(hand.cap_ball, rel=1e-12)  # 8.36574e-3·461 = 3.85661 J/K
    assert k.capacity_ball == pytest.approx(3.85661, rel=1e-5)
    assert k.capacity_vial == pytest.approx(hand.cap_vial, rel=1e-12)
    # 1.88309e-5 kg · 716.7857 J/(kg·K) = 0.0134978 J/K
    assert k.capacity_air == pytest.approx(0.0134978, rel=1e-4)
    assert k.t_ambient == pytest.approx(293.15, rel=1e-12)
    assert (k.no_tension, k.paper_heat, k.relative_convection) == (False, False, False)


def test_constants_follow_the_options(params: Parameters) -> None:
    k = model.constants_from(params.replace(no_tension=True, heat_model="paper", convection_velocity="relative"))
    assert (k.no_tension, k.paper_heat, k.relative_convection) == (True, True, True)


def test_initial_state(params: Parameters) -> None:
    changed = params.replace(phase=math.pi / 2, ball_position=1e-3, ball_momentum=2e-3, initial_temperature=300.0)
    y = model.initial_state(changed)
    assert y.shape == (model.N_STATE,)
    # x = X_v·sin(π/2) + 1 mm = 26 mm
    assert y[model.X] == pytest.approx(0.026, rel=1e-12)
    assert y[model.P] == pytest.approx(2e-3, rel=1e-12)
    np.testing.assert_array_equal(y[model.THETA_BALL : model.THETA_AIR + 1], [300.0, 300.0, 300.0])
    np.testing.assert_array_equal(y[model.WORK_VIAL :], 0.0)


# --- free flight ----------------------------------------------------------------------------------


def test_free_flight_at_the_vial_centre(params: Parameters, hand: Hand) -> None:
    speed = 2.0
    y = _state(0.0, hand.m * speed)  # vial centre at t = 0 (φ = 0)
    dydt = _rates(params, 0.0, y)
    assert dydt[model.X] == pytest.approx(speed, rel=1e-12)  # p/m
    assert dydt[model.P] == 0.0
    assert dydt[model.WORK_VIAL] == 0.0
    assert dydt[model.DISSIPATED] == 0.0
    assert dydt[model.HEAT_GENERATED] == 0.0
    expected = hand.rates(speed, 0.0)
    assert dydt[model.THETA_BALL] == pytest.approx(expected[0], rel=1e-9)
    assert dydt[model.THETA_VIAL] == pytest.approx(expected[1], rel=1e-9)
    assert dydt[model.THETA_AIR] == pytest.approx(expected[2], rel=1e-9)
    _, _, q_vo = hand.flows(speed)
    # Q̇_vo = 45 · 5.670575e-4 · (300 − 293.15) = 0.02551759 · 6.85 = 0.1747955 W
    assert q_vo == pytest.approx(0.1747955, rel=1e-6)
    assert dydt[model.HEAT_LOST] == pytest.approx(q_vo, rel=1e-12)


def test_free_flight_ball_to_air_hand_numbers(params: Parameters, hand: Hand) -> None:
    """Spot check of the hand chain at u = 2 m/s with literal numbers.

    Re = 2·6.35e-3·1.225·2/1.81346e-5 = 1715.78; 0.4·√Re + 0.06·Re^{2/3} = 16.5688 + 8.59921 = 25.1680;
    Pr^{0.4} = 0.75511^{0.4} = 0.893724;
    μ(320 K) = 1.716e-5 · (320/273.15)^{1.5} · 384.15/431 = 1.716e-5 · 1.268014 · 0.891299 = 1.93939e-5,
    ratio to 1.716e-5 = 1.130180, ^{−1/4} = 0.969870;
    Nu = 2 + 25.1680 · 0.893724 · 0.969870 = 23.8155; h = 23.8155 · 0.0241/0.0127 = 45.1932 W/(m²·K);
    Q̇_ba = 4π·(6.35e-3)²·0.3·45.1932·15 = 5.06707e-4 · 203.369 = 0.103049 W.
    """
    q_ba, q_va, _ = hand.flows(2.0)
    assert q_ba == pytest.approx(0.103049, rel=1e-4)
    # Q̇_va = 200 · 5.670575e-4 · (300 − 305) = −0.5670575 W
    assert q_va == pytest.approx(-0.5670575, rel=1e-6)
    dydt = _rates(params, 0.0, _state(0.0, hand.m * 2.0))
    assert dydt[model.THETA_BALL] * hand.cap_ball == pytest.approx(-0.103049, rel=1e-4)


def test_ball_at_rest_convects_with_nusselt_two(params: Parameters, hand: Hand) -> None:
    # u = 0: Nu = 2, h = k_a/R = 0.0241/6.35e-3 = 3.795276 W/(m²·K)
    # Q̇_ba = 4πR²·0.3·3.795276·15 = 5.06707e-4 · 17.07874 = 8.65394e-3 W
    dydt = _rates(params, 0.0, _state(0.0, 0.0))
    assert dydt[model.THETA_BALL] * hand.cap_ball == pytest.approx(-8.65394e-3, rel=1e-5)


def test_relative_convection_uses_the_velocity_relative_to_the_vial(params: Parameters, hand: Hand) -> None:
    relative = params.replace(convection_velocity="relative")
    speed = 2.0  # vial moves at ω X_v = 2.775 m/s at t = 0, so |ẋ − ẋ_v| = 0.775 m/s
    y = _state(0.0, hand.m * speed)
    dydt = _rates(relative, 0.0, y)
    _, vial_speed = hand.vial(0.0)
    assert vial_speed == pytest.approx(2.775, rel=1e-12)
    expected = hand.rates(speed - vial_speed, 0.0)
    assert dydt[model.THETA_BALL] == pytest.approx(expected[0], rel=1e-9)
    assert dydt[model.THETA_AIR] == pytest.approx(expected[2], rel=1e-9)
    # and differs from the default (ball velocity) choice
    default = _rates(params, 0.0, y)
    assert dydt[model.THETA_BALL] != pytest.approx(default[model.THETA_BALL], rel=1e-3)


def test_relative_convection_with_the_ball_moving_with_the_vial(params: Parameters, hand: Hand) -> None:
    relative = params.replace(convection_velocity="relative")
    y = _state(0.0, hand.m * 2.775)  # co-moving: u = 0, so Nu = 2
    dydt = _rates(relative, 0.0, y)
    assert dydt[model.THETA_BALL] * hand.cap_ball == pytest.approx(-8.65394e-3, rel=1e-5)


def test_free_flight_off_centre_and_later_time(params: Parameters, hand: Hand) -> None:
    t = 0.004
    centre, _ = hand.vial(t)
    y = _state(centre + 0.015, -hand.m * 1.3)  # gap to each face ≥ 22.65 − 15 mm > 0
    dydt = _rates(params, t, y)
    assert dydt[model.X] == pytest.approx(-1.3, rel=1e-12)
    assert dydt[model.P] == 0.0
    assert dydt[model.THETA_BALL] == pytest.approx(hand.rates(1.3, 0.0)[0], rel=1e-9)


# --- contact --------------------------------------------------------------------------------------


@pytest.mark.parametrize("t", [0.0, 0.004])
def test_right_wall_contact(params: Parameters, hand: Hand, t: float) -> None:
    overlap, speed = 2e-6, 5.0
    _, vial_speed = hand.vial(t)
    rate = speed - vial_speed  # right wall: ζ̇ = ẋ − ẋ_v (2.225 m/s at t = 0)
    assert rate > 0.0
    y = _right_contact(hand, t, overlap, speed)
    dydt = _rates(params, t, y)

    elastic, c = hand.elastic(overlap), hand.damping(overlap)
    force = elastic + c * rate
    assert dydt[model.X] == pytest.approx(speed, rel=1e-12)
    assert dydt[model.P] == pytest.approx(-force, rel=1e-6)
    assert dydt[model.DISSIPATED] == pytest.approx(c * rate**2, rel=1e-6)
    assert dydt[model.HEAT_GENERATED] == pytest.approx(params.eta * c * rate**2, rel=1e-6)
    assert dydt[model.WORK_VIAL] == pytest.approx(-force * vial_speed, rel=1e-6)
    heat = params.eta * c * rate**2
    expected = hand.rates(speed, heat)
    assert dydt[model.THETA_BALL] == pytest.approx(expected[0], rel=1e-6)
    assert dydt[model.THETA_VIAL] == pytest.approx(expected[1], rel=1e-6)
    assert dydt[model.THETA_AIR] == pytest.approx(expected[2], rel=1e-6)


def test_right_wall_contact_hand_numbers(params: Parameters, hand: Hand) -> None:
    """Literal numbers at t = 0, ζ = 2 µm, ẋ = 5 m/s (ζ̇ = 5 − 2.775 = 2.225 m/s).

    F_e = 4/3 · 1.0989011e11 · 0.0796869 · (2e-6)^{1.5} = 1.1675734e10 · 2.828427e-9 = 33.02396 N
    c = 78.83537 · 2^{1/4} = 78.83537 · 1.189207 = 93.75154 N·s/m (the 1 µm value of test_contact)
    F = 33.02396 + 93.75154 · 2.225 = 33.02396 + 208.5972 = 241.6212 N
    P_d = 93.75154 · 2.225² = 464.1287 W; Q̇_irr = 0.9 · P_d = 417.7159 W; Ẇ_vial = −241.6212 · 2.775 = −670.4987 W
    """
    dydt = _rates(params, 0.0, _right_contact(hand, 0.0, 2e-6, 5.0))
    assert dydt[model.P] == pytest.approx(-241.6212, rel=1e-5)
    assert dydt[model.DISSIPATED] == pytest.approx(464.1287, rel=1e-5)
    assert dydt[model.HEAT_GENERATED] == pytest.approx(417.7159, rel=1e-5)
    assert dydt[model.WORK_VIAL] == pytest.approx(-670.4987, rel=1e-5)


def test_left_wall_contact(params: Parameters, hand: Hand) -> None:
    overlap, speed, t = 3e-6, -3.0, 0.0
    _, vial_speed = hand.vial(t)
    rate = vial_speed - speed  # left wall: ζ̇ = ẋ_v − ẋ = 2.775 + 3 = 5.775 m/s
    dydt = _rates(params, t, _left_contact(hand, t, overlap, speed))
    elastic, c = hand.elastic(overlap), hand.damping(overlap)
    force = elastic + c * rate
    assert dydt[model.P] == pytest.approx(+force, rel=1e-6)  # n = +1 pushes the ball to the right
    assert dydt[model.DISSIPATED] == pytest.approx(c * rate**2, rel=1e-6)
    assert dydt[model.HEAT_GENERATED] == pytest.approx(params.eta * c * rate**2, rel=1e-6)
    assert dydt[model.WORK_VIAL] == pytest.approx(force * vial_speed, rel=1e-6)


def test_unloading_contact_pulls_without_no_tension(params: Parameters, hand: Hand) -> None:
    # right wall, ζ = 0.1 µm, separating at ζ̇ = −2 m/s: F_e + c ζ̇ < 0 is kept (tension)
    overlap, speed = 1e-7, 2.775 - 2.0
    dydt = _rates(params, 0.0, _right_contact(hand, 0.0, overlap, speed))
    total = hand.elastic(overlap) + hand.damping(overlap) * (-2.0)
    assert total < 0.0
    assert dydt[model.P] == pytest.approx(-total, rel=1e-6)
    assert dydt[model.DISSIPATED] == pytest.approx(hand.damping(overlap) * 4.0, rel=1e-6)


def test_no_tension_clips_the_force_and_dissipates_the_elastic_energy(params: Parameters, hand: Hand) -> None:
    clipped = params.replace(no_tension=True)
    overlap, speed = 1e-7, 2.775 - 2.0
    dydt = _rates(clipped, 0.0, _right_contact(hand, 0.0, overlap, speed))
    assert dydt[model.P] == 0.0
    assert dydt[model.WORK_VIAL] == 0.0
    # applied force 0: P_d = (0 − F_e)·ζ̇ = 2·F_e (the released elastic energy), not c·ζ̇²
    expected = 2.0 * hand.elastic(overlap)
    assert dydt[model.DISSIPATED] == pytest.approx(expected, rel=1e-6)
    assert dydt[model.HEAT_GENERATED] == pytest.approx(clipped.eta * expected, rel=1e-6)


def test_paper_heat_model(params: Parameters, hand: Hand) -> None:
    paper = params.replace(heat_model="paper")
    overlap, speed, t = 2e-6, 5.0, 0.0
    _, vial_speed = hand.vial(t)
    rate = speed - vial_speed
    dydt = _rates(paper, t, _right_contact(hand, t, overlap, speed))
    damping_force = hand.damping(overlap) * rate
    # η·|F_d·v| with the ball's lab-frame velocity v = 5 m/s: 0.9 · 208.5972 · 5 = 938.687 W
    assert dydt[model.HEAT_GENERATED] == pytest.approx(paper.eta * abs(damping_force * speed), rel=1e-6)
    assert dydt[model.HEAT_GENERATED] == pytest.approx(938.687, rel=1e-5)
    # the dissipation bookkeeping is still c·ζ̇²
    assert dydt[model.DISSIPATED] == pytest.approx(hand.damping(overlap) * rate**2, rel=1e-6)
    expected = hand.rates(speed, paper.eta * abs(damping_force * speed))
    assert dydt[model.THETA_BALL] == pytest.approx(expected[0], rel=1e-6)


def test_paper_heat_model_is_non_negative_when_moving_away(params: Parameters, hand: Hand) -> None:
    # ball moving left (v = −1 m/s) while the right wall catches it at 2.775 m/s: F_d·v < 0 in the lab frame
    paper = params.replace(heat_model="paper")
    overlap, speed = 2e-6, -1.0
    dydt = _rates(paper, 0.0, _right_contact(hand, 0.0, overlap, speed))
    rate = speed - 2.775  # −3.775 m/s
    assert dydt[model.HEAT_GENERATED] == pytest.approx(paper.eta * abs(hand.damping(overlap) * rate * speed), rel=1e-6)
    assert dydt[model.HEAT_GENERATED] > 0.0


# --- bookkeeping identities -----------------------------------------------------------------------

CASES = [
    ("flight", dict(), lambda h: (0.0, _state(0.0, h.m * 2.0))),
    ("right", dict(), lambda h: (0.0, _right_contact(h, 0.0, 2e-6, 5.0))),
    ("right_later", dict(), lambda h: (0.004, _right_contact(h, 0.004, 4e-6, 3.0))),
    ("left", dict(), lambda h: (0.0, _left_contact(h, 0.0, 3e-6, -3.0))),
    ("clipped", dict(no_tension=True), lambda h: (0.0, _right_contact(h, 0.0, 1e-7, 0.775))),
    (
        "paper_relative",
        dict(heat_model="paper", convection_velocity="relative"),
        lambda h: (0.0, _right_contact(h, 0.0, 2e-6, 5.0)),
    ),
]


@pytest.mark.parametrize("name, options, make", CASES, ids=[case[0] for case in CASES])
def test_thermal_rates_balance_heat_generated_and_lost(params: Parameters, hand: Hand, name, options, make) -> None:
    changed = params.replace(**options) if options else params
    t, y = make(hand)
    dydt = _rates(changed, t, y)
    stored = (
        hand.cap_ball * dydt[model.THETA_BALL]
        + hand.cap_vial * dydt[model.THETA_VIAL]
        + hand.cap_air * dydt[model.THETA_AIR]
    )
    balance = dydt[model.HEAT_GENERATED] - dydt[model.HEAT_LOST]
    scale = abs(dydt[model.HEAT_GENERATED]) + abs(dydt[model.HEAT_LOST])
    assert stored == pytest.approx(balance, rel=1e-9, abs=1e-12 * scale)


@pytest.mark.parametrize("name, options, make", CASES, ids=[case[0] for case in CASES])
def test_mechanical_energy_rate_is_vial_work_minus_dissipation(
    params: Parameters, hand: Hand, name, options, make
) -> None:
    """d/dt (p²/2m + V(ζ)) along the flow = Ẇ_vial − P_d (MODEL.md §3 energy audit)."""
    changed = params.replace(**options) if options else params
    k = model.constants_from(changed)
    t, y = make(hand)
    dydt = _rates(changed, t, y)
    step = 1e-10
    ahead = model.mechanical_energy(t + step, y + step * dydt, k)
    behind = model.mechanical_energy(t - step, y - step * dydt, k)
    numeric = (ahead - behind) / (2.0 * step)
    expected = dydt[model.WORK_VIAL] - dydt[model.DISSIPATED]
    scale = abs(dydt[model.WORK_VIAL]) + abs(dydt[model.DISSIPATED]) + abs(dydt[model.P] * dydt[model.X])
    assert numeric == pytest.approx(expected, abs=1e-5 * scale + 1e-12)


def test_mechanical_energy_hand_values(params: Parameters, hand: Hand) -> None:
    k = model.constants_from(params)
    # flight: p²/2m = ½ · 8.36574e-3 · 2² = 0.0167315 J
    assert model.mechanical_energy(0.0, _state(0.0, hand.m * 2.0), k) == pytest.approx(0.0167315, rel=1e-5)
    # contact: + 8/15 · E* √R · ζ^{5/2}; ζ = 2e-6: 8/15 · 8.756800e9 · 5.656854e-15 = 2.641917e-5 J
    y = _right_contact(hand, 0.0, 2e-6, 5.0)
    expected = 0.5 * hand.m * 25.0 + 2.641917e-5
    assert model.mechanical_energy(0.0, y, k) == pytest.approx(expected, rel=1e-8)


# --- helpers: wall_contact, gap, rhs_numpy ---------------------------------------------------------


def test_wall_contact_in_flight(params: Parameters, hand: Hand) -> None:
    k = model.constants_from(params)
    wall, overlap, rate, vial_speed = model.wall_contact(0.0, 0.0, 1.0, k)
    assert wall == model.NO_WALL
    assert (overlap, rate) == (0.0, 0.0)
    assert vial_speed == pytest.approx(2.775, rel=1e-12)


def test_wall_contact_identifies_the_wall(params: Parameters, hand: Hand) -> None:
    k = model.constants_from(params)
    y = _right_contact(hand, 0.0, 2e-6, 5.0)
    wall, overlap, rate, _ = model.wall_contact(0.0, y[model.X], 5.0, k)
    assert wall == model.RIGHT_WALL
    assert overlap == pytest.approx(2e-6, rel=1e-6)
    assert rate == pytest.approx(5.0 - 2.775, rel=1e-12)
    y = _left_contact(hand, 0.0, 3e-6, -3.0)
    wall, overlap, rate, _ = model.wall_contact(0.0, y[model.X], -3.0, k)
    assert wall == model.LEFT_WALL
    assert overlap == pytest.approx(3e-6, rel=1e-6)
    assert rate == pytest.approx(2.775 + 3.0, rel=1e-12)


def test_gap(params: Parameters, hand: Hand) -> None:
    k = model.constants_from(params)
    # centred ball at t = 0: l_v/2 − R = 29 − 6.35 = 22.65 mm to each face
    assert model.gap(0.0, 0.0, model.RIGHT_WALL, k) == pytest.approx(0.02265, rel=1e-12)
    assert model.gap(0.0, 0.0, model.LEFT_WALL, k) == pytest.approx(0.02265, rel=1e-12)
    # ball 5 mm right of centre, vial at +X_v (quarter period): right gap 22.65 + 25 − 5 = 42.65 mm
    quarter = math.pi / (2.0 * params.omega)
    assert model.gap(quarter, 0.005, model.RIGHT_WALL, k) == pytest.approx(0.04265, rel=1e-9)
    assert model.gap(quarter, 0.005, model.LEFT_WALL, k) == pytest.approx(0.00265, rel=1e-8)
    # overlap reads as a negative gap
    y = _right_contact(hand, 0.0, 2e-6, 5.0)
    assert model.gap(0.0, y[model.X], model.RIGHT_WALL, k) == pytest.approx(-2e-6, rel=1e-6)


def test_rhs_numpy_matches_the_compiled_rhs(params: Parameters, hand: Hand) -> None:
    k = model.constants_from(params)
    y = _right_contact(hand, 0.004, 4e-6, 3.0)
    expected = np.empty(model.N_STATE)
    model.rhs(0.004, y, k, expected)
    result = model.rhs_numpy(0.004, y, k)
    assert result.shape == (model.N_STATE,)
    np.testing.assert_array_equal(result, expected)
