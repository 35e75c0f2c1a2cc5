"""Parameter sweeps (issue 5): grids and point files, local pool, Dask cluster, resume, failures, the CLI.

Short runs of the averaged solver (~0.04 s a point once Numba's cache is warm) keep the file fast;
amplitudes are >= 23 mm so that a ball starting at rest is hit (the free gap is 22.65 mm).
"""

from __future__ import annotations

import importlib
import itertools
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from pandas.testing import assert_frame_equal

from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import default_parameters
from shakermill.studies.sweeps.backends import connect
from shakermill.studies.sweeps.plan import SweepPlan, parse_grid, plan_sweep, point_ids, read_points, sweep_parameters
from shakermill.studies.sweeps.storage import (
    MANIFEST_FILE,
    POINTS_FOLDER,
    TABLE_CSV,
    TABLE_PARQUET,
    comparable_columns,
    failed_points,
    load_sweep,
)
from shakermill.studies.sweeps.sweep import SweepFailed, SweepInterrupted, sweep

DURATION = 60.0  # simulated seconds per point
GRID = ("omega=100:120:3", "amplitude=23mm:29mm:2")  # 6 points
SHAKERMILL = Path(sys.executable).parent / "shakermill"
UNREACHABLE = "tcp://127.0.0.1:1"  # port 1 on loopback: nothing listens, connections are refused
POINTS_MODULE = importlib.import_module("shakermill.studies.sweeps.points")


@pytest.fixture(scope="module")
def base():
    return default_parameters(solver="averaged", duration=DURATION)


@pytest.fixture(scope="module")
def in_process(base, tmp_path_factory):
    """The small grid computed in this process (workers=1): the reference table."""
    plan = plan_sweep(GRID)
    folder = tmp_path_factory.mktemp("in_process")
    return plan, sweep(base, plan, folder, workers=1), folder


def comparable(table: pd.DataFrame) -> pd.DataFrame:
    return table[comparable_columns(table)].reset_index(drop=True)


def point_files(folder: Path) -> list[Path]:
    return sorted((folder / POINTS_FOLDER).glob("*.json"))


def partial_files(folder: Path) -> list[Path]:
    return [path for path in folder.rglob("*") if "partial" in path.name]


def assert_one_error_line(stderr: str, *fragments: str) -> None:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith("error: "), stderr
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    assert "Traceback" not in stderr


def run_cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([str(SHAKERMILL), *args], capture_output=True, text=True, timeout=timeout)


# Grids and point files ----------------------------------------------------------------------------


def test_parse_grid_converts_units_to_si():
    key, values = parse_grid("amplitude=23mm:30mm:3")
    assert key == "amplitude"
    np.testing.assert_allclose(values, [0.023, 0.0265, 0.030], rtol=1e-12)
    key, values = parse_grid(" omega = 90 : 130 : 5 ")
    assert key == "omega"
    np.testing.assert_allclose(values, np.linspace(90.0, 130.0, 5))
    # Mixed units in START and STOP; Hz on an angular rate is cycles per second.
    _, values = parse_grid("amplitude=2.3cm:30mm:2")
    np.testing.assert_allclose(values, [0.023, 0.030])
    _, values = parse_grid("omega=15Hz:20Hz:2")
    np.testing.assert_allclose(values, [2 * np.pi * 15, 2 * np.pi * 20])
    # One point: START.
    _, values = parse_grid("omega=100:130:1")
    np.testing.assert_allclose(values, [100.0])


def test_plan_is_the_product_with_the_first_grid_slowest():
    plan = plan_sweep(["omega=90:130:3", "amplitude=23mm:30mm:2"])
    assert plan.keys == ("omega", "amplitude")
    assert plan.grids == ("omega=90:130:3", "amplitude=23mm:30mm:2")
    omegas = parse_grid("omega=90:130:3")[1]
    amplitudes = parse_grid("amplitude=23mm:30mm:2")[1]
    expected = [{"omega": w, "amplitude": a} for w, a in itertools.product(omegas, amplitudes)]
    assert len(plan.points) == 6
    for point, wanted in zip(plan.points, expected):
        assert list(point) == ["omega", "amplitude"]
        assert point == pytest.approx(wanted)
    # The first grid varies slowest: omega is constant over the first two points.
    assert plan.points[0]["omega"] == plan.points[1]["omega"] != plan.points[2]["omega"]
    assert plan.points[0]["amplitude"] != plan.points[1]["amplitude"]


