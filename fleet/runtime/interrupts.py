"""Ctrl-C and SIGTERM as a ``KeyboardInterrupt`` that cannot be lost.

Python runs a signal handler between two bytecodes of the main thread, whatever
that thread is doing. If it is running a finalizer at that moment (numba's
compiler frees LLVM objects in ``__del__``), the ``KeyboardInterrupt`` raised
there is printed as "Exception ignored in ..." and dropped, and the run goes on
as if nobody had pressed Ctrl-C. So the handler also notes the interrupt, and
the run's clock asks ``interrupted()`` once a tick (the waits before the first
tick ``raise_if_interrupted()``): a dropped interrupt ends the run one tick
later instead of never.

Inside the lockstep loop the handler raises nothing at all
(``interrupts_deferred``): the loop ends the run between two ticks, sends the
final tick and the result like any other end, and only then raises. The AGV
processes and the recorder then end on the world's word, not on its
disappearance, and the recording is a whole run that ended "interrupted".
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager

_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_pending = False
_depth = 0
_deferred = 0


def _handler(signum, frame) -> None:
    global _pending
    _pending = True
    if not _deferred:
        raise KeyboardInterrupt


@contextmanager
def interrupts_raised() -> Iterator[None]:
    """While inside, Ctrl-C and SIGTERM raise ``KeyboardInterrupt`` (SIGTERM too, so
    that the caller's clean-up runs) and are remembered for ``raise_if_interrupted``.
    Only for the main thread, as ``signal.signal`` is."""
    global _depth, _pending
    previous = {s: signal.signal(s, _handler) for s in _SIGNALS}
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        for s, handler in previous.items():
            signal.signal(s, handler)
        if _depth == 0:
            _pending = False


@contextmanager
def interrupts_deferred() -> Iterator[None]:
    """While inside (and inside ``interrupts_raised``), Ctrl-C and SIGTERM are only noted:
    the caller asks ``interrupted()`` where it can end cleanly."""
    global _deferred
    _deferred += 1
    try:
        yield
    finally:
        _deferred -= 1


def interrupted() -> bool:
    """Whether Ctrl-C or SIGTERM came while inside ``interrupts_raised``."""
    return _pending


def raise_if_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C or SIGTERM came while inside
    ``interrupts_raised`` (whether or not its exception got through)."""
    if _pending:
        raise KeyboardInterrupt
