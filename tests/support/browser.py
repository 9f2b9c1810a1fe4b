"""Headless Chromium driven by selenium, for tests of pages a person opens (report, JupyterLab).

:func:`chromium` yields a WebDriver or skips the test, with the reason, where Debian's
``chromium`` / ``chromium-driver`` (or selenium) are missing. The flags keep Chromium
off this machine's closed network (no background connections, updates or sync).
:func:`element_pixels`, :func:`is_blank` and :func:`changed_share` look at what an
element shows (a WebGL canvas included: the screenshot is the composited page), and
:func:`drag` moves the mouse across it as a person would. :func:`processes_naming`
finds processes a test left behind by a folder on their command line.
"""

from __future__ import annotations

import io
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest

__all__ = ["CHROMIUM_FLAGS", "browser_logs", "changed_share", "chromium", "drag",
           "element_pixels", "is_blank", "processes_naming"]

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


def element_pixels(element: Any, margin: float = 0.2) -> np.ndarray:
    """RGB pixels of ``element`` as shown on the page, without a ``margin`` share on each
    side (where toolbars and notifications sit), as an (h, w, 3) int array."""
    from PIL import Image

    rgb = np.asarray(Image.open(io.BytesIO(element.screenshot_as_png)).convert("RGB"), int)
    h, w = rgb.shape[:2]
    dy, dx = int(h * margin), int(w * margin)
    return rgb[dy:h - dy, dx:w - dx]


def is_blank(pixels: np.ndarray, share: float = 0.02) -> bool:
    """True when fewer than ``share`` of the pixels differ from the most common colour."""
    flat = pixels.reshape(-1, 3)
    colours, counts = np.unique(flat, axis=0, return_counts=True)
    background = colours[counts.argmax()]
    return bool(np.mean(np.abs(flat - background).sum(axis=1) > 30) < share)


def changed_share(before: np.ndarray, after: np.ndarray) -> float:
    """Share of pixels whose colour changed visibly between two views of one element."""
    return float(np.mean(np.abs(before - after).sum(axis=-1) > 30))


def drag(driver: Any, element: Any, offsets: tuple[tuple[int, int], ...] = ((60, 20),) * 3
         ) -> None:
    """Press the left button at the centre of ``element``, move by ``offsets``, release."""
    from selenium.webdriver.common.action_chains import ActionChains

    chain = ActionChains(driver).move_to_element(element).click_and_hold()
    for dx, dy in offsets:
        chain = chain.move_by_offset(dx, dy).pause(0.05)
    chain.release().perform()


def processes_naming(marker: str | Path) -> list[int]:
    """Pids of live processes (not zombies) whose command line contains ``marker``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:  # the process ended meanwhile
            continue
        if str(marker) in command and state != "Z":
            found.append(int(entry.name))
    return found
