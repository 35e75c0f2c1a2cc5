"""Speed and convergence of the 'dem' engine: several balls in three dimensions (MODEL.md section 12).

1. Five balls (vial 38 mm across, friction 0.3, gravity on), 60 simulated s at full resolution.
2. The same five balls, averaged solver, one simulated hour, and the mechanics window it needed.
3. Cost per simulated second against the number of balls.
4. Convergence in the contact step (``contact_step_fraction``): restitution of single impacts, the 1-D
   limit's heat power against the 1-D engine, a five-ball run against the finest step; and the 1-D
   limit against ``max_flight_step``; with ``--means``, the five balls' means converged by the averaged
   solver's mechanics phase (±0.4 %) at each step.
5. The 1-D limit (one ball, no gravity, no friction, convection from the ball's own speed) against the
   1-D engine at several ω.

Times are wall and CPU seconds of this process (the engine runs on one thread, so on an idle machine
they agree; on a shared one the CPU time is the steadier figure). Run by hand; the figures go into
benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

import shakermill as sm
from shakermill.engines.dem import model, stepper
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.status import REACHED_STOP
from shakermill.solvers.impact import single_impact

T = TypeVar("T")

FIVE_BALLS = {"engine": "dem", "n_balls": 5, "vial_diameter": "38 mm"}
# The 1-D engine's model in the 'dem' engine: the drive is axial by default, the ball starts on the axis.
ONE_D_LIMIT = {"engine": "dem", "gravity": False, "friction": 0.0, "convection_velocity": "ball"}
TIGHT_1D = {"engine": "1d", "rtol": 1e-6, "atol_position": 1e-9, "atol_momentum": 1e-9}
IMPACT_SPEEDS = (1.0, 5.0)  # m/s, head-on on the resting end face
FLIGHT_STEPS = (2e-4, 1e-4, 5e-5)  # s
LIMIT_OMEGA = 111.0  # rad/s, the default
OMEGAS = (90.0, 111.0, 130.0)  # rad/s
HEAT_TARGET = 0.01  # the 1-D limit's heat power within 1 % of the 1-D engine's
RATE_TARGET = 0.02  # and its impact rate within 2 %
FULL_TARGET = 60.0  # s of wall time for the five balls' 60 simulated s
AVERAGED_TARGET = 90.0  # s for the averaged hour
# Runs that take longer are timed once: the benchmark should end in minutes on a shared 2-core machine.
CHEAP_SECONDS = 5.0


@dataclass(frozen=True)
class Plan:
    """How much to run: the full benchmark or the ``--quick`` one."""

    full_seconds: float  # simulated s of item 1
    averaged: bool  # item 2 (its mechanics window is not shortened: it runs until the means converge)
    ball_counts: dict[int, float]  # item 3: simulated s for each number of balls
    fractions: tuple[float, ...]  # contact_step_fraction values of item 4, the finest last
    limit_seconds: float  # simulated s of the 1-D limit runs (items 4 and 5)
    five_ball_seconds: int  # simulated s of item 4's five-ball runs, in 1-s batches


# Twenty balls of 6.35 mm in the 38 mm x 58 mm vial are jammed (~30 lasting contacts, ~2 min of CPU per
# simulated s), so they get less simulated time; their rates per simulated second hold from 0.5 s on.
FULL = Plan(60.0, True, {1: 5.0, 2: 5.0, 5: 5.0, 10: 2.0, 20: 0.5}, (0.2, 0.1, 0.05, 0.02, 0.01), 20.0, 10)
QUICK = Plan(5.0, False, {1: 1.0, 2: 1.0, 5: 1.0, 10: 0.5}, (0.2, 0.05, 0.01), 5.0, 3)


@dataclass(frozen=True)
class Timing:
    """Wall and CPU seconds of repeated runs."""

    wall: list[float]
    cpu: list[float]

    @property
    def median(self) -> float:
        return statistics.median(self.wall)

    @property
    def cpu_median(self) -> float:
        return statistics.median(self.cpu)

    def __str__(self) -> str:
        spread = f" ({min(self.wall):.2f}-{max(self.wall):.2f})" if len(self.wall) > 1 else ""
        runs = f"median of {len(self.wall)}" if len(self.wall) > 1 else "1 run"
        return f"{self.median:.2f} s wall{spread}, {self.cpu_median:.2f} s CPU, {runs}"


def timed(run: Callable[[], T], repeats: int) -> tuple[T, Timing]:
    """``run()`` and its timing: a median of ``repeats`` runs if the first took under CHEAP_SECONDS of CPU."""
    walls, cpus = [], []
    while len(walls) < (1 if cpus and cpus[0] >= CHEAP_SECONDS else repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        result = run()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return result, Timing(walls, cpus)


def repeat_note(repeats: int) -> str:
    return f"times: medians of {repeats} where a run takes under {CHEAP_SECONDS:g} s of CPU, else one run"


def simulate(**keys: object) -> sm.Result:
    result = sm.simulate(sm.default_parameters(**keys))
    if not result.success:
        raise RuntimeError(f"{keys}: {result.message}")
    return result


def percent(value: float, reference: float) -> float:
    return 100.0 * (value / reference - 1.0)


def verdict(timing: Timing, scale: float, target: float) -> str:
    """Whether ``scale`` times the run's wall and CPU time meet ``target`` (s): the CPU time is what an idle machine's
    wall time would be."""
    times = (("wall", timing.median), ("CPU", timing.cpu_median))
    return ", ".join(f"{name} {'met' if scale * value <= target else 'MISSED'}" for name, value in times)


def heading(text: str) -> None:
    print(f"\n{text}\n{'=' * len(text)}")


def table(header: str) -> None:
    print(header)
    print("-" * len(header))


def full_run(plan: Plan) -> None:
    heading(
        f"1. Five balls, {plan.full_seconds:g} simulated s at full resolution (vial 38 mm, friction 0.3, gravity on)"
    )
    result, timing = timed(lambda: simulate(**FIVE_BALLS, duration=plan.full_seconds), 1)
    c, s = result.counters, result.summary
    scale = 60.0 / plan.full_seconds
    scaled = f" (scaled to 60 s: {scale * timing.median:.1f} s wall, {scale * timing.cpu_median:.1f} s CPU)"
    scaled = "" if scale == 1.0 else scaled
    print(f"time: {timing}{scaled}; target <= {FULL_TARGET:g} s: {verdict(timing, scale, FULL_TARGET)}")
    print(
        f"steps {c['steps']:,} (contact {c['contact_steps']:,}, flight {c['flight_steps']:,}), impacts "
        f"{c['impacts']:,}; "
        f"{c['steps'] / timing.median:,.0f} steps per wall second, {c['steps'] / timing.cpu_median:,.0f} per "
        "CPU second "
        f"({1e6 * timing.cpu_median / c['steps']:.2f} µs a step)"
    )
    print(f"heat power {s.heat_power_W:.3f} W, impact rate {s.impacts.rate_hz:.1f} Hz (transient included)")


def averaged_run() -> None:
    heading("2. Five balls, averaged solver, 3600 simulated s")
    result, timing = timed(lambda: simulate(**FIVE_BALLS, solver="averaged"), 1)
    a, s = result.averages, result.summary
    print(f"time: {timing}; target <= {AVERAGED_TARGET:g} s: {verdict(timing, 1.0, AVERAGED_TARGET)}")
    print(
        f"mechanics: {a.transient + a.window:.1f} simulated s ({a.transient:.1f} s transient cut, a window of "
        f"{a.batches} "
        f"batches = {a.window:.1f} s), {result.counters['steps']:,} steps; {a.message}"
    )
    print(f"heat power {s.heat_power_W:.3f} ± {a.heat_power_stderr:.3f} W, θ∞ {s.theta_inf_C:.1f} °C")


def ball_counts(plan: Plan, repeats: int) -> None:
    heading("3. Cost per simulated second against the number of balls (vial 38 mm x 58 mm, defaults)")
    table(
        f"{'N':>3} {'sim s':>5} | {'wall s':>7} {'CPU s':>7} | {'wall/sim s':>10} {'CPU/sim s':>9} | "
        f"{'steps/sim s':>11} {'contact %':>9} {'impacts/sim s':>13} | {'µs/step':>7}"
    )
    for n, seconds in plan.ball_counts.items():
        result, timing = timed(
            lambda n=n, seconds=seconds: simulate(**{**FIVE_BALLS, "n_balls": n}, duration=seconds), repeats
        )
        c = result.counters
        print(
            f"{n:3d} {seconds:5g} | {timing.median:7.2f} {timing.cpu_median:7.2f} | {timing.median / seconds:10.3f} "
            f"{timing.cpu_median / seconds:9.3f} | {c['steps'] / seconds:11,.0f} "
            f"{100 * c['contact_steps'] / c['steps']:9.1f} "
            f"{c['impacts'] / seconds:13,.0f} | {1e6 * timing.cpu_median / c['steps']:7.2f}"
        )
    print(repeat_note(repeats))


def restitution_errors(plan: Plan) -> None:
    print("\n(a) head-on steel impacts on the resting end face: |e measured - e|")
    table(f"{'fraction':>8} | " + " | ".join(f"{speed:g} m/s".rjust(9) for speed in IMPACT_SPEEDS))
    for fraction in plan.fractions:
        params = sm.default_parameters(engine="dem", contact_step_fraction=fraction)
        errors = [abs(single_impact(params, speed).normal_restitution - params.restitution) for speed in IMPACT_SPEEDS]
        print(f"{fraction:8g} | " + " | ".join(f"{error:9.1e}" for error in errors))


def limit_run(seconds: float, repeats: int, **keys: object) -> tuple[sm.Result, Timing]:
    return timed(lambda: simulate(**ONE_D_LIMIT, omega=LIMIT_OMEGA, duration=seconds, **keys), repeats)


def settled_heat(result: sm.Result) -> float:
    """Heat power (W) of the impacts in the run's second half. The start from rest is sensitive to the step
    (at 111 rad/s the first second has 47 impacts at fraction 0.05, 39 at 0.02 and 0.01); the settled motion is not."""
    impacts = result.impact_columns
    later = impacts["time"] >= 0.5 * result.t_end
    return float(impacts["heat_generated"][later].sum()) / (0.5 * result.t_end)


def limit_convergence(plan: Plan, repeats: int) -> None:
    reference = simulate(**TIGHT_1D, omega=LIMIT_OMEGA, duration=plan.limit_seconds)
    whole, half = reference.summary.heat_power_W, settled_heat(reference)
    print(
        f"\n(b) the 1-D limit (one ball, ω {LIMIT_OMEGA:g} rad/s, {plan.limit_seconds:g} s, no gravity, no friction, "
        f"convection_velocity = 'ball'): heat power over the whole run and its second half; "
        f"1-D engine at rtol 1e-6: {whole:.5f} W and {half:.5f} W"
    )
    table(
        f"{'fraction':>8} | {'heat W':>8} {'vs 1-D %':>9} {'vs finest %':>11} | "
        f"{'2nd half W':>10} {'vs 1-D %':>9} {'vs finest %':>11} | "
        f"{'rate Hz':>7} | {'wall s':>6} {'CPU s':>6}"
    )
    runs = [limit_run(plan.limit_seconds, repeats, contact_step_fraction=fraction) for fraction in plan.fractions]
    finest = runs[-1][0]
    for fraction, (result, timing) in zip(plan.fractions, runs):
        heat, later = result.summary.heat_power_W, settled_heat(result)
        print(
            f"{fraction:8g} | {heat:8.5f} {percent(heat, whole):+9.3f} "
            f"{percent(heat, finest.summary.heat_power_W):+11.3f} | "
            f"{later:10.5f} {percent(later, half):+9.3f} {percent(later, settled_heat(finest)):+11.3f} | "
            f"{result.summary.impacts.rate_hz:7.2f} | {timing.median:6.2f} {timing.cpu_median:6.2f}"
        )
    print(repeat_note(repeats))


@dataclass(frozen=True)
class Batches:
    """A five-ball run in 1-s batches: heat generated (J) and impacts of each, and the wall and CPU time to each end."""

    heat: np.ndarray
    impacts: np.ndarray
    wall: np.ndarray
    cpu: np.ndarray

    def relative_errors(self, count: int) -> np.ndarray:
        """Standard errors (%) of the heat power and impact rate over the first ``count`` batches."""
        values = np.array([self.heat[:count], self.impacts[:count]])
        return 100.0 * values.std(axis=1, ddof=1) / np.sqrt(count) / values.mean(axis=1)

    def rates(self, first: int, last: int) -> tuple[float, float]:
        """Heat power (W) and impact rate (Hz) over batches ``first`` to ``last`` (exclusive)."""
        return float(self.heat[first:last].mean()), float(self.impacts[first:last].mean())


def five_ball_batches(fraction: float, seconds: int) -> Batches:
    engine = DemEngine(sm.default_parameters(**FIVE_BALLS, contact_step_fraction=fraction))
    totals, walls, cpus = [(0.0, 0)], [], []
    wall, cpu = time.perf_counter(), time.process_time()
    for second in range(1, seconds + 1):
        status = engine.advance(float(second))
        if status != REACHED_STOP:
            raise RuntimeError(f"contact_step_fraction {fraction}: {engine.explain(status)}")
        totals.append((engine.state.totals[model.HEAT_GENERATED], engine.stepper_counters[stepper.IMPACTS]))
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    heat, impacts = np.diff(np.array(totals), axis=0).T
    return Batches(heat, impacts, np.array(walls), np.array(cpus))


def five_ball_convergence(plan: Plan) -> None:
    seconds = plan.five_ball_seconds
    default = sm.default_parameters(engine="dem").contact_step_fraction
    # The default's run goes on for a second stretch as long: the spread between the two is the scale of
    # the statistics, against which the chaotic motion's differences between step sizes are to be read.
    runs = {f: five_ball_batches(f, 2 * seconds if f == default else seconds) for f in plan.fractions}
    heat_ref, rate_ref = runs[plan.fractions[-1]].rates(0, seconds)
    print(f"\n(c) five balls, {seconds} simulated s (defaults otherwise), against the finest fraction")
    table(
        f"{'fraction':>8} | {'heat W':>7} {'vs finest %':>11} {'±SE %':>6} | {'rate Hz':>7} "
        f"{'vs finest %':>11} {'±SE %':>6} | "
        f"{'wall s':>6} {'CPU s':>6} {'60 s est. CPU':>13}"
    )
    errors = {fraction: run.relative_errors(seconds) for fraction, run in runs.items()}
    for fraction, run in runs.items():
        heat, rate = run.rates(0, seconds)
        cpu = run.cpu[seconds - 1]
        print(
            f"{fraction:8g} | {heat:7.3f} {percent(heat, heat_ref):+11.2f} {errors[fraction][0]:6.2f} | {rate:7.1f} "
            f"{percent(rate, rate_ref):+11.2f} {errors[fraction][1]:6.2f} | "
            f"{run.wall[seconds - 1]:6.2f} {cpu:6.2f} {60.0 * cpu / seconds:13.1f}"
        )
    first, second = runs[default].rates(0, seconds), runs[default].rates(seconds, 2 * seconds)
    print(
        f"statistical scale, fraction {default:g}: seconds {seconds}-{2 * seconds} against 0-{seconds}: heat "
        f"{percent(second[0], first[0]):+.2f} %, impact rate {percent(second[1], first[1]):+.2f} %"
    )
    # Every row is compared with the same finest run, so its own fluctuation moves all the differences alike.
    difference = np.hypot(errors[default], errors[plan.fractions[-1]])
    print(
        f"±SE: standard error of a run's mean from its 1-s batches (the first second's transient included); "
        f"the difference default - finest has ±{difference[0]:.2f} % (heat), ±{difference[1]:.2f} % (rate)"
    )


def flight_step_convergence(plan: Plan, repeats: int) -> None:
    print(f"\n(e) the 1-D limit against max_flight_step (default contact step, {plan.limit_seconds:g} s)")
    table(
        f"{'max_flight_step s':>17} | {'heat W':>8} {'vs 1e-4 %':>9} {'2nd half %':>10} | {'rate Hz':>7} | "
        f"{'wall s':>6} {'CPU s':>6}"
    )
    runs = {step: limit_run(plan.limit_seconds, repeats, max_flight_step=step) for step in FLIGHT_STEPS}
    reference = runs[sm.default_parameters(engine="dem").max_flight_step][0]
    for step, (result, timing) in runs.items():
        heat = result.summary.heat_power_W
        print(
            f"{step:17g} | {heat:8.5f} {percent(heat, reference.summary.heat_power_W):+9.4f} "
            f"{percent(settled_heat(result), settled_heat(reference)):+10.4f} | "
            f"{result.summary.impacts.rate_hz:7.2f} | "
            f"{timing.median:6.2f} {timing.cpu_median:6.2f}"
        )


def converged_means(plan: Plan) -> None:
    print("\n(f) five balls: the averaged solver's converged means (its mechanics phase) against the fraction")
    table(
        f"{'fraction':>8} | {'heat W':>7} {'±SE W':>6} {'vs finest %':>11} {'±σ %':>5} | {'rate Hz':>7} "
        f"{'vs finest %':>11} | "
        f"{'mechanics s':>11} | {'wall s':>6} {'CPU s':>6}"
    )
    runs = {
        f: timed(lambda f=f: simulate(**FIVE_BALLS, solver="averaged", contact_step_fraction=f), 1)
        for f in plan.fractions
    }
    finest, _ = runs[plan.fractions[-1]]
    for fraction, (result, timing) in runs.items():
        a, rate, reference = result.averages, result.summary.impacts.rate_hz, finest.averages
        sigma = 100 * np.hypot(a.heat_power_stderr, reference.heat_power_stderr) / reference.heat_power
        print(
            f"{fraction:8g} | {a.heat_power:7.3f} {a.heat_power_stderr:6.3f} "
            f"{percent(a.heat_power, reference.heat_power):+11.2f} "
            f"{sigma:5.2f} | {rate:7.1f} {percent(rate, finest.summary.impacts.rate_hz):+11.2f} | "
            f"{a.transient + a.window:11.1f} | {timing.median:6.2f} {timing.cpu_median:6.2f}"
        )
    print("±σ: standard error of the difference from the finest fraction")


def tolerance_study(plan: Plan, repeats: int, means: bool) -> None:
    heading("4. Convergence in contact_step_fraction (default 0.05)")
    print("(d) the wall and CPU time of each run are the last columns of (b) and (c)")
    restitution_errors(plan)
    limit_convergence(plan, repeats)
    five_ball_convergence(plan)
    flight_step_convergence(plan, repeats)
    if means:
        converged_means(plan)


def one_d_limit(plan: Plan, repeats: int) -> None:
    seconds = plan.limit_seconds
    heading(
        f"5. The 1-D limit against the 1-D engine, {seconds:g} simulated s "
        "(dem: defaults, no gravity, no friction, convection from the ball)"
    )
    table(
        f"{'omega':>5} | {'heat dem':>8} {'1-D':>8} {'1-D tight':>9} | {'vs 1-D %':>8} {'vs tight %':>10} "
        f"{'2nd half %':>10} | "
        f"{'rate dem':>8} {'1-D':>6} {'tight':>6} | {'vs 1-D %':>8} {'vs tight %':>10} | {'dem s':>5} | targets"
    )
    for omega in OMEGAS:
        dem, timing = timed(lambda omega=omega: simulate(**ONE_D_LIMIT, omega=omega, duration=seconds), repeats)
        loose = simulate(engine="1d", omega=omega, duration=seconds)
        tight = simulate(**TIGHT_1D, omega=omega, duration=seconds)
        heat = [run.summary.heat_power_W for run in (dem, loose, tight)]
        rate = [run.summary.impacts.rate_hz for run in (dem, loose, tight)]
        met = abs(heat[0] / heat[2] - 1) <= HEAT_TARGET and abs(rate[0] / rate[2] - 1) <= RATE_TARGET
        print(
            f"{omega:5.0f} | {heat[0]:8.5f} {heat[1]:8.5f} {heat[2]:9.5f} | "
            f"{percent(heat[0], heat[1]):+8.3f} {percent(heat[0], heat[2]):+10.3f} "
            f"{percent(settled_heat(dem), settled_heat(tight)):+10.3f} | {rate[0]:8.2f} {rate[1]:6.2f} "
            f"{rate[2]:6.2f} | "
            f"{percent(rate[0], rate[1]):+8.2f} {percent(rate[0], rate[2]):+10.2f} | {timing.median:5.2f} | "
            f"{'met' if met else 'MISSED'}"
        )
    print(
        f"targets: heat within {100 * HEAT_TARGET:g} %, impact rate within {100 * RATE_TARGET:g} % of the 1-D "
        "engine at "
        "rtol 1e-6 (whole run); '2nd half': heat of dem against tight over the run's second half"
    )


def warm_up() -> None:
    """Compile or load every engine's Numba code before anything is timed."""
    simulate(**FIVE_BALLS, duration=0.05)
    simulate(engine="1d", duration=0.05)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="shorter runs, fewer fractions, no averaged hour (~2 min)")
    parser.add_argument("--repeats", type=int, default=3, help="repetitions of each cheap timing (median)")
    parser.add_argument(
        "--means", action="store_true", help="also the five balls' converged means at each fraction (~6 min more)"
    )
    args = parser.parse_args()
    plan = QUICK if args.quick else FULL
    warm_up()
    full_run(plan)
    if plan.averaged:
        averaged_run()
    ball_counts(plan, args.repeats)
    tolerance_study(plan, args.repeats, args.means)
    one_d_limit(plan, args.repeats)


if __name__ == "__main__":
    main()
