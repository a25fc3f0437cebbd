"""Reading in a forked child: crashes, hangs, memory, chatter, warnings and daemonic processes."""

import mmap
import multiprocessing as mp
import os
import signal
import time
import warnings
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from fepost.errors import FieldError, InputFileError, ReaderWarning
from fepost.reader import isolate, read_contact, transfer


def _segfault():
    os.kill(os.getpid(), signal.SIGSEGV)


def _abort():
    os.abort()


def _hang():
    time.sleep(60)


def _huge():
    return np.ones(1 << 40)  # 8 TB: beyond the child's address-space budget


def _chatty():
    os.write(
        2,
        b"HDF5-DIAG: Error detected in HDF5 (1.14.0) thread 0:\n"
        b"  #000: H5F.c line 620 in H5Fopen(): unable\n",
    )
    os.write(1, b"some stdout chatter\n")
    raise ValueError("the library gave up")


def _warns():
    warnings.warn("something was assumed", ReaderWarning, stacklevel=1)
    warnings.warn("a numpy detail", RuntimeWarning, stacklevel=1)  # not a fepost warning: not passed on
    return 42


def _field_error():
    raise FieldError("x.vtu: no array named 'P'")


def _array():
    return {"a": np.arange(3_000_000, dtype=float), "b": np.eye(3)}


@pytest.mark.parametrize(
    "func,pattern",
    [
        (_segfault, r"f\.vtu: the file reader crashed \(SIGSEGV\): corrupt or malformed file"),
        (_abort, r"f\.vtu: the file reader crashed \(SIGABRT\): corrupt or malformed file"),
        (_huge, r"f\.vtu: not enough memory to read the file \(declared sizes too large\?\)"),
    ],
)
def test_a_crash_in_the_reader_is_one_line_error(func, pattern):
    with pytest.raises(InputFileError, match=pattern):
        isolate.call(func, what="f.vtu")


def test_a_hang_is_killed_at_the_deadline():
    t = time.monotonic()
    with pytest.raises(
        InputFileError, match=r"f\.vtu: reading did not finish within 1 s .*FEPOST_READ_TIMEOUT"
    ):
        isolate.call(_hang, what="f.vtu", timeout=1.0)
    assert time.monotonic() - t < 10


def test_c_level_chatter_is_captured_and_summarised(capfd):
    with pytest.raises(InputFileError) as err:
        isolate.call(_chatty, what="f.e")
    msg = str(err.value)
    assert msg.startswith(
        "f.e: cannot read the file (ValueError: the library gave up); reader said: HDF5-DIAG: Error"
    )
    assert "\n" not in msg
    out, errout = capfd.readouterr()
    assert "HDF5" not in errout + out and "chatter" not in errout + out


def test_errors_warnings_and_results_cross_the_process_boundary():
    with pytest.raises(FieldError, match=r"x\.vtu: no array named 'P'"):
        isolate.call(_field_error, what="x.vtu")
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        assert isolate.call(_warns, what="w.vtu") == 42
    assert [(w.category, str(w.message)) for w in rec] == [(ReaderWarning, "something was assumed")]
    got = isolate.call(_array, what="big")
    np.testing.assert_array_equal(got["a"], np.arange(3_000_000, dtype=float))
    np.testing.assert_array_equal(got["b"], np.eye(3))


def _mixed_arrays():
    return {
        "points": np.arange(300_000, dtype=float).reshape(-1, 3),
        "triangles": np.arange(600_000, dtype=np.int64).reshape(-1, 3)[::-1],  # not contiguous
        "empty": np.empty((0, 3)),
        "flags": np.arange(1001) % 3 == 0,
        "small": np.float32([1.5, -2.0]),
    }


