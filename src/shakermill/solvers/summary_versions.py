"""The versions of ``summary.json``: the version a run folder's summary carries, and the reading of an older one
into the schema of ``solvers/summary.py``.

Version 1 has no ``"schema_version"`` (shakermill up to issue 39); it is read where possible
(:func:`summary_from_document`): ``clamp_C``/``clamp_steady_C`` become ``holder_C``/``holder_steady_C``
(:data:`~shakermill.analysis.sections.RENAMED_NODES`), keys a later version added are NaN
(``exponential_fit_describes_run`` true, as the readers of version 1 assumed) and keys since removed are dropped; a
document that still does not fit is refused in one line (:class:`SummaryVersionError`). Version 2 (issue 39): the
flat keys of the schema, with ``"schema_version": 2``. Version 3 (issue 48): the same flat keys, each now the field of
a typed section that the code computing it builds; a version-2 document is read as it is. Version 4 (issue 50): impacts
as MODEL.md §14.4 defines them, with the contact records and touches beside them, the energy-weighted stress
percentiles and the settled regime's window and measures; a version-3 document's impacts were its records, and the keys
it lacks are NaN.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from shakermill.analysis.sections import RENAMED_NODES
from shakermill.solvers.summary import Summary, SummaryKeyError, declared, holds_numbers, summary_keys

# The version ``summary.json`` carries as "schema_version"; a document without one is version 1.
SCHEMA_VERSION = 4
VERSION_KEY = "schema_version"
# What a version-1 summary that lacks them meant: the readers of version 1 showed the fit's rows, and an averaged run
# had one replica before there were several.
VERSION_1_MEANT = {"exponential_fit_describes_run": True, "averaging_replicas": 1}


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
        return Summary.from_flat(brought_forward(values, version))
    except ValueError as exc:
        raise SummaryVersionError(
            f"written by an older shakermill (summary schema {version}) and not readable as schema {SCHEMA_VERSION} "
            f"({exc})",
            older=True,
        ) from None


def brought_forward(values: Mapping[str, Any], version: int) -> dict[str, Any]:
    """The flat summary of an older ``version`` in this one's keys: each version's step to the next in turn."""
    for step in MIGRATIONS[version - 1 :]:
        values = step(values)
    return dict(values)


def _from_version_1(values: Mapping[str, Any]) -> dict[str, Any]:
    """A version-1 summary in version 2's keys: the renamed nodes' keys renamed, the keys since removed dropped, the
    keys added since, those every run has and those of every section the document has (the averaging's, ...), set to
    NaN, or to what version 1 meant (:data:`VERSION_1_MEANT`)."""
    renamed = {}
    for name, value in values.items():
        for old, new in RENAMED_NODES.items():
            if name in (f"{old}_C", f"{old}_steady_C"):
                name = name.replace(old, new, 1)
        renamed[name] = value
    kept = {name: value for name, value in renamed.items() if _is_declared(name)}
    return _added_as_nan(kept)


def _added_as_nan(kept: dict[str, Any]) -> dict[str, Any]:
    """``kept`` with the keys added since its version, those every run has and those of every section it has, set to
    NaN, or to what version 1 meant (:data:`VERSION_1_MEANT`)."""
    sections = {declared(name).section for name in kept}
    for key in summary_keys():
        due = key.required or (key.section in sections and key.in_every_section)
        if not due or key.name in kept or "{" in key.name:
            continue
        if key.name in VERSION_1_MEANT:
            kept[key.name] = VERSION_1_MEANT[key.name]
        elif holds_numbers(key.name):
            kept[key.name] = math.nan
    return kept


def _from_version_2(values: Mapping[str, Any]) -> dict[str, Any]:
    """A version-2 summary in version 3's keys: the same (version 3 types the sections that hold them)."""
    return dict(values)


def _from_version_3(values: Mapping[str, Any]) -> dict[str, Any]:
    """A version-3 summary in version 4's keys: the keys of the impacts as §14.4 defines them, NaN (its impacts were
    its contact records)."""
    return _added_as_nan(dict(values))


# The step from each version to the next, version 1's first.
MIGRATIONS: tuple[Callable[[Mapping[str, Any]], dict[str, Any]], ...] = (
    _from_version_1,
    _from_version_2,
    _from_version_3,
)


def _is_declared(name: str) -> bool:
    try:
        declared(name)
    except SummaryKeyError:
        return False
    return True
