"""Run a reading function in a child process, so a malformed file cannot kill the caller.

Why a child process
-------------------
VTK's readers and the netCDF/HDF5 libraries are C/C++ code: a corrupt or
hostile file can make them dereference a wild pointer (SIGSEGV), abort
(SIGABRT), allocate without bound or loop for ever. No amount of checking in
Python catches that inside the process. fepost validates what it can before
handing a file to those libraries (`fepost.reader.vtkcheck`,
`fepost.reader.exodus`) and, in addition, reads every file in a forked
child: a crash, a hang or an exhausted memory limit in the child becomes one
`fepost.errors.InputFileError` in the caller.

How
---
* ``os.fork`` (not `multiprocessing`): the child inherits the already
  imported modules, starts in milliseconds, and works inside daemonic
  processes (Dask workers), where ``multiprocessing`` refuses to start children.
* The child first lets go of what the caller's other threads held at the fork
  (per-module import locks, the streams' locks; `fepost.reader.afterfork`):
  a Dask worker imports on one thread while another forks a reader.
* The child's file descriptors 1 and 2 are redirected to an anonymous memory
  file, so the C libraries' chatter is captured at the descriptor level; the
  first error line is quoted in the message, nothing reaches the terminal.
* The child's address space is limited (`MEMORY_BUDGET` beyond what it
  holds at the fork), so a header declaring 10¹² points fails fast.
* The result travels back as a pickle (protocol 5) whose large numpy buffers
  go out of band into one anonymous private map in the caller (the caller's
  arrays are views of it), copied straight out of the waiting child where
  Linux allows it, else through the pipe (`fepost.reader.transfer`).
* The parent waits with a deadline (`timeout_for`); a child that misses
  it is killed. A child that has sent its whole answer is reaped in the
  background: its exit (freeing its memory) is not waited for.
* The modules a child had to import (a format's parser, its compression
  codecs) are named in its answer and imported by the caller before its next
  fork: a process that reads many files (a sweep, a test session) pays each
  import once instead of once per file (30-50 ms a read); a single read is
  not delayed (`preload`).
* Warnings the child issues are recorded and re-issued in the caller (fepost
  warnings only); exceptions are re-raised (fepost errors as they are, anything
  else as a one-line `fepost.errors.InputFileError` whose cause holds
  the child's traceback, shown by ``fepost --debug``).

Where ``os.fork`` does not exist, or with ``FEPOST_READ_ISOLATION=off``, the
function runs in the calling process (the validation still applies).
"""

from __future__ import annotations

import itertools
import os
import pickle
import signal
import struct
import sys
import time
import traceback
import warnings
from collections.abc import Callable
from typing import Any

from ..errors import FepostError, FepostWarning, InputFileError
from . import afterfork, transfer

try:  # imported here, not in each child (an import there costs every read)
    import resource
except ImportError:  # not on this platform: no memory limit, the deadline still applies
    resource = None  # type: ignore[assignment]

#: Environment variable: ``off`` reads in the calling process (no child).
ISOLATION_ENV = "FEPOST_READ_ISOLATION"
#: Environment variable: the read timeout in seconds (overrides `timeout_for`).
TIMEOUT_ENV = "FEPOST_READ_TIMEOUT"
#: Base read timeout, s, plus `TIMEOUT_PER_MB` per MB of file.
TIMEOUT_BASE = 60.0
TIMEOUT_PER_MB = 2.0
#: Address space the child may add to what it holds at the fork: max of this and 64 × the file size, bytes.
MEMORY_BUDGET = 6 << 30
#: Pipe size asked for on Linux (fewer wake-ups on large results).
_PIPE_SIZE = 1 << 20


#: Modules the reading children imported that the caller had not (imported before the next fork).
_CHILD_IMPORTS: set[str] = set()
#: Modules that failed to import here: left to the children, not tried again.
_NOT_HERE: set[str] = set()


def preload() -> None:
    """Import in this process what earlier reading children had to import (module docstring).

    A module that fails to import here is left to the children, as before. Only the names
    the children reported are looked at (a set of all of ``sys.modules`` cost 2 ms a read).
    """
    if not _CHILD_IMPORTS:
        return
    import importlib

    for name in sorted(_CHILD_IMPORTS):
        if name not in sys.modules:
            try:
                importlib.import_module(name)
            except Exception:  # noqa: BLE001 (any failure: leave the import to the child)
                _NOT_HERE.add(name)
    _CHILD_IMPORTS.clear()


class ChildTraceback(Exception):
    """The traceback of an unexpected exception in the reading child (for ``--debug``)."""


