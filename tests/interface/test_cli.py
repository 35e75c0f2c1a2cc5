"""The command line: run folders, --json output, exit codes and one-line errors for bad input."""

from __future__ import annotations

import contextlib
import importlib
import io
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import TIGHTEST_TOLERANCES, assert_one_error_line
from rich.console import Console
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.cli import common as cli_common
from shakermill.cli import scans
from shakermill.io.runs import RUN_FILES, load_run
from shakermill.parameters.config import load_config
from shakermill.parameters.engine_keys import reads
from shakermill.parameters.keys import FIELD_NAMES
from shakermill.parameters.presets import PRESETS
from shakermill.solvers.result import INTERRUPTED
from shakermill.studies.calibration.calibrate import DEFAULT_FREE
from shakermill.studies.sweeps.plan import plan_sweep
from shakermill.studies.sweeps.storage import load_sweep

# Short runs with small windows keep every invocation well under a second once Numba's cache is warm.
SHORT = ["--set", "duration=2", "--set", "record_windows=0:0.2"]
REQUIRED_SUMMARY_KEYS = {
    "theta_inf_C",
    "tau_min",
    "rate0_C_per_min",
    "ball_C",
    "vial_C",
    "air_C",
    "vial_ball_ratio",
    "impacts",
    "impact_rate_hz",
    "heat_power_W",
    "mean_impact_speed_m_s",
    "steps",
    "wall_time_s",
    "energy_audit_residual",
    "status",
    "success",
    "message",
    "output_dir",
}
SHAKERMILL = Path(sys.executable).parent / "shakermill"
# The module whose ``simulate`` the command line calls.
SIMULATE_MODULE = importlib.import_module("shakermill.solvers.simulate")

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(cli.app, list(args))


def test_run_json_prints_exactly_one_object_matching_the_stored_summary(tmp_path):
    out = tmp_path / "run"
    result = invoke("run", *SHORT, "--out", str(out), "--json", "--no-plots")
    assert result.exit_code == 0, result.stderr
    assert result.stdout.count("\n") == 1  # one line, one object
    summary = json.loads(result.stdout)
    assert isinstance(summary, dict)
    assert REQUIRED_SUMMARY_KEYS <= set(summary)
    assert summary["success"] is True and summary["status"] == 0
    assert summary["impacts"] > 0
    assert summary["output_dir"] == str(out)
    stored = json.loads((out / "summary.json").read_text(encoding="utf-8"))["summary"]
    for key in ("theta_inf_C", "tau_min", "ball_C", "impacts", "steps"):
        assert summary[key] == stored[key]
    assert sorted(entry.name for entry in out.iterdir()) == sorted(RUN_FILES)  # --no-plots: no figures


@pytest.mark.slow
def test_run_writes_figures_and_prints_a_human_summary(tmp_path):
    out = tmp_path / "run"
    result = invoke("run", *SHORT, "--out", str(out))
    assert result.exit_code == 0, result.stderr
    ball_celsius = load_run(out).summary.ball_C
    units = ("°C", "min", "Hz", "m/s", "W")
    # Shorter than its slowest time constant: one row says why no exponential is fitted (issue 37).
    expected = (
        "exponential fit",
        "none: the run is shorter than the slowest time constant",
        *units,
        "steps",
        "energy audit residual",
        f"{ball_celsius:.2f}",
        str(out),
    )
    for text in expected:
        assert text in result.stdout, text
    figures = sorted(path.name for path in (out / "figures").iterdir())
    names = ("ball_heating_zoom", "ball_motion", "temperatures")
    assert figures == sorted(f"{name}.{fmt}" for name in names for fmt in ("png", "svg"))
    assert "engine; balls" not in result.stdout and "balls' mean" not in result.stdout  # rows of the dem engine only


def test_config_file_and_set_overrides_end_up_in_the_stored_configuration(tmp_path):
    config = tmp_path / "mill.toml"
    config.write_text(
        'restitution = 0.8\nvial_mass = "60 g"\nduration = 5\nrecord_windows = [[0, 0.1]]\n', encoding="utf-8"
    )
    out = tmp_path / "run"
    result = invoke("run", str(config), "--set", "duration=2", "--out", str(out), "--json", "--no-plots")
    assert result.exit_code == 0, result.stderr
    params = load_config(out / "config.toml").params
    assert params.restitution == 0.8
    assert params.vial_mass == pytest.approx(0.06)
    assert params.duration == 2.0  # --set beats the file
    assert json.loads(result.stdout)["simulated_s"] == 2.0
    assert str(config) in (out / "config.toml").read_text(encoding="utf-8")  # provenance names the file


@pytest.mark.parametrize(
    "setting, fragments",
    [
        ("restitution=1.5", ("restitution", "allowed (0, 1]")),
        ("restitution=0", ("restitution", "allowed (0, 1]")),
        ("ball_radius=40 mm", ("ball_radius", "does not fit", "allowed ball_radius < vial_length/2 = 0.029 m")),
        ("vial_mass=-1", ("vial_mass", "allowed [0.001, 100] kg")),
        ("omega=0", ("omega", "allowed [1, 10000] rad/s")),
        (
            "amplitude=3 kg",
            ("amplitude", "'3 kg' has the wrong dimension (read as kilogram); expected a length such as m or mm"),
        ),
        (
            "omega=3 kg",
            (
                "omega: '3 kg' has the wrong dimension (read as kilogram); expected a frequency such as rad/s, Hz or "
                "rpm",
            ),
        ),
        ("omega=1060 rmp", ("omega: cannot parse '1060 rmp': unknown unit 'rmp'; expected a frequency",)),
        ("ambient_temperature=25 kg", ("ambient_temperature", "expected a temperature such as K, degC or degF")),
        ("restitutoin=0.5", ("restitutoin", "did you mean 'restitution'")),
        ("duration=abc", ("duration", "'abc'")),
        ("duration", ("'duration'", "expected KEY=VALUE")),
        ("heat_model=exact", ("heat_model", "'relative' or 'paper'")),
    ],
)
def test_bad_setting_exits_2_with_one_line_naming_the_key(tmp_path, setting, fragments):
    out = tmp_path / "run"
    result = invoke("run", "--set", setting, "--out", str(out))
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, *fragments)
    assert result.stdout == ""
    assert not out.exists()


def test_temperatures_in_degrees_celsius_and_rates_in_rpm_of_any_case_are_read(tmp_path):
    out = tmp_path / "run"
    settings = ["ambient_temperature=25 C", "initial_temperature=68 °F", "omega=1060 RPM", "atol_temperature=1e-6 degC"]
    result = invoke(
        "run",
        *SHORT,
        *(part for setting in settings for part in ("--set", setting)),
        "--out",
        str(out),
        "--json",
        "--no-plots",
    )
    assert result.exit_code == 0, result.stderr
    params = load_config(out / "config.toml").params
    assert params.ambient_temperature == pytest.approx(298.15)  # 25 °C, not 25 coulombs
    assert params.initial_temperature == pytest.approx(293.15)
    assert params.omega == pytest.approx(1060 * 2 * np.pi / 60)
    assert params.atol_temperature == pytest.approx(1e-6)  # a difference: one degree Celsius is one kelvin


