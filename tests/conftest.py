"""Test-wide settings and helpers: hypothesis runs derandomised so every run sees the same
examples; ``stream_server``, a local HTTP server for live-stream tests."""

from __future__ import annotations

import http.server
import socketserver
import threading

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "seawatch",
    derandomize=True,
    deadline=None,
    max_examples=60,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("seawatch")


class StreamServer:
    """A local HTTP server sending a file whole or cut off after half (a dropped stream).

    ``plan``: what the n-th request of ``/plan`` gets — ``"half"`` (cut off), ``"whole"``,
    other bytes (sent whole) or ``"down"`` (404: the camera is not back); ``"down"``
    after the plan's end. ``requests`` counts the requests of ``/plan``."""

    def __init__(self, data: bytes, plan: tuple[str | bytes, ...] = ()) -> None:
        payload = data
        todo = list(plan)
        self.requests = 0
        server = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                drop = self.path.startswith("/drop")
                body = payload
                if self.path.startswith("/plan"):
                    server.requests += 1
                    what = todo.pop(0) if todo else "down"
                    if what == "down":
                        self.send_error(404)
                        return
                    drop = what == "half"
                    body = what if isinstance(what, bytes) else payload
                self.send_response(200)
                self.send_header("Content-Type", "video/mp2t")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body[: len(body) // 2] if drop else body)
                self.wfile.flush()
                if drop:
                    self.connection.close()

            def log_message(self, *args: object) -> None:
                pass

        self.httpd = socketserver.TCPServer(("127.0.0.1", 0), Handler)
        self.port = self.httpd.server_address[1]
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)

    def __enter__(self) -> StreamServer:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def stream_server() -> type[StreamServer]:
    """:class:`StreamServer`, to serve bytes over HTTP as a live source (real sockets)."""
    return StreamServer


def _write_at(path, frames, fps: int = 25) -> None:
    """Write ``(index, image)`` pairs (grey or BGR uint8) as an H.264 file whose frame
    ``index`` has the timestamp ``index / fps``: indices left out are frames lost before
    the file was written (a recorder or stream that dropped them)."""
    from fractions import Fraction

    import av
    import numpy as np

    frames = list(frames)
    h, w = frames[0][1].shape[:2]
    container = av.open(str(path), "w")
    stream = container.add_stream("libx264", rate=Fraction(fps))
    stream.width, stream.height, stream.pix_fmt = w, h, "yuv420p"
    stream.codec_context.time_base = Fraction(1, fps)
    for index, image in frames:
        fmt = "gray" if np.ndim(image) == 2 else "bgr24"
        frame = av.VideoFrame.from_ndarray(image, format=fmt)
        frame.pts, frame.time_base = index, Fraction(1, fps)
        for packet in stream.encode(frame):
            container.mux(packet)
    for packet in stream.encode():
        container.mux(packet)
    container.close()


@pytest.fixture
def write_at():
    """:func:`_write_at`: a video file with frames missing from its timestamps."""
    return _write_at
