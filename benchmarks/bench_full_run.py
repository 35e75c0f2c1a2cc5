"""Speed of the default 60-minute run, cold and warm, and of the solve_ivp cross-check path.

Run by hand (`make bench`); the figures go into benchmarks/README.md. Timings on shared machines are
noisy, so every figure is a median of several repetitions and the comparison is a ratio.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import shakermill as sm
from shakermill.engines.one_d.reference import simulate_scipy

_COLD_START = """
import time
started = time.perf_counter()
import shakermill as sm
result = sm.simulate(sm.default_parameters(duration=1.0))
print(time.perf_counter() - started)
"""


def _fresh_process_seconds(cache_dir: str) -> float:
    environment = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    output = subprocess.run(
        [sys.executable, "-c", _COLD_START], env=environment, capture_output=True, text=True, check=True
    )
    return float(output.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3, help="repetitions of each warm measurement")
    parser.add_argument("--scipy-horizon", type=float, default=10.0, help="simulated seconds for the ratio")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as cache_dir:
        compile_run = _fresh_process_seconds(cache_dir)
        cached_run = _fresh_process_seconds(cache_dir)
    print(f"cold start, empty Numba cache (import + JIT compile + 1 s run): {compile_run:6.2f} s")
    print(f"cold start, Numba cache on disk (import + load + 1 s run):      {cached_run:6.2f} s")

    params = sm.default_parameters()
    sm.simulate(params.replace(duration=1.0))  # compile or load before timing
    times, result = [], None
    for _ in range(args.repeats):
        started = time.perf_counter()
        result = sm.simulate(params)
        times.append(time.perf_counter() - started)
    median = statistics.median(times)
    summary = result.summary
    print(
        f"default 60-min run, warm: median {median:.2f} s over {args.repeats} "
        f"(min {min(times):.2f}, max {max(times):.2f}); {summary.impacts.count} impacts, {summary.steps} steps, "
        f"{summary.rhs_evaluations} RHS evaluations ({1e9 * median / summary.rhs_evaluations:.0f} ns each, all "
        "included)"
    )
    paper_seconds = 41.3 * 60
    print(f"paper's MATLAB ode23 run of the same 60 min: {paper_seconds:.0f} s -> {paper_seconds / median:.0f}x faster")

    horizon = params.replace(duration=args.scipy_horizon, record_windows=())
    compiled = [sm.simulate(horizon).wall_time for _ in range(args.repeats)]
    reference = simulate_scipy(horizon)
    compiled_median = statistics.median(compiled)
    print(
        f"same {args.scipy_horizon:g} simulated s: compiled {compiled_median:.3f} s, solve_ivp(RK23) "
        f"{reference.wall_time:.2f} s -> ratio {reference.wall_time / compiled_median:.0f}x"
    )


if __name__ == "__main__":
    main()
