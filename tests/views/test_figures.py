"""Figures: the expected files, real images, labelled axes with units, the fit drawn where it belongs."""

from __future__ import annotations

import dataclasses
import re
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.io.runs import load_run, write_run
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.views.figures.common import png_bytes, window_data
from shakermill.views.figures.impacts import IMPACT_FIGURES, impact_figures, rate_bin_edges
from shakermill.views.figures.run import (
    PAPER_FIGURES,
    heating_zoom_figure,
    heating_zoom_window,
    motion_figure,
    plot_run,
    run_figures,
    temperature_figure,
)
from shakermill.views.figures.sweeps import (
    SWEEP_QUANTITIES,
    bifurcation_figure,
    contour_notes,
    parse_contour,
    sweep_context,
    sweep_figures,
)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
ALL_FIGURES = ("ball_heating_zoom", "ball_motion", "temperatures")
IMPACT_FIGURE_NAMES = (
    "impact_energy_histogram",
    "impact_phase_histogram",
    "impact_speed_histogram",
    "impacts_per_second",
    "stress_energy_spectrum",
)
# "quantity (unit)": every axis label ends with its unit in parentheses.
LABEL_WITH_UNIT = re.compile(r"^\S.* \([^()]+\)$")


@pytest.fixture(scope="module")
def result() -> sm.Result:
    # Two windows, as the default preset has, shortened: the motion window and the heating-zoom window.
    return sm.simulate(sm.default_parameters(duration=2.0, record_windows="0:0.2,1:0.1"))


def png_size(path: Path) -> tuple[int, int]:
    header = path.read_bytes()[:24]
    assert header[:8] == PNG_SIGNATURE, f"{path.name} is not a PNG"
    return struct.unpack(">II", header[16:24])


def written_names(paths: list[Path]) -> list[str]:
    return sorted(path.name for path in paths)


@pytest.mark.slow
def test_plot_run_writes_png_and_svg_of_every_figure(result, tmp_path):
    paths = plot_run(result, tmp_path / "figures")
    expected = sorted(f"{name}.{fmt}" for name in ALL_FIGURES for fmt in ("png", "svg"))
    assert written_names(paths) == expected
    assert sorted(entry.name for entry in (tmp_path / "figures").iterdir()) == expected  # no temporary files left
    for path in paths:
        if path.suffix == ".png":
            width, height = png_size(path)
            assert width > 600 and height > 400
            assert path.stat().st_size > 20_000
        else:
            assert path.read_text(encoding="utf-8").lstrip().startswith("<?xml")
            assert "<svg" in path.read_text(encoding="utf-8")


@pytest.mark.slow
def test_without_windows_only_the_temperature_figure_is_drawn(tmp_path):
    run = sm.simulate(sm.default_parameters(duration=2.0, record_windows=()))
    assert written_names(plot_run(run, tmp_path)) == ["temperatures.png", "temperatures.svg"]


@pytest.mark.slow
def test_figures_can_be_drawn_from_a_stored_run(result, tmp_path):
    folder = write_run(result, tmp_path / "run", preset=DEFAULT_PRESET)
    paths = plot_run(load_run(folder), tmp_path / "from_disk")
    assert {path.stem for path in paths} == set(ALL_FIGURES)


@pytest.fixture(scope="module")
def hour() -> sm.Result:
    """An averaged hour: longer than the network's slowest time constant, so its exponential is drawn."""
    return sm.simulate(sm.default_parameters(solver="averaged", record_windows=()))


def test_temperature_figure_shows_celsius_minutes_and_the_fit(hour):
    result = hour
    figure = temperature_figure(result)
    (axis,) = figure.axes
    assert axis.get_xlabel() == "time (min)"
    assert axis.get_ylabel() == "temperature (°C)"
    lines = {line.get_label(): line for line in axis.get_lines()}
    minutes = result.timeseries["time"].values / 60.0
    np.testing.assert_allclose(lines["ball"].get_xdata(), minutes)
    np.testing.assert_allclose(lines["vial"].get_ydata(), result.timeseries["theta_vial"].values - 273.15)
    window = f"0–{minutes[-1]:.3g} min"
    fit_line = lines[f"ball, exponential fitted over {window}"]
    assert fit_line.get_linestyle() == "--"
    steady = result.summary.ball_steady_C
    (steady_line,) = [line for label, line in lines.items() if label.startswith("ball steady state")]
    np.testing.assert_allclose(steady_line.get_ydata(), [steady, steady])
    assert f"{steady:.1f} °C" in steady_line.get_label()
    np.testing.assert_allclose(
        fit_line.get_ydata(), result.ball_fit.evaluate(result.timeseries["time"].values) - 273.15
    )
    box = "\n".join(text.get_text() for text in axis.texts)
    assert f"{result.ball_fit.theta_inf - 273.15:.2f} °C" in box
    assert f"{result.ball_fit.tau / 60:.2f} min" in box