def test_malformed_toml_exits_2_naming_file_and_line(tmp_path):
    config = tmp_path / "broken.toml"
    config.write_text("duration = 2\nrestitution = \neta = 0.5\n", encoding="utf-8")
    result = invoke("run", str(config), "--out", str(tmp_path / "run"))
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "broken.toml", "malformed TOML", "line 2")


def test_missing_config_file_exits_2(tmp_path):
    result = invoke("run", str(tmp_path / "absent.toml"))
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "absent.toml", "no such configuration file")


def test_unknown_preset_exits_2():
    result = invoke("run", "--preset", "spex9000")
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "unknown preset 'spex9000'", "spex8000m")


def test_output_over_a_foreign_folder_is_refused_before_running(tmp_path, monkeypatch):
    (tmp_path / "notes.txt").write_text("mine")
    monkeypatch.setattr(SIMULATE_MODULE, "simulate", lambda *_args, **_kwargs: pytest.fail("must not run"))
    result = invoke("run", *SHORT, "--out", str(tmp_path))
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, str(tmp_path), "not a shakermill run")
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_usage_error_from_the_parser_exits_2():
    result = invoke("run", "--no-such-option")
    assert result.exit_code == 2
    assert "No such option" in result.stderr


@pytest.mark.slow
def test_numerical_failure_keeps_the_results_and_exits_1(tmp_path):
    # A soft ball and vial overlap by more than the integrator allows at the first impact.
    out = tmp_path / "run"
    soft = ["--set", "ball_youngs_modulus=1e7", "--set", "vial_youngs_modulus=1e7"]
    result = invoke("run", *SHORT, *soft, "--out", str(out), "--json")
    assert result.exit_code == 1
    summary = json.loads(result.stdout)
    assert summary["success"] is False and summary["status"] < 0
    assert summary["simulated_s"] < 2.0
    assert "overlap" in result.stderr and str(out) in result.stderr
    assert load_run(out).status == summary["status"]
    assert (out / "figures" / "temperatures.png").is_file()


@pytest.mark.slow
def test_interruption_writes_partial_results_and_exits_130(tmp_path, monkeypatch):
    real_simulate = sm.simulate

    def press_ctrl_c(_t: float, _duration: float) -> None:
        raise KeyboardInterrupt

    # The interruption arrives after the first chunk, inside the library, as a real Ctrl-C would.
    monkeypatch.setattr(
        SIMULATE_MODULE,
        "simulate",
        lambda params, progress=None, notice=None: real_simulate(params, progress=press_ctrl_c, notice=notice),
    )
    out = tmp_path / "run"
    result = invoke("run", "--set", "duration=30", "--set", "record_windows=0:0.2", "--out", str(out), "--no-plots")
    assert result.exit_code == 130
    assert "interrupted" in result.stderr.lower()
    run = load_run(out)
    assert run.status == 1
    assert 0 < float(run.timeseries["time"].max()) < 30.0


@pytest.fixture(name="terminal")
def terminal_fixture(monkeypatch) -> io.StringIO:
    """What the command draws on stderr, as if stderr were a terminal."""
    screen = io.StringIO()
    real_console = Console

    def console(**kwargs):
        if kwargs.get("stderr"):
            return real_console(file=screen, force_terminal=True, width=120)
        return real_console(**kwargs)

    monkeypatch.setattr(cli_common, "Console", console)
    return screen


@pytest.mark.parametrize("solver", ["full", "averaged"])
def test_progress_bar_is_drawn_on_a_terminal_once_a_run_takes_a_while(terminal, monkeypatch, solver):
    monkeypatch.setattr(cli_common, "PROGRESS_DELAY_S", 0.0)
    result = cli_common.simulate_with_progress(
        sm.default_parameters(solver=solver, duration=60.0, attractor_starts=2, record_windows=())
    )
    assert result.success
    assert "s simulated" in terminal.getvalue()


def test_a_quick_run_draws_no_progress_bar(terminal):
    result = cli_common.simulate_with_progress(sm.default_parameters(duration=2.0, record_windows=()))
    assert result.success
    assert terminal.getvalue() == ""


@pytest.mark.slow
def test_sweep_progress_bar_shows_points_done_running_and_failed(terminal, tmp_path):
    outcome = invoke(
        "sweep", *QUICK_BASE, "--grid", "restitution=0.8:1.1:3", "--workers", "1", "--out", str(tmp_path / "s")
    )
    assert outcome.exit_code == 1  # restitution 1.1 is out of range: that point fails
    drawn = terminal.getvalue()
    assert "3/3 points · 0 running · 1 failed" in drawn
    assert "0/3 points" in drawn


def test_presets_lists_and_shows_values_with_units_and_sources():
    listing = invoke("presets")
    assert listing.exit_code == 0
    assert "spex8000m" in listing.stdout and "SPEX 8000M" in listing.stdout
    shown = invoke("presets", "spex8000m")
    assert shown.exit_code == 0
    for text in ("ball_radius", "0.00635 m", "111 rad/s", "[0, 1], [600, 0.1] s", "Table 1", "Son 2025"):
        assert text in shown.stdout, text
    missing = invoke("presets", "nope")
    assert missing.exit_code == 2
    assert_one_error_line(missing.stderr, "unknown preset 'nope'")
    # The paper's preset has no assumed inputs stated; a 3-D preset shows its own with ranges and reasons.
    assert "assumed inputs" not in shown.stdout
    planetary = invoke("presets", "pulverisette7")
    assert planetary.exit_code == 0
    for text in (
        "assumed inputs, no source fixes them",
        "[0.1, 0.6]",
        "[1000, 4000] J/K",
        "log-uniform",
        "[0.368, 0.5]",
    ):
        assert text in planetary.stdout, text
    assert "lateral_amplitude" not in planetary.stdout.split("assumed inputs")[1]
    listed = invoke("keys", "pair_friction")
    assert listed.exit_code == 0
    assert "Assumed, no source fixes it: [0.1, 0.6]" in " ".join(listed.stdout.split())


def test_keys_lists_every_key_with_its_allowed_range():
    result = invoke("keys")
    assert result.exit_code == 0
    lines = result.stdout.splitlines()
    for key in FIELD_NAMES:
        assert any(f" {key} " in line for line in lines), key
    restitution = next(line for line in lines if line.count("│") == 5 and line.split("│")[1].strip() == "restitution")
    assert "(0, 1]" in restitution and "0.7" in restitution
    assert "one of 'relative', 'paper'" in result.stdout


