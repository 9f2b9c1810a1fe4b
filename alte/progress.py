"""Progress bars that reach the person waiting, wherever the work runs.

A study's bar (grid runs, sensor missions, a table's maps) is a tqdm bar. Run from a
terminal or JupyterLab it is ``tqdm.auto``'s (text, or a widget in a notebook). Run in
a notebook kernel that ``alte report`` started, nobody watches the notebook: the
report opens a :class:`Relay` (a pipe its kernels find by :data:`ENV`), a kernel's bar
writes a short line there ("sweep runs 120/1344 [02:10<05:40]") every
:data:`KERNEL_INTERVAL_S` seconds, and the report shows it on its own terminal (beside
its bar over notebooks) or, on a log (CI, ``| tee``), as a line every
:data:`LOG_INTERVAL_S` seconds per bar. The bar's text stays out of the executed
notebook and its HTML.
"""

from __future__ import annotations

import contextlib
import functools
import os
import threading
import time
from collections.abc import Callable, Iterable
from types import TracebackType
from typing import TYPE_CHECKING, NoReturn, TextIO, TypeVar, overload

if TYPE_CHECKING:
    from tqdm import tqdm as bar_type

__all__ = ["ENV", "KERNEL_INTERVAL_S", "LINE_FORMAT", "LOG_INTERVAL_S", "Relay", "Throttle",
           "bar", "report_stream"]

#: Environment variable naming the file a kernel's bars write to (set by :class:`Relay`).
ENV = "ALTE_PROGRESS"
#: Seconds between two lines a kernel's bar writes to the report.
KERNEL_INTERVAL_S = 2.0
#: Seconds between two lines of one bar the report writes to a log (not a terminal).
LOG_INTERVAL_S = 30.0
#: What a kernel's bar writes: name, count, elapsed and estimated remaining time.
LINE_FORMAT = "{desc} {n_fmt}/{total_fmt} [{elapsed}<{remaining}]"

T = TypeVar("T")


class _Lines:
    """A bar's redraws (tqdm's ``\\r``) as one line each."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream

    def write(self, text: str) -> int:
        line = text.replace("\r", "").strip()
        return self.stream.write(line + "\n") if line else 0

    def flush(self) -> None:
        self.stream.flush()


@functools.cache
def report_stream() -> _Lines | None:
    """Where bars go when :data:`ENV` names a file that opens (None: tqdm's own)."""
    target = os.environ.get(ENV)
    if not target:
        return None
    try:
        stream = open(target, "a", buffering=1, encoding="utf-8")  # noqa: SIM115 - kept open
    except OSError:
        return None
    return _Lines(stream)


@overload
def bar(iterable: Iterable[T], *, total: float | None = None, desc: str | None = None,
        unit: str = "it", disable: bool = False, smoothing: float = 0.3,
        leave: bool = True) -> bar_type[T]: ...
@overload
def bar(iterable: None = None, *, total: float | None = None, desc: str | None = None,
        unit: str = "it", disable: bool = False, smoothing: float = 0.3,
        leave: bool = True) -> bar_type[NoReturn]: ...
def bar(iterable: Iterable[T] | None = None, *, total: float | None = None,
        desc: str | None = None, unit: str = "it", disable: bool = False,
        smoothing: float = 0.3, leave: bool = True) -> bar_type[T] | bar_type[NoReturn]:
    """A tqdm bar over ``iterable`` (or of ``total`` steps): lines to the report when
    this is a kernel of ``alte report``, else ``tqdm.auto``'s."""
    stream = report_stream()
    if stream is None:
        from tqdm.auto import tqdm

        return tqdm(iterable, total=total, desc=desc, unit=unit, disable=disable,
                    smoothing=smoothing, leave=leave)
    from tqdm import tqdm as text_bar

    return text_bar(iterable, total=total, desc=desc, unit=unit, disable=disable,
                    smoothing=smoothing, leave=leave, file=stream, bar_format=LINE_FORMAT,
                    mininterval=KERNEL_INTERVAL_S)


class Relay:
    """The report's end of its kernels' bars: a pipe they open through :data:`ENV`
    (``/proc/<pid>/fd/<n>``, set while the relay is open); ``show`` gets each line
    they write, in a thread of this process."""

    def __init__(self, show: Callable[[str], None]) -> None:
        self.show = show
        self._write = -1
        self._before: str | None = None
        self._thread: threading.Thread | None = None

    def __enter__(self) -> Relay:
        read, self._write = os.pipe()
        self._before = os.environ.get(ENV)
        os.environ[ENV] = f"/proc/{os.getpid()}/fd/{self._write}"
        self._thread = threading.Thread(target=self._pump, args=(read,), daemon=True)
        self._thread.start()
        return self

    def _pump(self, read: int) -> None:
        with os.fdopen(read, encoding="utf-8", errors="replace") as lines:
            for line in lines:
                if line.strip():
                    with contextlib.suppress(Exception):  # a display error stops no report
                        self.show(line.strip())

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        if self._before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = self._before
        os.close(self._write)  # the pump ends when the kernels' ends are closed too
        if self._thread is not None:
            self._thread.join(timeout=5.0)


class Throttle:
    """Lines for a log: each bar's line at most every ``every`` seconds, its last (100 %)
    always."""

    def __init__(self, write: Callable[[str], None], every: float = LOG_INTERVAL_S) -> None:
        self.write, self.every = write, every
        self._last: dict[str, float] = {}

    def __call__(self, line: str) -> None:
        name = line.rsplit(" ", 2)[0]  # "sweep runs 120/1344 [..]" -> "sweep runs"
        count = line.rsplit(" ", 2)[-2] if line.count(" ") >= 2 else ""
        done, _, total = count.partition("/")
        now = time.monotonic()
        if done == total or now - self._last.get(name, -self.every) >= self.every:
            self._last[name] = now
            self.write(line)