def test_motion_figure_has_two_labelled_axes_and_the_contact_limits(result):
    window = window_data(result, 0)
    assert float(window["time"].max()) <= 0.2
    figure = motion_figure(result.params, window)
    position_axis, momentum_axis = figure.axes
    assert position_axis.get_ylabel() == "position (mm)"
    assert momentum_axis.get_ylabel() == "momentum (kg·m/s)"
    assert momentum_axis.get_xlabel() == "time (s)"
    ball, lower, upper = position_axis.get_lines()
    np.testing.assert_allclose(ball.get_ydata(), window["x"].values * 1e3)
    # The ball centre stays between the contact positions, up to the contact overlap (< 5 % of R).
    reach_mm = (result.params.vial_length / 2 - result.params.ball_radius) * 1e3
    np.testing.assert_allclose(upper.get_ydata() - lower.get_ydata(), 2 * reach_mm)
    tolerance_mm = 0.05 * result.params.ball_radius * 1e3
    lower_at_ball = np.interp(ball.get_xdata(), lower.get_xdata(), lower.get_ydata())
    assert np.all(ball.get_ydata() >= lower_at_ball - tolerance_mm)


def test_heating_zoom_uses_the_window_nearest_ten_minutes_and_marks_its_impacts(result):
    index = heating_zoom_window(result.params)
    assert index == 1  # starts at 1 s, nearer to 600 s than the window at 0 s
    window = window_data(result, index)
    figure = heating_zoom_figure(result, window, start=1.0)
    (axis,) = figure.axes
    assert axis.get_xlabel() == "time after t = 1 s (ms)"
    assert axis.get_ylabel() == "ball temperature (°C)"
    impact_times = result.impacts["time"].to_numpy()
    inside = int(np.count_nonzero((impact_times >= 1.0) & (impact_times <= float(window["time"].max()))))
    assert inside > 0
    assert len(axis.get_lines()) == 1 + inside  # the temperature and one marker per impact
    temperature = axis.get_lines()[0].get_ydata()
    assert temperature[-1] > temperature[0]  # the impacts heat the ball


def test_window_without_enough_points_is_skipped(result):
    params = result.params.replace(record_windows=((0.0, 0.2), (600.0, 0.1)))
    run = dataclasses.replace(result, params=params)
    assert window_data(run, 1) is None
    assert window_data(run, 2) is None


def all_axes(figures):
    return [(name, axis) for name, figure in figures.items() for axis in figure.axes]


def test_figure_names_are_the_documented_ones():
    assert sorted(PAPER_FIGURES) == sorted(ALL_FIGURES)
    assert sorted(IMPACT_FIGURES) == sorted(IMPACT_FIGURE_NAMES)


@pytest.mark.slow
def test_every_axis_of_every_figure_is_labelled_with_its_unit(result):
    figures = run_figures(result, impacts=True)
    assert sorted(figures) == sorted(ALL_FIGURES + IMPACT_FIGURE_NAMES)
    for name, axis in all_axes(figures):
        # Shared time axes label only the bottom panel.
        xlabel_expected = axis.get_subplotspec().is_last_row()
        if xlabel_expected:
            assert LABEL_WITH_UNIT.match(axis.get_xlabel()), (name, axis.get_xlabel())
        assert LABEL_WITH_UNIT.match(axis.get_ylabel()), (name, axis.get_ylabel())
    temperature_labels = [axis.get_ylabel() for name, axis in all_axes(figures) if "temperature" in axis.get_ylabel()]
    assert temperature_labels and all(label.endswith("(°C)") for label in temperature_labels)


def test_paper_figures_say_which_figure_of_the_paper_they_are(result):
    figures = run_figures(result)
    assert "Fig. 5a" in figures["temperatures"].axes[0].get_title()
    assert "Fig. 4" in figures["ball_motion"].get_suptitle()
    assert "t = 0–0.2 s" in figures["ball_motion"].get_suptitle()  # the record window, not the last stored step
    assert "Fig. 5b" in figures["ball_heating_zoom"].axes[0].get_title()


