"""Keys set where they do not apply are refused; a preset's are ignored with a note; runs that would not fit in memory
and fits that could not end are refused before they start (issue 25)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

import shakermill as sm
from shakermill.engines.dem import model
from shakermill.engines.dem.engine import WINDOW_INTERVAL, DemEngine
from shakermill.engines.dem.stepper import RECORD_COLUMNS
from shakermill.parameters.config import load_config, write_config_toml
from shakermill.parameters.engine_keys import ENGINE_KEYS, SOLVER_KEYS, Reader, keys_decided_by
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.groups import keys_of_role
from shakermill.parameters.key_group import VIAL_MOTION
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.solvers import simulate as simulate_module
from shakermill.studies.calibration.calibrate import LONGEST_FULL_RESOLUTION_FIT_S, check_full_resolution_work
from shakermill.studies.sweeps.plan import check_keys_read, plan_sweep


def test_a_reader_names_where_a_key_applies():
    one_d = Reader(engine="1d", solver="full", thermal_model="paper", kinematics="axial")
    assert (
        one_d.not_read("ball_materials")
        == "the 1-D engine (engine = '1d') does not read it; it applies to engine = 'dem'"
    )
    assert (
        one_d.not_read("averaging_max_time") == "the 'full' solver does not read it; it applies to solver = 'averaged'"
    )
    assert (
        one_d.not_read("omega") is None
        and Reader(engine="1d", solver="averaged", thermal_model="paper", kinematics="axial").not_read(
            "averaging_max_time"
        )
        is None
    )
    dem = Reader(engine="dem", solver="averaged", thermal_model="paper", kinematics="axial")
    assert "it applies to engine = '1d'" in dem.not_read("heat_model")
    assert (
        dem.not_read("drive_heat") == "the 'paper' network does not read it; it applies to thermal_model = 'mill-head'"
    )
    assert (
        Reader(engine="dem", solver="averaged", thermal_model="mill-head", kinematics="axial").not_read("drive_heat")
        is None
    )
    # The powder's keys apply with powder, and then it coats every contact: the bare restitutions give way.
    assert dem.not_read("powder_heat_share") == (
        "a run without powder (powder_mass = 0) does not read it; it applies to powder_mass > 0"
    )
    coated = Reader(
        engine="dem", solver="averaged", thermal_model="paper", kinematics="axial", powder_mass=0.004, n_balls=2
    )
    assert coated.not_read("powder_heat_share") is None and dem.not_read("restitution") is None
    assert "powder_restitution applies instead" in coated.not_read("pair_restitution")
    # One ball touches no other: the pair's own keys are no input of its run.
    assert dem.not_read("pair_friction") == "with n_balls = 1 no two balls touch; it applies to n_balls >= 2"
    assert "engine = 'dem'" in Reader(
        engine="1d", solver="full", thermal_model="paper", kinematics="axial", powder_mass=0.004
    ).not_read("powder_heat_share")
    # Every key of these sets is one some run reads: none is dead.
    readers = [
        Reader(engine="1d", solver="averaged", thermal_model="paper", kinematics="axial"),
        *(
            Reader(engine="dem", solver="averaged", thermal_model="mill-head", kinematics=motion, n_balls=2)
            for motion in KINEMATIC_MODELS
        ),
        Reader(engine="dem", solver="averaged", thermal_model="paper", kinematics="axial", powder_mass=0.004),
    ]
    mill_head, motions = keys_decided_by("thermal_model", "mill-head"), keys_of_role(VIAL_MOTION)
    for key in SOLVER_KEYS | mill_head | motions | ENGINE_KEYS["1d"].reads | ENGINE_KEYS["dem"].reads:
        assert any(reader.not_read(key) is None for reader in readers), key


@pytest.mark.parametrize(
    "overrides, refused",
    [
        (["ball_materials=wc"], "ball_materials: set explicitly, but the 1-D engine"),
        (["ball_radii=3mm"], "ball_radii: set explicitly, but the 1-D engine"),
        (["engine=dem", "kinematics=axial", "heat_model=paper"], "heat_model: set explicitly, but the 'dem' engine"),
        (["solver=full", "averaging_rel_error=1e-4"], "averaging_rel_error: set explicitly, but the 'full' solver"),
    ],
)
def test_a_key_set_where_the_run_does_not_read_it_is_refused(overrides, refused):
    with pytest.raises(ParameterError) as raised:
        load_config(overrides=overrides)
    assert str(raised.value).startswith(refused)


def test_a_file_written_by_hand_is_explicit_a_runs_own_configuration_is_not(tmp_path):
    mine = tmp_path / "mine.toml"
    mine.write_text("friction = 0.5\n", encoding="utf-8")
    with pytest.raises(ParameterError, match="friction: set explicitly, but the 1-D engine"):
        load_config(mine)
    # What a run wrote holds every key, those its engine does not read included: it repeats the run.
    written = tmp_path / "config.toml"
    write_config_toml(sm.default_parameters(), written, preset="spex8000m")
    assert load_config(written).params == sm.default_parameters()


@pytest.mark.parametrize("network, other", [("paper", "mill-head"), ("mill-head", "paper")])
def test_a_key_of_one_network_is_refused_on_a_run_of_the_other_both_ways(network, other):
    """Issue 35: with thermal_model = 'mill-head', h_outer and outer_area changed nothing and were accepted."""
    reader = Reader(engine="dem", solver="averaged", thermal_model=other, kinematics="spex8000m")
    for key in keys_decided_by("thermal_model", network):
        assert (
            reader.not_read(key) == f"the {other!r} network does not read it; it applies to thermal_model = {network!r}"
        )
        assert (
            Reader(engine="dem", solver="averaged", thermal_model=network, kinematics="spex8000m").not_read(key) is None
        )
    key = sorted(keys_decided_by("thermal_model", network))[0]
    preset = "spex8000m-3d-calibrated" if other == "mill-head" else "spex8000m-3d"
    with pytest.raises(ParameterError) as raised:
        load_config(preset=preset, overrides=[f"{key}=1"])
    assert str(raised.value).startswith(f"{key}: set explicitly, but the {other!r} network does not read it")


def test_a_key_the_preset_inherits_but_its_own_run_does_not_read_is_no_note():
    """spex8000m-3d-calibrated (mill-head) inherits spex8000m-3d's outer_area, which neither of them reads with its
    network: it was never part of the preset's answer, so a run of it is not told it was ignored."""
    assert load_config(preset="spex8000m-3d-calibrated").params.outer_area != sm.default_parameters().outer_area
    assert load_config(preset="spex8000m-3d-calibrated").notes == ()
    assert load_config(preset="pulverisette7").notes == ()
    # Issue 37, point 4: a preset's averaging settings under the full solver the run chose are not said.
    assert load_config(preset="pulverisette7", overrides=["solver=full"]).notes == ()


