"""The Rerun binary as a local process: the web viewer server, or the native viewer.

Both listen on 127.0.0.1 only, on free ports that the binary picks and logs. Why
not the SDK's ``rr.serve_grpc()`` + ``rr.serve_web_viewer()`` and ``rr.spawn()``:
in rerun-sdk 0.41 the SDK's web viewer and the spawned viewer listen on 0.0.0.0,
``GrpcServerSink(port=0).uri`` does not tell the port the OS picked, and
``rr.spawn()`` looks for ``rerun`` on PATH (absent unless the venv is activated)
and only warns when the viewer cannot open a window. We run the binary itself (not
the ``rerun`` console script, a Python wrapper whose death would leave the binary
running) and end the web server by PID.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import quote

import rerun_cli

from planner.core.errors import EnvironmentFailure

RERUN_BINARY = Path(rerun_cli.__file__).with_name("rerun")
START_TIMEOUT = 20.0

_GRPC = re.compile(r"Listening for gRPC connections on 127\.0\.0\.1:(\d+)")
_WEB = re.compile(r"Hosting a web-viewer at http://127\.0\.0\.1:(\d+)")
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


class RerunError(EnvironmentFailure):
    """Rerun cannot show it here: no display, no viewer, or a file it cannot write."""


def _grpc_url(port: str) -> str:
    return f"rerun+http://127.0.0.1:{port}/proxy"


def _start(what: str, options: list[str], patterns, *, detach: bool, settle: float = 0.0):
    """Start the binary on 127.0.0.1 and wait until its log shows every pattern, and
    it has lived ``settle`` seconds more.

    Returns the process and each pattern's first group (the ports). The log is an
    unlinked temporary file read with ``pread`` (which leaves the offset the binary
    writes at alone), so a viewer that outlives us leaves no file behind."""
    command = [str(RERUN_BINARY), "--bind", "127.0.0.1", "--port", "0", *options]
    with tempfile.TemporaryFile() as log:
        try:
            process = subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=detach,
            )
        except OSError as err:
            raise RerunError(f"cannot start {RERUN_BINARY}: {err.strerror or err}") from None
        deadline = time.monotonic() + START_TIMEOUT
        ready_at = None
        while True:
            text = _ANSI.sub("", os.pread(log.fileno(), 1 << 20, 0).decode(errors="replace"))
            found = [p.search(text) for p in patterns]
            if ready_at is None and all(found):
                ready_at = time.monotonic() + settle
            if ready_at is not None and time.monotonic() >= ready_at:
                return process, [m.group(1) for m in found]
            if process.poll() is not None or time.monotonic() > deadline:
                _stop(process)
                lines = text.strip().splitlines()
                raise RerunError(f"{what} did not start: {lines[-1] if lines else 'no output'}")
            time.sleep(0.05)


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


class WebServer:
    """``with WebServer(port) as server``: ``server.grpc_url`` to log to,
    ``server.web_url`` to open in a browser (on ``port``; 0: a free port); the
    server ends with the block."""

    def __init__(self, port: int = 0):
        self.port = port
        self.grpc_url = ""
        self.web_url = ""
        self._process: subprocess.Popen | None = None

    def __enter__(self) -> WebServer:
        options = ["--serve-web", "--web-viewer-port", str(self.port)]
        # its own session: a Ctrl-C in the terminal reaches us alone, and we end the
        # server after the last flush (ended first, it made the SDK log gRPC errors)
        self._process, (grpc, web) = _start(
            "the Rerun web server", options, (_GRPC, _WEB), detach=True
        )
        self.grpc_url = _grpc_url(grpc)
        self.web_url = f"http://127.0.0.1:{web}/?url={quote(self.grpc_url, safe='')}"
        return self

    @property
    def running(self) -> bool:
        return self._process is not None and self._process.poll() is None

    def wait(self) -> None:
        """Until the server ends (Ctrl-C raises KeyboardInterrupt here)."""
        self._process.wait()

    def __exit__(self, *exc) -> None:
        process, self._process = self._process, None
        if process is not None:
            _stop(process)


def open_viewer() -> str:
    """Open a native viewer window and return its gRPC URL. The viewer is the user's:
    it runs in its own session and stays open after we exit."""
    require_display()
    # a viewer that cannot open its window exits just after binding its port
    _, (grpc,) = _start(
        "the Rerun viewer", ["--hide-welcome-screen"], (_GRPC,), detach=True, settle=1.0
    )
    return _grpc_url(grpc)


def require_display() -> None:
    """The native viewer needs a screen; on Linux say so before Rerun fails obscurely."""
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise RerunError(
            "no display for the Rerun viewer (DISPLAY and WAYLAND_DISPLAY are unset): "
            "use --save OUT.rrd or --web"
        )
