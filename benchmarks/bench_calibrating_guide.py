"""The calibration guide's example end to end, as docs/guide/calibrating.md writes it (issue 37, point 1), timed.

Copies the guide's ``my-mill.toml`` and ``vial.csv`` into a fresh folder and runs, with the repository's
``.venv/bin/shakermill``, every command of its sections 1, 3 and 4 on them in turn: the short check run, the fit
(posterior included) and the fitted preset's prediction. Prints each command's wall time and exit code, the fit's
last lines and the fitted file's keys. The suite runs the fit alone without the posterior
(tests/interface/test_calibrating_guide.py). Run by hand: ~7 min on 2 cores.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GUIDE = ROOT / "docs" / "guide" / "calibrating.md"
SHAKERMILL = ROOT / ".venv" / "bin" / "shakermill"


def fenced(text: str, language: str, first_line: str) -> str:
    return next(block for block in re.findall(rf"```{language}\n(.*?)```", text, re.S) if block.startswith(first_line))


def guide_commands(text: str) -> list[list[str]]:
    """The guide's commands on my-mill.toml, in order: its check run, its fit, its prediction."""
    check = re.search(r"`shakermill (run my-mill\.toml [^`]*)`", text).group(1)
    fits = [
        line for line in text.splitlines() if line.startswith(".venv/bin/shakermill calibrate my-mill.toml --curve")
    ]
    predictions = [
        line for line in text.splitlines() if line.startswith(".venv/bin/shakermill run my-mill-fitted.toml")
    ]
    return [shlex.split(check), *(shlex.split(line)[1:] for line in (fits[0], predictions[0]))]


def main() -> None:
    text = GUIDE.read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        (work / "my-mill.toml").write_text(fenced(text, "toml", "# my-mill.toml"), encoding="utf-8")
        (work / "vial.csv").write_text(fenced(text, "text", "time_min,vial_C"), encoding="utf-8")
        for arguments in guide_commands(text):
            started = time.perf_counter()
            completed = subprocess.run([str(SHAKERMILL), *arguments], cwd=work, capture_output=True, text=True)
            elapsed = time.perf_counter() - started
            print(f"$ shakermill {shlex.join(arguments)}\n  {elapsed:.0f} s, exit code {completed.returncode}")
            # The end of what it printed, then the last of what it said on stderr (its progress, its error).
            tail = completed.stdout.strip().splitlines()[-5:] + completed.stderr.strip().splitlines()[-1:]
            print("\n".join(f"  | {line[:160]}" for line in tail))
        fitted = tomllib.loads((work / "my-mill-fitted.toml").read_text(encoding="utf-8"))
        print(
            "my-mill-fitted.toml: "
            + ", ".join(f"{key} = {value}" for key, value in fitted.items() if not isinstance(value, dict))
        )


if __name__ == "__main__":
    main()
