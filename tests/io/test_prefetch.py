"""prefetch: order, errors at their item, early exit closes the source in its thread."""

from __future__ import annotations

import threading

import pytest

from seawatch.io.prefetch import prefetch


def test_items_come_in_order_through_the_work_function():
    out = list(prefetch(range(100), depth=2, work=lambda x: (x, x * x)))
    assert out == [(x, x * x) for x in range(100)]


def test_an_error_is_raised_at_its_item_after_the_items_before_it():
    def source():
        yield 1
        yield 2
        raise OSError("frame 3: corrupt")

    got = []
    with pytest.raises(OSError, match="frame 3"):
        for x in prefetch(source()):
            got.append(x)
    assert got == [1, 2]


def test_stopping_early_closes_the_source_in_the_background_thread():
    closed = threading.Event()
    threads = []

    def source():
        try:
            i = 0
            while True:
                threads.append(threading.current_thread().name)
                yield i
                i += 1
        finally:
            closed.set()

    it = prefetch(source(), depth=1)
    assert [next(it) for _ in range(3)] == [0, 1, 2]
    it.close()
    assert closed.wait(2.0)
    assert set(threads) == {"seawatch-prefetch"}


def test_bad_depth_raises_naming_it():
    with pytest.raises(ValueError, match="depth"):
        prefetch([1], depth=0)


def test_skip_drops_what_arrives_while_the_consumer_is_behind():
    """A source that does not wait (a live camera): with ``skip`` the thread drains it
    while nobody consumes, keeps the first ``depth`` items and hands every later one to
    ``skip`` (not to ``work``) instead of blocking."""
    drained = threading.Event()
    worked = []

    def source():
        yield from range(50)
        drained.set()

    def work(x):
        worked.append(x)
        return -x

    skipped = []
    it = prefetch(source(), depth=3, work=work, skip=skipped.append)
    assert drained.wait(5.0)  # the source ran to its end with no consumer
    assert list(it) == [0, -1, -2]
    assert skipped == list(range(3, 50)) and worked == [0, 1, 2]


def test_without_skip_a_consumer_behind_blocks_the_source_and_loses_nothing():
    drained = threading.Event()

    def source():
        yield from range(50)
        drained.set()

    it = prefetch(source(), depth=3)
    assert not drained.wait(0.3)  # held back by the full queue
    assert list(it) == list(range(50))
