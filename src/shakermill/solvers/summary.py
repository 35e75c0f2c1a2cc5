"""The run summary: :class:`Summary`, composed of the typed sections that the code computing each part builds
(:mod:`shakermill.analysis.sections`), and every key it has in its flat form, with its unit and meaning.

:class:`Summary` is what :func:`~shakermill.solvers.result.summarize` makes (``Result.summary``). Its sections are
nested where that is clearer (``summary.temperatures`` and ``summary.steady``, each node's temperature at the end and
at steady state; ``summary.impacts``; ``summary.averaging``; the balls of an engine of several, ``summary.charge``;
the attractor probe's ``summary.attractors``; a calibrated preset's ``summary.intervals``) and their fields are the
summary's own where they are not (``summary.heat_power_W``, ``summary.steps``, ...); the headline temperatures are
attributes too (``summary.ball_C``, ``summary.ball_steady_C``). Flat, as ``summary.json`` stores it under
``"summary"`` (with ``"schema_version"`` beside it), as ``shakermill run --json`` prints it and as a sweep table has
it as columns, every number is one key: :meth:`Summary.flat`, and the summary itself is a read-only mapping over those
keys (``summary["ball_steady_C"]``, ``"holder_C" in summary``, ``list(summary)``) for a notebook.

In the package a summary is read by attribute; where a key is chosen by name at run time (a calibration target, a
compared quantity, a table column), through :meth:`Summary.value`, :meth:`Summary.number` or :func:`declared_name`,
which refuse a name that is not declared (``SummaryKeyError``, with the nearest key). No module but this one reads a
summary by a string key (``tests/test_architecture.py``).

A key that only some runs have (a section of an engine of several balls, a ``mill-head`` network's holder, the
averaged solver, the attractor probe, a calibrated preset's intervals) is absent from the flat summary when the run has
none, and None read by :meth:`Summary.value`. The keys whose names depend on the run are *families*: a mapping by
member in their section, one flat key per member after a declared pattern (``dissipated_{channel}_W``,
``heat_{channel}_W``, ``stress_events_above_{threshold}_hz``, ``stress_power_above_{threshold}_W``, and ``{node}_C``,
``{node}_steady_C`` for a node of the thermal network that no key names, as the powder). A number that is not finite is
``null`` in JSON and NaN here once read back.

The version of ``summary.json`` and the reading of older ones: ``solvers/summary_versions.py``.
"""

from __future__ import annotations

import difflib
import math
import re
import typing
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Annotated, Any

from pydantic import Field, ValidationError, model_validator

from shakermill.analysis.attractors import AttractorSection
from shakermill.analysis.fit import FitSection
from shakermill.analysis.sections import Section, Unit
from shakermill.analysis.steady import SteadySection
from shakermill.analysis.stress_energy import StressSection
from shakermill.solvers.summary_sections import (
    Averaging,
    Charge,
    EndTemperatures,
    Heat,
    Impacts,
    Inputs,
    Numerics,
    Outcome,
    PredictionIntervals,
)


