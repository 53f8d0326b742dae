"""Showing runs in Rerun: replay a recording, or watch a run live.

Outputs: an ``.rrd`` file, the web viewer served on 127.0.0.1, or the native viewer
(which needs a display). A replay sends a whole recording at once (the viewer
plays it, at ``rate`` x real time if asked); the live view sends what the run
made every 0.1 s. Both go
through ``recordings.rerun_rows`` (whose docstring lists the entity paths) and
``recordings.rerun_log``, so they show the same entities with the same blueprint.
"""

from __future__ import annotations

import sys
import uuid
from contextlib import ExitStack, suppress
from pathlib import Path

import rerun as rr

from bridge.messages import to_dict
from recordings.rerun_log import Live, send_recording
from recordings.rerun_server import RerunError, WebServer, open_viewer, require_display
from recordings.rerun_tasks import stations_of

APP_ID = "agv-fleet"
FLUSH_TIMEOUT = 30.0

__all__ = [
    "LiveView",
    "Outputs",
    "RerunError",
    "require_display",
    "save_rrd",
    "serve_web",
    "spawn_viewer",
]


class Outputs:
    """A recording stream and where it goes: ``save`` (an .rrd path) and/or ``web``,
    else the native viewer. A context manager: the file is complete and the web
    server gone when the block ends."""

    def __init__(
        self,
        *,
        save: Path | str | None = None,
        web: bool = False,
        web_port: int = 0,
        notify=sys.stderr,
    ):
        self.stream = rr.RecordingStream(APP_ID, recording_id=uuid.uuid4())
        self._save = save
        self._web = web
        self._web_port = web_port
        self._notify = notify
        self._server: WebServer | None = None
        self._exit = ExitStack()

    def __enter__(self) -> Outputs:
        with self._exit:
            sinks = []
            if self._save is not None:
                sinks.append(rr.FileSink(str(self._save)))
            if self._web:
                self._server = self._exit.enter_context(WebServer(self._web_port))
                sinks.append(rr.GrpcSink(self._server.grpc_url))
            if not sinks:
                sinks.append(rr.GrpcSink(open_viewer()))
            try:
                self.stream.set_sinks(*sinks)
            except RuntimeError as err:  # a file it cannot create
                raise RerunError(str(err)) from None
            self._exit.callback(self._close_stream)
            if self._server is not None:
                print(f"Rerun web viewer: {self._server.web_url}", file=self._notify, flush=True)
            self._exit = self._exit.pop_all()
        return self

    def __exit__(self, *exc) -> None:
        self._exit.close()

    def _close_stream(self) -> None:
        """Deliver what was logged, then close the sinks (this writes the .rrd footer)."""
        try:
            self.stream.flush(timeout_sec=FLUSH_TIMEOUT)
        except RuntimeError as err:
            # The web server ended on its own (it has its own session, so a Ctrl-C does
            # not reach it): nobody is left to deliver to.
            if self._server is None or self._server.running:
                raise RerunError(f"Rerun did not get everything: {err}") from None
        finally:
            self.stream.disconnect()

    def replay(self, recording, rate: float | None = None, follow: str | None = None) -> None:
        """Send a whole recording; the viewer opens paused at its start, or playing it
        at ``rate`` x real time, and on the tab of the AGV named ``follow``, if given.
        (The viewer plays it: sending it paced made the web viewer fall behind.)"""
        stations = stations_of(recording.scenario_text)
        send_recording(self.stream, recording.messages, follow, rate, stations)

    def hold(self) -> None:
        """With the web viewer: keep serving until Ctrl-C (or the server ends)."""
        if self._server is None:
            return
        self.stream.flush(timeout_sec=FLUSH_TIMEOUT)
        # a stop once the notice is out is a stop, even one that comes while the print
        # still returns (a test saw 130, "interrupted", for a SIGTERM sent on the notice)
        with suppress(KeyboardInterrupt):
            print("serving; Ctrl-C to stop", file=self._notify, flush=True)
            self._server.wait()


def save_rrd(recording, out_path: Path | str, follow: str | None = None) -> None:
    """Convert a recording to an .rrd file that ``rerun OUT.rrd`` opens."""
    with Outputs(save=out_path) as out:
        out.replay(recording, follow=follow)


def serve_web(
    recording,
    *,
    rate: float | None = None,
    follow: str | None = None,
    port: int = 0,
    notify=sys.stderr,
) -> None:
    """Serve a recording in the web viewer on 127.0.0.1 (the URL goes to ``notify``)
    until Ctrl-C; ``port`` 0 lets the OS pick."""
    with Outputs(web=True, web_port=port, notify=notify) as out:
        out.replay(recording, rate, follow)
        out.hold()


def spawn_viewer(recording, *, rate: float | None = None, follow: str | None = None) -> None:
    """Show a recording in the native viewer (RerunError without a display)."""
    with Outputs() as out:
        out.replay(recording, rate, follow)


class LiveView:
    """A run's sink, ``sink(key, msg)``, for ``agv-fleet run --rerun``: every message is
    shown as it comes, on a ``sim_time`` timeline (``dt``: the scenario's control
    period, which dates AGV states). Use it as a context manager; ``hold()`` after
    the run keeps the web viewer up until Ctrl-C."""

    def __init__(
        self, dt: float, *, save: Path | str | None = None, web: bool = False, scenario_text=""
    ):
        self._outputs = Outputs(save=save, web=web)
        self._live = Live(self._outputs.stream, dt, stations_of(scenario_text))

    def __enter__(self) -> LiveView:
        self._outputs.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        try:
            self._live.send()
        finally:
            self._outputs.__exit__(*exc)

    def __call__(self, key: str, msg) -> None:
        self._live.feed(key, to_dict(msg))

    def hold(self) -> None:
        self._live.send()
        self._outputs.hold()
