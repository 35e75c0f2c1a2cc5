"""Parameter sweeps: one run per point of a grid or a list, in parallel, resumable (issue 5).

A sweep folder holds

* ``sweep.json``        the base parameters (SI), the swept keys, the grid specifications and every
                        point with its id: what a re-run is checked against before it resumes,
* ``points/<id>.json``  one file per finished point (its table row), written atomically the
                        moment the point finishes, so a killed sweep loses at most the points
                        that were running,
* ``sweep.parquet``     the table, one row per point in grid order: the point id, the swept
  ``sweep.csv``         values (columns named by their keys), ``regime`` and ``period``,
                        ``error`` (empty for a point that finished) and every key of
                        ``run --json``; rebuilt from the point files at the end of each sweep,
* ``runs/<id>/``        with ``keep_runs``: each point's run folder, as ``shakermill run`` writes it.

A point's id is a hash of the base parameters and the point's values, so re-running the same
sweep into the same folder skips the points whose file exists and can be read. Every point is computed on its
own from its parameters alone, so the table does not depend on the number of workers, the order
in which they finish, or whether the points ran on a Dask cluster.
"""

from __future__ import annotations

import ast
import hashlib
import io
import itertools
import json
import logging
import math
import os
import re
import sys
import warnings
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator, Mapping, Sequence

import numpy as np
import pandas as pd

from shakermill.io.runs import to_jsonable
from shakermill.parameters.config import RunConfig, load_config, parse_overrides, read_config_file
from shakermill.parameters.csvinput import read_csv_rows
from shakermill.parameters.defaults import DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.schema import (
    DEFAULT_PRESET,
    ParameterError,
    Parameters,
    check_known_keys,
    checked_name,
    field_unit,
    takes_names,
    whole_number,
)
from shakermill.parameters.units import UnitError, to_si
from shakermill.solvers.result import INTERRUPTED, Result
from shakermill.solvers.simulate import simulate
from shakermill.support.atomic import (
    check_writable_place,
    create_exclusively,
    remove_abandoned_writes,
    write_files_atomically,
    write_text_atomically,
)
from shakermill.support.limits import MAX_SWEEP_POINTS, quoted
from shakermill.support.version import __version__

if TYPE_CHECKING:
    from distributed import Client

MANIFEST_FILE = "sweep.json"
POINTS_FOLDER = "points"
RUNS_FOLDER = "runs"
TABLE_STEM = "sweep"
TABLE_PARQUET = f"{TABLE_STEM}.parquet"
TABLE_CSV = f"{TABLE_STEM}.csv"
MANIFEST_FORMAT = "shakermill-sweep/1"
# 64 bits of SHA-256: collisions are out of reach for any sweep that fits on a disk.
POINT_ID_LENGTH = 16
# What a point id looks like: file names are built from ids, and only from ids that match.
POINT_ID_PATTERN = re.compile(rf"[0-9a-f]{{{POINT_ID_LENGTH}}}")
# Columns that measure the machine, not the model: they differ between two runs of the same point.
TIMING_COLUMNS = ("wall_time_s",)
# A summary key that is also a swept key (only ``solver``: the averaged solver may fall back to
# full resolution) keeps the summary's value under this suffix; the swept value keeps the key.
USED_SUFFIX = "_used"
FIRST_COLUMNS = ("point_id",)
OUTCOME_COLUMNS = ("regime", "period", "error")
GRID_PATTERN = re.compile(r"^\s*(?P<key>[^=]+?)\s*=\s*(?P<range>.*)$")

ProgressCallback = Callable[["SweepProgress"], None]


@dataclass(frozen=True)
class SweepPlan:
    """The points of a sweep, in order, and where they came from (kept in ``sweep.json``)."""

    keys: tuple[str, ...]
    points: tuple[dict[str, Any], ...]
    grids: tuple[str, ...] = ()
    points_file: str | None = None


@dataclass(frozen=True)
class SweepProgress:
    """Where a sweep stands; ``done`` counts failed points and points finished by an earlier run."""

    total: int
    done: int
    failed: int
    running: int


@dataclass(frozen=True)
class PointOutcome:
    """A point's table row, and its result when the run folder is to be kept."""

    row: dict[str, Any]
    result: Result | None = None


@dataclass(frozen=True)
class SweepData:
    """A sweep folder read back: its manifest, swept keys and table."""

    path: Path
    manifest: dict[str, Any]
    keys: tuple[str, ...]
    table: pd.DataFrame


# Grids and points ---------------------------------------------------------------------------------


def normalize_value(key: str, value: Any) -> Any:
    """``value`` for ``key`` as stored and hashed: SI floats for real keys, ints for counts, the value itself
    otherwise (so "3" and 3 balls are one point).

    Only the unit and the type are interpreted here; whether the value is allowed is decided per point, so an
    out-of-range value (or balls that do not fit) makes that point fail, not the sweep.
    """
    annotation = Parameters.model_fields[key].annotation
    try:
        if annotation is float:
            return to_si(value, field_unit(key), key=key)
        if annotation is int:
            return whole_number(key, value)
    except UnitError as exc:
        raise ParameterError(str(exc)) from None
    return to_jsonable(value)


