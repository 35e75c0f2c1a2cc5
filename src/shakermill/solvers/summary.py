"""The run summary's schema: every key a run's summary can hold, with its unit and meaning.

:class:`Summary` is what :func:`~shakermill.solvers.result.summarize` makes (``Result.summary``), what ``summary.json``
stores under ``"summary"`` (with ``"schema_version"`` beside it), what ``shakermill run --json`` prints and what a sweep
table has as columns. Read it by attribute (``result.summary.ball_C``); where a key is chosen by name at run time (a
calibration target, a compared quantity, a table column), through :meth:`Summary.value`, :meth:`Summary.number` or
:func:`declared_name`, which refuse a name that is not declared here (``SummaryKeyError``, with the nearest key). No
module but this one reads a summary by a string key (``tests/test_architecture.py``).

Every field below is one key, in the unit its annotation names (``Celsius``: °C, ``PerSecond``: 1/s, ...; a bare
``float`` or ``int`` has none). A key that only some runs have (an engine of several balls, a ``mill-head`` network,
the averaged solver, the attractor probe, a calibrated preset's intervals) is optional: ``None`` when the run has
none, and then absent from ``summary.json``. The keys whose names depend on the run are *families*: in the summary a
mapping by member (a dissipation channel, a stress-energy threshold), in ``summary.json`` one flat key per member
after a declared pattern (:data:`FAMILIES`: ``dissipated_{channel}_W``, ``heat_{channel}_W``,
``stress_events_above_{threshold}_hz``, ``stress_power_above_{threshold}_W``, and ``{node}_C``, ``{node}_steady_C`` for
a node of the thermal network that no key names, as the powder: the ball, vial, air and holder have keys of their
own). A
number that is not finite is ``null`` in JSON and NaN here once read back.

The version of ``summary.json`` and the reading of older ones: ``solvers/summary_versions.py``.
"""

from __future__ import annotations

import difflib
import math
import re
import typing
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import cache
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

# The thermal network's nodes renamed since version 1 of the summary: the clamp and mill head is the holder. An engine
# that still names the node so has its keys under the new name.
RENAMED_NODES = {"clamp": "holder"}


@dataclass(frozen=True)
class Unit:
    """The unit of a summary key, as its annotation carries it (``Annotated[float, Unit("°C")]``)."""

    symbol: str


Celsius = Annotated[float, Unit("°C")]
Kelvin = Annotated[float, Unit("K")]
Minutes = Annotated[float, Unit("min")]
Seconds = Annotated[float, Unit("s")]
Watts = Annotated[float, Unit("W")]
Joules = Annotated[float, Unit("J")]
PerSecond = Annotated[float, Unit("1/s")]
MetresPerSecond = Annotated[float, Unit("m/s")]
Millimetres = Annotated[float, Unit("mm")]
CelsiusPerMinute = Annotated[float, Unit("°C/min")]
RadiansPerSecond = Annotated[float, Unit("rad/s")]
Hertz = Annotated[float, Unit("Hz")]
PerMinute = Annotated[float, Unit("rpm")]


