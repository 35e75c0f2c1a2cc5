"""An empty mill (``n_balls = 0``, MODEL.md §13.4): nothing moves that makes heat, so the vial warms on the drive's
heat alone; the 1-D engine, which moves one ball, refuses it."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from shakermill import cli
from shakermill.engines.registry import engine_named
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import default_parameters
from shakermill.solvers.simulate import simulate

runner = CliRunner()


@pytest.mark.parametrize("solver", ["averaged", "full"])
def test_the_drive_alone_warms_an_empty_mill_and_its_heat_is_accounted_for(solver):
    # A minute: with nothing to resolve, the full solver still steps through it at the 0.1-ms flight step.
    params = default_parameters("spex8000m-3d-calibrated", n_balls=0, duration=60.0, solver=solver)
    result = simulate(params)
    summary = result.summary
    assert result.success and summary.impacts.count == 0 and summary.heat_power_W == 0.0
    assert math.isnan(summary.ball_C) and math.isnan(summary.ball_steady_C) and summary.temperatures.each_ball_C == []
    assert summary.drive_heat_W == pytest.approx(params.drive_heat)
    assert 20.0 < summary.vial_C < summary.temperatures.holder < summary.vial_steady_C
    # The drive's heat is the only flow of the balance, and all of it is accounted for.
    assert abs(result.energy.thermal_residual) < 1e-9 * result.energy.drive_heat
    assert summary.energy_audit_residual == pytest.approx(abs(result.energy.residual) / result.energy.drive_heat)
    # At the steady state everything the drive puts in leaves to the room.
    steady = result.steady
    network = engine_named(params.engine).network_for(params)
    theta = np.array([steady.vial, steady.air, dict(steady.others)["holder"]])
    flows = dict(zip((path.name for path in network.paths), network.flows(theta, np.zeros(0)), strict=True))
    to_room = flows["holder → room"] + flows["vial → room, convection"] + flows["vial → room, radiation"]
    assert to_room == pytest.approx(params.drive_heat, rel=1e-6)
    assert not any("ball" in warning for warning in result.warnings)


def test_an_empty_mill_of_the_paper_network_stays_at_the_ambient():
    result = simulate(default_parameters("spex8000m-3d-calibrated-paper", n_balls=0, duration=600.0))
    assert result.summary.vial_C == pytest.approx(20.0, abs=1e-12)
    assert result.summary.vial_steady_C == pytest.approx(20.0, abs=1e-9)


def test_the_one_dimensional_engine_refuses_an_empty_mill():
    with pytest.raises(
        ParameterError, match=r"n_balls: the 1-D engine moves one ball; allowed n_balls = 1 .* engine = 'dem'"
    ):
        default_parameters("spex8000m", n_balls=0)


def test_run_prints_and_stores_an_empty_mill(tmp_path):
    out = tmp_path / "empty"
    outcome = runner.invoke(
        cli.app,
        [
            "run",
            "--preset",
            "spex8000m-3d-calibrated",
            "--set",
            "n_balls=0",
            "--set",
            "duration=600",
            "--out",
            str(out),
            "--no-plots",
        ],
    )
    assert outcome.exit_code == 0, outcome.output
    assert (
        re.search(r"amplitude; ball radius\s*│\s*25; none", outcome.stdout)
        and "drive heat into the holder" in outcome.stdout
    )
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))["summary"]
    assert summary["n_balls"] == 0 and summary["ball_C"] is None and summary["vial_C"] > 20.0


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--target", "theta_inf_C=40"], "target: the targets are the balls' temperatures"),
        (["--free", "drive_heat"], "curve: experiment (Takacs & McHenry 2006"),
    ],
)
def test_a_fit_to_the_balls_of_an_empty_mill_is_refused(option, message):
    outcome = runner.invoke(
        cli.app, ["calibrate", "--preset", "spex8000m-3d-calibrated", "--set", "n_balls=0", *option]
    )
    assert outcome.exit_code == 2 and message in outcome.output and "vial_C" in outcome.output


def test_an_empty_mill_draws_its_temperatures_alone_and_refuses_an_animation(tmp_path):
    from shakermill.io.runs import load_run
    from shakermill.views.figures.run import paper_figures, write_animation
    from shakermill.views.report import render_report

    out = tmp_path / "empty"
    outcome = runner.invoke(
        cli.app,
        [
            "run",
            "--preset",
            "spex8000m-3d-calibrated",
            "--set",
            "n_balls=0",
            "--set",
            "solver=full",
            "--set",
            "duration=2",
            "--out",
            str(out),
            "--no-plots",
        ],
    )
    assert outcome.exit_code == 0, outcome.output
    run = load_run(out)
    assert list(paper_figures(run)) == ["temperatures"]
    with pytest.raises(ParameterError, match="an empty mill"):
        write_animation(run, tmp_path / "balls.gif")
    page = render_report(run)
    assert "An empty mill (no balls)" in page and "<h2>Balls</h2>" not in page