@pytest.mark.parametrize(
    ("spec", "fragments"),
    [
        ("omega90:130:3", ["'omega90:130:3'", "KEY=START:STOP:N"]),
        ("=90:130:3", ["KEY=START:STOP:N"]),
        ("omega=90:130", ["three fields", "got 2"]),
        ("omega=90:100:130:3", ["three fields", "got 4"]),
        ("omega=90:130:0", ["N must be a whole number", "'0'"]),
        ("omega=90:130:-3", ["N must be a whole number", "'-3'"]),
        ("omega=90:130:2.5", ["N must be a whole number", "'2.5'"]),
        ("omega=90:130:many", ["N must be a whole number", "'many'"]),
        ("omega=90:130:²", ["N must be a whole number", "'²'"]),  # str.isdigit() is true for '²'; int() refuses it
        ("omgea=90:130:3", ["omgea", "unknown parameter", "did you mean 'omega'"]),
        ("frobnicate=1:2:3", ["frobnicate", "unknown parameter"]),
        ("solver=1:2:3", ["solver", "START:STOP:N is for real-valued parameters", "solver=A,B,C"]),
        ("amplitude=23 kg:30mm:3", ["amplitude", "kg", "expected a length such as m or mm"]),
        ("amplitude=23mm:30 s:3", ["amplitude", "wrong dimension", "expected a length"]),
        ("amplitude=23 blorps:30mm:3", ["amplitude", "cannot parse"]),
        ("omega=nan:130:3", ["omega", "'nan' is not a finite number"]),
        ("averaging_batch_periods=8:32:4", ["averaging_batch_periods", "real-valued", "averaging_batch_periods=A,B,C"]),
    ],
)
def test_bad_grid_is_one_line_naming_the_problem(spec, fragments):
    with pytest.raises(ParameterError) as caught:
        parse_grid(spec)
    message = str(caught.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    # plan_sweep passes the same error on.
    with pytest.raises(ParameterError, match="grid"):
        plan_sweep([spec])


def test_plan_refuses_nothing_to_sweep_and_a_key_twice():
    with pytest.raises(ParameterError, match="nothing to sweep"):
        plan_sweep([])
    with pytest.raises(ParameterError, match="omega: more than one"):
        plan_sweep(["omega=90:100:2", "omega=110:120:2"])


def test_read_points_with_units_and_a_byte_order_mark(tmp_path):
    path = tmp_path / "points.csv"
    # A spreadsheet's export: BOM, CRLF line ends, a blank line, units in some cells.
    path.write_bytes("\ufeffomega,amplitude,solver\r\n100,25 mm,averaged\r\n\r\n17 Hz,0.026,full\r\n".encode())
    points = read_points(path)
    assert [list(point) for point in points] == [["omega", "amplitude", "solver"]] * 2
    assert points[0] == pytest.approx({"omega": 100.0, "amplitude": 0.025, "solver": "averaged"})
    assert points[1]["omega"] == pytest.approx(2 * np.pi * 17)
    assert points[1]["amplitude"] == pytest.approx(0.026)
    assert points[1]["solver"] == "full"


def test_points_file_times_grid(tmp_path):
    path = tmp_path / "points.csv"
    path.write_text("restitution\n0.6\n0.8\n", encoding="utf-8")
    plan = plan_sweep(["amplitude=23mm:29mm:3"], points_file=path)
    assert plan.keys == ("restitution", "amplitude")
    assert plan.points_file == str(path)
    assert [(p["restitution"], round(p["amplitude"], 6)) for p in plan.points] == [
        (r, a) for r in (0.6, 0.8) for a in (0.023, 0.026, 0.029)
    ]


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("omega,amplitud\n100,25mm\n", ["amplitud", "unknown parameter", "did you mean 'amplitude'"]),
        ("omega,amplitude\n100,25mm\n110,\n", ["line 3", "no value for amplitude"]),
        ("omega,amplitude\n100,25mm\n110,25mm,7\n", ["line 3", "3 values for 2 columns"]),
        ("omega,amplitude\n100\n", ["line 2", "1 values for 2 columns"]),
        ("omega,amplitude\n100,25 kg\n", ["line 2", "amplitude", "expected a length"]),
        ("omega,omega\n100,110\n", ["omega", "more than one column"]),
        ("omega,amplitude\n", ["at least one row"]),
    ],
)
def test_bad_points_file_is_one_line_naming_the_problem(tmp_path, text, fragments):
    path = tmp_path / "points.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ParameterError) as caught:
        read_points(path)
    message = str(caught.value)
    assert "\n" not in message
    assert str(path) in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_missing_points_file(tmp_path):
    with pytest.raises(ParameterError, match="cannot read"):
        read_points(tmp_path / "absent.csv")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("content", "fragments"),
    [
        ("omega\n100\n# Mühle\n".encode("latin-1"), ["not UTF-8 text"]),
        (b"omega\n" + b"1" * 500 + b"\n", ["line 2: a cell of 500 characters; allowed at most 100"]),
        (b'omega\n"' + b"1" * 140_000 + b'"\n', ["malformed CSV at line 2"]),
        (b"omega\n100\nnan\n", ["line 3", "omega: 'nan' is not a finite number"]),
        (b"omega\n" + b"100\n" * 100_001, ["more than 100,000 rows after the header; allowed at most 100,000"]),
    ],
)
def test_a_points_file_beyond_the_limits_is_one_line_naming_it(tmp_path, content, fragments):
    path = tmp_path / "points.csv"
    path.write_bytes(content)
    with pytest.raises(ParameterError) as caught:
        read_points(path)
    message = str(caught.value)
    assert message.startswith(f"points {path}"), message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


@pytest.mark.parametrize(
    ("grids", "message"),
    [
        (["omega=90:130:100000000000"], "N must be a whole number of points in [1, 100,000], got '100000000000'"),
        (["omega=90:130:" + "9" * 5000], "(5002 characters)"),
        (["omega=90:130:1000", "amplitude=20mm:30mm:1000"], "sweep: 1,000,000 points; allowed at most 100,000"),
    ],
)
def test_grids_are_capped_before_their_points_are_made(grids, message):
    started = time.process_time()
    with pytest.raises(ParameterError) as caught:
        plan_sweep(grids)
    assert message in str(caught.value)
    assert time.process_time() - started < 1.0


def test_a_grid_times_a_points_file_is_capped_as_a_product(tmp_path):
    path = tmp_path / "points.csv"
    path.write_text("restitution\n0.6\n0.8\n", encoding="utf-8")
    with pytest.raises(ParameterError, match="sweep: 200,000 points"):
        plan_sweep(["omega=90:130:100000"], points_file=path)


def test_the_python_api_caps_the_points_it_is_given(tmp_path):
    with pytest.raises(ParameterError, match="sweep: 1,000,000 points"):
        sweep(
            default_parameters(),
            {"omega": np.linspace(90, 130, 1000), "amplitude": np.linspace(0.02, 0.03, 1000)},
            tmp_path / "sweep",
        )
    assert not (tmp_path / "sweep").exists()


def test_an_averaged_sweep_is_not_held_to_the_full_solvers_limits():
    # Eleven simulated days: too many drive periods for the full solver, nothing for the averaged one.
    base = sweep_parameters(None, preset=None, overrides=["duration=1e6", "output_interval=60"], full_resolution=False)
    assert base.params.solver == "averaged" and base.params.duration == 1e6
    with pytest.raises(ParameterError, match="duration: 1e\\+06 s at omega = 111 rad/s"):
        sweep_parameters(None, preset=None, overrides=["duration=1e6", "output_interval=60"], full_resolution=True)
    with pytest.raises(ParameterError, match="--full-resolution contradicts solver = 'averaged'"):
        sweep_parameters(None, preset=None, overrides=["solver=averaged"], full_resolution=True)


# Execution: in process, local pool, Dask cluster ---------------------------------------------------


@pytest.mark.slow
def test_in_process_table(base, in_process, tmp_path):
    plan, table, _ = in_process
    ids = point_ids(base, plan)
    assert list(table["point_id"]) == ids
    assert len(set(ids)) == len(ids) == 6
    assert list(table.columns[:6]) == ["point_id", "omega", "amplitude", "regime", "period", "error"]
    for column in ("omega", "amplitude"):
        np.testing.assert_array_equal(table[column].to_numpy(), [point[column] for point in plan.points])
    assert table["success"].all()
    assert table["error"].isna().all()
    assert failed_points(table).empty
    assert (table["impacts"] > 0).all()
    # The averaged solver ran (the swept keys don't include solver, so the column is `solver`).
    assert set(table["solver"]) <= {"averaged", "full"}
    assert "wall_time_s" in table and "wall_time_s" not in comparable_columns(table)
    assert "output_dir" not in comparable_columns(table)
    # The same run on its own gives the row's figures: the sweep adds nothing of its own.
    from shakermill.solvers.simulate import simulate

    alone = simulate(base.replace(**plan.points[4])).summary
    for key in ("theta_inf_C", "tau_min", "impacts", "heat_power_W"):
        assert table.loc[4, key] == alone.value(key), key