def parse_grid(spec: str, most: int = MAX_SWEEP_POINTS) -> tuple[str, np.ndarray]:
    """``"omega=90:130:9"`` -> ``("omega", linspace(90, 130, 9))``; START and STOP may carry units; N <= ``most``."""
    shown = quoted(spec)
    match = GRID_PATTERN.match(spec)
    if match is None:
        raise ParameterError(f"grid {shown}: expected KEY=START:STOP:N, for example omega=90:130:9")
    key, bounds = match["key"], match["range"].split(":")
    try:
        check_known_keys([key])
    except ParameterError as exc:
        raise ParameterError(f"grid {shown}: {exc}") from None
    if Parameters.model_fields[key].annotation is not float:
        raise ParameterError(
            f"grid {shown}: START:STOP:N is for real-valued parameters and {key} is not one; list its values as {key}=A,B,C"
        )
    if len(bounds) != 3:
        raise ParameterError(f"grid {shown}: expected KEY=START:STOP:N (three fields after '='), got {len(bounds)}")
    start, stop, count = (part.strip() for part in bounds)
    # Digits beyond the limit's are refused before int() would read a number of any length.
    if not (count.isascii() and count.isdigit()) or len(count) > len(str(most)) or not 1 <= int(count) <= most:
        raise ParameterError(f"grid {shown}: N must be a whole number of points in [1, {most:,}], got {quoted(count)}")
    try:
        low, high = normalize_value(key, start), normalize_value(key, stop)
    except ParameterError as exc:
        raise ParameterError(f"grid {shown}: {exc}") from None
    return key, np.linspace(low, high, int(count))


def grid_values(spec: str) -> tuple[str, Sequence[Any]]:
    """The values of one ``--grid``: ``KEY=START:STOP:N`` for a real-valued key (:func:`parse_grid`), or
    ``KEY=A,B,C`` for a key that takes names (``ball_material=steel,zirconia``, ``solver=full,averaged``), a
    count (``n_balls=1,2,5``) or a real value (``ball_radius=4mm,5mm,6.35mm``)."""
    match = GRID_PATTERN.match(spec)
    key = match["key"] if match is not None else ""
    if key not in Parameters.model_fields or not _takes_a_list(key, match["range"]):
        return parse_grid(spec)
    items = [item.strip() for item in match["range"].split(",") if item.strip()]
    if not items:
        raise ParameterError(f"grid {quoted(spec)}: expected KEY=A,B,C, for example ball_material=steel,zirconia")
    check_point_count(len(items))
    try:
        # A misspelt name or unit fails the sweep before it starts, not one point in the middle of it.
        return key, [checked_name(key, item) if takes_names(key) else normalize_value(key, item) for item in items]
    except ParameterError as exc:
        raise ParameterError(f"grid {quoted(spec)}: {exc}") from None


def _takes_a_list(key: str, values: str) -> bool:
    """Whether ``KEY=values`` lists values: always for names, for a count or a real key unless it reads START:STOP:N
    (which :func:`parse_grid` reads, or refuses for a count with a hint at the list)."""
    return takes_names(key) or (Parameters.model_fields[key].annotation in (int, float) and ":" not in values)


def product_points(grids: Sequence[tuple[str, Sequence[Any]]], listed: int = 1) -> list[dict[str, Any]]:
    """Every combination of the grids' values; the first grid varies slowest (row-major order).

    ``listed`` points of a file are combined with each; their product is capped before it is built.
    """
    keys = [key for key, _ in grids]
    _check_distinct(keys, "grid")
    check_point_count(listed * math.prod(len(values) for _, values in grids))
    value_lists = [[normalize_value(key, value) for value in values] for key, values in grids]
    return [dict(zip(keys, combination)) for combination in itertools.product(*value_lists)]


def check_point_count(count: int) -> None:
    if count > MAX_SWEEP_POINTS:
        raise ParameterError(f"sweep: {count:,} points; allowed at most {MAX_SWEEP_POINTS:,} in one sweep")


def read_points(path: Path | str) -> list[dict[str, Any]]:
    """The points of a CSV file: a header of canonical keys, one point per row, values with or without units."""
    source = Path(path)
    rows = read_csv_rows(source, f"points {source}", MAX_SWEEP_POINTS)
    rows = [row for row in rows if any(cell.strip() for cell in row)]
    if len(rows) < 2:
        raise ParameterError(f"points {source}: expected a header of parameter keys and at least one row of values")
    header = [cell.strip() for cell in rows[0]]
    try:
        check_known_keys(header)
        _check_distinct(header, "column")
    except ParameterError as exc:
        raise ParameterError(f"points {source}: {exc}") from None
    return [_point_from_row(source, number, header, row) for number, row in enumerate(rows[1:], start=2)]


def _point_from_row(source: Path, line: int, header: list[str], row: list[str]) -> dict[str, Any]:
    if len(row) != len(header):
        raise ParameterError(f"points {source} line {line}: {len(row)} values for {len(header)} columns")
    point = {}
    for key, cell in zip(header, row):
        if not cell.strip():
            raise ParameterError(f"points {source} line {line}: no value for {key}")
        try:
            point[key] = normalize_value(key, cell.strip())
        except ParameterError as exc:
            raise ParameterError(f"points {source} line {line}: {exc}") from None
    return point


def _check_distinct(keys: Sequence[str], what: str) -> None:
    repeated = sorted({key for key in keys if keys.count(key) > 1})
    if repeated:
        raise ParameterError(f"{repeated[0]}: more than one {what} for this key")


