"""Run folders: everything a run produced, written atomically, and read back for later tools.

A run folder holds

* ``timeseries.nc``   the sampled state history (NetCDF4 via h5netcdf; kelvin, SI units in attributes),
* ``windows.nc``      the full-resolution state inside the record windows,
* ``impacts.parquet`` one row per impact, units as JSON in the schema metadata under ``units``,
* ``summary.json``    summary (its keys declared in ``solvers/summary.py``, their version as ``schema_version``),
                      energy audit, exponential fit, counters, status and message,
* ``config.toml``     the resolved parameters with provenance; ``shakermill run config.toml`` repeats the run,

and, once it is in place, the figures the command line draws into it (``figures/``, in a folder of its own).

The folder is built in a hidden sibling ``.<name>.partial-<machine>-<pid>-<random>`` and
moved into place only when complete, so an interrupted write or a full disk never leaves a folder
at the target path that looks like a finished run (:func:`write_folder`).
"""

from __future__ import annotations

import difflib
import errno
import io
import json
import math
import os
import shutil
from collections.abc import Callable, Container, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from shakermill.analysis.fit import ExponentialFit
from shakermill.engines.interface import EngineDescription
from shakermill.engines.records import HERTZ_SCALE, TIME_ATTRIBUTES, StateHistory
from shakermill.engines.registry import describe
from shakermill.engines.status import REACHED_STOP
from shakermill.parameters.config import load_config, write_config_toml
from shakermill.parameters.keys import Parameters
from shakermill.solvers.result import Result
from shakermill.solvers.summary import Summary
from shakermill.solvers.summary_versions import SCHEMA_VERSION, VERSION_KEY, SummaryVersionError, summary_from_document
from shakermill.support.atomic import (
    SET_ASIDE,
    StorageError,
    check_writable_place,
    partial_path,
    remove_abandoned_writes,
)
from shakermill.support.limits import in_one_line
from shakermill.support.version import __version__

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr

    from shakermill.engines.interface import EngineDescription

TIMESERIES_FILE = "timeseries.nc"
WINDOWS_FILE = "windows.nc"
IMPACTS_FILE = "impacts.parquet"
SUMMARY_FILE = "summary.json"
CONFIG_FILE = "config.toml"
RUN_FILES = (TIMESERIES_FILE, WINDOWS_FILE, IMPACTS_FILE, SUMMARY_FILE, CONFIG_FILE)
# Key of the impact table's units in the Parquet schema metadata.
UNITS_METADATA_KEY = b"units"
# Key of what a file covers, where it is less than the whole run (averaged solver): attribute and Parquet metadata.
COVERAGE_KEY = "coverage"
# Reading goes through xarray with this engine; writing uses h5netcdf directly (:func:`netcdf_bytes`).
NETCDF_ENGINE = "h5netcdf"


@dataclass(frozen=True)
class RunData:
    """A run read back from its folder; attribute names follow :class:`shakermill.simulate.Result`."""

    path: Path
    params: Parameters
    preset: str
    status: int
    message: str
    timeseries: xr.Dataset
    windows: xr.Dataset
    impacts: pd.DataFrame
    impact_units: dict[str, str]
    summary: Summary
    energy: dict[str, Any]
    ball_fit: ExponentialFit
    counters: dict[str, int]
    description: EngineDescription  # what the run's engine declares, as a Result's

    @property
    def success(self) -> bool:
        return self.status == REACHED_STOP


