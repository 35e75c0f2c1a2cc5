"""Validated, immutable run parameters with the canonical keys of MODEL.md section 9 (:class:`Parameters`: every key
group of ``parameters/groups/`` gathered), what is known of each key (its unit, bounds, allowed values and meaning)
and their construction from user values (:func:`build_parameters`).

Every numeric field is SI. Users may give strings with units ("25 mm"); they are converted by :mod:`guards`
before validation, so a ``Parameters`` object only ever holds floats in SI. The checks across keys are in
:mod:`consistency`, the presets with their citations in :mod:`presets`.
"""

from __future__ import annotations

import difflib
import math
import typing
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Literal

import annotated_types
from pydantic import ConfigDict, ValidationError, field_validator, model_validator

from shakermill.parameters import consistency, guards, materials
from shakermill.parameters.bounds import Bounds
from shakermill.parameters.derived import DerivedQuantities
from shakermill.parameters.engine_keys import ENGINE_KEYS
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.fields import LONGEST_RUN_S, MAX_HARMONICS, MAX_STRESS_THRESHOLDS, one_of
from shakermill.parameters.geometry import balls_for_fill
from shakermill.parameters.groups import COMPONENTS, marked
from shakermill.parameters.groups.balls import PER_BALL_KEY_OF
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.parameters.motions import MAX_MOTION_HARMONIC, MOTION_COORDINATES
from shakermill.parameters.units import UnitError
from shakermill.support.limits import MAX_BALLS, MAX_RECORD_WINDOWS, MAX_RECORDED_SECONDS, QUOTED_LENGTH, quoted
from shakermill.support.presenters import present


class CoreParameters(DerivedQuantities):
    """The core keys of a run (``CoreKeys``), the quantities derived from them, the checks across keys and what a run's
    parameters do; :class:`Parameters` adds the components' keys."""

    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True, allow_inf_nan=False)

    @field_validator("engine")
    @classmethod
    def _known_engine(cls, name: Any) -> Any:
        return one_of(name, ENGINE_KEYS)

    @model_validator(mode="after")
    def _consistent(self) -> CoreParameters:
        """The checks across keys (:mod:`consistency`) and of the per-ball values' bounds, in this order: the first
        problem is the one reported."""
        consistency.ball_fits_vial(self)
        consistency.outside_holds_the_bore(self)
        consistency.fill_sets_the_balls(self, PER_BALL_KEYS)
        consistency.engine_takes_the_keys(self)
        for key in PER_BALL_KEYS:
            _check_per_ball(key, getattr(self, key), self.n_balls)
        consistency.motion_is_well_formed(self)
        consistency.balls_fit_side_by_side(self)
        consistency.components_are_consistent(self)
        consistency.stored_data_fit_in_memory(self)
        consistency.thermal_network_is_not_stiff(self)
        consistency.thresholds_are_distinct(self)
        return self

    @property
    def thermal_time_constants_at_rest(self) -> dict[str, tuple[float, tuple[str, ...]]]:
        """Heat capacity over conductance of each node that evolves (s), and the keys that set it
        (:func:`consistency.thermal_time_constants_at_rest`)."""
        return consistency.thermal_time_constants_at_rest(self)

    def _repr_html_(self) -> str:
        return present("parameters html", self)

    def replace(self, **changes: Any) -> Parameters:
        """A new validated ``Parameters`` with ``changes`` applied (values may carry units)."""
        current = self.model_dump()
        if self.fill > 0 and "fill" not in changes:
            # fill made n_balls: it makes it again for the changed ball or vial.
            del current["n_balls"]
        return build_parameters(current, changes)


if TYPE_CHECKING:
    # To mypy a run's parameters are their core keys: a component reads its own keys through its group
    # (``PowderHeat.of(params)``), and a key read by a name no core group declares is an error.
    class Parameters(CoreParameters):
        pass

else:

    class Parameters(*reversed(COMPONENTS), CoreParameters):
        """One run's keys: every group of ``parameters/groups/`` gathered with the names users type (MODEL.md section
        9), the core groups' and the components' (found in that folder at import).

        Every key has hard bounds: a value outside them is refused with one line naming the key and its range. They
        are wide enough for any real mill (PLAUSIBLE_RANGES warns about the merely unusual inside them) and tight
        enough that the model and its integrator stay meaningful and finish; the comment above each field in its group
        says why its bounds are where they are.
        """