@pytest.mark.slow
def test_plot_run_with_impacts_writes_the_impact_figures_too(result, tmp_path):
    paths = plot_run(result, tmp_path, impacts=True)
    expected = sorted(f"{name}.{fmt}" for name in ALL_FIGURES + IMPACT_FIGURE_NAMES for fmt in ("png", "svg"))
    assert written_names(paths) == expected


@pytest.mark.slow
def test_impact_histograms_count_every_impact_by_wall(result):
    figures = impact_figures(result)
    impacts = result.impacts
    for name, column, scale in (
        ("impact_speed_histogram", "impact_speed", 1.0),
        ("impact_energy_histogram", "dissipated_energy", 1e3),
    ):
        (axis,) = figures[name].axes
        assert sum(patch.get_height() for patch in axis.patches) == len(impacts)
        edges = [patch.get_x() for patch in axis.patches]
        assert min(edges) == pytest.approx(impacts[column].min() * scale)
        labels = [text.get_text() for text in axis.get_legend().get_texts()]
        assert labels == [
            f"left end face ({(impacts['wall'] == 'left').sum()})",
            f"right end face ({(impacts['wall'] == 'right').sum()})",
        ]
    assert figures["impact_energy_histogram"].axes[0].get_xlabel() == "energy dissipated per impact (mJ)"
    assert figures["impact_speed_histogram"].axes[0].get_xlabel() == "impact speed relative to the end face (m/s)"


@pytest.mark.slow
def test_impacts_per_second_integrate_to_the_impacts_at_each_wall(result):
    (axis,) = impact_figures(result)["impacts_per_second"].axes
    assert axis.get_ylabel() == "impacts per second (1/s)"
    assert axis.get_xlabel() == "time (s)"
    steps = axis.patches
    assert len(steps) == 2
    for wall, step in zip(("left", "right"), steps):
        rates, edges, _ = step.get_data()
        assert np.sum(rates * np.diff(edges)) == pytest.approx((result.impacts["wall"] == wall).sum())


@pytest.mark.slow
def test_the_stress_spectrum_counts_every_impact_and_its_power_at_the_lowest_energy(result):
    events, power = impact_figures(result)["stress_energy_spectrum"].axes[:2]
    window = result.summary.stress_window_s
    # One ball on the axis: the total and its normal part, which is all of it; no tangential part, no ball hit.
    assert [line.get_label() for line in events.get_lines() if not line.get_label().startswith("_")] == [
        "all impacts, normal + tangential",
        "normal part",
    ]
    total_events, total_power = events.get_lines()[0], power.get_lines()[0]
    assert total_events.get_ydata()[0] == pytest.approx(len(result.impacts) / window)
    assert total_power.get_ydata()[0] == pytest.approx(result.impacts["dissipated_energy"].sum() / window)
    assert np.all(np.diff(total_events.get_ydata()) <= 0) and np.all(np.diff(total_power.get_ydata()) <= 0)
    assert events.get_xscale() == "log" and events.get_xlabel() == "stress energy E, dissipated per impact (J)"
    # The thresholds of the run, dash-dot.
    assert sorted(line.get_xdata()[0] for line in power.get_lines() if line.get_linestyle() == "-.") == sorted(
        result.params.stress_energy_thresholds
    )


def test_rate_bins_span_the_impacts_in_bins_of_at_least_a_second_and_at_most_120():
    assert np.allclose(np.diff(rate_bin_edges(0.0, 30.0)), 1.0)
    hour = rate_bin_edges(0.01, 3600.0)
    assert len(hour) == 121 and hour[0] == 0.01 and hour[-1] == 3600.0
    assert rate_bin_edges(3.6, 18.1)[0] == 3.6  # the averaged solver's impacts start after its transient
    assert np.allclose(rate_bin_edges(0.1, 0.4), [0.1, 1.1])  # one bin of a second for a very short run


def test_no_impacts_no_impact_figures(result):
    run = dataclasses.replace(
        result, impact_columns={name: values[:0] for name, values in result.impact_columns.items()}
    )
    assert impact_figures(run) == {}


