"""Figures, report and notebook views of the 'dem' engine: the balls' paths in the vial frame, a line per
ball, the heat by channel, the animation, and no figure that only means something for one ball on the axis."""

from __future__ import annotations

import dataclasses
import io
import re

import numpy as np
import pandas as pd
import pytest
from PIL import Image
from scipy.spatial.transform import Rotation

import shakermill as sm
from shakermill.io.runs import load_run, write_run
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.errors import ParameterError
from shakermill.views.figures.common import window_data
from shakermill.views.figures.impacts import TARGETS, impact_figures, run_contacts
from shakermill.views.figures.run import (
    SEVERAL_BALL_FIGURES,
    heat_by_channel_figure,
    run_figures,
    temperature_figure,
    write_animation,
)
from shakermill.views.report import render_report
from shakermill.views.trajectories import ANIMATION_SIZE_INCHES, MOST_ANIMATION_FRAMES, animation_gif, vial_frame

# Every test here reads a run made once for the module: make test-fast leaves them out.
pytestmark = pytest.mark.slow

# A vial that yaws, pitches and rolls while it strokes: a figure drawn in the lab frame, or with the rotation
# applied the wrong way round, puts the balls millimetres outside the vial.
ROTATING_MOTION = "x:1:0:25 mm, y:2:0:5 mm, yaw:1:0:0.3, pitch:1:0.05:0, roll:2:0:0.1"
CHANNELS = ("normal", "tangential", "sliding", "rolling")
LABEL_WITH_UNIT = re.compile(r"^\S.* \([^()]+\)$")


@pytest.fixture(scope="module")
def result() -> sm.Result:
    params = sm.default_parameters(
        engine="dem",
        n_balls=3,
        vial_diameter=0.038,
        duration=2.0,
        kinematics="fourier",
        motion=ROTATING_MOTION,
        record_windows="0:0.5,1.5:0.1",
    )
    return sm.simulate(params)


@pytest.fixture(scope="module")
def stored(result, tmp_path_factory):
    return load_run(write_run(result, tmp_path_factory.mktemp("dem") / "run", preset=DEFAULT_PRESET))


def reference_vial_frame(window) -> np.ndarray:
    """s = Qᵀ(r − r_v) with SciPy's rotations: Q = R_z(yaw)·R_y(pitch)·R_x(roll) is the intrinsic z-y-x sequence."""
    roll, pitch, yaw = window["vial_angles"].values.T
    rotation = Rotation.from_euler("ZYX", np.column_stack([yaw, pitch, roll]))
    relative = window["position"].values - window["vial_centre"].values[:, None, :]
    return np.stack([rotation.inv().apply(relative[:, ball]) for ball in range(relative.shape[1])], axis=1)


def test_the_vial_frame_is_the_lab_frame_rotated_back_by_the_vials_orientation(result):
    window = window_data(result, 0)
    assert np.abs(window["vial_angles"].values).max(axis=0) == pytest.approx([0.1, 0.05, 0.3], rel=0.05)
    local = vial_frame(window["position"].values, window["vial_centre"].values, window["vial_angles"].values)
    np.testing.assert_allclose(local, reference_vial_frame(window), rtol=0, atol=1e-15)


def test_the_trajectory_figure_draws_each_balls_centre_in_the_vial_frame(stored):
    window = window_data(stored, 0)
    expected_mm = reference_vial_frame(window) * 1e3
    figure = run_figures(stored)["trajectories"]
    axes = figure.axes
    assert [axis.get_title() for axis in axes] == ["top view", "side view", "end view"]
    for axis, (i, j) in zip(axes, ((0, 1), (0, 2), (1, 2))):
        lines = axis.get_lines()
        assert [line.get_label() for line in lines] == ["ball 0", "ball 1", "ball 2"]
        for ball, line in enumerate(lines):
            np.testing.assert_allclose(line.get_xdata(), expected_mm[:, ball, i], atol=1e-9)
            np.testing.assert_allclose(line.get_ydata(), expected_mm[:, ball, j], atol=1e-9)
        assert LABEL_WITH_UNIT.match(axis.get_xlabel()) and axis.get_xlabel().endswith("(mm)")
        assert LABEL_WITH_UNIT.match(axis.get_ylabel()) and axis.get_ylabel().endswith("(mm)")
        assert axis.get_aspect() == 1.0
    (legend,) = figure.legends
    assert [text.get_text() for text in legend.get_texts()] == ["vial, inner wall", "ball 0", "ball 1", "ball 2"]


