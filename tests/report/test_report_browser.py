"""report.html in headless Chromium: no console errors, no request beyond the file itself
and its data: URIs, every figure decoded, a tall, non-blank page.

Drives Debian's ``chromium`` through the DevTools protocol over a pipe
(``--remote-debugging-pipe``: JSON messages separated by NUL bytes on file descriptors 3
and 4), so no extra Python package is needed. A control page with a console error, an
uncaught exception, a missing image and a blocked external image checks that each kind
of error is caught. Skips, saying why, where no chromium binary exists (``.ci/run``
installs the Debian package with apt-get when it can). Runs as root in containers, hence
``--no-sandbox``.
"""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from seawatch.report.html import write_report

CHROMIUM = shutil.which("chromium") or next(
    (p for p in ("/usr/bin/chromium", "/usr/bin/chromium-browser") if os.access(p, os.X_OK)),
    None,
)
pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="no chromium binary (Debian package 'chromium'; .ci/run installs it with apt-get "
    "when it can): report.html not rendered in a browser",
)

CONTROL_PAGE = """<!DOCTYPE html><html><head><meta charset="utf-8"><title>control</title>
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; img-src data:;
script-src 'unsafe-inline'"></head><body><h1>control</h1>
<img src="missing.png" alt=""><img src="http://127.0.0.1:9/x.png" alt="">
<script>console.error("boom"); console.log("fine"); notDefined();</script></body></html>"""


@dataclass
class Page:
    height: int
    png: bytes
    errors: list[str] = field(default_factory=list)
    requests: list[str] = field(default_factory=list)
    images: list[dict[str, Any]] = field(default_factory=list)


class Chromium:
    """A headless Chromium driven over ``--remote-debugging-pipe``."""

    def __init__(self, binary: str, profile: str) -> None:
        to_chrome_r, self._out = os.pipe()  # chrome reads commands on fd 3
        self._in, from_chrome_w = os.pipe()  # and writes replies/events on fd 4

        def wire() -> None:  # in the child, before exec: the pipes become fds 3 and 4
            a, b = os.dup(to_chrome_r), os.dup(from_chrome_w)  # (a < b, both > 2)
            os.dup2(a, 3)
            os.dup2(b, 4)
            # dup2(3, 3) is a no-op that keeps close-on-exec: set it explicitly. Every
            # other descriptor of Python's is non-inheritable: close_fds=False leaks none.
            os.set_inheritable(3, True)
            os.set_inheritable(4, True)

        self.proc = subprocess.Popen(
            [binary, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--no-first-run", "--no-default-browser-check", "--disable-extensions",
             "--disable-background-networking", "--disable-sync", "--mute-audio",
             "--hide-scrollbars", "--remote-debugging-pipe", f"--user-data-dir={profile}",
             "--window-size=1200,900", "about:blank"],
            close_fds=False, preexec_fn=wire, stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
        )  # fmt: skip
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._buf = b""
        self._id = 0
        self.events: list[dict[str, Any]] = []

    def _recv(self, timeout: float) -> dict[str, Any]:
        end = time.monotonic() + timeout
        while b"\0" not in self._buf:
            left = end - time.monotonic()
            if left <= 0:
                raise TimeoutError("no message from chromium")
            ready, _, _ = select.select([self._in], [], [], left)
            if ready:
                chunk = os.read(self._in, 1 << 20)
                if not chunk:
                    err = (
                        self.proc.stderr.read().decode(errors="replace") if self.proc.stderr else ""
                    )
                    raise RuntimeError(f"chromium closed the pipe: {err[-2000:]}")
                self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def call(self, method: str, params: dict | None = None, session: str | None = None,
             timeout: float = 90.0) -> dict[str, Any]:  # fmt: skip
        # 90 s: on a loaded 2-core host (the suite's two workers and other jobs) Chromium
        # once took over 30 s to open a tab
        self._id += 1
        msg: dict[str, Any] = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._out, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self._recv(timeout)
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def open(self, path: Path) -> Page:
        """Load a file, wait for its load event, then measure and screenshot it."""
        self.events.clear()
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        sid = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(f"{domain}.enable", session=sid)
        self.call("Page.navigate", {"url": path.resolve().as_uri()}, session=sid)
        end = time.monotonic() + 90.0
        while not any(e.get("method") == "Page.loadEventFired" for e in self.events):
            self.events.append(self._recv(max(0.1, end - time.monotonic())))

        def evaluate(expr: str) -> Any:
            r = self.call("Runtime.evaluate", {"expression": expr, "returnByValue": True},
                          session=sid)  # fmt: skip
            return r["result"]["value"]

        height = int(evaluate("document.documentElement.scrollHeight"))
        images = evaluate(
            "Array.from(document.images).map(i => ({src: i.src.slice(0, 40),"
            " complete: i.complete, width: i.naturalWidth}))"
        )
        shot = self.call("Page.captureScreenshot",
                         {"format": "png", "captureBeyondViewport": True}, session=sid)  # fmt: skip
        try:  # late messages (after load) still count
            while True:
                self.events.append(self._recv(0.3))
        except TimeoutError:
            pass
        page = Page(height=height, png=base64.b64decode(shot["data"]), images=images)
        for e in self.events:
            m, p = e.get("method"), e.get("params", {})
            if m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                page.errors.append("console: " + " ".join(str(a.get("value")) for a in p["args"]))
            elif m == "Runtime.exceptionThrown":
                d = p["exceptionDetails"]
                page.errors.append(f"exception: {d.get('exception', {}).get('description', d)}")
            elif m == "Log.entryAdded" and p["entry"]["level"] == "error":
                page.errors.append(f"log: {p['entry']['text']} {p['entry'].get('url', '')}")
            elif m == "Network.requestWillBeSent":
                page.requests.append(p["request"]["url"])
        self.call("Target.closeTarget", {"targetId": target})
        return page

    def close(self) -> None:
        try:
            self.call("Browser.close", timeout=5.0)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._out)
        os.close(self._in)


