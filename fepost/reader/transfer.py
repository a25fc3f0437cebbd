"""How the reading child's answer travels to the caller (`fepost.reader.isolate`).

The answer is a pickle (protocol 5) whose large numpy buffers go out of band.
The child writes, through a pipe, a header (the pickle's length, the number of
out-of-band buffers, where they are, then the size and place of each) and the pickle.

* Shared file (Linux): the caller made an anonymous memory file (``memfd``)
  before the fork; the child writes the buffers into it (the kernel copies them
  into its pages: no page faults, no huge-page compaction) and the caller maps
  the file: its arrays are views of pages the child filled, nothing is copied
  again. The child does not wait for the caller.
* Otherwise the child waits for the caller's word on a second pipe: ``v``, the
  caller copied the buffers straight out of the waiting child with
  ``process_vm_readv``; ``p``, they follow through the pipe. They land in one
  anonymous private map in the caller, backed by transparent huge pages where
  the system offers them.

(A shared map made before the fork cost 2-3x as much as either: its pages fault
one by one in both processes and are slow to free. The copy into a huge-page
map stalled now and then for 0.2-0.3 s on a 90 MB answer while the kernel
compacted memory for the huge pages.)

``process_vm_readv`` is reached through `ctypes`: neither the standard
library nor numpy wraps it.

Writing into the memory file costs the kernel one page allocation per 4 kB
(the file's pages are not huge): 34 ms of the 87 MB answer of a million-node
surface map. A reader that knows early about how large its answer will be says
so (`reserve`, the direct VTK XML decoder once its arrays are inflated): a
thread of the child then has the kernel allocate the file's pages while the
reader assembles the mesh on the other core, and the answer is only copied into
them (20 ms). A reservation larger than the answer is given back when the
file is cut to the answer's size.
"""

from __future__ import annotations

import io
import mmap
import os
import pickle
import select
import struct
import sys
import threading
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

LEN = struct.Struct("<Q")
#: Alignment (bytes) of each array in the caller's receiving map.
_ALIGN = 64
#: Huge-page size the receiving map is rounded to (2 MB on x86-64 and most arm64 systems).
_HUGE = 2 << 20


# ----------------------------------------------------------------------------- child side


def _write_all(fd: int, data) -> None:
    view = memoryview(data).cast("B")
    while view.nbytes:
        n = os.write(fd, view)
        view = view[n:]


#: Where the buffers are: the child's memory (the caller copies them or they follow the pickle) ...
IN_CHILD = 0
#: ... or the shared memory file, at the offsets the header gives.
IN_FILE = 1


def shared_file() -> int | None:
    """An anonymous memory file for a child's buffers (made before the fork), or None where
    the system has none."""
    if not hasattr(os, "memfd_create"):
        return None
    try:
        return os.memfd_create("fepost-read-answer", getattr(os, "MFD_CLOEXEC", 0))
    except OSError:
        return None


#: This reading child's memory file (`answer_file`) and the thread allocating its pages (`reserve`).
_ANSWER: dict[str, Any] = {}


def answer_file(shared: int | None) -> None:
    """Name the memory file this (reading child's) process will write its answer into."""
    _ANSWER.clear()
    if shared is not None:
        _ANSWER["fd"] = shared


def reserve(nbytes: int) -> None:
    """Have the kernel allocate ``nbytes`` of the answer's memory file now, on a thread of its
    own (module docstring); nothing outside a reading child or without a memory file."""
    fd = _ANSWER.get("fd")
    if fd is None or nbytes <= 0 or "thread" in _ANSWER or not hasattr(os, "posix_fallocate"):
        return

    def allocate() -> None:
        try:
            os.posix_fallocate(fd, 0, nbytes)
        except OSError:
            pass  # no room or not supported: the answer's writing allocates what it needs

    th = threading.Thread(target=allocate, name="fepost-reserve", daemon=True)
    th.start()
    _ANSWER["thread"] = th


