"""One BLAS thread for a block of code, without re-inspecting the process each time.

``threadpoolctl.threadpool_limits`` finds the loaded BLAS libraries anew on every call
(it reads ``/proc/self/maps`` and opens each library): about 2 ms, which is 10 % of a
``fepost diagnose`` run that integrates friction some sixty times. threadpoolctl's own
remedy is one `threadpoolctl.ThreadpoolController` per process, whose ``limit`` only sets
and restores the thread counts; `one_blas_thread` keeps that controller (made on first use,
after numpy has loaded its BLAS).
"""

from __future__ import annotations

import functools

from threadpoolctl import ThreadpoolController


@functools.cache
def _controller() -> ThreadpoolController:
    return ThreadpoolController()


def warm() -> None:
    """Make the controller now (it inspects the loaded libraries: 5-10 ms), e.g. while a file is read."""
    _controller()


def one_blas_thread():
    """Context manager: BLAS limited to one thread inside, its previous setting restored after."""
    return _controller().limit(limits=1, user_api="blas")
