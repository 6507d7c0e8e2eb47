"""Progress of long runs: a tqdm bar (progress=True, when tqdm is installed) or the caller's own function.

The compiled core calls the reporter every 50 ms or so from the calling thread, with the units done (rows,
samples, or thousandths of the mesh) and their total; `finish` completes the bar when the work is done.
"""

from __future__ import annotations

from typing import Callable, TypeVar, Union

ProgressCallback = Callable[[int, int], object]
Result = TypeVar("Result")
Progress = Union[bool, None, ProgressCallback]


def checked(progress: object) -> Progress:
    """`progress` itself if it is one of the forms it takes; a TypeError saying them otherwise."""
    if progress is True or progress is None or progress is False or callable(progress):
        return progress
    raise TypeError(f"progress must be True, False, None or a function (done, total), not {progress!r}")


class Reporter:
    """What the core calls: (done, total) -> None."""

    def __init__(self, progress: Progress, description: str) -> None:
        self._bar = None
        self._callback: ProgressCallback | None = None
        self._last = (0, 0)
        if checked(progress) is True:
            try:
                import tqdm
            except ImportError:
                raise ImportError("progress=True draws a tqdm bar: pip install tqdm, or pass a function") from None
            self._bar = tqdm.tqdm(desc=description, total=0)
        elif callable(progress):
            self._callback = progress

    @property
    def active(self) -> bool:
        return self._bar is not None or self._callback is not None

    def __call__(self, done: int, total: int) -> None:
        self._last = (done, total)
        if self._callback is not None:
            self._callback(done, total)
        if self._bar is not None:
            self._bar.total = total
            self._bar.update(done - self._bar.n)

    def finish(self, total: int) -> None:
        """The work is done: the last report says all of it."""
        if self._last != (total, total):
            self(total, total)
        if self._bar is not None:
            self._bar.close()

    def abandon(self) -> None:
        """The work failed or was interrupted: the bar stops where it was."""
        if self._bar is not None:
            self._bar.close()


def run_with_progress(
    progress: Progress, description: str, total: int, call: Callable[[Reporter | None], Result]
) -> Result:
    """call(reporter or None) with the reporter finished or abandoned afterwards."""
    reporter = Reporter(progress, description)
    if not reporter.active:
        return call(None)
    try:
        result = call(reporter)
    except BaseException:
        reporter.abandon()
        raise
    reporter.finish(total)
    return result
