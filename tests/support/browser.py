"""Headless Chromium driven by selenium, for tests of pages a person opens (report, JupyterLab).

:func:`chromium` yields a WebDriver or skips the test, with the reason, where Debian's
``chromium`` / ``chromium-driver`` (or selenium) are missing. The flags keep Chromium
off this machine's closed network (no background connections, updates or sync).
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

__all__ = ["CHROMIUM_FLAGS", "browser_logs", "chromium"]

CHROMIUM_FLAGS = (
    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-dev-shm-usage", "--use-gl=angle", "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
)


def _binaries() -> tuple[str, str] | None:
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    return (browser, driver) if browser and driver else None


@contextmanager
def chromium(tmp_path: Path, size: tuple[int, int] = (1400, 1000)) -> Iterator[Any]:
    """A headless Chromium WebDriver with browser console logging, closed on exit."""
    found = _binaries()
    if found is None:
        pytest.skip("headless Chromium not installed (Debian packages chromium and "
                    "chromium-driver; `make test` installs them as root)")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        pytest.skip("selenium is not installed (pip install -e .[dev])")
    options = webdriver.ChromeOptions()
    options.binary_location = found[0]
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--window-size={size[0]},{size[1]}")
    options.add_argument(f"--user-data-dir={tmp_path / 'chromium-profile'}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(found[1]), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def browser_logs(driver: Any, level: str = "SEVERE") -> list[str]:
    """Messages of the browser console at ``level`` since the last call."""
    return [entry["message"] for entry in driver.get_log("browser") if entry["level"] == level]
