"""Atomic output: files and folders appear whole or not at all.

A file is written to a hidden temporary file beside it and renamed over the
target (`write_text_atomic`); a folder is built in a hidden temporary folder
beside it and swapped into place when complete (`staged_folder`). On any
error, Ctrl-C or SIGTERM (which the CLI turns into an exception) the temporary
is removed and the target is left as it was. Files and folders are created
with the usual modes masked by the umask (``0o666`` and ``0o777``), like any
other program's output, not the private modes of `tempfile`.

Temporary names carry the writer's host and process id,
``.<name>.fepost-<host>-<pid>-<token>.tmp`` (``.old`` for a folder being
replaced), so a run killed outright (SIGKILL, power loss) leaves litter that the
next write into the same folder recognises and removes
(`remove_stale_temporaries`): only entries of this naming pattern, from
this host, whose process is gone or started after the entry was last touched
(its pid was reused).

`check_replaceable` refuses to replace a folder that holds the run's own
inputs, the current folder, the home folder or the file-system root.

A file named ``-`` (`STDOUT`, given as a string) is standard output:
`write_text_atomic` writes the text there (a file really named ``-`` is ``./-``);
`staged_folder` refuses ``-``, a folder cannot be standard output.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import secrets
import shutil
import signal
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import OutputError

_HOST = hashlib.blake2s(os.uname().nodename.encode(), digest_size=3).hexdigest()
_TEMP = re.compile(r"^\..+\.fepost-(?P<host>[0-9a-f]{6})-(?P<pid>\d+)-[0-9a-f]{8}\.(tmp|old)$")
#: Slack (s) when comparing a process's start time with a file's mtime (clock ticks, rounding).
_CLOCK_SLACK = 2.0


def _default(o):
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def to_json(data) -> str:
    """JSON text with numpy values converted; NaN/inf become null."""
    return json.dumps(_clean(data), indent=2, default=_default, allow_nan=False)


def _clean(o):
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_clean(v) for v in o]
    if type(o).__module__ == "numpy" and hasattr(o, "tolist"):
        return _clean(o.tolist())  # arrays and numpy scalars, without importing numpy here
    if isinstance(o, float):
        return float(o) if math.isfinite(o) else None
    return o


def _temporary_name(name: str, kind: str = "tmp") -> str:
    return f".{name}.fepost-{_HOST}-{os.getpid()}-{secrets.token_hex(4)}.{kind}"


def _start_time(pid: int) -> float | None:
    """Start of process ``pid`` in seconds since the epoch (Linux /proc), None if unknown."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        ticks = int(stat.rsplit(")", 1)[1].split()[19])
        boot = next(
            float(line.split()[1]) for line in Path("/proc/stat").read_text().splitlines()
            if line.startswith("btime ")
        )  # fmt: skip
        return boot + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, StopIteration):
        return None


def _is_stale(entry: Path, pid: int) -> bool:
    if pid != os.getpid():
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        except PermissionError:
            pass  # alive, another user's
        except OSError:
            return False
    started = _start_time(pid)
    if started is None:
        return False
    try:
        touched = entry.lstat().st_mtime
    except OSError:
        return False
    return started > touched + _CLOCK_SLACK


def remove_stale_temporaries(folder: str | Path) -> list[Path]:
    """Remove fepost temporaries in ``folder`` left by runs that no longer exist.

    Only names of this module's pattern written from this host are considered;
    an entry is stale when its process is gone, or when the process now holding
    that pid started after the entry was last modified. Returns what was removed.
    """
    removed: list[Path] = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        m = _TEMP.match(name)
        if not m or m["host"] != _HOST:
            continue
        entry = Path(folder) / name
        if not _is_stale(entry, int(m["pid"])):
            continue
        try:
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry)
            else:
                entry.unlink()
        except OSError:
            continue
        removed.append(entry)
    return removed


#: The output name that means standard output (files only; ``./-`` is a file named ``-``).
STDOUT = "-"


def is_stdout(path: str | Path | None) -> bool:
    """True when ``path`` is the string `STDOUT` (a `Path` never is: ``Path("./-")`` prints as ``-``)."""
    return isinstance(path, str) and path == STDOUT


