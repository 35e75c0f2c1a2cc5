"""Keys set where they do not apply are refused; a preset's are ignored with a note; runs that would not fit in memory
and fits that could not end are refused before they start (issue 25)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

import shakermill as sm
from shakermill.engines.dem import model
from shakermill.engines.dem.engine import WINDOW_INTERVAL, DemEngine
from shakermill.parameters.config import load_config, write_config_toml
from shakermill.parameters.engine_keys import AVERAGED_ONLY, ENGINE_KEYS, MILL_HEAD_ONLY, Reader
from shakermill.parameters.errors import ParameterError
from shakermill.solvers import simulate as simulate_module
from shakermill.studies.calibrate import LONGEST_FULL_RESOLUTION_FIT_S, check_full_resolution_work
from shakermill.studies.sweep_plan import check_keys_read, plan_sweep


def test_a_reader_names_where_a_key_applies():
    one_d = Reader("1d", "full", "paper")
    assert one_d.not_read("ball_materials") == "the 1-D engine (engine = '1d') does not read it; it applies to engine = 'dem'"
    assert one_d.not_read("averaging_max_time") == "the 'full' solver does not read it; it applies to solver = 'averaged'"
    assert one_d.not_read("omega") is None and Reader("1d", "averaged", "paper").not_read("averaging_max_time") is None
    dem = Reader("dem", "averaged", "paper")
    assert "it applies to engine = '1d'" in dem.not_read("heat_model")
    assert dem.not_read("drive_heat") == "the 'paper' network does not read it; it applies to thermal_model = 'mill-head'"
    assert Reader("dem", "averaged", "mill-head").not_read("drive_heat") is None
    # Every key of these sets is one some run reads: none is dead.
    for key in AVERAGED_ONLY | MILL_HEAD_ONLY | ENGINE_KEYS["1d"].unread | ENGINE_KEYS["dem"].unread:
        assert Reader("dem", "averaged", "mill-head").not_read(key) is None or Reader("1d", "averaged", "paper").not_read(key) is None


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
    mine.write_text('friction = 0.5\n', encoding="utf-8")
    with pytest.raises(ParameterError, match="friction: set explicitly, but the 1-D engine"):
        load_config(mine)
    # What a run wrote holds every key, those its engine does not read included: it repeats the run.
    written = tmp_path / "config.toml"
    write_config_toml(sm.default_parameters(), written, preset="spex8000m")
    assert load_config(written).params == sm.default_parameters()


def test_the_keys_a_preset_sets_and_the_run_does_not_read_are_said_in_a_note():
    calibrated = load_config(preset="spex8000m-3d-calibrated", overrides=["thermal_model=paper"])
    (note,) = calibrated.notes
    assert note == "Ignored, as this run does not read them: the preset's clamp_heat_capacity, clamp_loss, drive_heat."
    assert load_config(preset="spex8000m-3d-calibrated").notes == ()
    # A command that reads the keys its own way (a lone impact) checks nothing here.
    assert load_config(overrides=["ball_materials=wc"], reader=None).params.ball_materials == ("tungsten-carbide",)


def test_a_swept_key_a_point_would_not_read_is_refused():
    base = sm.default_parameters()
    with pytest.raises(ParameterError, match="friction: swept, but the 1-D engine"):
        check_keys_read(base, plan_sweep(["friction=0.2,0.4"]))
    check_keys_read(base, plan_sweep(["omega=100,110"]))


def test_the_records_of_a_dem_run_are_counted_before_they_are_allocated(monkeypatch):
    params = sm.default_parameters("spex8000m-3d", duration=2.0, record_windows="0:1", solver="full")
    nodes = len(DemEngine.network_for(params).nodes)
    rows = 3 + 1.0 / WINDOW_INTERVAL  # the samples at 0, 1 and 2 s, and the window at 10 kHz
    assert DemEngine.memory_needed(params, 3) == int(rows * model.row_width(params.n_balls, nodes) * 8)
    monkeypatch.setattr("psutil.virtual_memory", lambda: SimpleNamespace(available=2**20))
    with pytest.raises(ParameterError, match=r"record_windows: the run would keep .* GiB of records .*allowed shorter record_windows"):
        sm.simulate(params)
    # The 1-D engine caps its windows itself: nothing to refuse.
    simulate_module.preflight(sm.default_parameters(duration=2.0))


def test_a_full_resolution_fit_of_the_dem_engine_over_the_hour_is_refused():
    dem = sm.default_parameters("spex8000m-3d")
    with pytest.raises(ParameterError, match="--full-resolution: each of the fit's ~2000 evaluations would run 3600 s"):
        check_full_resolution_work(dem, 3600.0)
    check_full_resolution_work(dem, LONGEST_FULL_RESOLUTION_FIT_S)
    check_full_resolution_work(sm.default_parameters(), 3600.0)  # a 1-D hour is seconds
