"""Calibration against targets and curves, and the shipped calibrated preset (paper Table 5)."""

from __future__ import annotations

import numpy as np
import pytest

import shakermill as sm
from shakermill.parameters.config import load_config
from shakermill.parameters.defaults import DEM_DEFAULT_FREE
from shakermill.parameters.engine_keys import reader_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import PRESETS
from shakermill.studies.calibration.calibrate import (
    DEFAULT_FREE,
    DEFENSIBLE_RANGES,
    calibrate,
    default_free,
    free_set_study,
    log_bounds,
    parse_free,
    parse_targets,
    unstarted_defaults,
)
from shakermill.studies.calibration.fitted_preset import write_preset
from shakermill.studies.calibration.identifiability import (
    check_determinable,
    informative_points,
    loosely_determined,
    undetermined_keys,
)
from shakermill.studies.measured import CURVE_TOLERANCE_K, TABLE5, Curve, curve_from_option, experiment_curve

TABLE5_TARGETS = {entry.key: entry.experiment for entry in TABLE5 if entry.key != "vial_ball_ratio"}


@pytest.mark.slow
def test_recovers_known_parameters_from_a_noisy_simulated_curve() -> None:
    truth = {"beta": 0.6, "vial_mass": 0.1}
    generator = sm.default_parameters(solver="averaged", output_interval=30.0, **truth)
    series = sm.simulate(generator).timeseries
    rng = np.random.default_rng(2026)
    measured = series["theta_ball"].values - 273.15 + rng.normal(0.0, 0.05, series["time"].size)
    curve = Curve(series["time"].values, measured, "simulated with noise", sigma_K=0.05)
    start = sm.default_parameters(beta=0.3, vial_mass=0.05)
    fit = calibrate(start, ("beta", "vial_mass"), curve=curve)
    assert fit.success, fit.message
    for key, value in truth.items():
        assert fit.fitted[key] == pytest.approx(value, rel=0.01)
        assert 0 < fit.parameter_stderr[key] < 0.01 * value
    assert fit.curve_rms_K == pytest.approx(0.05, rel=0.2)


@pytest.mark.slow
def test_table5_calibration_meets_the_targets_and_round_trips_as_a_preset(tmp_path) -> None:
    fit = calibrate(sm.default_parameters(), ("beta", "vial_mass"), TABLE5_TARGETS)
    assert fit.success, fit.message
    for key, residual in fit.relative_residuals.items():
        assert abs(residual) < 1e-3, key
    assert set(fit.sensitivities) == set(TABLE5_TARGETS)
    path = write_preset(fit, tmp_path / "mine.toml", base_preset="spex8000m", command="test", description="test fit")
    params = load_config(path).params
    assert params.beta == fit.fitted["beta"] and params.vial_mass == fit.fitted["vial_mass"]
    assert params.restitution == sm.default_parameters().restitution


@pytest.mark.slow
def test_shipped_calibrated_preset_follows_the_experiments_curve_at_full_resolution() -> None:
    preset = PRESETS["spex8000m-calibrated"]
    assert preset.fitted == DEFAULT_FREE
    assert preset.provenance["curve"] == experiment_curve().source
    params = sm.default_parameters("spex8000m-calibrated", record_windows=())
    result = sm.simulate(params)
    assert result.solver == "full"
    series = result.timeseries
    assert experiment_curve().rms_K(series["time"].values, series["theta_ball"].values) <= CURVE_TOLERANCE_K
    for key in preset.fitted:
        assert DEFENSIBLE_RANGES[key].contains(getattr(params, key)), key


def test_experiment_curve_is_the_papers_exponential() -> None:
    curve = experiment_curve()
    assert curve.times[0] == 0.0 and curve.times[-1] == 3600.0 and curve.times.size == 61
    assert curve.temperature_C[0] == pytest.approx(20.0)
    # θ̇_0 = 28 K / 16.7 min, Table 5's 1.6766 °C/min.
    assert (curve.temperature_C[1] - curve.temperature_C[0]) == pytest.approx(1.6766 * np.exp(-0.5 / 16.7), rel=1e-3)
    assert curve.temperature_C[-1] == pytest.approx(48.0 - 28.0 * np.exp(-60.0 / 16.7))


