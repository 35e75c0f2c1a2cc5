"""The averaged (multiscale) solver against full resolution over the operating range.

Runs the default preset and operating points spanning ω 90–130 rad/s and amplitude 15–30 mm, 60
simulated minutes each, with both solvers; prints θ∞, τ, the steady state and final temperatures side
by side, the differences, and the speed ratio: of the averaged solver alone (``attractor_starts = 1``)
and with its default probe of 8 starts for coexisting attractors. Run by hand; figures go into
benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import statistics
import time

import shakermill as sm

NUDGE_SPEED = 1.0  # m/s, initial ball speed
OPERATING_POINTS = [  # (omega rad/s, amplitude m)
    (111.0, 25e-3),
    (90.0, 15e-3),
    (90.0, 30e-3),
    (100.0, 20e-3),
    (105.0, 27e-3),
    (120.0, 25e-3),
    (125.0, 22e-3),
    (130.0, 15e-3),
    (130.0, 30e-3),
]


def _timed(params: sm.Parameters, repeats: int) -> tuple[sm.Result, float]:
    times, result = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        result = sm.simulate(params)
        times.append(time.perf_counter() - started)
    return result, statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3, help="repetitions of each timing (median)")
    args = parser.parse_args()
    sm.simulate(sm.default_parameters(duration=1.0, solver="averaged"))  # compile or load the cache
    header = (
        f"{'omega':>6} {'X mm':>5} | {'θ∞ full':>8} {'Δθ∞ %':>7} | {'τ full':>7} {'Δτ %':>7} | {'Δsteady K':>9} | "
        f"{'max ΔT K':>8} | {'full s':>6} {'avg s':>6} {'ratio':>6} {'+probe s':>8} {'ratio':>6} | averaging"
    )
    print(header)
    print("-" * len(header))
    ratios, probed_ratios = [], []
    for omega, amplitude in OPERATING_POINTS:
        # A nudge so that the ball meets the walls when the amplitude is smaller than the free gap
        # (22.65 mm): in one dimension a ball at rest at the centre is otherwise never hit.
        base = sm.default_parameters(omega=omega, amplitude=amplitude)
        base = base.replace(ball_momentum=base.ball_mass * NUDGE_SPEED)
        full, full_time = _timed(base, 1)
        averaged, averaged_time = _timed(base.replace(solver="averaged", attractor_starts=1), args.repeats)
        _, probed_time = _timed(base.replace(solver="averaged"), args.repeats)
        f, a = full.summary, averaged.summary
        d_inf = 100 * (a.theta_inf_C - f.theta_inf_C) / (f.theta_inf_C - 20.0)
        d_tau = 100 * (a.tau_min / f.tau_min - 1)
        d_steady = a.ball_steady_C - f.ball_steady_C
        d_temp = max(abs(a.value(key) - f.value(key)) for key in ("ball_C", "vial_C", "air_C"))
        ratios.append(full_time / averaged_time)
        probed_ratios.append(full_time / probed_time)
        note = (
            "fell back to full resolution"
            if averaged.solver == "full"
            else a.averaging.message
            if a.averaging is not None
            else "no averaging"
        )
        print(
            f"{omega:6.0f} {amplitude * 1e3:5.0f} | {f.theta_inf_C:8.2f} {d_inf:7.3f} | {f.tau_min:7.2f} "
            f"{d_tau:7.3f} | "
            f"{d_steady:9.3f} | {d_temp:8.3f} | {full_time:6.2f} {averaged_time:6.3f} {ratios[-1]:6.0f} "
            f"{probed_time:8.3f} {probed_ratios[-1]:6.0f} | {note}"
        )
    print(
        f"speed ratio full/averaged: median {statistics.median(ratios):.0f}x for the solver alone, "
        f"{statistics.median(probed_ratios):.0f}x with the attractor probe"
    )
    print("Δθ∞ is relative to the rise θ∞ − 20 °C; Δτ relative to τ; ΔT is the largest final-temperature difference.")


if __name__ == "__main__":
    main()
