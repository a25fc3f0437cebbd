"""Optional, lazy numba compilation for the friction kernels.

numba takes about a second to import, more than a short command spends on
friction: `fepost.friction.kernel` and `fepost.friction.nodesums` therefore
hold plain Python functions and compile them (from numba's on-disk cache after
the first time) only when a caller asks for the compiled path, and the callers'
``backend="auto"`` asks only for jobs large enough to repay that.
"""

from __future__ import annotations

import importlib.util
import os
import threading
from collections.abc import Callable, Mapping
from typing import Any

#: True when numba can be imported (the optional ``fast`` extra is installed).
AVAILABLE = importlib.util.find_spec("numba") is not None

_LOCK = threading.Lock()


def cache_folder() -> str:
    """Where numba keeps its compiled kernels, outside the source tree: ``NUMBA_CACHE_DIR``
    when set, else ``$XDG_CACHE_HOME/fepost/numba`` (``~/.cache/fepost/numba``)."""
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given:
        return given
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "fepost", "numba")


def _writable(folder: str) -> bool:
    """Whether ``folder`` exists or can be made, and can be written (else numba's own default)."""
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return False
    return os.access(folder, os.W_OK)


def compile_functions(
    namespace: dict,
    names: tuple[str, ...],
    fastmath: set[str],
    overloads: Mapping[str, Callable] | None = None,
) -> None:
    """Replace the functions ``names`` of a module (``namespace``, its globals) by their
    numba-compiled versions, once per process; they call one another by these global
    names, which numba resolves when it compiles the first call.

    ``overloads``: module functions whose compiled implementation depends on the types
    of their arguments, each with the function that returns that implementation for
    the numba types it is given (numba's ``overload``, with the same options)."""
    with _LOCK:
        if namespace.get("_COMPILED"):
            return
        import numba
        from numba.extending import overload

        config: Any = numba.config
        if not config.CACHE_DIR and _writable(cache_folder()):  # numba's default: beside the source
            config.CACHE_DIR = cache_folder()

        fm = fastmath or False
        for name, typed in (overloads or {}).items():
            overload(namespace[name], jit_options={"nogil": True, "error_model": "numpy", "fastmath": fm})(
                typed
            )
        jit = numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=fm)
        for name in names:
            namespace[name] = jit(namespace[name])
        namespace["_COMPILED"] = True