@pytest.mark.slow
def test_calibration_without_targets_fits_the_experiments_curve_and_reports_predictions() -> None:
    fit = calibrate(sm.default_parameters(record_windows=()), ("beta", "vial_mass", "h_outer", "lam"))
    assert fit.curve_source == experiment_curve().source
    assert fit.curve_rms_K <= CURVE_TOLERANCE_K and fit.success, fit.message
    assert set(fit.predictions) >= {"vial_ball_ratio", "ball_steady_C", "slowest_time_constant_min"}
    assert all(np.isfinite(fit.parameter_stderr[key]) and fit.parameter_stderr[key] > 0 for key in fit.free)
    assert set(fit.sensitivities) == {"ball_C at 30 min", "ball_C at 60 min"}
    # A parameter that ends on the edge of its defensible range is said, not hidden.
    for key in fit.at_bounds:
        assert "on its edge" in fit.defensible[key]
        assert key in fit.message


@pytest.mark.slow
def test_free_sets_that_cannot_follow_the_curve_say_why() -> None:
    (paper_knobs,) = free_set_study(sm.default_parameters(record_windows=()), [("beta", "vial_mass")])
    assert not paper_knobs.follows_curve
    assert paper_knobs.calibration.curve_rms_K > CURVE_TOLERANCE_K
    # With the paper's end-face area the vial's time constant is hours: the ball still rises at 60 min.
    assert paper_knobs.calibration.predictions["slowest_time_constant_min"] > 60.0
    assert "still rising at the hour" in paper_knobs.verdict


@pytest.mark.slow
def test_unreachable_targets_are_reported_not_hidden() -> None:
    # vial_mass sets time constants, not temperatures: it cannot bring θ∞ down to 25 °C.
    fit = calibrate(sm.default_parameters(), ("vial_mass",), {"theta_inf_C": 25.0})
    assert not fit.success
    assert abs(fit.relative_residuals["theta_inf_C"]) > 0.1
    assert "cannot be met" in fit.message and "theta_inf_C is off by" in fit.message


@pytest.mark.parametrize(
    "items, fragment",
    [(["theta_inf=48"], "unknown target"), (["tau_min"], "NAME=VALUE"), (["tau_min=abc"], "needs a number")],
)
def test_bad_targets_get_one_clear_line(items, fragment) -> None:
    with pytest.raises(ParameterError, match=fragment):
        parse_targets(items)


def test_free_keys_are_checked() -> None:
    assert parse_free([]) == DEFAULT_FREE
    assert parse_free(["eta, vial_mass"]) == ("eta", "vial_mass")
    with pytest.raises(ParameterError, match="did you mean 'beta'"):
        parse_free(["bta"])
    with pytest.raises(ParameterError, match="not a numeric parameter"):
        parse_free(["heat_model"])


def test_curve_csv_is_read_in_minutes_or_seconds(tmp_path) -> None:
    path = tmp_path / "curve.csv"
    path.write_text("time_min,ball_C\n0,20\n1,21.5\n")
    curve = Curve.from_csv(path)
    np.testing.assert_allclose(curve.times, [0.0, 60.0])
    np.testing.assert_allclose(curve.temperature_C, [20.0, 21.5])
    (tmp_path / "bad.csv").write_text("t,T\n0,20\n")
    with pytest.raises(ParameterError, match="needs columns"):
        Curve.from_csv(tmp_path / "bad.csv")


# --- targets and curves that cannot be fitted (issue 12) -----------------------------------------


@pytest.mark.parametrize(
    ("item", "fragment"),
    [
        ("theta_inf_C=nan", "target: theta_inf_C = nan is not allowed; allowed (0, 1400] °C"),
        ("theta_inf_C=inf", "target: theta_inf_C = inf is not allowed"),
        ("theta_inf_C=0", "target: theta_inf_C = 0 is not allowed; allowed (0, 1400] °C"),
        ("tau_min=-5", "target: tau_min = -5 is not allowed; allowed (0, 10000] min"),
        ("rate0_C_per_min=1e308", "allowed (0, 1000] °C/min"),
        ("vial_ball_ratio=0", "target: vial_ball_ratio = 0 is not allowed; allowed (0, 10]"),
        ("tau_min=" + "1" * 10_000, "target: tau_min needs a number, got '1111"),
    ],
)
def test_targets_must_be_finite_and_inside_their_range(item, fragment) -> None:
    with pytest.raises(ParameterError) as info:
        parse_targets([item])
    assert fragment in str(info.value) and len(str(info.value)) < 200


