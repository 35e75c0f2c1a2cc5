"""The plan of a sweep: its points from grids (``KEY=START:STOP:N``, names, or values with units) and from a CSV of
points, each point's id (a hash of the base parameters and its values), and the base parameters a sweep runs with."""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from shakermill.io.runs import to_jsonable
from shakermill.parameters.config import (
    HALVED_ALIASES,
    RunConfig,
    halved,
    load_config,
    parse_overrides,
    read_config_file,
)
from shakermill.parameters.csvinput import read_csv_rows
from shakermill.parameters.engine_keys import DECIDING, reader_for
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.guards import whole_number
from shakermill.parameters.keys import Parameters, check_known_keys, checked_name, field_unit, takes_names
from shakermill.parameters.units import UnitError, to_si, unit_written
from shakermill.support.limits import MAX_SWEEP_POINTS, quoted

# 64 bits of SHA-256: collisions are out of reach for any sweep that fits on a disk.
POINT_ID_LENGTH = 16


# What a point id looks like: file names are built from ids, and only from ids that match.
POINT_ID_PATTERN = re.compile(rf"[0-9a-f]{{{POINT_ID_LENGTH}}}")


GRID_PATTERN = re.compile(r"^\s*(?P<key>[^=]+?)\s*=\s*(?P<range>.*)$")


@dataclass(frozen=True)
class SweepPlan:
    """The points of a sweep, in order, and where they came from (kept in ``sweep.json``)."""

    keys: tuple[str, ...]
    points: tuple[dict[str, Any], ...]
    grids: tuple[str, ...] = ()
    points_file: str | None = None
    # The unit each real key's values were first written in ('mm' for amplitude=5mm,10mm), that tables show them in;
    # the points hold SI.
    units: tuple[tuple[str, str], ...] = ()


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


def aliased(key: str) -> str:
    """The key a column or a grid of ``key`` sets: an alias people type (:data:`HALVED_ALIASES`: ``ball_diameter``)
    sets its key (``ball_radius``) at half the value (:func:`aliased_value`); a key sets itself."""
    return HALVED_ALIASES.get(key, key)


def aliased_value(column: str, value: Any) -> Any:
    """``value`` of a column or a grid of ``column``, as its key (:func:`aliased`) stores it; an alias's value out of
    its range is refused in the alias's terms, before any point runs (a point's failure would name the key)."""
    return halved(column, value) if column in HALVED_ALIASES else normalize_value(column, value)


def parse_grid(spec: str, most: int = MAX_SWEEP_POINTS) -> tuple[str, np.ndarray]:
    """``"omega=90:130:9"`` -> ``("omega", linspace(90, 130, 9))``; START and STOP may carry units; N <= ``most``.
    A grid of an alias is its key's (``ball_diameter=8mm:12mm:3`` -> ``ball_radius`` 4, 5, 6 mm)."""
    shown = quoted(spec)
    match = GRID_PATTERN.match(spec)
    if match is None:
        raise ParameterError(f"grid {shown}: expected KEY=START:STOP:N, for example omega=90:130:9")
    column, bounds = match["key"], match["range"].split(":")
    key = aliased(column)
    try:
        check_known_keys([key])
    except ParameterError as exc:
        raise ParameterError(f"grid {shown}: {exc}") from None
    if Parameters.model_fields[key].annotation is not float:
        raise ParameterError(
            f"grid {shown}: START:STOP:N is for real-valued parameters and {key} is not one; list its values as "
            f"{key}=A,B,C"
        )
    if len(bounds) != 3:
        raise ParameterError(f"grid {shown}: expected KEY=START:STOP:N (three fields after '='), got {len(bounds)}")
    start, stop, count = (part.strip() for part in bounds)
    # Digits beyond the limit's are refused before int() would read a number of any length.
    if not (count.isascii() and count.isdigit()) or len(count) > len(str(most)) or not 1 <= int(count) <= most:
        raise ParameterError(f"grid {shown}: N must be a whole number of points in [1, {most:,}], got {quoted(count)}")
    try:
        low, high = (aliased_value(column, bound) for bound in (start, stop))
    except ParameterError as exc:
        raise ParameterError(f"grid {shown}: {exc}") from None
    return key, np.linspace(low, high, int(count))


