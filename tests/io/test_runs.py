"""Run folders: content of every file, read-back, atomic replacement and interrupted writes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
import xarray as xr

import shakermill as sm
from shakermill.engines.one_d.description import IMPACT_UNITS
from shakermill.io import runs as storage
from shakermill.io.runs import StorageError, load_run, to_jsonable, write_run
from shakermill.parameters.config import load_config
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.solvers.summary_versions import SCHEMA_VERSION


@pytest.fixture(scope="module")
def short_result() -> sm.Result:
    return sm.simulate(sm.default_parameters(duration=2.0, record_windows="0:0.2"))


@pytest.fixture(name="run_folder")
def run_folder_fixture(short_result, tmp_path) -> Path:
    return write_run(short_result, tmp_path / "run", preset=DEFAULT_PRESET, extra_provenance={"note": "test"})


def strict_json(text: str):
    """json.loads that refuses NaN and Infinity, which are not JSON."""

    def refuse(constant: str):
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def test_run_folder_holds_exactly_the_documented_files(run_folder):
    assert sorted(entry.name for entry in run_folder.iterdir()) == sorted(storage.RUN_FILES)
    assert [entry.name for entry in run_folder.parent.iterdir()] == ["run"]  # no partial or old folders left


@pytest.mark.slow
@pytest.mark.parametrize("file_name, attribute", [("timeseries.nc", "timeseries"), ("windows.nc", "windows")])
def test_netcdf_files_hold_the_result_values_with_units(run_folder, short_result, file_name, attribute):
    expected: xr.Dataset = getattr(short_result, attribute)
    assert expected.sizes["time"] > 2
    with xr.open_dataset(run_folder / file_name, engine="h5netcdf") as stored:
        assert set(stored.data_vars) == set(expected.data_vars)
        np.testing.assert_array_equal(stored["time"].values, expected["time"].values)
        for name in expected.data_vars:
            np.testing.assert_array_equal(stored[name].values, expected[name].values)
            assert stored[name].attrs["units"] == expected[name].attrs["units"]
            assert stored[name].attrs["long_name"] == expected[name].attrs["long_name"]
        assert stored["theta_ball"].attrs["units"] == "K"
        assert stored["theta_ball_C"].attrs["units"] == "degC"
        assert "theta_*_C" in stored.attrs["temperature_note"]
        assert stored["time"].attrs["units"] == "s"
        assert stored.attrs["shakermill_version"] == sm.__version__
        assert stored.attrs["status"] == short_result.status
        assert stored.attrs["message"] == short_result.message
        assert "shakermill" in stored.attrs["title"]


def test_parquet_holds_every_impact_and_the_units(run_folder, short_result):
    table = pq.read_table(run_folder / "impacts.parquet")
    assert json.loads(table.schema.metadata[b"units"]) == IMPACT_UNITS
    stored = table.to_pandas()
    assert len(stored) == len(short_result.impacts) > 10
    assert list(stored.columns) == list(short_result.impacts.columns)
    assert list(stored["wall"]) == list(short_result.impacts["wall"])
    numeric = [column for column in stored.columns if column != "wall"]
    np.testing.assert_array_equal(stored[numeric].to_numpy(), short_result.impacts[numeric].to_numpy())


def test_summary_json_is_strict_json_matching_the_result(run_folder, short_result):
    document = strict_json((run_folder / "summary.json").read_text(encoding="utf-8"))
    assert document["status"] == short_result.status == 0
    assert document["success"] is True
    assert document["message"] == short_result.message
    assert document["counters"] == short_result.counters
    assert document["schema_version"] == SCHEMA_VERSION
    for key, value in short_result.summary.flat().items():
        if isinstance(value, (str, list)):
            assert document["summary"][key] == value
        elif isinstance(value, dict):
            assert document["summary"][key] == pytest.approx(value, rel=1e-15), key
        elif isinstance(value, float) and math.isnan(value):  # a statistic of nothing (no ball hits a ball in 1-D)
            assert document["summary"][key] is None, key
        else:
            assert document["summary"][key] == pytest.approx(float(value), rel=1e-15), key
    assert document["energy_audit"]["relative_residual"] == pytest.approx(short_result.energy.relative_residual)
    assert document["ball_fit"]["theta_inf"] == pytest.approx(short_result.ball_fit.theta_inf)


def test_config_toml_reproduces_the_parameters_and_records_provenance(run_folder, short_result):
    assert load_config(run_folder / "config.toml").params == short_result.params
    text = (run_folder / "config.toml").read_text(encoding="utf-8")
    assert 'note = "test"' in text and f'shakermill_version = "{sm.__version__}"' in text


@pytest.mark.slow
def test_load_run_returns_what_was_written(run_folder, short_result):
    run = load_run(run_folder)
    assert run.params == short_result.params
    assert run.preset == DEFAULT_PRESET
    assert run.success and run.status == 0
    assert run.ball_fit == short_result.ball_fit
    assert run.impact_units == IMPACT_UNITS
    assert run.counters == short_result.counters
    assert run.summary.impacts.count == short_result.summary.impacts.count
    xr.testing.assert_identical(run.timeseries.drop_attrs(), short_result.timeseries.drop_attrs())
    pd.testing.assert_frame_equal(run.impacts, short_result.impacts, check_dtype=False)


def test_load_run_refuses_a_folder_without_summary(tmp_path):
    with pytest.raises(StorageError, match="not a shakermill run folder"):
        load_run(tmp_path)


def write_foreign_netcdf(path: Path) -> None:
    import h5netcdf

    with h5netcdf.File(path, "w") as file:
        file.dimensions = {"step": 2}
        file.create_variable("temperature", ("step",), data=np.array([1.0, 2.0]))


def write_foreign_parquet(path: Path) -> None:
    import pyarrow as pa

    pq.write_table(pa.table({"sample": [1, 2], "value": [0.5, 0.25]}), path)


@pytest.mark.parametrize(
    ("name", "write_foreign", "missing"),
    [
        ("timeseries.nc", write_foreign_netcdf, "variable 'time'"),
        ("windows.nc", write_foreign_netcdf, "variable 'time'"),
        ("impacts.parquet", write_foreign_parquet, "column 'time'"),
    ],
)
def test_load_run_refuses_a_file_of_the_right_format_that_no_run_wrote(run_folder, name, write_foreign, missing):
    write_foreign(run_folder / name)
    with pytest.raises(StorageError, match=f"not a readable shakermill run folder \\({name}: no {missing}") as caught:
        load_run(run_folder)
    assert "\n" not in str(caught.value)


@pytest.mark.slow
def test_nan_values_are_written_as_null(tmp_path):
    # Too short to fit an exponential and without impacts: the summary holds NaNs.
    result = sm.simulate(sm.default_parameters(duration=0.001, record_windows=()))
    assert math.isnan(result.summary.theta_inf_C)
    folder = write_run(result, tmp_path / "short", preset=DEFAULT_PRESET)
    document = strict_json((folder / "summary.json").read_text(encoding="utf-8"))
    assert document["summary"]["theta_inf_C"] is None
    assert document["summary"]["mean_impact_speed_m_s"] is None
    run = load_run(folder)
    assert math.isnan(run.ball_fit.tau)
    assert run.windows.sizes["time"] == 0 and len(run.impacts) == 0


def test_to_jsonable_makes_numpy_values_plain_and_non_finite_values_null():
    converted = to_jsonable({"a": np.float64("nan"), "b": [np.int64(3), np.float64(-np.inf)], "c": np.bool_(True)})
    assert converted == {"a": None, "b": [3, None], "c": True}
    assert type(converted["b"][0]) is int and type(converted["c"]) is bool


def test_writing_again_replaces_the_old_run_completely(run_folder, short_result):
    (run_folder / "stale.txt").write_text("from the old run")
    write_run(short_result, run_folder, preset=DEFAULT_PRESET, overwrite=True)
    assert not (run_folder / "stale.txt").exists()
    assert sorted(entry.name for entry in run_folder.iterdir()) == sorted(storage.RUN_FILES)
    assert [entry.name for entry in run_folder.parent.iterdir()] == ["run"]


@pytest.mark.parametrize("existing", ["file", "foreign folder"])
def test_refuses_to_replace_what_is_not_a_run_folder(short_result, tmp_path, existing):
    target = tmp_path / "target"
    if existing == "file":
        target.write_text("precious")
        precious = target
    else:
        target.mkdir()
        precious = target / "thesis.tex"
        precious.write_text("precious")
    with pytest.raises(StorageError, match="choose another --out"):
        write_run(short_result, target, preset=DEFAULT_PRESET)
    assert precious.read_text() == "precious"


def test_refuses_to_replace_a_run_unless_told_to(run_folder, short_result):
    before = (run_folder / "summary.json").read_text(encoding="utf-8")
    with pytest.raises(StorageError, match="holds a run already.*--overwrite"):
        write_run(short_result, run_folder, preset=DEFAULT_PRESET)
    assert (run_folder / "summary.json").read_text(encoding="utf-8") == before


def fail_midway(*_args, **_kwargs):
    raise KeyboardInterrupt


def test_interrupted_write_leaves_no_folder_at_all(short_result, tmp_path, monkeypatch):
    monkeypatch.setattr(storage, "impacts_parquet", fail_midway)
    with pytest.raises(KeyboardInterrupt):
        write_run(short_result, tmp_path / "run", preset=DEFAULT_PRESET)
    assert list(tmp_path.iterdir()) == []


def test_interrupted_replacement_keeps_the_previous_run(run_folder, short_result, monkeypatch):
    before = (run_folder / "summary.json").read_text(encoding="utf-8")
    monkeypatch.setattr(storage, "impacts_parquet", fail_midway)
    with pytest.raises(KeyboardInterrupt):
        write_run(short_result, run_folder, preset=DEFAULT_PRESET, overwrite=True)
    assert (run_folder / "summary.json").read_text(encoding="utf-8") == before
    assert [entry.name for entry in run_folder.parent.iterdir()] == ["run"]


@pytest.mark.slow
def test_averaged_run_files_say_what_covers_only_the_averaging_window(tmp_path):
    result = sm.simulate(sm.default_parameters(solver="averaged", duration=600.0, attractor_starts=1))
    assert result.solver == "averaged" and result.impact_window is not None
    folder = write_run(result, tmp_path / "averaged", preset=DEFAULT_PRESET)
    end = result.averages.transient + result.averages.window
    with xr.open_dataset(folder / "timeseries.nc", engine="h5netcdf") as series:
        assert "x, p, velocity are NaN" in series.attrs["coverage"]
        for name in ("x", "p", "velocity"):
            assert np.isnan(series[name].values).all()
            assert "not computed by the averaged solver" in series[name].attrs["coverage"]
        assert "mean rate times time" in series["heat_generated"].attrs["coverage"]
        assert "coverage" not in series["theta_ball"].attrs
    with xr.open_dataset(folder / "windows.nc", engine="h5netcdf") as windows:
        assert f"up to t = {end:.6g} s" in windows.attrs["coverage"]
    coverage = pq.read_schema(folder / "impacts.parquet").metadata[b"coverage"].decode()
    assert f"to {end:.6g} s" in coverage and "impact_rate_hz" in coverage
    assert load_run(folder).impacts["time"].max() <= end


def test_full_run_files_cover_the_whole_run(tmp_path):
    folder = write_run(
        sm.simulate(sm.default_parameters(solver="full", duration=2.0)), tmp_path / "full", preset=DEFAULT_PRESET
    )
    with xr.open_dataset(folder / "timeseries.nc", engine="h5netcdf") as series:
        assert "coverage" not in series.attrs and "coverage" not in series["x"].attrs
    assert b"coverage" not in pq.read_schema(folder / "impacts.parquet").metadata


@pytest.mark.parametrize(
    "values",
    [
        np.array(["left", "right", "left"]),
        np.array(["é", "", "naïve wall"]),  # multi-byte UTF-8 and an empty string
        np.empty(0, dtype=str),
        np.arange(12.0).reshape(4, 3)[:, 1],  # a strided column of the impact records
        np.array([1, -2, 3], dtype=np.int64),
        np.array([np.nan, np.inf, -0.0]),
    ],
)
def test_arrow_arrays_built_from_buffers_hold_the_values(values):
    array = storage.arrow_array(values)
    assert len(array) == values.size and array.null_count == 0
    np.testing.assert_array_equal(array.to_numpy(zero_copy_only=False), values)


def as_version_1(folder: Path, change) -> None:
    """Make ``folder``'s summary.json one an older shakermill wrote (no schema_version), its summary changed by
    ``change``."""
    path = folder / "summary.json"
    document = json.loads(path.read_text(encoding="utf-8"))
    del document["schema_version"]
    change(document["summary"])
    path.write_text(json.dumps(document), encoding="utf-8")


def test_an_old_run_folder_is_read_with_its_keys_brought_forward(run_folder):
    def older(summary):
        summary["clamp_C"], summary["clamp_steady_C"] = 25.5, 31.0  # the holder's keys, before it was called so
        for added_since in ("exponential_fit_describes_run", "stress_window_s", "fast_impact_rate_hz"):
            del summary[added_since]
        summary["a_key_since_removed"] = 1.0

    as_version_1(run_folder, older)
    summary = load_run(run_folder).summary
    assert (summary.temperatures.holder, summary.steady.holder) == (25.5, 31.0)
    # As the readers of version 1 assumed: the fit's rows shown; a key it lacked is NaN (shown "n/a").
    assert summary.exponential_fit_describes_run is True
    assert math.isnan(summary.stress_window_s) and math.isnan(summary.impacts.fast_rate_hz)
    assert summary.impacts.count > 0


def test_an_old_run_folder_that_does_not_fit_is_refused_in_one_line_that_says_to_re_run_it(run_folder):
    as_version_1(run_folder, lambda summary: summary.pop("impacts"))
    with pytest.raises(StorageError) as refused:
        load_run(run_folder)
    message = str(refused.value)
    assert "\n" not in message and message.startswith(f"{run_folder}: summary.json")
    assert "older shakermill (summary schema 1)" in message and "'impacts'" in message
    assert f"re-run it to read it here: shakermill run {run_folder / 'config.toml'} --out NEW_FOLDER" in message


def test_a_run_folder_of_a_newer_schema_is_refused_in_one_line(run_folder):
    path = run_folder / "summary.json"
    document = json.loads(path.read_text(encoding="utf-8"))
    document["schema_version"] = SCHEMA_VERSION + 1
    path.write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(StorageError, match=f"newer shakermill \\(summary schema {SCHEMA_VERSION + 1}.*upgrade"):
        load_run(run_folder)


def test_a_current_summary_with_a_key_the_schema_does_not_declare_is_refused(run_folder):
    path = run_folder / "summary.json"
    document = json.loads(path.read_text(encoding="utf-8"))
    document["summary"]["ball_c"] = 20.0
    path.write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(StorageError, match="summary.json: 'ball_c' is not a summary key .*did you mean 'ball_C'"):
        load_run(run_folder)