def test_arrays_arrive_intact_as_views_of_one_receiving_map():
    got = isolate.call(_mixed_arrays, what="big")
    want = _mixed_arrays()
    for name, arr in want.items():
        assert got[name].dtype == arr.dtype and got[name].shape == arr.shape, name
        np.testing.assert_array_equal(got[name], arr)
    # the large contiguous arrays share one buffer, each aligned for vector loads
    base = got["points"].base
    assert base is not None
    for name in ("points", "flags"):
        assert got[name].ctypes.data % 64 == 0


def _reserving_reader(reserve_bytes):
    """A reader that reserves its answer's memory (`transfer.reserve`) before making it, and
    says whether a memory file was there to reserve in."""
    transfer.reserve(reserve_bytes)
    return {**_mixed_arrays(), "reserved": "thread" in transfer._ANSWER}


@pytest.mark.parametrize("reserve_bytes", [1 << 27, 1000])
def test_an_answer_written_into_reserved_pages_arrives_intact(reserve_bytes):
    """A reservation larger than the answer (128 MB for a 7 MB answer) or smaller: the arrays
    arrive the same, and the memory file is cut to the answer's size."""
    if transfer.shared_file() is None:
        pytest.skip("no memory file on this platform")
    sizes = []
    real = transfer._mapped_file

    def spy(shared, lengths, offsets):
        sizes.append(os.fstat(shared).st_size)
        return real(shared, lengths, offsets)

    transfer._mapped_file = spy
    try:
        got = isolate.call(_reserving_reader, reserve_bytes, what="reserved")
    finally:
        transfer._mapped_file = real
    assert got.pop("reserved") is True
    for name, arr in _mixed_arrays().items():
        assert got[name].dtype == arr.dtype and got[name].shape == arr.shape, name
        np.testing.assert_array_equal(got[name], arr)
    answer = sum(-(-a.nbytes // 64) * 64 for a in _mixed_arrays().values() if a.nbytes)
    assert sizes and sizes[0] <= answer + 64, (sizes, answer)


def test_a_reservation_outside_a_reading_child_does_nothing():
    transfer.answer_file(None)
    transfer.reserve(1 << 20)
    assert "thread" not in transfer._ANSWER


def _lying_send(fd, payload, ack, shared=None):
    # a header that declares far more than a reading child can hold (a compromised child)
    head = transfer.LEN.pack(10) + transfer.LEN.pack(1) + transfer.LEN.pack(transfer.IN_CHILD)
    os.write(fd, head + transfer.LEN.pack(1 << 62) + bytes(8))


def _lying_file_send(fd, payload, ack, shared=None):
    # buffers said to lie in the shared memory file beyond its end (a compromised child)
    head = transfer.LEN.pack(10) + transfer.LEN.pack(1) + transfer.LEN.pack(transfer.IN_FILE)
    os.write(fd, head + transfer.LEN.pack(4096) + transfer.LEN.pack(1 << 40) + bytes(10))


def _short_send(fd, payload, ack, shared=None):
    # the header of a real answer (with addresses the caller cannot copy from), then the
    # child stops after a little of its buffers (killed mid-transfer)
    buffers = []
    head = __import__("pickle").dumps(payload, protocol=5, buffer_callback=buffers.append)
    raws = [b.raw() for b in buffers]
    table = b"".join(transfer.LEN.pack(r.nbytes) + transfer.LEN.pack(8) for r in raws)
    sizes = transfer.LEN.pack(len(head)) + transfer.LEN.pack(len(raws)) + transfer.LEN.pack(transfer.IN_CHILD)
    os.write(fd, sizes + table + head)
    assert os.read(ack, 1) == b"p"
    os.write(fd, bytes(raws[0][:1000]))


def _copy_refused(*args):
    return False


def test_buffers_are_copied_straight_from_the_child_where_allowed(monkeypatch):
    if transfer.vm_readv() is None:
        pytest.skip("no process_vm_readv on this platform")
    copies = []
    real = transfer.copy_from

    def spy(*args):
        copies.append(real(*args))
        return copies[-1]

    monkeypatch.setattr(transfer, "copy_from", spy)
    monkeypatch.setattr(transfer, "shared_file", lambda: None)  # no memory file: the copy path
    got = isolate.call(_array, what="big")
    np.testing.assert_array_equal(got["a"], np.arange(3_000_000, dtype=float))
    if copies != [True]:
        pytest.skip("process_vm_readv is not permitted here (the pipe carried the arrays)")


def test_buffers_come_through_the_pipe_where_the_caller_cannot_copy_them(monkeypatch):
    monkeypatch.setattr(transfer, "copy_from", _copy_refused)
    monkeypatch.setattr(transfer, "shared_file", lambda: None)
    got = isolate.call(_mixed_arrays, what="big")
    for name, arr in _mixed_arrays().items():
        np.testing.assert_array_equal(got[name], arr)


@pytest.mark.parametrize(
    "send,pattern",
    [
        (_lying_send, r"^f\.vtu: the file reader sent a malformed answer: corrupt or malformed file$"),
        (_lying_file_send, r"^f\.vtu: the file reader sent a malformed answer: corrupt or malformed file$"),
        (_short_send, r"^f\.vtu: the file reader failed \(exit status 0\): corrupt or malformed file$"),
    ],
)
def test_a_malformed_or_cut_answer_is_one_line_error(monkeypatch, send, pattern):
    monkeypatch.setattr(transfer, "send", send)  # inherited by the forked child
    with pytest.raises(InputFileError, match=pattern):
        isolate.call(_array, what="f.vtu")


def _read_in_daemon(path, queue):
    try:
        fld = read_contact(path)
        queue.put(("ok", float(fld.values.max())))
    except Exception as exc:  # reported to the test
        queue.put(("error", repr(exc)))


def test_reading_inside_a_daemonic_process(analytic_mesh):
    """Dask workers are daemonic processes, where multiprocessing refuses to start children."""
    path = analytic_mesh("d.vtu", "hertz", radius=0.1, peak=1e6, n_rings=10)
    ctx = mp.get_context("fork")
    q = ctx.Queue()
    proc = ctx.Process(target=_read_in_daemon, args=(str(path), q), daemon=True)
    proc.start()
    kind, value = q.get(timeout=60)
    proc.join(timeout=30)
    assert kind == "ok", value
    assert value == pytest.approx(1e6, rel=1e-6)


def test_reading_from_many_threads_at_once(analytic_mesh):
    paths = [
        analytic_mesh(f"t{i}.vtu", "uniform", radius=0.1, peak=(i + 1) * 1e5, n_rings=8) for i in range(4)
    ]
    with ThreadPoolExecutor(4) as pool:
        peaks = list(pool.map(lambda p: float(read_contact(p).values.max()), paths * 2))
    assert peaks == pytest.approx([(i + 1) * 1e5 for i in range(4)] * 2)


def test_isolation_can_be_switched_off(analytic_mesh, monkeypatch):
    path = analytic_mesh("o.vtu", "hertz", n_rings=8)
    forked = read_contact(path)
    monkeypatch.setenv(isolate.ISOLATION_ENV, "off")
    assert not isolate.isolation_enabled()
    here = read_contact(path)
    np.testing.assert_array_equal(forked.values, here.values)
    np.testing.assert_array_equal(forked.points, here.points)
    with pytest.raises(
        InputFileError, match=r"f\.vtu: cannot read the file \(ValueError: the library gave up\)"
    ):
        isolate.call(_chatty, what="f.vtu")


def test_the_timeout_scales_with_the_file_and_the_environment(monkeypatch):
    assert isolate.timeout_for(0) == isolate.TIMEOUT_BASE
    assert isolate.timeout_for(100_000_000) == isolate.TIMEOUT_BASE + 100 * isolate.TIMEOUT_PER_MB
    monkeypatch.setenv(isolate.TIMEOUT_ENV, "7.5")
    assert isolate.timeout_for(10**9) == 7.5
    monkeypatch.setenv(isolate.TIMEOUT_ENV, "nonsense")
    assert isolate.timeout_for(0) == isolate.TIMEOUT_BASE


def _describe(pid: int) -> str:
    """State and command line of a process (for a failure message)."""
    try:
        state = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0]
        cmd = open(f"/proc/{pid}/cmdline", "rb").read().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return "gone"
    return f"state {state}: {cmd[:200]}"


def _children() -> set[int]:
    """Process ids of this process's children (zombies included)."""
    import glob

    me = os.getpid()
    kids = set()
    for stat in glob.glob("/proc/[0-9]*/stat"):
        try:
            fields = open(stat).read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == me:
            kids.add(int(stat.split("/")[2]))
    return kids


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs /proc to list child processes")
def test_started_reads_run_side_by_side_and_leave_no_child(analytic_mesh):
    from fepost.reader import start_reading

    a = start_reading(analytic_mesh("a.vtu", "uniform", peak=1e5, n_rings=8))
    b = start_reading(analytic_mesh("b.vtu", "uniform", peak=2e5, n_rings=8))
    ours = {a.pid, b.pid}
    assert None not in ours and ours <= _children()
    assert float(b.result().values.max()) == pytest.approx(2e5)
    assert float(a.result().values.max()) == pytest.approx(1e5)
    hung = isolate.start(_hang, what="h.vtu", timeout=30)
    ours.add(hung.pid)
    assert hung.pid in _children()  # the hung child runs
    hung.cancel()
    # killed and reaped; the finished readers are reaped in the background: no zombie left
    # (only the readers' own children are followed: other tests may leave helpers of their own)
    deadline = time.monotonic() + 5.0
    while ours & _children() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not ours & _children(), {pid: _describe(pid) for pid in ours & _children()}
    with pytest.raises(FieldError, match=r"x\.vtu: no array named 'P'"):
        isolate.start(_field_error, what="x.vtu").result()


# --- locks of the caller's other threads (held for ever in a forked child) ---------------

_HALF_IMPORTED = """
import builtins, os
_gate = getattr(builtins, "_fepost_gate", None)
if _gate is not None and os.getpid() == _gate[0]:
    _gate[1].set()  # the import is under way in the caller's other thread ...
    _gate[2].wait()  # ... and holds this module's import lock until released
VALUE = 42
"""


def _import_value(name):
    import importlib

    return importlib.import_module(name).VALUE


def test_a_module_another_thread_is_importing_does_not_block_the_child(tmp_path, monkeypatch):
    """A Dask worker imports on its event-loop thread while a task thread forks a reader; the
    child must not wait for that thread's module lock (it does not exist in the child)."""
    import builtins
    import sys
    import threading

    (tmp_path / "fepost_half_imported.py").write_text(_HALF_IMPORTED)
    monkeypatch.syspath_prepend(str(tmp_path))
    started, release = threading.Event(), threading.Event()
    monkeypatch.setattr(builtins, "_fepost_gate", (os.getpid(), started, release), raising=False)
    t = threading.Thread(target=_import_value, args=("fepost_half_imported",))
    t.start()
    try:
        assert started.wait(10)
        assert isolate.call(_import_value, "fepost_half_imported", what="probe", timeout=15) == 42
    finally:
        release.set()
        t.join(10)
        sys.modules.pop("fepost_half_imported", None)


class _StreamHeldByAnotherThread:
    """A stream whose lock another thread of the caller holds (it is writing) at the fork."""

    def __init__(self, lock):
        self.lock = lock

    def write(self, text):
        return len(text)

    def flush(self):
        if os.getpid() != self.owner_pid:
            self.lock.acquire()  # in the child: the holder does not exist, this never returns

    owner_pid = os.getpid()


def _print_and_answer():
    print("the child writes to its own stdout")  # captured, as C-level chatter is
    return 7


def test_streams_another_thread_is_writing_do_not_block_the_child(monkeypatch):
    import sys
    import threading

    lock = threading.Lock()
    lock.acquire()
    stream = _StreamHeldByAnotherThread(lock)
    monkeypatch.setattr(sys, "stdout", stream)
    monkeypatch.setattr(sys, "stderr", stream)
    try:
        assert isolate.call(_print_and_answer, what="probe", timeout=15) == 7
    finally:
        lock.release()


@pytest.mark.parametrize(("shape", "dtype"), [((7, 3), float), ((1 << 20, 3), float), ((1 << 21,), np.int64)])
def test_fresh_arrays_are_zero_filled_and_writable(shape, dtype):
    """A reader's output arrays: zeros of the shape and type asked for, on huge pages from
    `HUGE_FROM` bytes up (their buffer is then a map, kept alive by the array)."""
    a = transfer.fresh_array(shape, dtype)
    assert a.shape == shape and a.dtype == np.dtype(dtype) and a.flags.writeable and a.flags.c_contiguous
    assert not a.any()
    root = a
    while isinstance(root, np.ndarray) and root.base is not None:
        root = root.base
    if a.nbytes >= transfer.HUGE_FROM:
        assert isinstance(root, memoryview) and isinstance(root.obj, mmap.mmap)
    else:
        assert root is a
    a[...] = 5
    assert int(a.sum()) == 5 * a.size


_CHAINED = """
import tblib.pickling_support

from fepost.errors import InputFileError
from fepost.reader import isolate


class Unpicklable(Exception):
    pass


Unpicklable.__module__ = "no_such_module"  # as ISA-L's IsalError: its module cannot be imported
tblib.pickling_support.install()  # after fepost's errors are defined, as dask's distributed does


def read():
    try:
        raise Unpicklable("inflate failed")
    except Unpicklable:
        raise InputFileError("x.vtu: array 'P': block 1 does not decompress") from None


try:
    isolate.call(read, what="x.vtu")
except InputFileError as exc:
    print(exc)
"""


def test_an_error_raised_from_an_unpicklable_one_crosses_with_tblib_installed():
    """The child sends its error without the chain it was raised from: with tblib's pickling
    installed the chain would travel too, and an exception of a C library whose module cannot
    be imported would turn the error into 'cannot read the file (PicklingError ...)'."""
    import subprocess
    import sys

    pytest.importorskip("tblib")
    out = subprocess.run([sys.executable, "-c", _CHAINED], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "x.vtu: array 'P': block 1 does not decompress", out.stdout + out.stderr


def _imports_tabnanny() -> str:
    import tabnanny

    return tabnanny.__name__


def test_modules_a_child_imported_are_imported_here_before_the_next_fork():
    """A process reading many files pays a parser's import once, not once per child."""
    import sys

    if "tabnanny" in sys.modules:
        pytest.skip("tabnanny already imported in this process")
    assert isolate.call(_imports_tabnanny, what="first") == "tabnanny"
    assert "tabnanny" in isolate._CHILD_IMPORTS and "tabnanny" not in sys.modules
    assert isolate.call(len, "ab", what="second") == 2
    assert "tabnanny" in sys.modules


def _sleep_then_seven() -> int:
    time.sleep(0.6)
    return 7


def test_a_reader_of_a_caller_ignoring_sigint_ignores_it():
    """A sweep's Dask worker ignores SIGINT (a Ctrl-C is the client's); its reading children
    do too, instead of dying as if the file had crashed them."""
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        pending = isolate.start(_sleep_then_seven, what="f.vtu")
        time.sleep(0.2)
        os.kill(pending.pid, signal.SIGINT)
        assert pending.result() == 7
    finally:
        signal.signal(signal.SIGINT, old)


def test_a_reader_stopped_from_outside_does_not_blame_the_file():
    pending = isolate.start(_sleep_then_seven, what="f.vtu")
    time.sleep(0.2)
    os.kill(pending.pid, signal.SIGTERM)
    with pytest.raises(InputFileError, match=r"^f\.vtu: the file reader was stopped by SIGTERM$"):
        pending.result()
