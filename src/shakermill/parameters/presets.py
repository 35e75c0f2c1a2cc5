"""Presets: named parameter sets with a source for every value (the PyBaMM habit of parameter sets with citations).

The paper's SPEX 8000M (:data:`SPEX_8000M`) is built in; every other preset is a TOML file in ``presets/`` on top
of the preset it names as its base: for a calibration, the fit (command, targets, residuals, date, version) in
``[provenance]``; for a hand-made preset, ``[provenance.sources]``, the source of each value it sets.
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shakermill.parameters.assumed import AssumedInput, inherited_assumed
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.engine_keys import reader_for
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.groups import default_of
from shakermill.parameters.keys import FIELD_NAMES, Parameters, build_parameters, field_source, material_sources


@dataclass(frozen=True)
class Cited:
    """A preset value with where it comes from."""

    value: Any
    source: str


@dataclass(frozen=True)
class Preset:
    """A named parameter set. ``fitted`` names the keys a calibration set, ``provenance`` says how."""

    name: str
    description: str
    values: Mapping[str, Cited]
    fitted: tuple[str, ...] = ()
    provenance: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    # The inputs no source fixes, with their ranges (MODEL.md §14.1, parameters/assumed.py).
    assumed: Mapping[str, AssumedInput] = dataclasses.field(default_factory=dict)

    @property
    def covariance(self) -> list[list[float]] | None:
        """The calibration's covariance of the logarithms of ``fitted`` (in that order), if it recorded one."""
        return self.provenance.get("covariance_log")

    @property
    def caveat(self) -> str | None:
        """What the validation of this preset's temperatures found, where they failed a held-out test or were never
        tested (``[provenance.validation] caveat`` of its file): every run and report of the preset says it."""
        return self.provenance.get("validation", {}).get("caveat")

    def caveat_for(self, values: Mapping[str, Any], refitted: Sequence[str] = ()) -> str | None:
        """:attr:`caveat`, said of a run with ``values``: where the run changed keys a calibration fitted, or its
        configuration is a fitted file that refits ``refitted``, what was found is of the preset as shipped."""
        if not self.caveat:
            return None
        changed = [key for key in self.fitted if key in values and values[key] != self.values[key].value]
        if refitted:
            return (
                f"{self.caveat} (This run's configuration refits {', '.join(refitted)} to its own measurement "
                "(calibrate): what was found is of the preset as shipped; read the fit's own errors.)"
            )
        if not changed:
            return self.caveat
        return (
            f"{self.caveat} (This run changes {', '.join(changed)}, which the calibration fitted: what was found "
            "is of the preset as shipped.)"
        )

    @property
    def posterior(self) -> list[list[float]] | None:
        """The calibration's posterior samples of the logarithms of ``fitted``, if it recorded them."""
        return self.provenance.get("posterior_log")


# The paper's SPEX 8000M is the keys' defaults, each with its source, as the key groups declare them
# (parameters/groups/).
SPEX_8000M = Preset(
    name=DEFAULT_PRESET,
    description="SPEX 8000M Mixer/Mill, one 12.7 mm steel ball, as in Son 2025 (published parameters).",
    values={key: Cited(default_of(key), field_source(key)) for key in FIELD_NAMES},
)


# Presets other than the paper's ship as TOML files next to this module: a base preset, the values that
# differ and a [provenance] table: for a calibration, the fit (command, targets, residuals, date, version);
# for a hand-made preset, [provenance.sources], the source of each value it sets.
PRESET_FOLDER = Path(__file__).parent / "presets"


def load_preset_file(path: Path, known: Mapping[str, Preset]) -> Preset:
    """A preset from a calibration TOML file, on top of the preset it names as its base."""
    with path.open("rb") as handle:
        data = tomllib.load(handle)
    provenance = dict(data.pop("provenance", {}))
    assumed_tables = data.pop("assumed", {})
    base = known[data.pop("preset")]
    fitted = tuple(provenance.get("fitted", ()))
    sources = provenance.get("sources", {})
    note = f"fitted by calibration ({path.name}, [provenance])"
    values = {**base.values, **{key: Cited(value, source) for key, (value, source) in material_sources(data).items()}}
    for key, value in data.items():
        source = note if key in fitted else sources.get(key, f"set in {path.name}")
        values[key] = Cited(tuple(map(tuple, value)) if key == "record_windows" else value, source)
    plain = {key: cited.value for key, cited in values.items()}
    # A preset's ranges are of its mill whatever its own charge: a range of two balls' keys serves a run of more balls
    # (--set n_balls), though the preset's own has one; a run that cannot feel it does not vary it (ensemble_inputs).
    reader = reader_for({**plain, "n_balls": max(2, plain["n_balls"])})
    return Preset(
        name=path.stem,
        description=str(provenance.get("description", f"{base.name} with values from {path.name}")),
        values=values,
        fitted=fitted,
        provenance=provenance,
        assumed=inherited_assumed(base.assumed, assumed_tables, plain, fitted, reader, path.name),
    )


def load_presets(folder: Path, built_in: Preset) -> dict[str, Preset]:
    """The built-in preset and every TOML file of ``folder``, each loaded after the preset it builds on."""
    presets = {built_in.name: built_in}
    waiting = {path.stem: path for path in sorted(folder.glob("*.toml"))}
    bases = {name: _base_of(path) for name, path in waiting.items()}
    while waiting:
        ready = [name for name in waiting if bases[name] in presets]
        if not ready:
            raise ValueError(
                f"presets {', '.join(sorted(waiting))} build on presets that do not exist or on each other"
            )
        for name in ready:
            presets[name] = load_preset_file(waiting.pop(name), presets)
    return presets


def _base_of(path: Path) -> str:
    with path.open("rb") as handle:
        return str(tomllib.load(handle).get("preset", ""))


PRESETS: dict[str, Preset] = load_presets(PRESET_FOLDER, SPEX_8000M)


def preset_values(name: str) -> dict[str, Any]:
    if name not in PRESETS:
        raise ParameterError(f"preset: unknown preset {name!r}; available: {', '.join(sorted(PRESETS))}")
    return {key: cited.value for key, cited in PRESETS[name].values.items()}


def default_parameters(preset: str = DEFAULT_PRESET, **overrides: Any) -> Parameters:
    """The parameters of ``preset`` with keyword ``overrides`` (values may carry units)."""
    return build_parameters(preset_values(preset), overrides)
