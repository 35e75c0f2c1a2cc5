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
in which they finish, or whether the points ran on a Dask cluster. The points run through the executor of many runs
(:mod:`.executor`), which a calibration's training runs share.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from shakermill.io.runs import SWEEP_KIND
from shakermill.parameters.defaults import DEFAULT_PRESET, DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.keys import Parameters
from shakermill.studies.sweeps.executor import Execution, ProgressCallback, RunsInterrupted, execute
from shakermill.studies.sweeps.plan import SweepPlan, as_plan, point_ids
from shakermill.studies.sweeps.points import run_point
from shakermill.studies.sweeps.storage import (
    TABLE_CSV,
    build_table,
    failed_points,
    store_point,
    stored_rows,
    sweep_manifest,
    write_table,
)


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
    kind: str = SWEEP_KIND,
    announce: Callable[[str], None] | None = None,
    on_start: Callable[[], None] | None = None,
) -> pd.DataFrame:
    """Run ``base_params`` at every point of ``grid_points`` and return the sweep table.

    ``grid_points`` is a :class:`SweepPlan` (from :func:`plan_sweep`), a mapping of key -> values
    (their Cartesian product, first key slowest) or a sequence of points (mappings of key -> value);
    values may carry units. The solver is the one ``base_params`` names (the command line defaults
    to the averaged one, see :func:`sweep_parameters`). Points run on ``workers`` local processes
    (default: one per core; 1 runs them in this process) or on the Dask cluster at ``scheduler``
    ("tcp://host:8786"). Each finished point is stored at once in ``out_dir``; points stored by an
    earlier run of the same sweep are skipped; ``on_start`` is told when the checks have passed and the points
    start. Raises :class:`ParameterError` (one line) for bad
    input, a folder that holds another sweep, or an unreachable scheduler,
    :class:`~shakermill.atomic.StorageError` for a place where the folder cannot be created, and
    :class:`SweepFailed` (naming the first failure) when no point succeeded. Ctrl-C stops the workers at once and
    raises :class:`SweepInterrupted` (a ``KeyboardInterrupt``) once the table holds the finished points.
    """
    plan = as_plan(grid_points)
    execution = Execution(
        workers, scheduler, scheduler_timeout, progress, base_params.max_wall_time, announce, on_start
    )
    folder = Path(out_dir)
    ids = point_ids(base_params, plan)
    written: list[pd.DataFrame] = []

    def tabulate(unfinished: Mapping[str, str]) -> pd.DataFrame:
        # Also on Ctrl-C: the table then holds the finished points, the others marked not finished.
        table = build_table(folder, plan.keys, ids, plan.points, unfinished)
        write_table(table, folder)
        written.append(table)
        return table

    try:
        unfinished = execute(
            folder,
            sweep_manifest(base_params, plan, ids, preset, kind),
            list(zip(ids, plan.points)),
            functools.partial(run_point, base_params, keep_run=keep_runs),
            functools.partial(_store, preset=preset),
            execution,
            on_stop=tabulate,
        )
    except RunsInterrupted:
        raise SweepInterrupted(written[-1], folder, len(stored_rows(folder, ids))) from None
    table = tabulate(unfinished)
    if len(failed_points(table)) == len(table):
        raise SweepFailed(table, folder)
    return table


def _store(folder: Path, identifier: str, outcome: Any, *, preset: str) -> dict[str, Any]:
    return store_point(folder, identifier, outcome, preset)