def plan_sweep(grids: Sequence[str] = (), points_file: Path | str | None = None) -> SweepPlan:
    """The points of ``--grid`` specifications and/or a ``--points`` file (each row times the grid's product)."""
    parsed = [grid_values(spec) for spec in grids]
    listed = read_points(points_file) if points_file is not None else [{}]
    grid_points = product_points(parsed, len(listed)) if parsed else [{}]
    keys = [*listed[0], *(key for key, _ in parsed)]
    if not keys:
        raise ParameterError("sweep: nothing to sweep; give --grid KEY=START:STOP:N or --points FILE.csv")
    _check_distinct(keys, "grid or points column")
    points = tuple({**row, **values} for row in listed for values in grid_points)
    return SweepPlan(tuple(keys), points, tuple(grids), str(points_file) if points_file is not None else None)


def as_plan(grid_points: SweepPlan | Mapping[str, Sequence[Any]] | Sequence[Mapping[str, Any]]) -> SweepPlan:
    """A plan from a plan, a mapping of key -> values (their product) or a sequence of points."""
    if isinstance(grid_points, SweepPlan):
        return grid_points
    if isinstance(grid_points, Mapping):
        check_known_keys(list(grid_points))
        return SweepPlan(tuple(grid_points), tuple(product_points(list(grid_points.items()))))
    points = [dict(point) for point in grid_points]
    if not points:
        raise ParameterError("sweep: no points to run")
    check_point_count(len(points))
    keys = tuple(points[0])
    for number, point in enumerate(points, start=1):
        check_known_keys(list(point))
        if tuple(point) != keys:
            raise ParameterError(f"sweep: point {number} sets {sorted(point)}, the first point {sorted(keys)}")
    return SweepPlan(keys, tuple({key: normalize_value(key, value) for key, value in point.items()} for point in points))


def point_id(base: Parameters, values: Mapping[str, Any]) -> str:
    """A stable id for the run of ``base`` with ``values``: SHA-256 of both as canonical JSON, truncated."""
    document = {"base": to_jsonable(base.model_dump()), "point": to_jsonable(dict(values))}
    text = json.dumps(document, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:POINT_ID_LENGTH]


def point_ids(base: Parameters, plan: SweepPlan) -> list[str]:
    """The id of every point of ``plan``; a point listed twice is refused (it would be one file)."""
    ids = [point_id(base, values) for values in plan.points]
    first_seen: dict[str, int] = {}
    for number, identifier in enumerate(ids, start=1):
        if identifier in first_seen:
            raise ParameterError(
                f"sweep: point {number} repeats point {first_seen[identifier]} ({_describe(plan.points[number - 1])})"
            )
        first_seen[identifier] = number
    return ids


def _describe(values: Mapping[str, Any]) -> str:
    return ", ".join(f"{key}={value}" for key, value in values.items())


def sweep_parameters(
    config: Path | str | None, *, preset: str | None, overrides: Sequence[str], full_resolution: bool
) -> RunConfig:
    """The base configuration of a sweep: as for ``run``, but with the averaged solver by default.

    A sweep runs many points, and the averaged solver is ~60x faster at the same accuracy where
    it applies (it falls back to full resolution, and says so, where it does not). A ``solver``
    set in the file or with ``--set`` is respected; ``full_resolution`` asks for the full solver.
    """
    explicit = _named_solver(config, overrides)
    if full_resolution and explicit not in (None, "full"):
        raise ParameterError(f"--full-resolution contradicts solver = {quoted(explicit)}")
    solver = "full" if full_resolution else "averaged" if explicit is None else explicit
    # Validated with the solver it will run: the full solver's limits do not apply to an averaged sweep.
    return load_config(config, preset=preset, overrides=[*overrides, f"solver={solver}"])


def _named_solver(config: Path | str | None, overrides: Sequence[str]) -> Any:
    """The solver that ``--set`` or else the configuration file names, or None."""
    named = parse_overrides(overrides)
    if "solver" in named:
        return named["solver"]
    return read_config_file(Path(config)).get("solver") if config is not None else None


# One point --------------------------------------------------------------------------------------


class SweepFailed(RuntimeError):
    """Every point of a sweep failed; ``table`` is the sweep's table (written too), each row saying why."""

    def __init__(self, table: pd.DataFrame, folder: Path) -> None:
        first = failed_points(table).iloc[0]
        super().__init__(
            f"all {len(table)} points failed (first: {first['point_id']}: {first['error']}); "
            f"see the error column of {folder / TABLE_CSV}"
        )
        self.table = table


class PointInterrupted(Exception):
    """The user interrupted a point: it is not finished and must not be recorded as failed."""


