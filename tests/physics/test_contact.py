"""Ball–wall contact law (MODEL.md §2, §3, §7) against hand-computed values.

Default ball (MODEL.md §9): R = 6.35 mm, steel ρ = 7800 kg/m³, E = 200 GPa, ν = 0.3, e = 0.7.
Hand values used below (worked out with plain arithmetic, shown in the comments):

* E*  = 1/(2·(1 − 0.3²)/200e9) = 200e9/1.82 = 1.0989011e11 Pa
* m_b = 7800·4/3·π·(6.35e-3)³ = 7800·1.0725e-6 = 8.36574e-3 kg
* √R  = √6.35e-3 = 0.0796869
"""

from __future__ import annotations

import math

import pytest
from scipy.integrate import solve_ivp

from shakermill.physics import contact

RADIUS = 6.35e-3
DENSITY = 7800.0
YOUNG = 200e9
POISSON = 0.3
E_STAR = 1.0989011e11  # hand: 200e9 / (2·0.91)
MASS = 8.365740e-3  # hand: 7800·4/3·π·R³
RESTITUTION = 0.7


def _beta_e(e: float) -> float:
    """β_e = ln e/√(ln² e + π²), written out again from MODEL.md §2."""
    return math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi**2)


def _c_hand(overlap: float, e: float = RESTITUTION) -> float:
    """c(ζ) = −√(20/3)·β_e·(m²·R·E*²·ζ)^{1/4}, MODEL.md §2, with the module-level hand constants."""
    return -math.sqrt(20.0 / 3.0) * _beta_e(e) * (MASS**2 * RADIUS * E_STAR**2 * overlap) ** 0.25


# --- effective modulus ----------------------------------------------------------------------------


def test_effective_modulus_steel_on_steel() -> None:
    # 1/E* = 2·0.91/200e9 = 9.1e-12 Pa⁻¹ -> E* = 1.0989011e11 Pa
    value = contact.effective_modulus(YOUNG, POISSON, YOUNG, POISSON)
    assert value == pytest.approx(1.0989011e11, rel=1e-7)


def test_effective_modulus_dissimilar_materials() -> None:
    # steel ball on aluminium (70 GPa, ν = 0.33): 0.91/200e9 + 0.8911/70e9 = 4.55e-12 + 1.273e-11 = 1.728e-11
    value = contact.effective_modulus(200e9, 0.3, 70e9, 0.33)
    assert value == pytest.approx(1.0 / 1.728e-11, rel=1e-9)
    # the formula is symmetric in ball and wall
    assert contact.effective_modulus(70e9, 0.33, 200e9, 0.3) == pytest.approx(value, rel=1e-14)


# --- overlaps -------------------------------------------------------------------------------------


def test_overlap_left_positive_when_ball_crosses_the_left_face() -> None:
    # x_L = −29 mm, ball centre 3 µm closer than R: ζ_L = R − (x − x_L) = 3e-6 m
    x_left = -0.029
    x = x_left + RADIUS - 3e-6
    assert contact.overlap_left(x, x_left, RADIUS) == pytest.approx(3e-6, rel=1e-6)


def test_overlap_left_is_zero_when_apart() -> None:
    assert contact.overlap_left(0.0, -0.029, RADIUS) == 0.0
    # just touching
    assert contact.overlap_left(-0.029 + RADIUS + 1e-9, -0.029, RADIUS) == 0.0


def test_overlap_right_positive_when_ball_crosses_the_right_face() -> None:
    x_right = 0.029
    x = x_right - RADIUS + 5e-6
    assert contact.overlap_right(x, x_right, RADIUS) == pytest.approx(5e-6, rel=1e-6)


def test_overlap_right_is_zero_when_apart() -> None:
    assert contact.overlap_right(0.0, 0.029, RADIUS) == 0.0
    assert contact.overlap_right(0.029 - RADIUS - 1e-9, 0.029, RADIUS) == 0.0


def test_a_ball_at_the_left_face_has_no_right_overlap() -> None:
    x_left, x_right = -0.029, 0.029
    x = x_left + RADIUS - 2e-6
    assert contact.overlap_left(x, x_left, RADIUS) > 0.0
    assert contact.overlap_right(x, x_right, RADIUS) == 0.0


# --- Hertz spring ---------------------------------------------------------------------------------


