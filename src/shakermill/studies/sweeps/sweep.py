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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from shakermill.engines.budget import interrupts_held
from shakermill.parameters.defaults import DEFAULT_PRESET, DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.studies.sweeps.backends import backend_for
from shakermill.studies.sweeps.plan import SweepPlan, as_plan, point_ids
from shakermill.studies.sweeps.storage import (
    TABLE_CSV,
    build_table,
    check_folder,
    claim_folder,
    failed_points,
    finished_counts,
    store_point,
    stored_rows,
    sweep_manifest,
    write_table,
)

ProgressCallback = Callable[["SweepProgress"], None]


@dataclass(frozen=True)
class SweepProgress:
    """Where a sweep stands; ``done`` counts failed points and points finished by an earlier run."""

    total: int
    done: int
    failed: int
    running: int


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


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep: ``kept`` of its points are stored (the table says which), the others are marked not
    finished, and running the same sweep into ``folder`` again computes only those."""

    def __init__(self, table: pd.DataFrame, folder: Path, kept: int) -> None:
        super().__init__(f"interrupted; kept {kept} of {len(table)} points in {folder}")
        self.table, self.folder, self.kept = table, folder, kept


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
    :class:`SweepFailed` (naming the first failure) when no point succeeded. Ctrl-C stops the workers at once and
    raises :class:`SweepInterrupted` (a ``KeyboardInterrupt``) once the table holds the finished points.
    """
    plan = as_plan(grid_points)
    _check_execution(workers, scheduler)
    folder = Path(out_dir)
    ids = point_ids(base_params, plan)
    manifest = sweep_manifest(base_params, plan, ids, preset)
    check_folder(folder, manifest)
    stored = stored_rows(folder, ids, warn=True)
    pending = [(identifier, values) for identifier, values in zip(ids, plan.points) if identifier not in stored]
    unfinished: dict[str, str] = {}

    def tabulate() -> pd.DataFrame:
        # Also on Ctrl-C: the table then holds the finished points, the others marked not finished.
        table = build_table(folder, plan.keys, ids, plan.points, unfinished)
        write_table(table, folder)
        return table

    # The backend first: an unreachable scheduler leaves no folder behind.
    with backend_for(workers, scheduler, scheduler_timeout, len(pending)) as backend:
        claim_folder(folder, manifest)
        try:
            tracker = _Tracker(len(ids), finished_counts(stored), backend.slots, progress)
            for identifier, outcome in backend.outcomes(base_params, pending, keep_runs):
                if isinstance(outcome, BaseException):
                    unfinished[identifier] = (
                        f"not finished ({type(outcome).__name__}: {outcome}); re-run the sweep to retry"
                    )
                    tracker.finished(failed=True)
                    continue
                row = store_point(folder, identifier, outcome, preset)
                tracker.finished(failed=row.get("error") is not None)
        except BaseException as stopped:
            # The workers stop before the table is written, not after their points end; a second Ctrl-C
            # meanwhile must leave neither workers running nor the table unwritten.
            with interrupts_held(deliver=False):
                backend.stop()
                table = tabulate()
            if isinstance(stopped, KeyboardInterrupt):
                # Counted from the folder, not as points are stored: Ctrl-C may fall between a store and a count.
                raise SweepInterrupted(table, folder, len(stored_rows(folder, ids))) from None
            raise
        table = tabulate()
    if len(failed_points(table)) == len(table):
        raise SweepFailed(table, folder)
    return table


def _check_execution(workers: int | None, scheduler: str | None) -> None:
    if workers is not None and scheduler is not None:
        raise ParameterError("workers: the local pool's size; with a scheduler the cluster's workers run the points")
    if workers is not None and workers < 1:
        raise ParameterError(f"workers: {workers} is out of range; allowed 1 or more")


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