def run_point(base: Parameters, values: Mapping[str, Any], keep_run: bool = False) -> PointOutcome:
    """Run one point and build its table row; a point that cannot run records why instead of raising."""
    # Both build on simulate; imported where they are used.
    from shakermill.analysis.regime import classify
    from shakermill.solvers.result import probed

    swept = dict(values)
    try:
        params = base.replace(**swept)
    except ParameterError as exc:
        return PointOutcome(failed_row(swept, str(exc)))
    try:
        result = simulate(params)
        if result.status == INTERRUPTED:
            # Not classified: a run cut short may be too short for it, and the point is not done anyway.
            raise PointInterrupted(result.message)
        regime, period = classify(result)
        # The averaged solver probed the other starts already; a full run has them probed here, unless
        # it stopped early: a probe would start a budget of its own after the run had spent the point's.
        # The probe settles one ball on the axis: the 'dem' engine's several balls have no such starts.
        if result.success and params.engine == "1d":
            probed(result)
    except PointInterrupted:
        raise
    except Exception as exc:  # noqa: BLE001 - one point's crash must not stop the sweep; its row says why
        if _caused_by_ctrl_c(exc):
            raise PointInterrupted(str(exc)) from None
        return PointOutcome(failed_row(swept, f"{type(exc).__name__}: {exc}"))
    summary = {(f"{key}{USED_SUFFIX}" if key in swept else key): value for key, value in result.summary.items()}
    # A table cell holds one value: the warnings become one string, or none (CSV cannot tell "" from missing).
    summary["warnings"] = "; ".join(result.warnings) or None
    row = {
        **swept,
        "regime": regime,
        "period": period,
        "error": None if result.success else result.message,
        **summary,
        "output_dir": None,
    }
    return PointOutcome(to_jsonable(row), result if keep_run else None)


