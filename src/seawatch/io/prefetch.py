"""Read ahead: the items of an iterator produced in a background thread.

The track job decodes a frame and finds its horizon while the previous frame's ships are
detected and tracked: PyAV's decoder and most of OpenCV's and numpy's work release the
GIL, so on two cores the stages overlap. Written here because the standard library has
no bounded read-ahead iterator with error propagation and early-exit clean-up
(``concurrent.futures`` maps whole sequences; ``queue.Queue`` is the building block).
"""

from __future__ import annotations

import queue
import threading
import time
import warnings
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

T = TypeVar("T")

_ITEM, _ERROR, _END = 0, 1, 2

DEPTH = 3
"""Items that may wait for the consumer by default (:func:`prefetch`'s ``depth``): with
``skip``, how far a consumer may fall behind a live source before its items are dropped."""


class Skipped:
    """A ``skip`` for :func:`prefetch` that counts the items it is handed and remembers
    the first one's ``index`` (``"?"`` for an item without one). Its attributes are
    written by the prefetch thread and read by the consumer (an int and a reference:
    each assignment is atomic)."""

    def __init__(self) -> None:
        self.count = 0
        self.first: Any = None
        self._warned = False

    def __call__(self, item: Any) -> None:
        if self.first is None:
            self.first = getattr(item, "index", "?")
        self.count += 1

    def warn_once(self, consequence: str = "", stacklevel: int = 2) -> None:
        """Warn, once and only after an item was skipped, that the consumer is behind
        its source and frames are dropped (naming the first); ``consequence`` is
        appended to the message, ``stacklevel`` is that of the caller's own warning."""
        if self.count and not self._warned:
            self._warned = True
            warnings.warn(
                f"frame {self.first}: processing is behind the source; frames are dropped "
                f"to keep up with it{consequence}",
                stacklevel=stacklevel + 1,
            )


def prefetch(
    items: Iterable[Any],
    depth: int = DEPTH,
    work: Callable[[Any], T] | None = None,
    name: str = "seawatch-prefetch",
    skip: Callable[[Any], None] | None = None,
) -> Iterator[T]:
    """Iterate ``items`` (each passed through ``work`` when given) in a background
    thread, at most ``depth`` items ahead of the consumer, in order.

    An exception raised by ``items`` or ``work`` is raised by the returned iterator at
    that item, after the items before it. When the consumer stops early (``break``, an
    exception, Ctrl-C), the thread stops at its next item and the source iterator is
    closed in that thread.

    Args:
        items: any iterable (e.g. a :class:`~seawatch.io.video.VideoReader`).
        depth: how many items may wait (>= 1).
        work: optional per-item function run in the background thread.
        name: the thread's name (``threading``; shown by profilers and the benchmark).
        skip: keep up with a source that will not wait (a live camera): an item that
            arrives while ``depth`` items already wait — the consumer is behind — is
            handed to ``skip`` (to count it) instead of ``work`` and the queue. The
            thread then never blocks on a slow consumer (an item worked on while the
            queue filled still waits for its place), so the source is drained at its own
            rate and the consumer stays at most about ``depth`` items behind it, where
            a blocking queue leaves the backlog in the source (a live stream's socket
            and decoder) to grow without bound. None (default): every item, in order.

    Raises:
        ValueError: ``depth`` < 1.
    """
    if isinstance(depth, bool) or not isinstance(depth, int) or depth < 1:
        raise ValueError(f"depth: expected an integer >= 1, got {depth!r}")
    q: queue.Queue[tuple[int, Any]] = queue.Queue(maxsize=depth)
    stop = threading.Event()

    def put(kind: int, value: Any) -> bool:
        while not stop.is_set():
            try:
                q.put((kind, value), timeout=0.1)
                return True
            except queue.Full:
                continue
        return False

    def produce() -> None:
        it = iter(items)
        try:
            for x in it:
                if stop.is_set():
                    return
                if skip is not None and q.full():
                    skip(x)
                    continue
                if not put(_ITEM, work(x) if work is not None else x):
                    return
        except BaseException as exc:  # handed to the consumer, raised there
            put(_ERROR, exc)
            return
        finally:
            close = getattr(it, "close", None)
            if callable(close):
                close()
        put(_END, None)

    thread = threading.Thread(target=produce, name=name, daemon=True)
    thread.start()

    def consume() -> Iterator[T]:
        try:
            while True:
                kind, value = q.get()
                if kind == _END:
                    return
                if kind == _ERROR:
                    raise value
                yield value
        finally:
            stop.set()
            deadline = time.monotonic() + 2.0  # a live source may block in its read
            while thread.is_alive() and time.monotonic() < deadline:
                try:
                    q.get(timeout=0.05)  # unblock a producer waiting to put
                except queue.Empty:
                    pass

    return consume()
