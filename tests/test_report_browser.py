"""The report in a real browser: headless Chromium (Debian's ``chromium``) opens ``report.html`` from file://.

Two ways, both with no download and no network:

* the command line: ``chromium --headless --screenshot`` takes a screenshot, which must not be blank;
* the DevTools protocol over ``--remote-debugging-pipe`` (JSON messages on file descriptors 3 and 4, no
  websocket needed): the page's console errors, uncaught exceptions, failed loads and log errors are
  collected, every ``<img>`` is asked whether it decoded (``complete && naturalWidth > 0``), every request the
  page made is listed (all must be ``data:`` or the page's own ``file:`` URL), and a screenshot is taken.

A deliberately broken page (an image from the network, a console error, an uncaught exception) must be caught
by the same collector: the check can fail.
"""
from __future__ import annotations

import base64
import io
import json
import os
import select
import subprocess
import time

import numpy as np
import pytest

from swiftfin.report.html import SECTIONS, write_report
from tests.conftest import require_tool
from tests.test_report import fake_findings, fake_mass_properties, paper_audit, synthetic_parts

pytestmark = pytest.mark.browser

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]
TIMEOUT_S = 120


def chromium() -> str:
    return require_tool("chromium", "the report is checked in a real browser")


class DevTools:
    """A minimal Chrome DevTools Protocol client over ``--remote-debugging-pipe``."""

    def __init__(self, binary: str, user_data_dir, width: int = 1280, height: int = 4000):
        r_in, self._w = os.pipe()     # we write, the browser reads on fd 3
        self._r, w_out = os.pipe()    # the browser writes on fd 4, we read

        def child_fds():
            a, b = os.dup(r_in), os.dup(w_out)
            a = os.dup(a) if a in (3, 4) else a
            b = os.dup(b) if b in (3, 4) else b
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [binary, *FLAGS, f"--user-data-dir={user_data_dir}", "--remote-debugging-pipe",
             f"--window-size={width},{height}", "about:blank"],
            preexec_fn=child_fds, close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(r_in)
        os.close(w_out)
        self._buf = b""
        self._id = 0
        self.events: list[dict] = []
        self.session = None

    def send(self, method: str, params: dict | None = None) -> dict:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if self.session:
            msg["sessionId"] = self.session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        mid = self._id
        reply = self.wait(lambda m: m.get("id") == mid)
        if "error" in reply:
            raise RuntimeError(f"{method}: {reply['error']}")
        return reply.get("result", {})

    def wait(self, pred, timeout: float = TIMEOUT_S) -> dict:
        end = time.monotonic() + timeout
        while True:
            while b"\0" in self._buf:
                raw, self._buf = self._buf.split(b"\0", 1)
                m = json.loads(raw)
                if "method" in m:
                    self.events.append(m)
                if pred(m):
                    return m
            left = end - time.monotonic()
            if left <= 0:
                raise TimeoutError("no answer from the browser")
            ready, _, _ = select.select([self._r], [], [], min(left, 0.5))
            if ready:
                chunk = os.read(self._r, 1 << 20)
                if not chunk:
                    raise RuntimeError("the browser closed the DevTools pipe")
                self._buf += chunk

    def open(self, url: str) -> None:
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.send(f"{domain}.enable")
        self.send("Page.navigate", {"url": url})
        self.wait(lambda m: m.get("method") == "Page.loadEventFired" and m.get("sessionId") == self.session)

    def evaluate(self, expression: str):
        r = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True})
        return r["result"].get("value")

    def screenshot(self) -> bytes:
        return base64.b64decode(self.send("Page.captureScreenshot", {"format": "png", "captureBeyondViewport": False})["data"])

    def errors(self) -> list[str]:
        out = []
        for m in self.events:
            meth, prm = m["method"], m.get("params", {})
            if meth == "Runtime.exceptionThrown":
                out.append("exception: " + prm["exceptionDetails"].get("exception", {}).get("description", prm["exceptionDetails"].get("text", "")))
            elif meth == "Runtime.consoleAPICalled" and prm.get("type") in ("error", "assert"):
                out.append("console: " + " ".join(str(a.get("value", a.get("description", ""))) for a in prm.get("args", [])))
            elif meth == "Log.entryAdded" and prm["entry"].get("level") == "error":
                out.append("log: " + prm["entry"].get("text", ""))
            elif meth == "Network.loadingFailed":
                out.append("load failed: " + prm.get("errorText", ""))
        return out

    def requested_urls(self) -> list[str]:
        return [m["params"]["request"]["url"] for m in self.events if m["method"] == "Network.requestWillBeSent"]

    def close(self) -> None:
        try:
            self.session = None
            self._id += 1
            os.write(self._w, json.dumps({"id": self._id, "method": "Browser.close", "params": {}}).encode() + b"\0")
            self.proc.wait(timeout=30)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()
            self.proc.wait()
        finally:
            for fd in (self._w, self._r):
                try:
                    os.close(fd)
                except OSError:
                    pass


