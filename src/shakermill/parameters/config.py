"""Run configuration: a preset, an optional TOML file and ``--set KEY=VALUE`` overrides.

Precedence, lowest first: the preset (``spex8000m`` unless the file's ``preset``
or the command line's ``--preset`` names another, the command line winning),
then the file's values, then the ``--set`` overrides. The TOML file holds the
canonical keys at top level; values may be numbers, booleans, strings with
units ("25 mm") and, for ``record_windows``, an array of ``[start, length]``
pairs. A ``[provenance]`` table, as written by :func:`write_config_toml`, is
ignored on loading, so a stored run's ``config.toml`` reproduces its parameters.
"""

from __future__ import annotations

import dataclasses
import platform
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import tomli_w

from shakermill.parameters import guards
from shakermill.parameters.assumed import inherited_assumed
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.engine_keys import reader_for, reader_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.file_models import FittedProvenance, read_table
from shakermill.parameters.keys import (
    Parameters,
    bounds,
    build_parameters,
    field_description,
    field_unit,
    layered,
    with_materials,
)
from shakermill.parameters.presets import PRESETS, Cited, Preset, default_parameters, preset_values
from shakermill.parameters.units import UnitError
from shakermill.support.atomic import write_text_atomically
from shakermill.support.limits import MAX_CONFIG_BYTES, quoted
from shakermill.support.version import __version__

PRESET_KEY = "preset"
PROVENANCE_TABLE = "provenance"
# A configuration's own ranges of assumed inputs (MODEL.md §14.1): [assumed.KEY] tables, as a preset file's.
ASSUMED_TABLE = "assumed"
SI_NOTE = "all values are SI (m, kg, s, K, rad, Pa, J, W); strings with units are accepted on input"


@dataclass(frozen=True)
class RunConfig:
    """Validated parameters and where they came from."""

    params: Parameters
    preset: str
    source: Path | None
    # Sentences for the user that are no problem: the preset's keys that this run does not read.
    notes: tuple[str, ...] = ()
    # The file's [assumed.KEY] tables and [provenance] (a calibration's), unchecked: parameters/assumed.py reads them.
    assumed_tables: Mapping[str, Any] = field(default_factory=dict)
    provenance: Mapping[str, Any] = field(default_factory=dict)
    # The keys the user set: on the command line (--set) or in a configuration written by hand (a file shakermill
    # wrote sets every key, the user's or not). A command reads each as given or refuses it; no posterior replaces it.
    explicit: tuple[str, ...] = ()


def load_config(
    path: Path | str | None = None,
    *,
    preset: str | None = None,
    overrides: Sequence[str] = (),
    reader: str | None = "run",
) -> RunConfig:
    """Resolve ``preset`` < file at ``path`` < ``overrides`` ("KEY=VALUE" strings) into parameters.

    Raises :class:`ParameterError` with one line for any bad input: a missing or
    malformed file, a bad override, an unknown key or a value out of range, and a key set explicitly (an override,
    or a key of a file written by hand) that the run would not read: by its engine, or, with ``reader`` "run", by its
    solver ("averaged": the solver of the command, whatever the parameters name; None: no check, for a command that
    reads the keys its own way). The preset's keys that it would not read are ignored, and said in ``notes``.
    """
    file_values: dict[str, Any] = {}
    file_preset: str | None = None
    source = Path(path) if path is not None else None
    written_by_hand = False
    tables: dict[str, Any] = {"assumed_tables": {}, "provenance": {}}
    if source is not None:
        document = _config_document(source)
        written_by_hand = PROVENANCE_TABLE not in document
        tables = {"assumed_tables": document.pop(ASSUMED_TABLE, {}), "provenance": document.pop(PROVENANCE_TABLE, {})}
        file_values = resolve_aliases(document)
        file_preset = _file_preset(file_values, source)
    # An empty --preset names no preset: refused as unknown, not read as "the default".
    chosen_preset = preset if preset is not None else file_preset or DEFAULT_PRESET
    # Each layer completed by its own materials first: a file's material replaces the preset's values.
    preset_layer = preset_values(chosen_preset)
    base = layered(with_materials(preset_layer), with_materials(file_values))
    asked = parse_overrides(overrides)
    params = build_parameters(base, asked)
    explicit = tuple(dict.fromkeys([*(key for key in file_values if written_by_hand), *asked]))
    if reader is None:
        return RunConfig(params=params, preset=chosen_preset, source=source, explicit=explicit, **tables)
    run = reader_of(params, None if reader == "run" else reader)
    problem = run.unread_problem(explicit)
    if problem is not None:
        raise ParameterError(problem)
    inherited = {key: value for key, value in preset_layer.items() if key not in explicit}
    defaults = preset_values(DEFAULT_PRESET)
    preset_reader = reader_for(preset_layer)
    notes = [run.ignored_note(inherited, defaults, preset_reader)]
    if file_preset is not None and chosen_preset != file_preset:
        notes.append(f"The preset is {chosen_preset!r} (--preset), not the {file_preset!r} that {source} names.")
    config = RunConfig(
        params=params,
        preset=chosen_preset,
        source=source,
        notes=tuple(note for note in notes if note),
        explicit=explicit,
        **tables,
    )
    if config.assumed_tables or "fitted" in config.provenance:
        # Its [assumed.KEY] tables and a calibration's [provenance] checked now, with one line for the first that is
        # wrong.
        config_preset(config)
    return config