def grid_values(spec: str) -> tuple[str, Sequence[Any]]:
    """The values of one ``--grid``: ``KEY=START:STOP:N`` for a real-valued key (:func:`parse_grid`), or
    ``KEY=A,B,C`` for a key that takes names (``ball_material=steel,zirconia``, ``solver=full,averaged``), a
    count (``n_balls=1,2,5``) or a real value (``ball_radius=4mm,5mm,6.35mm``, or ``ball_diameter=8mm,10mm``)."""
    match = GRID_PATTERN.match(spec)
    column = match["key"] if match is not None else ""
    key = aliased(column)
    if match is None or key not in Parameters.model_fields or not _takes_a_list(key, match["range"]):
        key, grid = parse_grid(spec)
        return key, list(grid)
    items = [item.strip() for item in match["range"].split(",") if item.strip()]
    if not items:
        raise ParameterError(f"grid {quoted(spec)}: expected KEY=A,B,C, for example ball_material=steel,zirconia")
    check_point_count(len(items))
    try:
        # A misspelt name or unit fails the sweep before it starts, not one point in the middle of it.
        return key, [checked_name(key, item) if takes_names(key) else aliased_value(column, item) for item in items]
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


def grid_unit(spec: str) -> str:
    """The unit the values of one ``--grid`` are first written in ('mm' for amplitude=20mm:30mm:6); '' for none."""
    match = GRID_PATTERN.match(spec)
    return first_unit(re.split("[:,]", match["range"])) if match else ""


def first_unit(values: Iterable[Any]) -> str:
    return next((unit for unit in map(unit_written, values) if unit), "")


def read_points(path: Path | str) -> list[dict[str, Any]]:
    """The points of a CSV file: a header of canonical keys, one point per row, values with or without units."""
    return _points_of(*_point_rows(path))


def _point_rows(path: Path | str) -> tuple[Path, list[str], list[list[str]]]:
    """A points file's header and rows of values, checked as far as they go without the keys' units."""
    source = Path(path)
    rows = read_csv_rows(source, f"points {source}", MAX_SWEEP_POINTS)
    rows = [row for row in rows if any(cell.strip() for cell in row)]
    if len(rows) < 2:
        raise ParameterError(f"points {source}: expected a header of parameter keys and at least one row of values")
    header = [cell.strip() for cell in rows[0]]
    try:
        check_known_keys(header, extra_allowed=tuple(HALVED_ALIASES))
        _check_distinct([aliased(column) for column in header], "column")
    except ParameterError as exc:
        raise ParameterError(f"points {source}: {exc}") from None
    return source, header, rows[1:]


def _points_of(source: Path, header: list[str], rows: list[list[str]]) -> list[dict[str, Any]]:
    return [_point_from_row(source, number, header, row) for number, row in enumerate(rows, start=2)]


def _point_from_row(source: Path, line: int, header: list[str], row: list[str]) -> dict[str, Any]:
    if len(row) != len(header):
        raise ParameterError(f"points {source} line {line}: {len(row)} values for {len(header)} columns")
    point = {}
    for column, cell in zip(header, row):
        if not cell.strip():
            raise ParameterError(f"points {source} line {line}: no value for {column}")
        try:
            point[aliased(column)] = aliased_value(column, cell.strip())
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
    table = _point_rows(points_file) if points_file is not None else None
    listed = _points_of(*table) if table is not None else [{}]
    grid_points = product_points(parsed, len(listed)) if parsed else [{}]
    keys = [*listed[0], *(key for key, _ in parsed)]
    if not keys:
        raise ParameterError("sweep: nothing to sweep; give --grid KEY=START:STOP:N or --points FILE.csv")
    _check_distinct(keys, "grid or points column")
    points = tuple({**row, **values} for row in listed for values in grid_points)
    units = _units_written(table, {key: spec for (key, _), spec in zip(parsed, grids)})
    return SweepPlan(tuple(keys), points, tuple(grids), str(points_file) if points_file is not None else None, units)


def _units_written(
    table: tuple[Path, list[str], list[list[str]]] | None, grids: Mapping[str, str]
) -> tuple[tuple[str, str], ...]:
    """(key, unit) for each real key whose values a points file's column or a ``--grid`` writes with a unit."""
    columns = [aliased(column) for column in table[1]] if table else []
    written = {key: first_unit(row[index] for row in table[2]) for index, key in enumerate(columns)} if table else {}
    written |= {key: grid_unit(spec) for key, spec in grids.items()}
    return tuple(
        (key, unit) for key, unit in written.items() if unit and Parameters.model_fields[key].annotation is float
    )


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
    return SweepPlan(
        keys, tuple({key: normalize_value(key, value) for key, value in point.items()} for point in points)
    )


def check_keys_read(base: Parameters, plan: SweepPlan) -> None:
    """Refuse, in one line, a swept key that a point's run would not read (its engine, or its solver): every point
    would give the same numbers under different labels."""
    for point in plan.points:
        run = reader_for({key: point.get(key, getattr(base, key)) for key in DECIDING})
        problem = run.unread_problem(plan.keys, "swept")
        if problem is not None:
            raise ParameterError(problem)


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
