"""The reading child's first step after ``os.fork``: let go of what other threads held.

Why this module
---------------
A forked child holds one thread, the one that called ``fork``; every lock the
caller's *other* threads held at that instant stays held in the child for ever.
CPython re-creates its own global locks after a fork (the GIL, the global
import lock, the ``logging`` and ``threading`` locks), but not two kinds the
reading child meets:

* **Per-module import locks.** A Dask worker unpickles tasks and imports on its
  event-loop thread while a task thread forks a reader. If that thread was
  importing module *M* (say a numpy submodule that numpy loads on first
  attribute access, or ``netCDF4`` itself) at the fork, a child that imports or
  touches *M* waits for the lock of a thread that does not exist in it. This
  was seen: ``netCDF4``'s import in the child blocked in
  ``importlib._bootstrap._ModuleLock.acquire`` under ``numpy.__getattr__`` until
  the read's deadline.
* **The buffered streams' locks** (``sys.stdout``, ``sys.stderr``): a thread
  writing to them at the fork leaves the child unable to flush them.

`settle` therefore forgets the import machinery's per-module locks and
the modules that another thread was still initialising (the child imports them
afresh, whole), and gives the child new ``sys.stdout``/``sys.stderr`` objects
on the descriptors it redirects, never flushing the inherited ones (what they
buffer belongs to the caller, which flushed its own before forking).

This reaches into ``importlib._bootstrap`` (``_module_locks``,
``_blocking_on``): no public API resets import state after a fork. Where those
names are missing (another Python), the step is skipped and the read's
deadline still guards the caller.
"""

from __future__ import annotations

import io
import os
import sys


def settle() -> None:
    """In a freshly forked child: drop foreign import locks and half-imported modules.

    The modules being initialised at the fork are those with an import under way, which
    the per-module lock table names; only they are looked at. Every object the child
    touches costs it a copy of its memory page (copy-on-write): a walk over all of
    ``sys.modules`` cost each read about 8 ms in a large process."""
    # the loaded bootstrap module itself: an import statement here could block already
    bootstrap = sys.modules.get("_frozen_importlib") or sys.modules.get("importlib._bootstrap")
    if bootstrap is None:  # another Python: nothing to reset
        return
    locks = getattr(bootstrap, "_module_locks", None)
    busy = list(locks) if isinstance(locks, dict) else list(sys.modules)
    for name in ("_module_locks", "_blocking_on"):
        table = getattr(bootstrap, name, None)
        if table is not None and hasattr(table, "clear"):
            table.clear()
    for name in busy:
        module = sys.modules.get(name)
        spec = getattr(module, "__spec__", None)
        if spec is not None and getattr(spec, "_initializing", False):
            # another thread's import, cut off by the fork: import afresh if needed
            del sys.modules[name]


def fresh_streams() -> None:
    """New ``sys.stdout`` and ``sys.stderr`` on descriptors 1 and 2 (the inherited objects
    are left alone: their locks may belong to a thread the child does not have)."""
    for fd, attr in ((1, "stdout"), (2, "stderr")):
        try:
            stream = io.TextIOWrapper(
                io.FileIO(os.dup(fd), "w", closefd=True),
                encoding="utf-8",
                errors="replace",
                line_buffering=True,
            )
        except OSError:
            continue
        setattr(sys, attr, stream)
        setattr(sys, f"__{attr}__", stream)