class SummaryKeyError(KeyError):
    """A name that is not a declared summary key (a misspelling, or a key of another program)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class Summary(BaseModel):
    """The summary of one run (``Result.summary``, ``RunData.summary``): one attribute per key, in the unit its
    annotation names. Frozen: :meth:`updated` gives a copy with keys added or changed, checked against the schema."""

    model_config = ConfigDict(frozen=True, extra="forbid", use_attribute_docstrings=True)

    # ------------------------------------------------------------------ the run
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

    # ------------------------------------------------------------------ the exponential fitted to the ball
    theta_inf_C: Celsius
    """θ∞ of the exponential θ∞ − (θ∞ − θ₀)·exp(−t/τ) fitted to the ball temperature (the balls' mean) over the run
    (MODEL.md §8): a property of the run's window, not the steady state; NaN where the fit failed."""
    theta_inf_stderr_K: Kelvin
    """Standard error of ``theta_inf_C``."""
    tau_min: Minutes
    """τ of that fit."""
    tau_stderr_min: Minutes
    """Standard error of ``tau_min``."""
    rate0_C_per_min: CelsiusPerMinute
    """The fit's initial heating rate θ̇₀ = (θ∞ − θ₀)/τ."""
    fit_rms_residual_K: Kelvin
    """RMS residual of that fit."""
    exponential_fit_describes_run: bool
    """Whether the exponential is worth reading: fitted, over a run no shorter than the network's slowest time
    constant."""

    # ------------------------------------------------------------------ temperatures at the end
    ball_C: Celsius
    """The ball's temperature at the end of the run (with several balls, their mean)."""
    vial_C: Celsius
    """The vial's temperature at the end of the run."""
    air_C: Celsius
    """The inner air's temperature at the end of the run."""
    holder_C: Celsius | None = None
    """The holder's temperature at the end of the run (``thermal_model = 'mill-head'``: the clamp and mill head; the
    key was ``clamp_C`` in version 1); None without a holder node."""
    other_nodes_C: dict[str, Celsius] = Field(default_factory=dict)
    """The temperature at the end of each further node of the thermal network that no key above names (one an
    extension of ``engines/thermal/network.py`` adds: the powder), by the node's name; flat keys ``{node}_C``."""
    vial_ball_ratio: float
    """(θ_vial − θ₀)/(θ_ball − θ₀) at the end: the vial's temperature rise over the ball's (MODEL.md §8)."""
    ball_temperatures_C: list[Celsius] | None = None
    """Each ball's temperature at the end, ball 0 first (an engine of several balls)."""
    hottest_ball_C: Celsius | None = None
    """The hottest ball's temperature at the end (an engine of several balls)."""

    # ------------------------------------------------------------------ the steady state (MODEL.md §11)
    ball_steady_C: Celsius | None = None
    """The ball's steady temperature (the balls' mean): the root of the thermal network under the run's mean load,
    where a longer run would settle; None where the run stopped before it was computed."""
    vial_steady_C: Celsius | None = None
    """The vial's steady temperature."""
    air_steady_C: Celsius | None = None
    """The inner air's steady temperature."""
    holder_steady_C: Celsius | None = None
    """The holder's steady temperature (``clamp_steady_C`` in version 1); None without a holder node."""
    other_nodes_steady_C: dict[str, Celsius] = Field(default_factory=dict)
    """The steady temperature of each further node that no key above names, by name; flat keys
    ``{node}_steady_C``."""
    balls_steady_C: list[Celsius] | None = None
    """Each ball's steady temperature, ball 0 first (an engine of several balls)."""
    slowest_time_constant_min: Minutes | None = None
    """The thermal network's slowest time constant at the steady state: a run of several of them has settled."""
    steady_state_heat_power_W: Watts | None = None
    """The mean heat power the steady state was computed for."""
    steady_state_message: str | None = None
    """``solved``, or why the steady state was not found."""

    # ------------------------------------------------------------------ impacts
    impacts: int
    """Impacts in the run (the averaged solver: its window's rate times the duration)."""
    impact_rate_hz: PerSecond
    """Impacts per second, over the impact table's span (the whole run, or the averaging window)."""
    hit_rate_hz: PerSecond
    """Impacts per second at or above 0.1 m/s (``HIT_SPEED``): the hits that count, without the chatter."""
    mean_hit_speed_m_s: MetresPerSecond
    """Mean speed of those hits; NaN without any."""
    fast_impact_rate_hz: PerSecond
    """Impacts per second at or above 1 m/s (``FAST_IMPACT_SPEED``)."""
    mean_impact_speed_m_s: MetresPerSecond
    """Mean normal impact speed; NaN without impacts."""
    max_impact_speed_m_s: MetresPerSecond
    """Fastest impact; NaN without impacts."""
    mean_dissipated_per_impact_J: Joules
    """Mean energy dissipated per impact; NaN without impacts."""

    # ------------------------------------------------------------------ heat and power
    heat_power_W: Watts
    """Mean irreversible heat generation of the contacts, η times the dissipated power."""
    dissipated_power_W: Watts
    """Mean power dissipated in the contacts."""
    drive_heat_W: Watts
    """Mean heat the drive puts into the holder whatever the balls do (``drive_heat``; 0 without a holder)."""
    heat_paths_W: dict[str, Watts] = Field(default_factory=dict)
    """Each heat path's mean flow over the run, from its hot end to its cold end, by the path's name (``ball → air``,
    ``vial → room, convection``, ...; MODEL.md §13.1)."""
    dissipated_by_channel_W: dict[str, Watts] = Field(default_factory=dict)
    """Mean power dissipated in each channel of the engine (``normal``, ``tangential``, ``sliding``, ``rolling`` for
    the 'dem' engine; MODEL.md §12.4), by channel; flat keys ``dissipated_{channel}_W``. Empty for an engine that does
    not split its dissipation."""
    heat_by_channel_W: dict[str, Watts] = Field(default_factory=dict)
    """η times ``dissipated_by_channel_W``: the heat made in each channel; flat keys ``heat_{channel}_W``."""

    # ------------------------------------------------------------------ an engine of several balls
    engine: str | None = None
    """The engine (``dem``); None for the one-ball engine."""
    n_balls: int | None = None
    """The number of balls (an engine of several balls)."""
    fill_fraction: float | None = None
    """The share of the vial's inner volume the balls take."""
    wall_impacts: int | None = None
    """Impacts on the vial's walls in the run."""
    ball_ball_impacts: int | None = None
    """Impacts between balls in the run."""
    work_gravity_J: Joules | None = None
    """Work done by gravity on the balls over the run."""
    work_stiffening_J: Joules | None = None
    """Energy the tangential springs gained by stiffening with the load (``work_by_stiffening``)."""
    charge_regime: str | None = None
    """``pack`` (lasting contacts, under one impact above 1 m/s per ball and turn) or ``active`` (MODEL.md §14.2)."""

    # ------------------------------------------------------------------ numerics
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

    # ------------------------------------------------------------------ inputs echoed in the units people quote
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

    # ------------------------------------------------------------------ the stress-energy spectrum (guide: planetary)
    stress_window_s: Seconds
    """The seconds over which the impacts were resolved (the averaged solver: its mechanics)."""
    stress_lasting_power_W: Watts
    """The power the contacts lasting over 1 ms dissipated (rolling, sliding, resting under load)."""
    stress_lasting_share: float
    """The share of the dissipated power in those lasting contacts, which no median below describes."""
    stress_lasting_contacts_hz: PerSecond
    """Contacts per second that lasted over 1 ms."""
    stress_energy_median_J: Joules
    """Median stress energy of the impacts (the energy each dissipated); NaN without impacts."""
    stress_energy_p90_J: Joules
    """90th percentile of the impacts' stress energy."""
    stress_energy_normal_median_J: Joules
    """Median of the normal part (damping of the normal force)."""
    stress_energy_normal_p90_J: Joules
    """90th percentile of the normal part."""
    stress_energy_tangential_median_J: Joules
    """Median of the tangential part (tangential damping, sliding, rolling resistance)."""
    stress_energy_tangential_p90_J: Joules
    """90th percentile of the tangential part."""
    stress_energy_kinetic_median_J: Joules
    """Median of Kwade's stress energy ½·m*·v_n² at first touch."""
    stress_energy_kinetic_p90_J: Joules
    """90th percentile of Kwade's stress energy."""
    stress_energy_wall_median_J: Joules
    """Median stress energy of the impacts on the vial; NaN without any."""
    stress_energy_wall_p90_J: Joules
    """90th percentile of the impacts on the vial."""
    stress_energy_ball_median_J: Joules
    """Median stress energy of the impacts between balls; NaN without any."""
    stress_energy_ball_p90_J: Joules
    """90th percentile of the impacts between balls."""
    stress_events_above_hz: dict[str, PerSecond] = Field(default_factory=dict)
    """Impacts per second at or above each threshold of ``stress_energy_thresholds``, by the threshold's name
    (``0.001J``); flat keys ``stress_events_above_{threshold}_hz``."""
    stress_power_above_W: dict[str, Watts] = Field(default_factory=dict)
    """The power of those impacts, by threshold; flat keys ``stress_power_above_{threshold}_W``."""

    # ------------------------------------------------------------------ the averaged solver (MODEL.md §14)
    averaged_heat_power_W: Watts | None = None
    """Mean heat power of the settled motion (averaged solver)."""
    averaged_heat_power_stderr_W: Watts | None = None
    """Its standard error, from batch means."""
    averaged_dissipated_power_W: Watts | None = None
    """Mean dissipated power of the settled motion."""
    averaged_velocity_term: float | None = None
    """Mean Whitaker velocity term 0.4·Re^½ + 0.06·Re^⅔ of the settled motion."""
    averaged_velocity_term_stderr: float | None = None
    """Its standard error."""
    averaging_transient_s: Seconds | None = None
    """The start-up transient cut before averaging."""
    averaging_window_s: Seconds | None = None
    """The seconds averaged over."""
    averaging_batches: int | None = None
    """Batches of the batch means."""
    averaging_replicas: int | None = None
    """Independent replicas of the mechanics pooled."""
    averaging_batch_s: Seconds | None = None
    """Length of a batch after grouping to uncorrelated means."""
    averaging_batch_autocorrelation: float | None = None
    """The largest |lag-1 autocorrelation| of the batches' heat and velocity term."""
    averaging_transient_heat_power_W: Watts | None = None
    """Mean heat power of the transient cut."""
    averaging_converged: bool | None = None
    """Whether the averages converged to their tolerance."""
    averaging_message: str | None = None
    """How the averaging ended, in words."""

    # ------------------------------------------------------------------ the attractor probe (solvers/attractors.py)
    n_attractors: int | None = None
    """Settled motions reached from the probed starts."""
    heat_power_spread_W: Watts | None = None
    """Largest minus smallest heat power across those attractors."""
    heat_power_spread_relative: float | None = None
    """That spread over the configured start's heat power."""
    attractor_failed_starts: int | None = None
    """Probed starts that did not settle."""

    # ------------------------------------------------------------------ a preset's findings (shakermill run)
    validation_caveat: str | None = None
    """What the preset's validation found where it failed or is missing."""
    ball_C_low: Celsius | None = None
    """Lower end of the 90 % interval of ``ball_C`` (a calibrated preset's run; ``studies/uncertainty.py``)."""
    ball_C_high: Celsius | None = None
    """Upper end of that interval."""
    vial_C_low: Celsius | None = None
    """Lower end of the 90 % interval of ``vial_C``."""
    vial_C_high: Celsius | None = None
    """Upper end of that interval."""
    ball_steady_C_low: Celsius | None = None
    """Lower end of the 90 % interval of ``ball_steady_C``."""
    ball_steady_C_high: Celsius | None = None
    """Upper end of that interval."""
    vial_steady_C_low: Celsius | None = None
    """Lower end of the 90 % interval of ``vial_steady_C``."""
    vial_steady_C_high: Celsius | None = None
    """Upper end of that interval."""
    interval_note: str | None = None
    """What the intervals carry (the calibration's uncertainty, the averaging error)."""

    # ------------------------------------------------------------------ what a user should know
    warnings: list[str] = Field(default_factory=list)
    """One line each: what a user should know that did not stop the run."""
    notes: list[str] = Field(default_factory=list)
    """Sentences of advice that is not a problem (how the solver was chosen, a run shorter than its steady state)."""

    @model_validator(mode="before")
    @classmethod
    def _families_gathered(cls, data: Any) -> Any:
        """Flat keys (as :meth:`flat` gives them) into the model: each family's keys into its mapping."""
        if not isinstance(data, Mapping):
            return data
        values: dict[str, Any] = {}
        for name, value in data.items():
            family = _family_of(name) if name not in cls.model_fields else None
            if family is None:
                values[name] = value
            else:
                values.setdefault(family.field, {})[family.member(name)] = value
        return values

    @model_validator(mode="after")
    def _members_named_apart(self) -> Summary:
        for family in FAMILIES:
            for member in getattr(self, family.field):
                if family.name(member) in type(self).model_fields or not member:
                    raise ValueError(f"{family.pattern}: the member {member!r} would name another key")
        return self

    # ------------------------------------------------------------------ reading
    def value(self, name: str) -> Any:
        """The value of the key ``name`` (a flat name, as in ``summary.json``: ``ball_C``, ``heat_normal_W``); None
        where this run has no such optional key. Raises :class:`SummaryKeyError` for a name that is not declared, and
        for a family's key that this run has no member of (``heat_normall_W``): a family's members are the run's."""
        declared(name)
        if name in type(self).model_fields:
            return getattr(self, name)
        family = _family_of(name)
        assert family is not None  # declared() found it
        members = getattr(self, family.field)
        member = family.member(name)
        if member not in members:
            close = difflib.get_close_matches(name, list(self.flat()), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise SummaryKeyError(
                f"{name!r} is no key of this run's summary (its {family.placeholder}s: "
                f"{', '.join(members) or 'none'}){hint}"
            )
        return members[member]

    def number(self, name: str) -> float:
        """:meth:`value` as a float: NaN where this run has no such optional key. Raises :class:`SummaryKeyError` as
        :meth:`value` does, ``TypeError`` for a key that is no number."""
        value = self.value(name)
        if value is None:
            return math.nan
        if isinstance(value, (str, list, dict)):
            raise TypeError(f"summary key {name!r} is not a number")
        return float(value)

    def has(self, name: str) -> bool:
        """Whether this run's summary holds the key ``name``: declared, not None, a family's member of this run. Raises
        :class:`SummaryKeyError` for a name that is not declared."""
        declared(name)
        try:
            return self.value(name) is not None
        except SummaryKeyError:
            return False

    def further_nodes(self) -> dict[str, tuple[float, float | None]]:
        """The nodes of this run's thermal network beyond the balls, the vial and the air (the holder, and those of the
        family ``{node}_C``: the powder), each with its temperature at the end and its steady temperature (°C; None
        where the steady state was not computed), by name: for readers that loop over the nodes."""
        named = {"holder": (self.holder_C, self.holder_steady_C)}
        named.update({node: (end, self.other_nodes_steady_C.get(node)) for node, end in self.other_nodes_C.items()})
        return {node: (end, steady) for node, (end, steady) in named.items() if end is not None}

    def flat(self) -> dict[str, Any]:
        """Every key this run has, flat as ``summary.json`` stores it (the families spread, optional keys left out
        where None), in the order declared."""
        values: dict[str, Any] = {}
        families = {family.field: family for family in FAMILIES}
        for name in type(self).model_fields:
            value = getattr(self, name)
            if name in families:
                values.update({families[name].name(member): item for member, item in value.items()})
            elif value is not None:
                values[name] = type(value)(value) if isinstance(value, (list, dict)) else value
        return values

    def updated(self, **values: Any) -> Summary:
        """A copy with the keys ``values`` (flat names) added or changed, checked against the schema (:meth:`of`)."""
        return type(self).of({**self.flat(), **values})

    @classmethod
    def of(cls, values: Mapping[str, Any]) -> Summary:
        """The summary of flat ``values`` (a family's keys spread, None for a key the run does not have). Raises
        :class:`SummaryKeyError` for a key that is not declared and ``ValueError`` for a value of the wrong kind,
        each in one line."""
        try:
            return cls.model_validate(dict(values))
        except ValidationError as exc:
            first = exc.errors()[0]
            if first["type"] == "extra_forbidden":
                raise SummaryKeyError(_unknown(".".join(str(part) for part in first["loc"]))) from None
            raise ValueError(_first_problem(exc)) from None

    def __getitem__(self, name: str) -> Any:
        raise TypeError(
            f"a Summary is read by attribute (summary.{name}) or, for a name chosen at run time, with "
            f"summary.value({name!r}); summary.flat() is the flat dict of summary.json"
        )

    def __contains__(self, name: object) -> bool:
        raise TypeError(
            f"a Summary holds every declared key: summary.has({name!r}) says whether this run has a value for it"
        )

    def __len__(self) -> int:
        return len(self.flat())

    @classmethod
    def from_flat(cls, values: Mapping[str, Any]) -> Summary:
        """The summary of flat ``values`` as ``summary.json`` stores them: a null where a number is declared (a
        number that was not finite) is NaN. Raises ``ValueError`` in one line for a key that is not declared or a
        value of the wrong kind."""
        numbers = number_fields()
        read = {}
        for name, value in values.items():
            family = _family_of(name) if name not in cls.model_fields else None
            read[name] = _nan_for_null(value) if (family.field if family else name) in numbers else value
        try:
            return cls.of(read)
        except SummaryKeyError as exc:
            raise ValueError(str(exc)) from None


# ---------------------------------------------------------------------- families


@dataclass(frozen=True)
class KeyFamily:
    """Keys named after a member that depends on the run: ``pattern`` with ``{placeholder}``, the members held by the
    :class:`Summary` mapping ``field``; a member's name matches ``member_pattern`` (a regular expression)."""

    field: str
    pattern: str
    placeholder: str
    member_pattern: str = ".+"

    @property
    def regex(self) -> re.Pattern[str]:
        before, _, after = self.pattern.partition("{" + self.placeholder + "}")
        return re.compile(f"{re.escape(before)}({self.member_pattern}){re.escape(after)}")

    def name(self, member: str) -> str:
        """The flat key of ``member``."""
        return self.pattern.replace("{" + self.placeholder + "}", member)

    def member(self, name: str) -> str:
        match = self.regex.fullmatch(name)
        if match is None:
            raise SummaryKeyError(f"{name!r} is not a key of the family {self.pattern}")
        return match.group(1)


# A node's name in its keys: one word of lower-case letters (``lid``), so that no other key reads as a node's.
NODE_NAME = "[a-z]+"
FAMILIES = (
    KeyFamily("dissipated_by_channel_W", "dissipated_{channel}_W", "channel"),
    KeyFamily("heat_by_channel_W", "heat_{channel}_W", "channel"),
    KeyFamily("stress_events_above_hz", "stress_events_above_{threshold}_hz", "threshold"),
    KeyFamily("stress_power_above_W", "stress_power_above_{threshold}_W", "threshold"),
    KeyFamily("other_nodes_C", "{node}_C", "node", NODE_NAME),
    KeyFamily("other_nodes_steady_C", "{node}_steady_C", "node", NODE_NAME),
)


def _family_of(name: str) -> KeyFamily | None:
    return next((family for family in FAMILIES if family.regex.fullmatch(name)), None)


# ---------------------------------------------------------------------- the declarations


@dataclass(frozen=True)
class SummaryKey:
    """One declared key: its flat name (a family's pattern), unit ("" for none), meaning, and whether every run has
    it."""

    name: str
    unit: str
    meaning: str
    required: bool


def _unit_in(annotation: Any) -> str | None:
    if typing.get_origin(annotation) is Annotated:
        unit = next((item for item in annotation.__metadata__ if isinstance(item, Unit)), None)
        if unit is not None:
            return unit.symbol
    return next((found for arg in typing.get_args(annotation) if (found := _unit_in(arg)) is not None), None)


def _is_number(annotation: Any) -> bool:
    if annotation is float:
        return True
    return any(_is_number(arg) for arg in typing.get_args(annotation) if arg is not str)


@cache
def _annotations() -> dict[str, Any]:
    return typing.get_type_hints(Summary, include_extras=True)


@cache
def _fixed_fields() -> frozenset[str]:
    return frozenset(Summary.model_fields) - {family.field for family in FAMILIES}


@cache
def number_fields() -> frozenset[str]:
    """The fields that hold numbers (alone, in a list or by member): JSON's null in them is a number not finite."""
    return frozenset(name for name, annotation in _annotations().items() if _is_number(annotation))


@cache
def summary_keys() -> tuple[SummaryKey, ...]:
    """Every declared key in the order of :class:`Summary`, a family by its pattern."""
    families = {family.field: family for family in FAMILIES}
    keys = []
    for name, field in Summary.model_fields.items():
        shown = families[name].pattern if name in families else name
        meaning = " ".join((field.description or "").split())
        keys.append(SummaryKey(shown, _unit_in(_annotations()[name]) or "", meaning, field.is_required()))
    return tuple(keys)


def declared(name: str) -> SummaryKey:
    """The declaration of the key ``name`` (a flat name; a family's member by its pattern). Raises
    :class:`SummaryKeyError`, with the nearest declared key, for a name that is not one."""
    if name in _fixed_fields():
        return _by_name()[name]
    family = next((family for family in FAMILIES if family.field == name), None) or _family_of(name)
    if family is not None:
        return _by_name()[family.pattern]
    close = difflib.get_close_matches(name, list(_by_name()), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise SummaryKeyError(f"{name!r} is not a summary key (solvers/summary.py){hint}")


@cache
def _by_name() -> dict[str, SummaryKey]:
    return {key.name: key for key in summary_keys()}


def declared_name(name: str) -> str:
    """``name``, once :func:`declared` has checked that it is a summary key: for a table column or a list of keys
    chosen by name (``table[declared_name("ball_C")]``)."""
    declared(name)
    return name


def declared_names(names: Iterable[str]) -> tuple[str, ...]:
    """:func:`declared_name` of each of ``names``."""
    return tuple(declared_name(name) for name in names)


def unit_of(name: str) -> str:
    """The unit of the key ``name`` ("" for none)."""
    return declared(name).unit


def family_members(names: Iterable[str], pattern: str) -> dict[str, str]:
    """Of ``names`` (a table's columns), those of the family ``pattern``, each with its member:
    ``{"stress_power_above_0.001J_W": "0.001J"}``."""
    family = next((family for family in FAMILIES if family.pattern == pattern), None)
    if family is None:
        raise SummaryKeyError(f"{pattern!r} is not a family of summary keys; declared: {[f.pattern for f in FAMILIES]}")
    return {name: family.member(name) for name in names if family.regex.fullmatch(name)}


def node_key(node: str) -> str:
    """The name a thermal network's node has in the summary's keys (``holder`` for an engine's ``clamp``)."""
    return RENAMED_NODES.get(node, node)


def _nan_for_null(value: Any) -> Any:
    """A null where a number is declared, as the value or inside a list or mapping of numbers: NaN."""
    if value is None:
        return math.nan
    if isinstance(value, list):
        return [math.nan if item is None else item for item in value]
    if isinstance(value, Mapping):
        return {key: math.nan if item is None else item for key, item in value.items()}
    return value


def _first_problem(error: ValidationError) -> str:
    """The first problem pydantic found, in one line: ``summary key 'impacts': Input should be a valid integer``."""
    first = error.errors()[0]
    where = ".".join(str(part) for part in first["loc"]) or "summary"
    if first["type"] == "extra_forbidden":
        return str(SummaryKeyError(_unknown(where)))
    if first["type"] == "missing":
        return f"no summary key {where!r}"
    return f"summary key {where!r}: {first['msg']}"


def _unknown(name: str) -> str:
    try:
        declared(name)
    except SummaryKeyError as exc:
        return str(exc)
    return f"{name!r} is not a summary key"
