"""The UI work queue (matedit.app.turns): one job a turn of the event loop, with the timers
and paints that became due meanwhile run between jobs; a key queued twice runs once, at its
first place, with the newer job; a job whose owner is gone is dropped."""

from __future__ import annotations

import time

import pytest

pytestmark = pytest.mark.gui


def test_jobs_run_one_a_turn_with_other_timers_between(qtbot):
    from PySide6.QtCore import QObject, QTimer

    from matedit.app.turns import Turns

    q = Turns()
    owner = QObject()
    ran: list[tuple[str, float]] = []

    def job(name: str, ms: float = 8.0):
        def run():
            ran.append((name, time.perf_counter()))
            end = time.perf_counter() + ms / 1e3
            while time.perf_counter() < end:  # a step that holds the UI thread
                pass
        return run

    ticks: list[float] = []
    tick = QTimer()
    tick.setInterval(2)
    tick.timeout.connect(lambda: ticks.append(time.perf_counter()))
    tick.start()
    q.add(owner, "a", job("a-old"))
    q.add(owner, "b", job("b"))
    q.add(None, "c", job("c"))
    q.add(owner, "a", job("a"))  # the newer job, at a's place
    assert q.pending(owner, "a") and q.pending(None, "c")
    qtbot.waitUntil(lambda: len(ran) == 3, timeout=5000)
    tick.stop()
    assert [n for n, _ in ran] == ["a", "b", "c"]
    for (_, t0), (_, t1) in zip(ran, ran[1:]):
        assert any(t0 < t < t1 for t in ticks), "no timer ran between two jobs"
    assert not q.pending(owner, "a")

    # cancelled, and an owner deleted before its turn: neither runs
    gone = QObject()
    q.add(gone, "x", job("x"))
    q.add(owner, "y", job("y"))
    q.add(owner, "z", job("z"))
    q.cancel(owner, "y")
    import shiboken6

    shiboken6.delete(gone)
    qtbot.waitUntil(lambda: not q.pending(owner, "z"), timeout=5000)
    assert [n for n, _ in ran][3:] == ["z"]

    # run_all: everything now, in order
    q.add(owner, "p", job("p", 0))
    q.add(owner, "q", job("q", 0))
    q.run_all()
    assert [n for n, _ in ran][-2:] == ["p", "q"]
