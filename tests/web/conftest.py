"""Fixtures of the web tests: a real ``fsmbt serve`` subprocess, and Debian's chromium driven by
Playwright (the system browser; never a downloaded one)."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from support.web_server import REPO, running_server

CHROMIUM = os.environ.get("FSMBT_CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]
#: Where the browser tests write their screenshots (docs/web.md lists the names).
SCREENSHOTS = Path(os.environ.get("FSMBT_SCREENSHOTS", REPO / "build" / "web-screenshots"))


@pytest.fixture(scope="module")
def server_url() -> Iterator[str]:
    with running_server("--workers", "2") as url:
        yield url


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).exists() and not shutil.which("chromium"):
        if os.environ.get("CI"):
            pytest.fail(f"no chromium at {CHROMIUM}: scripts/install_browser.sh installs it")
        pytest.skip(f"no chromium at {CHROMIUM}: run scripts/install_browser.sh")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield launched
        launched.close()


@pytest.fixture
def page(browser, server_url):
    context = browser.new_context(accept_downloads=True, viewport={"width": 1500, "height": 1100})
    opened = context.new_page()
    opened.goto(server_url)
    opened.wait_for_selector("body[data-ready='1']")
    yield opened
    context.close()


@pytest.fixture(scope="session")
def screenshots() -> Path:
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    return SCREENSHOTS
