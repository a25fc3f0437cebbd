"""The Dask plumbing: a client on an embedded local cluster or an existing one.

The sweep computes on ``dask.distributed``: by default a
`LocalCluster` of ``workers`` processes (one thread each,
so numpy and VTK in one worker do not compete with the next), started on first
use and torn down at the end; with ``scheduler="tcp://HOST:PORT"`` the
workers of an existing cluster. Rows are sent as tasks; each result (a small
dict) comes back to the client, which saves it at once.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from ..errors import ArgumentError, ClusterError

#: Seconds to wait for a scheduler to answer and for its first worker.
CONNECT_TIMEOUT = 30.0
#: Times a task is retried after its worker died before it fails (the embedded cluster's setting).
ALLOWED_FAILURES = 1


class WorkerDied(RuntimeError):
    """The worker process running a task died (a crash in a reader, or out of memory)."""


def default_workers() -> int:
    """CPU cores this process may use: the embedded cluster's default size."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


class Cluster:
    """A Dask client, connected on first use and closed by `close`.

    Parameters
    ----------
    workers : int, optional
        Worker processes of the embedded `LocalCluster`
        (default `default_workers`).
    scheduler : str, optional
        Address of an existing scheduler (``tcp://HOST:PORT``); no embedded cluster.
    client : distributed.Client, optional
        A client to use as it is (not closed here).
    processes : bool
        Embedded cluster of worker processes (default) or of threads in this
        process (no start-up of new interpreters; for a few small files).
    """

    def __init__(
        self, workers: int | None = None, scheduler: str | None = None, client=None, processes: bool = True
    ):
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
            raise ArgumentError(f"--workers must be a positive whole number, got {workers!r}")
        if scheduler is not None and workers is not None:
            raise ArgumentError("--workers sizes the embedded cluster; it does not apply with --scheduler")
        self.workers = workers or default_workers()
        self.scheduler = scheduler
        self._client = client
        self._own = client is None
        self._processes = processes
        self._cluster: Any = None

    @property
    def client(self):
        if self._client is None:
            self._client = self._connect() if self.scheduler else self._start_local()
            self._check_workers(self._client)
        return self._client

    def _start_local(self):
        import dask
        from distributed import Client, LocalCluster

        # a file that crashes its worker fails its row after one retry, not after killing four workers
        with dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES}):
            self._cluster = LocalCluster(
                n_workers=self.workers,
                threads_per_worker=1,
                processes=self._processes,
                dashboard_address=":0",  # any free port: 8787 may be another cluster's
                silence_logs=logging.CRITICAL,  # a row's failure is in its row; shutdown races are noise
                # workers ignore Ctrl-C: the client stops the sweep and then the workers
                preload=["fepost.sweep.worker"] if self._processes else [],
            )
            return Client(self._cluster)

    def _connect(self):
        from distributed import Client

        try:
            client = Client(self.scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise ClusterError(f"--scheduler {self.scheduler}: cannot connect ({first})") from None
        try:
            client.wait_for_workers(1, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError):
            client.close()
            raise ClusterError(
                f"--scheduler {self.scheduler}: no worker joined within {CONNECT_TIMEOUT:.0f} s "
                "(start some with `dask worker ADDRESS`)"
            ) from None
        return client

    @staticmethod
    def _check_workers(client) -> None:
        """Every worker must run the client's fepost: the rows are its functions."""
        from .. import __version__ as ours

        versions = client.get_versions(packages=["fepost"])
        for addr, info in (versions.get("workers") or {}).items():
            theirs = (info.get("packages") or {}).get("fepost")
            if theirs is None:
                raise ClusterError(f"Dask worker {addr} cannot import fepost (install it on every worker)")
            if theirs != ours:
                raise ClusterError(f"Dask worker {addr} runs fepost {theirs}, this client {ours}")

    def map(self, func: Callable, items: Sequence, name: str) -> list:
        """Submit ``func(item)`` for every item; return the futures in the items' order."""
        import uuid

        token = uuid.uuid4().hex[:8]
        keys = [f"fepost-{name}-{i}-{token}" for i in range(len(items))]
        return self.client.map(func, items, key=keys, pure=False)

    def as_completed(self, futures: Iterable):
        """(future, result or exception) pairs as they finish.

        A worker that died while running a task (a crash in a reader, out of
        memory) gives that task a `WorkerDied`; a cancelled task (the
        scheduler went away) raises `ClusterError`.
        """
        from concurrent.futures import CancelledError

        from distributed import KilledWorker, as_completed

        for fut in as_completed(futures):
            try:
                yield fut, fut.result()
            except KilledWorker:
                yield (
                    fut,
                    WorkerDied("the worker process died while analysing it (a crash, or out of memory)"),
                )
            except CancelledError:
                raise ClusterError(
                    "the Dask scheduler cancelled the sweep's tasks (was it shut down?)"
                ) from None
            except Exception as exc:  # raised on the worker outside fepost's own handling
                yield fut, exc
            fut.release()

    def cancel(self, futures: Sequence) -> None:
        if self._client is not None and futures:
            try:
                self._client.cancel(list(futures))
            except Exception:  # the cluster may already be gone; nothing left to cancel
                pass

    def close(self) -> None:
        if self._own:
            if self._client is not None:
                self._client.close()
            if self._cluster is not None:
                self._cluster.close()
        self._client = None
        self._cluster = None

    def __enter__(self) -> Cluster:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