def test_every_ball_stays_inside_the_drawn_vial(stored):
    params = stored.params
    radius_mm = params.ball_radius * 1e3
    # Contacts overlap by at most the largest overlap of the impact table.
    overlap_mm = stored.impacts["max_overlap"].max() * 1e3 + 1e-9
    top, side, end = run_figures(stored)["trajectories"].axes
    along = np.concatenate([line.get_xdata() for line in top.get_lines()])
    across = np.concatenate([line.get_xdata() for line in end.get_lines()])
    up = np.concatenate([line.get_ydata() for line in end.get_lines()])
    assert np.abs(along).max() <= params.vial_length * 1e3 / 2 - radius_mm + overlap_mm
    assert np.hypot(across, up).max() <= params.vial_diameter * 1e3 / 2 - radius_mm + overlap_mm
    # The balls reach the end faces, so the bound above is tight (up to what a ball flies between two samples) ...
    assert np.abs(along).max() > params.vial_length * 1e3 / 2 - radius_mm - 0.5
    # ... and positions not rotated into the vial frame leave the vial by millimetres.
    window = window_data(stored, 0)
    unrotated_mm = (window["position"].values - window["vial_centre"].values[:, None, :]) * 1e3
    radial = np.hypot(unrotated_mm[..., 1], unrotated_mm[..., 2])
    assert radial.max() > params.vial_diameter * 1e3 / 2 - radius_mm + 1.0


def test_the_temperature_figure_has_a_line_per_ball_in_celsius(stored):
    (axis,) = temperature_figure(stored).axes
    lines = {line.get_label(): line for line in axis.get_lines()}
    balls = stored.timeseries["theta_balls_C"].transpose("time", "ball").values
    for ball in range(3):
        np.testing.assert_allclose(lines[f"ball {ball}"].get_ydata(), balls[:, ball])
    np.testing.assert_allclose(lines["vial"].get_ydata(), stored.timeseries["theta_vial_C"].values)
    np.testing.assert_allclose(lines["inner air"].get_ydata(), stored.timeseries["theta_air_C"].values)
    assert axis.get_ylabel() == "temperature (°C)" and axis.get_xlabel() == "time (min)"
    assert "3 balls" in axis.get_title()


def test_heat_by_channel_adds_up_to_the_runs_heat(stored):
    made, received = heat_by_channel_figure(stored).axes
    heights = np.zeros(len(CHANNELS))
    for bar in made.patches:
        heights[round(bar.get_x() + bar.get_width() / 2)] += bar.get_height()
    assert [tick.get_text() for tick in made.get_xticklabels()] == list(CHANNELS)
    impacts, span = stored.impacts, stored.summary.simulated_s
    expected = [stored.params.eta * impacts[f"dissipated_{channel}"].sum() / span for channel in CHANNELS]
    np.testing.assert_allclose(heights, expected, rtol=1e-9)
    # The impact table misses only the contacts still open at the end: within a percent of the energy audit.
    np.testing.assert_allclose(
        heights, [stored.summary.value(f"heat_{channel}_W") for channel in CHANNELS], rtol=0.01, atol=1e-3
    )
    assert heights[CHANNELS.index("sliding")] > 0.0  # friction is on: the channels are not all normal damping
    powers = [bar.get_height() for bar in received.patches]
    assert [tick.get_text() for tick in received.get_xticklabels()] == ["0", "1", "2", "vial"]
    assert sum(powers) == pytest.approx(stored.summary.heat_power_W, rel=1e-9)
    for axis in (made, received):
        assert axis.get_ylabel().endswith("(W)")