def test_a_run_shorter_than_the_slowest_time_constant_draws_no_exponential_and_says_why(result):
    """Issue 37, point 4: a fitted exponential that misses the curve was drawn as a headline."""
    assert result.summary.exponential_fit_describes_run is False
    (axis,) = temperature_figure(result).axes
    assert not [line for line in axis.get_lines() if "exponential" in line.get_label()]
    box = "\n".join(text.get_text() for text in axis.texts)
    slowest = result.summary.slowest_time_constant_min
    assert box.startswith("no exponential: the run") and f"({slowest:.3g} min)" in box


def test_ball_only_temperature_figure_draws_vial_and_air_as_one_ambient_line(hour):
    run = dataclasses.replace(hour, params=hour.params.replace(model="ball_only"))
    (axis,) = temperature_figure(run).axes
    labels = [line.get_label() for line in axis.get_lines()]
    assert labels[:2] == ["ball", "vial and air (held at ambient: ball_only model)"]
    assert labels[2].startswith("ball, exponential fitted over 0–")


@pytest.mark.slow
def test_png_bytes_is_a_png(result):
    assert png_bytes(temperature_figure(result), dpi=50).startswith(PNG_SIGNATURE)


@pytest.mark.slow
def test_matplotlib_is_imported_lazily_and_pyplot_never():
    script = (
        "import sys\n"
        "import shakermill as sm, shakermill.cli, shakermill.views.report\n"
        "assert 'matplotlib' not in sys.modules, 'imported at package import'\n"
        "from shakermill.views.figures.run import run_figures\n"
        "run = sm.simulate(sm.default_parameters(duration=0.5, record_windows='0:0.2'))\n"
        "run_figures(run, impacts=True)\n"
        "assert 'matplotlib' in sys.modules\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot imported'\n"
    )
    completed = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr


runner = CliRunner()


@pytest.mark.slow
def test_plot_command_writes_every_figure_into_the_run_folder(result, tmp_path):
    folder = write_run(result, tmp_path / "run", preset=DEFAULT_PRESET)
    outcome = runner.invoke(cli.app, ["plot", str(folder)])
    assert outcome.exit_code == 0, outcome.stderr
    figures = folder / "figures"
    expected = sorted(f"{name}.{fmt}" for name in ALL_FIGURES + IMPACT_FIGURE_NAMES for fmt in ("png", "svg"))
    assert sorted(path.name for path in figures.iterdir()) == expected
    for path in figures.iterdir():
        assert path.stat().st_size > 10_000, path.name
        if path.suffix == ".png":
            width, height = png_size(path)
            assert width > 600 and height > 300
    assert str(figures) in outcome.stdout


@pytest.mark.slow
def test_plot_command_out_and_dpi(result, tmp_path):
    folder = write_run(result, tmp_path / "run", preset=DEFAULT_PRESET)
    outcome = runner.invoke(cli.app, ["plot", str(folder), "--out", str(tmp_path / "small"), "--dpi", "60"])
    assert outcome.exit_code == 0, outcome.stderr
    width, _ = png_size(tmp_path / "small" / "temperatures.png")
    assert width < 600
    assert not (folder / "figures").exists()


@pytest.mark.parametrize("existing", [False, True])
def test_plot_command_refuses_a_folder_that_is_not_a_run(tmp_path, existing):
    folder = tmp_path / "nothing_here"
    if existing:
        folder.mkdir()
    outcome = runner.invoke(cli.app, ["plot", str(folder)])
    assert outcome.exit_code == 2
    lines = outcome.stderr.strip().splitlines()
    expected = "not a shakermill run folder (no summary.json)" if existing else "no such folder"
    assert len(lines) == 1 and lines[0].startswith("error: ") and expected in lines[0]
    assert not (folder / "figures").exists()


def test_plot_command_refuses_a_damaged_run_folder(result, tmp_path):
    folder = write_run(result, tmp_path / "run", preset=DEFAULT_PRESET)
    (folder / "timeseries.nc").unlink()
    outcome = runner.invoke(cli.app, ["plot", str(folder)])
    assert outcome.exit_code == 2
    lines = outcome.stderr.strip().splitlines()
    assert len(lines) == 1 and "not a readable shakermill run folder" in lines[0] and "Traceback" not in outcome.stderr


# Impact phases, sweeps and the bifurcation diagram -------------------------------------------------