class SummaryKeyError(KeyError):
    """A name that is not a declared summary key (a misspelling, or a key of another program), or a key this run's
    summary has no value for."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


# The sections whose fields are the summary's own: they are flat in Python too.
INLINED = (Outcome, FitSection, Heat, Numerics, Inputs, StressSection)


class Summary(Outcome, FitSection, Heat, Numerics, Inputs, StressSection, Mapping[str, Any]):
    """The summary of one run (``Result.summary``, ``RunData.summary``): the sections' keys, in the units their
    annotations name. Frozen: :meth:`updated` gives a copy with flat keys added or changed, checked against the schema.
    A read-only mapping over its flat keys as well (``summary["ball_C"]``)."""

    temperatures: EndTemperatures
    """Every node's temperature at the end of the run, and each ball's."""
    steady: SteadySection | None = None
    """The steady state (MODEL.md §11): every node's steady temperature and what it was computed for; None where the
    run stopped before it was computed."""
    impacts: Impacts
    """The impacts: how many, how often, how fast."""
    charge: Charge | None = None
    """The balls of an engine that moves several; None for an engine of one ball."""
    averaging: Averaging | None = None
    """What the averaged solver measured of the settled motion; None for a run at full resolution."""
    attractors: AttractorSection | None = None
    """The attractor probe's findings (``solvers/attractors.py``); None where it did not run."""
    validation_caveat: str | None = None
    """What the preset's validation found where it failed or is missing (``shakermill run``)."""
    intervals: PredictionIntervals | None = None
    """The 90 % intervals of a calibrated preset's run (``studies/calibration/intervals.py``)."""
    warnings: list[str] = Field(default_factory=list)
    """One line each: what a user should know that did not stop the run."""
    notes: list[str] = Field(default_factory=list)
    """Sentences of advice that is not a problem (how the solver was chosen, a run shorter than its steady state)."""

    @model_validator(mode="after")
    def _members_named_apart(self) -> Summary:
        for slot in _FAMILY_SLOTS:
            family = slot.family
            assert family is not None  # a family's slot
            for member in self._at(slot.path) or {}:
                if family.name(member) in _EXACT or not member:
                    raise ValueError(f"{family.pattern}: the member {member!r} would name another key")
                if not family.regex.fullmatch(family.name(member)):
                    raise ValueError(f"{family.pattern}: the member {member!r} is not {family.member_pattern}")
        return self

    @classmethod
    def compose(
        cls,
        *,
        outcome: Outcome,
        fit: FitSection,
        temperatures: EndTemperatures,
        steady: SteadySection | None,
        impacts: Impacts,
        heat: Heat,
        charge: Charge | None,
        numerics: Numerics,
        inputs: Inputs,
        stress: StressSection,
        averaging: Averaging | None,
        attractors: AttractorSection | None,
        warnings: Sequence[str],
        notes: Sequence[str],
    ) -> Summary:
        """The summary of a run's sections, each built by the code that computes it."""
        inlined = (outcome, fit, heat, numerics, inputs, stress)
        own = {name: getattr(section, name) for section in inlined for name in type(section).model_fields}
        return cls(
            **own,
            temperatures=temperatures,
            steady=steady,
            impacts=impacts,
            charge=charge,
            averaging=averaging,
            attractors=attractors,
            warnings=list(warnings),
            notes=list(notes),
        )

    def with_findings(
        self, *, validation_caveat: str | None = None, intervals: PredictionIntervals | None = None
    ) -> Summary:
        """A copy with what a preset's validation found and the 90 % intervals of a calibrated preset's run, those
        given (``shakermill run``)."""
        found = {"validation_caveat": validation_caveat, "intervals": intervals}
        return self.model_copy(update={name: value for name, value in found.items() if value is not None})

    # ------------------------------------------------------------------ the headline temperatures
    @property
    def ball_C(self) -> float:
        """The ball's temperature at the end of the run (°C; with several balls, their mean)."""
        return self.temperatures.ball

    @property
    def vial_C(self) -> float:
        """The vial's temperature at the end of the run (°C)."""
        return self.temperatures.vial

    @property
    def air_C(self) -> float:
        """The inner air's temperature at the end of the run (°C)."""
        return self.temperatures.air

    @property
    def vial_ball_ratio(self) -> float:
        """The vial's temperature rise over the ball's at the end."""
        return self.temperatures.vial_ball_ratio

    @property
    def ball_steady_C(self) -> float | None:
        """The ball's steady temperature (°C; the balls' mean); None where it was not computed."""
        return self.steady.ball if self.steady is not None else None

    @property
    def vial_steady_C(self) -> float | None:
        """The vial's steady temperature (°C); None where it was not computed."""
        return self.steady.vial if self.steady is not None else None

    @property
    def air_steady_C(self) -> float | None:
        """The inner air's steady temperature (°C); None where it was not computed."""
        return self.steady.air if self.steady is not None else None

    @property
    def slowest_time_constant_min(self) -> float | None:
        """The thermal network's slowest time constant at the steady state (min); None where it was not computed."""
        return self.steady.slowest_time_constant_min if self.steady is not None else None

    # ------------------------------------------------------------------ reading by name
    def _at(self, path: tuple[str, ...]) -> Any:
        """The value at ``path`` of attributes; None where a section on the way is absent."""
        found: Any = self
        for name in path:
            found = getattr(found, name)
            if found is None:
                return None
        return found

    def value(self, name: str) -> Any:
        """The value of the key ``name`` (a flat name, as in ``summary.json``: ``ball_C``, ``heat_normal_W``); None
        where this run has no such optional key. Raises :class:`SummaryKeyError` for a name that is not declared, and
        for a family's key that this run has no member of (``heat_normall_W``): a family's members are the run's."""
        slot, member = _slot_of(name)
        found = self._at(slot.path)
        if slot.family is None:
            return found
        members = found or {}
        if member not in members:
            close = difflib.get_close_matches(name, list(self.flat()), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise SummaryKeyError(
                f"{name!r} is no key of this run's summary (its {slot.family.placeholder}s: "
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
        steady = self.steady.by_node() if self.steady is not None else {}
        return {
            node: (end, steady.get(node))
            for node, end in self.temperatures.by_node().items()
            if node not in ("ball", "vial", "air")
        }

    def flat(self) -> dict[str, Any]:
        """Every key this run has, flat as ``summary.json`` stores it (the families spread, optional keys left out
        where None), in the order declared."""
        values: dict[str, Any] = {}
        for slot in _SLOTS:
            value = self._at(slot.path)
            if value is None:
                continue
            if slot.family is not None:
                values.update({slot.family.name(member): item for member, item in value.items()})
            else:
                values[slot.key] = _copied(value)
        return values

    def updated(self, **values: Any) -> Summary:
        """A copy with the keys ``values`` (flat names) added or changed, checked against the schema (:meth:`of`)."""
        return type(self).of({**self.flat(), **values})

    @classmethod
    def of(cls, values: Mapping[str, Any]) -> Summary:
        """The summary of flat ``values`` (a family's keys spread, None for a key the run does not have), each put into
        its section. Raises :class:`SummaryKeyError` for a key that is not declared and ``ValueError`` for a value of
        the wrong kind or a key missing, each in one line."""
        nested: dict[str, Any] = {}
        for name, value in values.items():
            slot, member = _slot_of(name)
            if value is None:
                continue
            *sections, last = slot.path
            into = nested
            for section in sections:
                into = into.setdefault(section, {})
            if slot.family is not None:
                into.setdefault(last, {})[member] = value
            else:
                into[last] = value
        try:
            return cls.model_validate(nested)
        except ValidationError as exc:
            raise ValueError(_first_problem(exc)) from None

    @classmethod
    def from_flat(cls, values: Mapping[str, Any]) -> Summary:
        """The summary of flat ``values`` as ``summary.json`` stores them: a null where a number is declared (a
        number that was not finite) is NaN. Raises ``ValueError`` in one line for a key that is not declared or a
        value of the wrong kind."""
        try:
            read = {name: _nan_for_null(value) if holds_numbers(name) else value for name, value in values.items()}
            return cls.of(read)
        except SummaryKeyError as exc:
            raise ValueError(str(exc)) from None

    # ------------------------------------------------------------------ a read-only mapping over the flat keys
    def __getitem__(self, name: str) -> Any:
        """The value of the flat key ``name`` (a copy of a list or mapping). Raises :class:`SummaryKeyError` (a
        ``KeyError``) for a name that is not declared and for a key this run has no value for."""
        value = self.value(name)
        if value is None:
            raise SummaryKeyError(f"{name!r}: this run's summary has no value for it (summary.value gives None)")
        return _copied(value)

    # A Mapping iterates over its keys, where a pydantic model iterates over (field, value) pairs: the flat keys win.
    def __iter__(self) -> Iterator[str]:  # type: ignore[override]
        return iter(self.flat())

    def __len__(self) -> int:
        return len(self.flat())


def _copied(value: Any) -> Any:
    """A list or mapping copied, so that no reader changes a frozen summary through it."""
    return type(value)(value) if isinstance(value, (list, dict)) else value


# ---------------------------------------------------------------------- the flat keys


@dataclass(frozen=True)
class KeyFamily:
    """Keys named after a member that depends on the run: ``pattern`` with ``{placeholder}``, the members held by the
    mapping at ``path`` of attributes (``("heat_by_channel_W",)``, ``("temperatures", "others")``); a member's name
    matches ``member_pattern`` (a regular expression)."""

    path: tuple[str, ...]
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


@dataclass(frozen=True)
class _Slot:
    """Where one flat key (or a family's keys) lives: its key (a family's pattern), the path of attributes to its value
    (a family's mapping) from the summary, and its declaration."""

    key: str
    path: tuple[str, ...]
    family: KeyFamily | None
    unit: str
    meaning: str
    required: bool
    in_section: bool
    numbers: bool


def _section_in(annotation: Any) -> tuple[type[Section] | None, bool]:
    """The section type a field holds (None for a value), and whether it may be None."""
    arguments = typing.get_args(annotation) or (annotation,)
    sections = [arg for arg in arguments if isinstance(arg, type) and issubclass(arg, Section)]
    return (sections[0] if sections else None), type(None) in arguments


def _slots_of(section: type[Section], names: Iterable[str], path: tuple[str, ...], required: bool) -> list[_Slot]:
    slots = []
    for name in names:
        field = section.model_fields[name]
        key = section.key_of(name)
        placeholder = re.search(r"\{(\w+)\}", key.pattern)
        family = KeyFamily((*path, name), key.pattern, placeholder.group(1), key.member) if placeholder else None
        unit = next((item.symbol for item in field.metadata if isinstance(item, Unit)), None)
        slots.append(
            _Slot(
                key.pattern,
                (*path, name),
                family,
                unit or _unit_in(field.annotation) or "",
                section.meaning_of(name),
                required and field.is_required(),
                field.is_required(),
                _is_number(field.annotation),
            )
        )
    return slots


def _summary_slots() -> tuple[_Slot, ...]:
    """Every flat key in order: the inlined sections' fields and the summary's own where they are declared, each
    nested section's fields at its place."""
    layout = [
        *Outcome.model_fields,
        *FitSection.model_fields,
        "temperatures",
        "steady",
        "impacts",
        *Heat.model_fields,
        "charge",
        *Numerics.model_fields,
        *Inputs.model_fields,
        *StressSection.model_fields,
        "averaging",
        "attractors",
        "validation_caveat",
        "intervals",
        "warnings",
        "notes",
    ]
    assert sorted(layout) == sorted(Summary.model_fields), "every field of Summary has its place"
    slots: list[_Slot] = []
    for name in layout:
        field = Summary.model_fields[name]
        section, optional = _section_in(field.annotation)
        if section is None:
            slots += _slots_of(Summary, [name], (), True)
        else:
            slots += _slots_of(section, section.model_fields, (name,), not optional)
    return tuple(slots)


def _unit_in(annotation: Any) -> str | None:
    if typing.get_origin(annotation) is Annotated:
        unit = next((item for item in annotation.__metadata__ if isinstance(item, Unit)), None)
        if unit is not None:
            return str(unit.symbol)
    return next((found for arg in typing.get_args(annotation) if (found := _unit_in(arg)) is not None), None)


def _is_number(annotation: Any) -> bool:
    if annotation is float:
        return True
    return any(_is_number(arg) for arg in typing.get_args(annotation) if arg is not str)


_SLOTS = _summary_slots()
_EXACT = {slot.key: slot for slot in _SLOTS if slot.family is None}
_FAMILY_SLOTS = tuple(slot for slot in _SLOTS if slot.family is not None)
FAMILIES = tuple(slot.family for slot in _FAMILY_SLOTS if slot.family is not None)


def _slot_of(name: str) -> tuple[_Slot, str]:
    """The slot of the flat key ``name``, and its member where it is a family's (else ""). Raises
    :class:`SummaryKeyError`, with the nearest declared key, for a name that is not one."""
    exact = _EXACT.get(name)
    if exact is not None:
        return exact, ""
    for slot in _FAMILY_SLOTS:
        assert slot.family is not None  # a family's slot
        if slot.family.regex.fullmatch(name):
            return slot, slot.family.member(name)
    close = difflib.get_close_matches(name, [slot.key for slot in _SLOTS], n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise SummaryKeyError(f"{name!r} is not a summary key (solvers/summary.py){hint}")


# ---------------------------------------------------------------------- the declarations


@dataclass(frozen=True)
class SummaryKey:
    """One declared key: its flat name (a family's pattern), unit ("" for none), meaning, whether every run has it,
    the nested section it is in ("" for the summary's own keys) and whether every summary with that section has it."""

    name: str
    unit: str
    meaning: str
    required: bool
    section: str = ""
    in_every_section: bool = False


@cache
def summary_keys() -> tuple[SummaryKey, ...]:
    """Every declared key in the order of the flat summary, a family by its pattern."""
    return tuple(
        SummaryKey(
            slot.key,
            slot.unit,
            slot.meaning,
            slot.required,
            slot.path[0] if len(slot.path) > 1 else "",
            slot.in_section,
        )
        for slot in _SLOTS
    )


@cache
def _by_name() -> dict[str, SummaryKey]:
    return {key.name: key for key in summary_keys()}


def declared(name: str) -> SummaryKey:
    """The declaration of the key ``name`` (a flat name; a family's member by its pattern). Raises
    :class:`SummaryKeyError`, with the nearest declared key, for a name that is not one."""
    return _by_name()[_slot_of(name)[0].key]


def holds_numbers(name: str) -> bool:
    """Whether the key ``name`` holds numbers (alone, in a list or by member): JSON's null in it is a number not
    finite. Raises :class:`SummaryKeyError` for a name that is not declared."""
    return _slot_of(name)[0].numbers


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


def _nan_for_null(value: Any) -> Any:
    """A null where a number is declared, as the value or inside a list or mapping of numbers: NaN."""
    if value is None:
        return math.nan
    if isinstance(value, list):
        return [math.nan if item is None else item for item in value]
    if isinstance(value, Mapping):
        return {key: math.nan if item is None else item for key, item in value.items()}
    return value


def _flat_name(location: tuple[int | str, ...]) -> str:
    """The flat key at a pydantic error's ``location`` (a path of attributes, a family's member at its end); for a
    section missing whole, its first key every run has."""
    parts = tuple(str(part) for part in location)
    for slot in _SLOTS:
        if parts[: len(slot.path)] == slot.path:
            beyond = parts[len(slot.path) :]
            return slot.family.name(beyond[0]) if slot.family is not None and beyond else slot.key
    within = [slot.key for slot in _SLOTS if slot.path[: len(parts)] == parts and slot.required]
    return within[0] if within and parts else ".".join(parts) or "summary"


def _first_problem(error: ValidationError) -> str:
    """The first problem pydantic found, in one line: ``summary key 'impacts': Input should be a valid integer``."""
    first = error.errors()[0]
    where = _flat_name(first["loc"])
    if first["type"] == "missing":
        return f"no summary key {where!r}"
    return f"summary key {where!r}: {first['msg']}"