def config_preset(config: RunConfig) -> Preset:
    """The preset a run of ``config`` stands on: its named preset, with the file's own [assumed.KEY] tables (which
    replace the preset's ranges) and, for a file a calibration wrote, the keys it fitted and their posterior."""
    base = PRESETS[config.preset]
    if config.source is None:
        return base
    if "fitted" in config.provenance:
        fitted = read_table(FittedProvenance, config.provenance, f"{config.source}: [provenance]").fitted
        note = f"fitted by calibration ({config.source.name}, [provenance])"
        values = {**base.values, **{key: Cited(getattr(config.params, key), note) for key in fitted}}
        base = dataclasses.replace(
            base, name=config.source.stem, values=values, fitted=fitted, provenance=config.provenance
        )
    tables = config.assumed_tables
    if not isinstance(tables, Mapping):
        raise ParameterError(f"{config.source}: [assumed] must hold tables [assumed.KEY]")
    reader = reader_of(config.params)
    problem = reader.unread_problem([key for key in tables if key in Parameters.model_fields], how="given a range")
    if problem is not None:
        raise ParameterError(f"{config.source}: [assumed]: {problem}")
    assumed = inherited_assumed(
        base.assumed, tables, config.params.model_dump(), base.fitted, reader, config.source.name
    )
    return dataclasses.replace(base, assumed=assumed)


def read_config_file(path: Path) -> dict[str, Any]:
    """The parameter entries of a TOML configuration (``preset`` included, ``[provenance]`` dropped)."""
    document = _config_document(path)
    document.pop(PROVENANCE_TABLE, None)
    document.pop(ASSUMED_TABLE, None)
    return document


def _config_document(path: Path) -> dict[str, Any]:
    """The whole TOML document of a configuration, ``[provenance]`` included where it has one."""
    text = _config_text(path)
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        # tomllib's message already ends with "(at line L, column C)".
        raise ParameterError(f"{path}: malformed TOML: {exc}") from None
    except ValueError:  # an integer of more digits than Python converts
        raise ParameterError(f"{path}: malformed TOML: a number too long to read") from None
    return document


def _config_text(path: Path) -> str:
    """The text of the TOML file at ``path``, or :class:`ParameterError` with one line saying why not."""
    try:
        with path.open("rb") as stream:
            # One byte more than allowed tells a file at the limit from a longer one without reading it all.
            data = stream.read(MAX_CONFIG_BYTES + 1)
    except FileNotFoundError:
        raise ParameterError(f"{path}: no such configuration file") from None
    except IsADirectoryError:
        raise ParameterError(f"{path}: is a directory, expected a TOML configuration file") from None
    except OSError as exc:
        raise ParameterError(f"{path}: cannot read the configuration file ({exc.strerror})") from None
    if len(data) > MAX_CONFIG_BYTES:
        raise ParameterError(f"{path}: larger than {MAX_CONFIG_BYTES:,} bytes; a configuration holds a few kilobytes")
    try:
        # -sig: editors on Windows start UTF-8 files with a byte-order mark, which TOML itself does not allow.
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ParameterError(
            f"{path}: not UTF-8 text (byte {data[exc.start]:#04x} at offset {exc.start}); save it as UTF-8"
        ) from None


def _file_preset(values: dict[str, Any], path: Path) -> str | None:
    """Remove and return the file's ``preset`` entry; it names a preset, it is not a parameter."""
    name = values.pop(PRESET_KEY, None)
    if name is not None and not isinstance(name, str):
        raise ParameterError(f"{path}: preset must be a string naming a preset, got {quoted(name)}")
    return name


# Names people type for a quantity that a key takes in another form: a ball's diameter is twice its radius.
HALVED_ALIASES = {"ball_diameter": "ball_radius"}


