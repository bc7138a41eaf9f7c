"""Headless Chromium (Debian's ``chromium``) for the tests: a page loaded from a file and a
script evaluated in it, through the DevTools protocol over a pipe (``--remote-debugging-pipe``:
no port opens), with a fresh, empty profile and the browser's own network traffic off.

:func:`require_chromium` skips a test where Chromium is absent, and fails it where
``ROCKYADE_REQUIRE_CHROMIUM=1`` (``make test``), as the YADE tests do.
"""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

#: Chromium's switches: headless, no sandbox (root in a container), no GPU, no network of its own.
SWITCHES = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--hide-scrollbars",
    "--remote-debugging-pipe",
)
#: The longest wait for one answer of the browser, s (a safety net for a browser that hangs, not a
#: synchronisation: every wait ends on the browser's own message).
ANSWER_TIMEOUT_S = 120.0


def require_chromium() -> str:
    """The browser's path; skip without it, fail where it is required (module docstring)."""
    found = shutil.which("chromium")
    if found:
        return found
    message = "Chromium is not installed (Debian package chromium; tools/install-system-deps.sh installs it)"
    if os.environ.get("ROCKYADE_REQUIRE_CHROMIUM") == "1":
        pytest.fail(message)
    pytest.skip(message)


class Browser:
    """One headless Chromium driven over a pipe (module docstring); a context manager."""

    def __init__(self, profile: Path) -> None:
        self.exe = require_chromium()
        profile.mkdir(parents=True, exist_ok=False)
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()

        def fds() -> None:  # the protocol's pipe: the browser reads fd 3 and writes fd 4
            a, b = os.dup(to_browser_r), os.dup(from_browser_w)
            os.dup2(a, 3)
            os.dup2(b, 4)
            os.set_inheritable(3, True)
            os.set_inheritable(4, True)

        self.process = subprocess.Popen(
            [self.exe, *SWITCHES, f"--user-data-dir={profile}", "about:blank"],
            preexec_fn=fds,
            close_fds=False,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buffer = b""
        self._id = 0
        self.session = ""

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            if self.process.poll() is None:
                self.send("Browser.close")
                self.process.wait(timeout=30)
        except (OSError, subprocess.TimeoutExpired, RuntimeError):
            self.process.kill()
            self.process.wait(timeout=30)
        finally:
            os.close(self._to_browser)
            os.close(self._from_browser)

    def send(self, method: str, params: dict[str, Any] | None = None, session: bool = False) -> int:
        """Send a command; its id."""
        self._id += 1
        message: dict[str, Any] = {"id": self._id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = self.session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        return self._id

    def wait(self, answer: int | None = None, event: str | None = None) -> dict[str, Any]:
        """The answer to command ``answer``, or the next ``event``."""
        deadline = time.monotonic() + ANSWER_TIMEOUT_S
        while True:
            while b"\0" not in self._buffer:
                left = deadline - time.monotonic()
                ready, _, _ = select.select([self._from_browser], [], [], max(left, 0.0))
                if not ready:
                    raise RuntimeError(f"Chromium gave no answer in {ANSWER_TIMEOUT_S:g} s")
                chunk = os.read(self._from_browser, 1 << 16)
                if not chunk:
                    raise RuntimeError("Chromium closed its pipe")
                self._buffer += chunk
            raw, self._buffer = self._buffer.split(b"\0", 1)
            message = json.loads(raw)
            if event is not None and message.get("method") == event:
                return message
            if answer is not None and message.get("id") == answer:
                if "error" in message:
                    raise RuntimeError(f"Chromium: {message['error']}")
                return message["result"]

    def call(self, method: str, params: dict[str, Any] | None = None, session: bool = True) -> dict[str, Any]:
        """Send a command and wait for its answer."""
        return self.wait(self.send(method, params, session))

    def open(self, path: Path, width: int = 1100, height: int = 1400) -> None:
        """Load a file in a new page and wait for its load event."""
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=False)["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True}, session=False)[
            "sessionId"
        ]
        self.call("Page.enable")
        self.call(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
        )
        self.send("Page.navigate", {"url": path.resolve().as_uri()}, session=True)
        self.wait(event="Page.loadEventFired")

    def evaluate(self, expression: str) -> Any:
        """The value of a script evaluated in the page (awaited when it is a promise)."""
        result = self.call("Runtime.evaluate", {"expression": expression, "awaitPromise": True, "returnByValue": True})
        if "exceptionDetails" in result:
            raise RuntimeError(f"the script failed: {result['exceptionDetails']}")
        return result["result"].get("value")

    def screenshot(self, path: Path) -> Path:
        """The whole page as a PNG."""
        size = self.call("Page.getLayoutMetrics")["cssContentSize"]
        clip = {"x": 0, "y": 0, "width": size["width"], "height": size["height"], "scale": 1}
        shot = self.call("Page.captureScreenshot", {"format": "png", "captureBeyondViewport": True, "clip": clip})
        path.write_bytes(base64.b64decode(shot["data"]))
        return path


__all__ = ["Browser", "require_chromium"]