def _into_file(shared: int, raws: list[memoryview]) -> list[int] | None:
    """Write the buffers into the memory file at aligned offsets; their offsets, or None if it failed."""
    reserving = _ANSWER.get("thread")
    if reserving is not None:
        reserving.join()  # the file's pages allocated (`reserve`): the writes only copy
    offsets, pos = [], 0
    try:
        for r in raws:
            offsets.append(pos)
            view, at = r.cast("B"), pos
            while view.nbytes:
                n = os.pwrite(shared, view, at)
                view, at = view[n:], at + n
            pos += -(-r.nbytes // _ALIGN) * _ALIGN
        os.ftruncate(shared, max(pos, 1))
    except OSError:
        return None
    return offsets


def send(fd: int, payload: Any, ack: int | None = None, shared: int | None = None) -> None:
    """Write the payload: its header (where the out-of-band buffers are, the size and place of
    each), then the pickle. With the memory file ``shared``, the buffers are written into it
    first; else, after the pickle, wait for the caller's word on ``ack``: it has copied the
    buffers itself (``v``), or they follow through the pipe (``p``)."""
    buffers: list[pickle.PickleBuffer] = []
    head = pickle.dumps(payload, protocol=5, buffer_callback=buffers.append)
    raws = [b.raw() for b in buffers]
    offsets = _into_file(shared, raws) if shared is not None and raws else None
    where = IN_FILE if offsets is not None else IN_CHILD
    places = offsets if offsets is not None else [_address(r) for r in raws]
    table = b"".join(LEN.pack(r.nbytes) + LEN.pack(at) for r, at in zip(raws, places, strict=True))
    _write_all(fd, LEN.pack(len(head)) + LEN.pack(len(raws)) + LEN.pack(where) + table)
    _write_all(fd, head)
    if not raws or where == IN_FILE:
        return
    how = os.read(ack, 1) if ack is not None else b"p"
    if how == b"p":
        for r in raws:
            _write_all(fd, r)


def _address(raw: memoryview) -> int:
    """The address of a contiguous buffer's first byte (0 when empty)."""
    if not raw.nbytes:
        return 0
    import numpy as np

    return int(np.frombuffer(raw, np.uint8).ctypes.data)


# ----------------------------------------------------------------------------- caller side


class Deadline(Exception):
    """The child did not answer in time."""


class Reader:
    """The caller's end of the pipes: reads with a deadline, replies ``v``/``p``."""

    def __init__(self, fd: int, deadline: float, ack: int | None = None, shared: int | None = None):
        self.f = io.FileIO(fd, "rb", closefd=True)
        self.deadline = deadline
        self.ack = ack  # the write end of the caller's reply to the child
        self.shared = shared  # the memory file the child may write its buffers into

    def reply(self, word: bytes) -> None:
        """Tell the child how its buffers travel (it waits for this once its header is sent)."""
        if self.ack is not None:
            try:
                os.write(self.ack, word)
            except OSError:
                pass  # the child is gone: the pipe's end of file says so

    def _wait(self) -> None:
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise Deadline
        ready, _, _ = select.select([self.f], [], [], left)
        if not ready:
            raise Deadline

    def exact(self, n: int) -> bytearray:
        buf = bytearray(n)
        self.into(memoryview(buf))
        return buf

    def into(self, view: memoryview) -> None:
        """Fill ``view`` from the pipe (EOFError if the child stops short)."""
        pos, n = 0, view.nbytes
        while pos < n:
            self._wait()
            got = self.f.readinto(view[pos:])
            if not got:
                raise EOFError
            pos += got

    def close(self) -> None:
        self.f.close()
        for name in ("ack", "shared"):
            fd = getattr(self, name)
            if fd is not None:
                setattr(self, name, None)
                os.close(fd)


def receive(pid: int, reader: Reader, limit: int, shared: int | None = None) -> Any:
    """The child's answer, unpickled; its arrays are views of one map (of the memory file
    ``shared`` when the child wrote its buffers there).

    ``limit`` (bytes) caps what the child may declare.

    Raises
    ------
    Deadline
        The child did not answer in time.
    EOFError
        The child stopped short.
    ValueError, struct.error, pickle.UnpicklingError
        A malformed answer.
    """
    sizes = reader.exact(24)
    nhead, nbuf, where = (LEN.unpack_from(sizes, k)[0] for k in (0, 8, 16))
    if nbuf > 1 << 20 or where not in (IN_CHILD, IN_FILE) or (where == IN_FILE and shared is None):
        raise ValueError("malformed header")
    table = reader.exact(16 * nbuf)
    lengths = [LEN.unpack_from(table, 16 * i)[0] for i in range(nbuf)]
    places = [LEN.unpack_from(table, 16 * i + 8)[0] for i in range(nbuf)]
    if nhead > limit or sum(lengths) > limit:
        raise ValueError("the child declares more than it could hold")
    head = reader.exact(nhead)
    if where == IN_FILE:
        return pickle.loads(head, buffers=_mapped_file(shared, lengths, places))  # type: ignore[arg-type]
    buf, offsets = _receiving_map(lengths)
    view = memoryview(buf) if buf is not None else memoryview(bytearray(0))
    # the arrays are views of the receiving map: no further copy
    bufs = [view[at : at + n] for n, at in zip(lengths, offsets, strict=True)]
    if bufs:
        if buf is not None and copy_from(pid, buf, offsets, lengths, places):
            reader.reply(b"v")
        else:
            reader.reply(b"p")
            for part in bufs:
                reader.into(part)
    return pickle.loads(head, buffers=bufs)


def _mapped_file(shared: int, lengths: list[int], offsets: list[int]) -> list[memoryview]:
    """Views of the buffers the child wrote into the memory file (its pages mapped at once)."""
    size = os.fstat(shared).st_size
    if any(at < 0 or at + n > size for n, at in zip(lengths, offsets, strict=True)):
        raise ValueError("a buffer outside the shared file")
    flags = getattr(mmap, "MAP_SHARED", 0) | getattr(mmap, "MAP_POPULATE", 0)
    buf = mmap.mmap(shared, size, flags=flags) if flags else mmap.mmap(shared, size)
    view = memoryview(buf)
    return [view[at : at + n] for n, at in zip(lengths, offsets, strict=True)]


def copy_from(pid: int, buf: mmap.mmap, offsets: list[int], sizes: list[int], addresses: list[int]) -> bool:
    """Copy the child's buffers into ``buf`` with ``process_vm_readv``; False where not possible.

    Linux only, and only where the caller may trace its child (the usual default); a
    short or failed copy also gives False: the buffers then come through the pipe.
    """
    found = vm_readv()
    if found is None or len(sizes) > 1024:  # IOV_MAX
        return False
    import ctypes

    call, iovec = found
    holder = ctypes.c_char.from_buffer(buf)
    try:
        base = ctypes.addressof(holder)
        n = len(sizes)
        local, remote = (iovec * n)(), (iovec * n)()
        for i, (at, size, where) in enumerate(zip(offsets, sizes, addresses, strict=True)):
            local[i].base, local[i].len = base + at, size
            remote[i].base, remote[i].len = where, size
        return call(pid, local, n, remote, n, 0) == sum(sizes)
    finally:
        del holder


_VM_READV: list = []


def vm_readv():
    """(libc's process_vm_readv, its iovec type) through ctypes, or None where there is none."""
    if not _VM_READV:
        _VM_READV.append(_load_vm_readv())
    return _VM_READV[0]


def _load_vm_readv():
    if not sys.platform.startswith("linux"):
        return None
    try:
        import ctypes

        class Iovec(ctypes.Structure):
            _fields_ = [("base", ctypes.c_void_p), ("len", ctypes.c_size_t)]

        fn = ctypes.CDLL(None, use_errno=True).process_vm_readv
    except (OSError, AttributeError, ImportError):
        return None
    fn.restype = ctypes.c_ssize_t
    iov = ctypes.POINTER(Iovec)
    fn.argtypes = [ctypes.c_int, iov, ctypes.c_ulong, iov, ctypes.c_ulong, ctypes.c_ulong]
    return fn, Iovec


def _receiving_map(sizes: list[int]) -> tuple[mmap.mmap | None, list[int]]:
    """A private anonymous map for buffers of ``sizes`` (bytes), and the offset of each.

    Backed by transparent huge pages where the system allows it (one page fault per
    2 MB instead of per 4 kB). None when there is nothing to receive.
    """
    offsets, pos = [], 0
    for n in sizes:
        offsets.append(pos)
        pos += -(-n // _ALIGN) * _ALIGN
    if pos == 0:
        return None, offsets
    return huge_map(pos), offsets


def huge_map(nbytes: int) -> mmap.mmap:
    """A private anonymous map of at least ``nbytes`` (> 0), zero-filled, backed by transparent
    huge pages where the system allows it (one page fault per 2 MB instead of per 4 kB)."""
    size = -(-nbytes // _HUGE) * _HUGE
    private = getattr(mmap, "MAP_PRIVATE", 0) | getattr(mmap, "MAP_ANONYMOUS", 0)
    buf = mmap.mmap(-1, size, flags=private) if private else mmap.mmap(-1, size)
    if hasattr(mmap, "MADV_HUGEPAGE"):
        try:
            buf.madvise(mmap.MADV_HUGEPAGE)
        except OSError:
            pass  # no transparent huge pages here: ordinary pages
    return buf


#: Arrays from this size (bytes) up are made by `fresh_array` on huge pages.
HUGE_FROM = 4 << 20


def fresh_array(shape, dtype) -> np.ndarray:
    """A zero-filled array for a reader to fill; from `HUGE_FROM` bytes up on a `huge_map`.

    A reader's large outputs are new memory, touched once: on some virtual machines a
    64 MB array from malloc costs 0.1–0.2 s in page faults where the same on huge pages
    costs 0.01 s (measured on an Exodus connectivity, docs/reading.md)."""
    import numpy as np

    dt = np.dtype(dtype)
    count = int(np.prod(shape, dtype=np.int64))
    if count * dt.itemsize < HUGE_FROM:
        return np.zeros(shape, dt)
    return np.frombuffer(huge_map(count * dt.itemsize), dt, count=count).reshape(shape)