def test_figures_of_one_ball_on_the_axis_are_left_out(stored):
    names = set(run_figures(stored, impacts=True))
    assert names == set(SEVERAL_BALL_FIGURES) | {
        "impact_speed_histogram",
        "impact_energy_histogram",
        "impacts_per_second",
        "stress_energy_spectrum",
    }
    assert "ball_motion" not in names and "impact_phase_histogram" not in names


def test_impact_histograms_stack_the_walls_and_the_other_balls(stored):
    """Of the impacts (MODEL.md §14.4), not the contact records: chatter merged, touches left out."""
    (axis,) = impact_figures(stored)["impact_speed_histogram"].axes
    impacts = pd.DataFrame(run_contacts(stored).impacts)
    counts = impacts["target"].value_counts()
    expected = [f"{label} ({counts.get(target, 0)})" for target, label, _ in TARGETS]
    assert [text.get_text() for text in axis.get_legend().get_texts()] == expected
    assert counts.get("ball", 0) > 0 and counts.get("side", 0) > 0
    assert len(impacts) < len(stored.impacts) and (impacts["impact_speed"] >= stored.params.touch_speed).all()


def test_the_animation_has_the_frames_and_size_asked_for(stored):
    window = window_data(stored, 0)
    gif = Image.open(io.BytesIO(animation_gif(stored.params, window, frames=12, dpi=50)))
    width, height = ANIMATION_SIZE_INCHES
    assert (gif.n_frames, gif.size) == (12, (round(width * 50), round(height * 50)))
    first = np.asarray(gif.convert("RGB"))
    gif.seek(11)
    assert np.any(np.asarray(gif.convert("RGB")) != first)  # the balls move
    capped = Image.open(io.BytesIO(animation_gif(stored.params, window, frames=10_000, dpi=20)))
    assert capped.n_frames == MOST_ANIMATION_FRAMES


def test_an_animation_is_refused_for_a_window_without_motion_and_for_a_1d_run(stored, tmp_path):
    beyond_the_run = stored.params.replace(record_windows=((0.0, 0.5), (5.0, 0.1)))
    with pytest.raises(ParameterError, match="window 1: .* holds no stored motion"):
        write_animation(dataclasses.replace(stored, params=beyond_the_run), tmp_path / "a.gif", window=1)
    one_d = sm.simulate(sm.default_parameters(duration=0.2, record_windows="0:0.1"))
    with pytest.raises(ParameterError, match="1-D"):
        write_animation(one_d, tmp_path / "b.gif")
    assert not list(tmp_path.iterdir())


def test_the_report_has_a_table_per_ball_and_leaves_out_what_is_one_dimensional(stored):
    document = render_report(stored)
    assert "<h2>Balls</h2>" in document
    temperatures = stored.summary.temperatures.each_ball_C
    for ball, value in enumerate(temperatures):
        assert f'<td>{ball}</td><td class="num">6.35</td><td class="num">{value:.2f}</td>' in document
    assert "regime of the settled motion" not in document
    assert "n_balls = 3 (experiment: one ball)" in document
    assert document.count("<figure>") == 4 + 4  # temperatures, paths, heat, heating zoom; four impact figures
    assert "After 0.0333 min the 3 balls are at" in document


def test_result_plot_and_html_of_a_dem_result(result):
    figures = result.plot()
    # The spectrum a run of several balls with impacts promises (issue 37, point 3), after the main figures.
    assert list(figures) == [
        "temperatures",
        "trajectories",
        "heat_by_channel",
        "ball_heating_zoom",
        "stress_energy_spectrum",
    ]
    assert figures._repr_html_().count("data:image/png;base64,") == 5
    assert "the 3 balls are at" in result._repr_html_()


def test_a_planetary_jar_is_seen_from_the_side_along_its_upright_axis_and_from_the_top_across_it():
    from shakermill.views.trajectories import axis_label, view_name

    planetary = sm.default_parameters("pulverisette7")
    shaker = sm.default_parameters("spex8000m-3d")
    assert (view_name(planetary, "end view"), axis_label(planetary, "x")) == (
        "top view",
        "x, along the jar's axis, up (mm)",
    )
    assert (view_name(shaker, "end view"), axis_label(shaker, "z")) == ("end view", "z, up at rest (mm)")
