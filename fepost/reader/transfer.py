"""How the reading child's answer travels to the caller (`fepost.reader.isolate`).

The answer is a pickle (protocol 5) whose large numpy buffers go out of band.
The child writes, through a pipe, a header (the pickle's length, then the size
and address of each out-of-band buffer) and the pickle, and waits for the
caller's word on a second pipe:

* ``v``: the caller copied the buffers straight out of the waiting child with
  ``process_vm_readv`` (Linux; one copy, no scheduling round trips);
* ``p``: they follow through the pipe (where that copy is not allowed).

The buffers land in one anonymous private map in the caller, backed by
transparent huge pages where the system offers them; the caller's arrays are
views of it. (A shared map made before the fork cost 2-3x as much: its pages
fault one by one in both processes and are slow to free.)

``process_vm_readv`` is reached through `ctypes`: neither the standard
library nor numpy wraps it.
"""

from __future__ import annotations

import io
import mmap
import os
import pickle
import select
import struct
import sys
import time
from typing import Any

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


def send(fd: int, payload: Any, ack: int | None = None) -> None:
    """Write the payload: its header (size and address of each out-of-band buffer), the pickle,
    then wait for the caller's word on ``ack``: it has copied the buffers itself (``v``), or they
    follow through the pipe (``p``)."""
    buffers: list[pickle.PickleBuffer] = []
    head = pickle.dumps(payload, protocol=5, buffer_callback=buffers.append)
    raws = [b.raw() for b in buffers]
    table = b"".join(LEN.pack(r.nbytes) + LEN.pack(_address(r)) for r in raws)
    _write_all(fd, LEN.pack(len(head)) + LEN.pack(len(raws)) + table)
    _write_all(fd, head)
    if not raws:
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

    def __init__(self, fd: int, deadline: float, ack: int | None = None):
        self.f = io.FileIO(fd, "rb", closefd=True)
        self.deadline = deadline
        self.ack = ack  # the write end of the caller's reply to the child

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
        if self.ack is not None:
            os.close(self.ack)
            self.ack = None


def receive(pid: int, reader: Reader, limit: int) -> Any:
    """The child's answer, unpickled; its arrays are views of one receiving map.

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
    sizes = reader.exact(16)
    nhead, nbuf = LEN.unpack_from(sizes, 0)[0], LEN.unpack_from(sizes, 8)[0]
    if nbuf > 1 << 20:
        raise ValueError("too many buffers")
    table = reader.exact(16 * nbuf)
    lengths = [LEN.unpack_from(table, 16 * i)[0] for i in range(nbuf)]
    addresses = [LEN.unpack_from(table, 16 * i + 8)[0] for i in range(nbuf)]
    if nhead > limit or sum(lengths) > limit:
        raise ValueError("the child declares more than it could hold")
    head = reader.exact(nhead)
    buf, offsets = _receiving_map(lengths)
    view = memoryview(buf) if buf is not None else memoryview(bytearray(0))
    # the arrays are views of the receiving map: no further copy
    bufs = [view[at : at + n] for n, at in zip(lengths, offsets, strict=True)]
    if bufs:
        if buf is not None and copy_from(pid, buf, offsets, lengths, addresses):
            reader.reply(b"v")
        else:
            reader.reply(b"p")
            for part in bufs:
                reader.into(part)
    return pickle.loads(head, buffers=bufs)


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
    size = -(-pos // _HUGE) * _HUGE
    private = getattr(mmap, "MAP_PRIVATE", 0) | getattr(mmap, "MAP_ANONYMOUS", 0)
    buf = mmap.mmap(-1, size, flags=private) if private else mmap.mmap(-1, size)
    if hasattr(mmap, "MADV_HUGEPAGE"):
        try:
            buf.madvise(mmap.MADV_HUGEPAGE)
        except OSError:
            pass  # no transparent huge pages here: ordinary pages
    return buf, offsets
