"""``shakermill presets``, ``materials`` and ``keys``: what can be set, with units, ranges and sources."""

from __future__ import annotations

import fnmatch
import json
from collections.abc import Mapping, Sequence
from typing import Annotated, Any

import typer
from rich.table import Table
from rich.text import Text

from shakermill.cli.common import JsonOption, add_plain_row, fail, format_value, stdout_console, user_errors
from shakermill.parameters.defaults import DEFAULT_PRESET


def presets(
    name: Annotated[str | None, typer.Argument(help="Show every value of this preset with its source.")] = None,
) -> None:
    """List the presets, or show one preset's values, units and sources."""
    from shakermill.parameters.presets import PRESETS, preset_values

    console = stdout_console()
    if name is None:
        table = Table("preset", "description", title="presets")
        for preset in PRESETS.values():
            marker = " (default)" if preset.name == DEFAULT_PRESET else ""
            add_plain_row(table, preset.name + marker, preset.description)
        console.print(table)
        return
    with user_errors():
        preset_values(name)  # validates the name with the library's one-line message
    preset = PRESETS[name]
    table = Table("key", "value", "source", title=f"{preset.name}: {preset.description}")
    for key, cited in preset.values.items():
        add_plain_row(table, key, format_value(key, cited.value), cited.source)
    console.print(table)
    if preset.assumed:
        assumed = Table(
            "key",
            "value",
            "range",
            "distribution",
            "reason",
            title=f"{preset.name}: assumed inputs, no source fixes them (MODEL.md §14.1)",
        )
        for key, stated in preset.assumed.items():
            add_plain_row(
                assumed,
                key,
                format_value(key, preset.values[key].value),
                stated.shown_range(),
                stated.distribution,
                stated.reason + (f" (moves {', '.join(stated.moves)} with it)" if stated.moves else ""),
            )
        console.print(assumed)
    if preset.caveat:
        console.print(Text(f"Caveat ({preset.name}): {preset.caveat}"))


# The library's table: property, header with its unit, scale from SI.
MATERIAL_COLUMNS = (
    ("density", "ρ (kg/m³)", 1.0),
    ("youngs_modulus", "E (GPa)", 1e-9),
    ("poisson_ratio", "ν", 1.0),
    ("heat_capacity", "c (J/(kg·K))", 1.0),
    ("conductivity", "k (W/(m·K))", 1.0),
    ("restitution", "e (range, not applied)", 1.0),
    ("friction", "μ (range, not applied)", 1.0),
)


def materials_command(
    name: Annotated[
        str | None, typer.Argument(help="Show every value of this material with its unit and source.")
    ] = None,
    json_output: JsonOption = False,
) -> None:
    """List the materials library, or show one material's values, units and sources. Select one with
    --set ball_material=NAME (or vial_material, or ball_materials per ball); its restitution and friction are
    shown, never applied."""
    from shakermill.parameters.materials import UnknownMaterial, library, material

    try:
        chosen = [material(name)] if name is not None else list(library().values())
    except UnknownMaterial as exc:
        fail(str(exc))
    if json_output:
        described = [found.as_dict() for found in chosen]
        typer.echo(json.dumps(described[0] if name is not None else {"materials": described}, allow_nan=False))
        return
    stdout_console().print(material_table(chosen[0]) if name is not None else materials_table(chosen))


def _material_value(value: float | tuple[float, float], scale: float = 1.0) -> str:
    return f"{value[0]:g}-{value[1]:g}" if isinstance(value, tuple) else f"{value * scale:g}"


def materials_table(chosen: Sequence[Any]) -> Table:
    table = Table("material", *(header for _, header, _ in MATERIAL_COLUMNS), title="materials (room temperature)")
    for found in chosen:
        add_plain_row(
            table,
            found.name,
            *(_material_value(getattr(found, key).value, scale) for key, _, scale in MATERIAL_COLUMNS),
        )
    table.caption = "`shakermill materials NAME`: every value's source; restitution and friction are shown, not applied"
    return table