def halved(alias: str, value: Any) -> float:
    """The value of the key an alias of :data:`HALVED_ALIASES` stands for (SI): half of ``value``, a length with or
    without its unit; one line naming the alias for a value that is no length or out of twice the key's range."""
    key = HALVED_ALIASES[alias]
    try:
        length = guards.quantity(alias, value, field_unit(key))
    except UnitError as exc:
        raise ParameterError(f"{exc}; allowed {twice_range(key)}") from None
    # Refused in the user's terms: the radius's range would name a key the user never typed.
    if not bounds(key).contains(bounds(key).snapped(length / 2.0)):
        raise ParameterError(f"{alias}: {length:g} {field_unit(key)} is out of range; allowed {twice_range(key)}")
    return length / 2.0


def resolve_aliases(layer: Mapping[str, Any]) -> dict[str, Any]:
    """``layer`` with each alias of :data:`HALVED_ALIASES` replaced by its key, the value converted to SI and halved;
    one line for a layer that gives both, or a value that is no length."""
    found = dict(layer)
    for alias, key in HALVED_ALIASES.items():
        if alias not in found:
            continue
        if key in found:
            raise ParameterError(f"{alias}: give {key} or {alias} (twice {key}), not both")
        found[key] = halved(alias, found.pop(alias))
    return found


def twice_range(key: str) -> str:
    """The lengths an alias of ``key`` (twice it) allows, in words."""
    low, high = (2.0 * bound for bound in (bounds(key).low, bounds(key).high))
    return f"a length from {low:g} to {high:g} {field_unit(key)} (twice {key})"


def parse_overrides(items: Sequence[str]) -> dict[str, Any]:
    """``["restitution=0.8", "duration=2 min"]`` -> ``{"restitution": "0.8", "duration": "2 min"}``; later wins; an
    alias people type (``ball_diameter="10 mm"``) becomes its key's SI value (``ball_radius`` 0.005)."""
    overrides: dict[str, Any] = {}
    for item in items:
        key, separator, value = item.partition("=")
        key = key.strip()
        if not separator or not key:
            raise ParameterError(f"--set {quoted(item)}: expected KEY=VALUE, for example --set restitution=0.8")
        overrides[key] = value.strip()
    return resolve_aliases(overrides)


def config_toml_text(
    params: Parameters,
    *,
    preset: str,
    extra_provenance: Mapping[str, Any] | None = None,
) -> str:
    """The TOML text of :func:`write_config_toml`: one commented entry per key, then ``[provenance]``."""
    entries = [f"# shakermill run configuration; {SI_NOTE}.", tomli_w.dumps({PRESET_KEY: preset})]
    for key, value in params.model_dump().items():
        unit = field_unit(key)
        comment = f"# {field_description(key)}" + (f" [{unit}]" if unit else "")
        if key == "n_balls" and params.fill > 0:
            # Written as a value, it would contradict fill as soon as the file is run with another ball or vial.
            entries.append(f"{comment}\n# n_balls = {value}: follows from fill\n")
            continue
        entries.append(comment + "\n" + tomli_w.dumps({key: value}))
    entries.append(tomli_w.dumps({PROVENANCE_TABLE: _provenance(preset, extra_provenance or {})}))
    return "\n".join(entries)


def values_beyond_preset(params: Parameters, preset: str) -> dict[str, Any]:
    """The values of ``params`` that differ from those of ``preset``, as a configuration file writes them (SI);
    ``n_balls`` is left out where ``fill`` sets it."""
    ours, theirs = params.model_dump(), default_parameters(preset).model_dump()
    return {
        key: value for key, value in ours.items() if value != theirs[key] and not (key == "n_balls" and params.fill > 0)
    }


def _provenance(preset: str, extra: Mapping[str, Any]) -> dict[str, Any]:
    provenance: dict[str, Any] = {
        "shakermill_version": __version__,
        "preset": preset,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "units": SI_NOTE,
    }
    # TOML has no null; absent values are simply left out.
    provenance.update({key: value for key, value in extra.items() if value is not None})
    return provenance


def write_config_toml(
    params: Parameters,
    path: Path | str,
    *,
    preset: str,
    extra_provenance: Mapping[str, Any] | None = None,
) -> Path:
    """Write ``params`` as a TOML file that :func:`load_config` turns back into equal parameters.

    Floats are written with their shortest exact representation, so the round
    trip is exact. The file replaces any previous one atomically.
    """
    return write_text_atomically(path, config_toml_text(params, preset=preset, extra_provenance=extra_provenance))
