"""Optional, lazy numba compilation for the friction kernels.

numba takes about a second to import, more than a short command spends on
friction: `fepost.friction.kernel` and `fepost.friction.nodesums` therefore
hold plain Python functions and compile them (from numba's on-disk cache after
the first time) only when a caller asks for the compiled path, and the callers'
``backend="auto"`` asks only for jobs large enough to repay that.
"""

from __future__ import annotations

import importlib.util
import threading

#: True when numba can be imported (the optional ``fast`` extra is installed).
AVAILABLE = importlib.util.find_spec("numba") is not None

_LOCK = threading.Lock()


def compile_functions(namespace: dict, names: tuple[str, ...], fastmath: set[str]) -> None:
    """Replace the functions ``names`` of a module (``namespace``, its globals) by their
    numba-compiled versions, once per process; they call one another by these global
    names, which numba resolves when it compiles the first call."""
    with _LOCK:
        if namespace.get("_COMPILED"):
            return
        import numba

        jit = numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=fastmath or False)
        for name in names:
            namespace[name] = jit(namespace[name])
        namespace["_COMPILED"] = True