@pytest.mark.slow
def test_tables_on_disk_match_the_returned_table(in_process):
    _, table, folder = in_process
    data = load_sweep(folder)
    assert data.keys == ("omega", "amplitude")
    assert_frame_equal(comparable(data.table), comparable(table))
    assert len(point_files(folder)) == len(table)
    # sweep.csv holds the same rows as sweep.parquet.
    assert_csv_matches_parquet(folder)


def assert_csv_matches_parquet(folder: Path) -> None:
    parquet = pd.read_parquet(folder / TABLE_PARQUET)
    csv = pd.read_csv(folder / TABLE_CSV)
    assert list(csv.columns) == list(parquet.columns)
    assert len(csv) == len(parquet)
    assert list(csv["point_id"].astype(str)) == list(parquet["point_id"])
    for column in parquet.columns:
        left, right = csv[column], parquet[column]
        if pd.api.types.is_bool_dtype(right) or pd.api.types.is_numeric_dtype(right):
            np.testing.assert_array_equal(
                left.to_numpy(dtype=float, na_value=np.nan),
                right.to_numpy(dtype=float, na_value=np.nan),
                err_msg=column,
            )
        else:
            assert [None if pd.isna(v) else str(v) for v in left] == [None if pd.isna(v) else str(v) for v in right], (
                column
            )


@pytest.mark.slow
def test_local_pool_matches_in_process_in_grid_order(base, in_process, tmp_path):
    plan, reference, _ = in_process
    table = sweep(base, plan, tmp_path / "pool", workers=2)
    assert_frame_equal(comparable(table), comparable(reference))
    assert_frame_equal(comparable(load_sweep(tmp_path / "pool").table), comparable(reference))


@pytest.mark.slow
def test_rows_follow_the_plan_not_the_completion_order(base, tmp_path):
    # The first point runs at full resolution for 40 simulated minutes (~1.5 s), the others are
    # one simulated minute with the averaged solver (~0.03 s): with two workers the first finishes last.
    keys = ("solver", "duration", "amplitude")
    slow = {"solver": "full", "duration": 2400.0, "amplitude": 0.025}
    fast = [{"solver": "averaged", "duration": 60.0, "amplitude": a} for a in (0.023, 0.024, 0.026, 0.027, 0.028)]
    points = [slow, *fast]
    folder = tmp_path / "order"
    table = sweep(base, points, folder, workers=2)
    ids = point_ids(base, SweepPlan(keys, tuple(points)))
    finished = {path.stem: path.stat().st_mtime_ns for path in point_files(folder)}
    assert finished[ids[0]] > max(finished[identifier] for identifier in ids[1:]), "the slow point did not finish last"
    assert list(table["point_id"]) == ids
    assert list(table.columns[1:4]) == list(keys)
    for key in keys:
        assert list(table[key]) == [point[key] for point in points], key
    # `solver` is swept, so the summary's solver (the one that actually ran) is `solver_used`.
    assert table.loc[0, "solver_used"] == "full"
    assert table["success"].all()


@pytest.fixture
def local_cluster():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    )
    try:
        yield cluster
    finally:
        cluster.close()


@pytest.mark.slow
def test_dask_cluster_matches_local_pool(base, in_process, local_cluster, tmp_path):
    plan, _, _ = in_process
    pool = sweep(base, plan, tmp_path / "pool", workers=2)
    reports = []
    cluster = sweep(
        base, plan, tmp_path / "cluster", scheduler=local_cluster.scheduler_address, progress=reports.append
    )
    assert_frame_equal(comparable(cluster), comparable(pool))
    assert len(point_files(tmp_path / "cluster")) == len(plan.points)
    assert reports[-1].done == len(plan.points) and reports[-1].failed == 0
    # The cluster's two single-threaded workers are its slots.
    assert reports[0].running == 2


def test_workers_and_scheduler_are_exclusive(base, tmp_path):
    with pytest.raises(ParameterError, match="workers"):
        sweep(base, plan_sweep(GRID), tmp_path / "x", workers=2, scheduler=UNREACHABLE)
    with pytest.raises(ParameterError, match="workers: 0"):
        sweep(base, plan_sweep(GRID), tmp_path / "y", workers=0)


@pytest.mark.slow
def test_unreachable_scheduler_is_one_line(base, tmp_path):
    started = time.monotonic()
    with pytest.raises(ParameterError) as caught:
        connect(UNREACHABLE, timeout=2)
    message = str(caught.value)
    assert message.startswith("scheduler: ") and UNREACHABLE in message and "\n" not in message
    with pytest.raises(ParameterError) as caught:
        sweep(base, plan_sweep(GRID), tmp_path / "s", scheduler=UNREACHABLE, scheduler_timeout=2)
    assert "scheduler" in str(caught.value) and "\n" not in str(caught.value)
    assert time.monotonic() - started < 30, "the timeout was not respected"
    # Nothing was computed, and no folder was left behind.
    assert not (tmp_path / "s").exists()


@pytest.fixture
def tcp_server():
    """``serve(reply)``: the address of a loopback TCP server that accepts and sends ``reply`` (b"": says nothing)."""
    import socket
    import threading

    listeners, held = [], []

    def serve(reply: bytes) -> str:
        listener = socket.create_server(("127.0.0.1", 0))
        listeners.append(listener)

        def accept() -> None:
            while True:
                try:
                    connection, _ = listener.accept()
                except OSError:  # closed at the end of the test
                    return
                held.append(connection)
                if reply:
                    connection.sendall(reply)

        threading.Thread(target=accept, daemon=True).start()
        return f"tcp://127.0.0.1:{listener.getsockname()[1]}"

    yield serve
    for item in (*held, *listeners):
        item.close()


@pytest.mark.slow
@pytest.mark.parametrize(
    ("reply", "fragment"),
    [
        (b"", "did not answer as a Dask scheduler"),  # an HTTP server such as the dashboard waits for a request
        (b"HTTP/1.1 400 Bad Request\r\n\r\n" * 4, "scheduler"),  # another protocol answers
    ],
)
def test_a_server_that_is_not_a_scheduler_is_one_line_within_the_timeout(base, tmp_path, tcp_server, reply, fragment):
    address = tcp_server(reply)
    started = time.monotonic()
    with pytest.raises(ParameterError) as caught:
        sweep(base, plan_sweep(GRID), tmp_path / "s", scheduler=address, scheduler_timeout=1)
    message = str(caught.value)
    assert message.startswith("scheduler: ") and address in message and fragment in message, message
    assert "\n" not in message
    assert time.monotonic() - started < 10, "the handshake was not bounded by the timeout"
    assert not (tmp_path / "s").exists()


def test_unparsable_scheduler_address_is_one_line():
    with pytest.raises(ParameterError, match="scheduler") as caught:
        connect("nonsense://::::", timeout=2)
    assert "\n" not in str(caught.value)


# Resume, failures, other sweeps -------------------------------------------------------------------


