"""Progress as the reader sees it: a tqdm bar on a terminal; in a log file or a pipe, a plain
line at most every :data:`PLAIN_SECONDS` and one at the end (no carriage returns, no escape
codes)."""

import sys
import time

from tqdm import tqdm

PLAIN_SECONDS = 30.0


class _PlainLines:
    """A counter with tqdm's ``n``, ``update`` and ``close`` that writes plain lines."""

    def __init__(self, *, total=None, initial=0, desc: str = "", unit: str = "it", **_):
        self.n, self.total, self.desc, self.unit = initial, total, desc, unit
        self._start = self._last = time.monotonic()

    def _Line(self) -> None:
        of = f"/{self.total:g}" if self.total else ""
        elapsed = time.monotonic() - self._start
        print(f"{self.desc}: {self.n:g}{of} {self.unit} ({elapsed:.0f} s)", file=sys.stderr)
        self._last = time.monotonic()

    def update(self, count=1) -> None:
        self.n += count
        if time.monotonic() - self._last >= PLAIN_SECONDS:
            self._Line()

    def refresh(self) -> None:
        pass

    def close(self) -> None:
        self._Line()


def ProgressBar(**options):
    """A tqdm bar (``options`` as for tqdm) when standard error is a terminal, else plain lines."""
    if options.get("disable") or sys.stderr.isatty():
        return tqdm(**options)
    return _PlainLines(**options)


def Say(line: str) -> None:
    """``line`` on standard error, beside any bars (tqdm moves them out of its way)."""
    tqdm.write(line, file=sys.stderr)