def test_calibrate_checks_its_targets_before_any_run() -> None:
    with pytest.raises(ParameterError, match="theta_inf_C = nan is not allowed"):
        calibrate(sm.default_parameters(), ("beta",), {"theta_inf_C": float("nan")})
    with pytest.raises(ParameterError, match="unknown target 'theta'"):
        calibrate(sm.default_parameters(), ("beta",), {"theta": 48.0})


@pytest.mark.parametrize(
    ("times", "temperatures", "fragment"),
    [
        (
            [0, 600, 1200],
            [20, float("nan"), 40],
            "point 2 has ball_C = nan °C; allowed a finite temperature above -273.15 °C",
        ),
        ([0, 600, float("inf")], [20, 30, 40], "point 3 is at inf s; allowed times in [0, 1e+06] s"),
        ([0, 600, 1e308], [20, 30, 40], "point 3 is at 1e+308 s"),
        ([-60, 600], [20, 30], "point 1 is at -60 s"),
        (
            [0, 600, 300],
            [20, 30, 35],
            "point 3 at 300 s does not come after the one before (600 s); times must increase",
        ),
        ([0, 600, 600], [20, 30, 31], "point 3 at 600 s does not come after"),
        ([0, 600], [20, -300], "point 2 has ball_C = -300"),
        ([], [], "0 times and 0 temperatures; allowed 1 to 100,000 of each"),
        ([0, 600], [20], "2 times and 1 temperatures"),
    ],
)
def test_a_curve_is_checked_when_it_is_made(times, temperatures, fragment) -> None:
    with pytest.raises(ParameterError) as info:
        Curve(np.array(times, dtype=float), np.array(temperatures, dtype=float), "lab")
    assert str(info.value).startswith("curve lab: ") and fragment in str(info.value)


def test_a_curve_file_with_a_byte_order_mark_is_read(tmp_path) -> None:
    path = tmp_path / "curve.csv"
    path.write_text("time_s,ball_C\n0,20\n600,30\n", encoding="utf-8-sig")
    np.testing.assert_allclose(Curve.from_csv(path).times, [0.0, 600.0])


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        ("time_s,ball_C\n0,20\n# gemessen bei 20 °C\n".encode("latin-1"), "not UTF-8 text"),
        ("time_s,ball_C\n0,20\n".encode("utf-16"), "not UTF-8 text"),
        (b"time_s,ball_C\n0," + b"2" * 150 + b"\n", "line 2: a cell of 150 characters; allowed at most 100"),
        (b'time_s,ball_C\n0,"' + b"2" * 140_000 + b'"\n', "malformed CSV at line 2"),
        (b"time_s,ball_C\n0,20\n600\n", "line 3: 1 cell for the 2 columns of its header (time_s, ball_C)"),
        (b"time_s,ball_C\n0,20\n600,x\n", "line 3: needs a number in time_s and in ball_C"),
        (b"time_s,ball_C\n", "has no data rows"),
    ],
)
def test_a_curve_file_that_cannot_be_read_is_one_line_naming_it(tmp_path, content, fragment) -> None:
    path = tmp_path / "curve.csv"
    path.write_bytes(content)
    with pytest.raises(ParameterError) as info:
        Curve.from_csv(path)
    message = str(info.value)
    assert message.startswith(f"curve {path}") and fragment in message


@pytest.mark.parametrize(("key", "low", "high"), [("ball_density", 500.0, 25_000.0), ("vial_mass", 0.02, 1.0)])
def test_fit_bounds_stay_inside_the_hard_bounds(key, low, high) -> None:
    # ball_density has no defensible range: a factor 100 either way of 7800, cut to its hard bounds.
    start = getattr(sm.default_parameters(), key)
    assert np.exp(log_bounds(key, start)) == pytest.approx((low, high), rel=1e-12)


def test_fit_bounds_keep_off_an_open_hard_bound() -> None:
    # air_heat_capacity_ratio > 1: a factor 100 below 1.4 would be 0.014.
    low, high = np.exp(log_bounds("air_heat_capacity_ratio", 1.4))
    assert 1.0 < low < 1.0 + 1e-8 and high == pytest.approx(5 / 3)
    sm.default_parameters(air_heat_capacity_ratio=float(low))


