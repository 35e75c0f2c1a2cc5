"""Planetary mills beside the SPEX 8000M: what a simulated second and a simulated hour cost, and the stress-energy
spectra side by side (issue 27).

Part ``second``: one simulated second at full resolution of each planetary preset (``pulverisette7``, ``pm100``:
ten Ø10-mm steel balls, started carried by the jar) and five seconds of five 12.7-mm balls in the SPEX 8000M
(``spex8000m-3d``), in CPU time with Numba's cache warm: steps, impacts per second, heat power and the
stress-energy spectrum of that start.

Part ``hour``: one averaged hour of each planetary preset as shipped (``--batch-periods`` changes the batches of the
averaged solver's mechanics) and of the five SPEX balls: wall and CPU time, seconds of mechanics, the balls', jar's
and air's temperatures, the heat paths that carry the most and the spectrum of the settled motion (the averaged
solver's impact records, after its transient). It draws those three spectra into
``docs/figures/stress-energy-spex-vs-planetary.png``. The planetary presets are not calibrated: their temperatures
are estimates.

    .venv/bin/python benchmarks/bench_planetary.py                 # both parts (~20 min on 2 cores)
    .venv/bin/python benchmarks/bench_planetary.py --only second   # the first seconds (~1 min)
    .venv/bin/python benchmarks/bench_planetary.py --only hour --presets pm100 --batch-periods 4
"""

from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

import shakermill as sm
from shakermill.analysis.stress_energy import stress_spectrum
from shakermill.solvers.summary import Summary

ROOT = Path(__file__).resolve().parents[1]
FIGURE = ROOT / "docs" / "figures" / "stress-energy-spex-vs-planetary.png"
PLANETARY = ("pulverisette7", "pm100")
LABELS = {
    "spex8000m-3d": "SPEX 8000M, 5 balls Ø12.7 mm (spex8000m-3d)",
    "pulverisette7": "Pulverisette 7 type, 10 balls Ø10 mm, 800 rpm (pulverisette7)",
    "pm100": "PM 100 type, 10 balls Ø10 mm, 500 rpm (pm100)",
}
SPEX = ("spex8000m-3d", {"n_balls": 5})
# (preset, overrides, simulated seconds): five SPEX balls for five seconds hold about as many impacts as a planetary
# jar's second.
SECOND_RUNS = ((*SPEX, 5.0), ("pulverisette7", {}, 1.0), ("pm100", {}, 1.0))
STYLES = (
    {"color": "tab:blue", "lw": 2.0},
    {"color": "tab:red", "lw": 2.0},
    {"color": "tab:green", "lw": 2.0, "ls": "--"},
)
HOUR_S = 3600.0


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed(params: sm.Parameters) -> tuple[sm.Result, float, float]:
    """The run of ``params`` with its wall and CPU seconds (Numba's compilation done by a short run first)."""
    sm.simulate(params.replace(duration=min(params.duration, 0.001), solver="full", record_windows=()))
    wall, cpu = time.perf_counter(), cpu_seconds()
    result = sm.simulate(params)
    return result, time.perf_counter() - wall, cpu_seconds() - cpu


def spectrum_line(summary: Summary) -> str:
    above = ", ".join(f"{threshold}: {power:.3g} W" for threshold, power in summary.stress_power_above_W.items())
    return (
        f"stress energy median {summary.stress_energy_median_J * 1e3:.3g} mJ, 90th percentile "
        f"{summary.stress_energy_p90_J * 1e3:.3g} mJ (normal {summary.stress_energy_normal_median_J * 1e3:.3g}, "
        f"tangential {summary.stress_energy_tangential_median_J * 1e3:.3g} mJ median); power above {above}; "
        f"contacts lasting over 1 ms {summary.stress_lasting_contacts_hz:.3g}/s, "
        f"{summary.stress_lasting_power_W:.3g} W"
    )


def second_part() -> None:
    for preset, overrides, seconds in SECOND_RUNS:
        params = sm.default_parameters(preset, solver="full", duration=seconds, record_windows=(), **overrides)
        result, wall, cpu = timed(params)
        summary = result.summary
        print(
            f"{LABELS[preset]}: {seconds:g} simulated s in {cpu:.1f} CPU-s ({wall:.1f} wall-s), {cpu / seconds:.3g} "
            "CPU-s "
            f"per simulated s; {result.counters['steps']} steps, {summary.impacts.rate_hz:.4g} impacts/s, heat "
            f"{summary.heat_power_W:.3g} W, audit residual {summary.energy_audit_residual:.1e}"
        )
        print(f"  {spectrum_line(summary)}")


def hour_part(presets: list[str], batch_periods: int | None) -> None:
    from shakermill.views.figures.impacts import spectra_figure

    curves = []
    for (preset, overrides), style in zip((SPEX, *((name, {}) for name in presets)), STYLES, strict=False):
        settings = {"averaging_batch_periods": batch_periods} if batch_periods and preset != SPEX[0] else {}
        params = sm.default_parameters(preset, duration=HOUR_S, **overrides, **settings)
        result, wall, cpu = timed(params)
        summary = result.summary
        paths = sorted(summary.heat_paths_W.items(), key=lambda item: -abs(item[1]))[:4]
        print(
            f"{LABELS[preset]}, averaged hour (batches of {params.averaging_batch_periods} periods): {wall:.0f} "
            f"wall-s, {cpu:.0f} CPU-s; {summary.number('averaging_window_s'):.3g} s of mechanics kept; "
            f"status {result.status}: {result.message}"
        )
        print(
            f"  balls {summary.ball_C:.1f} °C (mean; hottest {summary.temperatures.hottest_ball_C:.1f} °C), jar "
            f"{summary.vial_C:.1f} °C, air {summary.air_C:.1f} °C, holder "
            f"{summary.number('holder_C'):.1f} °C; "
            f"heat {summary.heat_power_W:.3g} W at {summary.impacts.rate_hz:.4g} impacts/s"
        )
        print(f"  {spectrum_line(summary)}")
        print("  largest heat paths: " + "; ".join(f"{name} {flow:.3g} W" for name, flow in paths))
        spectrum = stress_spectrum(
            result.contacts(),
            summary.stress_window_s,
            params.stress_energy_thresholds,
            summary.dissipated_power_W,
        )
        curves.append((LABELS[preset], spectrum, "total", "all", style))
    figure = spectra_figure(curves, params.stress_energy_thresholds)
    figure.suptitle(
        "Stress-energy spectra of the settled motion: a SPEX 8000M and two planetary mills (not calibrated)"
    )
    figure.savefig(FIGURE, dpi=110)
    print(f"figure: {FIGURE.relative_to(ROOT)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=("second", "hour"), help="one part only")
    parser.add_argument("--presets", default=",".join(PLANETARY), help="planetary presets of the hour part")
    parser.add_argument(
        "--batch-periods", type=int, help="averaging_batch_periods of the hour part (default: the preset's)"
    )
    args = parser.parse_args()
    if args.only in (None, "second"):
        second_part()
    if args.only in (None, "hour"):
        hour_part(args.presets.split(","), args.batch_periods)


if __name__ == "__main__":
    main()
