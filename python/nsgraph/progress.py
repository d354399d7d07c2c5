"""Progress of long work on stderr, as the C++ reporter (lib/core progress.h) writes it.

On a terminal: one line redrawn in place, at most ten times a second, ended by a newline.
In a log (stderr redirected to a file or a pipe): a plain line every ``interval_s`` seconds
and one final line, never a carriage return, so a log stays one line per report instead of
one line thousands of characters long. The line is
``label: done/total (P%) E.Es, ETA Ns[, detail]`` (``label: done E.Es`` without a total).
"""
import sys
import time

__all__ = ["Progress"]

# A terminal redraw at most this often: faster is invisible and costs the caller.
_TERMINAL_INTERVAL_S = 0.1


def _is_terminal(stream):
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


class Progress:
    """``with Progress("predict test", len(tiles)) as bar: ... bar.advance()``.

    ``enabled=False`` writes nothing (a command's ``--quiet``). ``clock`` returns seconds
    (tests pass their own); ``stream`` defaults to ``sys.stderr`` at construction.
    """

    def __init__(self, label, total=0, enabled=True, stream=None, interval_s=5.0, clock=time.monotonic):
        self.label, self.total, self.enabled = label, int(total), enabled
        self.stream = sys.stderr if stream is None else stream
        self.terminal = enabled and _is_terminal(self.stream)
        self.interval_s, self.clock = interval_s, clock
        self.done, self.detail, self.finished = 0, "", False
        self.start_s = self.last_draw_s = clock()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.finish()
        return False

    def advance(self, n=1):
        self.done += n
        self._maybe_draw(force=False)

    def set_detail(self, text):
        self.detail = str(text)

    def finish(self):
        """Writes the final line once (later calls do nothing)."""
        if self.finished:
            return
        self.finished = True
        self._maybe_draw(force=True)

    def line(self):
        elapsed_s = self.clock() - self.start_s
        if self.total > 0:
            fraction = self.done / self.total
            eta_s = elapsed_s * (1.0 - fraction) / fraction if fraction > 0 else 0.0
            text = f"{self.label}: {self.done}/{self.total} ({100.0 * fraction:.0f}%) {elapsed_s:.1f}s, ETA {eta_s:.0f}s"
        else:
            text = f"{self.label}: {self.done} {elapsed_s:.1f}s"
        return text + (f", {self.detail}" if self.detail else "")

    def _maybe_draw(self, force):
        if not self.enabled:
            return
        now_s = self.clock()
        if not force and now_s - self.last_draw_s < (_TERMINAL_INTERVAL_S if self.terminal else self.interval_s):
            return
        self.last_draw_s = now_s
        if self.terminal:
            self.stream.write("\r\033[K" + self.line() + ("\n" if force else ""))
        else:
            self.stream.write(self.line() + "\n")
        self.stream.flush()
