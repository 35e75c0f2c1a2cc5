"""The impact statistics of a run: histograms of impact speed and dissipated energy per impact, the stress-energy
spectrum (analysis/stress_energy.py), impacts per
second on each kind of target against time, and the drive phase of the impacts; each split by what was hit (the
end faces, and for an engine of several balls the side wall and the other balls)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from shakermill.analysis.impacts import LASTING_CONTACT_S, Contacts, contacts_of
from shakermill.analysis.stress_energy import StressSpectrum, stress_spectrum
from shakermill.solvers.result import counting_rules
from shakermill.views.figures.common import (
    RunLike,
    add_context,
    averaging_window_note,
    new_figure,
    run_context,
    several_balls,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure


IMPACT_FIGURES = (
    "impact_speed_histogram",
    "impact_energy_histogram",
    "stress_energy_spectrum",
    "impacts_per_second",
    "impact_phase_histogram",
)


WALLS = (("left", "left end face", "tab:blue"), ("right", "right end face", "tab:orange"))


# What a ball of the 'dem' engine hits (its impact table's column ``target``).
TARGETS = (*WALLS, ("side", "side wall", "tab:green"), ("ball", "another ball", "tab:purple"))


HISTOGRAM_BINS = 60


HISTOGRAM_HEADROOM = 1.35


# Impacts per second are counted in bins of at least a second (a few drive periods), at most this many bins.
RATE_BINS = 120


MIN_RATE_BIN_S = 1.0


# Beyond this span the rate is plotted against minutes, as the temperatures are.
MINUTES_AXIS_FROM_S = 300.0


def _spectrum(run: RunLike) -> dict[str, Figure]:
    spectrum = run_stress_spectrum(run)
    return {} if spectrum is None else {"stress_energy_spectrum": stress_energy_figure(spectrum)}


def spectrum_figures(run: RunLike) -> dict[str, Figure]:
    """The stress-energy spectrum alone, with the run's context: what a run of several balls with impacts draws
    besides its main figures (the other impact statistics wait for ``plot --impacts``)."""
    return {} if run.impacts.empty else _in_context(run, _spectrum(run))


def _in_context(run: RunLike, figures: dict[str, Figure]) -> dict[str, Figure]:
    context, window = run_context(run), averaging_window_note(run)
    return {name: add_context(figure, context, window) for name, figure in figures.items()}


def run_contacts(run: RunLike) -> Contacts:
    """The contacts of ``run``'s records by the rules of its engine (MODEL.md §14.4)."""
    return contacts_of(run.impacts, *counting_rules(run.params))


def impact_figures(run: RunLike) -> dict[str, Figure]:
    """Histograms of impact speed and dissipated energy, impacts per second at each wall, and (1-D) the
    impact phases, of the run's impacts (MODEL.md §14.4: its records' chatter merged, touches left out); none
    without impacts."""
    impacts = pd.DataFrame(run_contacts(run).impacts)
    if impacts.empty:
        return {}
    balls = several_balls(run.params)
    speed = "normal impact speed relative to what is hit" if balls else "impact speed relative to the end face"
    figures = {
        "impact_speed_histogram": impact_histogram_figure(impacts, "impact_speed", 1.0, speed, "m/s"),
        "impact_energy_histogram": impact_histogram_figure(
            impacts, "dissipated_energy", 1e3, "energy dissipated per impact", "mJ"
        ),
        "impacts_per_second": impact_rate_figure(impacts),
    }
    figures.update(_spectrum(run))
    if not balls:
        # Regimes are sequences of end faces hit at fixed drive phases: a notion of one ball on the axis.
        figures["impact_phase_histogram"] = impact_phase_figure(run)
    return _in_context(run, figures)


# The spectrum's energy axis spans six decades below its largest energy.
SPECTRUM_DECADES = 1e-6


# The spectrum's curves: (component, target, label, style); the split by target only where balls hit balls.
SPECTRUM_CURVES = (
    ("total", "all", "all impacts, normal + tangential", {"color": "black", "lw": 2.0}),
    ("normal", "all", "normal part", {"color": "tab:blue", "lw": 1.5}),
    (
        "tangential",
        "all",
        "tangential part (damping, sliding, rolling)",
        {"color": "tab:orange", "lw": 1.5, "ls": "--"},
    ),
    ("total", "wall", "impacts on the vial", {"color": "tab:green", "lw": 1.2, "ls": ":"}),
    ("total", "ball", "impacts between balls", {"color": "tab:purple", "lw": 1.2, "ls": ":"}),
)