@pytest.mark.slow
def test_resume_recomputes_only_missing_points(base, in_process, tmp_path):
    plan, reference, _ = in_process
    folder = tmp_path / "resume"
    first = sweep(base, plan, folder, workers=1)
    assert_frame_equal(comparable(first), comparable(reference))
    files = point_files(folder)
    before = {path.name: path.stat().st_mtime_ns for path in files}
    removed = files[2]
    removed.unlink()
    time.sleep(0.01)  # a later mtime for the recomputed file even on coarse clocks

    reports = []
    second = sweep(base, plan, folder, workers=1, progress=reports.append)
    total = len(plan.points)
    assert [report.done for report in reports] == [total - 1, total]
    assert all(report.total == total and report.failed == 0 for report in reports)
    after = {path.name: path.stat().st_mtime_ns for path in point_files(folder)}
    assert set(after) == set(before)
    assert [name for name in after if after[name] != before[name]] == [removed.name]
    assert_frame_equal(comparable(second), comparable(first))
    assert_frame_equal(comparable(load_sweep(folder).table), comparable(first))

    # A finished sweep run again computes nothing.
    reports.clear()
    third = sweep(base, plan, folder, workers=2, progress=reports.append)
    assert [report.done for report in reports] == [total]
    assert {path.name: path.stat().st_mtime_ns for path in point_files(folder)} == after
    assert_frame_equal(comparable(third), comparable(first))


@pytest.mark.slow
def test_table_is_rebuilt_from_point_files_if_missing(in_process, base, tmp_path):
    plan, reference, _ = in_process
    folder = tmp_path / "rebuild"
    sweep(base, plan, folder, workers=1)
    (folder / TABLE_PARQUET).unlink()
    rebuilt = load_sweep(folder).table
    assert_frame_equal(comparable(rebuilt), comparable(reference))


@pytest.mark.slow
def test_failing_point_records_its_error_and_the_others_finish(base, tmp_path):
    # restitution is allowed in (0, 1]: the last point is out of range.
    plan = plan_sweep(["restitution=0.5:1.3:3", "amplitude=24mm:26mm:2"])
    reports = []
    table = sweep(base, plan, tmp_path / "fail", workers=1, progress=reports.append)
    bad = table["restitution"] > 1
    assert bad.sum() == 2 and len(table) == 6
    for _, row in table[bad].iterrows():
        assert not row["success"]
        assert "restitution" in row["error"] and "out of range" in row["error"] and "(0, 1]" in row["error"]
        assert pd.isna(row["regime"])
    assert table.loc[~bad, "success"].all()
    assert table.loc[~bad, "error"].isna().all()
    assert (table.loc[~bad, "impacts"] > 0).all()
    assert list(failed_points(table)["point_id"]) == list(table.loc[bad, "point_id"])
    assert reports[-1].done == 6 and reports[-1].failed == 2
    # Failed points are finished too: a re-run does not retry them.
    reports.clear()
    again = sweep(base, plan, tmp_path / "fail", workers=1, progress=reports.append)
    assert [(report.done, report.failed) for report in reports] == [(6, 2)]
    assert_frame_equal(comparable(again), comparable(table))


@pytest.mark.slow
def test_points_file_with_one_out_of_range_value(base, tmp_path):
    path = tmp_path / "points.csv"
    path.write_text("omega,amplitude\n100,25 mm\n-5,25 mm\n120 rad/s,2.4 cm\n", encoding="utf-8")
    table = sweep(base, plan_sweep(points_file=path), tmp_path / "sweep", workers=2)
    assert list(table["success"]) == [True, False, True]
    assert "omega" in table.loc[1, "error"] and "out of range" in table.loc[1, "error"]
    assert table.loc[[0, 2], "error"].isna().all()
    assert table.loc[2, "amplitude"] == pytest.approx(0.024)


@pytest.mark.slow
def test_a_folder_with_another_sweep_is_refused(base, tmp_path):
    folder = tmp_path / "taken"
    plan = plan_sweep(["omega=100:110:2"])
    sweep(base, plan, folder, workers=1)
    with pytest.raises(ParameterError, match="other points") as caught:
        sweep(base, plan_sweep(["omega=100:120:2"]), folder, workers=1)
    assert "\n" not in str(caught.value)
    with pytest.raises(ParameterError, match="other base parameters") as caught:
        sweep(base.replace(restitution=0.6), plan, folder, workers=1)
    assert "restitution" in str(caught.value)
    # A folder that is not a sweep and is not empty is refused and left alone.
    other = tmp_path / "mine"
    other.mkdir()
    (other / "notes.txt").write_text("keep me", encoding="utf-8")
    with pytest.raises(ParameterError, match="not a shakermill sweep folder"):
        sweep(base, plan, other, workers=1)
    assert sorted(path.name for path in other.iterdir()) == ["notes.txt"]


@pytest.mark.slow
def test_keep_runs_writes_each_point_run_folder(base, tmp_path):
    from shakermill.io.runs import load_run

    plan = plan_sweep(["amplitude=24mm:26mm:2"])
    kept = sweep(base, plan, tmp_path / "kept", workers=1, keep_runs=True)
    plain = sweep(base, plan, tmp_path / "plain", workers=1)
    assert_frame_equal(comparable(kept), comparable(plain))
    assert plain["output_dir"].isna().all()
    for _, row in kept.iterrows():
        folder = Path(row["output_dir"])
        assert folder == tmp_path / "kept" / "runs" / row["point_id"]
        run = load_run(folder)
        assert run.summary.impacts.count == row["impacts"]
        assert run.params.amplitude == row["amplitude"]


def test_a_point_listed_twice_is_refused(base, tmp_path):
    with pytest.raises(ParameterError, match="repeats point 1"):
        sweep(base, [{"omega": 100.0}, {"omega": "100 rad/s"}], tmp_path / "twice", workers=1)


# The command line ---------------------------------------------------------------------------------


@pytest.mark.slow
def test_cli_bad_grid_exits_2_with_one_line(tmp_path):
    completed = run_cli("sweep", "--grid", "bogus", "--out", str(tmp_path / "s"))
    assert completed.returncode == 2, completed.stderr
    assert_one_error_line(completed.stderr, "bogus")
    completed = run_cli("sweep", "--grid", "omgea=90:130:3", "--out", str(tmp_path / "s"))
    assert completed.returncode == 2, completed.stderr
    assert_one_error_line(completed.stderr, "omgea")
    assert not (tmp_path / "s" / MANIFEST_FILE).exists()


@pytest.mark.slow
def test_cli_unreachable_scheduler_exits_2_with_one_line(tmp_path):
    folder = tmp_path / "s"
    completed = run_cli(
        "sweep", "--grid", "omega=100:110:2", "--set", "duration=60", "--out", str(folder),
        "--scheduler", UNREACHABLE, "--scheduler-timeout", "2",
    )  # fmt: skip
    assert completed.returncode == 2, completed.stderr
    assert_one_error_line(completed.stderr, "scheduler", UNREACHABLE)
    assert not folder.exists()  # the connection is tried before the sweep folder is created