FIELD_NAMES: tuple[str, ...] = tuple(Parameters.model_fields)


# The per-ball list keys and the scalar key each one refines.
PER_BALL_KEYS = tuple(PER_BALL_KEY_OF.values())
SCALAR_KEY_OF = {per_ball: scalar for scalar, per_ball in PER_BALL_KEY_OF.items()}
# The keys that name materials (``material_name`` fields and the per-ball list of names).
MATERIAL_KEYS = tuple(key for key in FIELD_NAMES if marked(key, "material"))


def _check_per_ball(key: str, values: tuple[float, ...], n_balls: int) -> None:
    if values and len(values) != n_balls:
        raise ValueError(
            f"{key}: {len(values)} values for n_balls = {n_balls}; allowed an empty list or exactly {n_balls} values"
        )
    scalar = SCALAR_KEY_OF[key]
    for number, value in enumerate(values, start=1):
        if not bounds(scalar).contains(value):
            shown = _shown_value(value)
            raise ValueError(f"{key}: value {number} ({shown}) is out of range; allowed {allowed_range(scalar, value)}")


def field_unit(key: str) -> str:
    return str(marked(key, "unit") or "")


def field_description(key: str) -> str:
    return str(marked(key, "description") or "")


def field_source(key: str) -> str:
    """Where ``key``'s default (the paper's preset's value) comes from."""
    return str(marked(key, "source") or "")


def thermal_only(key: str) -> bool:
    """Whether ``key`` enters the thermal network alone, never a force, a contact's heat or what the stepping measures
    (fields.py)."""
    return bool(marked(key, "thermal_only"))


def bounds(key: str) -> Bounds:
    """The hard bounds of the numeric ``key``, from its field's constraints."""
    low, high, low_open, high_open = -math.inf, math.inf, True, True
    for constraint in Parameters.model_fields[key].metadata:
        if isinstance(constraint, annotated_types.Gt):
            low, low_open = _number(constraint.gt), True
        elif isinstance(constraint, annotated_types.Ge):
            low, low_open = _number(constraint.ge), False
        elif isinstance(constraint, annotated_types.Lt):
            high, high_open = _number(constraint.lt), True
        elif isinstance(constraint, annotated_types.Le):
            high, high_open = _number(constraint.le), False
    return Bounds(float(low), float(high), low_open, high_open)


def _number(bound: object) -> float:
    """A field's bound as a float: every key's bounds are numbers (parameters/fields.py)."""
    if not isinstance(bound, (int, float)):
        raise TypeError(f"a key's bound is a number, not {bound!r}")
    return float(bound)


def allowed_range(key: str, refused: Any = None) -> str:
    """Human-readable allowed values of ``key`` from its field constraints, e.g. '(0, 1]', its bounds in
    enough digits to tell them from the ``refused`` value."""
    field = Parameters.model_fields[key]
    choices = choices_of(key)
    if choices:
        return "one of " + ", ".join(repr(choice) for choice in choices)
    if field.annotation is bool:
        return "true or false"
    if key == "stress_energy_thresholds":
        return f"at most {MAX_STRESS_THRESHOLDS} energies in J, each in [1e-09, 1000]"
    if key == "record_windows":
        return (
            f"at most {MAX_RECORD_WINDOWS} (start, length) pairs in s, start in [0, {LONGEST_RUN_S:g}], length > 0, "
            f"{MAX_RECORDED_SECONDS:g} s of the run in all"
        )
    if key in PER_BALL_KEYS:
        return f"an empty list or n_balls values, each in {allowed_range(SCALAR_KEY_OF[key], refused)}"
    if key in MATERIAL_KEYS:
        return materials.allowed_for(key)
    if key == "motion":
        return (
            f"at most {MAX_HARMONICS} (coordinate, k, cos, sin) terms: coordinate one of "
            f"{', '.join(MOTION_COORDINATES)}, "
            f"k in [0, {MAX_MOTION_HARMONIC}], translations in m, angles in rad"
        )
    shown = bounds(key).shown(refused if isinstance(refused, float) else None)
    if field.annotation is int:
        return f"a whole number in {shown}"
    return f"{shown} {field_unit(key)}".rstrip()