def _caused_by_ctrl_c(error: BaseException | None) -> bool:
    """Whether a ``KeyboardInterrupt`` is behind ``error``: one raised inside compiled code (Numba,
    SciPy) surfaces as another exception, a ``SystemError`` with the interrupt as its cause."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return True
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return False


def failed_row(values: Mapping[str, Any], error: str) -> dict[str, Any]:
    """The row of a point without a result: its values, why, and ``success`` false."""
    return to_jsonable({**values, "regime": None, "period": None, "error": error, "success": False})


# The sweep ----------------------------------------------------------------------------------------


def sweep(
    base_params: Parameters,
    grid_points: SweepPlan | Mapping[str, Sequence[Any]] | Sequence[Mapping[str, Any]],
    out_dir: Path | str,
    workers: int | None = None,
    scheduler: str | None = None,
    keep_runs: bool = False,
    progress: ProgressCallback | None = None,
    *,
    preset: str = DEFAULT_PRESET,
    scheduler_timeout: float = DEFAULT_SCHEDULER_TIMEOUT_S,
) -> pd.DataFrame:
    """Run ``base_params`` at every point of ``grid_points`` and return the sweep table.

    ``grid_points`` is a :class:`SweepPlan` (from :func:`plan_sweep`), a mapping of key -> values
    (their Cartesian product, first key slowest) or a sequence of points (mappings of key -> value);
    values may carry units. The solver is the one ``base_params`` names (the command line defaults
    to the averaged one, see :func:`sweep_parameters`). Points run on ``workers`` local processes
    (default: one per core; 1 runs them in this process) or on the Dask cluster at ``scheduler``
    ("tcp://host:8786"). Each finished point is stored at once in ``out_dir``; points stored by an
    earlier run of the same sweep are skipped. Raises :class:`ParameterError` (one line) for bad
    input, a folder that holds another sweep, or an unreachable scheduler,
    :class:`~shakermill.atomic.StorageError` for a place where the folder cannot be created, and
    :class:`SweepFailed` (naming the first failure) when no point succeeded.
    """
    plan = as_plan(grid_points)
    _check_execution(workers, scheduler)
    folder = Path(out_dir)
    ids = point_ids(base_params, plan)
    manifest = sweep_manifest(base_params, plan, ids, preset)
    _check_folder(folder, manifest)
    stored = stored_rows(folder, ids, warn=True)
    pending = [(identifier, values) for identifier, values in zip(ids, plan.points) if identifier not in stored]
    unfinished: dict[str, str] = {}
    # The backend first: an unreachable scheduler leaves no folder behind.
    with _backend(workers, scheduler, scheduler_timeout, len(pending)) as backend:
        _claim_folder(folder, manifest)
        try:
            tracker = _Tracker(len(ids), _finished_counts(stored), backend.slots, progress)
            for identifier, outcome in backend.outcomes(base_params, pending, keep_runs):
                if isinstance(outcome, BaseException):
                    unfinished[identifier] = f"not finished ({type(outcome).__name__}: {outcome}); re-run the sweep to retry"
                    tracker.finished(failed=True)
                    continue
                row = _store_point(folder, identifier, outcome, preset)
                tracker.finished(failed=row.get("error") is not None)
        finally:
            # Also on Ctrl-C: the table then holds the finished points, the others marked not finished.
            table = build_table(folder, plan.keys, ids, plan.points, unfinished)
            write_table(table, folder)
    if len(failed_points(table)) == len(table):
        raise SweepFailed(table, folder)
    return table


def _check_execution(workers: int | None, scheduler: str | None) -> None:
    if workers is not None and scheduler is not None:
        raise ParameterError("workers: the local pool's size; with a scheduler the cluster's workers run the points")
    if workers is not None and workers < 1:
        raise ParameterError(f"workers: {workers} is out of range; allowed 1 or more")


def sweep_manifest(base: Parameters, plan: SweepPlan, ids: Sequence[str], preset: str) -> dict[str, Any]:
    """The content of ``sweep.json``."""
    return to_jsonable(
        {
            "format": MANIFEST_FORMAT,
            "shakermill_version": __version__,
            "created_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "preset": preset,
            "base": base.model_dump(),
            "keys": list(plan.keys),
            "grids": list(plan.grids),
            "points_file": plan.points_file,
            "points": [{"point_id": identifier, "values": values} for identifier, values in zip(ids, plan.points)],
        }
    )


def _check_folder(folder: Path, manifest: dict[str, Any]) -> None:
    """Refuse a folder that is neither empty, absent, nor a folder of this very sweep."""
    manifest_path = folder / MANIFEST_FILE
    if manifest_path.is_file():
        _check_same_sweep(folder, read_manifest(folder), manifest)
    elif folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise ParameterError(f"{folder}: exists and is not a shakermill sweep folder; choose another --out")
    elif not folder.exists():
        check_writable_place(folder)


def _claim_folder(folder: Path, manifest: dict[str, Any]) -> None:
    """Make ``folder`` this sweep's: create its manifest, or find this very sweep's there; clear
    what killed writers left in it.

    The manifest is created exclusively: of two sweeps started at once into one new folder, one
    creates it and the other finds it and is refused unless it is the same sweep, before either
    stores a point. A manifest that cannot be written (a full disk) leaves no folder behind that
    the same command would later refuse.
    """
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        create_exclusively(folder / MANIFEST_FILE, json.dumps(manifest, indent=2, allow_nan=False) + "\n")
    except FileExistsError:
        _check_same_sweep(folder, read_manifest(folder), manifest)
    except BaseException:
        if created:
            with suppress(OSError):  # not empty: someone else's files arrived meanwhile, and stay
                folder.rmdir()
        raise
    (folder / POINTS_FOLDER).mkdir(exist_ok=True)
    for place in (folder, folder / POINTS_FOLDER, folder / RUNS_FOLDER):
        remove_abandoned_writes(place)


def _check_same_sweep(folder: Path, stored: dict[str, Any], wanted: dict[str, Any]) -> None:
    """Refuse to resume into a folder whose base parameters or points differ: its rows would not match."""
    difference = _first_difference(stored.get("base", {}), wanted["base"])
    if difference is not None:
        key, before, now = difference
        raise ParameterError(
            f"{folder}: holds a sweep with other base parameters ({key} = {before!r} there, {now!r} now); "
            "choose another --out"
        )
    if stored.get("keys") != wanted["keys"] or stored.get("points") != wanted["points"]:
        raise ParameterError(
            f"{folder}: holds a sweep over other points (grid {' '.join(stored.get('grids') or []) or 'from a points file'}); "
            "choose another --out"
        )


def _first_difference(stored: Mapping[str, Any], wanted: Mapping[str, Any]) -> tuple[str, Any, Any] | None:
    for key in sorted(set(stored) | set(wanted)):
        if stored.get(key) != wanted.get(key):
            return key, stored.get(key), wanted.get(key)
    return None


def read_manifest(folder: Path) -> dict[str, Any]:
    """``sweep.json`` of ``folder``, checked: paths are built from its point ids, so each must be one."""
    try:
        manifest = json.loads((folder / MANIFEST_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ParameterError(f"{folder}: cannot read {MANIFEST_FILE} ({_reason(exc)})") from None
    if not isinstance(manifest, dict) or manifest.get("format") != MANIFEST_FORMAT:
        raise ParameterError(f"{folder}: {MANIFEST_FILE} is not a shakermill sweep manifest")
    problem = _manifest_problem(manifest)
    if problem is not None:
        raise ParameterError(f"{folder}: {MANIFEST_FILE} is damaged ({problem}); run the sweep into a new folder")
    return manifest


def _manifest_problem(manifest: Mapping[str, Any]) -> str | None:
    keys, points = manifest.get("keys"), manifest.get("points")
    if not isinstance(keys, list) or not keys or not all(isinstance(key, str) for key in keys):
        return "keys is not a list of parameter keys"
    if not isinstance(points, list) or not points:
        return "points is not a list of points"
    for number, entry in enumerate(points, start=1):
        if not isinstance(entry, dict) or not isinstance(entry.get("values"), dict):
            return f"point {number} is not an object with values"
        identifier = entry.get("point_id")
        if not isinstance(identifier, str) or not POINT_ID_PATTERN.fullmatch(identifier):
            return f"point {number} has the id {identifier!r}, not {POINT_ID_LENGTH} hexadecimal digits"
    return None


def _point_path(folder: Path, identifier: str) -> Path:
    if not POINT_ID_PATTERN.fullmatch(identifier):
        raise ValueError(f"{identifier!r} is not a point id")  # ids from read_manifest or point_id only
    return folder / POINTS_FOLDER / f"{identifier}.json"


def stored_rows(folder: Path, ids: Sequence[str], *, warn: bool = False) -> dict[str, dict[str, Any]]:
    """The rows of the points of ``ids`` stored in ``folder``, by id.

    A point file that cannot be read (empty, truncated, not JSON, not a row: a disk that filled up,
    a hand edit) counts as not stored, so the sweep computes that point again; with ``warn``, one
    warning says so.
    """
    rows, unreadable = {}, []
    for identifier in ids:
        path = _point_path(folder, identifier)
        if not path.exists():
            continue
        try:
            rows[identifier] = _read_row(path)
        except (OSError, ValueError) as exc:
            unreadable.append(f"{path} ({_reason(exc)})")
    if warn and unreadable:
        more = f" and {len(unreadable) - 1} more" if len(unreadable) > 1 else ""
        warnings.warn(f"sweep: unreadable point file {unreadable[0]}{more}; computing those points again", stacklevel=3)
    return rows


def _read_row(path: Path) -> dict[str, Any]:
    document = json.loads(path.read_text(encoding="utf-8"))
    row = document.get("row") if isinstance(document, dict) else None
    if not isinstance(row, dict):
        raise ValueError("not a shakermill point file")
    return row


def _finished_counts(stored: Mapping[str, Mapping[str, Any]]) -> tuple[int, int]:
    """(points stored by an earlier run, how many of them failed)."""
    return len(stored), sum(row.get("error") is not None for row in stored.values())


def _store_point(folder: Path, identifier: str, outcome: PointOutcome, preset: str) -> dict[str, Any]:
    """Write the run folder (if kept) and then the point file: the point file marks the point finished."""
    row = {"point_id": identifier, **outcome.row}
    if outcome.result is not None:
        from shakermill.io.runs import write_run  # netCDF and Parquet writers: only needed with keep_runs

        target = folder / RUNS_FOLDER / identifier
        provenance = {"command": "shakermill sweep", "sweep": str(folder.absolute()), "point_id": identifier}
        # A run folder without its point file was left by a killed sweep: this point's, so it is replaced.
        row["output_dir"] = str(write_run(outcome.result, target, preset=preset, extra_provenance=provenance, overwrite=True))
    document = {"point_id": identifier, "shakermill_version": __version__, "row": row}
    write_text_atomically(_point_path(folder, identifier), json.dumps(document, indent=1, allow_nan=False) + "\n")
    return row


class _Tracker:
    """Counts finished points and reports them to the progress callback."""

    def __init__(self, total: int, finished: tuple[int, int], slots: int, progress: ProgressCallback | None) -> None:
        self.total, (self.done, self.failed), self.slots, self.progress = total, finished, slots, progress
        self._report()

    def finished(self, *, failed: bool) -> None:
        self.done += 1
        self.failed += int(failed)
        self._report()

    def _report(self) -> None:
        if self.progress is not None:
            running = min(self.slots, self.total - self.done)
            self.progress(SweepProgress(self.total, self.done, self.failed, running))


# Execution backends ---------------------------------------------------------------------------------

Task = tuple[str, Mapping[str, Any]]
Outcomes = Iterator[tuple[str, "PointOutcome | BaseException"]]


@dataclass
class _InProcess:
    slots: int = 1

    def outcomes(self, base: Parameters, tasks: Sequence[Task], keep_runs: bool) -> Outcomes:
        for identifier, values in tasks:
            try:
                yield identifier, run_point(base, values, keep_runs)
            except PointInterrupted:
                raise KeyboardInterrupt from None


@dataclass
class _LocalPool:
    slots: int
    executor: Any = field(default=None)

    def outcomes(self, base: Parameters, tasks: Sequence[Task], keep_runs: bool) -> Outcomes:
        from concurrent.futures import as_completed

        futures = {self.executor.submit(run_point, base, values, keep_runs): identifier for identifier, values in tasks}
        for future in as_completed(futures):
            error = future.exception()
            yield futures[future], error if error is not None else future.result()


@dataclass
class _Cluster:
    client: Client
    slots: int

    def outcomes(self, base: Parameters, tasks: Sequence[Task], keep_runs: bool) -> Outcomes:
        from distributed import as_completed

        # pure=False: a point is a computation to run, not a value Dask may deduplicate or cache.
        futures = {self.client.submit(run_point, base, values, keep_runs, pure=False): identifier for identifier, values in tasks}
        # The client is not Dask's default one (set_as_default=False), so as_completed is told its loop.
        for future in as_completed(futures, loop=self.client.loop):
            yield futures[future], future.result() if future.status == "finished" else _cluster_error(future)


def _cluster_error(future: Any) -> BaseException:
    """Why the cluster did not finish a point: the worker's exception, or the future's state (cancelled, lost)."""
    if future.status == "error":
        return future.exception()
    return RuntimeError(f"the cluster reports the point as {future.status}")


@contextmanager
def _backend(workers: int | None, scheduler: str | None, timeout: float, pending: int) -> Iterator[Any]:
    if scheduler is not None:
        client = connect(scheduler, timeout)
        try:
            yield _Cluster(client, max(1, sum(client.nthreads().values())))
        finally:
            client.close()
        return
    size = min(workers or os.cpu_count() or 1, pending)
    if size <= 1:
        yield _InProcess()
        return
    context = _start_context()
    if context is None:
        warnings.warn(
            "sweep: called from the top level of a script without an `if __name__ == \"__main__\":` guard, where "
            "worker processes cannot start on this platform; the points run one after another in this process",
            stacklevel=4,
        )
        yield _InProcess()
        return
    executor = _process_pool(size, context)
    try:
        yield _LocalPool(size, executor)
    except BaseException:
        # Ctrl-C or an error while storing: queued points are dropped; running ones end with the pool.
        executor.shutdown(wait=False, cancel_futures=True)
        raise
    executor.shutdown()


def _process_pool(size: int, context: Any) -> Any:
    """A process pool of ``context`` whose workers ignore Ctrl-C; the sweep's own process handles it and stops the pool."""
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(
        max_workers=size, mp_context=context, initializer=_start_worker, initargs=(os.getpid(),)
    )


