"""The corpus of hostile and careless inputs (issue 12): every case ends cleanly and in time.

Each ``tests/hostile/*.toml`` file lists cases as ``[[case]]`` tables:

* ``name``    what the case is, unique across the corpus;
* ``args``    the command line after ``shakermill``; ``{tmp}`` is a fresh folder of the case's own;
* ``expect``  ``"refused"``: exit code 2 and exactly one line on stderr, ``error: ...``, containing every
  fragment of ``match`` (a string or a list); ``"ok"``: exit code 0; ``"stopped"``: exit code 1, the code
  of a run that ended with a failed status (its budget used up, results that cannot be trusted), of a
  scan or fit stopped by such a run, or of a sweep with failed points: stderr ends with exactly one
  ``error: ...`` line containing every fragment of ``match``, after nothing but ``warning: ...`` lines;
* ``seconds`` the CPU time the command may take in this process, its threads included (default 20); the case
  fails beyond it. CPU time, not the wall clock: on a loaded machine (CI's) the wall clock stretches with the load;
* ``files``   optional, files made in ``{tmp}`` first: a string (written as UTF-8), or a table
  ``{ text = "...", encoding = "utf-8-sig" }`` for any Python codec, or ``{ hex = "..." }`` for raw bytes;
* ``before``  optional, command lines run first, each of which must succeed (to build a run or sweep
  folder that the case then damages through ``files``);
* ``absent``  optional, paths (with ``{tmp}``) that must not exist afterwards: nothing that looks complete;
* ``env``     optional, environment variables set for the command alone (``SHAKERMILL_THREADS``, say).

The commands run in this process (typer's runner), so hundreds of cases take seconds, not minutes.
"""

from __future__ import annotations

import re
import time
import tomllib
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli

CORPUS = Path(__file__).resolve().parents[1] / "hostile"
DEFAULT_SECONDS = 20.0
EXIT_CODES = {"ok": 0, "stopped": 1, "refused": 2}
# What a command may say on stderr before it stops: a fit's announcement, its curves' notes, piped progress lines.
SAID_BEFORE = re.compile(r"^(calibrate: fitting |note: |[\w -]+: .*, \d+ min \d\d s$)")


def load_cases() -> list[dict[str, Any]]:
    cases = []
    for path in sorted(CORPUS.glob("*.toml")):
        with path.open("rb") as file:
            for case in tomllib.load(file)["case"]:
                cases.append({**case, "corpus": path.stem})
    return cases


CASES = load_cases()


def expand(text: str, tmp: Path) -> str:
    return text.replace("{tmp}", str(tmp))


def make_files(files: dict[str, Any], tmp: Path) -> None:
    for name, content in files.items():
        path = tmp / expand(name, tmp)
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, str):
            path.write_bytes(content.encode("utf-8"))
        elif "hex" in content:
            path.write_bytes(bytes.fromhex(content["hex"]))
        else:
            path.write_bytes(content["text"].encode(content["encoding"]))


def test_the_corpus_is_large_and_its_names_unique():
    names = [case["name"] for case in CASES]
    assert len(names) == len(set(names)), sorted(name for name in names if names.count(name) > 1)
    assert len(CASES) >= 150
    assert {case["expect"] for case in CASES} <= set(EXIT_CODES)


@pytest.fixture(name="compiled_engines", scope="module")
def compiled_engines_fixture() -> None:
    """Each engine's compiled code loaded in this process once, before any case is timed: on a fresh clone Numba
    compiles it on the first call (a minute on a busy machine), which no case's bound is about."""
    from shakermill.solvers.impact import single_impact

    single_impact(sm.default_parameters(), 1.0)
    for preset in ("spex8000m", "spex8000m-3d"):
        sm.simulate(sm.default_parameters(preset, duration=0.01, solver="full", record_windows=()))


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[f"{case['corpus']}: {case['name']}" for case in CASES])
def test_hostile_input_ends_cleanly_and_in_time(case, tmp_path, compiled_engines):
    runner = CliRunner()
    for command in case.get("before", []):
        prepared = runner.invoke(cli.app, [expand(argument, tmp_path) for argument in command])
        assert prepared.exit_code == 0, (command, prepared.stderr, prepared.exception)
    make_files(case.get("files", {}), tmp_path)
    started = time.process_time()
    outcome = runner.invoke(cli.app, [expand(argument, tmp_path) for argument in case["args"]], env=case.get("env"))
    used = time.process_time() - started
    assert used <= case.get("seconds", DEFAULT_SECONDS), f"took {used:.1f} CPU-s"
    assert "Traceback" not in outcome.stderr + outcome.stdout
    assert outcome.exit_code == EXIT_CODES[case["expect"]], (outcome.exit_code, outcome.stderr, outcome.exception)
    if case["expect"] != "ok":
        lines = outcome.stderr.strip().splitlines()
        before = lines[:-1]
        if case["expect"] == "stopped":
            # Long work says what it does and how far it is (a fit its free keys, piped progress lines) before it stops.
            before = [line for line in before if not line.startswith("warning: ") and not SAID_BEFORE.match(line)]
        assert lines and not before, outcome.stderr
        assert lines[-1].startswith("error: "), outcome.stderr
        fragments = case.get("match", [])
        for fragment in [fragments] if isinstance(fragments, str) else fragments:
            assert fragment in lines[-1], (fragment, lines[-1])
    for path in case.get("absent", []):
        assert not Path(expand(path, tmp_path)).exists(), path
