"""`make test` on a fresh machine: the test target installs Chromium for the browser test when asked (BROWSER=1, as
CI does), and otherwise changes nothing on the machine and says how to run that test."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ENSURE_BROWSER = ROOT / "scripts" / "ensure-browser"
BASH = shutil.which("bash")

pytestmark = pytest.mark.skipif(BASH is None, reason="bash is needed to run scripts/ensure-browser")

FAKE_APT_GET = """#!/bin/sh
echo "$@" >> "{log}"
case "$*" in
  *install*chromium*) {install} ;;
esac
"""


def machine_without_chromium(tmp_path: Path, *, install_succeeds: bool) -> tuple[dict[str, str], Path]:
    """A PATH with the few commands the script uses, a fake apt-get that logs its calls, and no Chromium."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("id", "env", "sh", "chmod"):
        os.symlink(shutil.which(tool), bin_dir / tool)
    log = tmp_path / "apt-get.log"
    chromium = bin_dir / "chromium"
    install = f"printf '#!/bin/sh\\n' > {chromium} && chmod +x {chromium}" if install_succeeds else "exit 100"
    apt_get = bin_dir / "apt-get"
    apt_get.write_text(FAKE_APT_GET.format(log=log, install=install))
    apt_get.chmod(0o755)
    (bin_dir / "sudo").write_text('#!/bin/sh\nexec "$@"\n')
    (bin_dir / "sudo").chmod(0o755)
    environment = {"PATH": str(bin_dir), "HOME": str(tmp_path)}
    return environment, log


def ensure_browser(environment: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run([BASH, str(ENSURE_BROWSER)], env=environment, capture_output=True, text=True, timeout=60)


def test_make_test_runs_the_dependency_step_before_the_suite():
    plan = subprocess.run(["make", "-n", "test"], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert plan.returncode == 0, plan.stderr
    step = next(line for line in plan.stdout.splitlines() if "pytest" in line)
    assert step.index("scripts/ensure-browser") < step.index("pytest")
    assert "SHAKERMILL_BROWSER_UNAVAILABLE" in step


def test_ci_calls_make_test_and_asks_for_the_browser():
    lines = (ROOT / ".ci" / "run").read_text().strip().splitlines()
    assert lines[-1] == "make test" and "export BROWSER=1" in lines


def test_make_test_passes_the_request_for_the_browser_on():
    plan = subprocess.run(["make", "-n", "test", "BROWSER=1"], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert "BROWSER=1 scripts/ensure-browser" in plan.stdout


def test_missing_chromium_is_installed_with_apt_get_when_asked_and_nothing_else_upgraded(tmp_path):
    environment, log = machine_without_chromium(tmp_path, install_succeeds=True)
    completed = ensure_browser({**environment, "BROWSER": "1"})
    assert completed.returncode == 0, completed.stderr
    assert completed.stdout == ""  # nothing to skip: the browser test runs
    assert "install -y -qq --no-upgrade chromium" in log.read_text()
    assert (tmp_path / "bin" / "chromium").exists()


def test_a_plain_make_test_installs_nothing_and_says_how_to_run_the_browser_test(tmp_path):
    environment, log = machine_without_chromium(tmp_path, install_succeeds=True)
    completed = ensure_browser(environment)
    assert completed.returncode == 0 and not log.exists()
    reason = completed.stdout.strip()
    assert len(reason.splitlines()) == 1 and "`make test BROWSER=1` installs it" in reason
    assert not (tmp_path / "bin" / "chromium").exists()


def test_impossible_install_gives_one_line_and_a_skip_reason(tmp_path):
    environment, log = machine_without_chromium(tmp_path, install_succeeds=False)
    completed = ensure_browser({**environment, "BROWSER": "1"})
    assert completed.returncode == 0  # make goes on to the suite; the browser test skips
    reason = completed.stdout.strip()
    assert len(reason.splitlines()) == 1
    assert "chromium could not be installed" in reason and "skipped" in reason
    assert reason in completed.stderr


def test_chromium_present_or_skip_requested_installs_nothing(tmp_path):
    environment, log = machine_without_chromium(tmp_path, install_succeeds=True)
    completed = ensure_browser({**environment, "SHAKERMILL_SKIP_BROWSER": "1"})
    assert completed.returncode == 0 and completed.stdout == ""
    assert not log.exists()