def _folder_of(path: Path) -> Path:
    return path.parent if str(path.parent) else Path(".")


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file in the same folder, then
    rename; to standard output when ``path`` is `STDOUT` (``-``)."""
    if is_stdout(path):
        sys.stdout.write(text)
        sys.stdout.flush()
        return Path(STDOUT)
    given = Path(path)
    path = Path(os.path.realpath(given)) if given.is_symlink() else given  # keep the link
    folder = _folder_of(path)
    if path.is_dir():
        raise OutputError(f"{given}: is a folder, not a file")
    if path.exists() and not path.is_file():  # /dev/stdout, a FIFO: write through, never replace
        return _write_through(given, text)
    if not folder.is_dir():
        raise OutputError(f"{given}: folder {folder} does not exist")
    with atomic_path(path, name=given) as tmp:
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except OSError as exc:
            raise OutputError(f"{given}: cannot write ({exc.strerror or exc})") from None
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
    return given


def _write_through(path: Path, text: str) -> Path:
    try:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror or exc})") from None
    return path


@contextmanager
def atomic_path(path: str | Path, *, name: str | Path | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (not created) for a writer that makes its own
    file (pyarrow, matplotlib); renamed over ``path`` when the block ends, removed on error.

    The writer creates the file with the usual mode masked by the umask, unlike
    `tempfile.mkstemp`'s private 0600. Errors name ``name`` (default ``path``).
    """
    path = Path(path)
    name = path if name is None else name
    folder = _folder_of(path)
    remove_stale_temporaries(folder)
    tmp = folder / _temporary_name(path.name)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise OutputError(f"{name}: cannot write ({exc.strerror or exc})") from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _umask() -> int:
    """The process's umask, read without changing it where Linux shows it (threads run)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def umask_mode(path: str | Path) -> None:
    """Give ``path`` the mode a plain ``open``/``mkdir`` would (0o666 or 0o777 masked by
    the umask): for a folder another library made private (`tempfile.mkdtemp`'s 0700)."""
    mask = _umask()
    base = 0o777 if os.path.isdir(path) else 0o666
    try:
        os.chmod(path, base & ~mask)
    except OSError as exc:
        raise OutputError(f"{path}: cannot set its permissions ({exc.strerror or exc})") from None


def write_json_atomic(path: str | Path, data) -> Path:
    """`to_json` of ``data`` written with `write_text_atomic`."""
    return write_text_atomic(path, to_json(data) + "\n")


def _contains(folder: Path, other: Path) -> bool:
    return folder == other or folder in other.parents


def _resolve(path: str | Path) -> Path:
    """``Path(path).resolve()``, with a symbolic-link loop or a name too long as `OutputError`
    (Python 3.11 raises RuntimeError for a loop)."""
    try:
        return Path(path).resolve()
    except RuntimeError:
        raise OutputError(f"{path}: cannot write here (a symbolic-link loop)") from None
    except OSError as exc:
        raise OutputError(f"{path}: cannot write here ({exc.strerror or exc})") from None


def check_replaceable(out: str | Path, inputs: Iterable[str | Path | None] = ()) -> None:
    """Refuse writing ``out`` when that would delete an input or a folder one works in.

    ``out`` (a file or a folder) must not be, or contain, any of ``inputs``, the
    current folder, the home folder or the file-system root. Raises
    `OutputError` with one line naming what it holds.
    """
    target = _resolve(out)
    guarded = [(_resolve(p), f"the input {p}") for p in inputs if p is not None]
    guarded.append((Path.cwd().resolve(), "the current folder"))
    try:
        guarded.append((Path.home().resolve(), "the home folder"))
    except (RuntimeError, KeyError):  # no HOME and no password entry
        pass
    kind = "overwrite this file" if os.path.isfile(target) else "replace this folder"
    for path, what in guarded:
        if _contains(target, path):
            rel = "is" if target == path else "contains"
            raise OutputError(f"{out}: refusing to {kind}: it {rel} {what}")
    if target == Path(target.anchor):
        raise OutputError(f"{out}: refusing to replace the file-system root")


@contextmanager
def _signals_deferred() -> Iterator[None]:
    """Hold SIGINT/SIGTERM/SIGHUP while a few renames run, so they complete together."""
    try:
        block = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
        old = signal.pthread_sigmask(signal.SIG_BLOCK, block)
    except (AttributeError, OSError, ValueError):
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextmanager
def staged_folder(
    out: str | Path, force: bool = False, protect: Iterable[str | Path | None] = ()
) -> Iterator[Path]:
    """Yield a temporary folder beside ``out``; on success it replaces ``out``.

    An existing non-empty ``out`` is refused unless ``force``; an existing
    ``out`` that holds any of ``protect`` (the run's inputs), the current or the
    home folder is always refused (`check_replaceable`). On any error or
    interruption the temporary folder is removed and ``out`` is left as it was.
    """
    if str(out) == STDOUT:  # also Path("-"): a folder is never standard output
        raise OutputError(f"{STDOUT}: an output folder cannot be standard output; give a folder name")
    out = Path(os.path.realpath(out)) if Path(out).is_symlink() else Path(out)
    if out.exists() and not out.is_dir():
        raise OutputError(f"{out}: exists and is not a folder")
    if out.is_dir():
        check_replaceable(out, protect)
        if not force and any(out.iterdir()):
            raise OutputError(f"{out}: folder exists and is not empty (use --force to replace it)")
    parent = _folder_of(out)
    if not parent.is_dir():
        raise OutputError(f"{out}: parent folder {parent} does not exist")
    remove_stale_temporaries(parent)
    tmp = parent / _temporary_name(out.name)
    try:
        os.mkdir(tmp, 0o777)
    except OSError as exc:
        raise OutputError(f"{out}: cannot write in {parent} ({exc.strerror or exc})") from None
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    old = parent / _temporary_name(out.name, "old")
    with _signals_deferred():
        try:
            if out.is_dir():
                os.replace(out, old)
                try:
                    os.replace(tmp, out)
                except OSError:
                    os.replace(old, out)
                    raise
            else:
                os.replace(tmp, out)
        except OSError as exc:
            shutil.rmtree(tmp, ignore_errors=True)
            raise OutputError(f"{out}: cannot move results into place ({exc.strerror or exc})") from None
        shutil.rmtree(old, ignore_errors=True)
