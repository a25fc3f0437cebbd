"""Set-up of the embedded cluster's worker processes (a Dask preload module).

Ctrl-C in a terminal reaches every process of the foreground group. Only the
client should act on it (stop the sweep, then shut the workers down); a worker
that also took it would print a KeyboardInterrupt traceback. So the workers
of the embedded cluster ignore SIGINT from their start.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker) -> None:
    """Called by Dask in each new worker process: ignore SIGINT."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