def _start_context() -> Any:
    """How to start the workers: None when no worker could start, and the points must run in this process.

    forkserver, where the platform has it: its workers import shakermill once, from a clean
    single-threaded server, whereas fork from a process with threads (a progress bar, a Dask client)
    can deadlock, and spawn re-imports everything in every worker. But forkserver and spawn also run
    the main script again in each worker; called from a script's top level without a
    ``__main__`` guard, each worker would start a sweep of its own and fail. There, Linux forks (the
    script has no threads of shakermill's, and Numba's compiled code survives a fork); elsewhere,
    where fork is unsafe, there is no way to start workers.
    """
    import multiprocessing

    methods = multiprocessing.get_all_start_methods()
    if _called_from_unguarded_main():
        return multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None
    context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if "forkserver" in methods:
        context.set_forkserver_preload([__name__])
    return context


def _called_from_unguarded_main() -> bool:
    """Whether this call comes from the top level of the main script, outside ``if __name__ == "__main__":``.

    A notebook's or the interpreter's ``__main__`` has no file and is not run again by the workers.
    """
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if main is None or path is None or getattr(main, "__spec__", None) is not None:
        return False  # run with -m, the workers import it under its own name with the guard honoured
    frame = sys._getframe(1)
    while frame is not None and not (frame.f_globals is vars(main) and frame.f_code.co_name == "<module>"):
        frame = frame.f_back
    if frame is None:
        return False
    try:
        tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    except (OSError, SyntaxError, ValueError):
        return True
    return not any(_is_main_guard(node) and node.lineno <= frame.f_lineno <= node.end_lineno for node in tree.body)