def isolation_enabled() -> bool:
    """True when files are read in a forked child (the default where ``os.fork`` exists)."""
    return hasattr(os, "fork") and os.environ.get(ISOLATION_ENV, "").strip().lower() not in ("off", "0", "no")


def timeout_for(nbytes: int) -> float:
    """The read deadline (s) for a file of ``nbytes``; ``FEPOST_READ_TIMEOUT`` overrides it."""
    env = os.environ.get(TIMEOUT_ENV)
    if env:
        try:
            value = float(env)
        except ValueError:
            value = float("nan")
        if value > 0:
            return value
    return TIMEOUT_BASE + TIMEOUT_PER_MB * nbytes / 1e6


def call(
    func: Callable[..., Any],
    *args: Any,
    what: str,
    nbytes: int = 0,
    timeout: float | None = None,
    **kwargs: Any,
) -> Any:
    """Return ``func(*args, **kwargs)``, computed in a forked child when isolation is enabled.

    Parameters
    ----------
    what : str
        The file being read: the prefix of every error message.
    nbytes : int
        Its size in bytes (sets the deadline and the memory budget).
    timeout : float, optional
        Deadline in s (default `timeout_for`).

    Raises
    ------
    FepostError
        Whatever ``func`` raised on purpose.
    InputFileError
        The child crashed, ran out of memory or time, or ``func`` failed unexpectedly.
    """
    return start(func, *args, what=what, nbytes=nbytes, timeout=timeout, **kwargs).result()


class Pending:
    """A call started by `start`: `result` waits for it, `cancel` abandons it."""

    def __init__(self, what: str, value: Any = None, error: BaseException | None = None, child=None):
        self.what = what
        self._value, self._error, self._child = value, error, child

    @property
    def pid(self) -> int | None:
        """Process id of the reading child while it computes the value (None in-process or after)."""
        return None if self._child is None else self._child[0]

    @property
    def running(self) -> bool:
        """True while a child computes the value (False once `result` has collected it)."""
        return self._child is not None

    def result(self) -> Any:
        """The function's value (raises what it raised, or the child's failure)."""
        if self._child is not None:
            child, self._child = self._child, None
            try:
                self._value = _finish(*child)
            except BaseException as exc:
                self._error = exc
        if self._error is not None:
            error, self._error = self._error, None
            raise error
        return self._value

    def cancel(self) -> None:
        """Kill the child if it still runs (nothing is left behind)."""
        if self._child is not None:
            pid, reader = self._child[0], self._child[1]
            self._child = None
            _reap(pid, kill=True)
            reader.close()

    def __del__(self) -> None:
        try:
            self.cancel()
        except Exception:  # interpreter shutdown: nothing more to do
            pass


def start(
    func: Callable[..., Any],
    *args: Any,
    what: str,
    nbytes: int = 0,
    timeout: float | None = None,
    **kwargs: Any,
) -> Pending:
    """Start ``func(*args, **kwargs)`` in a forked child and return at once (see `call`).

    The caller can go on with other work (imports, a second file) while the
    child reads; without isolation the function runs here and now.
    """
    if not isolation_enabled():
        try:
            return Pending(what, value=_in_process(func, args, kwargs, what))
        except (KeyboardInterrupt, SystemExit):
            raise
        except BaseException as exc:
            return Pending(what, error=exc)
    deadline = timeout if timeout is not None else timeout_for(nbytes)
    preload()
    return Pending(what, child=_fork(func, args, kwargs, what, nbytes, deadline))


def _unexpected(what: str, name: str, first: str, tb: str, detail: str = "") -> InputFileError:
    """The one-line error for an unexpected exception ``name: first`` (``tb`` kept for ``--debug``)."""
    msg = f"{what}: cannot read the file ({name}: {first})"
    if detail and detail not in msg:
        msg = f"{msg}; reader said: {detail}"
    err = InputFileError(msg)
    err.__cause__ = ChildTraceback(tb)
    return err


def _out_of_memory(what: str) -> InputFileError:
    return InputFileError(f"{what}: not enough memory to read the file (declared sizes too large?)")


def _first_line(obj: object) -> str:
    lines = [ln.strip() for ln in str(obj).strip().splitlines() if ln.strip()]
    text = lines[0] if lines else type(obj).__name__
    return text if len(text) <= 200 else text[:197] + "..."


def _in_process(func, args, kwargs, what):
    try:
        return func(*args, **kwargs)
    except FepostError:
        raise
    except MemoryError:
        raise _out_of_memory(what) from None
    except (KeyboardInterrupt, SystemExit):
        raise
    except Exception as exc:  # a library error on a malformed file: one line, never a traceback
        raise _unexpected(what, type(exc).__name__, _first_line(exc), traceback.format_exc()) from None