def to_jsonable(value: Any) -> Any:
    """``value`` with numpy scalars made plain and non-finite floats made ``None`` (JSON has no NaN)."""
    if isinstance(value, Mapping):
        return {str(key): to_jsonable(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(item) for item in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


@dataclass(frozen=True)
class FolderKind:
    """What one command writes as a folder: its name in messages, and how to recognise one it wrote."""

    noun: str
    written_by_shakermill: Callable[[Path], bool]


# What a folder shakermill wrote holds, recorded as KIND_KEY in the JSON file that describes it (a sweep's manifest, a
# run's or an ensemble's summary), so that --overwrite replaces only a folder of the command's own kind.
KIND_KEY = "kind"
RUN_KIND = "run"
SWEEP_KIND = "sweep"
ENSEMBLE_KIND = "uncertainty ensemble"
DESIGN_KIND = "calibration design"
KIND_PHRASES = {
    RUN_KIND: "a run",
    SWEEP_KIND: "a sweep",
    ENSEMBLE_KIND: "an uncertainty ensemble",
    DESIGN_KIND: "the design of runs of a calibration",
}
# A sweep's manifest: the executor's folders (sweeps, ensembles, a calibration's design) all have one.
MANIFEST_FILE = "sweep.json"


def folder_kind(folder: Path) -> str | None:
    """The kind of folder shakermill wrote at ``folder`` (a key of KIND_PHRASES), or None for anything else.

    A folder written before folders recorded their kind is known by its files: a manifest with a summary beside it is
    an ensemble (its summary written last), a manifest alone a sweep, a summary alone a run."""
    documents = {name: _json_object(folder / name) for name in (MANIFEST_FILE, SUMMARY_FILE)}
    for document in documents.values():
        if document is not None and document.get(KIND_KEY) in KIND_PHRASES:
            return str(document[KIND_KEY])
    manifest, summary = (documents[name] is not None for name in (MANIFEST_FILE, SUMMARY_FILE))
    if manifest:
        return ENSEMBLE_KIND if summary else SWEEP_KIND
    return RUN_KIND if summary and (folder / CONFIG_FILE).is_file() else None


def _json_object(path: Path) -> dict[str, Any] | None:
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):  # absent, unreadable, not UTF-8, not JSON
        return None
    return document if isinstance(document, dict) else None


def other_kind_problem(folder: Path, noun: str) -> str | None:
    """'… holds an uncertainty ensemble, not a run' where ``folder`` holds a shakermill folder of another kind than
    ``noun``'s."""
    found = folder_kind(folder)
    if found is None or found == noun:
        return None
    return f"{folder}: holds {KIND_PHRASES[found]}, not {KIND_PHRASES.get(noun, f'a {noun}')}"


RUN_FOLDER = FolderKind(RUN_KIND, lambda folder: folder_kind(folder) == RUN_KIND)


def check_target(path: Path, *, overwrite: bool = False, kind: FolderKind = RUN_FOLDER) -> None:
    """Raise :class:`StorageError` unless ``path`` can be created, or is an empty folder, or a folder
    of ``kind`` and ``overwrite``.

    Replacing deletes the old folder: one shakermill wrote only when asked to, anything else (a file,
    a folder of the user's own) never.
    """
    if not path.exists() and not path.is_symlink():
        check_writable_place(path)
        return
    if path.is_symlink() or not path.is_dir():
        raise StorageError(f"{path}: exists and is not a folder; choose another --out")
    if not any(path.iterdir()):
        return
    if not kind.written_by_shakermill(path):
        problem = (
            other_kind_problem(path, kind.noun) or f"{path}: a non-empty folder that is not a shakermill {kind.noun}"
        )
        raise StorageError(f"{problem}; choose another --out")
    if not overwrite:
        raise StorageError(
            f"{path}: holds a {kind.noun} already; choose another --out, or add --overwrite to replace it"
        )


def write_folder(
    path: Path | str, fill: Callable[[Path], object], *, overwrite: bool = False, kind: FolderKind = RUN_FOLDER
) -> Path:
    """Have ``fill(folder)`` write a folder's files, then move the folder to ``path`` whole.

    What ``path`` holds is replaced only as :func:`check_target` allows. The folder is built in a
    hidden sibling, so a failure (a full disk) or an interruption leaves nothing at ``path`` that
    looks complete, and the hidden sibling is removed, or, after a kill, by a later write to the same
    parent folder. Returns the folder's absolute path.
    """
    # Absolute, so that "." has a name to derive the sibling folders from.
    target = Path(path).absolute()
    check_target(target, overwrite=overwrite, kind=kind)
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_abandoned_writes(target.parent)
    partial = partial_path(target)
    partial.mkdir()
    try:
        fill(partial)
        _move_into_place(partial, target)
    except BaseException:
        # KeyboardInterrupt included: the half-written folder must not survive.
        shutil.rmtree(partial, ignore_errors=True)
        raise
    return target


def write_run(
    result: Result,
    path: Path | str,
    *,
    preset: str,
    extra_provenance: Mapping[str, Any] | None = None,
    overwrite: bool = False,
) -> Path:
    """Write ``result`` as a run folder at ``path``; a previous run folder there is replaced only with ``overwrite``.
    Returns the folder's absolute path."""

    def fill(folder: Path) -> None:
        _write_contents(result, folder, preset=preset, extra_provenance=extra_provenance or {})

    return write_folder(path, fill, overwrite=overwrite)


def _write_contents(result: Result, folder: Path, *, preset: str, extra_provenance: Mapping[str, Any]) -> None:
    attributes = _run_attributes(result, preset)
    description = result.description
    coverage = averaging_coverage(result)
    history = _mark_averaged_variables(result.history, description, coverage) if coverage else result.history
    title = "shakermill sampled state history"
    series = netcdf_bytes(history, title=title, **attributes, **_covers(coverage, "timeseries"))
    (folder / TIMESERIES_FILE).write_bytes(series)
    title = "shakermill full-resolution state in the record windows"
    windows = netcdf_bytes(result.window_history, title=title, **attributes, **_covers(coverage, "motion"))
    (folder / WINDOWS_FILE).write_bytes(windows)
    impacts = impacts_parquet(result.impact_columns, description.impact_units, coverage=coverage.get("impacts"))
    (folder / IMPACTS_FILE).write_bytes(impacts)
    (folder / SUMMARY_FILE).write_text(summary_json(result, preset), encoding="utf-8")
    provenance = {"status": result.status, "message": result.message, "simulated_s": result.t_end, **extra_provenance}
    write_config_toml(result.params, folder / CONFIG_FILE, preset=preset, extra_provenance=provenance)


def _run_attributes(result: Result, preset: str) -> dict[str, Any]:
    # NetCDF attributes cannot be booleans, hence the integer status only.
    return {
        "shakermill_version": __version__,
        "preset": preset,
        "status": int(result.status),
        "message": result.message,
        "simulated_s": float(result.t_end),
        "temperature_note": "theta_ball, theta_vial, theta_air in kelvin; the same temperatures in degC as theta_*_C",
    }


def averaging_coverage(result: Result) -> dict[str, str]:
    """What the files of an averaged run cover, in words (the motion only over the averaging window); empty for a full
    run."""
    averages = result.averages
    if result.impact_window is None or averages is None:
        return {}
    description = result.description
    start, end = averages.transient, averages.transient + averages.window
    motion = (
        f"the ball's motion was integrated at full resolution only up to t = {end:.6g} s (the averaged solver's "
        f"mechanics phase); record windows after that hold no points"
    )
    return {
        "timeseries": (
            f"averaged solver: the temperatures cover the whole run; {', '.join(description.motion)} are NaN "
            f"(not computed), and {', '.join(description.averaged_flows)} are the averaging window's mean rates times "
            "time"
        ),
        "motion": motion,
        "impacts": (
            f"averaged solver: only the impacts of the averaging window, t = {start:.6g} to {end:.6g} s; the summary's "
            "impacts and impact_rate_hz extend this window's rate to the whole run"
        ),
        "motion_variable": "not computed by the averaged solver (NaN); the motion is in windows.nc and impacts.parquet",
        "flow_variable": "averaged solver: the averaging window's mean rate times time",
    }


def _covers(coverage: Mapping[str, str], part: str) -> dict[str, str]:
    return {COVERAGE_KEY: coverage[part]} if coverage else {}


def _mark_averaged_variables(
    history: StateHistory, description: EngineDescription, coverage: Mapping[str, str]
) -> StateHistory:
    marks = {
        name: {COVERAGE_KEY: coverage["motion_variable"]} for name in description.motion if name in history.variables
    }
    marks.update({name: {COVERAGE_KEY: coverage["flow_variable"]} for name in description.averaged_flows})
    return history.with_attributes(marks)


def import_writers() -> None:
    """Import the libraries that write a run folder's data files before the run: its files must be written at once
    when Ctrl-C ends it, and importing them takes ~0.4 s that a run writing its folder spends anyway."""
    import h5netcdf  # noqa: F401
    import pyarrow.parquet  # noqa: F401


def netcdf_bytes(history: StateHistory, *, title: str, **attributes: Any) -> bytes:
    """``history`` as a NetCDF4 file over the dimension ``time``, with global attributes and each variable's own.

    h5netcdf writes it directly: building an xarray Dataset first would cost a run without figures
    half its start-up. ``xarray.open_dataset`` reads the file as the Dataset :meth:`StateHistory.dataset` gives.
    HDF5 writes into memory, never onto the disk: a full disk makes the HDF5 library fail to close
    the file and crash the interpreter at exit (exit code 139); Python's own write fails cleanly.
    """
    import h5netcdf

    buffer = io.BytesIO()
    with h5netcdf.File(buffer, "w") as file:
        file.attrs.update(title=title, **attributes)
        sizes = {"time": history.times.size}
        for name, (values, _) in history.variables.items():
            sizes.update(zip(history.dims(name), np.shape(values)))
        file.dimensions = sizes
        for name, (values, variable_attributes) in {
            "time": (history.times, TIME_ATTRIBUTES),
            **history.variables,
        }.items():
            variable = file.create_variable(name, history.dims(name), data=values)
            variable.attrs.update(variable_attributes)
    return buffer.getvalue()


def impacts_parquet(
    columns: Mapping[str, np.ndarray], units: Mapping[str, str], *, coverage: str | None = None
) -> memoryview:
    """The impact columns as a Parquet file, with their ``units`` as JSON in the schema metadata, and what
    the table covers (``coverage``) where it is not the whole run."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    units = {column: units.get(column, "") for column in columns}
    metadata = {UNITS_METADATA_KEY: json.dumps(units).encode()}
    if coverage is not None:
        metadata[COVERAGE_KEY.encode()] = coverage.encode()
    arrays = [arrow_array(np.asarray(values)) for values in columns.values()]
    # Dictionary encoding pays for the few names of a string column (what a ball hit), not for floats: on them it
    # takes five times as long (0.26 s against 0.05 s for the 180 000 impacts of a 1-D hour), all of it after Ctrl-C.
    named = [column for column, values in columns.items() if np.asarray(values).dtype.kind in "US"]
    sink = pa.BufferOutputStream()
    pq.write_table(pa.Table.from_arrays(arrays, names=list(columns), metadata=metadata), sink, use_dictionary=named)
    return memoryview(sink.getvalue())


def arrow_array(values: np.ndarray) -> Any:
    """``values`` (numbers, or strings) as a ``pyarrow.Array`` built from its buffers.

    ``pyarrow.array`` would build the same, but first imports pandas to see whether it was handed a
    pandas object: a quarter of the start-up of a run that writes its table without pandas.
    """
    import pyarrow as pa

    if values.dtype.kind in "US":
        encoded = np.char.encode(values.astype(str), "utf-8")
        offsets = np.zeros(values.size + 1, dtype=np.int32)
        np.cumsum(np.char.str_len(encoded), out=offsets[1:])
        buffers = [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(encoded.tolist()))]
        return pa.Array.from_buffers(pa.string(), values.size, buffers)
    contiguous = np.ascontiguousarray(values)
    return pa.Array.from_buffers(
        pa.from_numpy_dtype(contiguous.dtype), contiguous.size, [None, pa.py_buffer(contiguous)]
    )


def summary_document(result: Result, preset: str) -> dict[str, Any]:
    """The content of ``summary.json``, JSON-ready (NaN as ``None``)."""
    return to_jsonable(
        {
            KIND_KEY: RUN_KIND,
            "status": result.status,
            "success": result.success,
            "message": result.message,
            "preset": preset,
            "shakermill_version": __version__,
            VERSION_KEY: SCHEMA_VERSION,
            "summary": result.summary.flat(),
            "energy_audit": result.energy.as_dict(),
            "ball_fit": result.ball_fit.as_dict(),
            "counters": result.counters,
        }
    )


def summary_json(result: Result, preset: str) -> str:
    return json.dumps(summary_document(result, preset), sort_keys=True, indent=2, allow_nan=False) + "\n"


def _move_into_place(partial: Path, target: Path) -> None:
    """Rename ``partial`` to ``target``; an old run folder there is set aside first and deleted after."""
    if not target.exists():
        os.rename(partial, target)
        return
    aside = partial_path(target, SET_ASIDE)
    os.rename(target, aside)
    try:
        os.rename(partial, target)
    except BaseException:
        os.rename(aside, target)
        raise
    shutil.rmtree(aside, ignore_errors=True)


def load_run(path: Path | str) -> RunData:
    """Read a run folder written by :func:`write_run` (datasets are loaded into memory, files closed).

    Raises :class:`StorageError` naming the file, in one line, for a folder that is not a run or a
    file that is missing, truncated or damaged.
    """
    folder = Path(path)
    summary_path = folder / SUMMARY_FILE
    if not folder.exists():
        raise StorageError(no_such_folder(folder))
    if not folder.is_dir():
        raise StorageError(f"{folder}: a file, not a shakermill run folder")
    if not summary_path.is_file():
        raise StorageError(f"{folder}: not a shakermill run folder (no {SUMMARY_FILE})")
    problem = other_kind_problem(folder, RUN_KIND)
    if problem is not None:
        raise StorageError(f"{problem} folder")
    try:
        document = _read_part(summary_path, _summary_document)
    except SummaryVersionError as exc:
        # What to do in the same line: re-run an old run (its config.toml repeats it), or read a newer one with a newer
        # shakermill.
        rerun = f"; re-run it to read it here: shakermill run {folder / CONFIG_FILE} --out NEW_FOLDER"
        rerun = rerun if exc.older else ""
        raise StorageError(f"{folder}: {SUMMARY_FILE} {exc}{rerun}") from None
    config = _read_part(folder / CONFIG_FILE, load_config)
    # The one lookup by name: a run folder names its engine in config.toml; the run data carry its description.
    description = describe(config.params.engine)
    impacts, impact_units = _read_part(folder / IMPACTS_FILE, lambda path: _read_impact_table(path, description))
    return RunData(
        path=folder,
        params=config.params,
        preset=config.preset,
        status=document["status"],
        message=document["message"],
        timeseries=_read_part(folder / TIMESERIES_FILE, lambda path: _read_history(path, description)),
        windows=_read_part(folder / WINDOWS_FILE, lambda path: _read_history(path, description)),
        impacts=impacts,
        impact_units=impact_units,
        summary=document["summary"],
        energy=document["energy_audit"],
        ball_fit=_fit_from_dict(document["ball_fit"]),
        counters=document["counters"],
        description=description,
    )


def no_such_folder(folder: Path) -> str:
    """'results/defualt: no such folder', with the folder beside it likely meant: a typo is the usual reason."""
    try:
        beside = [entry.name for entry in folder.parent.iterdir() if entry.is_dir()]
    except OSError:  # no parent folder, or one that cannot be listed
        beside = []
    close = difflib.get_close_matches(folder.name, beside, n=1)
    return f"{folder}: no such folder" + (f"; did you mean {folder.parent / close[0]}?" if close else "")


# What summary.json must hold, and of which JSON type, for the tools that read a run folder back.
SUMMARY_SHAPE = {
    "status": int,
    "message": str,
    "summary": dict,
    "energy_audit": dict,
    "ball_fit": dict,
    "counters": dict,
}


def _summary_document(path: Path) -> dict[str, Any]:
    """``summary.json`` with its summary read into the schema (an older version's brought forward where it can be:
    :func:`~shakermill.solvers.summary_versions.summary_from_document`)."""
    document = json.loads(path.read_text(encoding="utf-8"))
    if not isinstance(document, dict):
        raise ValueError(f"a JSON {type(document).__name__}, not an object")
    for key, kind in SUMMARY_SHAPE.items():
        if type(document.get(key)) is not kind:  # not isinstance: true is no status
            raise ValueError(f"{key!r} is missing or not a JSON {kind.__name__}")
    return {**document, "summary": summary_from_document(document["summary"], document.get(VERSION_KEY))}


def _read_history(path: Path, description: EngineDescription) -> xr.Dataset:
    import xarray as xr

    dataset = xr.load_dataset(path, engine=NETCDF_ENGINE)
    # What plot and report read (every version wrote them).
    _require(description.read_back, dataset.variables, "variable")
    return dataset


def _read_impact_table(path: Path, description: EngineDescription) -> tuple[pd.DataFrame, dict[str, str]]:
    impacts, units = read_impacts(path)
    # A folder written before issue 50 has no Hertz durations: its records are read as its contacts.
    _require([name for name in description.impact_units if name != HERTZ_SCALE], impacts.columns, "column")
    return impacts, units


def _require(names: Iterable[str], present: Container[object], kind: str) -> None:
    """A file of the right format but not written by a run (another tool's, an empty one) lacks what plot and report
    read."""
    missing = [name for name in names if name not in present]
    if missing:
        raise ValueError(f"no {kind} {missing[0]!r}; not written by shakermill run")


def _read_part(path: Path, read: Callable[[Path], Any]) -> Any:
    """``read(path)``, or :class:`StorageError` naming the run folder, the file and why it cannot be read."""
    try:
        if not path.is_file():
            raise FileNotFoundError(errno.ENOENT, "missing")
        return read(path)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        # ValueError covers malformed JSON, TOML and Parquet (ArrowInvalid) and a configuration that no longer
        # validates.
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else in_one_line(exc)
        # A configuration error names the file already.
        reason = reason.removeprefix(f"{path}: ") or type(exc).__name__
        raise StorageError(f"{path.parent}: not a readable shakermill run folder ({path.name}: {reason})") from None


def read_impacts(path: Path) -> tuple[pd.DataFrame, dict[str, str]]:
    """The impact table and its column units."""
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    metadata = table.schema.metadata or {}
    units = json.loads(metadata.get(UNITS_METADATA_KEY, b"{}"))
    return table.to_pandas(), units


def _fit_from_dict(values: Mapping[str, Any]) -> ExponentialFit:
    """The fit ``summary.json`` stores under ``ball_fit``: null where a number was not finite, NaN again here."""

    def number(name: str) -> float:
        value = values.get(name)
        return math.nan if value is None else float(value)

    return ExponentialFit(
        theta_0=number("theta_0"),
        theta_inf=number("theta_inf"),
        tau=number("tau"),
        theta_inf_stderr=number("theta_inf_stderr"),
        tau_stderr=number("tau_stderr"),
        rms_residual=number("rms_residual"),
        success=bool(values.get("success")),
        message=str(values.get("message", "")),
    )
