"""The files of a sweep folder (the folder's layout: :mod:`sweep`): the manifest a re-run is checked against, one
file per finished point, written the moment it finishes, and the table built from them."""

from __future__ import annotations

import io
import json
import warnings
from collections.abc import Mapping, Sequence
from contextlib import suppress
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pandas as pd

from shakermill.io.runs import (
    ENSEMBLE_KIND,
    KIND_KEY,
    MANIFEST_FILE,
    SWEEP_KIND,
    folder_kind,
    other_kind_problem,
    to_jsonable,
)
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.studies.sweeps.plan import POINT_ID_LENGTH, POINT_ID_PATTERN, SweepPlan
from shakermill.studies.sweeps.points import PointOutcome, failed_row
from shakermill.support.atomic import (
    check_writable_place,
    create_exclusively,
    remove_abandoned_writes,
    write_files_atomically,
    write_text_atomically,
)
from shakermill.support.limits import in_one_line
from shakermill.support.version import __version__

POINTS_FOLDER = "points"


RUNS_FOLDER = "runs"


TABLE_STEM = "sweep"


TABLE_PARQUET = f"{TABLE_STEM}.parquet"


TABLE_CSV = f"{TABLE_STEM}.csv"


MANIFEST_FORMAT = "shakermill-sweep/1"


# Columns that measure the machine, not the model: they differ between two runs of the same point.
TIMING_COLUMNS = ("wall_time_s",)


FIRST_COLUMNS = ("point_id",)


OUTCOME_COLUMNS = ("regime", "period", "error")


@dataclass(frozen=True)
class SweepData:
    """A sweep folder read back: its manifest, swept keys and table."""

    path: Path
    manifest: dict[str, Any]
    keys: tuple[str, ...]
    table: pd.DataFrame


def sweep_manifest(
    base: Parameters, plan: SweepPlan, ids: Sequence[str], preset: str, kind: str = SWEEP_KIND
) -> dict[str, Any]:
    """The content of ``sweep.json``; ``kind`` says which study's folder it is (``io.runs.KIND_PHRASES``)."""
    return to_jsonable(
        {
            "format": MANIFEST_FORMAT,
            KIND_KEY: kind,
            "shakermill_version": __version__,
            "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
            "preset": preset,
            "base": base.model_dump(),
            "keys": list(plan.keys),
            "grids": list(plan.grids),
            "points_file": plan.points_file,
            "points": [{"point_id": identifier, "values": values} for identifier, values in zip(ids, plan.points)],
        }
    )


def check_folder(folder: Path, manifest: dict[str, Any]) -> None:
    """Refuse a folder that is neither empty, absent, nor a folder of this very sweep."""
    manifest_path = folder / MANIFEST_FILE
    if manifest_path.is_file():
        _check_same_sweep(folder, read_manifest(folder), manifest)
    elif folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        not_ours = f"{folder}: exists and is not a shakermill {manifest[KIND_KEY]} folder"
        raise ParameterError(f"{other_kind_problem(folder, manifest[KIND_KEY]) or not_ours}; choose another --out")
    elif not folder.exists():
        check_writable_place(folder)


def claim_folder(folder: Path, manifest: dict[str, Any]) -> None:
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
    """Refuse to resume into a folder of another kind (an ensemble's, for a sweep), or whose base parameters or points
    differ: its rows would not match."""
    # A manifest written before manifests recorded their kind: a finished ensemble's has its summary beside it, and
    # any other may be resumed by the study that wrote it.
    legacy = ENSEMBLE_KIND if folder_kind(folder) == ENSEMBLE_KIND else wanted[KIND_KEY]
    stored_kind = stored.get(KIND_KEY, legacy)
    if stored_kind != wanted[KIND_KEY]:
        raise ParameterError(f"{other_kind_problem(folder, wanted[KIND_KEY])}; choose another --out")
    difference = _first_difference(stored.get("base", {}), wanted["base"])
    if difference is not None:
        key, before, now = difference
        raise ParameterError(
            f"{folder}: holds a sweep with other base parameters ({key} = {before!r} there, {now!r} now); "
            "choose another --out"
        )
    if stored.get("keys") != wanted["keys"] or stored.get("points") != wanted["points"]:
        raise ParameterError(
            f"{folder}: holds a sweep over other points (grid "
            f"{' '.join(stored.get('grids') or []) or 'from a points file'}); "
            "choose another --out"
        )


def _first_difference(stored: Mapping[str, Any], wanted: Mapping[str, Any]) -> tuple[str, Any, Any] | None:
    for key in sorted(set(stored) | set(wanted)):
        if stored.get(key) != wanted.get(key):
            return key, stored.get(key), wanted.get(key)
    return None


def read_manifest(folder: Path) -> dict[str, Any]:
    """``sweep.json`` of ``folder``, checked: paths are built from its point ids, so each must be one."""
    damaged = f"run the sweep into a new folder, or put back the {MANIFEST_FILE} it wrote"
    try:
        manifest = json.loads((folder / MANIFEST_FILE).read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise ParameterError(
            f"{folder}: {MANIFEST_FILE} is not UTF-8 text, so not the manifest a sweep writes; {damaged}"
        ) from None
    except json.JSONDecodeError as exc:
        raise ParameterError(
            f"{folder}: {MANIFEST_FILE} is not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg}), so not "
            "the "
            f"manifest a sweep writes; {damaged}"
        ) from None
    except OSError as exc:
        raise ParameterError(f"{folder}: cannot read {MANIFEST_FILE} ({in_one_line(exc)})") from None
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
            unreadable.append(f"{path} ({in_one_line(exc)})")
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


def finished_counts(stored: Mapping[str, Mapping[str, Any]]) -> tuple[int, int]:
    """(points stored by an earlier run, how many of them failed)."""
    return len(stored), sum(row.get("error") is not None for row in stored.values())


def store_point(folder: Path, identifier: str, outcome: PointOutcome, preset: str) -> dict[str, Any]:
    """Write the run folder (if kept) and then the point file: the point file marks the point finished."""
    row = {"point_id": identifier, **outcome.row}
    if outcome.result is not None:
        from shakermill.io.runs import write_run  # netCDF and Parquet writers: only needed with keep_runs

        target = folder / RUNS_FOLDER / identifier
        provenance = {"command": "shakermill sweep", "sweep": str(folder.absolute()), "point_id": identifier}
        # A run folder without its point file was left by a killed sweep: this point's, so it is replaced.
        row["output_dir"] = str(
            write_run(outcome.result, target, preset=preset, extra_provenance=provenance, overwrite=True)
        )
    document = {"point_id": identifier, "shakermill_version": __version__, "row": row}
    write_text_atomically(_point_path(folder, identifier), json.dumps(document, indent=1, allow_nan=False) + "\n")
    return row


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
        table = build_table(
            folder, keys, [entry["point_id"] for entry in entries], [entry["values"] for entry in entries]
        )
    return SweepData(folder, manifest, keys, table)


def _read_table(path: Path, keys: Sequence[str]) -> pd.DataFrame:
    try:
        table = pd.read_parquet(path)
    except (OSError, ValueError) as exc:  # pyarrow's ArrowInvalid is a ValueError
        raise ParameterError(
            f"{path}: cannot read the table ({in_one_line(exc)}); re-run the sweep to rebuild it"
        ) from None
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