def layered(lower: Mapping[str, Any], upper: Mapping[str, Any]) -> dict[str, Any]:
    """``upper``'s values over ``lower``'s. A fill > 0 in ``upper`` sets the number of balls itself, so it
    replaces ``lower``'s n_balls; an n_balls in ``upper`` stays, and must agree with it."""
    merged = {**lower, **upper}
    if "n_balls" not in upper and "fill" in upper and _coerce("fill", upper["fill"]) > 0:
        merged.pop("n_balls", None)
    return merged


def _with_balls_of_fill(values: dict[str, Any]) -> dict[str, Any]:
    """SI ``values`` with the n_balls their fill > 0 makes, where no layer gave n_balls (:func:`layered`)."""
    if "n_balls" in values or not values.get("fill", 0) > 0:
        return values
    radius, length, diameter = (values.get(key) for key in ("ball_radius", "vial_length", "vial_diameter"))
    # A missing or non-positive length gets its own error, as does a count beyond MAX_BALLS: fill's, which
    # names fill, rather than n_balls' bounds.
    count = 1
    if isinstance(radius, float) and isinstance(length, float) and isinstance(diameter, float):
        count = balls_for_fill(values["fill"], radius, length, diameter) if min(radius, length, diameter) > 0 else 1
    return {**values, "n_balls": min(count, MAX_BALLS)}


def with_materials(layer: Mapping[str, Any]) -> dict[str, Any]:
    """``layer`` (a preset, a file, the ``--set`` overrides, a sweep point) with the values its materials fill in.

    A key that ``layer`` sets itself wins over its material, and a later layer wins over both: each layer is
    completed on its own before the layers are merged, so ``--set ball_material=wc`` replaces the preset's
    steel density, while a file's ``ball_density`` beside its ``ball_material`` is kept.
    """
    return {**{key: value for key, (value, _) in material_sources(layer).items()}, **layer}


def material_sources(layer: Mapping[str, Any]) -> dict[str, tuple[Any, str]]:
    """The keys that the materials named in ``layer`` stand for, each with the material's value and source."""
    single = tuple(key for key in MATERIAL_KEYS if key.endswith("_material"))
    return materials.filled_keys(layer, FIELD_NAMES, PER_BALL_KEY_OF, single)


def choices_of(key: str) -> tuple[str, ...]:
    """The names an option takes (the engines' for ``engine``); () for a key that is no option."""
    if key == "engine":
        return tuple(ENGINE_KEYS)
    if key == "kinematics":
        return tuple(KINEMATIC_MODELS)
    annotation = Parameters.model_fields[key].annotation
    return typing.get_args(annotation) if typing.get_origin(annotation) is Literal else ()


def takes_names(key: str) -> bool:
    """Whether ``key`` takes one name: a material or one of an option's choices."""
    annotation = Parameters.model_fields[key].annotation
    return annotation is str or typing.get_origin(annotation) is Literal


def checked_name(key: str, value: Any) -> str:
    """``value`` of a key that :func:`takes_names`, checked: its canonical name (a material's alias resolved)."""
    if key in MATERIAL_KEYS:
        return str(materials.names_in(key, value))
    if value not in choices_of(key):
        raise ParameterError(f"{key}: {quoted(value)} is not allowed; allowed {allowed_range(key)}")
    return str(value)


def check_known_keys(keys: list[str] | tuple[str, ...], *, extra_allowed: tuple[str, ...] = ()) -> None:
    """Raise :class:`ParameterError` with a did-you-mean suggestion for the first unknown key."""
    known = FIELD_NAMES + extra_allowed
    for key in keys:
        if key not in known:
            # A key longer than any known one is no typo of one; it is quoted short so the line stays readable.
            close = difflib.get_close_matches(key, known, n=1) if len(key) <= QUOTED_LENGTH else []
            hint = f"; did you mean {close[0]!r}?" if close else "; `shakermill keys WORD` finds the keys about WORD"
            shown = key if len(key) <= QUOTED_LENGTH else quoted(key)
            raise ParameterError(f"{shown}: unknown parameter{hint}")


