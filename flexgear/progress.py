"""Progress display: a tqdm bar on a terminal, plain lines in a log file.

On a terminal (``stream.isatty()``) :class:`Progress` draws a tqdm bar that updates in place. Anywhere
else (a log file, a pipe, CI) carriage returns would run together, so it prints one plain line per
``plain_step`` of the total (default: every 25 %) and one at the end. :func:`say` prints a message
without breaking an active bar.
"""

from __future__ import annotations

import sys
import time
from typing import IO, Any

__all__ = ["Progress", "say"]


def _is_tty(stream: IO[str]) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def say(text: str, stream: IO[str] | None = None) -> None:
    """Print one message line on ``stream`` (stderr), above an active tqdm bar if there is one."""
    stream = sys.stderr if stream is None else stream
    if _is_tty(stream):
        from tqdm import tqdm

        tqdm.write(text, file=stream)
    else:
        print(text, file=stream, flush=True)


class Progress:
    """Progress of ``total`` units (steps, seconds of simulated time, runs), labelled ``desc``.

    ``enabled=False`` shows nothing. ``fmt`` formats a value for the plain lines (default ``{:g}``).
    """

    def __init__(self, total: float, desc: str, unit: str = "", enabled: bool = True,
                 stream: IO[str] | None = None, plain_step: float = 0.25, fmt: str = "{:g}") -> None:
        self.total, self.desc, self.unit, self.enabled = float(total), desc, unit, enabled
        self.stream = sys.stderr if stream is None else stream
        self.plain_step, self.fmt = plain_step, fmt
        self.value = 0.0
        self._postfix = ""
        self._next_plain = plain_step
        self._t0 = time.perf_counter()
        self._bar: Any = None
        if enabled and _is_tty(self.stream):
            from tqdm import tqdm

            self._bar = tqdm(total=self.total, desc=desc, unit=unit, file=self.stream, leave=True,
                             dynamic_ncols=True, bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} {unit} "
                             "[{elapsed}<{remaining}{postfix}]")

    def update_to(self, value: float, postfix: str = "") -> None:
        """Set the progress to ``value`` (of ``total``); ``postfix``: a short status after the bar."""
        if not self.enabled:
            return
        value = min(float(value), self.total)
        self._postfix = postfix or self._postfix
        if self._bar is not None:
            self._bar.update(value - self._bar.n)
            if postfix:
                self._bar.set_postfix_str(postfix, refresh=False)
        elif self.total > 0:
            while value / self.total >= self._next_plain - 1e-12 and self._next_plain < 1.0 - 1e-12:
                self._plain(value, postfix)
                self._next_plain += self.plain_step
        self.value = value

    def extend(self, total: float) -> None:
        """A longer task than announced (a run continued until it settles): the new ``total``."""
        self.total = float(total)
        if self._bar is not None:
            self._bar.total = self.total
            self._bar.refresh()

    def _plain(self, value: float, postfix: str) -> None:
        pct = 100.0 * value / self.total if self.total > 0 else 100.0
        text = (f"{self.desc}: {self.fmt.format(value)}/{self.fmt.format(self.total)} {self.unit} ({pct:.0f} %), "
                f"{time.perf_counter() - self._t0:.1f} s")
        print(text + (f", {postfix}" if postfix else ""), file=self.stream, flush=True)

    def close(self, postfix: str = "") -> None:
        """Finish the display (a last plain line with the final value and the elapsed time)."""
        if not self.enabled:
            return
        if self._bar is not None:
            if postfix:
                self._bar.set_postfix_str(postfix, refresh=False)
            self._bar.close()
            self._bar = None
        elif self._next_plain <= 1.0 + 1e-12:
            self._plain(self.value, postfix or self._postfix)
            self._next_plain = 2.0

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