def test_hertz_force_hand_value() -> None:
    # F_e = 4/3 · 1.0989011e11 · 0.0796869 · (1e-6)^{3/2} = 4/3 · 8.75681e9 · 1e-9 = 11.6757 N
    assert contact.hertz_force(1e-6, E_STAR, RADIUS) == pytest.approx(11.6757, rel=1e-4)


def test_hertz_force_scales_with_overlap_to_the_three_halves() -> None:
    small = contact.hertz_force(1e-7, E_STAR, RADIUS)
    large = contact.hertz_force(4e-7, E_STAR, RADIUS)
    assert large / small == pytest.approx(8.0, rel=1e-12)  # 4^{3/2} = 8


def test_hertz_force_zero_at_zero_overlap() -> None:
    assert contact.hertz_force(0.0, E_STAR, RADIUS) == 0.0


def test_elastic_energy_hand_value() -> None:
    # V = 8/15 · E* · √R · ζ^{5/2}; ζ = 1e-6 -> 8/15 · 8.75681e9 · 1e-15 = 4.67030e-6 J
    assert contact.elastic_energy(1e-6, E_STAR, RADIUS) == pytest.approx(4.67030e-6, rel=1e-4)


@pytest.mark.parametrize("overlap", [1e-7, 2e-6, 3e-5])
def test_elastic_energy_derivative_is_the_hertz_force(overlap: float) -> None:
    h = overlap * 1e-5
    numeric = (
        contact.elastic_energy(overlap + h, E_STAR, RADIUS) - contact.elastic_energy(overlap - h, E_STAR, RADIUS)
    ) / (2.0 * h)
    assert numeric == pytest.approx(contact.hertz_force(overlap, E_STAR, RADIUS), rel=1e-7)
    # and against the hand formula
    assert numeric == pytest.approx(4.0 / 3.0 * E_STAR * math.sqrt(RADIUS) * overlap**1.5, rel=1e-7)


# --- damping --------------------------------------------------------------------------------------


def test_damping_ratio_hand_value_for_e_07() -> None:
    # ln 0.7 = −0.3566749; ln² + π² = 0.1272170 + 9.8696044 = 9.9968214; √ = 3.1617750
    # β_e = −0.3566749 / 3.1617750 = −0.1128085
    assert contact.damping_ratio(0.7) == pytest.approx(-0.1128085, rel=1e-6)


def test_damping_ratio_is_zero_for_elastic_and_negative_below_one() -> None:
    assert contact.damping_ratio(1.0) == 0.0
    for e in (0.05, 0.3, 0.7, 0.99):
        assert contact.damping_ratio(e) < 0.0
        assert contact.damping_ratio(e) == pytest.approx(_beta_e(e), rel=1e-12)


def test_damping_coefficient_hand_value() -> None:
    # m²·R·E*²·ζ = (8.36574e-3)² · 6.35e-3 · (1.0989011e11)² · 1e-6 = 5.36657e9 ; ^{1/4} = 270.660
    # c = −√(20/3)·(−0.1128085)·270.660 = 2.581989 · 0.1128085 · 270.660 = 78.835 N·s/m
    beta_e = -0.1128085
    assert contact.damping_coefficient(1e-6, MASS, RADIUS, E_STAR, beta_e) == pytest.approx(78.835, rel=1e-4)
    assert contact.damping_coefficient(1e-6, MASS, RADIUS, E_STAR, beta_e) == pytest.approx(_c_hand(1e-6), rel=1e-6)


@pytest.mark.parametrize("e", [0.1, 0.5, 0.7, 0.95])
@pytest.mark.parametrize("overlap", [1e-8, 1e-6, 5e-5])
def test_damping_coefficient_is_non_negative_below_unit_restitution(e: float, overlap: float) -> None:
    c = contact.damping_coefficient(overlap, MASS, RADIUS, E_STAR, contact.damping_ratio(e))
    assert c > 0.0
    assert c == pytest.approx(_c_hand(overlap, e), rel=1e-6)


def test_damping_coefficient_vanishes_for_elastic_impacts() -> None:
    c = contact.damping_coefficient(1e-6, MASS, RADIUS, E_STAR, contact.damping_ratio(1.0))
    assert c == 0.0


def test_damping_coefficient_scales_with_overlap_to_the_quarter() -> None:
    beta_e = _beta_e(0.7)
    ratio = contact.damping_coefficient(16e-7, MASS, RADIUS, E_STAR, beta_e) / contact.damping_coefficient(
        1e-7, MASS, RADIUS, E_STAR, beta_e
    )
    assert ratio == pytest.approx(2.0, rel=1e-12)  # 16^{1/4} = 2