# ----------------------------------------------------------------------------- child side


def _budget(nbytes: int) -> int:
    """The address space (bytes) a child reading ``nbytes`` of file may add: the most it can answer with."""
    return max(MEMORY_BUDGET, 64 * nbytes)


def _limit_memory(nbytes: int) -> None:
    if resource is None:
        return
    try:
        with open("/proc/self/statm", "rb") as fh:
            vsize = int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        budget = _budget(nbytes)
        resource.setrlimit(resource.RLIMIT_AS, (vsize + budget, vsize + budget))
    except (OSError, ValueError, ImportError, AttributeError):
        pass  # no /proc or no limits on this platform: the deadline still applies


def _capture_fd() -> int:
    """An anonymous file the child's stdout and stderr are redirected to."""
    if hasattr(os, "memfd_create"):
        try:
            return os.memfd_create("fepost-read-chatter")
        except OSError:
            pass
    import tempfile

    return os.dup(tempfile.TemporaryFile().fileno())


def _chatter(fd: int, limit: int = 1 << 16) -> str:
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        return os.read(fd, limit).decode("utf-8", "replace")
    except OSError:
        return ""


def _child_main(wfd: int, ack: int, shared: int | None, func, args, kwargs, nbytes: int) -> None:
    afterfork.settle()  # first: locks of the caller's other threads are held for ever here
    import faulthandler

    inherited = len(sys.modules)  # the modules it imports are added after these (`_new_modules`)

    faulthandler.disable()  # a crash here is reported by the parent, not dumped on the terminal
    for sig in (signal.SIGINT, signal.SIGTERM):
        # the default action (die with the caller), unless the caller ignores the signal: a
        # sweep's Dask worker ignores SIGINT, so that a Ctrl-C to the terminal's process
        # group stops the sweep's client, not the reads under way in its workers
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)  # blocked by the parent around the fork
    cap = _capture_fd()
    os.dup2(cap, 1)
    os.dup2(cap, 2)
    afterfork.fresh_streams()  # the inherited stream objects are not flushed (afterfork)
    _limit_memory(nbytes)
    transfer.answer_file(shared)  # a reader may have its pages allocated early (`transfer.reserve`)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        try:
            result = func(*args, **kwargs)
            payload: tuple = ("ok", result)
        except FepostError as exc:
            payload = ("fepost", _unchained(exc))
        except MemoryError:
            payload = ("memory", None)
        except BaseException as exc:  # reported to the parent as one line
            payload = ("other", (type(exc).__name__, _first_line(exc), traceback.format_exc()))
    caught = [(w.category, str(w.message)) for w in rec if issubclass(w.category, FepostWarning)]
    text = _chatter(cap)
    imported = _new_modules(inherited)
    try:
        transfer.send(wfd, (payload, caught, text, imported), ack, shared)
    except Exception as exc:  # the result itself could not be pickled: say so
        other = ("other", (type(exc).__name__, _first_line(exc), traceback.format_exc()))
        transfer.send(wfd, (other, caught, text, imported), ack, shared)


def _new_modules(inherited: int) -> list[str]:
    """The names of the modules imported since ``sys.modules`` held ``inherited`` entries.

    ``sys.modules`` is a dict, in the order of insertion: the new ones are its last
    entries, read from the end so that the child does not touch (and copy) the pages of
    every inherited name. A module dropped meanwhile makes the list shorter, never wrong:
    it only tells the caller what to import before its next fork (`preload`)."""
    new = itertools.islice(reversed(sys.modules), max(0, len(sys.modules) - inherited))
    return sorted(name for name in new if not name.startswith("__"))


def _unchained(exc: BaseException) -> BaseException:
    """``exc`` without the exceptions it was raised from and its traceback: the caller needs its
    type and message. A chained exception of a C library may not pickle (ISA-L's ``IsalError``
    names a module that cannot be imported), and with tblib's pickling installed (as dask's
    distributed installs it) the chain would travel with the error and spoil it."""
    exc.__cause__ = exc.__context__ = None
    exc.__traceback__ = None
    return exc


# ----------------------------------------------------------------------------- parent side


def _signal_name(sig: int) -> str:
    try:
        return signal.Signals(sig).name
    except ValueError:
        return f"signal {sig}"