def material_table(found: Any) -> Table:
    from shakermill.parameters.materials import PROPERTIES

    table = Table("property", "value", "unit (SI)", "source", title=f"{found.name}: {found.description}")
    for key, sourced in found.properties().items():
        add_plain_row(table, PROPERTIES[key][1], _material_value(sourced.value), sourced.unit, sourced.source)
    aliases = f"aliases: {', '.join(found.aliases)}; " if found.aliases else ""
    table.caption = f"{aliases}select with --set ball_material={found.name} (or vial_material, ball_materials)"
    return table


def keys(
    pattern: Annotated[
        str | None,
        typer.Argument(
            metavar="PATTERN",
            help=(
                "Only the keys whose name or description contains this, case ignored, or matches it as a glob "
                "('ball_*')."
            ),
        ),
    ] = None,
    engine: Annotated[
        str | None, typer.Option("--engine", metavar="NAME", help="Only the keys this engine reads: '1d' or 'dem'.")
    ] = None,
) -> None:
    """List the canonical parameter keys, component by component, with unit, allowed values, default and
    description."""
    from shakermill.parameters.engine_keys import ENGINE_KEYS, reads
    from shakermill.parameters.groups import GROUPS
    from shakermill.parameters.keys import FIELD_NAMES, allowed_range, field_description
    from shakermill.parameters.presets import PRESETS, preset_values

    if engine is not None and engine not in ENGINE_KEYS:
        fail(f"--engine: {engine!r} is no engine; allowed {', '.join(map(repr, ENGINE_KEYS))}")
    chosen = {
        key
        for key in FIELD_NAMES
        if (engine is None or reads(engine, key))
        and (pattern is None or _matches(pattern, key, field_description(key)))
    }
    narrowed = [f"matching {pattern!r}"] if pattern is not None else []
    if engine is not None:
        narrowed.append(f"read by {ENGINE_KEYS[engine].title}")
    which = " ".join(narrowed)
    if not chosen:
        typer.echo(f"no parameter key {which}; `shakermill keys` lists all {len(FIELD_NAMES)}")
        return
    defaults = preset_values(DEFAULT_PRESET)
    console = stdout_console()
    console.print(Text(f"parameter keys {which}: {len(chosen)} of {len(FIELD_NAMES)}" if which else "parameter keys"))
    header = ("key", "allowed (SI)", f"default ({DEFAULT_PRESET})", "description")
    for group in GROUPS:
        listed = [key for key in group.keys() if key in chosen]
        if not listed:
            continue
        table = Table(*header, title=f"{group.title[:1].upper()}{group.title[1:]}", title_justify="left")
        for key in listed:
            add_plain_row(
                table,
                key,
                allowed_range(key),
                format_value(key, defaults[key]),
                field_description(key) + _assumed_note(key, PRESETS),
            )
        console.print(table)


def _assumed_note(key: str, presets: Mapping[str, Any]) -> str:
    """Where presets state ``key`` as an assumed input: its ranges and how many presets state each."""
    ranges: dict[str, int] = {}
    for preset in presets.values():
        if key in preset.assumed:
            shown = preset.assumed[key].shown_range()
            ranges[shown] = ranges.get(shown, 0) + 1
    if not ranges:
        return ""
    stated = "; ".join(f"{shown} in {count} preset{'s' if count > 1 else ''}" for shown, count in ranges.items())
    return f". Assumed, no source fixes it: {stated} (`presets NAME`)"


def _matches(pattern: str, *texts: str) -> bool:
    """Whether any of ``texts`` contains ``pattern`` or, with a wildcard in it, matches it as a glob; case ignored."""
    wanted = pattern.lower()
    globbed = any(wildcard in wanted for wildcard in "*?[")
    return any(fnmatch.fnmatchcase(text.lower(), wanted) if globbed else wanted in text.lower() for text in texts)