def run_stress_spectrum(run: RunLike) -> StressSpectrum | None:
    """The stress-energy spectrum of ``run``'s impacts as its summary measured it; None for a run folder written
    before the spectrum was reported."""
    window = run.summary.stress_window_s
    if not window > 0.0:
        return None
    return stress_spectrum(
        run_contacts(run),
        window,
        run.params.stress_energy_thresholds,
        run.summary.dissipated_power_W,
        run.params.ball_masses(),
    )


def stress_energy_figure(spectrum: StressSpectrum) -> Figure:
    """The stress-energy spectrum of one run: its total, the total's normal and tangential parts and (where balls
    hit balls) its impacts on each target, with the run's thresholds marked (:func:`spectra_figure`)."""
    curves = [
        (label, spectrum, component, target, style)
        for component, target, label, style in SPECTRUM_CURVES
        if target == "all" or spectrum.hit_ball.any()
    ]
    figure = spectra_figure(curves, spectrum.thresholds)
    events, power = figure.axes
    events.set_title(f"Stress frequency ({spectrum.of().size} impacts in {spectrum.window:.3g} s)")
    if spectrum.lasting.any():
        power.set_title(
            f"Stress power; contacts lasting over {LASTING_CONTACT_S * 1e3:g} ms: {spectrum.lasting_power():.3g} W"
        )
    return figure


def spectra_figure(
    curves: Sequence[tuple[str, StressSpectrum, str, str, dict]], thresholds: Sequence[float] = ()
) -> Figure:
    """Stress events per second (left) and their power (right) at or above each stress energy E, one line per
    ``(label, spectrum, component, target, style)``; ``thresholds`` (J) dash-dot."""
    figure, (events, power) = new_figure(columns=2, height=4.5, width=11.0)
    for label, spectrum, component, target, style in curves:
        energies = np.sort(spectrum.of(component, target))
        energies = energies[energies > 0.0]
        if not energies.size:
            continue
        # Ascending energies E_i: at E in (E_{i-1}, E_i] the events at or above E are the i-th and all after it.
        events.step(energies, np.arange(energies.size, 0, -1) / spectrum.window, where="pre", label=label, **style)
        power.step(energies, np.cumsum(energies[::-1])[::-1] / spectrum.window, where="pre", label=label, **style)
    for axis in (events, power):
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel("stress energy E, dissipated per impact (J)")
        for threshold in thresholds:
            axis.axvline(threshold, color="0.5", lw=0.8, ls="-.")
        axis.grid(alpha=0.3, which="both")
    events.set_ylabel("stress events at or above E per second (1/s)")
    power.set_ylabel("power of the stress events at or above E (W)")
    events.set_title("Stress frequency")
    power.set_title("Stress power" + (" (dash-dot: the run's thresholds)" if thresholds else ""))
    events.legend(loc="lower left", fontsize="small")
    # Energies below a millionth of the largest carry nothing a reader can see: the axes start there.
    largest = max(
        (float(np.max(spectrum.of(component, target), initial=0.0)) for _, spectrum, component, target, _ in curves),
        default=0.0,
    )
    if largest > 0.0:
        for axis in (events, power):
            axis.set_xlim(left=largest * SPECTRUM_DECADES)
    return figure


def impact_kinds(impacts: pd.DataFrame) -> tuple[np.ndarray, tuple[tuple[str, str, str], ...]]:
    """What each impact hit, and the kinds to tell apart as (name, label, colour): the end faces of a 1-D
    run (column ``wall``), or the end faces, the side wall and another ball of a 'dem' run (``target``)."""
    if "target" in impacts:
        return impacts["target"].to_numpy(), TARGETS
    return impacts["wall"].to_numpy(), WALLS


def impact_histogram_figure(impacts: pd.DataFrame, column: str, scale: float, quantity: str, unit: str) -> Figure:
    """Histogram of ``column`` × ``scale`` (in ``unit``), stacked by what was hit (:func:`impact_kinds`), with the
    mean and maximum in a box."""
    figure, (axis,) = new_figure(height=4.0)
    values = impacts[column].to_numpy() * scale
    edges = np.histogram_bin_edges(values, bins=HISTOGRAM_BINS)
    _stacked_by_kind(axis, values, *impact_kinds(impacts), edges)
    axis.text(
        0.98,
        0.96,
        f"mean {values.mean():.3g} {unit}\nmax {values.max():.3g} {unit}",
        transform=axis.transAxes,
        ha="right",
        va="top",
        bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.85},
    )
    # Headroom above the highest bar for the legend and the statistics box.
    axis.set_ylim(0.0, axis.get_ylim()[1] * HISTOGRAM_HEADROOM)
    axis.set_xlabel(f"{quantity} ({unit})")
    axis.set_ylabel("impacts per bin (count)")
    axis.set_title(f"Distribution of the {quantity} ({len(values)} impacts)")
    axis.legend(loc="upper left")
    axis.grid(alpha=0.3)
    return figure


