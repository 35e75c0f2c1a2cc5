"""Sweeps over the balls of the 'dem' engine (issue 15): their number, size, material and fill.

Each point runs 5 ms of the 'dem' engine at full resolution in the paper's Ø19 mm bore, where five
12.7-mm balls do not fit side by side: that point fails with its one-line reason, and the sweep goes on.
"""

from __future__ import annotations

import json

import pytest

import shakermill as sm
from shakermill.studies.sweeps.plan import as_plan, plan_sweep, point_ids
from shakermill.studies.sweeps.storage import POINTS_FOLDER, load_sweep
from shakermill.studies.sweeps.sweep import sweep

GRIDS = ("n_balls=1,5", "ball_radius=3mm,6.35mm")


@pytest.fixture(name="base", scope="module")
def base_fixture():
    return sm.default_parameters(engine="dem", solver="full", duration=0.005, output_interval=0.001, record_windows=())


def test_a_plan_over_number_and_size_of_balls():
    plan = plan_sweep(GRIDS)
    assert plan.keys == ("n_balls", "ball_radius")
    assert plan.points == (
        {"n_balls": 1, "ball_radius": pytest.approx(3e-3)},
        {"n_balls": 1, "ball_radius": pytest.approx(6.35e-3)},
        {"n_balls": 5, "ball_radius": pytest.approx(3e-3)},
        {"n_balls": 5, "ball_radius": pytest.approx(6.35e-3)},
    )
    assert all(type(point["n_balls"]) is int for point in plan.points)
    # "5" and 5 are one point: counts are stored as numbers, so the ids agree.
    base = sm.default_parameters(engine="dem")
    assert point_ids(base, plan_sweep(["n_balls=5"])) == point_ids(base, as_plan([{"n_balls": "5"}]))


def test_a_diameter_people_type_sets_the_radius_in_grids_and_points(tmp_path):
    """issue 49: ``ball_diameter`` (twice ball_radius) is read where ``--set`` reads it, in grids and points files."""
    assert plan_sweep(["ball_diameter=8mm:12mm:3"]).points == tuple(
        {"ball_radius": pytest.approx(radius)} for radius in (4e-3, 5e-3, 6e-3)
    )
    assert plan_sweep(["ball_diameter=10mm,12.7mm"]).points == (
        {"ball_radius": pytest.approx(5e-3)},
        {"ball_radius": pytest.approx(6.35e-3)},
    )
    points = tmp_path / "points.csv"
    points.write_text("ball_diameter,n_balls\n10 mm,2\n0.5 in,3\n")
    plan = plan_sweep(points_file=points)
    assert plan.keys == ("ball_radius", "n_balls")
    assert plan.points == ({"ball_radius": pytest.approx(5e-3), "n_balls": 2}, {"ball_radius": 6.35e-3, "n_balls": 3})
    assert dict(plan.units) == {"ball_radius": "mm"}
    with pytest.raises(sm.ParameterError, match="ball_radius: more than one grid or points column for this key"):
        plan_sweep(["ball_radius=4mm,5mm"], points_file=points)


@pytest.mark.parametrize(
    ("spec", "fragments"),
    [
        ("n_balls=1:5:5", ("START:STOP:N is for real-valued parameters", "n_balls=A,B,C")),
        ("n_balls=1,2.5", ("n_balls", "whole number", "'2.5'")),
        ("ball_radius=4mm,5 kg", ("ball_radius", "kg")),
    ],
)
def test_bad_lists_are_refused_before_the_sweep_starts(spec, fragments):
    with pytest.raises(sm.ParameterError) as caught:
        plan_sweep([spec])
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"grid '{spec}'")
    assert all(fragment in message for fragment in fragments), message


def test_balls_that_do_not_fit_fail_their_point_and_the_sweep_resumes(base, tmp_path):
    folder = tmp_path / "balls"
    table = sweep(base, plan_sweep(GRIDS), folder, workers=1)
    assert list(table["n_balls"]) == [1, 1, 5, 5]
    assert list(table["ball_radius"]) == pytest.approx([3e-3, 6.35e-3, 3e-3, 6.35e-3])
    failed = table["error"].notna()
    assert list(failed) == [False, False, False, True]
    reason = table["error"].iloc[3]
    assert "\n" not in reason and reason.startswith("n_balls: 5 balls (radius up to 6.35 mm) do not fit")
    assert "allowed fewer balls" in reason
    finished = table[~failed]
    assert list(finished["engine"]) == ["dem"] * 3
    assert finished["regime"].notna().all()
    assert list(finished["fill_fraction"]) == pytest.approx(
        [n * r**3 / (0.25 * 19e-3**2 * 58e-3) * 4 / 3 for n, r in ((1, 3e-3), (1, 6.35e-3), (5, 3e-3))]
    )
    # The failed point has its file: a second run finds all four and computes none again.
    stamps = {path.name: path.stat().st_mtime_ns for path in (folder / POINTS_FOLDER).iterdir()}
    assert len(stamps) == 4
    again = sweep(base, plan_sweep(GRIDS), folder, workers=1)
    assert {path.name: path.stat().st_mtime_ns for path in (folder / POINTS_FOLDER).iterdir()} == stamps
    assert list(again["point_id"]) == list(table["point_id"])
    assert json.loads((folder / "sweep.json").read_text())["keys"] == ["n_balls", "ball_radius"]
    assert load_sweep(folder).table["error"].notna().sum() == 1


def test_a_sweep_over_fill_and_material_runs_each_count(base, tmp_path):
    plan = plan_sweep(["fill=0.02,0.04", "ball_material=steel,wc"])
    table = sweep(base.replace(vial_diameter="38 mm"), plan, tmp_path / "fill", workers=1)
    assert table["error"].isna().all()
    # 0.02 and 0.04 of the Ø38 x 58 mm bore (65 779 mm³) in 12.7-mm balls (1072.6 mm³): 1.23 and 2.45 balls.
    assert list(table["n_balls"]) == [1, 1, 2, 2]
    assert list(table["ball_material"]) == ["hardened-steel", "tungsten-carbide"] * 2
    assert table["fill_fraction"].iloc[0] == pytest.approx(1072.6 / 65779, rel=1e-3)
