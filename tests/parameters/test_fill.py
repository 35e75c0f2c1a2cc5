"""``fill``: the fraction of the vial's inner volume the balls take, which sets n_balls of the 'dem' engine."""

from __future__ import annotations

import math

import pytest
from conftest import assert_one_error_line
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.parameters.config import load_config, write_config_toml
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.geometry import balls_for_fill
from shakermill.studies.sweeps.plan import plan_sweep

# The spex8000m-3d bore, Ø38 x 58 mm: π/4 · 38² · 58 mm³ = 65 779 mm³.
VIAL_MM3 = math.pi / 4 * 38**2 * 58


def ball_mm3(radius_mm: float) -> float:
    return 4 / 3 * math.pi * radius_mm**3


def test_the_count_by_hand():
    # 0.1 · 65 779 mm³ over a 12.7-mm ball's 1072.6 mm³ is 6.13 balls: 6.
    assert 0.1 * VIAL_MM3 / ball_mm3(6.35) == pytest.approx(6.13, abs=0.01)
    assert balls_for_fill(0.1, 6.35e-3, 58e-3, 38e-3) == 6
    # 0.1 · 65 779 / 523.6 (Ø10 mm) = 12.56: 13, rounded to the nearer count.
    assert balls_for_fill(0.1, 5e-3, 58e-3, 38e-3) == 13
    # Less than half a ball is still one ball.
    assert balls_for_fill(1e-6, 6.35e-3, 58e-3, 38e-3) == 1


def test_fill_sets_n_balls_and_the_summary_reports_what_was_achieved():
    params = sm.default_parameters("spex8000m-3d", fill=0.1)
    assert params.n_balls == 6
    assert params.fill_fraction == pytest.approx(6 * ball_mm3(6.35) / VIAL_MM3)
    # Another ball through replace: fill makes the count again.
    assert params.replace(ball_radius="5 mm").n_balls == 13
    # fill = 0 keeps the count fill had made.
    assert params.replace(fill=0).n_balls == 6
    # An n_balls that agrees with fill is accepted.
    assert sm.default_parameters("spex8000m-3d", fill=0.1, n_balls=6).n_balls == 6


def test_a_file_with_fill_round_trips_and_runs_with_another_ball(tmp_path):
    params = sm.default_parameters("spex8000m-3d", fill=0.1)
    path = write_config_toml(params, tmp_path / "config.toml", preset="spex8000m-3d")
    assert load_config(path).params == params
    assert load_config(path, overrides=["ball_radius=5mm"]).params.n_balls == 13
    # The file's fill replaces the preset's n_balls; an n_balls on the command line must agree with it.
    with pytest.raises(ParameterError, match="n_balls: 3 contradicts fill = 0.1"):
        load_config(path, overrides=["n_balls=3"])


@pytest.mark.parametrize(
    ("overrides", "fragments"),
    [
        ({"fill": 0.1, "n_balls": 3}, ("n_balls: 3 contradicts fill = 0.1", "allowed n_balls = 6", "fill = 0")),
        ({"fill": 0.5}, ("fill: 0.5 of the vial is 31 balls of radius 6.35 mm", "allowed fill < 0.334")),
        (
            {"fill": 0.3, "ball_radius": "0.5 mm"},
            ("fill: 0.3 of this vial is 37688 balls", "allowed fill <", "at most 2000 balls"),
        ),
        ({"fill": 0.8}, ("fill: 0.8 is out of range", "allowed [0, 0.74")),
        ({"fill": 0.1, "engine": "1d", "kinematics": "axial"}, ("fill:", "allowed fill = 0 with engine = '1d'")),
        ({"fill": 0.1, "ball_materials": "wc,wc"}, ("fill:", "ball_materials", "allowed fill = 0 with per-ball lists")),
    ],
)
def test_bad_fill_is_refused_in_one_line(overrides, fragments):
    with pytest.raises(ParameterError) as caught:
        sm.default_parameters("spex8000m-3d", **overrides)
    message = str(caught.value)
    assert "\n" not in message
    assert all(fragment in message for fragment in fragments), message


def test_the_command_line_refuses_fill_beside_another_n_balls(tmp_path):
    outcome = CliRunner().invoke(
        cli.app,
        ["run", "--preset", "spex8000m-3d", "--set", "fill=0.1", "--set", "n_balls=3", "--out", str(tmp_path / "r")],
    )
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, "n_balls: 3 contradicts fill = 0.1", "allowed n_balls = 6")


@pytest.mark.slow
def test_a_sweep_plan_over_fill_and_ball_size():
    plan = plan_sweep(["fill=0.05,0.1", "ball_radius=4mm,6.35mm"])
    assert plan.keys == ("fill", "ball_radius")
    base = sm.default_parameters("spex8000m-3d", solver="averaged")
    counts = [base.replace(**point).n_balls for point in plan.points]
    # 0.05 · 65 779 / 268.1 (Ø8 mm) = 12.3 and / 1072.6 = 3.07; 0.1: 24.5 and 6.13.
    assert counts == [12, 3, 25, 6]
    assert plan_sweep(["fill=0.05:0.2:4"]).points[-1] == {"fill": pytest.approx(0.2)}