def test_the_default_free_set_is_what_moves_the_engines_network_alone():
    assert default_free(sm.default_parameters()) == DEFAULT_FREE
    # The 'dem' engine measures its mechanics once per fit: λ splits the heat inside the stepping.
    assert default_free(sm.default_parameters(engine="dem")) == DEM_DEFAULT_FREE == ("beta", "vial_mass", "h_outer")


@pytest.mark.parametrize("preset", ["spex8000m-3d-mill-head", "spex8000m-3d-calibrated", "pm100", "pulverisette7"])
def test_the_default_free_set_of_a_mill_head_network_is_keys_it_reads(preset):
    """Issue 35: every 3-D preset's default free set held h_outer, which the mill-head network does not read."""
    params = sm.default_parameters(preset)
    free = default_free(params)
    assert "h_outer" not in free and set(free) | set(unstarted_defaults(params)) == {
        "drive_heat",
        "clamp_heat_capacity",
        "clamp_loss",
    }
    assert all(reader_of(params).not_read(key) is None and getattr(params, key) > 0 for key in free)
    # The planetary presets start the drive's heat at 0: fitted in log space it needs a positive start.
    assert unstarted_defaults(params) == (("drive_heat",) if preset in ("pm100", "pulverisette7") else ())


def test_the_default_free_set_of_an_empty_mill_leaves_the_balls_keys_out():
    assert default_free(sm.default_parameters("spex8000m-3d", n_balls=0)) == ("vial_mass", "h_outer")


def test_a_fit_of_more_keys_than_informative_values_is_refused_before_it_runs():
    """Issue 35: four free keys fitted to a curve of one or two rows said "success": true, RMS 5e-7 K."""
    two_rows = Curve(np.array([0.0, 1800.0]), np.array([20.0, 40.0]), "lab")
    assert informative_points(two_rows) == 1
    with pytest.raises(ParameterError) as raised:
        calibrate(sm.default_parameters(), DEFAULT_FREE, curve=two_rows)
    assert str(raised.value) == (
        "free: 4 keys (beta, vial_mass, h_outer, lam) cannot be determined by 1 informative value (1 of lab after "
        "t = 0); allowed at most 1 free key (--free), or more measured points"
    )
    with pytest.raises(ParameterError, match="by 2 informative values \\(2 targets after t = 0\\)"):
        check_determinable(("beta", "vial_mass", "h_outer"), {"theta_inf_C": 48.0, "tau_min": 16.7}, ())
    check_determinable(("beta", "vial_mass"), {"theta_inf_C": 48.0}, (two_rows,))


def test_a_jacobian_that_leaves_keys_free_is_named_undetermined():
    rng = np.random.default_rng(1)
    good = rng.standard_normal((12, 3))
    assert undetermined_keys(good, ("a", "b", "c")) == ""
    dead = good.copy()
    dead[:, 1] = 0.0
    assert (
        undetermined_keys(dead, ("a", "b", "c")) == "undetermined: the fitted values do not depend on b (sensitivity 0)"
    )
    # h_outer and outer_area enter as their product: their columns are equal, one combination is all the data fix.
    collinear = good.copy()
    collinear[:, 2] = collinear[:, 0] * (1 + 1e-9)
    message = undetermined_keys(collinear, ("h_outer", "b", "outer_area"))
    assert message.startswith("undetermined: the data fix no more than a combination of h_outer, outer_area")
    assert (
        undetermined_keys(np.zeros((3, 2)), ("a", "b"))
        == "undetermined: the fitted values do not depend on a, b (sensitivity 0)"
    )


@pytest.mark.slow
def test_a_fit_whose_run_does_not_depend_on_its_keys_is_undetermined_not_a_success():
    # An empty mill on the paper's network makes no heat: its vial stays at the room's temperature whatever β is.
    curve = Curve(np.array([0.0, 600.0, 1800.0, 3600.0]), np.array([20.0, 25.0, 30.0, 33.0]), "lab", node="vial")
    fitted = calibrate(
        sm.default_parameters("spex8000m-3d", n_balls=0), ("beta", "vial_mass"), curve=curve, sample_posterior=False
    )
    assert fitted.status == "undetermined" and not fitted.success
    assert fitted.message.startswith("undetermined: the fitted values do not depend on beta, vial_mass")
    assert fitted.as_dict()["status"] == "undetermined"


