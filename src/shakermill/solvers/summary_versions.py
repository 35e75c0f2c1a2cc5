"""The versions of ``summary.json``: the version a run folder's summary carries, and the reading of an older one
into the schema of ``solvers/summary.py``.

Version 1 has no ``"schema_version"`` (shakermill up to issue 39); it is read where possible
(:func:`summary_from_document`): ``clamp_C``/``clamp_steady_C`` become ``holder_C``/``holder_steady_C``
(:data:`~shakermill.solvers.summary.RENAMED_NODES`), keys a later version added are NaN
(``exponential_fit_describes_run`` true, as the readers of version 1 assumed) and keys since removed are dropped; a
document that still does not fit is refused in one line (:class:`SummaryVersionError`). Version 2: the schema of
``solvers/summary.py``, with ``"schema_version": 2``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from shakermill.solvers.summary import RENAMED_NODES, Summary, SummaryKeyError, declared, number_fields

# The version ``summary.json`` carries as "schema_version"; a document without one is version 1.
SCHEMA_VERSION = 2
VERSION_KEY = "schema_version"


class SummaryVersionError(Exception):
    """A ``summary.json`` this version cannot read: of an older schema it cannot be brought to (``older``), or of a
    newer one. Not a ``ValueError``: a reader says what to do (re-run, upgrade) rather than call the file damaged."""

    def __init__(self, message: str, *, older: bool) -> None:
        super().__init__(message)
        self.older = older


def summary_from_document(values: Any, version: Any) -> Summary:
    """The summary stored in ``summary.json`` (its ``"summary"`` object) of schema ``version`` (None: version 1).
    Raises :class:`SummaryVersionError` for a version this one cannot read (newer, or an old document that does not
    fit once brought forward) and ``ValueError`` for a current document that does not fit the schema."""
    if version is None:
        version = 1
    if type(version) is not int or version < 1:
        raise ValueError(f"{VERSION_KEY} {version!r} is not a version number")
    if version > SCHEMA_VERSION:
        raise SummaryVersionError(
            f"written by a newer shakermill (summary schema {version}; this version reads 1 to {SCHEMA_VERSION}): "
            "read it with that version, or upgrade shakermill",
            older=False,
        )
    if not isinstance(values, Mapping):
        raise ValueError("'summary' is not a JSON object")
    if version == SCHEMA_VERSION:
        return Summary.from_flat(values)
    try:
        return Summary.from_flat(_brought_forward(values))
    except ValueError as exc:
        raise SummaryVersionError(
            f"written by an older shakermill (summary schema {version}) and not readable as schema {SCHEMA_VERSION} "
            f"({exc})",
            older=True,
        ) from None


def _brought_forward(values: Mapping[str, Any]) -> dict[str, Any]:
    """A version-1 summary in this schema: the renamed nodes' keys renamed, the keys since removed dropped, the keys
    added since set to NaN (``exponential_fit_describes_run`` to true, as the readers of version 1 assumed)."""
    renamed = {}
    for name, value in values.items():
        for old, new in RENAMED_NODES.items():
            if name in (f"{old}_C", f"{old}_steady_C"):
                name = name.replace(old, new, 1)
        renamed[name] = value
    kept = {name: value for name, value in renamed.items() if _is_declared(name)}
    for name, field in Summary.model_fields.items():
        if field.is_required() and name not in kept:
            if name == "exponential_fit_describes_run":
                kept[name] = True
            elif name in number_fields():
                kept[name] = math.nan
    return kept


def _is_declared(name: str) -> bool:
    try:
        declared(name)
    except SummaryKeyError:
        return False
    return True