# --- total force and dissipation ------------------------------------------------------------------


def test_contact_force_is_elastic_plus_damping() -> None:
    # 11.6757 + 78.835 · 0.5 = 51.0932 N
    assert contact.contact_force(11.6757, 78.835, 0.5, False) == pytest.approx(51.0932, rel=1e-6)


def test_contact_force_is_not_clipped_by_default() -> None:
    # separating fast: 11.6757 + 78.835·(−1) = −67.159 N (tension) is kept
    assert contact.contact_force(11.6757, 78.835, -1.0, False) == pytest.approx(-67.1593, rel=1e-6)


def test_contact_force_no_tension_clips_at_zero() -> None:
    assert contact.contact_force(11.6757, 78.835, -1.0, True) == 0.0
    # a compressive force is not changed by the option
    assert contact.contact_force(11.6757, 78.835, -0.1, True) == pytest.approx(11.6757 - 7.8835, rel=1e-9)


@pytest.mark.parametrize("rate", [2.0, 0.3, -0.05, -1.0])
def test_dissipated_power_is_c_times_rate_squared_when_unclipped(rate: float) -> None:
    overlap = 1e-6
    elastic = contact.hertz_force(overlap, E_STAR, RADIUS)
    c = _c_hand(overlap)
    force = contact.contact_force(elastic, c, rate, False)
    power = contact.dissipated_power(force, elastic, rate)
    assert power == pytest.approx(c * rate * rate, rel=1e-9)
    assert power >= 0.0


def test_dissipated_power_uses_the_clipped_force() -> None:
    elastic = 11.6757  # F_e at 1 µm (hand value above)
    c = 78.835
    rate = -1.0  # F_e + c·ζ̇ = −67.16 N < 0: clipped to 0
    force = contact.contact_force(elastic, c, rate, True)
    assert force == 0.0
    power = contact.dissipated_power(force, elastic, rate)
    # applied force 0: the non-elastic part is −F_e, its power on ζ̇ is −F_e·ζ̇ = 11.6757 W (not c·ζ̇² = 78.8 W)
    assert power == pytest.approx(11.6757, rel=1e-9)
    assert power != pytest.approx(c * rate * rate, rel=1e-3)


# --- time scales ----------------------------------------------------------------------------------


def test_rayleigh_time_hand_value() -> None:
    # G = 200e9/(2·1.3) = 7.6923e10 Pa; √(ρ/G) = √(7800/7.6923e10) = √1.01400e-7 = 3.18434e-4 s/m
    # πR = 0.0199491 m; 0.1631·0.3 + 0.8766 = 0.92553
    # t_R = 0.0199491/0.92553 · 3.18434e-4 = 0.0215542 · 3.18434e-4 = 6.8636e-6 s
    t_r = contact.rayleigh_time(RADIUS, DENSITY, YOUNG, POISSON)
    assert t_r == pytest.approx(6.8636e-6, rel=1e-4)


def test_rayleigh_time_is_close_to_the_papers_quoted_value() -> None:
    # MODEL.md §7: ≈ 6.9 µs here, the paper quotes 6.745 µs: 6.8636/6.745 − 1 = 1.8 %
    t_r = contact.rayleigh_time(RADIUS, DENSITY, YOUNG, POISSON)
    assert t_r == pytest.approx(6.745e-6, rel=0.03)


def test_hertz_max_overlap_hand_value() -> None:
    # ζ_max = (15·m·v²/(16·E*·√R))^{2/5}, v = 2 m/s:
    # 15 · 8.36574e-3 · 4 = 0.501944 ; 16 · 1.0989011e11 · 0.0796869 = 1.40111e11 ; ratio 3.58248e-12
    # ^{0.4} = 2.64044e-5 m
    assert contact.hertz_max_overlap(MASS, RADIUS, E_STAR, 2.0) == pytest.approx(2.64044e-5, rel=1e-4)


@pytest.mark.parametrize("speed", [0.1, 2.0, 7.0])
def test_hertz_max_overlap_stores_all_kinetic_energy(speed: float) -> None:
    overlap = contact.hertz_max_overlap(MASS, RADIUS, E_STAR, speed)
    stored = 8.0 / 15.0 * E_STAR * math.sqrt(RADIUS) * overlap**2.5
    assert stored == pytest.approx(0.5 * MASS * speed**2, rel=1e-10)