def unit_slip(key: str, value: float) -> str | None:
    """Why ``value`` (SI) of ``key`` looks like a unit slip (:func:`guards.unit_slip`); None if plausible."""
    return guards.unit_slip(key, value, field_unit(key))


def unit_slip_warnings(params: Parameters) -> list[str]:
    """One line per value outside :data:`guards.PLAUSIBLE_RANGES` (see :func:`unit_slip`)."""
    return [line for key in guards.PLAUSIBLE_RANGES if (line := unit_slip(key, getattr(params, key))) is not None]


def _coerce(key: str, value: Any) -> Any:
    """Convert a user value for ``key`` to SI (strings with units) or to the option's type.

    Raises :class:`ParameterError` naming the key and its allowed values.
    """
    annotation = Parameters.model_fields[key].annotation
    try:
        if annotation is float:
            return bounds(key).snapped(guards.quantity(key, value, field_unit(key)))
        if annotation is int:
            return guards.whole_number(key, value)
        if annotation is bool:
            return guards.switch(key, value)
        if key == "record_windows":
            return guards.windows(value)
        if key == "stress_energy_thresholds":
            return guards.quantity_list(key, value, "J", "a list of energies")
        if key in PER_BALL_KEYS:
            scalar = SCALAR_KEY_OF[key]
            return tuple(map(bounds(scalar).snapped, guards.per_ball(key, value, field_unit(scalar))))
        if key == "motion":
            return guards.motion(value)
        if key in MATERIAL_KEYS:
            return materials.names_in(key, value)
    except UnitError as exc:
        raise ParameterError(f"{exc}; allowed {allowed_range(key)}") from None
    return value  # one of a few names: the model checks it


RANGE_ERRORS = frozenset({"greater_than", "greater_than_equal", "less_than", "less_than_equal"})


def _shown_value(value: Any) -> str:
    """A float as short as it reads back exactly (1e+12, not 1000000000000.0); anything else quoted short."""
    if isinstance(value, float) and float(f"{value:g}") == value:
        return f"{value:g}"
    return quoted(value)


def _one_line(error: ValidationError) -> str:
    first = error.errors()[0]
    location = first.get("loc") or ()
    key = str(location[0]) if location else ""
    if key not in Parameters.model_fields:
        return str(first["msg"]).removeprefix("Value error, ")
    value = _shown_value(first.get("input"))
    message = str(first["msg"])
    problem = (
        f"{value} is out of range"
        if first.get("type") in RANGE_ERRORS
        else f"{message[:1].lower()}{message[1:]} (got {value})"
    )
    return f"{key}: {problem}; allowed {allowed_range(key, first.get('input'))}"


def build_parameters(base: Mapping[str, Any], overrides: Mapping[str, Any] | None = None) -> Parameters:
    """Validate ``base`` updated with ``overrides`` (:func:`layered`) into :class:`Parameters`, each completed
    by its materials first (:func:`with_materials`); a fill > 0 makes n_balls where neither layer above it does.

    Raises :class:`ParameterError` with one line that names the offending key.
    """
    merged = layered(with_materials(base), with_materials(overrides or {}))
    check_known_keys(list(merged))
    coerced = _with_balls_of_fill({key: _coerce(key, value) for key, value in merged.items()})
    missing = [key for key in FIELD_NAMES if key not in coerced]
    if missing:
        raise ParameterError(f"{missing[0]}: no value given and no preset supplies one")
    try:
        return Parameters(**coerced)
    except ValidationError as exc:
        raise ParameterError(_with_unit_hint(_one_line(exc), coerced)) from None


def _with_unit_hint(message: str, values: Mapping[str, Any]) -> str:
    """``message`` about a key, with the unit slip behind it when there is one.

    A ball of 6.35 m does not fit the vial: the geometry error alone would hide the slip.
    """
    key = message.partition(":")[0]
    slip = unit_slip(key, values[key]) if key in guards.PLAUSIBLE_RANGES else None
    return message if slip is None else f"{message} ({slip})"
