"""Open the HTML report in headless Chromium as a reader would: every image must decode, the
page must make no request outside itself, and a screenshot of the first screen is saved.

Chromium is driven over its DevTools protocol on a pipe (``--remote-debugging-pipe``: JSON
messages, NUL-terminated, on file descriptors 3 and 4), so nothing beyond the standard
library and a ``chromium`` executable is needed.
"""
from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "chrome")
IMAGES = ("JSON.stringify([...document.images].map(i => "
          "({alt: i.alt, complete: i.complete, width: i.naturalWidth})))")


def find_browser() -> str | None:
    return next((p for p in map(shutil.which, BROWSERS) if p), None)


@dataclass
class PageCheck:
    images: list[dict]  # alt, complete, width (0: not decoded)
    external: list[str] = field(default_factory=list)  # requests not to data: or the file itself
    title: str = ""

    @property
    def broken(self) -> list[str]:
        return [i["alt"] for i in self.images if not (i["complete"] and i["width"] > 0)]

    @property
    def ok(self) -> bool:
        return not self.broken and not self.external


class _Pipe:
    """DevTools protocol over the browser's pipe; ``call`` returns a command's result and
    keeps every event it reads in ``events``."""

    def __init__(self, to_browser, from_browser):
        self.out, self.inp = to_browser, from_browser
        self.next_id, self.buffer, self.events = 0, b"", []

    def _read(self, deadline):
        while b"\0" not in self.buffer:
            if time.monotonic() > deadline:
                raise TimeoutError("chromium did not answer")
            chunk = os.read(self.inp, 1 << 16)
            if not chunk:
                raise RuntimeError("chromium closed the pipe")
            self.buffer += chunk
        msg, _, self.buffer = self.buffer.partition(b"\0")
        return json.loads(msg)

    def call(self, method, params=None, session=None, timeout=30.0):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.out, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._read(deadline)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method, timeout=30.0):
        deadline = time.monotonic() + timeout
        while not any(e.get("method") == method for e in self.events):
            self.events.append(self._read(deadline))


def check_report(html_path, screenshot=None, width=1280, height=900, browser=None) -> PageCheck:
    """Load ``html_path`` in headless Chromium; decode state of every image, the requests that
    left the file, and (optionally) a PNG screenshot of the first ``width`` x ``height`` screen."""
    browser = browser or find_browser()
    if browser is None:
        raise FileNotFoundError("no Chromium found (Debian: apt-get install chromium)")
    url = Path(html_path).resolve().as_uri()
    r_to, w_to = os.pipe()  # we write commands, the browser reads them on fd 3
    r_from, w_from = os.pipe()  # the browser writes on fd 4
    profile = tempfile.mkdtemp(prefix="sph-surge-chromium-")
    args = [browser, "--headless", "--remote-debugging-pipe", "--disable-gpu", "--no-first-run",
            "--no-default-browser-check", f"--user-data-dir={profile}", "about:blank"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        args.insert(1, "--no-sandbox")  # Chromium refuses to run its sandbox as root

    def child_fds():  # in the child: the pipe ends on fds 3 and 4, whatever numbers they had
        import fcntl
        a, b = fcntl.fcntl(r_to, fcntl.F_DUPFD, 10), fcntl.fcntl(w_from, fcntl.F_DUPFD, 10)
        os.dup2(a, 3)
        os.dup2(b, 4)

    proc = subprocess.Popen(args, pass_fds=(3, 4), preexec_fn=child_fds,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(r_to)
    os.close(w_from)
    try:
        cdp = _Pipe(w_to, r_from)
        page = next(t for t in cdp.call("Target.getTargets")["targetInfos"] if t["type"] == "page")
        s = cdp.call("Target.attachToTarget", {"targetId": page["targetId"], "flatten": True})["sessionId"]
        cdp.call("Network.enable", session=s)
        cdp.call("Page.enable", session=s)
        cdp.call("Emulation.setDeviceMetricsOverride",
                 {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False}, session=s)
        cdp.events.clear()
        cdp.call("Page.navigate", {"url": url}, session=s)
        cdp.wait_for("Page.loadEventFired", timeout=60.0)
        images = json.loads(cdp.call("Runtime.evaluate", {"expression": IMAGES, "returnByValue": True},
                                     session=s)["result"]["value"])
        title = cdp.call("Runtime.evaluate", {"expression": "document.title", "returnByValue": True},
                         session=s)["result"]["value"]
        requested = [e["params"]["request"]["url"] for e in cdp.events
                     if e.get("method") == "Network.requestWillBeSent"]
        external = [u for u in requested if not (u.startswith("data:") or u == url)]
        if screenshot is not None:
            png = cdp.call("Page.captureScreenshot", {"format": "png"}, session=s)["data"]
            Path(screenshot).parent.mkdir(parents=True, exist_ok=True)
            Path(screenshot).write_bytes(base64.b64decode(png))
        try:
            cdp.call("Browser.close", timeout=5.0)
        except (RuntimeError, TimeoutError):
            pass
        return PageCheck(images, external, title)
    finally:
        os.close(w_to)
        os.close(r_from)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
        shutil.rmtree(profile, ignore_errors=True)