@pytest.mark.slow
def test_impact_phase_histogram_counts_the_settled_impacts_by_wall(result):
    (axis,) = impact_figures(result)["impact_phase_histogram"].axes
    settled = result.impacts[result.impacts["time"] >= 0.5 * result.t_end]  # a full run: its second half
    assert sum(patch.get_height() for patch in axis.patches) == len(settled)
    labels = [text.get_text() for text in axis.get_legend().get_texts()]
    assert labels == [f"{name} end face ({(settled['wall'] == name).sum()})" for name in ("left", "right")]
    assert [tick.get_text() for tick in axis.get_xticklabels()] == ["0", "π/2", "π", "3π/2", "2π"]
    assert axis.get_xlim() == pytest.approx((0.0, 2 * np.pi))
    assert f"{len(settled)} impacts" in axis.get_title()


@pytest.mark.slow
def test_plot_command_impacts_draws_only_the_impact_figures(result, tmp_path):
    folder = write_run(result, tmp_path / "run", preset=DEFAULT_PRESET)
    outcome = runner.invoke(cli.app, ["plot", str(folder), "--impacts", "--out", str(tmp_path / "impacts")])
    assert outcome.exit_code == 0, outcome.stderr
    expected = sorted(f"{name}.{fmt}" for name in IMPACT_FIGURE_NAMES for fmt in ("png", "svg"))
    assert sorted(path.name for path in (tmp_path / "impacts").iterdir()) == expected


def synthetic_sweep(failed_index: int | None = None) -> pd.DataFrame:
    """A 3 × 2 grid over omega and amplitude whose results are simple functions of the two keys."""
    omega, amplitude = np.meshgrid([90.0, 110.0, 130.0], [0.024, 0.028], indexing="ij")
    table = pd.DataFrame({"omega": omega.ravel(), "amplitude": amplitude.ravel()})
    table["theta_inf_C"] = table["omega"] - 40.0 + 1000.0 * (table["amplitude"] - 0.024)  # 50 … 94 °C
    for column, _, _ in SWEEP_QUANTITIES[1:]:
        table[column] = table["omega"] / 100.0
    table["regime"] = ["period-1", "period-2", "period-2", "irregular", "period-1", "period-2"]
    table["error"] = None
    if failed_index is not None:
        table.loc[failed_index, "error"] = "restitution: 2 is out of range"
    return table


@pytest.mark.slow
def test_sweep_maps_fill_the_grid_and_blank_the_failed_point():
    table = synthetic_sweep(failed_index=3)
    figures = sweep_figures(table, ("omega", "amplitude"))
    assert sorted(figures) == sorted([f"sweep_{column}" for column, _, _ in SWEEP_QUANTITIES] + ["sweep_regime"])
    axis, colourbar = figures["sweep_theta_inf_C"].axes
    assert axis.get_xlabel() == "omega (rad/s)" and axis.get_ylabel() == "amplitude (mm)"
    assert colourbar.get_ylabel() == "ball θ∞ of the exponential fitted over the run (°C)"
    mesh, missing = axis.collections
    cells = mesh.get_array()
    # Rows are amplitudes, columns omegas; the failed point (omega 110, amplitude 28 mm) is masked.
    expected = np.array([[50.0, 70.0, 90.0], [54.0, np.nan, 94.0]])
    np.testing.assert_allclose(np.ma.filled(cells, np.nan).reshape(2, 3), expected)
    assert cells.mask.reshape(2, 3)[1, 1] and cells.mask.sum() == 1
    # And marked, so that the blank cell reads as a missing point, not as a colour of the map.
    np.testing.assert_allclose(missing.get_offsets(), [[110.0, 28.0]])
    assert axis.get_legend().get_texts()[0].get_text() == "failed or no value (1)"
    # Cell edges half-way between the grid values, in mm on the amplitude axis.
    assert axis.get_ylim() == pytest.approx((22.0, 30.0))


@pytest.mark.slow
def test_sweep_contour_is_drawn_at_its_level_on_every_map():
    table = synthetic_sweep()
    figures = sweep_figures(table, ("omega", "amplitude"), [("theta_inf_C", 60.0)])
    for name in ("sweep_theta_inf_C", "sweep_impact_rate_hz"):
        axis = figures[name].axes[0]
        contours = [collection for collection in axis.collections if hasattr(collection, "levels")]
        assert len(contours) == 1 and list(contours[0].levels) == [60.0]
        vertices = np.concatenate([path.vertices for path in contours[0].get_paths()])
        # θ∞ = omega − 40 + 1000 (amplitude − 0.024): 60 °C at omega = 100 − 1000 (amplitude − 0.024).
        np.testing.assert_allclose(vertices[:, 0], 100.0 - (vertices[:, 1] / 1e3 - 0.024) * 1e3, atol=1e-9)