@pytest.mark.slow
def test_cli_sweep_writes_matching_csv_and_parquet(base, tmp_path):
    folder = tmp_path / "cli"
    completed = run_cli(
        "sweep", "--grid", "omega=100:120:2", "--grid", "amplitude=23mm:29mm:2", "--set", "duration=60",
        "--set", "restitution=0.8", "--out", str(folder), "--workers", "2", "--json",
    )  # fmt: skip
    assert completed.returncode == 0, completed.stderr
    assert "Traceback" not in completed.stderr
    json.loads(completed.stdout)  # --json prints one JSON document
    table = load_sweep(folder).table
    assert len(table) == 4 and table["success"].all()
    assert_csv_matches_parquet(folder)
    # The command line's base: the default preset, the averaged solver, --set applied.
    expected = sweep(
        base.replace(restitution=0.8),
        plan_sweep(["omega=100:120:2", "amplitude=23mm:29mm:2"]),
        tmp_path / "api",
        workers=1,
    )
    assert_frame_equal(comparable(table), comparable(expected))


@pytest.mark.slow
def test_cli_some_points_failed_exits_1(tmp_path):
    folder = tmp_path / "cli"
    completed = run_cli(
        "sweep", "--grid", "restitution=0.9:1.1:2", "--set", "duration=60", "--out", str(folder), "--workers", "1"
    )
    assert completed.returncode == 1, completed.stderr
    assert "Traceback" not in completed.stderr
    table = load_sweep(folder).table
    assert list(table["success"]) == [True, False]
    assert "restitution" in table.loc[1, "error"]


# Killed and resumed -------------------------------------------------------------------------------


def _live_processes_in_group(group: int) -> list[int]:
    """The processes of ``group`` that are not zombies (Linux /proc)."""
    live = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        fields = text[text.rindex(")") + 2 :].split()
        state, process_group = fields[0], int(fields[2])
        if process_group == group and state != "Z":
            live.append(int(stat.parent.name))
    return live


@pytest.mark.slow
def test_sigkill_mid_sweep_then_resume(tmp_path):
    # 64 points of one simulated minute: ~0.03 s each, ~1 s on two workers after their start.
    grid = ["omega=90:130:8", "amplitude=23mm:30mm:8"]
    settings = ["--set", "duration=60"]
    folder = tmp_path / "killed"
    command = [
        str(SHAKERMILL),
        "sweep",
        *(arg for spec in grid for arg in ("--grid", spec)),
        *settings,
        "--out",
        str(folder),
        "--workers",
        "2",
    ]
    total = 64

    process = subprocess.Popen(command, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while True:
            done = len(point_files(folder)) if (folder / POINTS_FOLDER).is_dir() else 0
            if done >= 3:
                os.killpg(process.pid, signal.SIGKILL)
                break
            if process.poll() is not None or time.monotonic() > deadline:
                pytest.fail(
                    f"the sweep ended or stalled before it could be killed (rc {process.poll()}): "
                    f"{process.stderr.read()!r}"
                )
            time.sleep(0.002)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=30)
        process.stderr.close()
    assert process.returncode == -signal.SIGKILL
    finished_before = {path.name: path.stat().st_mtime_ns for path in point_files(folder)}
    print(f"killed after {len(finished_before)} of {total} points")
    assert 3 <= len(finished_before) < total, f"{len(finished_before)} of {total} points finished: not killed mid-way"
    if Path("/proc/self/stat").exists():
        waited = time.monotonic() + 10
        while _live_processes_in_group(process.pid) and time.monotonic() < waited:
            time.sleep(0.05)
        assert _live_processes_in_group(process.pid) == [], "pool workers outlived the killed sweep"

    completed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr

    # Points finished before the kill were kept, not recomputed.
    after = {path.name: path.stat().st_mtime_ns for path in point_files(folder)}
    assert {name: after[name] for name in finished_before} == finished_before
    assert len(after) == total
    assert partial_files(folder) == []

    manifest = json.loads((folder / MANIFEST_FILE).read_text(encoding="utf-8"))
    planned = [entry["point_id"] for entry in manifest["points"]]
    table = pd.read_parquet(folder / TABLE_PARQUET)
    assert len(planned) == total == len(table)
    assert table["point_id"].is_unique
    assert list(table["point_id"]) == planned
    assert table["success"].all()
    assert_csv_matches_parquet(folder)

    # The same sweep, uninterrupted, in this process: the same ids (same base) and the same values.
    base = sweep_parameters(None, preset=None, overrides=["duration=60"], full_resolution=False).params
    uninterrupted = sweep(base, plan_sweep(grid), tmp_path / "uninterrupted", workers=1)
    assert list(uninterrupted["point_id"]) == planned
    assert_frame_equal(comparable(table), comparable(load_sweep(tmp_path / "uninterrupted").table))


