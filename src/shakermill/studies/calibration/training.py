"""The runs an emulated calibration learns from (Kennedy & O'Hagan 2001): a scrambled Sobol' design over the prior,
``members`` runs of the mechanics over the inputs it reads and, at each, ``thermal_draws`` points of the keys only the
thermal network reads (a network under the member's mean load, milliseconds), so the cheap directions are sampled
densely.

The members run through the executor of many runs (``studies.sweeps.executor``): in parallel on a local pool or a
Dask cluster, each member's rises stored in the training's folder the moment it finishes, so that Ctrl-C keeps the
members finished and the same training into the same folder computes only the others. A member's rises depend on its
values alone: the training is the same whatever the number of workers, and whether it was resumed.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from shakermill.engines.registry import engine_named
from shakermill.io.runs import DESIGN_KIND
from shakermill.parameters.assumed import AssumedInput, with_derived
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.keys import Parameters
from shakermill.solvers.simulate import thermal_variants
from shakermill.studies.calibration.observables import Observable, node_rises
from shakermill.studies.inference.design import check_power_of_two, design_seed, sobol
from shakermill.studies.inference.prior import Prior
from shakermill.studies.sweeps.executor import LOCAL_POOL, Execution, Progress, execute
from shakermill.studies.sweeps.plan import SweepPlan, point_id
from shakermill.studies.sweeps.points import PointOutcome
from shakermill.studies.sweeps.storage import store_point, stored_rows, sweep_manifest


@dataclass
class Training:
    """The runs an emulator learns from: the inputs, their unit-cube points, the observables' rises (K) and the
    mechanical member each point belongs to."""

    inputs: tuple[AssumedInput, ...]
    observables: tuple[Observable, ...]
    unit: np.ndarray
    rises: np.ndarray
    member: np.ndarray
    failed: list[str] = field(default_factory=list)


def design_points(
    params: Parameters, inputs: Sequence[AssumedInput], members: int, thermal_draws: int
) -> tuple[np.ndarray, int]:
    """The unit-cube points of the training (members × draws, inputs), each member's draws together, and the draws a
    member has (1 where no input is the network's alone)."""
    for name, count in (("members", members), ("thermal draws", thermal_draws)):
        check_power_of_two(name, count)
    thermal_only = set(params.engine_keys.thermal_only_keys)
    mechanical = [index for index, item in enumerate(inputs) if item.key not in thermal_only]
    network = [index for index, item in enumerate(inputs) if item.key in thermal_only]
    draws = thermal_draws if network else 1
    seed = design_seed(params, inputs)
    unit = np.empty((members * draws, len(inputs)))
    mechanics = sobol(max(len(mechanical), 1), members, seed)
    unit[:, mechanical] = np.repeat(mechanics[:, : len(mechanical)], draws, axis=0)
    if network:
        unit[:, network] = sobol(len(network), members * draws, seed + 1)
    return unit, draws


def train(
    params: Parameters,
    inputs: Sequence[AssumedInput],
    observables: Sequence[Observable],
    members: int,
    thermal_draws: int,
    progress: Callable[[int, int], None] | None = None,
    folder: Path | None = None,
    execution: Execution = LOCAL_POOL,
) -> Training:
    """Run ``params`` at ``members`` points of a Sobol' design over the inputs its mechanics reads, and its network
    at ``thermal_draws`` points each over the inputs only the network reads (module docstring), through the executor
    into ``folder`` (a temporary one, not kept, where None); ``progress(done, members)`` as members finish. A member
    whose run fails is left out and named in ``failed``; one whose run raises (a spent budget) stops the training
    and is raised. Ctrl-C raises ``executor.RunsInterrupted``, the finished members kept in ``folder``."""
    unit, draws = design_points(params, inputs, members, thermal_draws)
    values = Prior(tuple(inputs)).values(unit)
    keys = [item.key for item in inputs]
    names = [observable.name for observable in observables]
    tasks = []
    for member in range(members):
        rows = range(member * draws, (member + 1) * draws)
        point = {"draws": [dict(zip(keys, map(float, values[row]))) for row in rows], "observables": names}
        tasks.append((point_id(params, point), point))
    # A member is one run of the mechanics: its max_wall_time bounds each wait on a cluster.
    bounded = dataclasses.replace(execution, round_limit_s=params.max_wall_time)
    shown = bounded if progress is None else _counting(bounded, progress)
    work = functools.partial(run_member, params, tuple(inputs), tuple(observables))
    with _training_folder(folder) as place:
        plan = SweepPlan(tuple(keys), tuple(point for _, point in tasks))
        manifest = sweep_manifest(params, plan, [identifier for identifier, _ in tasks], DEFAULT_PRESET, DESIGN_KIND)
        execute(place, manifest, tasks, work, _store, shown, raise_failures=True)
        stored = stored_rows(place, [identifier for identifier, _ in tasks])
    rises = np.full((len(unit), len(observables)), np.nan)
    failed = []
    for member, (identifier, _) in enumerate(tasks):
        row = stored[identifier]
        if row["error"] is not None:
            failed.append(f"member {member}: {row['error']}")
        else:
            rises[member * draws : (member + 1) * draws] = np.array(row["rises"], dtype=float)
    kept = np.isfinite(rises).all(axis=1)
    return Training(
        tuple(inputs), tuple(observables), unit[kept], rises[kept], np.repeat(np.arange(members), draws)[kept], failed
    )


def run_member(
    base: Parameters, inputs: tuple[AssumedInput, ...], observables: tuple[Observable, ...], point: Mapping[str, Any]
) -> PointOutcome:
    """One member of a training: its mechanics run once (the averaged solver), then each of its draws' network under
    that mean load; the row holds each draw's rises (K) of ``observables``, or the run's failure."""
    runs = [base.replace(**with_derived(base, inputs, draw)) for draw in point["draws"]]
    result = thermal_variants(runs[0])(runs[0])
    if not result.success or result.load is None:
        return PointOutcome({"error": result.message, "rises": None})
    rises = node_rises(observables, engine_named(base.engine).network_for)
    table = [[_stored(value) for value in rises(run, result.load).values()] for run in runs]
    return PointOutcome({"error": None, "rises": table})


def _stored(value: float) -> float | None:
    # A point file holds JSON without NaN: a rise that is not finite is stored as none, and read back as NaN.
    return value if math.isfinite(value) else None


def _store(folder: Path, identifier: str, outcome: PointOutcome) -> dict[str, Any]:
    return store_point(folder, identifier, outcome, DEFAULT_PRESET)


def _counting(execution: Execution, progress: Callable[[int, int], None]) -> Execution:
    def report(state: Progress) -> None:
        progress(state.done, state.total)

    return dataclasses.replace(execution, progress=report)


@contextmanager
def _training_folder(folder: Path | None) -> Iterator[Path]:
    if folder is not None:
        yield Path(folder)
        return
    with tempfile.TemporaryDirectory(prefix="shakermill-training-") as place:
        yield Path(place) / "runs"


def group_folder(folder: Path | None, conditions: Sequence[str]) -> Path | None:
    """The training folder of one set of conditions under a calibration's folder of runs (None: a temporary one)."""
    if folder is None:
        return None
    digest = hashlib.sha256(json.dumps(list(conditions)).encode()).hexdigest()[:8]
    return Path(folder) / ("own-conditions" if not conditions else f"conditions-{digest}")
