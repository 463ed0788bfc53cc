"""``spinectl explore``: its errors as one line, exit 2, before any server starts (the app: tests/explore)."""

from __future__ import annotations

import socket
import subprocess
import sys
from pathlib import Path

import pytest

from spinectl.cli import main

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--port", "0"], "--port must be an integer from 1 to 65535 (got '0')"),
        (["--port", "http"], "--port must be an integer from 1 to 65535 (got 'http')"),
        (["--max-sessions", "0"], "--max-sessions must be an integer from 1 to 64 (got '0')"),
        (["--max-sessions", "65"], "--max-sessions must be an integer from 1 to 64 (got '65')"),
        (["--max-sessions", "2.5"], "--max-sessions must be an integer from 1 to 64 (got '2.5')"),
        (["--preset", "nope"], "preset"),
        (["--address", ""], "--address: must name the interface to listen on, e.g. 127.0.0.1 or ::1 (got '')"),
        (["--address", "0.0.0.0"], "--address: must name one interface"),
    ],
)
def test_bad_options_are_one_line(capsys, argv, message):
    """A bad port, preset or address: one line, exit 2, before any server starts (an empty address was a
    traceback of Bokeh's origin list)."""
    assert main(["explore", "--no-browser", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_without_panel_it_says_how_to_install_it():
    """Panel absent (None in sys.modules of a fresh interpreter: any import of it fails): one line naming the extra."""
    code = "import sys; sys.modules['panel'] = None; from spinectl.cli import main; sys.exit(main(['explore']))"
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and run.stdout == ""
    assert (
        run.stderr
        == "spinectl: error: spinectl explore needs Panel (panel is missing): pip install 'spinectl[explore]'\n"
    )


def test_a_port_in_use_is_one_line(capsys):
    """Another program listens on the port: an error naming it, no traceback, no server left running, and no URL
    announced (before: the URL was printed, then the error)."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["explore", "--no-browser", "--port", str(port)]) == 2
    out, err = capsys.readouterr()
    assert err.startswith(f"spinectl: error: --port: cannot listen on 127.0.0.1:{port}") and err.count("\n") == 1
    assert out == ""