@pytest.fixture(scope="module")
def browser():
    with tempfile.TemporaryDirectory(prefix="seawatch-chromium-") as profile:
        chrome = Chromium(CHROMIUM, profile)
        try:
            yield chrome
        finally:
            chrome.close()


def _screenshot_checks(png: bytes, min_height: int, ink: float = 0.03) -> None:
    img = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    assert img is not None and img.shape[0] >= min_height
    packed = img.astype(np.int32) @ np.array([1 << 16, 1 << 8, 1], np.int32)
    colours = np.unique(packed)
    assert len(colours) > 100  # text, figures, table shading: not one flat colour
    not_white = np.any(img < 235, axis=-1)
    assert not_white.mean() > ink
    rows_with_ink = np.flatnonzero(not_white.any(axis=1))
    assert rows_with_ink.max() - rows_with_ink.min() > 0.8 * min_height  # content all down


def test_control_page_errors_are_all_caught(browser, tmp_path):
    path = tmp_path / "control.html"
    path.write_text(CONTROL_PAGE, encoding="utf-8")
    page = browser.open(path)
    text = "\n".join(page.errors)
    assert "console: boom" in text
    assert "notDefined" in text  # uncaught ReferenceError
    assert "missing.png" in text  # failed load
    assert "127.0.0.1:9" in text  # blocked by the Content-Security-Policy
    assert "console: fine" not in text  # console.log is not an error


def test_report_renders_without_errors_or_network_and_is_not_blank(browser, tmp_path, sim):
    tracks_csv = sim.write_csv(tmp_path / "tracks.csv", sim.ship_rows())
    vessel = {"north_m": [-3000.0, -2900.0], "east_m": [1000.0, 1100.0]}
    ais = {"matches": {2: 235000001}, "dark": [1, 3], "unseen": [235000009],
           "vessels": {"235000009": vessel}}  # fmt: skip
    path = write_report(tmp_path / "report.html", tracks_csv, camera=sim.make_camera(),
                        summary={"source": "clip.mp4", "frames": 1501, "warnings": ["w"]},
                        errors={"rmse_position_m": 23.4, "mota": 0.9}, ais=ais)  # fmt: skip
    page = browser.open(path)
    assert page.errors == []
    fetched = [u for u in page.requests if not u.startswith("data:")]
    assert fetched == [path.resolve().as_uri()]  # the page only; figures are inline
    assert len(page.images) == 2
    assert all(i["complete"] and i["width"] > 500 for i in page.images), page.images
    assert page.height > 1500
    _screenshot_checks(page.png, 1500)


def test_empty_report_renders_without_errors(browser, tmp_path, sim):
    tracks_csv = sim.write_csv(tmp_path / "tracks.csv", [])
    path = write_report(tmp_path / "report.html", tracks_csv, summary={"frames": 10})
    page = browser.open(path)
    assert page.errors == []
    assert page.requests == [path.resolve().as_uri()]
    assert page.height > 300
    _screenshot_checks(page.png, 300, ink=0.01)