def keys_listed(stdout: str) -> list[str]:
    """The keys of a `keys` table, one per row (a row's later lines leave the key's cell empty)."""
    cells = [line.split("│")[1].strip() for line in stdout.splitlines() if line.count("│") == 5]
    return [cell for cell in cells if cell]


def test_keys_with_a_pattern_lists_the_keys_whose_name_or_description_has_it():
    omega = invoke("keys", "OMEGA")
    assert omega.exit_code == 0, omega.stderr
    assert keys_listed(omega.stdout) == ["omega"]
    assert f"parameter keys matching 'OMEGA': 1 of {len(FIELD_NAMES)}" in omega.stdout
    assert "The drive" in omega.stdout  # the component whose key it is, the title of its table
    radii = invoke("keys", "ball_r*")
    assert keys_listed(radii.stdout) == ["ball_radius", "ball_radii"]
    none = invoke("keys", "tempreature")
    assert none.exit_code == 0
    assert none.stdout == f"no parameter key matching 'tempreature'; `shakermill keys` lists all {len(FIELD_NAMES)}\n"


@pytest.mark.parametrize("engine", ["1d", "dem"])
def test_keys_of_an_engine_are_those_it_reads(engine):
    result = invoke("keys", "--engine", engine)
    assert result.exit_code == 0, result.stderr
    assert keys_listed(result.stdout) == [key for key in FIELD_NAMES if reads(engine, key)]
    one_d_only, dem_only = ("rtol", "energy_projection"), ("friction", "n_balls", "kinematics", "clamp_loss")
    listed = set(keys_listed(result.stdout))
    assert listed >= set(one_d_only if engine == "1d" else dem_only)
    assert not listed & set(dem_only if engine == "1d" else one_d_only)


def test_keys_of_an_unknown_engine_is_refused():
    result = invoke("keys", "--engine", "one_d")
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, "--engine: 'one_d' is no engine; allowed '1d', 'dem'")


def test_help_shows_switches_as_flags_without_a_value():
    assert invoke("--help").exit_code == 0  # every command registered by now
    commands = [command.name for command in cli_common.app.registered_commands]
    assert len(commands) >= 12
    for command in commands:
        result = invoke(command, "--help")
        assert result.exit_code == 0, command
        # typer's rich help shows a switch as `--json <bool>`, as if it took a value.
        assert "<bool>" not in result.stdout, command
        assert "--json" not in result.stdout or re.search(r"^  --json  +\S", result.stdout, flags=re.MULTILINE), command


def test_sweep_table_shows_swept_values_in_the_units_they_were_written_in(tmp_path):
    plan = plan_sweep(["amplitude=5mm,10mm", "omega=1000 RPM:1100 rpm:2", "n_balls=1"])
    assert plan.units == (("amplitude", "mm"), ("omega", "RPM"))
    assert [point["amplitude"] for point in plan.points[::2]] == pytest.approx([0.005, 0.01])  # stored in SI
    table = pd.DataFrame(
        {
            "amplitude": [0.005, 0.01],
            "omega": [1000 * np.pi / 30, 1100 * np.pi / 30],
            "n_balls": [1, 1],
            "error": [None, None],
        }
    )
    drawn = io.StringIO()
    Console(file=drawn, width=250).print(scans.sweep_preview(table, plan.keys, tmp_path, dict(plan.units)))
    rows = [[cell.strip() for cell in line.split("│")[1:4]] for line in drawn.getvalue().splitlines() if "│" in line]
    assert "amplitude (mm) ┃ omega (RPM) ┃ n_balls" in drawn.getvalue()
    assert rows == [["5", "1000", "1"], ["10", "1100", "1"]]


@pytest.mark.parametrize("command", ["report", "plot"])
def test_a_run_folder_that_does_not_exist_is_named_so(tmp_path, command):
    (tmp_path / "default").mkdir()
    result = invoke(command, str(tmp_path / "defualt"))
    assert result.exit_code == 2
    assert_one_error_line(
        result.stderr, f"{tmp_path / 'defualt'}: no such folder; did you mean {tmp_path / 'default'}?"
    )
    result = invoke(command, str(tmp_path / "default"))
    assert_one_error_line(result.stderr, f"{tmp_path / 'default'}: not a shakermill run folder (no summary.json)")


def test_version_option():
    result = invoke("--version")
    assert result.exit_code == 0
    assert result.stdout.strip() == f"shakermill {sm.__version__}"


