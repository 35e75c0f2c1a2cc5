"""The sections of a run's summary that the solvers build (``solvers/result.py``: ``summarize``, and the averaging's
:meth:`~shakermill.solvers.result.MechanicsAverages.as_summary`) and the one a study adds to a run's summary (the 90 %
intervals of ``studies/calibration/intervals.py``): typed as :mod:`shakermill.analysis.sections` describes, composed
into :class:`~shakermill.solvers.summary.Summary`."""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field

from shakermill.analysis.sections import (
    Celsius,
    Hertz,
    Joules,
    Key,
    MetresPerSecond,
    Millimetres,
    NodeTemperatures,
    PerMinute,
    PerSecond,
    RadiansPerSecond,
    Seconds,
    Section,
    Watts,
)


class Outcome(Section):
    """How the run ended, and what ran it."""

    status: int
    """0 when the run reached its end; 1 interrupted (Ctrl-C); negative: stopped early or failed a check
    (``engines/status.py``; -5 a temperature out of the model's range, -6 an energy audit that does not close)."""
    success: bool
    """Whether ``status`` is 0."""
    message: str
    """How the run ended, in a sentence."""
    solver: str
    """The solver that made these numbers: ``full``, or ``averaged`` (an averaged run that fell back to full resolution
    says ``full``)."""
    simulated_s: Seconds
    """The simulated time."""


class EndTemperatures(NodeTemperatures):
    """Every node's temperature at the end of the run, keys ``{node}_C`` (``summary.temperatures``), and the balls'
    own."""

    node_key = "{node}_C"
    node_meaning = "its temperature at the end of the run."

    vial_ball_ratio: float
    """(θ_vial − θ₀)/(θ_ball − θ₀) at the end: the vial's temperature rise over the ball's (MODEL.md §8)."""
    each_ball_C: Annotated[list[Celsius] | None, Key("ball_temperatures_C")] = None
    """Each ball's temperature at the end, ball 0 first (an engine of several balls)."""
    hottest_ball_C: Celsius | None = None
    """The hottest ball's temperature at the end (an engine of several balls)."""


class Impacts(Section):
    """The impacts of the run (``summary.impacts``): how many, how often, how fast. An impact is a contact as MODEL.md
    §14.4 defines it: a pair's records that part and touch again within ``chatter_factor`` Hertz durations merged
    into one, and a contact that begins slower than ``touch_speed`` a touch, not an impact ('dem' engine; the 1-D
    engine's records are its impacts)."""

    count: Annotated[int, Key("impacts")]
    """Impacts in the run (the averaged solver: its window's rate times the duration)."""
    rate_hz: Annotated[PerSecond, Key("impact_rate_hz")]
    """Impacts per second, over the impact table's span (the whole run, or the averaging window)."""
    hit_rate_hz: PerSecond
    """Impacts per second at or above 0.1 m/s (``HIT_SPEED``); the impact rate itself at the default
    ``touch_speed``."""
    mean_hit_speed_m_s: MetresPerSecond
    """Mean speed of those hits; NaN without any."""
    fast_rate_hz: Annotated[PerSecond, Key("fast_impact_rate_hz")]
    """Impacts per second at or above 1 m/s (``FAST_IMPACT_SPEED``)."""
    mean_speed_m_s: Annotated[MetresPerSecond, Key("mean_impact_speed_m_s")]
    """Mean normal impact speed; NaN without impacts."""
    max_speed_m_s: Annotated[MetresPerSecond, Key("max_impact_speed_m_s")]
    """Fastest impact; NaN without impacts."""
    mean_dissipated_J: Annotated[Joules, Key("mean_dissipated_per_impact_J")]
    """Mean energy dissipated per impact; NaN without impacts."""
    on_walls: Annotated[int | None, Key("wall_impacts")] = None
    """Impacts on the vial's walls in the run (an engine of several balls)."""
    between_balls: Annotated[int | None, Key("ball_ball_impacts")] = None
    """Impacts between balls in the run (an engine of several balls)."""
    records_hz: Annotated[PerSecond, Key("contact_records_hz")] = math.nan
    """Contact records per second, every touch and chatter included: what the records hold, not impacts."""
    touches_hz: Annotated[PerSecond, Key("touch_rate_hz")] = math.nan
    """Touches per second: contacts that began slower than ``touch_speed``."""