def test_hertz_contact_time_factor() -> None:
    # t_c = 2 ζ_max/v · ∫₀¹ dx/√(1 − x^{5/2}) = 2 Γ(7/5) √π / Γ(9/10) · ζ_max/v = 2.943275 · ζ_max/v
    factor = 2.0 * math.gamma(1.4) * math.sqrt(math.pi) / math.gamma(0.9)
    assert factor == pytest.approx(2.943275, rel=1e-6)
    speed = 2.0
    expected = factor * 2.64044e-5 / speed  # = 3.8858e-5 s
    assert contact.hertz_contact_time(MASS, RADIUS, E_STAR, speed) == pytest.approx(expected, rel=1e-4)


def _single_impact(speed: float, restitution: float) -> tuple[float, float]:
    """Integrate one ball–wall impact with the module's force law; return (rebound/impact speed, duration)."""
    beta_e = contact.damping_ratio(restitution)

    def rhs(_t, y):
        overlap, rate = y
        overlap = max(overlap, 0.0)
        elastic = contact.hertz_force(overlap, E_STAR, RADIUS)
        c = contact.damping_coefficient(overlap, MASS, RADIUS, E_STAR, beta_e)
        return [rate, -contact.contact_force(elastic, c, rate, False) / MASS]

    def separation(_t, y):
        return y[0]

    separation.terminal = True
    separation.direction = -1
    t_end = 5.0 * 2.943 * contact.hertz_max_overlap(MASS, RADIUS, E_STAR, speed) / speed
    solution = solve_ivp(
        rhs, (0.0, t_end), [0.0, speed], method="DOP853", events=separation, rtol=1e-10, atol=[1e-16, 1e-12]
    )
    assert solution.t_events[0].size == 1
    return -solution.y_events[0][0][1] / speed, solution.t_events[0][0]


@pytest.mark.parametrize("restitution", [0.3, 0.7, 0.95])
@pytest.mark.parametrize("speed", [0.5, 3.0, 10.0])
def test_one_impact_restitution_equals_input_at_every_speed(restitution: float, speed: float) -> None:
    """MODEL.md §2: with the unclipped force the restitution of one impact equals e, at any speed."""
    ratio, _ = _single_impact(speed, restitution)
    assert ratio == pytest.approx(restitution, rel=1e-6)


@pytest.mark.parametrize("speed", [0.5, 5.0])
def test_elastic_impact_lasts_the_hertz_contact_time(speed: float) -> None:
    ratio, duration = _single_impact(speed, 1.0)
    assert ratio == pytest.approx(1.0, rel=1e-7)
    assert duration == pytest.approx(contact.hertz_contact_time(MASS, RADIUS, E_STAR, speed), rel=1e-4)


# Tangential contact of the dem engine (MODEL.md §12.3), against hand-computed values.


def test_effective_shear_modulus_of_two_steels() -> None:
    # 1/G* = 2·2·(2−0.3)(1+0.3)/200e9 = 8.84/200e9 → G* = 22.624 GPa
    assert contact.effective_shear_modulus(200e9, 0.3, 200e9, 0.3) == pytest.approx(200e9 / 8.84, rel=1e-12)


def test_concave_radius_of_a_ball_in_a_bore() -> None:
    # R = 6.35 mm in a bore of radius 19 mm: 6.35·19/12.65 = 9.5375 mm (the side is flatter than the ball)
    assert contact.concave_radius(6.35e-3, 19e-3) == pytest.approx(9.537549407e-3, rel=1e-9)


def test_mindlin_stiffness_and_damping_hand_values() -> None:
    # k_t = 8·G*·√(R*ζ) = 8·22.624e9·√(6.35e-3·1e-5) = 8·22.624e9·2.51992e-4 = 4.5609e7 N/m
    stiffness = contact.tangential_stiffness(22.624e9, 6.35e-3, 1e-5)
    assert stiffness == pytest.approx(8 * 22.624e9 * 2.519920634e-4, rel=1e-9)
    beta = contact.damping_ratio(0.7)
    # c_t = −2√(5/6)·β_e·√(k_t m*) ≥ 0 for e < 1, and zero for e = 1
    assert contact.tangential_damping(beta, stiffness, 8.366e-3) == pytest.approx(
        -2 * math.sqrt(5 / 6) * beta * math.sqrt(stiffness * 8.366e-3), rel=1e-12
    )
    assert contact.tangential_damping(beta, stiffness, 8.366e-3) > 0.0
    assert contact.tangential_damping(contact.damping_ratio(1.0), stiffness, 8.366e-3) == 0.0
