"""A JupyterLab server for browser tests, started as a person starts it from the repository.

:func:`jupyterlab` runs ``python -m jupyterlab`` (what ``.venv/bin/jupyter lab`` runs)
in ``root`` on 127.0.0.1 and a free port, with this environment minus ``make``'s
headless settings (``ALTE_RENDER``, ``MPLBACKEND``, ``PYVISTA_OFF_SCREEN``), which a
person's shell does not have. Only what would touch files outside the test is moved
into ``tmp_path``: Jupyter's user configuration and runtime folders, the Lab settings
(autosave off, so opening a notebook never rewrites it) and workspaces. On exit the
server is asked to shut down (its kernels with it), then terminated if it lingers.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

__all__ = ["Lab", "jupyterlab"]

_HEADLESS = {"ALTE_RENDER", "MPLBACKEND", "PYVISTA_OFF_SCREEN", "JPY_SESSION_NAME", "DISPLAY"}


@dataclass
class Lab:
    """A running JupyterLab: its address, token, process and log file."""

    base: str
    token: str
    process: subprocess.Popen[bytes]
    log: Path
    runtime: Path

    def url(self, path: str) -> str:
        """Address of ``path`` (relative to the server's root) in the Lab page."""
        return f"{self.base}/lab/tree/{path}?token={self.token}"

    def api(self, path: str, method: str = "GET") -> Any:
        """JSON answer of the server's REST ``path`` (``/api/...``, ``/lab/api/...``)."""
        request = urllib.request.Request(f"{self.base}{path}", method=method,
                                         headers={"Authorization": f"token {self.token}"})
        with urllib.request.urlopen(request, timeout=20) as response:
            body = response.read()
        return json.loads(body) if body else None

    def log_text(self) -> str:
        """What the server printed so far (its terminal output)."""
        return self.log.read_text(errors="replace")


def _settings(folder: Path) -> Path:
    plugin = folder / "@jupyterlab" / "docmanager-extension" / "plugin.jupyterlab-settings"
    plugin.parent.mkdir(parents=True, exist_ok=True)
    plugin.write_text(json.dumps({"autosave": False}))
    return folder


def _wait_ready(lab: Lab, timeout: float) -> None:
    """Wait for the server's info file (it names the port), then for its status."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if lab.process.poll() is not None:
            pytest.fail(f"JupyterLab exited ({lab.process.returncode}):\n{lab.log_text()[-3000:]}")
        info = lab.runtime / f"jpserver-{lab.process.pid}.json"
        if info.is_file():
            with suppress(OSError, ValueError):
                lab.base = f"http://127.0.0.1:{json.loads(info.read_text())['port']}"
                lab.api("/api/status")
                return
        time.sleep(0.3)
    pytest.fail(f"JupyterLab not ready after {timeout:.0f} s:\n{lab.log_text()[-3000:]}")


def _stop(lab: Lab) -> None:
    """Shut the server down through its API (kernels included), else terminate it."""
    with suppress(OSError):
        lab.api("/api/shutdown", method="POST")
    try:
        lab.process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(lab.process.pid, signal.SIGTERM)
        try:
            lab.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(lab.process.pid, signal.SIGKILL)
            lab.process.wait()


@contextmanager
def jupyterlab(tmp_path: Path, root: Path, timeout: float = 90) -> Iterator[Lab]:
    """A JupyterLab server serving ``root`` (see the module docstring); skips without it."""
    pytest.importorskip("jupyterlab", reason="JupyterLab is not installed (pip install -e .)")
    home = tmp_path / "jupyter"
    runtime = home / "runtime"
    env = {k: v for k, v in os.environ.items() if k not in _HEADLESS}
    env |= {"JUPYTER_CONFIG_DIR": str(home / "config"), "JUPYTER_RUNTIME_DIR": str(runtime)}
    token = os.urandom(16).hex()
    command = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1",
               "--ServerApp.port=0", f"--IdentityProvider.token={token}",
               f"--ServerApp.root_dir={root}",
               f"--LabApp.user_settings_dir={_settings(home / 'settings')}",
               f"--LabApp.workspaces_dir={home / 'workspaces'}"]
    if os.geteuid() == 0:  # containers and CI run as root; JupyterLab refuses by default
        command.append("--allow-root")
    log = home / "server.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    with log.open("wb") as out:
        process = subprocess.Popen(command, cwd=root, env=env, stdout=out,
                                   stderr=subprocess.STDOUT, start_new_session=True)
    lab = Lab("", token, process, log, runtime)
    try:
        _wait_ready(lab, timeout)
        yield lab
    finally:
        _stop(lab)
