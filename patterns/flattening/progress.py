"""How far :func:`patterns.flatten` is: one ``progress(done, total)`` that moves and never goes back.

A model's panels are flattened one by one, each by one relaxation; where ``max_strain`` parts and darts a
panel, a search flattens it, or its pieces, tens of times first, and how many times is not known before it
ends.  :class:`Bar` gives each stage its span of the bar (``total`` is the model's panel count): the span
fills as the flattenings inside it go (the engine's own ``progress``: ``(0, 1)`` as a flattening starts, then
``(iteration, max_iterations)``): to ``k / (k + 1)`` of it after ``k`` flattenings (a half after one, nine
tenths after nine), so that a long search moves with every flattening it makes, however few iterations each
takes; it is full when the stage ends.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["Bar"]

_STEP = 1e-3
"""The bar is told of a move of at least this share of ``total`` (and of every stage's end)."""


class Bar:
    """The progress of one :func:`patterns.flatten` call.

    Parameters
    ----------
    progress : callable
        ``progress(done, total)``: ``done`` (float) of ``total`` (float: the model's panel count), never
        less than the time before.
    total : int
        The model's panel count.
    """

    def __init__(self, progress: Callable[[float, float], object], total: int):
        self._progress, self.total = progress, float(total)
        self._lo = self._hi = self._told = 0.0
        self._runs, self._share, self._started = 0, 0.0, False

    def span(self, lo: float, hi: float) -> None:
        """The next stage fills the bar from ``lo`` to ``hi`` (of ``total``); the stage before is done."""
        self._tell(self._hi, force=True)
        self._lo, self._hi = max(lo, self._hi), max(hi, self._hi)
        self._runs, self._share, self._started = 0, 0.0, False

    def engine(self, done: float, total: float) -> None:
        """The engine's ``progress``: ``done`` 0 as a flattening starts (the stage's next one, after the
        first), then its iteration ``done`` of ``total``."""
        if done <= 0:
            self._runs += self._started
            self._share, self._started = 0.0, True
        else:
            self._share = max(self._share, min(done / total, 1.0) if total > 0 else 1.0)
        work = self._runs + self._share  # flattenings done, and the share of this one
        self._tell(self._lo + (self._hi - self._lo) * work / (work + 1.0))

    def finish(self) -> None:
        """The last stage is done: the bar is full."""
        self._tell(self.total, force=True)

    def _tell(self, done: float, *, force: bool = False) -> None:
        done = min(max(done, self._told), self.total)
        if done > self._told and (force or done - self._told >= _STEP * self.total):
            self._told = done
            self._progress(done, self.total)