class Heat(Section):
    """The heat and power of the contacts, and the heat paths' flows."""

    heat_power_W: Watts
    """Mean irreversible heat generation of the contacts, η times the dissipated power."""
    dissipated_power_W: Watts
    """Mean power dissipated in the contacts."""
    drive_heat_W: Watts
    """Mean heat the drive puts into the holder whatever the balls do (``drive_heat``; 0 without a holder)."""
    heat_paths_W: dict[str, Watts] = Field(default_factory=dict)
    """Each heat path's mean flow over the run, from its hot end to its cold end, by the path's name (``ball → air``,
    ``vial → room, convection``, ...; MODEL.md §13.1)."""
    dissipated_by_channel_W: Annotated[dict[str, Watts], Key("dissipated_{channel}_W")] = Field(default_factory=dict)
    """Mean power dissipated in each channel of the engine (``normal``, ``tangential``, ``sliding``, ``rolling`` for
    the 'dem' engine; MODEL.md §12.4), by channel. Empty for an engine that does not split its dissipation."""
    heat_by_channel_W: Annotated[dict[str, Watts], Key("heat_{channel}_W")] = Field(default_factory=dict)
    """η times ``dissipated_by_channel_W``: the heat made in each channel."""


class Charge(Section):
    """The balls of an engine that moves several (``summary.charge``; None for an engine of one ball)."""

    engine: str
    """The engine that moves them (``dem``)."""
    n_balls: int
    """The number of balls (an engine of several balls)."""
    fill_fraction: float
    """The share of the vial's inner volume the balls take."""
    work_gravity_J: Joules
    """Work done by gravity on the balls over the run."""
    work_stiffening_J: Joules
    """Energy the tangential springs gained by stiffening with the load (``work_by_stiffening``)."""
    regime: Annotated[str | None, Key("charge_regime")] = None
    """The regime of the settled motion (MODEL.md §14.2), from ``charge_regime_from_s`` to the end, never the start-up:
    ``pack`` (lasting contacts take at least half the dissipation, and fewer than one impact above 1 m/s per ball and
    turn), ``active`` (the rest), or ``intermittent`` (an averaged run whose batches switched between the two at least
    twice: ``charge_regime_active_share`` of the time active, switching every ``charge_regime_switch_interval_s``);
    None where the share of lasting contacts is not known."""
    regime_from_s: Annotated[Seconds, Key("charge_regime_from_s")] = math.nan
    """Where the window the regime is named from begins (s): the second half of a full run, the averaging window."""
    regime_lasting_share: Annotated[float, Key("charge_regime_lasting_share")] = math.nan
    """The share of that window's dissipation in contacts lasting over 1 ms."""
    regime_fast_impact_rate_hz: Annotated[PerSecond, Key("charge_regime_fast_impact_rate_hz")] = math.nan
    """That window's impacts per second at or above 1 m/s."""
    regime_active_share: Annotated[float, Key("charge_regime_active_share")] = math.nan
    """The share of the averaged solver's batches (of its time) that were active; NaN for a full run."""
    regime_switch_interval_s: Annotated[Seconds, Key("charge_regime_switch_interval_s")] = math.nan
    """The mean time between the batches' switches of regime; NaN without a switch, and for a full run."""


class Numerics(Section):
    """What the integration took, and how well its energy balance closed."""

    steps: int
    """Accepted integrator steps."""
    rejected_steps: int
    """Rejected integrator steps."""
    rhs_evaluations: int
    """Evaluations of the equations' right-hand side."""
    wall_time_s: Seconds
    """Wall-clock time of the run."""
    energy_audit_residual: float
    """Relative residual of the energy audit (|residual| over the largest flow); above 1e-2 the run fails."""
    energy_projection_relative: float
    """The kinetic energy the energy projection corrected, over the energy dissipated."""


