"""The Franka hand's commands, sent from a thread of their own so that the 20 Hz loop never waits.

The hand runs one command at a time and answers it only when the fingers have settled: a grasp
closing on air takes about 0.6 s. A policy may open again before that, and a second command sent
while the first runs blocks its caller until the first is answered (franky holds the gripper
connection meanwhile; franky-sim never answers a command it was told to stop). So the loop only
states what it wants; this worker sends the newest wanted state as soon as the hand is free, and
a command superseded while it waited is never sent.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

logger = logging.getLogger(__name__)


class GripperWorker:
    """Latest-wins gripper commands: ``want(closed)`` returns at once; a thread sends them in turn."""

    def __init__(self, close: Callable[[], object], open_: Callable[[], object]) -> None:
        self._close, self._open = close, open_
        self._cond = threading.Condition()
        self._wanted: bool | None = None
        self._sent: bool | None = None
        self._busy = False
        self._stopping = False
        self._error: Exception | None = None  # the last command's failure, raised by the owner
        self._thread = threading.Thread(target=self._run, name="gripper", daemon=True)
        self._thread.start()

    def want(self, closed: bool) -> None:
        with self._cond:
            self._wanted = bool(closed)
            self._cond.notify_all()

    def take_error(self) -> Exception | None:
        with self._cond:
            error, self._error = self._error, None
            return error

    def wait_idle(self, timeout: float) -> bool:
        """Block until the wanted state was sent and answered (True) or ``timeout`` seconds passed."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._busy and self._wanted == self._sent, timeout)

    def close(self, timeout: float) -> bool:
        """Send nothing more; wait (bounded) for a running command. True: the thread has ended."""
        with self._cond:
            self._stopping = True
            self._cond.notify_all()
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def _run(self) -> None:
        while True:
            with self._cond:
                self._cond.wait_for(lambda: self._stopping or self._wanted != self._sent)
                if self._stopping:
                    return
                target = self._wanted
                self._busy = True
            try:
                (self._close if target else self._open)()  # a grasp on air answers False: not a failure
            except Exception as error:  # noqa: BLE001 - handed to the loop's thread, which maps it
                logger.warning("gripper command failed: %s", error)
                with self._cond:
                    self._error = error
            with self._cond:
                self._sent = target
                self._busy = False
                self._cond.notify_all()
