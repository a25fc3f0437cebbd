"""What the pre-read checks of every format share: the limits, the declared counts, the error.

`vtkcheck` (dispatch by suffix), `xmlcheck` (VTK XML files, serial, parallel and
structured), `legacycheck` (legacy ``.vtk``) and `xdmfcheck` (XDMF) all import
from here and never from each other's private names.
"""

from __future__ import annotations

import mmap
import stat
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputFileError

#: Deepest XML nesting accepted (VTK files need about 6, XDMF about 8).
MAX_DEPTH = 32
#: Largest point, cell or value count accepted from a header.
MAX_COUNT = (1 << 31) - 1
#: Most nested .vtm files followed.
MAX_VTM_DEPTH = 4


@dataclass
class Counts:
    """What a checked file declares, for the comparison after the library has read it."""

    connectivity: list[int] = field(default_factory=list)  # values of each piece's connectivity arrays


#: The first bytes of netCDF files (classic, 64-bit offset, 64-bit data; netCDF-4 is HDF5).
NETCDF_MAGIC = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")


def refuse_netcdf(path: Path, data) -> None:
    """Refuse a netCDF file under a VTK suffix (an Exodus II export renamed), saying so."""
    if bytes(data[:8]).startswith(NETCDF_MAGIC):
        raise bad_file(
            path,
            "refused: this is a netCDF file (an Exodus II export?), not VTK; give it the suffix "
            f".e or .exo instead of {path.suffix}",
        )


def bad_file(path: Path, what: str) -> InputFileError:
    """The one-line error for ``path``: refusals as they are, everything else as corrupt or truncated.

    ``what`` starting with ``"refused: "`` gives "refused .SUFFIX file (...)"; any other
    text gives "corrupt or truncated .SUFFIX file (...)".
    """
    if what.startswith("refused: "):
        return InputFileError(f"{path}: refused {path.suffix} file ({what[len('refused: ') :]})")
    return InputFileError(f"{path}: corrupt or truncated {path.suffix} file ({what})")


def inside_folder(path: Path, ref: str, what: str, *, folder: Path | None = None) -> Path:
    """The file ``ref`` names relative to ``path``'s folder; refused when it lies outside that folder.

    A parallel or multi-block file, or an XDMF file's heavy data, may only point at files
    in its own folder or below it: an absolute path, ``..`` or a symbolic link that leaves
    the folder is refused (a file handed to fepost must not make it read elsewhere).
    ``folder``: that folder when it is not ``path``'s as named (an XDMF file's heavy data
    lie next to its real path).
    """
    base = path.parent if folder is None else folder
    folder = base.resolve()
    try:
        target = (base / ref).resolve()
    except (OSError, RuntimeError, ValueError):
        raise bad_file(path, f"refused: {what} {ref!r} cannot be resolved") from None
    if not target.is_relative_to(folder):
        raise bad_file(path, f"refused: {what} {ref!r} lies outside the file's folder")
    return target


def regular_file(path: Path, target: Path, ref: str, what: str) -> None:
    """Refuse ``target`` (named ``ref`` in ``path``) unless it is a regular file: missing, a
    directory, a FIFO (never opened: reading one would wait for a writer), a device or a socket."""
    try:
        mode = target.stat().st_mode
    except OSError:
        raise bad_file(path, f"{what} {ref!r} not found") from None
    if stat.S_ISREG(mode):
        return
    kind = next(
        (name for test, name in _KINDS if test(mode)),
        "something else",
    )
    raise bad_file(path, f"refused: {what} {ref!r} is not a regular file but {kind}")


_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
)

#: Bytes of a mapped file walked before the pages behind are let go (`release`).
RELEASE_STEP = 64 << 20


def release(data, start: int, end: int) -> None:
    """Let go of the pages of the mapped file ``data`` wholly inside [start, end): they
    leave the process's resident memory and come back from the page cache if read again.

    A check walks a whole file and a decoder reads only some arrays: without this, every
    page walked stays resident (a 450 MB file counted in full). No-op for bytes.
    """
    if not isinstance(data, mmap.mmap) or not hasattr(mmap, "MADV_DONTNEED"):
        return
    page = mmap.PAGESIZE
    lo, hi = -(-start // page) * page, (end // page) * page
    if hi > lo:
        try:
            data.madvise(mmap.MADV_DONTNEED, lo, hi - lo)
        except (OSError, ValueError):
            pass


def find_releasing(data, sub: bytes, start: int = 0) -> int:
    """``data.find(sub, start)``, letting go of the pages walked past (`release`) as it goes."""
    if not isinstance(data, mmap.mmap):
        return data.find(sub, start)
    pos, n = start, len(data)
    while pos < n:
        stop = min(n, pos + RELEASE_STEP)
        hit = data.find(sub, pos, min(n, stop + len(sub) - 1))  # a match across `stop` is found here
        if hit >= 0:
            return hit
        release(data, pos, stop)
        pos = stop
    return -1
