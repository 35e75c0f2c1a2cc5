"""Full and read-only disks, and the leftovers of killed writes (issue 12).

A full disk is simulated three ways: in this process, by files that refuse bytes beyond a budget
(every file shakermill writes goes through Python's own file objects); in a child process whose
files may not grow beyond a size (RLIMIT_FSIZE, the operating system's own refusal); and, where
this machine allows a user namespace, on a small tmpfs mounted for the child alone.
"""

from __future__ import annotations

import errno
import os
import pathlib
import resource
import shutil
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from shakermill import cli
from shakermill.io.runs import load_run
from shakermill.studies.sweeps.storage import MANIFEST_FILE, load_sweep
from shakermill.support.atomic import PARTIAL, create_exclusively, partial_path, remove_abandoned_writes, this_machine

# One simulated second without record windows: the run folder is ~50 kB, written in a second.
RUN = ["run", "--set", "duration=1", "--set", "record_windows=", "--set", "attractor_starts=1", "--no-plots"]
SWEEP = [
    "sweep",
    "--grid",
    "omega=100:110:2",
    "--set",
    "duration=1",
    "--set",
    "record_windows=",
    "--set",
    "attractor_starts=1",
    "--workers",
    "1",
]
NO_SPACE = os.strerror(errno.ENOSPC)
SHAKERMILL_MAIN = [sys.executable, "-c", "from shakermill.cli import main; main()"]

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(cli.app, list(args))


def error_lines(stderr: str) -> list[str]:
    """stderr without the run's warnings (a one-second run is short, and says so)."""
    return [line for line in stderr.strip().splitlines() if not line.startswith("warning: ")]


def assert_one_error_line(stderr: str, *fragments: str) -> None:
    lines = error_lines(stderr)
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


def hidden_entries(folder: Path) -> list[str]:
    return sorted(str(path.relative_to(folder)) for path in folder.rglob(".*"))


class _FillingFile:
    """A file object that takes bytes until its disk's budget is spent, then fails as a full disk does."""

    def __init__(self, stream, disk: dict[str, int]) -> None:
        self._stream, self._disk = stream, disk

    def write(self, data) -> int:
        size = len(data) if isinstance(data, str) else memoryview(data).nbytes
        if size > self._disk["left"]:
            raise OSError(errno.ENOSPC, NO_SPACE)
        self._disk["left"] -= size
        return self._stream.write(data)

    def __enter__(self):
        return self

    def __exit__(self, *exc_info) -> None:
        self._stream.close()

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


@pytest.fixture
def disk_with(monkeypatch, tmp_path):
    """``disk_with(bytes)``: from now on, files written under ``tmp_path`` share that many bytes."""

    def limit(budget: int) -> None:
        disk = {"left": budget}
        opened = pathlib.Path.open

        def open_on_the_small_disk(path, mode="r", *args, **kwargs):
            stream = opened(path, mode, *args, **kwargs)
            writing = any(flag in mode for flag in "wax+")
            return _FillingFile(stream, disk) if writing and tmp_path in Path(path).absolute().parents else stream

        monkeypatch.setattr(pathlib.Path, "open", open_on_the_small_disk)

    return limit


# Full disk, simulated in this process ---------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("budget", [0, 20_000, 45_000], ids=["no space", "full in windows.nc", "full near the end"])
def test_a_run_onto_a_full_disk_is_one_line_and_leaves_nothing(tmp_path, disk_with, budget):
    disk_with(budget)
    outcome = invoke(*RUN, "--out", str(tmp_path / "run"))
    assert outcome.exit_code == 2, outcome.stderr
    assert_one_error_line(outcome.stderr, str(tmp_path / "run"), "cannot write the run folder", NO_SPACE)
    assert list(tmp_path.iterdir()) == []  # neither the run nor its hidden partial folder


@pytest.mark.slow
def test_a_full_disk_keeps_the_run_that_was_to_be_replaced(tmp_path, disk_with):
    out = tmp_path / "run"
    assert invoke(*RUN, "--out", str(out)).exit_code == 0
    before = (out / "summary.json").read_bytes()
    disk_with(10_000)
    outcome = invoke(*RUN, "--set", "duration=2", "--out", str(out), "--overwrite")
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, NO_SPACE)
    assert (out / "summary.json").read_bytes() == before
    assert [entry.name for entry in tmp_path.iterdir()] == ["run"]


