"""What the browser tests of ``airgun-xl serve`` share: the server started as a process, plain
HTTP requests, Debian's Chromium under Playwright, and a page that records every request and
every error (tests/test_serve.py, tests/test_serve_pages.py)."""
import contextlib
import os
import shutil
import subprocess
import sys
import urllib.error
import urllib.request

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def start(root, *extra):
    """``airgun-xl serve`` on a free port: the process and its base URL (from its first
    line)."""
    process = subprocess.Popen(
        [sys.executable, "-m", "airgun_xl", "serve", "--archive", str(root), "--port", "0",
         *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    assert line.startswith("serving "), (line, process.stderr.read())
    url = line.split(" at ", 1)[1].split(" ", 1)[0].rstrip("/")
    listed(url)
    return process, url


def listed(url, timeout=60.0):
    """Wait until the server at ``url`` has read its listing and its runs' inputs (its pages
    say 503 before): A2, an input the index does not hold, is what the poll asks for."""
    import time

    deadline = time.monotonic() + timeout
    while get(f"{url}/shots.csv?input=A2")[0] == 503:
        assert time.monotonic() < deadline, "the listing was not read in time"
        time.sleep(0.02)  # a poll for a condition, not a wait for a guessed time


@contextlib.contextmanager
def serving(root):
    """A server on ``root`` for the block: its base URL; stopped by Ctrl-C (SIGINT) after."""
    import signal

    process, url = start(root)
    try:
        yield url
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=20)


def get(url, method="GET", headers=None):
    """(status, headers, body) of one request."""
    request = urllib.request.Request(url, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=20) as response:
            return response.status, dict(response.headers), response.read()
    except urllib.error.HTTPError as exc:
        return exc.code, dict(exc.headers), exc.read()


@contextlib.contextmanager
def chromium():
    """Debian's Chromium under Playwright (skipped where it is not installed)."""
    if CHROMIUM is None:
        pytest.skip("needs Debian's chromium (apt-get install chromium)")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        launched = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        try:
            yield launched
        finally:
            launched.close()


@contextlib.contextmanager
def watched(browser, server):
    """A fresh page that records every request's address and every page error; on leaving,
    no error and no request but to ``server``."""
    context = browser.new_context(viewport={"width": 1100, "height": 900})
    page = context.new_page()
    page.requests, page.errors = [], []
    page.on("request", lambda r: page.requests.append(r.url))
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.on("console", lambda m: m.type == "error" and page.errors.append(m.text))
    try:
        yield page
        assert not page.errors, page.errors
        assert all(u.startswith(server + "/") for u in page.requests), page.requests
    finally:
        context.close()


def screenshot(page, name):
    """With $AIRGUN_XL_SCREENSHOTS (a folder), the page as the browser drew it, for docs/."""
    folder = os.environ.get("AIRGUN_XL_SCREENSHOTS")
    if folder:
        page.screenshot(path=os.path.join(folder, f"{name}.png"), full_page=False)
