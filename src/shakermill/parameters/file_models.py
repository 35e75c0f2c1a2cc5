"""The tables users write or edit by hand, as pydantic models: an ``[assumed.KEY]`` table (:class:`AssumedTable`) and
the ``[provenance]`` of a fitted file (:class:`FittedProvenance`).

Each field is checked for what it must be before anything reads it, and a bad one is refused in one line that names
the file, the table and the field (:func:`read_table`): a hand-edited file must not reach NumPy as ragged lists, a
boolean read as 0 or a bound too large for a float.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Annotated, Any, TypeVar

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, ValidationError, field_validator, model_validator

from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.support.limits import quoted

# Uniform on [low, high], or uniform in the logarithm where the range spans orders of magnitude.
DISTRIBUTIONS = ("uniform", "log-uniform")
# The keys an input of a vial's dimensions may move with it (parameters/assumed.py), and what each follows, for a
# user who gives it a range of its own where it moves with the bowl.
DERIVED_FROM = {"inner_area": "the bore diameter and length", "vial_mass": "the vial's dimensions"}
DERIVED_KEYS = tuple(DERIVED_FROM)
ASSUMED_FIELDS = "low, high, distribution, reason (and moves, optionally)"


def finite_number(value: Any) -> float:
    """A TOML number as a float: a boolean is no number (``false`` must not read as 0), nor is an integer too large
    for a float (400 digits) or an infinity."""
    if isinstance(value, bool):
        raise ValueError(f"{str(value).lower()} is a boolean, not a number")
    if not isinstance(value, (int, float)):
        raise ValueError(f"{quoted(value)} is not a number")
    try:
        number = float(value)
    except OverflowError:
        raise ValueError(f"{str(value)[:12]}... ({len(str(value))} digits) is too large for a number") from None
    if not math.isfinite(number):
        raise ValueError(f"{quoted(value)} is not a finite number")
    return number


FiniteNumber = Annotated[float, BeforeValidator(finite_number)]


def number_rows(value: Any) -> list[list[float]]:
    """A TOML list of lists of numbers (a matrix, a set of samples), every row as long as the first."""
    if not isinstance(value, list) or not value or not all(isinstance(row, list) for row in value):
        raise ValueError(f"a list of lists of numbers, not {quoted(value)[:40]}")
    rows = [[finite_number(item) for item in row] for row in value]
    for number, row in enumerate(rows, start=1):
        if len(row) != len(rows[0]):
            raise ValueError(f"row {number} has {len(row)} values, row 1 has {len(rows[0])}")
    return rows


NumberRows = Annotated[list[list[float]], BeforeValidator(number_rows)]


class AssumedTable(BaseModel):
    """An ``[assumed.KEY]`` table: the range of an input in its key's SI unit, its distribution, the reason for it and
    the derived keys it moves (the range against the key's bounds: ``parameters.assumed.assumed_input``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    low: FiniteNumber
    high: FiniteNumber
    distribution: str
    reason: str
    moves: tuple[str, ...] = ()

    @field_validator("distribution", mode="before")
    @classmethod
    def _known_distribution(cls, value: Any) -> str:
        if value not in DISTRIBUTIONS:
            raise ValueError(f"must be one of {', '.join(DISTRIBUTIONS)}, not {quoted(value)}")
        return str(value)

    @field_validator("reason", mode="before")
    @classmethod
    def _stated_reason(cls, value: Any) -> str:
        if not isinstance(value, str) or not value.strip():
            raise ValueError("give the reason for the range, as text")
        return value

    @field_validator("moves", mode="before")
    @classmethod
    def _derived_keys(cls, value: Any) -> tuple[str, ...]:
        # Not a set test on the raw list: a list inside it ([[1]]) cannot be hashed.
        if not isinstance(value, list) or not all(isinstance(key, str) and key in DERIVED_KEYS for key in value):
            raise ValueError(
                f"lists keys derived from the vial's dimensions ({', '.join(DERIVED_KEYS)}), not {quoted(value)}"
            )
        return tuple(value)


class FittedProvenance(BaseModel):
    """The ``[provenance]`` of a file a calibration wrote, as far as a run reads it: the keys it ``fitted`` and their
    posterior, as a covariance of their logarithms and as samples of them (its other fields are the fit's record)."""

    model_config = ConfigDict(extra="allow", frozen=True)

    fitted: tuple[str, ...]
    covariance_log: NumberRows | None = None
    posterior_log: NumberRows | None = None

    @field_validator("fitted", mode="before")
    @classmethod
    def _numeric_keys(cls, value: Any) -> tuple[str, ...]:
        if not isinstance(value, list) or not value:
            raise ValueError(f"a list of the keys the calibration fitted, not {quoted(value)}")
        for key in value:
            field = Parameters.model_fields.get(key) if isinstance(key, str) else None
            if field is None or field.annotation is not float:
                raise ValueError(f"{quoted(key)} is not a numeric key of a single value")
        if len(set(value)) != len(value):
            raise ValueError("names a key twice")
        return tuple(value)

    @model_validator(mode="after")
    def _one_column_per_key(self) -> FittedProvenance:
        keys = len(self.fitted)
        if self.covariance_log is not None and np.shape(self.covariance_log) != (keys, keys):
            raise ValueError(
                f"covariance_log: a {keys} x {keys} matrix (one row and column per fitted key), not "
                f"{' x '.join(map(str, np.shape(self.covariance_log)))}"
            )
        if self.posterior_log is not None:
            check_samples(np.asarray(self.posterior_log), self.fitted)
        return self


def check_samples(samples: np.ndarray, keys: tuple[str, ...]) -> None:
    """Samples of the fitted keys' logarithms, one column per key, that spread in every key: a Gaussian is fitted to
    them, and a constant or collinear sample has no covariance to draw from."""
    if samples.shape[1] != len(keys):
        raise ValueError(f"posterior_log: {samples.shape[1]} values a sample, not one per fitted key ({len(keys)})")
    if samples.shape[0] <= len(keys):
        raise ValueError(f"posterior_log: {samples.shape[0]} samples of {len(keys)} keys; give more than {len(keys)}")
    spread = np.ptp(samples, axis=0)
    if not np.all(spread > 0):
        raise ValueError(f"posterior_log: constant in {keys[int(np.argmin(spread))]}; its samples must spread")
    if np.linalg.matrix_rank(np.cov(samples, rowvar=False).reshape(len(keys), len(keys))) < len(keys):
        raise ValueError("posterior_log: its samples lie on a line (their covariance is singular)")


Model = TypeVar("Model", bound=BaseModel)


def read_table(model: type[Model], table: Any, where: str) -> Model:
    """``table`` read as ``model``, or :class:`ParameterError` in one line: ``where``, the field and what is wrong."""
    if not isinstance(table, Mapping):
        raise ParameterError(f"{where}: a table of {ASSUMED_FIELDS if model is AssumedTable else 'fields'}")
    try:
        return model.model_validate(dict(table))
    except ValidationError as exc:
        raise ParameterError(f"{where}: {_field_problem(exc)}") from None


def _field_problem(error: ValidationError) -> str:
    first = error.errors()[0]
    field = ".".join(str(part) for part in first.get("loc", ())[:1])
    message = str(first["msg"]).removeprefix("Value error, ")
    if first["type"] == "missing":
        return (
            f"{field}: missing; give exactly {ASSUMED_FIELDS}"
            if field in AssumedTable.model_fields
            else f"{field}: missing"
        )
    if first["type"] == "extra_forbidden":
        return f"{field}: not a field of the table; give exactly {ASSUMED_FIELDS}"
    return f"{field}: {message}" if field else message