@pytest.mark.slow
def test_a_sweep_whose_manifest_finds_no_space_leaves_no_folder_and_can_run_later(tmp_path, disk_with, monkeypatch):
    out = tmp_path / "sweep"
    disk_with(0)
    outcome = invoke(*SWEEP, "--out", str(out))
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, NO_SPACE)
    assert "re-run" not in outcome.stderr  # there is nothing to resume
    assert list(tmp_path.iterdir()) == []
    monkeypatch.undo()
    assert invoke(*SWEEP, "--out", str(out)).exit_code == 0


@pytest.mark.slow
def test_a_sweep_that_fills_the_disk_midway_is_resumed_by_the_same_command(tmp_path, disk_with, monkeypatch):
    out = tmp_path / "sweep"
    disk_with(6_000)  # the manifest, not both points
    outcome = invoke(*SWEEP, "--out", str(out))
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, NO_SPACE, f"re-run with --out {out}")
    assert (out / MANIFEST_FILE).is_file()
    monkeypatch.undo()
    resumed = invoke(*SWEEP, "--out", str(out))
    assert resumed.exit_code == 0, resumed.stderr
    assert load_sweep(out).table["error"].isna().all()
    assert hidden_entries(out) == []


@pytest.mark.slow
def test_a_sweep_keeping_its_runs_on_a_full_disk_is_one_line(tmp_path, disk_with):
    out = tmp_path / "sweep"
    disk_with(30_000)  # the manifest and part of the first run folder
    outcome = invoke(*SWEEP, "--keep-runs", "--out", str(out))
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, NO_SPACE)
    assert hidden_entries(out) == []
    assert not list((out / "runs").iterdir())


@pytest.mark.slow
def test_calibrate_onto_a_full_disk_says_why_in_one_line(tmp_path, disk_with):
    preset = tmp_path / "fitted.toml"
    disk_with(0)
    outcome = invoke("calibrate", "--target", "theta_inf_C=100", "--free", "beta", "--out", str(preset))
    assert outcome.exit_code == 2
    # The fit said which key it moves when it started; the failed write is the one error line after it.
    announced, error = outcome.stderr.splitlines()
    assert announced == "calibrate: fitting beta"
    assert_one_error_line(error, str(preset), "cannot write the preset", NO_SPACE)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_report_onto_a_full_disk_keeps_the_earlier_report(tmp_path, disk_with):
    run = tmp_path / "run"
    assert invoke(*RUN, "--out", str(run)).exit_code == 0
    report = run / "report.html"
    report.write_text("an earlier report")
    disk_with(1_000)
    outcome = invoke("report", str(run), "--overwrite")
    assert outcome.exit_code == 2
    assert_one_error_line(outcome.stderr, str(report), "cannot write the report", NO_SPACE)
    assert report.read_text() == "an earlier report"
    assert hidden_entries(run) == []


# Full and read-only disks, for real, in a child process ------------------------------------------------


def run_limited(args: list[str], file_size_limit: int, cwd: Path) -> subprocess.CompletedProcess:
    """The command line in a child whose files may not grow beyond ``file_size_limit`` bytes.

    Python ignores SIGXFSZ, so an oversized write fails with EFBIG instead of killing the child.
    """

    def limit_file_size() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_size_limit, file_size_limit))

    return subprocess.run(
        [*SHAKERMILL_MAIN, *args], cwd=cwd, preexec_fn=limit_file_size, capture_output=True, text=True, timeout=300
    )


@pytest.mark.slow
@pytest.mark.parametrize("limit", [4_000, 12_000])
def test_a_child_whose_files_cannot_grow_exits_2_without_a_crash(tmp_path, limit):
    # Numba's cache must be warm: the child could not write it either.
    warm = subprocess.run(
        [*SHAKERMILL_MAIN, *RUN, "--out", str(tmp_path / "warm")], capture_output=True, text=True, timeout=300
    )
    assert warm.returncode == 0, warm.stderr
    limited = tmp_path / "limited"
    limited.mkdir()
    completed = run_limited([*RUN, "--out", str(limited / "run")], limit, tmp_path)
    # HDF5 writing onto the disk itself crashed at exit here (-11, exit code 139 in a shell).
    assert completed.returncode == 2, completed.stderr
    assert_one_error_line(completed.stderr, "cannot write the run folder", os.strerror(errno.EFBIG))
    assert list(limited.iterdir()) == []