def not_blank(png: bytes, min_std: float = 12.0) -> np.ndarray:
    from PIL import Image

    im = Image.open(io.BytesIO(png))
    arr = np.asarray(im.convert("RGB"), float)
    assert arr.std() > min_std, f"screenshot looks blank (pixel std {arr.std():.1f})"
    # more than a background: a good share of the pixels differ from the most common colour
    flat = arr.reshape(-1, 3)
    vals, counts = np.unique(flat[:: max(1, flat.shape[0] // 200000)], axis=0, return_counts=True)
    bg = vals[counts.argmax()]
    assert np.mean(np.abs(flat - bg).sum(axis=1) > 30) > 0.15
    return arr


@pytest.fixture(scope="module")
def page(tmp_path_factory, default_params):
    from PIL import Image

    d = tmp_path_factory.mktemp("report")
    fit = d / "fit"
    fit.mkdir()
    (fit / "fit_report.json").write_text(json.dumps({"family": "joint", "added_effects": [], "final": {},
                                                     "baseline": {}, "units": {"rmse": "rad"}}))
    y, x = np.mgrid[0:150, 0:300]
    Image.fromarray((np.stack([x, y, x + y], -1) % 256).astype(np.uint8)).save(fit / "before_after.png")
    return write_report(default_params, d / "out", parts=synthetic_parts(), mass_properties=fake_mass_properties(),
                        fit_dir=fit, findings=fake_findings(), audit=paper_audit())


def test_screenshot_from_the_command_line_is_not_blank(page, tmp_path):
    binary = chromium()
    shot = tmp_path / "shot.png"
    r = subprocess.run([binary, *FLAGS, f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={shot}",
                        "--window-size=1280,4000", page.as_uri()],
                       capture_output=True, text=True, timeout=TIMEOUT_S)
    assert r.returncode == 0, r.stderr[-2000:]
    assert shot.exists(), r.stderr[-2000:]
    arr = not_blank(shot.read_bytes())
    assert arr.shape[:2] == (4000, 1280)


def test_page_loads_offline_without_errors_and_every_image_decodes(page, tmp_path):
    dt = DevTools(chromium(), tmp_path / "profile")
    try:
        dt.open(page.as_uri())
        info = dt.evaluate("""JSON.stringify({
            images: document.images.length,
            decoded: Array.from(document.images).filter(i => i.complete && i.naturalWidth > 0).length,
            sections: Array.from(document.querySelectorAll('main > section')).map(s => s.id),
            navTargetsPresent: Array.from(document.querySelectorAll('nav a')).every(
                a => document.getElementById(a.getAttribute('href').slice(1)) !== null),
            height: document.documentElement.scrollHeight,
            fonts: Array.from(document.fonts).length})""")
        shot = dt.screenshot()
        time.sleep(0.3)
        try:   # collect anything the page logs after load
            dt.wait(lambda m: False, timeout=1.0)
        except TimeoutError:
            pass
        errors = dt.errors()
        urls = dt.requested_urls()
    finally:
        dt.close()
    info = json.loads(info)
    assert errors == []
    assert info["images"] == 2 + 2 + 3 + 1 and info["decoded"] == info["images"]
    assert info["sections"] == [sid for sid, _ in SECTIONS]
    assert info["navTargetsPresent"]
    assert info["fonts"] == 0                     # no web fonts: system fonts only
    assert info["height"] > 3000
    assert all(u.startswith("data:") or u == page.as_uri() for u in urls), urls
    not_blank(shot)


def test_the_error_collector_catches_a_broken_page(tmp_path):
    """The check can fail: an image from the network, a console error and an uncaught exception are caught."""
    bad = tmp_path / "bad.html"
    bad.write_text('<!DOCTYPE html><html><body><img src="http://example.invalid/x.png">'
                   '<script>console.error("boom"); no_such_function();</script></body></html>')
    dt = DevTools(chromium(), tmp_path / "profile")
    try:
        dt.open(bad.as_uri())
        decoded = dt.evaluate("Array.from(document.images).filter(i => i.complete && i.naturalWidth > 0).length")
        try:
            dt.wait(lambda m: False, timeout=1.0)
        except TimeoutError:
            pass
        errors = dt.errors()
        urls = dt.requested_urls()
    finally:
        dt.close()
    assert decoded == 0
    assert any(e.startswith("console: boom") for e in errors), errors
    assert any(e.startswith("exception:") and "no_such_function" in e for e in errors), errors
    assert any(e.startswith("load failed") for e in errors), errors
    assert "http://example.invalid/x.png" in urls