class Inputs(Section):
    """Inputs echoed in the units people quote (guards against unit slips)."""

    omega_rad_s: RadiansPerSecond
    """The drive's angular frequency ω."""
    omega_hz: Hertz
    """The drive frequency, ω/2π."""
    omega_rpm: PerMinute
    """The drive frequency in cycles per minute."""
    amplitude_mm: Millimetres
    """The vial's amplitude."""
    ball_radius_mm: Millimetres
    """The ball radius."""
    vial_length_mm: Millimetres
    """The vial's inner length."""
    vial_diameter_mm: Millimetres
    """The vial's inner diameter."""
    ambient_temperature_C: Celsius
    """The room's temperature."""
    initial_temperature_C: Celsius
    """The temperature every node starts at (θ₀)."""


class Averaging(Section):
    """What the averaged solver measured of the settled motion (MODEL.md §14; ``summary.averaging``)."""

    heat_power_W: Annotated[Watts, Key("averaged_heat_power_W")]
    """Mean heat power of the settled motion (averaged solver)."""
    heat_power_stderr_W: Annotated[Watts, Key("averaged_heat_power_stderr_W")]
    """Its standard error, from batch means."""
    dissipated_power_W: Annotated[Watts, Key("averaged_dissipated_power_W")]
    """Mean dissipated power of the settled motion."""
    velocity_term: Annotated[float, Key("averaged_velocity_term")]
    """Mean Whitaker velocity term 0.4·Re^½ + 0.06·Re^⅔ of the settled motion."""
    velocity_term_stderr: Annotated[float, Key("averaged_velocity_term_stderr")]
    """Its standard error."""
    transient_s: Annotated[Seconds, Key("averaging_transient_s")]
    """The start-up transient cut before averaging."""
    window_s: Annotated[Seconds, Key("averaging_window_s")]
    """The seconds averaged over."""
    batches: Annotated[int, Key("averaging_batches")]
    """Batches of the batch means."""
    replicas: Annotated[int, Key("averaging_replicas")]
    """Independent replicas of the mechanics pooled."""
    batch_s: Annotated[Seconds, Key("averaging_batch_s")]
    """Length of a batch after grouping to uncorrelated means."""
    batch_autocorrelation: Annotated[float, Key("averaging_batch_autocorrelation")]
    """The largest |lag-1 autocorrelation| of the batches used (after grouping) in their total heat and mean velocity
    term, as measured: also where a spread within the target error spares a column the test."""
    transient_heat_power_W: Annotated[Watts, Key("averaging_transient_heat_power_W")]
    """Mean heat power of the transient cut."""
    converged: Annotated[bool, Key("averaging_converged")]
    """Whether the averages converged to their tolerance."""
    message: Annotated[str, Key("averaging_message")]
    """How the averaging ended, in words."""


class PredictionIntervals(Section):
    """The 90 % intervals of a calibrated preset's run (``studies/calibration/intervals.py``; ``summary.intervals``)."""

    ball_C_low: Celsius
    """Lower end of the 90 % interval of ``ball_C`` (a calibrated preset's run; studies/calibration/intervals.py)."""
    ball_C_high: Celsius
    """Upper end of that interval."""
    vial_C_low: Celsius
    """Lower end of the 90 % interval of ``vial_C``."""
    vial_C_high: Celsius
    """Upper end of that interval."""
    ball_steady_C_low: Celsius
    """Lower end of the 90 % interval of ``ball_steady_C``."""
    ball_steady_C_high: Celsius
    """Upper end of that interval."""
    vial_steady_C_low: Celsius
    """Lower end of the 90 % interval of ``vial_steady_C``."""
    vial_steady_C_high: Celsius
    """Upper end of that interval."""
    note: Annotated[str, Key("interval_note")]
    """What the intervals carry (the calibration's uncertainty, the averaging error)."""