@pytest.mark.slow
def test_installed_command_reports_bad_input_without_traceback(tmp_path):
    completed = subprocess.run(
        [str(SHAKERMILL), "run", "--set", "restitution=1.5", "--out", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert completed.returncode == 2
    assert completed.stdout == ""
    assert completed.stderr == "error: restitution: 1.5 is out of range; allowed (0, 1]\n"


@pytest.mark.slow
def test_installed_command_json_output_is_clean(tmp_path):
    completed = subprocess.run(
        [str(SHAKERMILL), "run", *SHORT, "--out", str(tmp_path / "run"), "--json", "--no-plots"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert completed.returncode == 0, completed.stderr
    summary = json.loads(completed.stdout)
    assert REQUIRED_SUMMARY_KEYS <= set(summary)
    assert summary["success"] is True


@pytest.mark.slow
def test_compare_solvers_reports_both_solvers_and_the_speed_ratio():
    outcome = runner.invoke(cli.app, ["compare-solvers", "--set", "duration=300", "--set", "record_windows=", "--json"])
    assert outcome.exit_code == 0, outcome.output
    payload = json.loads(outcome.stdout)
    assert payload["averaged_solver_used"] == "averaged"
    assert payload["speed_ratio"] > 1.0
    full, averaged = payload["full"], payload["averaged"]
    assert averaged["ball_C"] == pytest.approx(full["ball_C"], abs=0.2)
    assert averaged["heat_power_W"] == pytest.approx(full["heat_power_W"], rel=0.005)


@pytest.mark.slow
def test_validate_prints_table5_with_fitted_and_predicted_roles():
    outcome = runner.invoke(cli.app, ["validate", "--solver", "averaged", "--no-three-d", "--json"])
    assert outcome.exit_code == 0, outcome.output
    payload = json.loads(outcome.stdout)
    assert "five_balls" not in payload
    published, calibrated = payload["runs"]["spex8000m"], payload["runs"]["spex8000m-calibrated"]
    assert set(published["role"].values()) == {"predicted"}
    assert calibrated["role"]["vial_ball_ratio"] == "predicted"
    assert calibrated["fitted_parameters"] == list(DEFAULT_FREE)
    for key in ("theta_inf_C", "tau_min", "rate0_C_per_min"):
        assert calibrated["role"][key] == "fitted"
        assert abs(calibrated["relative_error_vs_experiment"][key]) < 0.1
    assert calibrated["curve_rms_K"] <= 1.0 < published["curve_rms_K"]
    assert payload["quantities"]["theta_inf_C"]["experiment"] == 48.0
    study = {tuple(entry["free"]): entry for entry in payload["free_set_study"]}
    assert study[DEFAULT_FREE]["follows_curve"] and not study[("beta", "vial_mass")]["follows_curve"]
    assert "still rising at the hour" in study[("beta", "vial_mass")]["verdict"]
    # Issue 35: a quick validation without the 3-D studies said "full": true; it says what it ran.
    assert payload["full"] is False
    assert payload["ran"] == {
        "table5": True,
        "free_set_study": True,
        "validation_matrix": False,
        "experiments": [],
        "structure_study": False,
        "held_out": False,
        "cross_prediction": False,
        "powder": False,
    }


@pytest.mark.slow
def test_calibrate_writes_a_preset_that_run_accepts_with_the_settings_it_was_fitted_under(tmp_path):
    preset_file = tmp_path / "fitted.toml"
    outcome = runner.invoke(
        cli.app,
        [
            "calibrate",
            "--target",
            "theta_inf_C=100",
            "--free",
            "beta",
            "--set",
            "omega=1200 rpm",
            "--out",
            str(preset_file),
            "--json",
        ],
    )
    assert outcome.exit_code == 0, outcome.output
    payload = json.loads(outcome.stdout)
    assert abs(payload["relative_residuals"]["theta_inf_C"]) < 0.005
    params = load_config(preset_file).params
    assert params.beta == pytest.approx(payload["fitted"]["beta"])
    # The fit's --set is in the preset: without it the fitted beta would describe another drive.
    assert params.omega == pytest.approx(1200 * 2 * math.pi / 60)
    run = runner.invoke(
        cli.app,
        ["run", str(preset_file), "--set", "solver=averaged", "--json", "--no-plots", "--out", str(tmp_path / "run")],
    )
    assert run.exit_code == 0, run.output
    assert json.loads(run.stdout)["theta_inf_C"] == pytest.approx(100.0, rel=0.005)


@pytest.mark.slow
def test_calibrate_that_cannot_meet_its_targets_exits_1(tmp_path):
    outcome = runner.invoke(cli.app, ["calibrate", "--target", "theta_inf_C=25", "--free", "vial_mass"])
    assert outcome.exit_code == 1
    assert "cannot be met" in outcome.stderr


# Sweep folders and bifurcation scans ------------------------------------------------------------------

QUICK_BASE = ["--set", "duration=60", "--set", "record_windows="]


@pytest.fixture(scope="module")
def sweep_folder(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("sweeps") / "omega_amplitude"
    outcome = invoke(
        "sweep",
        *QUICK_BASE,
        "--grid",
        "omega=100:120:2",
        "--grid",
        "amplitude=24mm:26mm:2",
        "--workers",
        "1",
        "--out",
        str(folder),
    )
    assert outcome.exit_code == 0, outcome.stderr
    return folder


@pytest.mark.slow
def test_plot_of_a_sweep_folder_draws_maps_with_the_contour(sweep_folder, tmp_path):
    table = load_sweep(sweep_folder).table
    level = float(table["theta_inf_C"].median())
    outcome = invoke("plot", str(sweep_folder), "--out", str(tmp_path / "maps"), "--contour", f"theta_inf_C={level}")
    assert outcome.exit_code == 0, outcome.stderr
    stems = {path.stem for path in (tmp_path / "maps").iterdir()}
    assert stems == {
        "sweep_theta_inf_C",
        "sweep_tau_min",
        "sweep_impact_rate_hz",
        "sweep_heat_power_W",
        "sweep_mean_impact_speed_m_s",
        "sweep_ball_steady_C",
        "sweep_stress_energy_median_J",
        "sweep_stress_energy_p90_J",
        "sweep_regime",
    }
    assert "18 files written" in outcome.stdout
    assert "not crossed" not in outcome.stderr


@pytest.mark.slow
def test_plot_says_when_a_contour_level_is_never_reached(sweep_folder, tmp_path):
    table = load_sweep(sweep_folder).table
    level = float(table["theta_inf_C"].max()) + 10.0
    outcome = invoke("plot", str(sweep_folder), "--out", str(tmp_path / "maps"), "--contour", f"theta_inf_C={level}")
    assert outcome.exit_code == 0, outcome.stderr
    (line,) = outcome.stderr.strip().splitlines()
    assert line.startswith(f"note: theta_inf_C = {level:g} not crossed") and "below it at every point" in line
    assert "18 files written" in outcome.stdout


@pytest.mark.slow
@pytest.mark.parametrize(
    ("extra", "fragments"),
    [
        (["--contour", "theta_inf_C"], ("contour", "COLUMN=VALUE")),
        (["--contour", "warmth=60"], ("warmth is not a numeric column",)),
        (["--impacts"], ("--impacts", "sweep folder")),
    ],
)
def test_plot_of_a_sweep_folder_refuses_bad_options_with_one_line(sweep_folder, tmp_path, extra, fragments):
    outcome = invoke("plot", str(sweep_folder), "--out", str(tmp_path / "maps"), *extra)
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, *fragments)
    assert not (tmp_path / "maps").exists()


@pytest.mark.slow
def test_plot_of_a_sweep_over_the_solver_draws_every_figure(tmp_path):
    # The README's sweep over a string key: --points with a solver column.
    points = tmp_path / "solvers.csv"
    points.write_text("solver\nfull\naveraged\n", encoding="utf-8")
    folder = tmp_path / "sweep"
    swept = invoke(
        "sweep",
        "--points",
        str(points),
        "--set",
        "duration=2",
        "--set",
        "record_windows=",
        "--set",
        "attractor_starts=1",
        "--workers",
        "1",
        "--out",
        str(folder),
    )
    assert swept.exit_code == 0, swept.stderr
    outcome = invoke("plot", str(folder), "--out", str(tmp_path / "lines"))
    assert outcome.exit_code == 0, outcome.stderr
    assert "18 files written" in outcome.stdout


# Three balls in a vial wide enough for them side by side, for 2 s: a few seconds with the figures.
DEM = [
    "--set",
    "engine=dem",
    "--set",
    "n_balls=3",
    "--set",
    "vial_diameter=38 mm",
    "--set",
    "duration=2",
    "--set",
    "record_windows=0:0.5,1.5:0.1",
]
# A run of several balls with impacts draws its stress-energy spectrum too (issue 37, point 3).
DEM_FIGURES = ("ball_heating_zoom", "heat_by_channel", "stress_energy_spectrum", "temperatures", "trajectories")
DEM_IMPACT_FIGURES = ("impact_energy_histogram", "impact_speed_histogram", "impacts_per_second")


@pytest.fixture(scope="module")
def dem_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("dem") / "run"
    return out, invoke("run", *DEM, "--out", str(out))


def table_rows(stdout: str) -> dict[str, tuple[str, str]]:
    """The run table's rows as {quantity: (value, unit)}."""
    cells = [[cell.strip() for cell in line.split("│")[1:-1]] for line in stdout.splitlines() if line.count("│") == 4]
    return {quantity: (value, unit) for quantity, value, unit in cells}


@pytest.mark.slow
def test_a_dem_run_draws_its_figures_and_its_table_tells_the_balls_apart(dem_run):
    out, outcome = dem_run
    assert outcome.exit_code == 0, outcome.stderr
    figures = sorted(path.name for path in (out / "figures").iterdir())
    assert figures == sorted(f"{name}.{fmt}" for name in DEM_FIGURES for fmt in ("png", "svg"))
    for name in DEM_FIGURES:
        assert (out / "figures" / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    summary = load_run(out).summary
    rows = table_rows(outcome.stdout)
    assert rows["engine; balls; fill of the vial"] == (f"dem; 3; {summary.charge.fill_fraction:.3f}", "")
    each = "; ".join(f"{value:.2f}" for value in summary.temperatures.each_ball_C)
    assert rows["each ball at the end (ball 0; 1; …)"] == (each, "°C")
    assert rows["impacts on the walls; between balls"] == (
        f"{summary.impacts.on_walls}; {summary.impacts.between_balls}",
        "",
    )
    heat = "; ".join(
        f"{summary.value(f'heat_{channel}_W'):.3g}" for channel in ("normal", "tangential", "sliding", "rolling")
    )
    assert rows["heat by channel: normal; tangential; sliding; rolling"] == (heat, "W")
    assert rows["balls' mean at the end"] == (f"{summary.ball_C:.2f}", "°C")
    assert "ball at the end" not in rows


@pytest.mark.slow
def test_plot_of_a_dem_run_adds_the_impact_figures_and_the_animation(dem_run, tmp_path):
    from PIL import Image

    out, _ = dem_run
    target = tmp_path / "figures"
    outcome = invoke("plot", str(out), "--animate", "--frames", "10", "--out", str(target))
    assert outcome.exit_code == 0, outcome.stderr
    names = [f"{name}.{fmt}" for name in DEM_FIGURES + DEM_IMPACT_FIGURES for fmt in ("png", "svg")]
    assert sorted(path.name for path in target.iterdir()) == sorted([*names, "trajectories.gif"])
    assert f"{len(names) + 1} files written" in outcome.stdout
    with Image.open(target / "trajectories.gif") as gif:
        assert (gif.n_frames, gif.size) == (10, (640, 400))


@pytest.mark.slow
def test_report_of_a_dem_run_has_the_balls_and_their_figures(dem_run, tmp_path):
    out, _ = dem_run
    outcome = invoke("report", str(out), "--out", str(tmp_path / "report.html"))
    assert outcome.exit_code == 0, outcome.stderr
    document = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert "<h2>Balls</h2>" in document and document.count("<figure>") == len(DEM_FIGURES) + len(DEM_IMPACT_FIGURES)
    # Its configuration lists the keys of the 'dem' engine, not the tolerances of the 1-D integrator.
    assert (
        "<td>friction</td>" in document and "<td>n_balls</td>" in document and "<td>atol_position</td>" not in document
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    ("engine", "extra", "fragments"),
    [
        ("dem", ["--window", "2"], ("window 2", "allowed 0 to 1")),
        ("1d", ["--animate"], ("--animate", "1-D")),
    ],
)
def test_plot_refuses_a_window_the_run_lacks_and_an_animation_of_one_ball(dem_run, tmp_path, engine, extra, fragments):
    folder = dem_run[0]
    if engine == "1d":
        folder = tmp_path / "run"
        assert invoke("run", *SHORT, "--no-plots", "--out", str(folder)).exit_code == 0
    outcome = invoke("plot", str(folder), *extra, "--out", str(tmp_path / "figures"))
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, *fragments)
    assert not (tmp_path / "figures").exists()


@pytest.mark.slow
def test_contour_on_a_run_folder_is_refused(tmp_path):
    assert invoke("run", *SHORT, "--no-plots", "--out", str(tmp_path / "run")).exit_code == 0
    outcome = invoke("plot", str(tmp_path / "run"), "--contour", "theta_inf_C=60")
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, "--contour", "sweep folder")


@pytest.mark.slow
def test_bifurcation_writes_regimes_phases_and_the_diagram(tmp_path):
    folder = tmp_path / "scan"
    outcome = invoke("bifurcation", *QUICK_BASE, "--grid", "omega=100:120:3", "--out", str(folder))
    assert outcome.exit_code == 0, outcome.stderr
    regimes = pd.read_parquet(folder / "bifurcation_regimes.parquet")
    phases = pd.read_parquet(folder / "bifurcation_phases.parquet")
    assert list(regimes["omega"]) == [100.0, 110.0, 120.0]
    assert regimes["solver"].eq("averaged").all()  # the scan defaults to the averaged solver
    assert set(phases["omega"]) == {100.0, 110.0, 120.0}
    assert phases["phase"].between(0.0, 2 * np.pi).all() and set(phases["wall"]) <= {"left", "right"}
    assert pd.read_csv(folder / "bifurcation_regimes.csv")["regime"].tolist() == regimes["regime"].tolist()
    assert (folder / "bifurcation.png").read_bytes().startswith(b"\x89PNG")
    for label in regimes["regime"].unique():
        assert label in outcome.stdout
    attractors = pd.read_parquet(folder / "bifurcation_attractors.parquet")
    assert attractors.groupby("omega")["basin_fraction"].sum().to_numpy() == pytest.approx(1.0)
    coexisting = int((attractors.groupby("omega").size() > 1).sum())
    if coexisting:
        assert f"coexisting attractors (8 starts per value): at {coexisting} of 3 values" in outcome.stdout
    else:
        assert "coexisting attractors: none; all 8 starts reach one attractor at each of 3 values" in outcome.stdout


@pytest.mark.parametrize(
    ("grid", "fragments"),
    [
        ("omega=90:130", ("KEY=START:STOP:N",)),
        ("speed=1:2:3", ("speed", "unknown parameter")),
        ("omega=-10:10:3", ("omega",)),
    ],
)
def test_bifurcation_bad_grid_exits_2_with_one_line(tmp_path, grid, fragments):
    outcome = invoke("bifurcation", "--grid", grid, "--out", str(tmp_path / "scan"))
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, *fragments)
    assert not (tmp_path / "scan").exists()


@pytest.fixture(scope="module")
def start_up_s(tmp_path_factory) -> float:
    """CPU-seconds a short run takes as a process here, with Numba's cache warm: how much work a process does before
    it can be interrupted in its run. CPU time, not the wall clock: on a machine shared with the rest of the suite a
    start-up stretches far past what it takes alone, and a Ctrl-C that lands in the start-up is another test's case."""
    import resource  # POSIX only, like the /proc that cpu_seconds reads

    out = tmp_path_factory.mktemp("warm") / "run"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    warm = subprocess.run(
        [str(SHAKERMILL), "run", *SHORT, "--no-plots", "--out", str(out)], capture_output=True, text=True, timeout=300
    )
    assert warm.returncode == 0, warm.stderr
    return children_cpu_s(resource.getrusage(resource.RUSAGE_CHILDREN)) - children_cpu_s(before)


def children_cpu_s(usage) -> float:
    return usage.ru_utime + usage.ru_stime


def interrupt_after(command: list[str], after_cpu_s: float, stops_within_cpu_s: float = 3.0) -> str:
    """Run ``command``, send it SIGINT once it has used ``after_cpu_s`` CPU-seconds, and return its stderr once it
    exited with 130, having used at most ``stops_within_cpu_s`` CPU-seconds after the signal."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    process = subprocess.Popen([str(SHAKERMILL), *command], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for_cpu(process, after_cpu_s)
    used = cpu_seconds(process.pid)
    process.send_signal(signal.SIGINT)
    # A hang guard, not a speed bound: the work after the signal is bounded in CPU time below.
    _, stderr = process.communicate(timeout=600)
    assert process.returncode == 130, stderr
    after = children_cpu_s(resource.getrusage(resource.RUSAGE_CHILDREN)) - children_cpu_s(before) - used
    assert after <= stops_within_cpu_s, f"{after:.2f} CPU-s after the signal"
    # A fit says which keys it moves once it starts; the Ctrl-C is the one line after.
    lines = [line for line in stderr.strip().splitlines() if not line.startswith("calibrate: fitting ")]
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    return lines[0]


@pytest.mark.slow
def test_real_ctrl_c_during_a_full_run_keeps_the_run_and_exits_130(tmp_path, start_up_s):
    out = tmp_path / "run"
    command = ["run", "--set", "solver=full", "--set", "duration=600 min", "--no-plots", "--out", str(out)]
    stderr = interrupt_after(command, start_up_s + 2.0)
    assert stderr.startswith("interrupted:") and str(out) in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == INTERRUPTED
    assert summary["message"].startswith("Interrupted by the user")
    assert 0 < summary["summary"]["simulated_s"] < 36000


@pytest.mark.slow
@pytest.mark.parametrize(
    "command",
    [
        ["bifurcation", "--full-resolution", "--set", "duration=600", "--grid", "omega=90:130:50"],
        ["calibrate", "--full-resolution"],
    ],
    ids=["bifurcation", "calibrate"],
)
def test_real_ctrl_c_during_a_scan_or_fit_says_so_in_one_line(tmp_path, start_up_s, command):
    out = tmp_path / "out"
    stderr = interrupt_after(
        [*command, "--out", str(out if command[0] == "bifurcation" else out.with_suffix(".toml"))], start_up_s + 2.0
    )
    assert stderr.startswith("error: interrupted; nothing was written")
    assert list(tmp_path.iterdir()) == []


def cpu_seconds(pid: int) -> float:
    """The CPU time a running process and its live children have used (a sweep's or a fit's workers do its work)."""
    import psutil

    process = psutil.Process(pid)
    total = 0.0
    for member in (process, *process.children(recursive=True)):
        with contextlib.suppress(psutil.NoSuchProcess):
            times = member.cpu_times()
            total += times.user + times.system
    return total


def wait_for_cpu(process: subprocess.Popen, cpu_s: float, within_s: float = 600.0) -> None:
    """Wait until ``process`` has used ``cpu_s`` CPU-seconds (or fail after ``within_s`` of wall clock).

    CPU time, not the wall clock: on a machine shared with the rest of the suite a process's start-up stretches far
    past what it took alone, and a Ctrl-C that lands before the run has begun is another test's case."""
    waited_until = time.monotonic() + within_s
    while cpu_seconds(process.pid) < cpu_s:
        assert process.poll() is None, "the run ended before it could be interrupted"
        assert time.monotonic() < waited_until, f"the run used under {cpu_s:.1f} CPU-s in {within_s:.0f} s"
        time.sleep(0.1)


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads a process's CPU time from /proc (Linux)")
@pytest.mark.parametrize(
    "settings",
    [
        ["--set", "solver=full", "--set", "duration=600 min"],
        ["--preset", "spex8000m-3d", "--set", "solver=full", "--set", "duration=60"],
    ],
    ids=["1-D", "3-D"],
)
def test_real_ctrl_c_exits_within_a_second_with_the_data_written(tmp_path, settings):
    import resource  # POSIX only, like the /proc this test reads

    # Twice: the first warms Numba's cache (a compilation is no run to interrupt); the second is timed. All a short run
    # does but its steps: start-up, checks, writing. Past its CPU time by 1.5 s, the long run is stepping.
    for short_run in ("warm", "timed"):
        children_before = resource.getrusage(resource.RUSAGE_CHILDREN)
        done = subprocess.run(
            [
                str(SHAKERMILL),
                "run",
                *settings,
                "--set",
                "duration=0.01",
                "--no-plots",
                "--out",
                str(tmp_path / short_run),
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, done.stderr
        children_after = resource.getrusage(resource.RUSAGE_CHILDREN)
    short_run_cpu_s = children_cpu_s(children_after) - children_cpu_s(children_before)
    out = tmp_path / "run"
    # Figures asked for: they are what an interrupted run leaves to `plot`. --json: its summary all the same.
    process = subprocess.Popen(
        [str(SHAKERMILL), "run", *settings, "--json", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    wait_for_cpu(process, short_run_cpu_s + 1.5)
    used = cpu_seconds(process.pid)
    process.send_signal(signal.SIGINT)
    _, status, usage = os.wait4(process.pid, 0)
    after = children_cpu_s(usage) - used
    stderr = process.stderr.read()
    assert os.waitstatus_to_exitcode(status) == 130, stderr
    printed = json.loads(process.stdout.read())
    assert printed["status"] == INTERRUPTED and printed["output_dir"] == str(out.absolute())
    # What Ctrl-C costs: under a second of work. Its wall time, which a machine shared with the rest of the suite
    # stretches, benchmarks/bench_first_hour.py measures on a quiet one.
    assert after <= 1.0, f"{after:.2f} CPU-s after the signal"
    assert len(stderr.strip().splitlines()) == 1 and stderr.startswith("interrupted:"), stderr
    assert f"shakermill plot {out}" in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == INTERRUPTED and 0 < summary["summary"]["simulated_s"]
    assert not (out / "figures").exists()
    assert load_run(out).timeseries.sizes["time"] >= 1


@pytest.mark.slow
def test_real_ctrl_c_in_validate_says_so_in_one_line(start_up_s):
    process = subprocess.Popen(
        [str(SHAKERMILL), "validate", "--no-three-d"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    wait_for_cpu(process, start_up_s + 2.0)
    process.send_signal(signal.SIGINT)
    # Heard between bytecodes: on a fresh clone a compilation still running (Numba's, tens of seconds) comes first.
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130 and stdout == ""
    # What it is about to do, its steps as they end (piped: a line each), then the Ctrl-C.
    said, *steps, interrupted = stderr.strip().splitlines()
    assert all(step.startswith("validation: ") for step in steps), stderr
    assert said.startswith("validate: quick")
    assert interrupted.startswith("error: interrupted; nothing was written") and "Traceback" not in stderr


TINY_STEPS = [*(f"--set={key}={value}" for key, value in TIGHTEST_TOLERANCES.items()), "--set", "record_windows="]


@pytest.mark.slow
@pytest.mark.parametrize(
    "command, first_words",
    [
        (["run", "--set", "solver=full", "--no-plots", "--out", "{out}"], "interrupted:"),
        # Stopped in its mechanics or in the probe of its attractors (as the machine's load has it), the run is kept.
        (["run", "--set", "solver=averaged", "--no-plots", "--out", "{out}"], "interrupted: Interrupted by the user"),
        (["bifurcation", "--grid", "omega=100:120:2", "--out", "{out}"], "error: interrupted; nothing was written"),
        (
            ["calibrate", "--target", "theta_inf_C=100", "--free", "beta", "--out", "{out}.toml"],
            "error: interrupted; nothing was written",
        ),
    ],
    ids=["full run", "averaged run", "bifurcation", "calibrate"],
)
def test_real_ctrl_c_stops_a_run_stuck_on_tiny_steps_at_once(tmp_path, start_up_s, command, first_words):
    # Before the compiled loop handed control back within a chunk, the signal waited for the chunk's end.
    arguments = [argument.replace("{out}", str(tmp_path / "out")) for argument in command]
    stderr = interrupt_after([*arguments, *TINY_STEPS], start_up_s + 2.0)
    assert stderr.startswith(first_words)


@pytest.mark.slow
def test_a_run_that_uses_up_its_budget_keeps_its_folder_and_exits_1(tmp_path):
    out = tmp_path / "run"
    result = invoke("run", *SHORT, "--set", "max_steps=1000", "--no-plots", "--out", str(out))
    assert result.exit_code == 1
    assert "max_steps = 1000" in result.stdout  # the status row of the usual table
    errors = [line for line in result.stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "--set max_steps=2000" in errors[0] and str(out) in errors[0]
    summary = load_run(out).summary
    assert summary.status == -4 and summary.steps == 1000


@pytest.mark.slow
def test_run_onto_a_run_folder_is_refused_unless_overwrite(tmp_path):
    out = tmp_path / "run"
    assert invoke("run", *SHORT, "--no-plots", "--out", str(out)).exit_code == 0
    before = (out / "summary.json").read_text()
    refused = invoke("run", *SHORT, "--set", "duration=1", "--no-plots", "--out", str(out))
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, str(out), "holds a run already", "--overwrite")
    assert (out / "summary.json").read_text() == before
    replaced = invoke("run", *SHORT, "--set", "duration=1", "--no-plots", "--out", str(out), "--overwrite")
    assert replaced.exit_code == 0, replaced.stderr
    assert load_run(out).summary.simulated_s == 1.0


def test_overwrite_never_replaces_a_folder_shakermill_did_not_write(tmp_path):
    (tmp_path / "thesis.tex").write_text("precious")
    refused = invoke("run", *SHORT, "--no-plots", "--out", str(tmp_path), "--overwrite")
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, "not a shakermill run")
    assert [entry.name for entry in tmp_path.iterdir()] == ["thesis.tex"]


@pytest.mark.slow
def test_bifurcation_onto_a_non_empty_folder_is_refused_unless_overwrite(tmp_path):
    folder = tmp_path / "scan"
    folder.mkdir()
    (folder / "bifurcation_regimes.csv").write_text("earlier scan")
    arguments = ["bifurcation", *QUICK_BASE, "--grid", "omega=100:120:2", "--out", str(folder)]
    refused = invoke(*arguments)
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, str(folder), "holds a bifurcation scan already", "--overwrite")
    assert (folder / "bifurcation_regimes.csv").read_text() == "earlier scan"
    replaced = invoke(*arguments, "--overwrite")
    assert replaced.exit_code == 0, replaced.stderr
    assert pd.read_csv(folder / "bifurcation_regimes.csv")["omega"].tolist() == [100.0, 120.0]


def test_bifurcation_never_writes_into_a_folder_of_the_users_own(tmp_path):
    (tmp_path / "bifurcation_regimes.csv").write_text("earlier scan")
    (tmp_path / "thesis.tex").write_text("precious")
    refused = invoke("bifurcation", *QUICK_BASE, "--grid", "omega=100:120:2", "--out", str(tmp_path), "--overwrite")
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, str(tmp_path), "not a shakermill bifurcation scan")
    assert sorted(entry.name for entry in tmp_path.iterdir()) == ["bifurcation_regimes.csv", "thesis.tex"]
    assert (tmp_path / "bifurcation_regimes.csv").read_text() == "earlier scan"


@pytest.mark.slow
def test_report_onto_an_existing_file_is_refused_unless_overwrite(tmp_path):
    run_folder = tmp_path / "run"
    assert invoke("run", *SHORT, "--no-plots", "--out", str(run_folder)).exit_code == 0
    report = tmp_path / "report.html"
    report.write_text("an earlier report")
    refused = invoke("report", str(run_folder), "--out", str(report))
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, str(report), "exists", "--overwrite")
    assert report.read_text() == "an earlier report"
    replaced = invoke("report", str(run_folder), "--out", str(report), "--overwrite")
    assert replaced.exit_code == 0, replaced.stderr
    assert report.read_text().lstrip().lower().startswith("<!doctype html")


@pytest.mark.slow
def test_calibrate_onto_an_existing_preset_file_is_refused_unless_overwrite(tmp_path, monkeypatch):
    preset_file = tmp_path / "fitted.toml"
    preset_file.write_text("# an earlier fit\n")
    calibrate_module = importlib.import_module("shakermill.studies.calibration.calibrate")
    monkeypatch.setattr(calibrate_module, "calibrate", lambda *_args, **_kwargs: pytest.fail("must not fit"))
    arguments = ["calibrate", "--target", "theta_inf_C=100", "--free", "beta", "--out", str(preset_file)]
    refused = invoke(*arguments)
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, str(preset_file), "exists", "--overwrite")
    assert preset_file.read_text() == "# an earlier fit\n"
    monkeypatch.undo()
    replaced = invoke(*arguments, "--overwrite", "--json")
    assert replaced.exit_code == 0, replaced.stderr
    assert load_config(preset_file).params.beta == pytest.approx(json.loads(replaced.stdout)["fitted"]["beta"])


def test_ctrl_c_in_the_averaged_solver_says_so_in_one_line_and_writes_nothing(tmp_path, monkeypatch):
    def interrupted(*_args, **_kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(SIMULATE_MODULE, "simulate", interrupted)
    result = invoke("run", "--set", "solver=averaged", "--out", str(tmp_path / "run"))
    assert result.exit_code == 130
    assert_one_error_line(result.stderr, "interrupted; nothing was written")
    assert list(tmp_path.iterdir()) == []


# What a run without figures must not import: xarray's first Dataset imports dask and pint, and these
# together are most of a second of start-up (benchmarks/bench_startup.py). Figures and read-back use them.
NOT_FOR_A_RUN_WITHOUT_FIGURES = ("xarray", "pandas", "dask", "pint", "matplotlib", "distributed")


@pytest.mark.slow
def test_a_run_without_figures_writes_its_files_without_the_heavy_libraries(tmp_path):
    script = (
        "import sys\n"
        "from shakermill import cli\n"
        "sys.argv = ['shakermill', 'run', '--set', 'solver=averaged', '--set', 'duration=120', '--no-plots', '--out', "
        f"{str(tmp_path / 'run')!r}]\n"
        "try:\n"
        "    cli.app()\n"
        "except SystemExit as exit:\n"
        "    assert exit.code in (0, None), exit.code\n"
        f"print('imported:', *(name for name in {NOT_FOR_A_RUN_WITHOUT_FIGURES!r} if name in sys.modules))\n"
    )
    completed = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert completed.stdout.splitlines()[-1] == "imported:"
    run = load_run(tmp_path / "run")  # and what it wrote reads back as a full run's files do
    assert run.summary.solver == "averaged" and run.timeseries["theta_ball_C"].attrs["units"] == "degC"
    assert len(run.impacts) == len(run.impacts["wall"].dropna()) > 0


def test_a_run_of_a_calibrated_preset_reports_intervals_and_where_its_heat_goes(tmp_path):
    out = tmp_path / "calibrated"
    # A minute: longer than the least mechanics that averaging needs (18 s), so the run is averaged.
    averaged = ("--set", "solver=averaged", "--set", "duration=60")
    result = invoke("run", "--preset", "spex8000m-calibrated", *SHORT, *averaged, "--out", str(out), "--no-plots")
    assert result.exit_code == 0, result.stderr
    summary = load_run(out).summary
    assert summary.solver == "averaged"
    # Its held-out test is stored with the preset, and every run of it says what it found.
    assert summary.validation_caveat == PRESETS["spex8000m-calibrated"].caveat
    assert f"Caveat (spex8000m-calibrated): {PRESETS['spex8000m-calibrated'].caveat}" in " ".join(result.stdout.split())
    for key in ("ball_C", "vial_C", "ball_steady_C", "vial_steady_C"):
        assert summary.value(f"{key}_low") < summary.value(key) < summary.value(f"{key}_high"), key
    assert "covariance" in summary.intervals.note and "averaging error" in summary.intervals.note
    assert "90 % interval, ball at the end" in result.stdout
    paths = summary.heat_paths_W
    assert set(paths) == {"ball → air", "vial → air", "vial → room"}
    assert "heat path vial → room" in result.stdout
    # At the end of the run what the contacts give the vial and the ball has gone to the air, the room or stays.
    assert paths["vial → room"] > 0.0 and paths["ball → air"] > 0.0


def test_a_short_averaged_run_says_before_it_starts_that_it_runs_at_full_resolution(tmp_path):
    result = invoke(
        "run",
        "--preset",
        "spex8000m-calibrated",
        *SHORT,
        "--set",
        "solver=averaged",
        "--no-plots",
        "--out",
        str(tmp_path / "short"),
    )
    assert result.exit_code == 0, result.stderr
    first = result.stderr.splitlines()[0]
    assert first.startswith("note: Full resolution instead of the averaged solver: duration = 2 s is no longer than")
    assert result.stderr.count("Full resolution instead") == 1
    summary = load_run(tmp_path / "short").summary
    assert summary.solver == "full" and summary.message.startswith("Full resolution instead")
    # How the solver was chosen is a note of the run, said once on the terminal: before the run, not again under it.
    reason, length = summary.notes
    assert first == f"note: {reason}" and reason not in " ".join(result.stdout.split())
    # Advice, not a problem: the run's length is a sentence of the answer under the table, not a warning.
    assert not any("slowest time constant" in line for line in result.stderr.splitlines())
    assert "slowest time constant" in length and length in " ".join(result.stdout.split())


def test_a_run_of_an_uncalibrated_preset_reports_no_intervals(tmp_path):
    out = tmp_path / "plain"
    result = invoke("run", *SHORT, "--out", str(out), "--no-plots", "--json")
    assert result.exit_code == 0, result.stderr
    assert not any(key.endswith("_low") for key in json.loads(result.stdout))


def test_long_work_piped_into_a_log_says_how_far_it_is_at_most_every_interval(monkeypatch, capsys):
    """Issue 35: a calibration piped into a log ran 91 s and 1,379 evaluations without a line."""
    clock = [0.0]
    monkeypatch.setattr(cli_common.time, "monotonic", lambda: clock[0])
    update = cli_common.piped_lines("fitting", "{task.completed} model evaluations", interval_s=30.0)
    for evaluation, now in enumerate((1.0, 29.0, 31.0, 40.0, 62.0, 95.0), start=1):
        clock[0] = now
        update(evaluation)
    assert capsys.readouterr().err.splitlines() == [
        "fitting: 3 model evaluations, 0 min 31 s",
        "fitting: 5 model evaluations, 1 min 02 s",
        "fitting: 6 model evaluations, 1 min 35 s",
    ]
    sweep = cli_common.piped_lines(
        "sweep", "{task.completed}/{task.total} points · {task.fields[failed]} failed", 0.0, 4, failed=0
    )
    sweep(1, failed=1)
    assert capsys.readouterr().err == "sweep: 1/4 points · 1 failed, 0 min 00 s\n"