def test_the_keys_a_preset_sets_and_the_run_does_not_read_are_said_in_a_note():
    calibrated = load_config(preset="spex8000m-3d-calibrated", overrides=["thermal_model=paper"])
    (note,) = calibrated.notes
    assert note == "Ignored, as this run does not read them: the preset's clamp_heat_capacity, clamp_loss, drive_heat."
    assert load_config(preset="spex8000m-3d-calibrated").notes == ()
    # A command that reads the keys its own way (a lone impact) checks nothing here.
    assert load_config(overrides=["ball_materials=wc"], reader=None).params.ball_materials == ("tungsten-carbide",)


def test_a_key_of_the_vial_motion_is_read_only_by_the_kinematic_models_that_take_it():
    spex = Reader(engine="dem", solver="full", thermal_model="paper", kinematics="spex8000m")
    assert spex.not_read("lateral_amplitude") is None and spex.not_read("amplitude") is None
    assert (
        spex.not_read("swing_radius")
        == "kinematics = 'spex8000m' does not read it; it applies to kinematics = 'mixer-mill-arc'"
    )
    assert Reader(engine="dem", solver="full", thermal_model="paper", kinematics="fourier").not_read("amplitude") == (
        "kinematics = 'fourier' does not read it; it applies to kinematics = 'axial' or 'mixer-mill-arc' or 'spex8000m'"
    )
    with pytest.raises(ParameterError, match="motion: set explicitly, but kinematics = 'spex8000m' does not read it"):
        load_config(preset="spex8000m-3d", overrides=["motion=x:1:0.001:0"])