def _is_main_guard(node: ast.stmt) -> bool:
    if not isinstance(node, ast.If) or not isinstance(node.test, ast.Compare):
        return False
    operands = [node.test.left, *node.test.comparators]
    names = {operand.id for operand in operands if isinstance(operand, ast.Name)}
    constants = {operand.value for operand in operands if isinstance(operand, ast.Constant)}
    return names == {"__name__"} and constants == {"__main__"}


# How often a pool worker checks that the sweep that started it is still alive.
PARENT_CHECK_INTERVAL_S = 1.0


def _start_worker(sweep_pid: int) -> None:
    """Ignore Ctrl-C (the sweep handles it), and exit when the sweep's process is gone.

    A sweep killed with SIGKILL (by the user, or the out-of-memory killer) cannot stop its pool;
    without this, its workers would wait for more points forever. A thread watches the sweep's
    process and ends the worker once that process is gone or a zombie: killed, but not yet reaped
    by its own parent (a shell or a job runner may take its time), when it still has its process id.

    Why not ``prctl(PR_SET_PDEATHSIG)``, or watching ``os.getppid()``: a worker's parent is the
    forkserver, not the sweep, and the forkserver lives on as long as its workers hold their end of
    its "alive" pipe, so neither ever fires. psutil tells a zombie from a live process on every
    platform, and compares start times, so a process id reused by another process is not taken
    for the sweep. The thread runs between compiled chunks, so a worker ends within seconds.
    """
    import signal
    import threading
    import time

    import psutil

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        sweep_process = psutil.Process(sweep_pid)
    except psutil.NoSuchProcess:
        os._exit(1)

    def alive() -> bool:
        try:
            return sweep_process.is_running() and sweep_process.status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    def exit_with_the_sweep() -> None:
        while alive():
            time.sleep(PARENT_CHECK_INTERVAL_S)
        os._exit(1)

    threading.Thread(target=exit_with_the_sweep, name="exit-with-the-sweep", daemon=True).start()


def connect(address: str, timeout: float = DEFAULT_SCHEDULER_TIMEOUT_S) -> Client:
    """A Dask client of the scheduler at ``address``, or :class:`ParameterError` with one line saying why not."""
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("scheduler: dask.distributed is not installed (pip install 'dask[distributed]')") from None
    from distributed.security import Security

    # The environment's TLS settings (distributed.comm.tls.* in Dask's configuration, or the
    # DASK_DISTRIBUTED__COMM__TLS__* variables): the same for the handshake as for the client.
    security = Security()
    with _quiet_dask_logging():
        _check_scheduler_answers(address, timeout, security)
        try:
            return Client(address, timeout=timeout, set_as_default=False, security=security)
        except Exception as exc:  # noqa: BLE001 - whatever Dask raises, the user gets one line
            raise ParameterError(f"scheduler: cannot connect to {address}: {_reason(exc)}") from None


