"""The scene clock of one tab: the one time at which moving obstacles, the driving car and the
simulated movers are drawn, so what the planner avoided in time is seen avoided.

It is the only writer of the `Scene time` slider and the `Play scene time` box; the planner run
(Drive car) and the simulation set it through its methods, and the session draws the scene at
it whenever it changes.
"""

from __future__ import annotations

import math
import time

__all__ = ["SceneClock"]


class SceneClock:
    def __init__(self, slider, play, max_step: float) -> None:
        self._slider, self._play = slider, play
        self._max_step = max_step  # a late tick moves the clock no further: no jumps
        self._played_at = time.monotonic()

    @property
    def t(self) -> float:
        return self._slider.value

    def on_change(self, show) -> None:
        """``show(t)`` whenever the time changes (the slider, `set`, playing)."""
        self._slider.on_update(lambda _: show(self._slider.value))

    def set(self, t: float) -> None:
        self._slider.value = t

    def reach(self, t: float) -> None:
        """The slider reaches at least ``t`` (a path's or a simulation's end)."""
        self._slider.max = max(self._slider.max, math.ceil(t))

    def play_from_start(self) -> None:
        self._slider.value = 0.0
        self._play.value = True

    def advance(self, loop_end: float | None) -> None:
        """While playing, move on by the real time since the last call; back to 0 after
        ``loop_end`` (a driving car's path end), else after the slider's end."""
        now, last = time.monotonic(), self._played_at
        self._played_at = now
        if self._play.value:
            end = self._slider.max if loop_end is None else loop_end
            t = self._slider.value + min(now - last, self._max_step)
            self._slider.value = 0.0 if t > end else t