def test_a_preset_on_the_command_line_over_a_files_is_said(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text('preset = "spex8000m-3d"\nduration = 2\n')
    config = load_config(path, preset="mm400")
    assert config.preset == "mm400" and config.params.kinematics == "mixer-mill-arc"
    assert f"The preset is 'mm400' (--preset), not the 'spex8000m-3d' that {path} names." in config.notes
    assert not any("--preset" in note for note in load_config(path).notes)
    with pytest.raises(ParameterError, match="unknown preset ''"):
        load_config(preset="")


def test_a_swept_key_a_point_would_not_read_is_refused():
    base = sm.default_parameters()
    with pytest.raises(ParameterError, match="friction: swept, but the 1-D engine"):
        check_keys_read(base, plan_sweep(["friction=0.2,0.4"]))
    check_keys_read(base, plan_sweep(["omega=100,110"]))


def test_the_records_of_a_dem_run_are_counted_before_they_are_allocated(monkeypatch):
    params = sm.default_parameters("spex8000m-3d", duration=2.0, record_windows="0:1", solver="full")
    nodes = len(DemEngine.network_for(params).nodes)
    rows = 3 + 1.0 / WINDOW_INTERVAL  # the samples at 0, 1 and 2 s, and the window at 10 kHz
    contacts = model.contact_memory(model.constants_from(params), len(RECORD_COLUMNS))
    assert DemEngine.memory_needed(params, 3) == int(rows * model.row_width(params.n_balls, nodes) * 8 + contacts)
    # The contacts' memory grows linearly with the balls: 2000 balls hold well under 100 MB of it.
    crowd = sm.default_parameters(
        "pulverisette7",
        n_balls=2000,
        ball_radius=2.5e-3,
        vial_diameter=0.12,
        vial_length=0.07,
        outer_diameter=0.13,
        outer_length=0.08,
        record_windows=(),
    )
    assert 20e6 < model.contact_memory(model.constants_from(crowd), len(RECORD_COLUMNS)) < 100e6
    monkeypatch.setattr("psutil.virtual_memory", lambda: SimpleNamespace(available=2**20))
    with pytest.raises(
        ParameterError, match=r"record_windows: the run would keep .* GiB of records .*allowed shorter record_windows"
    ):
        sm.simulate(params)
    # The 1-D engine caps its windows itself: nothing to refuse.
    simulate_module.preflight(sm.default_parameters(duration=2.0))


def test_a_dem_run_that_needs_more_steps_than_its_budget_allows_is_refused_before_it_starts():
    # No step of the 'dem' engine is longer than max_flight_step: 100 s take at least 1e6 steps at the default 1e-4 s.
    full = sm.default_parameters("spex8000m-3d", duration=100.0, solver="full", max_steps=999_999)
    assert DemEngine.least_steps(full, 100.0) == pytest.approx(1e6)
    with pytest.raises(
        ParameterError,
        match=r"max_steps: 100 s of the run .* at least 1e\+06 steps .*allowed max_steps >= 1000000, "
        "a shorter duration or solver = 'averaged'",
    ):
        simulate_module.preflight(full)
    simulate_module.preflight(full.model_copy(update={"max_steps": 1_000_000}))
    # An averaged run needs at least its least mechanics at full resolution, whatever its duration.
    averaged = sm.default_parameters("spex8000m-3d", max_steps=1000)
    with pytest.raises(ParameterError, match=r"max_steps: .* of the least mechanics of the averaged solver"):
        simulate_module.preflight(averaged)


def test_a_full_resolution_fit_of_the_dem_engine_over_the_hour_is_refused():
    dem = sm.default_parameters("spex8000m-3d")
    with pytest.raises(ParameterError, match="--full-resolution: each of the fit's ~2000 evaluations would run 3600 s"):
        check_full_resolution_work(dem, 3600.0)
    check_full_resolution_work(dem, LONGEST_FULL_RESOLUTION_FIT_S)
    check_full_resolution_work(sm.default_parameters(), 3600.0)  # a 1-D hour is seconds


def test_the_fifty_balls_of_the_issue_are_refused_in_one_line_before_any_memory_is_taken(monkeypatch, tmp_path):
    from typer.testing import CliRunner

    from shakermill import cli

    # Issue 25: 50 balls with a 600-s record window asked for 27.7 GiB at start-up and ended in a traceback. The
    # machine here is told it has 8 GiB free, so that the case is the same on any machine.
    monkeypatch.setattr("psutil.virtual_memory", lambda: SimpleNamespace(available=8 * 2**30))
    outcome = CliRunner().invoke(
        cli.app,
        [
            "run",
            "--preset",
            "spex8000m-3d",
            "--set",
            "n_balls=50",
            "--set",
            "ball_radius=3mm",
            "--set",
            "solver=full",
            "--set",
            "duration=600",
            "--set",
            "record_windows=0:600",
            "--no-plots",
            "--out",
            str(tmp_path / "run"),
        ],
    )
    assert outcome.exit_code == 2 and "Traceback" not in outcome.stderr
    (line,) = outcome.stderr.strip().splitlines()
    assert line.startswith("error: record_windows: the run would keep ") and "of the 8 GiB free" in line
    assert "GiB of records and contacts (50 balls, 600 s of record windows" in line
    assert not (tmp_path / "run").exists()
