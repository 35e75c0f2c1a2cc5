"""The file of a fitted preset: its values over the preset it refines, the conditions they were fitted under and the
fit's provenance, as TOML that ``shakermill run FILE`` reads (written atomically)."""

from __future__ import annotations

from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import tomli_w

from shakermill.support.atomic import remove_abandoned_writes, write_text_atomically
from shakermill.support.version import __version__

if TYPE_CHECKING:
    from shakermill.studies.calibration.calibrate import Calibration


def write_preset(
    calibration: Calibration,
    path: Path | str,
    *,
    base_preset: str,
    command: str,
    description: str,
    settings: Mapping[str, Any] | None = None,
) -> Path:
    """Write a preset TOML usable with ``shakermill run FILE`` and as a shipped preset, with provenance: the fitted
    values over ``base_preset`` and the ``settings`` (SI values) under which they were fitted, without which the
    fitted values would describe another mill."""
    values = {key: calibration.fitted[key] for key in calibration.free}
    document = {
        "preset": base_preset,
        **{key: value for key, value in (settings or {}).items() if key not in values},
        **values,
        "provenance": {
            "description": description,
            "command": command,
            "fitted": list(calibration.free),
            "targets": calibration.targets,
            "achieved": calibration.achieved,
            "relative_residuals": calibration.relative_residuals,
            "sensitivities": calibration.sensitivities,
            "parameter_stderr": calibration.parameter_stderr,
            "predictions": calibration.predictions,
            "defensible": calibration.defensible,
            "at_bounds": calibration.at_bounds,
            "start": calibration.start,
            "solver": calibration.solver,
            "evaluations": calibration.evaluations,
            "message": calibration.message,
            "shakermill_version": __version__,
            "date_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        },
    }
    # TOML has no null: a fit that does not determine its covariance or samples no posterior leaves the key out.
    if calibration.covariance is not None:
        document["provenance"]["covariance_log"] = calibration.covariance
    if calibration.posterior is not None:
        document["provenance"]["posterior_log"] = calibration.posterior.logarithms.tolist()
    if calibration.curve_rms_K is not None:
        document["provenance"]["curve_rms_K"] = calibration.curve_rms_K
        document["provenance"]["curve"] = calibration.curve_source
    return write_preset_file(
        path, f"# shakermill preset fitted by calibration; keys not listed come from {base_preset!r}.", document
    )


def write_preset_file(path: Path | str, header: str, document: Mapping[str, Any]) -> Path:
    """A fitted preset's TOML ``document`` under its comment ``header``, written atomically (its folder made)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_abandoned_writes(path.parent)
    return write_text_atomically(path, f"{header}\n" + tomli_w.dumps(document))