def _stacked_by_kind(
    axis: object, values: np.ndarray, kinds: np.ndarray, categories: Sequence[tuple[str, str, str]], edges: np.ndarray
) -> None:
    """A histogram of ``values`` stacked by what was hit (``categories``: :func:`impact_kinds`), each labelled with its
    count."""
    parts = [values[kinds == kind] for kind, _, _ in categories]
    axis.hist(  # type: ignore[attr-defined]
        parts,
        bins=edges,
        stacked=True,
        color=[colour for _, _, colour in categories],
        label=[f"{label} ({len(part)})" for (_, label, _), part in zip(categories, parts)],
    )


def rate_bin_edges(first_impact: float, last_impact: float) -> np.ndarray:
    """Equal bins from the first to the last impact: at least :data:`MIN_RATE_BIN_S` wide, :data:`RATE_BINS` at most.

    The averaged solver keeps only the impacts after its start-up transient, so the bins start at the
    first impact, not at t = 0.
    """
    span = max(last_impact - first_impact, MIN_RATE_BIN_S)
    bins = int(min(RATE_BINS, max(1.0, span // MIN_RATE_BIN_S)))
    return np.linspace(first_impact, first_impact + span, bins + 1)


def impact_rate_figure(impacts: pd.DataFrame) -> Figure:
    """Impacts per second on each kind of target (:func:`impact_kinds`) against time, counted in the bins of
    :func:`rate_bin_edges`."""
    figure, (axis,) = new_figure(height=4.0)
    times = impacts["time"].to_numpy()
    edges = rate_bin_edges(float(times.min()), float(times.max()))
    width = edges[1] - edges[0]
    in_minutes = edges[-1] >= MINUTES_AXIS_FROM_S
    time_scale = 60.0 if in_minutes else 1.0
    kinds, categories = impact_kinds(impacts)
    for kind, label, colour in categories:
        counts, _ = np.histogram(times[kinds == kind], bins=edges)
        rates = counts / width
        legend = f"{label} (mean {rates.mean():.3g}/s)"
        # No baseline: the vertical edges down to zero at both ends would read as a drop in the rate.
        axis.stairs(rates, edges / time_scale, baseline=None, color=colour, lw=1.5, label=legend)
    axis.set_ylim(bottom=0.0)
    axis.set_xlabel("time (min)" if in_minutes else "time (s)")
    axis.set_ylabel("impacts per second (1/s)")
    where = "at each end face" if categories == WALLS else "on each wall and between balls"
    axis.set_title(f"Impacts per second {where} (bins of {width:.3g} s)")
    axis.legend(loc="best")
    axis.grid(alpha=0.3)
    return figure


PHASE_BINS = 72  # 5° bins


def impact_phase_figure(run: RunLike) -> Figure:
    """Distribution of the drive phase ωt + φ (mod 2π) at the impacts of the settled motion, by end face.

    A periodic motion hits at a few sharp phases; an irregular one spreads them. The start-up
    transient is left out (the second half of a full run; the averaged solver's impacts are settled).
    """
    from shakermill.analysis.regime import classify_impacts, impact_phases, settled_run_impacts

    settled = settled_run_impacts(run)
    params = run.params
    phases = impact_phases(settled, params.omega, params.phase)
    regime, _ = classify_impacts(settled, params.omega, params.phase)
    figure, (axis,) = new_figure(height=4.0)
    edges = np.linspace(0.0, 2 * math.pi, PHASE_BINS + 1)
    _stacked_by_kind(axis, phases.phase, phases.wall, WALLS, edges)
    _radian_ticks(axis.xaxis)
    axis.set_xlim(0.0, 2 * math.pi)
    axis.set_ylim(0.0, axis.get_ylim()[1] * HISTOGRAM_HEADROOM)
    axis.set_xlabel("drive phase at impact, ωt + φ mod 2π (rad)")
    axis.set_ylabel("impacts per 5° bin (count)")
    axis.set_title(f"Impact phases of the settled motion ({len(settled['time'])} impacts, {regime})")
    axis.legend(loc="upper left")
    axis.grid(alpha=0.3)
    return figure


def _radian_ticks(axis: object) -> None:
    ticks = np.arange(5) * math.pi / 2
    axis.set_ticks(ticks, ["0", "π/2", "π", "3π/2", "2π"])  # type: ignore[attr-defined]