@pytest.mark.slow
def test_ctrl_c_keeps_the_finished_points_in_the_table_and_exits_130(tmp_path):
    # Ctrl-C in a terminal sends SIGINT to the whole foreground group: the sweep and its workers.
    folder = tmp_path / "interrupted"
    command = [str(SHAKERMILL), "sweep", "--grid", "omega=90:130:8", "--grid", "amplitude=23mm:30mm:8",
               "--set", "duration=60", "--out", str(folder), "--workers", "2"]  # fmt: skip
    process = subprocess.Popen(
        command, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + 120
    while not ((folder / POINTS_FOLDER).is_dir() and len(point_files(folder)) >= 3):
        if process.poll() is not None or time.monotonic() > deadline:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
            pytest.fail(f"the sweep ended or stalled before it could be interrupted: {process.communicate()[1]!r}")
        time.sleep(0.002)
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    table = pd.read_parquet(folder / TABLE_PARQUET)
    finished = table["error"].isna()
    assert_one_error_line(
        stderr,
        "interrupted",
        f"kept {finished.sum()} of 64 points",
        f"--out {folder}",
        f"the other {64 - finished.sum()}",
    )
    assert finished.sum() == len(point_files(folder)) and 3 <= finished.sum() < 64
    assert table.loc[~finished, "error"].str.startswith("not finished").all()
    assert table["point_id"].is_unique and len(table) == 64

    completed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    assert load_sweep(folder).table["error"].isna().all()


def _alive(processes: list) -> list[int]:
    return [process.pid for process in processes if _live(process)]


def wait_for_a_stored_point(process: subprocess.Popen, folder: Path, seconds: float, before: str) -> None:
    """Wait until the sweep ``process`` has stored a point in ``folder``; fail if it ends or stalls first."""
    deadline = time.monotonic() + seconds
    while not ((folder / POINTS_FOLDER).is_dir() and point_files(folder)):
        assert process.poll() is None and time.monotonic() < deadline, f"the sweep ended or stalled before {before}"
        time.sleep(0.01)


@pytest.mark.slow
def test_ctrl_c_stops_a_3d_sweeps_workers_within_2_s_and_the_resume_computes_only_the_running_points(tmp_path):
    import psutil

    folder = tmp_path / "three_d"
    # The 3-D engine at full resolution takes ~10 s of wall time per simulated second: the 0.2-s point ends while
    # the 0.7-s and 1.2-s points run, and those would run for seconds more.
    command = [str(SHAKERMILL), "sweep", "--preset", "spex8000m-3d", "--set", "solver=full", "--set", "record_windows=",
               "--grid", "duration=0.2:1.2:3", "--out", str(folder), "--workers", "2"]  # fmt: skip
    process = subprocess.Popen(
        command, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
    )
    descendants = []
    try:
        wait_for_a_stored_point(process, folder, 180, "Ctrl-C")
        descendants = psutil.Process(process.pid).children(recursive=True)
        assert len(descendants) >= 3  # two workers and the forkserver that started them
        os.killpg(process.pid, signal.SIGINT)
        signalled = time.monotonic()
        while (process.poll() is None or _alive(descendants)) and time.monotonic() - signalled < 10:
            time.sleep(0.01)
        gone_after = time.monotonic() - signalled
        assert process.poll() is not None and _alive(descendants) == [], (
            f"still running {gone_after:.1f} s after Ctrl-C"
        )
        print(f"the sweep and its {len(descendants)} helper processes gone {gone_after:.2f} s after Ctrl-C")
        assert gone_after < 2.0
    finally:
        for descendant in descendants:
            if _live(descendant):
                descendant.kill()
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        stderr = process.communicate(timeout=30)[1]
    assert process.returncode == 130, stderr
    kept = {path.stem: path.stat().st_mtime_ns for path in point_files(folder)}
    table = pd.read_parquet(folder / TABLE_PARQUET)
    not_done = table.loc[table["error"].notna(), "point_id"].tolist()
    assert 1 <= len(kept) < 3 and sorted(kept) == sorted(table.loc[table["error"].isna(), "point_id"])
    assert table.set_index("point_id").loc[not_done, "error"].str.startswith("not finished").all()
    assert_one_error_line(
        stderr, f"kept {len(kept)} of 3 points in {folder}", f"--out {folder} to compute the other {len(not_done)}"
    )

    resumed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    after = {path.stem: path.stat().st_mtime_ns for path in point_files(folder)}
    # The resume ran exactly the points that were running: the kept point files are untouched, the others new.
    assert {identifier: after[identifier] for identifier in kept} == kept
    assert sorted(set(after) - set(kept)) == sorted(not_done)
    assert load_sweep(folder).table["error"].isna().all()


@pytest.mark.slow
def test_ctrl_c_on_a_dask_sweep_cancels_the_points_not_finished(base, local_cluster, tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    cancelled: list[str] = []
    cancel = distributed.Client.cancel

    def recording_cancel(client, futures, *args, **kwargs):
        cancelled.extend(future.key for future in futures)
        return cancel(client, futures, *args, **kwargs)

    monkeypatch.setattr(distributed.Client, "cancel", recording_cancel)

    def ctrl_c_after_the_first_point(state) -> None:
        if state.done >= 1:
            raise KeyboardInterrupt

    plan = plan_sweep(GRID)
    with pytest.raises(SweepInterrupted) as interrupted:
        # Full runs of ten simulated minutes: the other points still run when the first one is stored.
        sweep(
            base.replace(solver="full", duration=600.0),
            plan,
            tmp_path / "dask",
            scheduler=local_cluster.scheduler_address,
            progress=ctrl_c_after_the_first_point,
        )
    table = interrupted.value.table
    assert interrupted.value.kept == 1 == table["error"].isna().sum() == len(point_files(tmp_path / "dask"))
    # Every point not stored was cancelled, unless it finished between Ctrl-C and the cancel.
    assert 0 < len(cancelled) <= len(plan.points) - 1


README_SWEEP = """\
import json
import shakermill as sm

table = sm.sweep(sm.default_parameters(solver="averaged", duration=600),
                 {"omega": [100, 110, 120], "amplitude": ["24 mm", "26 mm"]}, "results/small")
print(json.dumps(table.pivot(index="amplitude", columns="omega", values="theta_inf_C").to_dict()))
"""


@pytest.mark.slow
@pytest.mark.parametrize("guarded", [False, True], ids=["plain script", "guarded script"])
def test_the_readme_sweep_runs_from_a_script_with_or_without_a_main_guard(tmp_path, guarded):
    source = (
        README_SWEEP
        if not guarded
        else "if __name__ == '__main__':\n" + "".join(f"    {line}\n" for line in README_SWEEP.splitlines())
    )
    (tmp_path / "script.py").write_text(source)
    completed = subprocess.run([sys.executable, "script.py"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    assert "BrokenProcessPool" not in completed.stderr and "Error" not in completed.stderr
    pivot = json.loads(completed.stdout)
    assert sorted(float(omega) for omega in pivot) == [100.0, 110.0, 120.0]
    assert all(len(column) == 2 and all(np.isfinite(value) for value in column.values()) for column in pivot.values())


def test_a_sweep_where_every_point_fails_raises_naming_the_first_failure(base, tmp_path):
    with pytest.raises(SweepFailed, match=r"all 2 points failed \(first: [0-9a-f]{16}: .*omega") as raised:
        sweep(base, {"omega": [-1.0, -2.0]}, tmp_path / "failed", workers=1)
    assert len(raised.value.table) == 2
    assert pd.read_csv(tmp_path / "failed" / TABLE_CSV)["error"].notna().all()


@pytest.mark.slow
def test_cli_sweep_where_every_point_fails_exits_1_with_one_line(tmp_path):
    folder = tmp_path / "failed"
    command = [
        str(SHAKERMILL),
        "sweep",
        "--grid",
        "omega=-2:-1:2",
        "--set",
        "duration=60",
        "--out",
        str(folder),
        "--workers",
        "1",
    ]
    completed = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert completed.returncode == 1
    assert_one_error_line(completed.stderr, "2 of 2 points failed", "omega")


# Damaged folders, races, orphaned workers, interrupted points, TLS (issue 12) ----------------------


SMALL = ("omega=100:120:3",)


@pytest.mark.slow
@pytest.mark.parametrize(
    "damage",
    [b"", b'{"point_id": "', b"[]", b'{"row": 3}', b"\xff\xfe\x00garbage"],
    ids=["empty", "truncated", "a JSON array", "a row that is no object", "not UTF-8"],
)
def test_an_unreadable_point_file_is_computed_again(base, tmp_path, damage):
    plan = plan_sweep(SMALL)
    folder = tmp_path / "damaged"
    sweep(base, plan, folder, workers=1)
    files = point_files(folder)
    damaged = files[1]
    damaged.write_bytes(damage)
    untouched = {path: path.stat().st_mtime_ns for path in files if path != damaged}
    # Without the table, the damaged point reads as not finished rather than crashing the reader.
    (folder / TABLE_PARQUET).unlink()
    assert load_sweep(folder).table.set_index("point_id").loc[damaged.stem, "error"].startswith("not finished")

    with pytest.warns(UserWarning, match=rf"unreadable point file .*{damaged.name}.*computing those points again"):
        table = sweep(base, plan, folder, workers=1)
    assert table["error"].isna().all() and len(table) == 3
    assert json.loads(damaged.read_text(encoding="utf-8"))["row"]["point_id"] == damaged.stem
    assert {path: path.stat().st_mtime_ns for path in untouched} == untouched


@pytest.mark.slow
def test_cli_says_in_one_warning_line_that_it_recomputes_an_unreadable_point(tmp_path):
    folder = tmp_path / "damaged"
    command = ["sweep", "--grid", SMALL[0], "--set", f"duration={DURATION}", "--workers", "1", "--out", str(folder)]
    assert run_cli(*command).returncode == 0
    point_files(folder)[0].write_text('{"point_id": "trunc', encoding="utf-8")
    completed = run_cli(*command)
    assert completed.returncode == 0, completed.stderr
    lines = completed.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: sweep: unreadable point file"), completed.stderr
    assert load_sweep(folder).table["error"].isna().all()


@pytest.mark.slow
def test_two_sweeps_racing_into_one_new_folder_one_wins_the_other_is_refused(base, tmp_path, monkeypatch):
    import threading

    folder = tmp_path / "race"
    plans = {"low": plan_sweep(["omega=100:105:2"]), "high": plan_sweep(["omega=110:115:2"])}
    # Both sweeps find the folder free before either creates it: the moment the race is decided.
    both_checked = threading.Barrier(len(plans), timeout=60)
    # The executor checks a folder for every many-run study, the sweep among them.
    executor = importlib.import_module("shakermill.studies.sweeps.executor")
    check_folder = executor.check_folder

    def check_then_wait_for_the_other(*args):
        check_folder(*args)
        both_checked.wait()

    monkeypatch.setattr(executor, "check_folder", check_then_wait_for_the_other)
    outcomes: dict[str, object] = {}

    def start(name: str) -> None:
        try:
            outcomes[name] = sweep(base, plans[name], folder, workers=1)
        except ParameterError as exc:
            outcomes[name] = exc

    threads = [threading.Thread(target=start, args=(name,)) for name in plans]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=120)
    winners = [name for name, outcome in outcomes.items() if isinstance(outcome, pd.DataFrame)]
    losers = [name for name, outcome in outcomes.items() if isinstance(outcome, ParameterError)]
    assert len(winners) == 1 and len(losers) == 1, outcomes
    assert "holds a sweep over other points" in str(outcomes[losers[0]])
    winning_ids = point_ids(base, plans[winners[0]])
    assert sorted(path.stem for path in point_files(folder)) == sorted(winning_ids)
    assert list(load_sweep(folder).table["point_id"]) == winning_ids


@pytest.mark.slow
def test_two_sweep_processes_started_at_once_into_one_new_folder(tmp_path):
    folder = tmp_path / "race"
    grids = ["omega=100:105:2", "omega=110:115:2"]
    processes = [
        subprocess.Popen(
            [
                str(SHAKERMILL),
                "sweep",
                "--grid",
                grid,
                "--set",
                f"duration={DURATION}",
                "--workers",
                "1",
                "--out",
                str(folder),
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        for grid in grids
    ]
    outcomes = [(process.wait(timeout=300), process.stderr.read()) for process in processes]
    for process in processes:
        process.stderr.close()
    codes = sorted(code for code, _ in outcomes)
    assert codes == [0, 2], outcomes
    winner = next(index for index, (code, _) in enumerate(outcomes) if code == 0)
    assert_one_error_line(outcomes[1 - winner][1], str(folder), "choose another --out")
    table = load_sweep(folder).table
    assert list(table["omega"]) == list(parse_grid(grids[winner])[1])
    assert sorted(path.stem for path in point_files(folder)) == sorted(table["point_id"])


@pytest.mark.slow
@pytest.mark.parametrize(
    "crafted", ["../../outside", "/etc/hostname", "0123456789abcdef/../../../outside", "0123456789ABCDEF", 17]
)
def test_a_crafted_point_id_in_the_manifest_is_refused_and_nothing_outside_is_read(base, tmp_path, crafted):
    folder = tmp_path / "crafted"
    sweep(base, {"omega": [100.0, 110.0]}, folder, workers=1)
    # What the crafted id would have the table read: a file outside the sweep folder.
    (tmp_path / "outside.json").write_text(json.dumps({"row": {"point_id": "stolen", "secret": 42}}), encoding="utf-8")
    manifest = json.loads((folder / MANIFEST_FILE).read_text(encoding="utf-8"))
    manifest["points"][0]["point_id"] = crafted
    (folder / MANIFEST_FILE).write_text(json.dumps(manifest), encoding="utf-8")
    (folder / TABLE_PARQUET).unlink()  # the table is then built from the point files the manifest names

    with pytest.raises(ParameterError, match="sweep.json is damaged") as caught:
        load_sweep(folder)
    assert "\n" not in str(caught.value)
    completed = run_cli("plot", str(folder))
    assert completed.returncode == 2
    assert_one_error_line(completed.stderr, "sweep.json is damaged", "point 1")
    assert not (folder / "figures").exists()


def _interrupted_second_point(how: str, simulate: Callable[..., Any]) -> Callable[..., Any]:
    """``simulate`` that is interrupted by Ctrl-C on its second call, the way ``how`` says."""
    calls = []

    def ctrl_c(*_progress) -> None:
        raise KeyboardInterrupt

    def interrupted(params):
        calls.append(params)
        if len(calls) != 2:
            return simulate(params)
        if how == "a run cut short":
            return simulate(params.replace(solver="full"), progress=ctrl_c)
        try:
            ctrl_c()
        except KeyboardInterrupt as interrupt:
            # What Python makes of a KeyboardInterrupt raised inside a Numba call.
            raise SystemError(
                "CPUDispatcher(<function _advance>) returned a result with an exception set"
            ) from interrupt

    return interrupted


@pytest.mark.slow
@pytest.mark.parametrize("how", ["a run cut short", "an error caused by Ctrl-C"])
def test_an_interrupted_point_is_not_done_and_runs_again_on_resume(base, tmp_path, monkeypatch, how):
    plan = plan_sweep(SMALL)
    ids = point_ids(base, plan)
    folder = tmp_path / "interrupted"
    monkeypatch.setattr(POINTS_MODULE, "simulate", _interrupted_second_point(how, POINTS_MODULE.simulate))
    with pytest.raises(KeyboardInterrupt):
        sweep(base, plan, folder, workers=1)
    assert [path.stem for path in point_files(folder)] == [ids[0]]
    table = pd.read_parquet(folder / TABLE_PARQUET)
    assert table.loc[1, "error"].startswith("not finished") and table.loc[2, "error"].startswith("not finished")

    monkeypatch.undo()
    reports = []
    resumed = sweep(base, plan, folder, workers=1, progress=reports.append)
    assert reports[0].done == 1
    assert resumed["error"].isna().all()


def _live(process) -> bool:
    """Whether ``process`` (psutil) still runs: neither gone nor a zombie waiting to be reaped."""
    import psutil

    try:
        return process.is_running() and process.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@pytest.mark.slow
def test_workers_stop_when_the_sweep_is_killed_and_not_yet_reaped(tmp_path):
    import psutil

    folder = tmp_path / "orphans"
    command = [
        str(SHAKERMILL),
        "sweep",
        "--grid",
        "omega=90:130:40",
        "--set",
        "duration=600",
        "--workers",
        "2",
        "--out",
        str(folder),
    ]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    descendants = []
    try:
        wait_for_a_stored_point(process, folder, 120, "the kill")
        descendants = psutil.Process(process.pid).children(recursive=True)
        assert len(descendants) >= 2  # the two workers, and the processes that start them
        # SIGKILL to the sweep alone, not its group; this test, its parent, reaps it only at the end,
        # so meanwhile it is a zombie that still holds its process id.
        os.kill(process.pid, signal.SIGKILL)
        killed = time.monotonic()
        while any(_live(descendant) for descendant in descendants) and time.monotonic() - killed < 10:
            time.sleep(0.05)
        assert psutil.Process(process.pid).status() == psutil.STATUS_ZOMBIE
        assert [descendant.pid for descendant in descendants if _live(descendant)] == [], "workers outlived the sweep"
        print(f"every process of the sweep gone {time.monotonic() - killed:.1f} s after the kill")
    finally:
        for descendant in descendants:
            if _live(descendant):
                descendant.kill()
        if process.poll() is None:
            process.kill()
        process.wait(timeout=30)


@pytest.fixture(scope="module")
def tls_certificates(tmp_path_factory) -> dict[str, str]:
    """A certificate authority and a certificate it signed for 127.0.0.1, made with the openssl command."""
    if shutil.which("openssl") is None:
        pytest.skip("no openssl command to make the test certificates with")
    folder = tmp_path_factory.mktemp("tls")
    files = {"ca": folder / "ca.pem", "cert": folder / "node.pem", "key": folder / "node.key"}
    (folder / "extensions.cnf").write_text("subjectAltName=DNS:localhost,IP:127.0.0.1\n", encoding="ascii")
    commands = [
        ["req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out", "ca.pem", "-days", "2",
         "-subj", "/CN=shakermill test CA"],
        ["req", "-newkey", "rsa:2048", "-nodes", "-keyout", "node.key", "-out", "node.csr", "-subj", "/CN=localhost"],
        ["x509", "-req", "-in", "node.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial", "-out", "node.pem",
         "-days", "2", "-extfile", "extensions.cnf"],
    ]  # fmt: skip
    for command in commands:
        made = subprocess.run(["openssl", *command], cwd=folder, capture_output=True, text=True, timeout=60)
        assert made.returncode == 0, made.stderr
    return {name: str(path) for name, path in files.items()}


@pytest.fixture(scope="module")
def tls_scheduler(tls_certificates):
    """The address of a local Dask cluster that speaks TLS only, with one single-threaded worker."""
    distributed = pytest.importorskip("distributed")
    from distributed.security import Security

    ca, cert, key = tls_certificates["ca"], tls_certificates["cert"], tls_certificates["key"]
    security = Security(
        tls_ca_file=ca,
        tls_scheduler_cert=cert,
        tls_scheduler_key=key,
        tls_worker_cert=cert,
        tls_worker_key=key,
        tls_client_cert=cert,
        tls_client_key=key,
        require_encryption=True,
    )
    cluster = distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tls://",
        host="127.0.0.1",
        security=security,
        dashboard_address=None,
    )
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def environment_without_dask_tls() -> dict[str, str]:
    return {name: value for name, value in os.environ.items() if not name.startswith("DASK_DISTRIBUTED__COMM__TLS")}


@pytest.mark.slow
def test_a_tls_scheduler_runs_the_sweep_with_the_environments_tls_settings(
    in_process, tls_certificates, tls_scheduler, tmp_path
):
    assert tls_scheduler.startswith("tls://127.0.0.1:")
    _, reference, _ = in_process
    environment = {
        **environment_without_dask_tls(),
        "DASK_DISTRIBUTED__COMM__TLS__CA_FILE": tls_certificates["ca"],
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT": tls_certificates["cert"],
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY": tls_certificates["key"],
    }
    folder = tmp_path / "tls"
    grids = [argument for spec in GRID for argument in ("--grid", spec)]
    command = [str(SHAKERMILL), "sweep", *grids, "--set", f"duration={DURATION}", "--scheduler", tls_scheduler,
               "--scheduler-timeout", "10", "--out", str(folder), "--json"]  # fmt: skip
    completed = subprocess.run(command, capture_output=True, text=True, timeout=300, env=environment)
    assert completed.returncode == 0, completed.stderr
    assert json.loads(completed.stdout)["failed"] == 0
    assert_frame_equal(comparable(load_sweep(folder).table), comparable(reference))


@pytest.mark.slow
def test_a_tls_scheduler_without_tls_settings_is_one_line(tls_scheduler, tmp_path):
    folder = tmp_path / "no-tls"
    command = [
        str(SHAKERMILL),
        "sweep",
        "--grid",
        SMALL[0],
        "--scheduler",
        tls_scheduler,
        "--scheduler-timeout",
        "5",
        "--out",
        str(folder),
    ]
    completed = subprocess.run(command, capture_output=True, text=True, timeout=120, env=environment_without_dask_tls())
    assert completed.returncode == 2
    assert_one_error_line(completed.stderr, tls_scheduler, "TLS")
    assert not folder.exists()


def test_a_point_whose_run_spent_its_budget_is_not_probed_on_a_budget_of_its_own():
    from shakermill.studies.sweeps.points import run_point

    base = default_parameters(solver="full", duration=60.0, record_windows=(), max_steps=2000)
    row = run_point(base, {"omega": 110.0}).row
    assert row["status"] == -4 and row["steps"] == 2000
    # Before, the probe ran on a fresh budget after the run had spent the point's, and filled these keys.
    assert row.get("n_attractors") is None and row.get("heat_power_spread_W") is None
