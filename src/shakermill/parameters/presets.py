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
from shakermill.parameters.engine_keys import READER_FIELDS, Reader
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.geometry import end_faces_area
from shakermill.parameters.keys import PER_BALL_KEYS, Parameters, build_parameters, material_sources
from shakermill.parameters.kinematic_models import ASSUMED_DEFAULTS

PAPER = "Son 2025, Mathematics 13, 446"


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


SPEX_8000M = Preset(
    name=DEFAULT_PRESET,
    description="SPEX 8000M Mixer/Mill, one 12.7 mm steel ball, as in Son 2025 (published parameters).",
    values={
        "ball_radius": Cited(6.35e-3, f"{PAPER}, Table 1"),
        "vial_length": Cited(58e-3, f"{PAPER}, Table 1"),
        "vial_diameter": Cited(19e-3, f"{PAPER}, Table 1 (A_i = A_o = 567.06 mm² = 2·π·d_v²/4)"),
        "amplitude": Cited(25e-3, f"{PAPER}, Table 1 (X_v)"),
        "omega": Cited(
            111.0, "assumption: not stated (range 90-130 rad/s); ~1060 cycles/min, the SPEX 8000M on 60 Hz mains"
        ),
        "phase": Cited(0.0, "assumption"),
        "ball_density": Cited(7800.0, f"{PAPER}, Table 2"),
        "vial_density": Cited(7800.0, f"{PAPER}, Table 2"),
        "ball_youngs_modulus": Cited(200e9, f"{PAPER}, Table 2"),
        "vial_youngs_modulus": Cited(200e9, f"{PAPER}, Table 2"),
        "ball_poisson_ratio": Cited(0.3, f"{PAPER}, Table 2"),
        "vial_poisson_ratio": Cited(0.3, f"{PAPER}, Table 2"),
        "ball_heat_capacity": Cited(461.0, f"{PAPER}, Table 2"),
        "vial_heat_capacity": Cited(461.0, f"{PAPER}, Table 2"),
        "vial_mass": Cited(
            0.05,
            "assumption: not printed in the paper; the steel near the two end faces that exchanges heat with the "
            "inside and outside air. It sets the time constant, not the steady state; calibration fits it",
        ),
        "air_density": Cited(1.225, f"{PAPER}, Table 3"),
        "air_viscosity_ref": Cited(1.716e-5, f"{PAPER}, Table 3 (at 273.15 K)"),
        "air_reference_temperature": Cited(273.15, f"{PAPER}, Table 3 footnote (0 °C)"),
        "air_conductivity": Cited(0.0241, f"{PAPER}, Table 3"),
        "air_cp": Cited(1003.5, f"{PAPER}, Table 3"),
        "air_heat_capacity_ratio": Cited(1.4, "assumption: diatomic ideal gas; c_a = c_p,a/1.4 (MODEL.md section 6)"),
        "sutherland": Cited(111.0, f"{PAPER}, Table 3"),
        "h_inner": Cited(200.0, f"{PAPER}, Table 3"),
        "h_outer": Cited(45.0, f"{PAPER}, Table 3"),
        "inner_area": Cited(
            end_faces_area(19e-3), f"{PAPER}, Table 1 (A_i = 567.06 mm²: the two end faces, MODEL.md §1)"
        ),
        "outer_area": Cited(
            end_faces_area(19e-3),
            f"{PAPER}, Table 1 (A_o = 567.06 mm²: the two end faces only; a real vial also loses heat through its "
            "side, MODEL.md §11)",
        ),
        "thermal_model": Cited("paper", f"{PAPER}, section 2.3: ball, vial and air (MODEL.md section 13)"),
        "outer_diameter": Cited(
            50e-3,
            "estimate: walls ~6 mm round a Ø38 mm bore (the SPEX 8001 vial's outside is not published, "
            "docs/notes/dem-references.md §2.3); thermal_model = 'mill-head' only",
        ),
        "outer_length": Cited(
            70e-3, "estimate: ends ~6 mm beyond a 58 mm bore, as outer_diameter; thermal_model = 'mill-head' only"
        ),
        "emissivity": Cited(
            0.2,
            "assumption: machined, lightly oxidised steel, 0.1-0.3 (Incropera & DeWitt, Table A.11: stainless steel "
            "0.17-0.30, polished 0.07-0.1); thermal_model = 'mill-head' only",
        ),
        "vial_conductivity": Cited(46.6, "as ball_conductivity: hardened steel (AISI 52100, ASM data sheet)"),
        "clamp_heat_capacity": Cited(
            2000.0,
            "assumption: ~4 kg of steel in the clamp, its arm and the mill head (not published); a free parameter of "
            "calibrations with thermal_model = 'mill-head'",
        ),
        "clamp_conductance": Cited(
            10.0,
            "order of magnitude: steel-on-steel contact conductance 10³-10⁴ W/(m²·K) under clamping pressure "
            "(Madhusudana, Thermal Contact Conductance, 1996) over ~10⁻³ m² at each clamped end",
        ),
        "clamp_loss": Cited(
            3.0,
            "assumption: ~0.1 m² of clamp and head at ~25 W/(m²·K) of forced convection, plus conduction into the "
            "frame (not measured)",
        ),
        "drive_heat": Cited(0.0, "none unless measured or fitted (thermal_model = 'mill-head')"),
        "powder_mass": Cited(0.0, "none: the paper's runs are of balls alone; set it for a charge with powder"),
        "powder_material": Cited("iron", "assumption: iron, a common powder of mechanical alloying; set the charge's"),
        "powder_heat_capacity": Cited(449.0, "material iron (CRC Handbook; recalled, not re-read)"),
        "powder_heat_share": Cited(
            0.5,
            "assumption, range 0.2-0.8: powder caught between colliding bodies takes part of the impact's "
            "deformation and friction as its own (Suryanarayana, Prog. Mater. Sci. 46 (2001) 1, §5: the powder is "
            "trapped, deformed and heated at each collision; recalled); no measured share found",
        ),
        "powder_restitution": Cited(
            0.5,
            "assumption, range 0.2-0.8: a powder layer makes impacts less elastic than bare steel's 0.7 (no measured "
            "value for coated milling media found)",
        ),
        "powder_contact_coefficient": Cited(
            300.0,
            "assumption, range 50-2000: 2k/ℓ of a powder layer ℓ ≈ 0.3 mm thick with a bed conductivity k ≈ 0.05 "
            "W/(m·K) (loose metal powder in air, Zehner-Schlünder order of magnitude; recalled)",
        ),
        "restitution": Cited(0.7, f"{PAPER}, Table 4 (e)"),
        "eta": Cited(0.9, f"{PAPER}, Table 4 (η)"),
        "lam": Cited(0.368, f"{PAPER}, Table 4 (λ)"),
        "beta": Cited(0.3, f"{PAPER}, Table 4 (β, tuned by hand by the author)"),
        "duration": Cited(3600.0, f"{PAPER}, Table 4 (60 min)"),
        "ambient_temperature": Cited(293.15, f"{PAPER}, Table 3 footnote (ambient 20 °C)"),
        "initial_temperature": Cited(293.15, f"assumption: θ̇_0 of {PAPER} Table 5 implies θ_0 = 20 °C"),
        "ball_temperature_limit": Cited(
            1673.15,
            "assumption: carbon and bearing steels begin to melt near 1400 °C; above it the model does not hold",
        ),
        "ball_position": Cited(0.0, "assumption: ball starts at the vial centre"),
        "ball_momentum": Cited(0.0, "assumption: ball starts at rest"),
        "rtol": Cited(1e-3, "MATLAB ode23 default RelTol, as used by the paper"),
        "atol_position": Cited(1e-6, "MATLAB ode23 default AbsTol (1e-6, in SI)"),
        "atol_momentum": Cited(1e-6, "MATLAB ode23 default AbsTol (1e-6, in SI)"),
        "atol_temperature": Cited(1e-6, "MATLAB ode23 default AbsTol (1e-6, in SI)"),
        "output_interval": Cited(1.0, "assumption: 1 s sampling of the stored time series"),
        "solver": Cited("full", "full resolution, as the paper"),
        "averaging_rel_error": Cited(1e-3, "numerical choice: ±0.1 % on the mean heat rate, ~0.1 K on a 100 K rise"),
        "dem_averaging_rel_error": Cited(
            1e-2, "numerical choice: ±1 % on each ball's mean heat rate (~0.3 K on a 30 K rise) in ~40 s of mechanics"
        ),
        "dem_replicas": Cited(
            1, "numerical choice: one replica, as before replicas existed; set it to the cores a run may use"
        ),
        "averaging_batch_periods": Cited(16, "numerical choice: batches of 16 drive periods (~0.9 s)"),
        "averaging_min_batches": Cited(
            20, "MODEL.md §14.2: at least 20 uncorrelated batches, so that their lag-1 autocorrelation can be tested"
        ),
        "averaging_max_time": Cited(120.0, "numerical choice: 2 simulated minutes of mechanics at most"),
        "averaging_fallback": Cited("full", "numerical choice: fall back to full resolution and say so"),
        "attractor_starts": Cited(
            8,
            "numerical choice: the configured start and 7 spread over the free gap, at rest or at the vial's peak "
            "speed; ~0.02 s of mechanics each",
        ),
        "energy_projection": Cited(True, "numerical choice: projection method (Hairer, Lubich & Wanner 2006, §IV.4)"),
        "max_wall_time": Cited(
            3600.0,
            "numerical choice: an hour; the default 60-min run takes ~3 s, the same at rtol 1e-6 ~20 s, and 10⁹ steps "
            "(max_steps) ~10-20 min",
        ),
        "max_steps": Cited(
            1_000_000_000,
            "numerical choice: ~290 simulated hours at the defaults (3.4 million steps an hour), ~30 h at rtol 1e-6; "
            "beyond it the steps are tiny (a stiff node or an extreme drive)",
        ),
        "model": Cited("three_node", f"{PAPER}: ball, vial and inner air as three lumped reservoirs"),
        "no_tension": Cited(False, "MODEL.md section 2: the total force is not clipped by default"),
        "heat_model": Cited("relative", "MODEL.md section 3: frame-invariant dissipation c·ζ̇²"),
        "convection_velocity": Cited(
            "auto",
            f"{PAPER}, section 3.3 (Re from the ball's velocity) for the 1-D engine; relative to the vial for 'dem' "
            "(MODEL.md section 12.5)",
        ),
        "engine": Cited("1d", f"{PAPER}: one ball on the vial's axis"),
        "n_balls": Cited(1, f"{PAPER}: one ball"),
        "fill": Cited(0.0, "unused: n_balls gives the number of balls"),
        **{
            key: Cited("", "no material: the keys' own values (the paper's steel)")
            for key in ("ball_material", "vial_material")
        },
        "ball_materials": Cited((), "every ball takes ball_material, or the scalar keys' values"),
        **{key: Cited((), "every ball takes the scalar key's value") for key in PER_BALL_KEYS},
        "ball_conductivity": Cited(
            46.6, "AISI 52100 bearing steel at room temperature (ASM data sheet); only ratios between balls matter"
        ),
        "gravity": Cited(True, "MODEL.md section 12.1: 9.81 m/s² downward, the vial axis horizontal (engine = 'dem')"),
        "friction": Cited(
            0.3,
            "assumption: a common choice for dry steel-on-steel contacts in DEM mill studies; not measured for SPEX "
            "media (docs/notes/dem-references.md, section 3), so results should be checked against it",
        ),
        "pair_friction": Cited(
            0.3, "assumption: the ball-on-vial friction's common choice for steel on steel, no source of its own"
        ),
        "pair_restitution": Cited(
            0.7, f"{PAPER}, Table 4 (e): the paper's one e, for two balls too (no source of its own)"
        ),
        "rolling_friction": Cited(0.0, "MODEL.md section 12.3: no rolling resistance by default"),
        "kinematics": Cited("axial", f"{PAPER}: the vial moves along its axis (MODEL.md section 12.2)"),
        "motion": Cited((), "used only with kinematics = 'fourier'"),
        "revolution_radius": Cited(
            0.07,
            "Fritsch Pulverisette 7 premium line: effective sun-disc diameter 140 mm (used only by kinematics = "
            "'planetary')",
        ),
        "speed_ratio": Cited(
            -2.0, "Retsch PM 100 and Fritsch Pulverisette 7: jar to sun wheel 1 : −2 (kinematics = 'planetary')"
        ),
        "jar_tilt": Cited(0.0, "upright jars, as in the Pulverisette 7 and PM 100 (kinematics = 'planetary')"),
        **{key: Cited(value, source) for key, (value, source) in ASSUMED_DEFAULTS.items()},
        "contact_step_fraction": Cited(
            0.025,
            "numerical choice: restitution within 1e-3 of e for ball-ball and ball-wall impacts at 0.5-5 m/s (at most "
            "6.4e-4; 0.05 left 1.45e-3), the 1-D limit's heat power within 0.25 % of the converged value, five balls' "
            "within the ~1 % their statistics resolve (benchmarks/README.md, dem engine)",
        ),
        "enduring_step_fraction": Cited(
            0.05,
            "numerical choice: 20 steps a period of a contact that outlasted two of its periods; heat power and hit "
            "statistics within their statistical errors of finer steps (benchmarks/README.md, enduring contacts)",
        ),
        "max_flight_step": Cited(1e-4, "numerical choice: ~1/60 of a drive period, so the wall's motion is resolved"),
        "stress_energy_thresholds": Cited(
            (1e-3, 1e-2),
            "numerical choice: 1 mJ and 10 mJ, about the median and the upper tail of the energy a steel ball "
            "dissipates "
            "per impact in the SPEX 8000M and the planetary presets (benchmarks/README.md, stress energies)",
        ),
        "record_windows": Cited(
            ((0.0, 1.0), (600.0, 0.1)),
            f"the windows of {PAPER} Fig. 4 (first second) and Fig. 5b (100 ms at 10 min)",
        ),
    },
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
    reader = Reader(*(plain[field] for field in READER_FIELDS))
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