@pytest.mark.slow
def test_a_contour_level_outside_the_values_is_said_on_every_figure_not_drawn():
    # θ∞ is 50 … 94 °C; with the failed point (omega 130, amplitude 28 mm: 94 °C) left out, 90 is the top.
    table = synthetic_sweep(failed_index=5)
    contours = [("theta_inf_C", 40.0), ("theta_inf_C", 92.0), ("theta_inf_C", 60.0)]
    notes = contour_notes(table, contours)
    assert notes == [
        "theta_inf_C = 40 not crossed: theta_inf_C is 50 to 90, above it at every point",
        "theta_inf_C = 92 not crossed: theta_inf_C is 50 to 90, below it at every point",
    ]
    for keys, frame in ((("omega", "amplitude"), table), (("omega",), table[table["amplitude"] == 0.024])):
        figures = sweep_figures(frame.drop(columns=[] if len(keys) == 2 else ["amplitude"]), keys, contours)
        for column, _, _ in SWEEP_QUANTITIES:
            axis = figures[f"sweep_{column}"].axes[0]
            texts = [text.get_text() for text in axis.texts]
            assert any("theta_inf_C = 40 not crossed" in text for text in texts), (keys, column, texts)
    # Every level crossed: no note.
    assert contour_notes(table, [("theta_inf_C", 60.0)]) == []
    crossed = sweep_figures(table, ("omega", "amplitude"), [("theta_inf_C", 60.0)])["sweep_tau_min"].axes[0]
    # The contour's own label: the quantity's name and unit, not the column's name.
    assert [text.get_text() for text in crossed.texts] == ["ball θ∞ = 60 °C"]
    assert contour_notes(synthetic_sweep().assign(error="failed"), [("tau_min", 1.0)]) == [
        "tau_min = 1: no finished point has a value"
    ]


def test_one_key_sweep_is_a_line_with_the_contour_crossing_marked():
    table = synthetic_sweep().iloc[[4, 0, 2]].assign(regime="period-1")  # amplitude 24 mm only, out of order
    figures = sweep_figures(table.drop(columns="amplitude"), ("omega",), [("theta_inf_C", 60.0)])
    (axis,) = figures["sweep_theta_inf_C"].axes
    curve, crossing, level = axis.get_lines()[:3]
    np.testing.assert_allclose(curve.get_xdata(), [90.0, 110.0, 130.0])
    np.testing.assert_allclose(curve.get_ydata(), [50.0, 70.0, 90.0])
    assert crossing.get_xdata()[0] == pytest.approx(100.0)  # linear between (90, 50) and (110, 70)
    assert level.get_ydata()[0] == pytest.approx(60.0)
    assert axis.get_legend().get_texts()[0].get_text() == "ball θ∞ = 60 °C"
    assert (
        axis.get_xlabel() == "omega (rad/s)"
        and axis.get_ylabel() == "ball θ∞ of the exponential fitted over the run (°C)"
    )


@pytest.mark.slow
def test_regime_map_counts_each_regime_and_the_failed_points():
    figures = sweep_figures(synthetic_sweep(failed_index=0), ("omega", "amplitude"))
    (axis,) = figures["sweep_regime"].axes
    labels = [text.get_text() for text in axis.get_legend().get_texts()]
    assert labels == ["period-1 (1)", "period-2 (3)", "irregular (1)", "failed (1)"]


def test_regime_map_frames_the_points_with_more_than_one_attractor():
    table = synthetic_sweep(failed_index=0)
    table["n_attractors"] = pd.array([None, 1, 2, 1, 3, 1], dtype="Int64")
    (axis,) = sweep_figures(table, ("omega", "amplitude"))["sweep_regime"].axes
    assert [text.get_text() for text in axis.get_legend().get_texts()][-1] == "more than one attractor (2)"
    framed = axis.collections[-1].get_offsets()
    np.testing.assert_allclose(framed, [[110.0, 24.0], [130.0, 24.0]])


