"""Post-processing fits (MODEL.md §8) on synthetic curves with known parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shakermill.analysis.fit import ExponentialFit, exponential_approach, fit_exponential, increment_ratio

THETA_0 = 293.15  # 20 °C
# The paper's model (Table 5): θ_∞ = 47.89 °C, τ = 16.70 min
THETA_INF = 273.15 + 47.89
TAU = 16.70 * 60.0
T = np.arange(0.0, 3601.0, 1.0)


def _curve(t: np.ndarray, theta_inf: float = THETA_INF, tau: float = TAU) -> np.ndarray:
    """θ(t) = (θ_0 − θ_∞)·e^{−t/τ} + θ_∞, written out again from MODEL.md §8."""
    return (THETA_0 - theta_inf) * np.exp(-t / tau) + theta_inf


def test_exponential_approach_formula() -> None:
    # at t = τ: θ = θ_∞ + (θ_0 − θ_∞)/e = 321.04 − 27.89 · 0.3678794 = 310.779783 K
    value = exponential_approach(np.array([0.0, TAU]), THETA_0, THETA_INF, TAU)
    assert value[0] == pytest.approx(THETA_0, rel=1e-15)
    assert value[1] == pytest.approx(321.04 - 27.89 * 0.36787944, rel=1e-9)


def test_fit_recovers_an_exact_exponential() -> None:
    fit = fit_exponential(T, _curve(T), THETA_0)
    assert fit.success
    assert fit.theta_0 == THETA_0
    assert fit.theta_inf == pytest.approx(THETA_INF, rel=1e-8)
    assert fit.tau == pytest.approx(TAU, rel=1e-6)
    assert fit.rms_residual < 1e-6


def test_fit_recovers_a_cooling_curve() -> None:
    # cooling from 20 °C towards 5 °C with τ = 300 s
    t = np.linspace(0.0, 2000.0, 401)
    fit = fit_exponential(t, _curve(t, theta_inf=278.15, tau=300.0), THETA_0)
    assert fit.success
    assert fit.theta_inf == pytest.approx(278.15, rel=1e-8)
    assert fit.tau == pytest.approx(300.0, rel=1e-6)


def test_fit_with_noise_is_within_tolerance() -> None:
    # σ = 0.05 K on 3601 points: the standard errors are ~0.005 K on θ_∞ and ~1 s on τ,
    # so 0.05 K and 1 % are generous yet would catch a biased or broken fit.
    rng = np.random.default_rng(20250203)
    noisy = _curve(T) + rng.normal(0.0, 0.05, T.size)
    fit = fit_exponential(T, noisy, THETA_0)
    assert fit.success
    assert fit.theta_inf == pytest.approx(THETA_INF, abs=0.05)
    assert fit.tau == pytest.approx(TAU, rel=0.01)
    assert fit.rms_residual == pytest.approx(0.05, rel=0.1)
    # the reported standard errors are consistent with the actual errors
    assert 0.0 < fit.theta_inf_stderr < 0.05
    assert 0.0 < fit.tau_stderr < 0.01 * TAU
    assert abs(fit.theta_inf - THETA_INF) < 5.0 * fit.theta_inf_stderr
    assert abs(fit.tau - TAU) < 5.0 * fit.tau_stderr


def test_fit_ignores_non_finite_samples() -> None:
    theta = _curve(T)
    theta[100] = np.nan
    theta[2000] = np.inf
    fit = fit_exponential(T, theta, THETA_0)
    assert fit.success
    assert fit.tau == pytest.approx(TAU, rel=1e-6)


def test_initial_rate_hand_value() -> None:
    # (47.89 − 20)/16.70 = 27.89/16.70 = 1.670060 °C/min; the paper prints 1.6702 (Table 5)
    fit = ExponentialFit(THETA_0, THETA_INF, TAU, 0.0, 0.0, 0.0, True, "")
    assert fit.initial_rate == pytest.approx(27.89 / 1002.0, rel=1e-12)
    assert fit.initial_rate * 60.0 == pytest.approx(1.670060, rel=1e-6)
    assert fit.initial_rate * 60.0 == pytest.approx(1.6702, rel=1e-3)


def test_initial_rate_of_a_fitted_curve() -> None:
    fit = fit_exponential(T, _curve(T), THETA_0)
    assert fit.initial_rate == pytest.approx((THETA_INF - THETA_0) / TAU, rel=1e-6)
    as_dict = fit.as_dict()
    assert as_dict["initial_rate"] == pytest.approx(fit.initial_rate, rel=1e-15)
    assert as_dict["tau"] == fit.tau


def test_evaluate_reproduces_the_data() -> None:
    fit = fit_exponential(T, _curve(T), THETA_0)
    np.testing.assert_allclose(fit.evaluate(T), _curve(T), rtol=1e-9)


def test_flat_curve_fails_with_nan() -> None:
    fit = fit_exponential(T, np.full(T.size, THETA_0), THETA_0)
    assert fit.success is False
    assert math.isnan(fit.theta_inf)
    assert math.isnan(fit.tau)
    assert math.isnan(fit.initial_rate)
    assert fit.message


def test_too_few_points_fail() -> None:
    fit = fit_exponential(np.array([0.0, 1.0]), np.array([THETA_0, THETA_0 + 1.0]), THETA_0)
    assert fit.success is False
    assert math.isnan(fit.theta_inf)


def test_increment_ratio_hand_values() -> None:
    # five-ball experiment after 1 h (paper §4): vial +21 °C, ball +46 °C -> 21/46 = 0.456522
    assert increment_ratio(THETA_0 + 21.0, THETA_0 + 46.0, THETA_0) == pytest.approx(0.456522, rel=1e-5)
    assert increment_ratio(THETA_0 + 21.0, THETA_0 + 46.0, THETA_0) == pytest.approx(0.46, abs=0.005)
    # vial 300 K, ball 310 K from 290 K: 10/20 = 0.5
    assert increment_ratio(300.0, 310.0, 290.0) == pytest.approx(0.5, rel=1e-12)


def test_increment_ratio_without_ball_rise_is_nan() -> None:
    assert math.isnan(increment_ratio(300.0, THETA_0, THETA_0))
