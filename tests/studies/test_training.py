"""The training runs of a calibration over every uncertain input go through the executor of many runs (issue 48):
each member stored as it finishes, Ctrl-C keeping those, and the same training resumed computing only the others,
to the same numbers as a training never interrupted."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from shakermill.parameters.assumed import AssumedInput
from shakermill.parameters.presets import default_parameters
from shakermill.studies.calibration import training
from shakermill.studies.calibration.observables import Observable
from shakermill.studies.sweeps.executor import Execution, RunsInterrupted
from shakermill.studies.sweeps.points import PointOutcome
from shakermill.studies.sweeps.storage import POINTS_FOLDER

SHAKERMILL = Path(sys.executable).with_name("shakermill")
PRESET = "spex8000m-3d-mill-head"
# One input the mechanics reads and one only the network reads: each member has its draws of the second.
INPUTS = (
    AssumedInput("friction", 0.1, 0.6, "uniform", "a test's range"),
    AssumedInput("clamp_loss", 1.0, 10.0, "log-uniform", "a test's range"),
)
OBSERVABLES = (Observable("ball", 600.0), Observable("vial", 600.0))
MEMBERS, DRAWS = 8, 2


class Members:
    """A stand-in for a member's run: rises made from its draws' values, a failed run for one member, and Ctrl-C at
    the ``interrupt_at``-th call."""

    def __init__(self, interrupt_at: int = 0) -> None:
        self.calls: list[dict] = []
        self.interrupt_at = interrupt_at

    def __call__(self, base, inputs, observables, point):
        self.calls.append(point)
        if len(self.calls) == self.interrupt_at:
            raise KeyboardInterrupt
        friction = point["draws"][0]["friction"]
        if friction > 0.55:
            return PointOutcome({"error": "a made-up failure", "rises": None})
        rises = [[draw["friction"] * 10 + draw["clamp_loss"] + index for index in range(len(observables))]
                 for draw in point["draws"]]  # fmt: skip
        return PointOutcome({"error": None, "rises": rises})


def trained(folder, members, monkeypatch):
    monkeypatch.setattr(training, "run_member", members)
    return training.train(
        default_parameters(PRESET), INPUTS, OBSERVABLES, MEMBERS, DRAWS, folder=folder, execution=Execution(workers=1)
    )


def test_an_interrupted_training_keeps_its_members_and_resumes_to_the_uninterrupted_numbers(tmp_path, monkeypatch):
    whole = trained(tmp_path / "whole", Members(), monkeypatch)
    first = Members(interrupt_at=4)
    with pytest.raises(RunsInterrupted) as stopped:
        trained(tmp_path / "resumed", first, monkeypatch)
    assert (stopped.value.kept, stopped.value.total) == (3, MEMBERS)
    assert len(list((tmp_path / "resumed" / POINTS_FOLDER).glob("*.json"))) == 3
    rest = Members()
    resumed = trained(tmp_path / "resumed", rest, monkeypatch)
    # Only the members not stored ran again, the interrupted one among them.
    assert len(rest.calls) == MEMBERS - 3
    assert not [point for point in rest.calls if point in first.calls[:3]]
    for name in ("unit", "rises", "member"):
        np.testing.assert_array_equal(getattr(resumed, name), getattr(whole, name))
    assert resumed.failed == whole.failed and whole.failed
    assert whole.failed[0].startswith("member ") and whole.failed[0].endswith(": a made-up failure")
    # Each member's draws share its mechanics: the failed member's draws are all left out.
    assert len(whole.unit) == DRAWS * (MEMBERS - len(whole.failed))


def test_a_training_folder_of_other_runs_is_refused_before_anything_runs(tmp_path, monkeypatch):
    from shakermill.parameters.errors import ParameterError

    trained(tmp_path / "runs", Members(), monkeypatch)
    other = Members()
    monkeypatch.setattr(training, "run_member", other)
    with pytest.raises(ParameterError, match="holds a sweep"):
        training.train(
            default_parameters(PRESET, n_balls=2), INPUTS, OBSERVABLES, MEMBERS, DRAWS, folder=tmp_path / "runs"
        )
    assert other.calls == []


def point_files(folder: Path) -> dict[str, int]:
    """Each stored member's file and when it was written (ns)."""
    return {path.name: path.stat().st_mtime_ns for path in folder.rglob(f"{POINTS_FOLDER}/*.json")}


def wait_for(condition, process: subprocess.Popen, seconds: float, what: str) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        if process.poll() is not None or time.monotonic() > deadline:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
            pytest.fail(f"the calibration ended or stalled before {what}: {process.communicate()[1]!r}")
        time.sleep(0.05)


@pytest.mark.slow
def test_ctrl_c_keeps_the_calibrations_finished_runs_and_the_same_command_resumes_from_them(tmp_path):
    # Ctrl-C in a terminal sends SIGINT to the whole foreground group: the calibration and its workers.
    (tmp_path / "vial.csv").write_text("time_min,vial_C\n0,20\n2,20.6\n5,21.3\n", encoding="utf-8")
    runs = tmp_path / "runs"
    command = [str(SHAKERMILL), "calibrate", "--preset", PRESET, "--curve", str(tmp_path / "vial.csv"),
               "--set", "duration=300", "--set", "dem_averaging_rel_error=0.05", "--with-assumed",
               "--members", "8", "--runs", str(runs), "--workers", "2"]  # fmt: skip

    def started() -> subprocess.Popen:
        return subprocess.Popen(
            command, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )

    process = started()
    wait_for(lambda: len(point_files(runs)) >= 1, process, 600, "a run was stored")
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    kept = point_files(runs)
    said = [line for line in stderr.splitlines() if line.startswith("error:")]
    assert len(said) == 1 and "interrupted" in said[0] and f"--runs {runs}" in said[0], stderr
    assert f"kept {len(kept)} of the 8 runs" in said[0]

    process = started()
    wait_for(lambda: len(point_files(runs)) > len(kept), process, 600, "a further run was stored")
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    # The runs stored before were read back, not computed again: their files are as they were.
    assert {name: written for name, written in point_files(runs).items() if name in kept} == kept
