"""The one executor of many runs: every study that runs many (a sweep, an ensemble, a calibration's training) hands it
its tasks, each an id and its values, and the work that turns values into an outcome. It runs them in this process,
on a local pool or on a Dask cluster (:mod:`.backends`), stores each outcome in its folder the moment it finishes
(``points/<id>.json``, :mod:`.storage`), and skips the tasks an earlier run into the same folder stored: Ctrl-C keeps
what finished, and the same call resumes.

The folder's manifest (``sweep.json``) says what it holds, so that a folder of other runs is refused before anything
runs. A task's outcome depends on its values alone, so what is stored does not depend on the number of workers, the
order in which they finish, or whether the tasks ran on a cluster.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shakermill.engines.budget import interrupts_held
from shakermill.parameters.defaults import DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.errors import ParameterError
from shakermill.studies.sweeps.backends import Task, Work, backend_for
from shakermill.studies.sweeps.storage import check_folder, claim_folder, finished_counts, stored_rows


@dataclass(frozen=True)
class Progress:
    """Where many runs stand; ``done`` counts failed tasks and tasks finished by an earlier run."""

    total: int
    done: int
    failed: int
    running: int


ProgressCallback = Callable[[Progress], None]
# Stores a task's outcome in the folder and returns its row (``error`` set where the task failed).
Store = Callable[[Path, str, Any], Mapping[str, Any]]


class RunsInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped many runs: ``kept`` of the ``total`` tasks are stored in ``folder``; running the same tasks into
    it again computes only the others."""

    def __init__(self, folder: Path, kept: int, total: int) -> None:
        super().__init__(f"interrupted; kept {kept} of {total} in {folder}")
        self.folder, self.kept, self.total = folder, kept, total


@dataclass(frozen=True)
class Execution:
    """Where and how the tasks run: the local pool's ``workers`` (one per core by default; 1 runs them in this
    process) or the Dask ``scheduler``'s cluster, and the progress callback."""

    workers: int | None = None
    scheduler: str | None = None
    scheduler_timeout: float = DEFAULT_SCHEDULER_TIMEOUT_S
    progress: ProgressCallback | None = None
    # The longest one task may take (a run's max_wall_time), which bounds each wait on a cluster; None: no bound.
    round_limit_s: float | None = None
    # Where a wait for the cluster says that it still waits (a line for the user).
    announce: Callable[[str], None] | None = None
    # Told once every check has passed and the workers are up, before the first task: a command's announcement of
    # its work must not come before a refusal of its folder, its workers or its scheduler.
    on_start: Callable[[], None] | None = None

    def __post_init__(self) -> None:
        if self.workers is not None and self.scheduler is not None:
            raise ParameterError(
                "workers: the local pool's size; with a scheduler the cluster's workers run the points"
            )
        if self.workers is not None and self.workers < 1:
            raise ParameterError(f"workers: {self.workers} is out of range; allowed 1 or more")


# One worker process a core, Ctrl-C and progress as the defaults say.
LOCAL_POOL = Execution()


def execute(
    folder: Path,
    manifest: dict[str, Any],
    tasks: Sequence[Task],
    work: Work,
    store: Store,
    execution: Execution = LOCAL_POOL,
    *,
    raise_failures: bool = False,
    on_stop: Callable[[Mapping[str, str]], None] | None = None,
) -> dict[str, str]:
    """Run ``work(values)`` for each task not stored in ``folder`` and ``store`` each outcome as it finishes; return
    why each task not stored is not (a task that raised, with ``raise_failures`` False: the sweep's table says so).

    ``folder`` must be absent, empty or hold this very ``manifest`` (ParameterError otherwise, before anything runs).
    With ``raise_failures`` the first task that raised stops the others and its exception is raised. On Ctrl-C the
    workers stop, ``on_stop(unfinished)`` is called with further Ctrl-C held (the sweep writes its table there), and
    :class:`RunsInterrupted` is raised; any other exception calls ``on_stop`` too and is raised again."""
    folder = Path(folder)
    ids = [identifier for identifier, _ in tasks]
    check_folder(folder, manifest)
    stored = stored_rows(folder, ids, warn=True)
    pending = [(identifier, values) for identifier, values in tasks if identifier not in stored]
    unfinished: dict[str, str] = {}
    # The backend first: an unreachable scheduler leaves no folder behind.
    with backend_for(
        execution.workers,
        execution.scheduler,
        execution.scheduler_timeout,
        len(pending),
        round_limit_s=execution.round_limit_s,
        announce=execution.announce,
    ) as backend:
        claim_folder(folder, manifest)
        if execution.on_start is not None:
            execution.on_start()
        try:
            tracker = _Tracker(len(ids), finished_counts(stored), backend.slots, execution.progress)
            for identifier, outcome in backend.outcomes(work, pending):
                if isinstance(outcome, BaseException):
                    if raise_failures:
                        raise outcome
                    unfinished[identifier] = (
                        f"not finished ({type(outcome).__name__}: {outcome}); re-run the sweep to retry"
                    )
                    tracker.finished(failed=True)
                    continue
                row = store(folder, identifier, outcome)
                tracker.finished(failed=row.get("error") is not None)
        except BaseException as stopped:
            # The workers stop before the table is written, not after their points end; a second Ctrl-C
            # meanwhile must leave neither workers running nor the table unwritten.
            with interrupts_held(deliver=False):
                backend.stop()
                if on_stop is not None:
                    on_stop(unfinished)
            if isinstance(stopped, KeyboardInterrupt):
                # Counted from the folder, not as tasks are stored: Ctrl-C may fall between a store and a count.
                raise RunsInterrupted(folder, len(stored_rows(folder, ids)), len(ids)) from None
            raise
    return unfinished


class _Tracker:
    """Counts finished tasks and reports them to the progress callback."""

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
            self.progress(Progress(self.total, self.done, self.failed, running))
