"""Table 5 comparison: what is fitted and what is predicted is stated, and the numbers are this model's."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from shakermill.solvers import simulate as simulate_module
from shakermill.solvers.result import INTERRUPTED
from shakermill.studies.measured import (
    CURVE_QUANTITIES,
    CURVE_TOLERANCE_K,
    TABLE5,
    Curve,
    fitted_quantities,
    relative_error,
)
from shakermill.studies.validation.table5 import compare, validate


def test_table5_holds_the_published_numbers(paper: dict) -> None:
    by_key = {entry.key: entry for entry in TABLE5}
    assert set(by_key) == set(paper["table5"]["paper_model"])
    for key, value in paper["table5"]["paper_model"].items():
        assert by_key[key].paper_model == value, key
    for key, value in paper["table5"]["experiment"].items():
        assert by_key[key].experiment == value, key
    # The ratio's experiment is the five-ball one, and the row says so.
    assert by_key["vial_ball_ratio"].experiment == paper["five_balls"]["experiment"]["vial_ball_ratio"]
    assert "five balls" in by_key["vial_ball_ratio"].experiment_note


def test_compare_marks_fitted_and_predicted_rows(default_run_20s) -> None:
    summary = default_run_20s.summary.updated(theta_inf_C=50.0, tau_min=16.7, rate0_C_per_min=1.8, vial_ball_ratio=0.5)
    rows = compare(summary, fitted_keys=("theta_inf_C",))
    assert [row.role for row in rows] == ["fitted", "predicted", "predicted", "predicted"]
    assert rows[0].error_vs_experiment == pytest.approx(relative_error(50.0, 48.0)) == pytest.approx(2.0 / 48.0)


@pytest.mark.slow
def test_validation_of_published_and_calibrated_presets() -> None:
    published, calibrated = validate(solver="averaged")
    assert all(row.role == "predicted" for row in published.rows)
    assert "nothing fitted" in published.statement
    # With the paper's β the model overshoots the measured θ∞ by far: that must show, not be hidden.
    assert published.rows[0].value > 60.0
    assert published.curve_rms_K > 10.0
    fitted = {row.quantity.key: row for row in calibrated.rows if row.fitted}
    # Fitted through the experiment's curve, which is nothing but these three numbers.
    assert set(fitted) == set(CURVE_QUANTITIES)
    assert calibrated.fitted_to_curve and calibrated.curve_rms_K <= CURVE_TOLERANCE_K
    for row in fitted.values():
        assert abs(row.error_vs_experiment) < 0.1
    ratio = next(row for row in calibrated.rows if row.quantity.key == "vial_ball_ratio")
    assert ratio.role == "predicted"
    assert "vial_ball_ratio, ball_steady_C predicted" in calibrated.statement
    assert "fitted to the experiment's curve" in calibrated.statement


def test_fitted_quantities_of_a_curve_fit_are_the_exponentials_numbers() -> None:
    assert fitted_quantities({"curve": "x"}) == CURVE_QUANTITIES
    assert fitted_quantities({"targets": {"tau_min": 16.7}}) == ("tau_min",)
    assert fitted_quantities({"targets": {"tau_min": 16.7}, "curve": "x"}) == (
        "tau_min",
        "theta_inf_C",
        "rate0_C_per_min",
    )
    assert fitted_quantities({}) == ()


def test_curve_residuals_interpolate_the_model_at_the_curve_times() -> None:
    curve = Curve(np.array([0.0, 60.0]), np.array([20.0, 22.0]))
    times = np.array([0.0, 30.0, 120.0])
    theta_K = np.array([293.15, 294.15, 298.65])  # 295.65 K = 22.5 °C at 60 s
    np.testing.assert_allclose(curve.residuals_K(times, theta_K), [0.0, 0.5])
    assert curve.rms_K(times, theta_K) == pytest.approx(np.sqrt(0.125))


def test_a_run_of_table5_cut_short_by_ctrl_c_stops_the_validation(monkeypatch):
    # An interrupted run returns what it computed: Table 5 must not take it for the hour.
    monkeypatch.setattr(simulate_module, "simulate", lambda params, **_: SimpleNamespace(status=INTERRUPTED))
    with pytest.raises(KeyboardInterrupt):
        validate(solver="averaged")
