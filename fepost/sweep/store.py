"""The sweep's work folder: finished rows on disk, so a sweep can be resumed.

``DIR/.fepost-sweep/`` holds one small JSON file per finished row
(``rows/<key>.json``, written atomically by renaming a complete temporary
file) and the time steps listed per file (``steps/<key>.json``). A sweep that
is killed leaves only whole row files behind; the next run with the same
inputs and options reads them and computes only the rest. A lock file keeps
two sweeps from writing into one folder at once.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
from pathlib import Path

from ..errors import OutputError
from ..output import to_json, write_text_atomic

#: Name of the work folder inside the output folder.
WORK = ".fepost-sweep"
#: Files a sweep writes into its output folder (besides the work folder).
OUTPUTS = ("coefficients.parquet", "coefficients.csv", "trends.html", "trends.json", "trends")


class WorkFolder:
    """Finished rows and listed time steps of a sweep writing into ``out``.

    Use as a context manager: it creates ``out`` when missing and holds the
    folder's lock until closed.

    Raises
    ------
    OutputError
        ``out`` is a file, or a non-empty folder that holds no earlier sweep
        (unless ``force``), or another sweep holds its lock, or it cannot be written.
    """

    def __init__(self, out: str | Path, force: bool = False, fresh: bool = False):
        self.out = Path(out)
        self.root = self.out / WORK
        self.force = force
        self.fresh = fresh
        self._lock_fd: int | None = None

    def __enter__(self) -> WorkFolder:
        out = self.out
        if out.exists() and not out.is_dir():
            raise OutputError(f"{out}: exists and is not a folder")
        if out.is_dir() and not self.root.is_dir() and not self.force:
            foreign = [p.name for p in out.iterdir() if p.name not in OUTPUTS]
            if foreign:
                raise OutputError(
                    f"{out}: folder holds other files than an earlier sweep (e.g. {foreign[0]}); "
                    "choose another --out or use --force"
                )
        try:
            (self.root / "rows").mkdir(parents=True, exist_ok=True)
            (self.root / "steps").mkdir(exist_ok=True)
            fd = os.open(self.root / "lock", os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise OutputError(f"{out}: cannot write ({exc.strerror or exc})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise OutputError(f"{out}: another fepost sweep is writing into this folder") from None
        self._lock_fd = fd
        if self.fresh:
            for folder in ("rows", "steps"):
                for p in (self.root / folder).glob("*.json"):
                    p.unlink(missing_ok=True)
        return self

    def __exit__(self, *exc) -> None:
        if self._lock_fd is not None:
            fcntl.flock(self._lock_fd, fcntl.LOCK_UN)
            os.close(self._lock_fd)
            self._lock_fd = None

    # rows ---------------------------------------------------------------
    def row_path(self, key: str) -> Path:
        return self.root / "rows" / f"{key}.json"

    def load_row(self, key: str) -> dict | None:
        """The saved row ``key``, or None when absent or unreadable (then it is recomputed)."""
        try:
            data = json.loads(self.row_path(key).read_text())
        except (OSError, ValueError):
            return None
        return data if isinstance(data, dict) and data.get("status") in ("ok", "error") else None

    def save_row(self, key: str, row: dict) -> None:
        write_text_atomic(self.row_path(key), to_json(row))

    # time steps ---------------------------------------------------------
    @staticmethod
    def steps_key(path: str) -> str:
        st = os.stat(path)
        ident = json.dumps([path, st.st_size, st.st_mtime_ns])
        return hashlib.sha1(ident.encode()).hexdigest()

    def load_steps(self, path: str) -> tuple[float, ...] | None | bool:
        """Listed time values of ``path``; None: not a series; False: not listed yet."""
        try:
            data = json.loads((self.root / "steps" / f"{self.steps_key(path)}.json").read_text())
            times = data["times"]
        except (OSError, ValueError, KeyError, TypeError):
            return False
        return None if times is None else tuple(float(t) for t in times)

    def save_steps(self, path: str, times: tuple[float, ...] | None) -> None:
        try:
            key = self.steps_key(path)
        except OSError:
            return
        write_text_atomic(self.root / "steps" / f"{key}.json", to_json({"path": path, "times": times}))
