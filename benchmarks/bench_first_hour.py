"""What a newcomer waits for, timed as whole processes with Numba's cache warm (issue "A newcomer's first hour").

Prints, each as the median and range over ``--repeats`` runs:

* the short runs of the README: a 10-s ``mm400`` run at 15 Hz and a 1-s ``spex8000m-3d`` run, each with the
  preset's averaged solver (which now runs them at full resolution from the start) and with ``solver=full``, and
  their ratio (target ≤ 1.5);
* Ctrl-C: the wall time from SIGINT to the exit of a 1-D and a 3-D run at full resolution, figures asked for, and the
  CPU time the process spent after the signal (target ≤ 1 s).

Run by hand on a quiet machine; the figures go into benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SHAKERMILL = Path(sys.executable).parent / "shakermill"
SHORT_RUNS = {
    "mm400, 10 s at 15 Hz": ["--preset", "mm400", "--set", "duration=10", "--set", "omega=15 Hz"],
    "spex8000m-3d, 1 s": ["--preset", "spex8000m-3d", "--set", "duration=1"],
}
INTERRUPTED_RUNS = {
    "1-D, full, 600 min asked": ["--set", "solver=full", "--set", "duration=600 min"],
    "3-D, full, 60 s asked": ["--preset", "spex8000m-3d", "--set", "solver=full", "--set", "duration=60"],
}
# Seconds from the start of an interrupted run to its Ctrl-C: past the start-up, inside the engine's loop.
INTERRUPT_AFTER_S = 6.0


def run_time(arguments: list[str], out: Path) -> float:
    started = time.perf_counter()
    subprocess.run(
        [str(SHAKERMILL), "run", *arguments, "--no-plots", "--out", str(out)], check=True, capture_output=True
    )
    return time.perf_counter() - started


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def interrupt(arguments: list[str], out: Path) -> tuple[float, float]:
    """Wall and CPU seconds from a SIGINT to the exit of ``shakermill run ARGUMENTS``."""
    process = subprocess.Popen(
        [str(SHAKERMILL), "run", *arguments, "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    time.sleep(INTERRUPT_AFTER_S)
    used = cpu_seconds(process.pid)
    signalled = time.perf_counter()
    process.send_signal(signal.SIGINT)
    _, status, usage = os.wait4(process.pid, 0)
    if os.waitstatus_to_exitcode(status) != 130:
        raise SystemExit(f"{arguments}: exit code {os.waitstatus_to_exitcode(status)}, not 130")
    return time.perf_counter() - signalled, usage.ru_utime + usage.ru_stime - used


def spread(values: list[float]) -> str:
    return f"median {statistics.median(values):6.2f} s   range {min(values):.2f}–{max(values):.2f} s"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3, help="runs per timing (median), at least 3")
    repeats = max(parser.parse_args().repeats, 3)
    folder = Path(tempfile.mkdtemp(prefix="bench-first-hour-"))
    try:
        for label, arguments in SHORT_RUNS.items():
            run_time([*arguments, "--set", "solver=full"], folder / f"warm-{len(label)}")  # Numba's cache warm
            preset = [run_time(arguments, folder / f"preset-{label}-{index}") for index in range(repeats)]
            full = [
                run_time([*arguments, "--set", "solver=full"], folder / f"full-{label}-{index}")
                for index in range(repeats)
            ]
            print(f"{label:<28} preset's solver {spread(preset)}")
            print(f"{'':<28} solver=full     {spread(full)}")
            print(f"{'':<28} ratio of medians {statistics.median(preset) / statistics.median(full):.2f} (target ≤ 1.5)")
        for label, arguments in INTERRUPTED_RUNS.items():
            timings = [interrupt(arguments, folder / f"ctrl-c-{len(label)}-{index}") for index in range(repeats)]
            print(f"Ctrl-C, {label:<26} wall {spread([wall for wall, _ in timings])}")
            print(f"{'':<34} CPU  {spread([cpu for _, cpu in timings])}   (target ≤ 1 s)")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
