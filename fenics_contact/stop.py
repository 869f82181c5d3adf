"""Stop a run cleanly on SIGINT (Ctrl-C) or SIGTERM (a batch scheduler's time limit).

A signal only sets a flag; the run looks at it at safe points (each Newton
iteration, each finished load step) through :meth:`StopOnSignal.check`,
which all processes call together and which raises :class:`StopRequested`
on every process when any of them got a signal. So no process leaves a
collective operation its partners are still in, and the stop happens
between file writes: every finished load step is on disk and closed.
A second signal of the same kind stops at once (the files of finished
steps are still safe: none is open between steps).
"""

from __future__ import annotations

import signal
import threading
from types import FrameType, TracebackType

from mpi4py import MPI

#: The signals that stop a run cleanly.
SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopRequested(Exception):
    """A run stopped by a signal.

    Attributes:
        signum: the signal number.
    """

    def __init__(self, signum: int) -> None:
        self.signum = int(signum)
        super().__init__(f"stopped by {self.signal_name}")

    @property
    def signal_name(self) -> str:
        """SIGINT, SIGTERM, ..."""
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        """The shell's convention for a signal: 128 + its number (130, 143)."""
        return 128 + self.signum


class StopOnSignal:
    """Context manager that turns SIGINT and SIGTERM into a collective, clean stop.

    Args:
        comm: the processes that stop together.
    """

    def __init__(self, comm: MPI.Comm = MPI.COMM_WORLD) -> None:
        self.comm = comm
        self.received = 0
        self._previous: dict[int, object] = {}

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        if self.received == signum:  # asked twice: stop now
            raise StopRequested(signum)
        self.received = signum

    def __enter__(self) -> StopOnSignal:
        if threading.current_thread() is threading.main_thread():
            for s in SIGNALS:
                self._previous[s] = signal.signal(s, self._handle)
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)  # type: ignore[arg-type]
        self._previous.clear()

    def check(self) -> None:
        """Raise :class:`StopRequested` on every process if any got a signal (collective)."""
        signum = self.comm.allreduce(self.received, op=MPI.MAX)
        if signum:
            raise StopRequested(signum)