def _chatter_summary(text: str) -> str:
    """The first line of the captured C-level output that says what went wrong."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    for ln in lines:
        low = ln.lower()
        if "error" in low and not low.startswith("error: in "):
            return _first_line(ln)
    return _first_line(lines[0]) if lines else ""


def _reap(pid: int, kill: bool) -> int:
    if kill:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    while True:
        try:
            _, status = os.waitpid(pid, 0)
            return status
        except ChildProcessError:
            return 0
        except InterruptedError:
            continue


def _reap_soon(pid: int) -> None:
    """Reap a child that has sent its answer and is exiting: now if it is gone, else in a thread."""
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return
    if not done:
        import threading

        threading.Thread(target=_reap, args=(pid, False), name="fepost-reap", daemon=True).start()


def _fork(func, args, kwargs, what, nbytes, timeout):
    import fcntl

    rfd, wfd = os.pipe()
    ack_r, ack_w = os.pipe()
    shared = transfer.shared_file()
    if hasattr(fcntl, "F_SETPIPE_SZ"):
        try:
            fcntl.fcntl(wfd, fcntl.F_SETPIPE_SZ, _PIPE_SIZE)
        except OSError:
            pass
    sys.stdout.flush()
    sys.stderr.flush()
    # Termination signals wait until the fork is over: a handler that raises inside the
    # interpreter's at-fork hooks would be ignored there (and the signal lost).
    old_mask = _block_signals()
    with warnings.catch_warnings():
        # Python >= 3.12 warns about forking a multi-threaded process; the child
        # only reads a file and exits through os._exit, and a deadline guards it.
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:  # child: never returns into the caller's stack
        code = 0
        try:
            os.close(rfd)
            os.close(ack_w)
            _child_main(wfd, ack_r, shared, func, args, kwargs, nbytes)
        except BaseException:
            code = 70
        finally:
            os._exit(code)
    try:
        os.close(wfd)
        os.close(ack_r)
        reader = transfer.Reader(rfd, time.monotonic() + timeout, ack_w, shared)
        _restore_signals(old_mask)  # a signal that came meanwhile is handled here
    except BaseException:
        _reap(pid, kill=True)
        for fd in (rfd, ack_w, shared if shared is not None else -1):
            try:
                os.close(fd)
            except OSError:
                pass
        raise
    return pid, reader, what, timeout, nbytes


_SIGNALS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n))


def _block_signals():
    if not hasattr(signal, "pthread_sigmask"):
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)


def _restore_signals(old_mask) -> None:
    if old_mask is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)


def _finish(pid: int, reader: transfer.Reader, what: str, timeout: float, nbytes: int):
    received = None
    killed = malformed = False
    try:
        try:
            received = transfer.receive(pid, reader, _budget(nbytes), reader.shared)
        except transfer.Deadline:
            killed = True
        except EOFError:  # the child stopped short: its exit status says why
            received = None
        except (pickle.UnpicklingError, struct.error, ValueError):
            malformed = True
    except BaseException:  # KeyboardInterrupt in the parent: do not leave the child behind
        _reap(pid, kill=True)
        reader.close()
        raise
    if received is not None:
        # the answer is complete: the child's exit (freeing its memory, tens of ms for a large
        # mesh) is reaped in the background instead of waited for
        _reap_soon(pid)
        status = 0
    else:
        status = _reap(pid, kill=True)
    reader.close()
    if killed:
        raise InputFileError(
            f"{what}: reading did not finish within {timeout:.0f} s (malformed or hostile file?); "
            f"set {TIMEOUT_ENV} to allow more time"
        )
    if malformed:
        raise InputFileError(f"{what}: the file reader sent a malformed answer: corrupt or malformed file")
    if received is None:
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
            if sig in _SIGNALS:  # stopped from outside (Ctrl-C, kill): not the file's doing
                raise InputFileError(f"{what}: the file reader was stopped by {_signal_name(sig)}")
            if sig == signal.SIGKILL:
                cause = "killed (out of memory?)"
            else:
                cause = f"crashed ({_signal_name(sig)})"
        else:
            cause = f"failed (exit status {os.WEXITSTATUS(status)})"
        raise InputFileError(f"{what}: the file reader {cause}: corrupt or malformed file")
    (kind, value), caught, text, imported = received
    _CHILD_IMPORTS.update(n for n in imported if n not in sys.modules and n not in _NOT_HERE)
    for category, message in caught:
        warnings.warn(message, category, stacklevel=3)
    if kind == "ok":
        return value
    if kind == "fepost":
        raise value
    if kind == "memory":
        raise _out_of_memory(what)
    name, first, tb = value
    raise _unexpected(what, name, first, tb, _chatter_summary(text))