@pytest.mark.parametrize(
    ("text", "expected_C", "note"),
    [
        (
            "time_min;vial_C\n0;20\n5;25,1\n",
            [20.0, 25.1],
            "read as ';'-separated columns, with decimal commas as points",
        ),
        ("time_min,vial_K\n0,293.15\n5,298.25\n", [0.0 + 20.0, 25.1], ""),
        ("time_min,vial_C,remark\n0,20,start\n5,25.1,\n", [20.0, 25.1], ""),
    ],
)
def test_a_curve_file_is_read_in_its_own_unit_and_separator(tmp_path, text, expected_C, note):
    path = tmp_path / "curve.csv"
    path.write_text(text)
    curve = Curve.from_csv(path)
    np.testing.assert_allclose(curve.temperature_C, expected_C, rtol=1e-12)
    np.testing.assert_allclose(curve.times, [0.0, 300.0])
    assert curve.node == "vial" and curve.note.endswith(note) and bool(curve.note) == bool(note)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (
            "time_min,vial_C\n0,20\n5,25,1\n",
            "line 3: 3 cells for the 2 columns of its header (time_min, vial_C); a decimal comma",
        ),
        ("time_s,time_min,vial_C\n0,0,20\n", "has both time_s and time_min"),
        ("time_min,vial_C,vial_C\n0,20,20\n", "the column vial_C appears 2 times"),
        ("time_min,vial_C\n0,293.15\n60,320\n", "vial_C holds 293.15 to 320, which look like kelvin"),
        ("time_min,ball_K\n0,20\n60,48\n", "ball_K holds 20 to 48, which look like °C"),
        ("time_min,vial_C\n0,20\n30,-300\n", "point 2 has vial_C = -300 °C"),
    ],
)
def test_a_curve_file_that_says_one_thing_and_means_another_is_refused(tmp_path, text, fragment):
    """Issue 35: decimal commas dropped a cell without a word (25.1 °C read as 25), kelvin was fitted as °C, a bad
    vial_C value was reported as ball_C."""
    path = tmp_path / "curve.csv"
    path.write_text(text)
    with pytest.raises(ParameterError) as raised:
        Curve.from_csv(path)
    assert fragment in str(raised.value) and str(raised.value).startswith(f"curve {path}")


# --- several curves, each of its own node and conditions (issue 23) ------------------------------------------


def test_a_curve_option_names_its_file_its_node_and_its_conditions(tmp_path) -> None:
    path = tmp_path / "vial.csv"
    path.write_text("time_min,vial_C\n0,20\n30,31\n")
    curve = curve_from_option(f"{path}:n_balls=5, omega=120 rad/s")
    assert curve.node == "vial" and curve.variable == "theta_vial"
    assert curve.conditions == ("n_balls=5", "omega=120 rad/s")
    np.testing.assert_allclose(curve.temperature_C, [20.0, 31.0])
    assert curve_from_option(str(path)).conditions == ()
    (tmp_path / "both.csv").write_text("time_s,ball_C,vial_C\n0,20,20\n")
    with pytest.raises(ParameterError, match="one of ball_C, vial_C, ball_K, vial_K"):
        Curve.from_csv(tmp_path / "both.csv")


def test_a_curve_may_not_set_a_key_the_fit_moves() -> None:
    curve = Curve(np.array([0.0, 60.0]), np.array([20.0, 21.0]), "lab", conditions=("beta=0.5",))
    with pytest.raises(ParameterError, match="curve: the conditions of lab set beta, which the fit moves"):
        calibrate(sm.default_parameters(), ("beta", "vial_mass"), curve=[curve])


