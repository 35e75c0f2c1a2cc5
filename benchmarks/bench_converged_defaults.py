"""Is the default tolerance converged? Default runs against converged ones over the operating range.

Grid: ω 90–130 rad/s × amplitude 23–30 mm, 20 simulated s from the default start (at rest at the
centre), record windows off. Each point runs at the default rtol 1e-3 and at the converged
references rtol 1e-5 and 1e-6 (absolute tolerances lowered with rtol, so that the references do not
rest on them). A point counts where the two references agree with each other (heat power within
1 %, impact rate within 3 %); it passes where the default run is within the same margins of the
rtol 1e-6 reference. ``--study`` adds the tolerance study of benchmarks/README.md ("Accuracy against
tolerance") and checks the references against tighter runs at two points.

Run by hand; the figures go into benchmarks/README.md. Runs are deterministic, and the process pool
returns them in grid order, so the table does not depend on the number of workers.
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import shakermill as sm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from conftest import single_impact_parameters  # noqa: E402  (the tests' set-up of one impact)

OMEGAS = np.arange(90, 131, 5, dtype=float)  # rad/s
AMPLITUDES = np.arange(23, 31) * 1e-3  # m
DEFAULT_RTOL = sm.default_parameters().rtol
REFERENCE_RTOLS = (1e-5, 1e-6)
HEAT_MARGIN = 0.01
RATE_MARGIN = 0.03
DURATION = 20.0  # s
TIGHTER_CHECK = ((90.0, 25e-3), (120.0, 25e-3))  # (ω, amplitude): references against rtol 1e-7, 1e-8


def _run(omega: float, amplitude: float, rtol: float) -> tuple[float, float, float]:
    """(heat power W, impact rate Hz, wall s) of one run from the default start."""
    base = sm.default_parameters()
    # The default absolute tolerances belong to the default rtol; scale them with rtol.
    shrink = min(1.0, rtol / DEFAULT_RTOL)
    params = base.replace(
        omega=omega,
        amplitude=amplitude,
        duration=DURATION,
        rtol=rtol,
        atol_position=base.atol_position * shrink,
        atol_momentum=base.atol_momentum * shrink,
        atol_temperature=base.atol_temperature * shrink,
        record_windows=(),
        output_interval=1.0,
    )
    started = time.perf_counter()
    result = sm.simulate(params)
    wall = time.perf_counter() - started
    if not result.success:
        raise RuntimeError(f"ω={omega} X={amplitude} rtol={rtol}: {result.message}")
    return result.summary.heat_power_W, result.summary.impacts.rate_hz, wall


def _point(point: tuple[float, float]) -> list[tuple[float, float, float]]:
    omega, amplitude = point
    return [_run(omega, amplitude, rtol) for rtol in (DEFAULT_RTOL, *REFERENCE_RTOLS)]


def _within(value: tuple[float, float], reference: tuple[float, float]) -> bool:
    return abs(value[0] / reference[0] - 1) <= HEAT_MARGIN and abs(value[1] / reference[1] - 1) <= RATE_MARGIN


def grid(workers: int) -> None:
    points = [(float(omega), float(amplitude)) for omega in OMEGAS for amplitude in AMPLITUDES]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        runs = list(pool.map(_point, points))
    header = (
        f"{'omega':>5} {'X mm':>4} | {'heat 1e-3':>9} {'1e-5':>7} {'1e-6':>7} | {'rate 1e-3':>9} {'1e-5':>6} "
        f"{'1e-6':>6} | "
        f"{'dheat %':>7} {'drate %':>7} | verdict"
    )
    print(header)
    print("-" * len(header))
    counted = passed = 0
    for (omega, amplitude), (default, loose, tight) in zip(points, runs):
        agree = _within(loose[:2], tight[:2])
        ok = _within(default[:2], tight[:2])
        counted += agree
        passed += agree and ok
        verdict = ("pass" if ok else "FAIL") if agree else "references disagree: not counted"
        print(
            f"{omega:5.0f} {1e3 * amplitude:4.0f} | {default[0]:9.4f} {loose[0]:7.4f} {tight[0]:7.4f} | "
            f"{default[1]:9.2f} {loose[1]:6.2f} {tight[1]:6.2f} | "
            f"{100 * (default[0] / tight[0] - 1):+7.2f} {100 * (default[1] / tight[1] - 1):+7.2f} | {verdict}"
        )
    walls = np.array([[run[2] for run in point] for point in runs])
    print(
        f"verdict: {counted} of {len(points)} points counted (references agree), {passed} of {counted} pass "
        f"(default within {100 * HEAT_MARGIN:g} % heat, {100 * RATE_MARGIN:g} % rate)"
    )
    print(
        f"wall time per {DURATION:g} s run, mean over the grid: "
        + ", ".join(
            f"rtol {rtol:g} {wall:.3f} s" for rtol, wall in zip((DEFAULT_RTOL, *REFERENCE_RTOLS), walls.mean(axis=0))
        )
    )


def _worst_restitution_error(rtol: float) -> float:
    worst = 0.0
    for restitution in (0.5, 0.7, 0.9):
        for speed in (0.1, 1.0, 5.0):
            impact = sm.simulate(single_impact_parameters(speed, restitution, rtol=rtol)).impacts.iloc[0]
            worst = max(worst, abs(impact["rebound_speed"] / impact["impact_speed"] - restitution))
    return worst


def study() -> None:
    """The README's table: 60 simulated s of the default preset at the default atol, and single impacts."""
    print(
        "\nrtol  | heat W  | rate Hz | projection/dissipated | steps/impact | s per sim. hour | worst restitution error"
    )
    base = sm.default_parameters(duration=60.0, record_windows=())
    for rtol in (1e-3, 1e-4, 1e-5, 1e-6):
        started = time.perf_counter()
        summary = sm.simulate(base.replace(rtol=rtol)).summary
        wall = time.perf_counter() - started
        print(
            f"{rtol:5.0e} | {summary.heat_power_W:.4f} | {summary.impacts.rate_hz:7.2f} | "
            f"{summary.energy_projection_relative:21.1e} | {summary.steps / summary.impacts.count:12.1f} | "
            f"{60 * wall:15.1f} | {_worst_restitution_error(rtol):.1e}"
        )
    print("\nreferences against tighter runs (20 s from the default start):")
    for omega, amplitude in TIGHTER_CHECK:
        print(f"  ω {omega:g} rad/s, X {1e3 * amplitude:g} mm:")
        for rtol in (*REFERENCE_RTOLS, 1e-7, 1e-8):
            heat, rate, wall = _run(omega, amplitude, rtol)
            print(f"    rtol {rtol:5.0e}: {heat:.5f} W, {rate:.2f} Hz ({wall:.2f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--workers", type=int, default=2, help="processes for the grid")
    parser.add_argument("--study", action="store_true", help="also the tolerance study and the tighter check")
    args = parser.parse_args()
    sm.simulate(sm.default_parameters(duration=1.0))  # compile or load the cache before the workers start
    grid(args.workers)
    if args.study:
        study()


if __name__ == "__main__":
    main()
