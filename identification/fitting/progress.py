"""Progress bars of long work (tqdm, on stderr), shown only where someone watches.

A bar draws only when stderr is a terminal (or in a Jupyter kernel): redirected to a file, its
carriage-return redraws would fill the log and glue the next line (a ``WARNING:``) to the last
bar. Without tqdm (the base install) there are no bars.
"""
from __future__ import annotations

import sys
import threading
import weakref

from identification.fitting.presets import SearchSettings

_open_bars = weakref.WeakSet()
"""The bars made by :func:`bar` and not yet garbage (a closed bar's close() does nothing)."""


def watched() -> bool:
    """Whether someone sees the bars: stderr is a terminal, or this is a Jupyter kernel (whose
    stderr is no terminal but shows the bars)."""
    if "ipykernel" in sys.modules:
        return True
    stream = sys.stderr
    try:
        return stream is not None and stream.isatty()
    except (AttributeError, ValueError):   # a closed or unusual stream
        return False


def bar(total: int, description: str, unit: str, enabled: bool = True, leave: bool = False):
    """A tqdm bar on stderr, or None when disabled or nobody watches."""
    if not (enabled and watched()):
        return None
    try:
        from tqdm import tqdm
    except ImportError:   # the base install: work goes on without a bar
        return None
    made = tqdm(total=total, desc=description, unit=unit, leave=leave, file=sys.stderr)
    _open_bars.add(made)
    return made


_pending_notices = weakref.WeakSet()
"""The notices of :func:`notice_later` not yet shown or cancelled."""


def notice_later(seconds: float, message) -> threading.Timer:
    """Print ``message()`` on stderr after ``seconds`` unless the returned timer is cancelled
    first (or :func:`close_open_bars` cancels it): a note on work that turns out to be long."""
    def show():
        _pending_notices.discard(timer)
        print(message(), file=sys.stderr, flush=True)
    timer = threading.Timer(seconds, show)
    timer.daemon = True
    _pending_notices.add(timer)
    return timer


def close_open_bars() -> None:
    """Close every bar still drawn and cancel every notice not yet shown (a command interrupted
    in the middle of its work), so that the next line on stderr starts on a line of its own and
    nothing is printed after the command's last line, while the interpreter shuts down."""
    for open_bar in list(_open_bars):
        open_bar.close()
    for notice in list(_pending_notices):
        notice.cancel()


class SearchProgress:
    """One bar for the screening and one for each least-squares stage of a fit."""

    def __init__(self, enabled: bool, settings: SearchSettings, screening_total: int):
        self.enabled = enabled
        self.settings = settings
        self.screening_total = screening_total
        self._bar = None
        self._stage = None

    def screening(self, count: int):
        self._advance("screening", self.screening_total, "points", count)

    def stage(self, index: int, count: int, again: bool = False, more: bool = False, total: int | None = None):
        starts, evaluations = self.settings.stages[index]
        starts = total or starts
        self._advance(f"stage {index + 1}/{len(self.settings.stages)} ({starts} starts x {evaluations})"
                      + (" again, finer steps" if again else "") + (" on more starts" if more else ""),
                      starts, "starts", count)

    def _advance(self, name, total, unit, count):
        if self._stage != name:
            self.close()
            self._bar = bar(total, name, unit, self.enabled)
            self._stage = name
        if self._bar is not None:
            self._bar.update(count)

    def close(self):
        if self._bar is not None:
            self._bar.close()
            self._bar = None