def test_sweeps_over_three_keys_are_refused_with_one_line():
    with pytest.raises(sm.ParameterError, match="3 keys"):
        sweep_figures(synthetic_sweep(), ("omega", "amplitude", "restitution"))


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("theta_inf_C", "expected COLUMN=VALUE"),
        ("nope=3", "nope is not a numeric column"),
        ("theta_inf_C=hot", "not a number"),
    ],
)
def test_bad_contours_name_the_problem(spec, message):
    with pytest.raises(sm.ParameterError, match=message):
        parse_contour(spec, ["theta_inf_C", "tau_min"])
    assert parse_contour(" theta_inf_C = 60 ", ["theta_inf_C"]) == ("theta_inf_C", 60.0)


@pytest.mark.slow
def test_bifurcation_figure_plots_every_phase_and_the_periods_of_every_attractor():
    phases = pd.DataFrame(
        {
            "omega": [100.0, 100.0, 100.0, 110.0, 110.0],
            "start": [0, 0, 1, 0, 0],
            "attractor": [0, 0, 1, 0, 0],
            "phase": [0.5, 4.0, 5.9, 1.0, 3.0],
            "wall": ["left", "right", "left", "left", "right"],
        }
    )
    attractors = pd.DataFrame(
        {
            "omega": [100.0, 100.0, 110.0],
            "attractor": [0, 1, 0],
            "regime": ["period-1", "period-2", "irregular"],
            "period": pd.array([1, 2, None], dtype="Int64"),
            "basin_fraction": [0.75, 0.25, 1.0],
        }
    )
    figure = bifurcation_figure(phases, attractors, "omega")
    phase_axis, period_axis = figure.axes
    # One scatter per attractor and end face: attractor 0 left, right; attractor 1 left, right.
    first_left, first_right, second_left, second_right = phase_axis.collections
    np.testing.assert_allclose(first_left.get_offsets()[:, 1], [0.5, 1.0])
    np.testing.assert_allclose(first_right.get_offsets()[:, 1], [4.0, 3.0])
    np.testing.assert_allclose(second_left.get_offsets()[:, 1], [5.9])
    assert len(second_right.get_offsets()) == 0
    assert not np.allclose(first_left.get_edgecolor()[0], second_left.get_edgecolor()[0])
    legend = [text.get_text() for text in phase_axis.get_legend().get_texts()]
    assert legend == ["attractor 0 (configured start)", "attractor 1", "left end face", "right end face"]
    assert phase_axis.get_ylim() == pytest.approx((0.0, 2 * np.pi))
    (periods,) = period_axis.collections
    # Irregular motion is drawn one above the largest period; marker area follows the basin fraction.
    np.testing.assert_allclose(periods.get_offsets(), [[100.0, 1.0], [100.0, 2.0], [110.0, 3.0]])
    sizes = periods.get_sizes()
    assert sizes[0] == pytest.approx(3 * sizes[1]) and sizes[2] == pytest.approx(4 * sizes[1])
    assert period_axis.get_xlabel() == "omega (rad/s)"
    assert period_axis.get_ylabel().startswith("period n (drive periods)")
    # The irregular row is named, not numbered "3", and ruled off from the periods.
    assert [label.get_text() for label in period_axis.get_yticklabels()] == ["1", "2", "irregular"]
    (rule,) = period_axis.get_lines()
    assert rule.get_ydata()[0] == pytest.approx(2.5)
    assert [child.get_xlabel() for child in period_axis.child_axes] == ["drive frequency (rpm)"]
    titled = bifurcation_figure(phases, attractors, "omega", context="spex8000m, 60 min, averaged solver")
    assert titled.get_suptitle().endswith("\nspex8000m, 60 min, averaged solver")
    assert phase_axis.get_ylabel() == "impact phase ωt + φ mod 2π (rad)"


def test_one_key_sweep_lines_break_where_the_regime_changes_and_mark_the_missing_points():
    table = synthetic_sweep(failed_index=4).iloc[[0, 2, 4]].drop(columns="amplitude")  # amplitude 24 mm
    table["regime"] = ["period-1", "period-2", "period-2"]
    table.loc[2, "tau_min"] = np.nan  # finished, but without a value
    figures = sweep_figures(table, ("omega",))
    (axis,) = figures["sweep_theta_inf_C"].axes
    curve = axis.get_lines()[0]
    # A NaN between omega 90 (period-1) and 110 (period-2), and before the failed point: no line joins regimes.
    np.testing.assert_allclose(curve.get_xdata(), [90.0, np.nan, 110.0, np.nan, 130.0])
    np.testing.assert_allclose(curve.get_ydata(), [50.0, np.nan, 70.0, np.nan, np.nan])
    (missing,) = axis.collections
    assert missing.get_offsets()[:, 0].tolist() == [130.0]  # the failed point
    (axis,) = figures["sweep_tau_min"].axes
    assert axis.collections[0].get_offsets()[:, 0].tolist() == [110.0, 130.0]
    assert axis.get_legend().get_texts()[0].get_text() == "failed or no value (2)"


