"""`snakemake --report` of the tiny workflow, rendered in headless Chromium with the network off.

Not run by default (marker ``browser``): ``python -m pytest -m browser tests/test_report.py``.
Needs the Debian package ``chromium`` (or the binary named by $CHROMIUM); without it the test
fails and says so. The report is a React app with no page addresses: its categories and
results open from buttons and links. So the test drives a real Chromium over the DevTools
protocol (a pipe, no socket), clicks through the pages as a reader would and checks what the
browser shows: the workflow description, every figure with its caption, the claims table
(shown in an iframe) and the COMIC minima. Screenshots of the start page and the claims table
are saved next to the report; their paths are printed.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import queue
import shutil
import subprocess
import threading
import time
from pathlib import Path

import pandas as pd
import pytest
from conftest import TINY, run_snakemake

from particle_entropy.figures import FIGURES as ALL_FIGURES

pytestmark = pytest.mark.browser

FIGURES = [f.name for f in ALL_FIGURES if f.name not in ("fig9_mechanism", "optimum")]  # the default target's
CATEGORY = {f.name: f.category for f in ALL_FIGURES}
# Headless, no GPU, no sandbox (root in a container), nothing fetched: every host name is unresolvable.
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-extensions",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--host-resolver-rules=MAP * ~NOTFOUND",
    "--remote-debugging-pipe",
]


def chromium_binary() -> str:
    """The Chromium to use ($CHROMIUM, else `chromium` on PATH); fails the test when there is none."""
    binary = os.environ.get("CHROMIUM") or shutil.which("chromium")
    if not binary or not Path(binary).exists():
        pytest.fail(
            "headless Chromium not found: install the Debian package (sudo apt-get install -y chromium) "
            "or set $CHROMIUM to a Chromium binary",
            pytrace=False,
        )
    return binary


class Browser:
    """Chromium driven over the DevTools protocol on a pipe: Chromium reads commands on fd 3 and
    writes replies and events on fd 4, each a JSON message ended by a NUL byte."""

    def __init__(self, binary: str, profile: Path):
        cmd_read, self._cmd = os.pipe()
        self._out, out_write = os.pipe()
        # the browser's ends moved above fd 9, so that making them fds 3 and 4 cannot clobber one another
        ends = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (cmd_read, out_write)]
        for fd in (cmd_read, out_write):
            os.close(fd)
        shell = f'exec "$@" 3<&{ends[0]} 4>&{ends[1]}'  # bash: fds above 9; `exec`: the browser keeps its pid
        argv = [binary, *FLAGS, f"--user-data-dir={profile}", "about:blank"]
        self.log = profile.with_suffix(".log")
        with open(self.log, "w") as log:
            self.proc = subprocess.Popen(
                ["bash", "-c", shell, "bash", *argv],
                pass_fds=ends,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        for fd in ends:
            os.close(fd)
        self._replies: dict[int, queue.Queue] = {}
        self.events: list[dict] = []
        self._next = 0
        self._lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()
        self.session = None

    def _read(self) -> None:
        buffer = b""
        while chunk := os.read(self._out, 1 << 16):
            buffer += chunk
            *messages, buffer = buffer.split(b"\0")
            for raw in messages:
                msg = json.loads(raw)
                if "id" in msg:
                    with self._lock:
                        box = self._replies.get(msg["id"])
                    if box is not None:
                        box.put(msg)
                else:
                    self.events.append(msg)

    def call(self, method: str, timeout: float = 60, session: bool = True, **params):
        with self._lock:
            self._next += 1
            ident = self._next
            box = self._replies[ident] = queue.Queue()
        msg = {"id": ident, "method": method, "params": params}
        if session and self.session:
            msg["sessionId"] = self.session
        try:
            os.write(self._cmd, json.dumps(msg).encode() + b"\0")
            reply = box.get(timeout=timeout)
        except (queue.Empty, BrokenPipeError):
            raise AssertionError(
                f"Chromium did not answer {method} within {timeout} s (exit status {self.proc.poll()}); "
                f"its output: {self.log}\n{self.log.read_text()[-2000:]}"
            ) from None
        if "error" in reply:
            raise AssertionError(f"{method}: {reply['error']}")
        return reply["result"]

    def open_page(self, width: int = 1500, height: int = 1000) -> None:
        """A tab with the network off: offline, and any http(s)/ws URL blocked."""
        target = self.call("Target.createTarget", session=False, url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", session=False, targetId=target, flatten=True)["sessionId"]
        self.call("Page.enable")
        self.call("Network.enable")
        self.call("Network.setBlockedURLs", urls=["http://*", "https://*", "ws://*", "wss://*"])
        self.call(
            "Network.emulateNetworkConditions", offline=True, latency=0, downloadThroughput=-1, uploadThroughput=-1
        )
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)

    def evaluate(self, expression: str, context: int | None = None):
        params = {"expression": expression, "returnByValue": True, "awaitPromise": True}
        if context is not None:
            params["contextId"] = context
        result = self.call("Runtime.evaluate", **params)
        if "exceptionDetails" in result:
            raise AssertionError(f"script failed: {expression}\n{result['exceptionDetails']}")
        return result["result"].get("value")

    def wait_for(self, expression: str, what: str, timeout: float = 30, context: int | None = None):
        """Poll a script until it returns something truthy (the app renders asynchronously)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                value = self.evaluate(expression, context)
            except AssertionError:
                value = None  # e.g. a frame still loading
            if value:
                return value
            time.sleep(0.2)
        raise AssertionError(f"not shown within {timeout} s: {what}")

    def navigate(self, url: str) -> None:
        self.call("Page.navigate", url=url)
        self.wait_for("document.readyState === 'complete' && typeof app !== 'undefined'", "the report app")

    def screenshot(self, path: Path) -> Path:
        path.write_bytes(base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"]))
        return path

    def frame_context(self, url_prefix: str) -> int:
        """An execution context in the child frame whose URL starts with ``url_prefix`` (the
        report shows an HTML result as a data: URL in an iframe, which page scripts cannot read)."""

        def find(tree):
            if tree["frame"].get("url", "").startswith(url_prefix):
                return tree["frame"]["id"]
            return next((f for child in tree.get("childFrames", []) if (f := find(child))), None)

        end = time.monotonic() + 30
        while (frame := find(self.call("Page.getFrameTree")["frameTree"])) is None:
            if time.monotonic() > end:
                raise AssertionError(f"no frame showing {url_prefix[:40]}...")
            time.sleep(0.2)
        return self.call("Page.createIsolatedWorld", frameId=frame, worldName="test")["executionContextId"]

    def web_requests(self) -> list[str]:
        return [
            e["params"]["request"]["url"]
            for e in self.events
            if e.get("method") == "Network.requestWillBeSent"
            and e["params"]["request"]["url"].split(":", 1)[0] in ("http", "https", "ws", "wss")
        ]

    def close(self) -> None:
        try:
            self.call("Browser.close", session=False, timeout=10)
        except (AssertionError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, 9)
            self.proc.wait()
        os.close(self._cmd)


def click(selector: str) -> str:
    """JS: click the first element matching a CSS selector; true when there was one."""
    return f"(() => {{ const a = document.querySelector({json.dumps(selector)}); if (a) a.click(); return !!a; }})()"


def row_button(path: str, which: int) -> str:
    """JS: click button ``which`` (0: view, 1: caption) of the result row of ``path``; true when found."""
    return (
        "(() => { const row = Array.from(document.querySelectorAll('tr')).find("
        f"r => r.cells.length && r.cells[0].innerText.trim() === {json.dumps(path)});"
        f" if (!row) return false; row.querySelectorAll('a')[{which}].click(); return true; }})()"
    )


def open_category(browser: Browser, category: str, path: str) -> None:
    """Show a category's page (as its menu entry does) and wait for the row of ``path``."""
    browser.evaluate(f"app.showCategory({json.dumps(category)})")
    browser.wait_for(
        f"Array.from(document.querySelectorAll('tr')).some(r => r.cells.length && r.cells[0].innerText.trim() === "
        f"{json.dumps(path)})",
        f"{path} in {category}",
    )


def show_result(browser: Browser, path: str) -> str:
    """Open a result (view button) and its caption (info button); returns the caption text."""
    browser.wait_for(row_button(path, 0), f"view button of {path}")
    browser.wait_for(row_button(path, 1), f"caption button of {path}")
    return browser.wait_for(
        "(() => { const c = Array.from(document.querySelectorAll('li.prose')).map(e => e.innerText).join(' ');"
        " return c.length ? c : null; })()",
        f"caption of {path}",
    )


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """Runs the tiny workflow and its report, then opens the report in Chromium: what the browser showed."""
    binary = chromium_binary()
    work = tmp_path_factory.mktemp("report")
    started = time.monotonic()
    run_snakemake(work, configfile=TINY)
    run_snakemake(work, "--report", work / "report.html", configfile=TINY)
    seen = {"built_s": time.monotonic() - started, "workdir": work}
    seen.update(browse(binary, work / "report.html", work))
    seen["seconds"] = time.monotonic() - started
    return seen


def browse(binary: str, html: Path, out: Path) -> dict:
    """Open the report as a reader would and collect what the browser shows; screenshots go to ``out``."""
    browser = Browser(binary, out / "chromium-profile")
    seen = {}
    try:
        browser.open_page()
        url = html.as_uri()

        # start page: the workflow description, rendered by the app from its JSON
        browser.navigate(url)
        seen["start"] = browser.wait_for(
            "document.body.innerText.includes('How to read this report') && document.body.innerText",
            "the workflow description",
        )
        # where the description starts: the app centres it, so a long one loses its top off-screen
        seen["title_top"] = browser.evaluate("document.querySelector('.prose h1').getBoundingClientRect().top")
        seen["start_shot"] = browser.screenshot(out / "report_start.png")

        # every figure: its row in its category, the image itself, and its caption
        browser.wait_for(click("a[href=\"javascript:app.showCategory('Figures')\"]"), "the description's Figures link")
        seen["figures_page"] = browser.wait_for(
            "document.body.innerText.includes('figures/fig1.png') && document.body.innerText", "the Figures page"
        )
        seen["figures"] = {}
        for fig in FIGURES:
            path = f"figures/{fig}.png"
            open_category(browser, CATEGORY[fig], path)
            caption = show_result(browser, path)
            image = browser.wait_for(  # this figure's own image, decoded
                f"(() => {{ const i = Array.from(document.images).find(i => i.src === results[{json.dumps(path)}]"
                ".data_uri); return i && i.complete && i.naturalWidth > 0 && [i.naturalWidth, i.naturalHeight]; })()",
                f"the image of {path}",
            )
            seen["figures"][fig] = {"caption": caption, "size": image}

        # the claims table: reached from the description's link, shown in an iframe
        browser.navigate(url)
        browser.wait_for(click("a[href=\"javascript:app.showCategory('Claims')\"]"), "the description's Claims link")
        path = "results/paper_claims.html"
        open_category(browser, "Claims", path)
        seen["claims_caption"] = show_result(browser, path)
        frame = browser.frame_context("data:text/html")
        seen["claims"] = browser.wait_for(
            "(() => { const rows = Array.from(document.querySelectorAll('table.claims tbody tr'))"
            ".map(r => Array.from(r.cells).map(c => [c.innerText, c.className]));"
            " return rows.length ? {summary: document.querySelector('p').innerText, rows: rows,"
            " header: Array.from(document.querySelectorAll('thead th')).map(h => h.innerText)} : null; })()",
            "the claims table",
            context=frame,
        )
        seen["claims_shot"] = browser.screenshot(out / "report_claims.png")

        # the COMIC minima, in the COMIC category
        browser.navigate(url)
        path = "results/tables/comic_minima.html"
        open_category(browser, "COMIC", path)
        seen["comic_caption"] = show_result(browser, path)
        frame = browser.frame_context("data:text/html")
        seen["comic"] = browser.wait_for(
            "(() => { const t = document.querySelector('table'); return t && t.tBodies[0].rows.length"
            " ? Array.from(t.rows).map(r => Array.from(r.cells).map(c => c.innerText)) : null; })()",
            "the COMIC minima table",
            context=frame,
        )
        seen["web_requests"] = browser.web_requests()
    finally:
        browser.close()
    return seen


def test_report_start_page_describes_workflow_and_paper(report, capsys):
    text = report["start"]
    for words in (
        "Benson et al. (2020), reproduced",
        "Benson, Pankavich, Schmidt and Sole-Mari (2020)",
        "mass-transfer particle tracking",
        "COMIC = 2 ln(SSE/N) - ln dV",
        "Code and equations part (Fig. 9)",
        "How to read this report",
    ):
        assert words in text
    assert "D = 0.001, up to t = 20" in text  # filled in from the config the report was built with
    assert report["title_top"] >= 0, "the description is too long: its title is cut off a 1500 x 1000 window"
    assert report["web_requests"] == [], "the report fetched something from the network"
    with capsys.disabled():
        print(f"\nreport built in {report['built_s']:.0f} s, browser checks done at {report['seconds']:.0f} s")
        print(f"screenshot of the start page: {report['start_shot']}")
        print(f"screenshot of the claims table: {report['claims_shot']}")


def test_report_shows_every_figure_with_a_caption_saying_what_to_look_for(report):
    assert set(report["figures"]) == set(FIGURES)
    for fig, shown in report["figures"].items():
        width, height = shown["size"]
        assert width > 100 and height > 100, fig
        assert "Look for" in shown["caption"], fig
        if fig == "tradeoff":
            assert "not a figure of the paper" in shown["caption"]
        else:
            assert f"Fig. {fig[3:]}" in shown["caption"], fig


def test_report_shows_the_claims_table(report):
    work, claims = report["workdir"], report["claims"]
    expected = pd.read_parquet(work / "results" / "tables" / "paper_claims.parquet")
    assert claims["header"] == ["claim", "paper", "reproduced", "tolerance", "result"]
    shown = [(row[0][0], row[4][0], row[4][1]) for row in claims["rows"]]
    verdicts = ["pass" if passed else "FAIL" for passed in expected["passed"]]
    wanted = [(claim, v, v.lower()) for claim, v in zip(expected["claim"], verdicts)]
    assert shown == wanted  # every claim, in order, with its verdict cell classed for colour
    assert {"pass", "FAIL"} <= {verdict for _, verdict, _ in shown}  # the tiny config passes some, fails others
    assert claims["summary"] == f"{int(expected['passed'].sum())} of {len(expected)} claims pass."
    assert "Look for" in report["claims_caption"]


def test_report_shows_the_comic_minima(report):
    header, *rows = report["comic"]
    minima = pd.read_parquet(report["workdir"] / "results" / "tables" / "comic_minima.parquet")
    assert header[:3] == ["label", "time", "n_opt"]
    assert [(r[0], int(r[2])) for r in rows] == list(zip(minima["label"], minima["n_opt"]))
    assert "Look for" in report["comic_caption"]
