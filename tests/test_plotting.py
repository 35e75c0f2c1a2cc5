"""Figures: the expected files, real images, labelled axes with units, the fit drawn where it belongs."""

from __future__ import annotations

import dataclasses
import struct
from pathlib import Path

import numpy as np
import pytest

import shakermill as sm
from shakermill.params import DEFAULT_PRESET
from shakermill.plotting import (
    heating_zoom_figure,
    heating_zoom_window,
    motion_figure,
    plot_run,
    temperature_figure,
    window_data,
)
from shakermill.storage import load_run, write_run

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
ALL_FIGURES = ("ball_heating_zoom", "ball_motion", "temperatures")


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


def test_without_windows_only_the_temperature_figure_is_drawn(tmp_path):
    run = sm.simulate(sm.default_parameters(duration=2.0, record_windows=()))
    assert written_names(plot_run(run, tmp_path)) == ["temperatures.png", "temperatures.svg"]


def test_figures_can_be_drawn_from_a_stored_run(result, tmp_path):
    folder = write_run(result, tmp_path / "run", preset=DEFAULT_PRESET)
    paths = plot_run(load_run(folder), tmp_path / "from_disk")
    assert {path.stem for path in paths} == set(ALL_FIGURES)


def test_temperature_figure_shows_celsius_minutes_and_the_fit(result):
    figure = temperature_figure(result)
    (axis,) = figure.axes
    assert axis.get_xlabel() == "time (min)"
    assert axis.get_ylabel() == "temperature (°C)"
    lines = {line.get_label(): line for line in axis.get_lines()}
    minutes = result.timeseries["time"].values / 60.0
    np.testing.assert_allclose(lines["ball"].get_xdata(), minutes)
    np.testing.assert_allclose(lines["vial"].get_ydata(), result.timeseries["theta_vial"].values - 273.15)
    fit_line = lines["ball, exponential fit"]
    assert fit_line.get_linestyle() == "--"
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
