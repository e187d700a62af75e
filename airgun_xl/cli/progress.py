"""A progress bar for long fills, on a terminal only.

The kernel is one C call, so the bar moves by stages (running, summary, workbook, sidecar,
publishing). Each stage's share of the expected time comes from measured 5 ns fills of shot A
(benchmarks/bench_fill.py); within a stage the bar advances with the clock, never past the
next stage's start. Logs (stderr not a terminal) get nothing.
"""
import sys
import threading
import time

#: Seconds a fill is expected to take per time row (5 ns shot A: 1.2M rows in about 3 s).
SECONDS_PER_ROW = 2.5e-6

#: Fills expected to take less than this show no bar.
SHOW_AFTER_SECONDS = 2.0

#: Fraction of a fill's time at which each stage starts (measured; see the module docstring).
STAGES = {"running": 0.0, "summarizing": 0.15, "writing the workbook": 0.25,
          "writing the sidecar": 0.75, "archiving": 0.9, "publishing": 0.97}

WIDTH = 30

#: The bar on screen now, if any: other messages clear its line first.
ACTIVE: list = []

#: ``--quiet`` given: no bar, whatever the stream.
QUIET: list = []


def clear_line(stream):
    """Clear the bar's line before another message is printed on ``stream``."""
    if ACTIVE and ACTIVE[0].stream is stream:
        stream.write("\r\x1b[K")


class Progress:
    """``progress(stage)`` moves the bar to ``stage`` (a key of :data:`STAGES`);
    :meth:`close` ends it. A no-op when ``enabled`` is false."""

    def __init__(self, expected_seconds, stream=None, enabled=None):
        self.stream = stream if stream is not None else sys.stderr
        if enabled is None:
            enabled = expected_seconds >= SHOW_AFTER_SECONDS and _is_terminal(self.stream)
        self.enabled = enabled
        self.expected = max(expected_seconds, 1e-3)
        self.started = time.perf_counter()
        self.stage, self.stage_started = "running", self.started
        self._stop = threading.Event()
        self._thread = None
        if enabled:
            self._thread = threading.Thread(target=self._tick, daemon=True)
            self._thread.start()
            ACTIVE[:] = [self]

    @classmethod
    def for_rows(cls, rows, stream=None, enabled=None):
        return cls(rows * SECONDS_PER_ROW, stream, enabled)

    def __call__(self, stage):
        self.stage, self.stage_started = stage, time.perf_counter()
        self._draw()

    def fraction(self):
        """Where the bar stands: the stage's start, plus the clock within it, capped below the
        next stage's start."""
        start = STAGES.get(self.stage, 0.0)
        later = [f for f in STAGES.values() if f > start]
        end = min(later) if later else 1.0
        within = (time.perf_counter() - self.stage_started) / self.expected
        return min(start + within, end - 0.01)

    def _draw(self):
        if not self.enabled:
            return
        f = self.fraction()
        filled = int(round(f * WIDTH))
        elapsed = time.perf_counter() - self.started
        self.stream.write(f"\r[{'#' * filled}{'.' * (WIDTH - filled)}] {f:4.0%} "
                          f"{self.stage} ({elapsed:.1f} s)\x1b[K")
        self.stream.flush()

    def _tick(self):
        while not self._stop.wait(0.2):
            self._draw()

    def close(self):
        """Stop the bar and clear its line (what follows prints the outcome)."""
        if not self.enabled:
            return
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        ACTIVE.clear()
        self.stream.write("\r\x1b[K")
        self.stream.flush()


def _is_terminal(stream):
    if QUIET:
        return False
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False


class CountBar:
    """A campaign's one bar: shots done of all, and how many failed; on a terminal only.
    ``update(failed)`` counts one more shot done."""

    def __init__(self, total, stream=None, enabled=None):
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = _is_terminal(self.stream) if enabled is None else enabled
        self.total, self.done, self.failed = total, 0, 0
        self.started = time.perf_counter()
        if self.enabled:
            ACTIVE[:] = [self]
            self._draw()

    def update(self, failed=False):
        self.done += 1
        self.failed += bool(failed)
        self._draw()

    def advance(self, n=1):
        """``n`` more shots done (a study's chunk)."""
        self.done += int(n)
        self._draw()

    def _draw(self):
        if not self.enabled:
            return
        filled = int(round(self.done / max(self.total, 1) * WIDTH))
        failed = f", {self.failed} failed" if self.failed else ""
        self.stream.write(f"\r[{'#' * filled}{'.' * (WIDTH - filled)}] {self.done}/"
                          f"{self.total} shots{failed} "
                          f"({time.perf_counter() - self.started:.1f} s)\x1b[K")
        self.stream.flush()

    def close(self):
        if not self.enabled:
            return
        ACTIVE.clear()
        self.stream.write("\r\x1b[K")
        self.stream.flush()


def count_bar(total):
    """A :class:`CountBar` of ``total`` things (shots) on a terminal; None in logs, CI, or
    with ``--quiet``: what a study's ``progress_for`` makes."""
    bar = CountBar(total)
    return bar if bar.enabled else None