@pytest.mark.slow
def test_curves_of_two_nodes_under_two_conditions_recover_the_parameters_that_made_them() -> None:
    truth = {"beta": 0.6, "vial_mass": 0.1}
    settings = {"solver": "averaged", "output_interval": 60.0, "record_windows": ()}
    ball = sm.simulate(sm.default_parameters(**settings, **truth)).timeseries
    vial = sm.simulate(sm.default_parameters(**settings, **truth, omega=100.0)).timeseries
    curves = [
        Curve(ball["time"].values, ball["theta_ball"].values - 273.15, "ball at 111 rad/s"),
        Curve(
            vial["time"].values,
            vial["theta_vial"].values - 273.15,
            "vial at 100 rad/s",
            node="vial",
            conditions=("omega=100",),
        ),
    ]
    fit = calibrate(sm.default_parameters(**settings, beta=0.3, vial_mass=0.05), ("beta", "vial_mass"), curve=curves)
    for key, value in truth.items():
        assert fit.fitted[key] == pytest.approx(value, rel=1e-3)
    assert fit.curve_rms_K < 0.01
    assert "vial_C at 30 min (omega=100)" in fit.sensitivities
    assert "vial at 100 rad/s (vial, omega=100)" in fit.curve_source


def test_a_ctrl_c_while_the_posterior_is_sampled_is_raised_without_emcee_printing_a_traceback(capsys):
    from shakermill.studies.calibration.calibrate import posterior_samples

    calls = []

    def residuals_of(x):
        calls.append(x)
        if len(calls) == 5:
            raise KeyboardInterrupt
        return x - 1.0

    with pytest.raises(KeyboardInterrupt):
        posterior_samples(residuals_of, np.zeros(2), np.full(2, -5.0), np.full(2, 5.0), 1.0)
    assert capsys.readouterr().err == "" and len(calls) == 5


def test_a_fit_tells_its_progress_each_evaluation_with_its_rms_from_the_curve():
    """Issue 37, point 2: a long fit says how far it has got and how close it is, on a terminal and piped."""
    seen = []
    calibration = calibrate(
        sm.default_parameters("spex8000m", record_windows=()),
        ("beta", "vial_mass"),
        progress=lambda done, rms: seen.append((done, rms)),
    )
    assert [done for done, _ in seen] == list(range(1, calibration.evaluations + 1))
    # The start is far off the experiment's curve; the fit ends where its own RMS says, the last evaluations near it.
    assert seen[0][1] > 10 * calibration.curve_rms_K
    assert min(rms for _, rms in seen) == pytest.approx(calibration.curve_rms_K, rel=1e-6)


def test_a_key_whose_standard_error_exceeds_its_value_is_named_loosely_determined():
    assert loosely_determined(None, ("a", "b")) == ""
    assert loosely_determined(np.diag([0.01, 0.25]), ("a", "b")) == ""
    message = loosely_determined(np.diag([0.01, 4.0, 1.5]), ("h_outer", "beta", "lam"))
    assert message.startswith("undetermined: the data leave beta, lam free") and "--free h_outer" in message
    # A key its range holds on an edge is not free: the fit says it ended there, not that the data leave it.
    assert loosely_determined(np.diag([0.01, 4.0]), ("h_outer", "lam"), on_bounds=("lam",)) == ""


GUIDE_VIAL_CURVE = Curve(
    np.array([0.0, 5.0, 10.0, 20.0, 40.0, 60.0]) * 60.0,
    np.array([22.0, 25.1, 27.6, 31.0, 34.2, 35.3]),
    "vial.csv",
    node="vial",
)


@pytest.mark.slow
def test_four_keys_on_the_guides_six_vial_points_are_undetermined_and_predict_nothing():
    """Issue 37, point 5: the 1-D fit of four keys met five points within a hundredth of a kelvin and reported a ball
    steady state of 231 °C beside the vial's 36 °C, with no remark."""
    base = sm.default_parameters("spex8000m", initial_temperature=295.15, ambient_temperature=295.15)
    fit = calibrate(base, default_free(base), curve=GUIDE_VIAL_CURVE, sample_posterior=False)
    assert len(fit.free) == 4 and fit.status == "undetermined" and not fit.success
    assert "standard error larger than the value" in fit.message
    # Fewer keys, the ones it names, are determined, and their predictions carry standard errors.
    fewer = calibrate(base, ("h_outer",), curve=GUIDE_VIAL_CURVE, sample_posterior=False)
    assert fewer.status != "undetermined", fewer.message
    assert 0 < fewer.prediction_stderr["vial_steady_C"] < abs(fewer.predictions["vial_steady_C"] - 22.0)