def user_namespace_mounts() -> str | None:
    """Why a tmpfs cannot be mounted for a child here, or None when it can."""
    if shutil.which("unshare") is None:
        return "no unshare command"
    probe = subprocess.run(
        ["unshare", "-rm", "sh", "-c", "mount -t tmpfs -o size=16k tmpfs /mnt"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    if probe.returncode != 0:
        return f"cannot mount a tmpfs in a user namespace here: {probe.stderr.strip() or probe.returncode}"
    return None


def on_small_tmpfs(mount_options: str, args: list[str], mount_point: Path) -> tuple[int, str, list[str]]:
    """Run the command line with a tmpfs of ``mount_options`` at ``mount_point``, seen by the child alone.

    Returns its exit code, its stderr and what the tmpfs holds afterwards (hidden entries included).
    """
    script = textwrap.dedent(
        """\
        mount -t tmpfs -o "$1" tmpfs "$2" || exit 99
        shift 2
        "$@" 2>&1 >/dev/null
        echo "exit code: $?"
        find "$MOUNT_POINT" -mindepth 1 | sort
        """
    )
    completed = subprocess.run(
        ["unshare", "-rm", "sh", "-c", script, "sh", mount_options, str(mount_point), *SHAKERMILL_MAIN, *args],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MOUNT_POINT": str(mount_point)},
    )
    assert completed.returncode != 99, completed.stderr
    output = completed.stdout.splitlines()
    marker = next(index for index, line in enumerate(output) if line.startswith("exit code: "))
    return int(output[marker].removeprefix("exit code: ")), "\n".join(output[:marker]), output[marker + 1 :]


@pytest.fixture
def tmpfs_point(tmp_path):
    reason = user_namespace_mounts()
    if reason is not None:
        pytest.skip(reason)
    point = tmp_path / "mnt"
    point.mkdir()
    return point


@pytest.mark.slow
@pytest.mark.parametrize("size", ["16k", "40k"])
def test_a_run_onto_a_full_tmpfs_exits_2_without_a_crash(tmpfs_point, size):
    code, stderr, left = on_small_tmpfs(f"size={size}", [*RUN, "--out", str(tmpfs_point / "run")], tmpfs_point)
    assert code == 2, stderr
    assert_one_error_line(stderr, "cannot write the run folder", NO_SPACE)
    assert left == []


@pytest.mark.slow
def test_a_sweep_keeping_its_runs_onto_a_full_tmpfs_exits_2_without_a_crash(tmpfs_point):
    code, stderr, left = on_small_tmpfs(
        "size=40k", [*SWEEP, "--keep-runs", "--out", str(tmpfs_point / "sweep")], tmpfs_point
    )
    assert code == 2, stderr
    assert_one_error_line(stderr, "cannot write the sweep", NO_SPACE)
    assert not [path for path in left if "/." in path]  # no hidden partial file or folder


@pytest.mark.slow
@pytest.mark.parametrize(
    "command",
    [RUN, SWEEP, ["bifurcation", "--grid", "omega=100:110:2", *RUN[1:-1]]],
    ids=["run", "sweep", "bifurcation"],
)
def test_a_read_only_disk_is_refused_before_the_work(tmpfs_point, command):
    code, stderr, left = on_small_tmpfs("size=1m,ro", [*command, "--out", str(tmpfs_point / "out")], tmpfs_point)
    assert code == 2, stderr
    assert_one_error_line(stderr, os.strerror(errno.EROFS))
    assert left == []


# Leftovers of killed writes ------------------------------------------------------------------------


def dead_process_id() -> int:
    """The id of a process that has exited and been reaped: no process has it (until it is reused)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


@pytest.mark.slow
def test_a_killed_write_leaves_a_partial_folder_that_the_next_write_removes(tmp_path):
    # The child builds a run folder's hidden partial sibling and is killed while filling it.
    script = textwrap.dedent(
        f"""\
        import os, signal
        from shakermill.io.runs import write_folder

        def killed_midway(folder):
            (folder / "timeseries.nc").write_bytes(b"half a file")
            os.kill(os.getpid(), signal.SIGKILL)

        write_folder({str(tmp_path / "run")!r}, killed_midway)
        """
    )
    killed = subprocess.Popen([sys.executable, "-c", script])
    assert killed.wait(timeout=120) == -signal.SIGKILL
    leftovers = [entry.name for entry in tmp_path.iterdir()]
    assert len(leftovers) == 1 and leftovers[0].startswith(f".run.{PARTIAL}-{this_machine()}-{killed.pid}-")
    outcome = invoke(*RUN, "--out", str(tmp_path / "run"))
    assert outcome.exit_code == 0, outcome.stderr
    assert load_run(tmp_path / "run").success
    assert [entry.name for entry in tmp_path.iterdir()] == ["run"]


def test_only_leftovers_of_gone_processes_on_this_machine_are_removed(tmp_path):
    target = tmp_path / "run"
    gone, alive = dead_process_id(), os.getpid()
    machine = this_machine()
    other_machine = "0" * 8 if machine != "0" * 8 else "1" * 8
    entries = {
        f".run.partial-{machine}-{gone}-00000001": "dead writer here: removed",
        f".run.partial-{machine}-{alive}-00000002": "live writer: kept",
        f".run.partial-{other_machine}-{gone}-00000003": "another machine's writer: kept",
        f".report.html.partial-{machine}-{gone}-00000004": "a dead writer's file: removed",
        f".run.old-{machine}-{gone}-00000005": "set aside while its replacement is missing: kept",
        ".run.partial-not-a-writer": "not our naming: kept",
        ".hidden-by-the-user": "kept",
    }
    for name, text in entries.items():
        folder = tmp_path / name
        folder.mkdir()
        (folder / "content").write_text(text)
    remove_abandoned_writes(tmp_path)
    kept = sorted(entry.name for entry in tmp_path.iterdir())
    assert kept == sorted(name for name, text in entries.items() if "kept" in text)

    target.mkdir()  # the replacement arrived: the old folder set aside is no longer needed
    remove_abandoned_writes(tmp_path)
    assert f".run.old-{machine}-{gone}-00000005" not in {entry.name for entry in tmp_path.iterdir()}


def test_partial_names_record_the_machine_and_the_process(tmp_path):
    name = partial_path(tmp_path / "run").name
    assert name.startswith(f".run.{PARTIAL}-{this_machine()}-{os.getpid()}-")
    assert partial_path(tmp_path / "run") != partial_path(tmp_path / "run")


@pytest.mark.parametrize("hard_links", [True, False], ids=["hard links", "a file system without hard links"])
def test_a_file_created_exclusively_is_created_once(tmp_path, monkeypatch, hard_links):
    if not hard_links:

        def no_links(*_args):
            raise PermissionError(errno.EPERM, os.strerror(errno.EPERM))

        monkeypatch.setattr(os, "link", no_links)
    manifest = tmp_path / "sweep.json"
    create_exclusively(manifest, "the first")
    with pytest.raises(FileExistsError):
        create_exclusively(manifest, "the second")
    assert manifest.read_text() == "the first"
    assert [entry.name for entry in tmp_path.iterdir()] == ["sweep.json"]


@pytest.mark.skipif(not Path("/proc/sys").is_dir(), reason="needs /proc/sys (Linux), a folder no file can be made in")
def test_a_place_that_refuses_files_is_found_before_the_work_even_as_root(tmp_path):
    """Issue 35: `validate --report` into such a path was refused only after the study had run; permissions say
    nothing to root, so a file is made (and removed) where the output would go."""
    from shakermill.support.atomic import StorageError, check_writable_place

    with pytest.raises(
        StorageError, match=r"^/proc/sys/report\.html: cannot write in /proc/sys \(.+\); choose another --report$"
    ):
        check_writable_place(Path("/proc/sys/report.html"), "--report")
    check_writable_place(tmp_path / "new" / "report.html", "--report")
    assert list(tmp_path.iterdir()) == []