def _check_scheduler_answers(address: str, timeout: float, security: Any) -> None:
    """Open one connection to ``address`` and complete Dask's handshake, within ``timeout`` for each.

    Done before a :class:`~distributed.Client` is made, because a Client waits for the handshake
    without limit (a server that never speaks first, such as the HTTP dashboard on port 8787, keeps
    it waiting forever), and a Client whose start failed hangs the interpreter's exit closing itself.
    The probe runs on its own event loop in its own thread, so it works inside a running loop (Jupyter).
    """
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm import connect as open_comm

    async def handshake() -> None:
        # open_comm bounds the connection by ``timeout`` but not the handshake; wait_for bounds both.
        comm = await open_comm(address, timeout=timeout, **security.get_connection_args("client"))
        await comm.close()

    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="scheduler-probe") as probe:
        try:
            probe.submit(asyncio.run, asyncio.wait_for(handshake(), 2 * timeout)).result()
        except asyncio.TimeoutError:
            raise ParameterError(
                f"scheduler: {address} accepted the connection but did not answer as a Dask scheduler "
                f"(waited {2 * timeout:g} s); give the scheduler's address (tcp://HOST:8786), not the dashboard's"
            ) from None
        except (OSError, ValueError, TypeError) as exc:
            # OSError: refused or timed out; ValueError/TypeError: an address Dask cannot parse.
            raise ParameterError(f"scheduler: cannot connect to {address}: {_reason(exc)}") from None
        except Exception as exc:  # noqa: BLE001 - a peer speaking another protocol can make Dask raise anything
            raise ParameterError(
                f"scheduler: {address} does not answer as a Dask scheduler ({type(exc).__name__} in the handshake)"
            ) from None


def _reason(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


@contextmanager
def _quiet_dask_logging() -> Iterator[None]:
    # Dask logs each failed connection attempt; the user gets one line from connect() instead.
    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)


# The table ------------------------------------------------------------------------------------------


def build_table(
    folder: Path,
    keys: Sequence[str],
    ids: Sequence[str],
    points: Sequence[Mapping[str, Any]],
    unfinished: Mapping[str, str] | None = None,
) -> pd.DataFrame:
    """One row per point in grid order, from the point files; a point without a readable file says why."""
    unfinished = unfinished or {}
    stored = stored_rows(folder, ids)
    rows = []
    for identifier, values in zip(ids, points):
        if identifier in stored:
            rows.append(stored[identifier])
        else:
            reason = unfinished.get(identifier, "not finished; re-run the sweep to compute it")
            rows.append({"point_id": identifier, **failed_row(values, reason)})
    return _tabulate(rows, keys)


def _tabulate(rows: list[dict[str, Any]], keys: Sequence[str]) -> pd.DataFrame:
    leading = [*FIRST_COLUMNS, *keys, *OUTCOME_COLUMNS]
    rest = list(dict.fromkeys(column for row in rows for column in row if column not in leading))
    table = pd.DataFrame.from_records(rows, columns=[*leading, *rest])
    for column in _integer_columns(rows, table.columns):
        # Nullable integers, not floats with NaN for the failed points: 190759, not 190759.0.
        table[column] = table[column].astype("Int64")
    return table


def _integer_columns(rows: list[dict[str, Any]], columns: Sequence[str]) -> list[str]:
    """The columns whose values are all integers (booleans excluded) or missing, with at least one integer."""
    def is_integer(value: Any) -> bool:
        return isinstance(value, int) and not isinstance(value, bool)

    integer = []
    for column in columns:
        present = [row[column] for row in rows if row.get(column) is not None]
        if present and all(is_integer(value) for value in present):
            integer.append(column)
    return integer


def write_table(table: pd.DataFrame, folder: Path, stem: str = TABLE_STEM) -> list[Path]:
    """Write ``<stem>.parquet`` and ``<stem>.csv`` atomically, both or neither; return their paths."""
    parquet = io.BytesIO()
    table.to_parquet(parquet, index=False)
    csv_text = table.to_csv(index=False).encode("utf-8")
    return write_files_atomically({folder / f"{stem}.parquet": parquet.getbuffer(), folder / f"{stem}.csv": csv_text})


def load_sweep(path: Path | str) -> SweepData:
    """A sweep folder's manifest and table (rebuilt from the point files if the table is missing).

    Raises :class:`ParameterError` (one line) for a damaged manifest or table.
    """
    folder = Path(path)
    manifest = read_manifest(folder)
    keys = tuple(manifest["keys"])
    parquet = folder / TABLE_PARQUET
    if parquet.is_file():
        table = _read_table(parquet, keys)
    else:
        entries = manifest["points"]
        table = build_table(folder, keys, [entry["point_id"] for entry in entries], [entry["values"] for entry in entries])
    return SweepData(folder, manifest, keys, table)


def _read_table(path: Path, keys: Sequence[str]) -> pd.DataFrame:
    try:
        table = pd.read_parquet(path)
    except (OSError, ValueError) as exc:  # pyarrow's ArrowInvalid is a ValueError
        raise ParameterError(f"{path}: cannot read the table ({_reason(exc)}); re-run the sweep to rebuild it") from None
    missing = [column for column in (*FIRST_COLUMNS, *keys, *OUTCOME_COLUMNS) if column not in table.columns]
    if missing:
        raise ParameterError(f"{path}: not this sweep's table (no column {missing[0]}); re-run the sweep to rebuild it")
    return table


def is_sweep_folder(path: Path | str) -> bool:
    return (Path(path) / MANIFEST_FILE).is_file()


def failed_points(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of points that did not finish successfully."""
    return table[table["error"].notna()]


def comparable_columns(table: pd.DataFrame) -> list[str]:
    """The columns that are the same for two runs of the same sweep (all but the timings and folders)."""
    return [column for column in table.columns if column not in (*TIMING_COLUMNS, "output_dir")]
