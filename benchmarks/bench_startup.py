"""Start-up of the command line, timed as whole processes (what a user waits for).

Prints the median and range over ``--repeats`` runs (at least 5) of

* ``shakermill --help``,
* ``shakermill run --set solver=averaged --no-plots`` (60 simulated minutes), with the default probe of
  8 starts for coexisting attractors and with ``attractor_starts=1`` (the solver alone),
* ``shakermill plot RUN_DIR`` of that run folder (the figures),

each with Numba's cache warm (one untimed run first). Run by hand; figures go into benchmarks/README.md.
Targets: --help ≤ 0.5 s, the averaged run ≤ 1.5 s.
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SHAKERMILL = Path(sys.executable).parent / "shakermill"
RUN = ["run", "--set", "solver=averaged", "--no-plots"]  # the preset runs 60 min


def timed(arguments: list[str], repeats: int, out: Path | None = None) -> list[float]:
    """Wall times of ``shakermill ARGUMENTS`` as a process, each checked to succeed; with ``out``, each
    repetition writes a fresh folder inside it (--out onto an earlier run is refused)."""
    times = []
    for repetition in range(repeats):
        target = [] if out is None else ["--out", str(out / f"{repetition}")]
        started = time.perf_counter()
        subprocess.run([str(SHAKERMILL), *arguments, *target], check=True, capture_output=True)
        times.append(time.perf_counter() - started)
    return times


def report(label: str, times: list[float]) -> None:
    print(f"{label:<48} median {statistics.median(times):6.3f} s   range {min(times):.3f}–{max(times):.3f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7, help="runs per timing (median), at least 5")
    args = parser.parse_args()
    repeats = max(args.repeats, 5)
    folder = Path(tempfile.mkdtemp(prefix="bench-startup-"))
    try:
        timed(RUN, 1, folder / "warm")  # Numba's cache and the OS's file cache warm
        report("shakermill --help", timed(["--help"], repeats))
        report("run, averaged, 60 min, --no-plots", timed(RUN, repeats, folder / "probed"))
        single = [*RUN, "--set", "attractor_starts=1"]
        report("run, averaged, 60 min, --no-plots, attractor_starts=1", timed(single, repeats, folder / "single"))
        report("plot RUN_DIR", timed(["plot", str(folder / "warm" / "0")], repeats))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
