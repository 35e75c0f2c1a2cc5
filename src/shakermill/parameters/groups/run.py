"""The run itself: which engine and solver, for how long, what is kept, its budget and its bounds; and the averaged
solver's own keys."""

from __future__ import annotations

from typing import Literal

from shakermill.parameters.fields import (
    LONGEST_RUN_S,
    MAX_STRESS_THRESHOLDS,
    StressThreshold,
    Window,
    choice,
    count,
    listed,
    quantity,
)
from shakermill.parameters.key_group import KeyGroup, only_with_solver
from shakermill.parameters.sources import PAPER
from shakermill.support.limits import MAX_RECORD_WINDOWS


class RunControl(KeyGroup):
    """Every run, whatever its engine: which engine and solver, for how long, what is kept, its budget and its bounds
    (``attractor_starts`` too: its 1, "no probe", is what an engine without the probe does anyway)."""

    title = "the run"

    # The engine (engine_keys.py; engines/registry.py adds any registered): its name is checked by _known_engine.
    engine: str = choice(
        "'1d': one ball on the vial's axis (MODEL.md sections 1-7); 'dem': n_balls spheres in three "
        "dimensions with friction and rotation (section 12)",
        default="1d",
        source=f"{PAPER}: one ball on the vial's axis",
    )
    solver: Literal["full", "averaged"] = choice(
        "'full': every impact for the whole run; 'averaged': mechanics until its statistics converge, then "
        "the slow network",
        default="full",
        source="full resolution, as the paper",
    )
    # A microsecond: less than one contact step. 1e6 s (11.6 days): longer than any milling run (~100 h);
    # the stored samples are capped too (MAX_SAMPLES), and full-resolution runs by their drive periods.
    duration: float = quantity(
        "s",
        "simulated time",
        default=3600.0,
        source=f"{PAPER}, Table 4 (60 min)",
        # An averaged run measures its mechanics over their own window, however long the run.
        thermal_only=True,
        ge=1e-6,
        le=LONGEST_RUN_S,
    )
    # The sample count duration/output_interval is capped as well (MAX_SAMPLES).
    output_interval: float = quantity(
        "s",
        "sampling interval of the stored time series",
        default=1.0,
        source="assumption: 1 s sampling of the stored time series",
        thermal_only=True,
        ge=1e-6,
        le=LONGEST_RUN_S,
    )
    record_windows: tuple[Window, ...] = listed(
        "s",
        "(start, length) windows stored at full resolution",
        default=((0.0, 1.0), (600.0, 0.1)),
        source=f"the windows of {PAPER} Fig. 4 (first second) and Fig. 5b (100 ms at 10 min)",
        most=MAX_RECORD_WINDOWS,
    )
    # Budget of one run (shakermill.budget): beyond either limit it stops with a non-ok status, keeping its results
    max_wall_time: float = quantity(
        "s",
        "wall-clock budget of one run, its mechanics phase, fall-back and attractor probe included",
        default=3600.0,
        source="numerical choice: an hour; the default 60-min run takes ~3 s, the same at rtol 1e-6 ~20 s, and 10⁹ "
        "steps (max_steps) ~10-20 min",
        gt=0,
        le=LONGEST_RUN_S,
    )
    max_steps: int = count(
        "step budget of one run: accepted integrator steps, all its integrations together",
        default=1_000_000_000,
        source="numerical choice: ~290 simulated hours at the defaults (3.4 million steps an hour), ~30 h at rtol "
        "1e-6; beyond it the steps are tiny (a stiff node or an extreme drive)",
        strict=False,
        gt=0,
        le=10**12,  # at ~0.5 µs a step, about a week of computing
    )
    stress_energy_thresholds: tuple[StressThreshold, ...] = listed(
        "J",
        "stress energies above which each run reports the impacts' power (analysis/stress_energy.py)",
        default=(1e-3, 1e-2),
        source="numerical choice: 1 mJ and 10 mJ, about the median and the upper tail of the energy a steel ball "
        "dissipates per impact in the SPEX 8000M and the planetary presets (benchmarks/README.md, stress energies)",
        most=MAX_STRESS_THRESHOLDS,
    )
    # Up to 4000 K: tungsten, the most refractory ball material, melts at 3695 K.
    ball_temperature_limit: float = quantity(
        "K",
        "highest physical ball temperature: a run that exceeds it ends with a non-ok status",
        default=1673.15,
        source="assumption: carbon and bearing steels begin to melt near 1400 °C; above it the model does not hold",
        ge=50.0,
        le=4000.0,
    )
    # Each start costs a settled run at every point of a scan; 100 cover the gap far more densely than
    # the basins found so far need (the default 8 finds them).
    attractor_starts: int = count(
        "initial states settled to find coexisting attractors (bifurcation, sweeps, averaged solver); "
        "1: only the configured start",
        default=8,
        source="numerical choice: the configured start and 7 spread over the free gap, at rest or at the vial's peak "
        "speed; ~0.02 s of mechanics each",
        ge=1,
        le=100,
    )


class AveragedSolver(KeyGroup):
    """The averaged solver of any engine (each engine adds the key of its own target error)."""

    title = "the averaged solver"
    rule = only_with_solver("averaged")

    # 10 000 periods (~10 min) per batch: already past any averaging_max_time worth waiting for.
    averaging_batch_periods: int = count(
        "averaged solver: drive periods per batch of the batch-means estimate",
        default=16,
        source="numerical choice: batches of 16 drive periods (~0.9 s)",
        ge=1,
        le=10_000,
    )
    averaging_min_batches: int = count(
        "averaged solver: fewest batches after the transient",
        default=20,
        source="MODEL.md §14.2: at least 20 uncorrelated batches, so that their lag-1 autocorrelation can be tested",
        ge=4,
        le=10_000,
    )
    # An hour of mechanics costs what a full-resolution hour does; averaging converges in ~20 s.
    averaging_max_time: float = quantity(
        "s",
        "averaged solver: longest mechanics window before giving up",
        default=120.0,
        source="numerical choice: 2 simulated minutes of mechanics at most",
        gt=0,
        le=3600.0,
    )
    averaging_fallback: Literal["full", "fail"] = choice(
        "averaged solver: what to do when averaging is not valid",
        default="full",
        source="numerical choice: fall back to full resolution and say so",
    )
