"""scripts/setup, the README's first step: quiet when it works, and the installer's own words when it fails.

Run in a sandbox: a copy of the script, and a PATH of only the tools it uses, where ``apt-get`` and
``python`` are stand-ins that record their arguments (nothing is installed) and there is no Chromium.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DEBCONF = "debconf: delaying package configuration, since apt-utils is not installed"
"""What apt-get prints on stderr in a fresh Debian container, even with -qq (seen in scripts/setup's output)."""


def _sandbox(tmp_path: Path, apt_status: int) -> Path:
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("bash", "dirname", "mktemp", "cat", "rm"):
        (bin_dir / tool).symlink_to(shutil.which(tool))
    stand_ins = {
        "id": "echo 0",  # root: no sudo
        "apt-get": f'echo "apt-get $*" >> "$LOG"; echo "{DEBCONF}" >&2; exit {apt_status}',
        "python": 'echo "python $*" >> "$LOG"; [ "$1" != -c ]',  # pip and ipykernel succeed; no import check
    }
    for name, body in stand_ins.items():
        (bin_dir / name).write_text(f"#!{shutil.which('bash')}\n{body}\n")
        (bin_dir / name).chmod(0o755)
    (tmp_path / "scripts").mkdir()
    shutil.copy(ROOT / "scripts" / "setup", tmp_path / "scripts" / "setup")
    return bin_dir


def _setup(tmp_path: Path, apt_status: int) -> subprocess.CompletedProcess:
    bin_dir = _sandbox(tmp_path, apt_status)
    env = {"PATH": str(bin_dir), "LOG": str(tmp_path / "log"), "HOME": str(tmp_path)}
    return subprocess.run(
        [str(bin_dir / "bash"), str(tmp_path / "scripts" / "setup")], env=env, capture_output=True, text=True
    )


def test_setup_lets_no_apt_chatter_through(tmp_path):
    """apt-get's debconf line on stderr is not shown when apt-get succeeds; Chromium and the extras are asked."""
    done = _setup(tmp_path, apt_status=0)
    assert (done.returncode, done.stdout, done.stderr) == (0, "", "")
    log = (tmp_path / "log").read_text()
    assert "apt-get install -y -qq --no-install-recommends chromium" in log
    assert "python -m pip install --quiet -e .[test]" in log


@pytest.mark.parametrize("status", [1, 100])
def test_setup_shows_what_apt_said_when_it_fails(tmp_path, status):
    done = _setup(tmp_path, apt_status=status)
    assert done.returncode != 0 and DEBCONF in done.stderr