def test_a_sweep_over_a_named_key_has_one_tick_per_name():
    # A points file may sweep the solver: its values are names, drawn one tick apart in sorted order.
    table = synthetic_sweep().iloc[[0, 2, 4]].drop(columns="amplitude")
    table["solver"] = ["full", "averaged", "full"]
    table["regime"] = "period-1"
    table = table.drop(columns="omega")
    (axis,) = sweep_figures(table, ("solver",))["sweep_theta_inf_C"].axes
    assert [tick.get_text() for tick in axis.get_xticklabels()] == ["averaged", "full"]
    assert axis.get_lines()[0].get_xdata().tolist() == [0.0, 1.0, 1.0]
    assert axis.get_xlabel() == "solver (–)"


@pytest.mark.slow
def test_a_map_over_a_named_and_a_numeric_key_fills_its_grid():
    table = synthetic_sweep()
    table["model"] = table["amplitude"].map({0.024: "three_node", 0.028: "ball_only"})
    table = table.drop(columns="amplitude")
    figures = sweep_figures(table, ("omega", "model"))
    axis, _ = figures["sweep_theta_inf_C"].axes
    assert [tick.get_text() for tick in axis.get_yticklabels()] == ["ball_only", "three_node"]
    cells = np.ma.filled(axis.collections[0].get_array(), np.nan).reshape(2, 3)
    np.testing.assert_allclose(cells, [[54.0, 74.0, 94.0], [50.0, 70.0, 90.0]])  # ball_only (28 mm) first
    (regime_axis,) = figures["sweep_regime"].axes
    assert [tick.get_text() for tick in regime_axis.get_yticklabels()] == ["ball_only", "three_node"]


@pytest.mark.slow
def test_omega_axes_also_read_in_rpm():
    figures = sweep_figures(synthetic_sweep(), ("amplitude", "omega"))
    axis = figures["sweep_theta_inf_C"].axes[0]
    (secondary,) = axis.child_axes
    assert secondary.get_ylabel() == "drive frequency (rpm)"
    # 111 rad/s is the SPEX 8000M's 1060 rpm.
    assert secondary.yaxis.get_transform().inverted().transform(111.0) == pytest.approx(111.0 * 60 / (2 * np.pi))
    line = sweep_figures(synthetic_sweep().iloc[[0, 2, 4]].drop(columns="amplitude"), ("omega",))
    assert [child.get_xlabel() for child in line["sweep_regime"].axes[0].child_axes] == ["drive frequency (rpm)"]
    assert sweep_figures(synthetic_sweep(), ("omega", "amplitude"))["sweep_tau_min"].axes[0].child_axes[
        0
    ].get_xlabel() == ("drive frequency (rpm)")


def test_sweep_titles_carry_the_preset_and_duration():
    manifest = {"preset": "spex8000m-calibrated", "base": {"duration": 3600.0, "solver": "averaged"}}
    context = sweep_context(manifest, ("omega", "amplitude"))
    assert context == "spex8000m-calibrated, 60 min, averaged solver"
    assert sweep_context(manifest, ("duration",)) == "spex8000m-calibrated, averaged solver"
    figures = sweep_figures(synthetic_sweep(), ("omega", "amplitude"), context=context)
    for name, figure in figures.items():
        assert figure.axes[0].get_title().endswith("\n" + context), name


@pytest.mark.slow
def test_run_figures_name_the_run_and_averaged_impact_figures_their_window(tmp_path):
    params = sm.default_parameters(solver="averaged", duration=600.0)
    run = load_run(write_run(sm.simulate(params), tmp_path / "run", preset="spex8000m"))
    figures = run_figures(run, impacts=True)
    window = f"impacts of the {run.summary.averaging.window_s:.3g} s averaging window only"
    for name, figure in figures.items():
        title = figure.get_suptitle() or figure.axes[0].get_title()
        assert "spex8000m, 10 min, averaged solver" in title, name
        assert (window in title) == (name in IMPACT_FIGURES), name
