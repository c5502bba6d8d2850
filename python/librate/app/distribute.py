"""The one distribution helper of librate: a list of independent tasks run in this process or on a
Dask cluster, each result checksummed on arrival and handed to the caller's commit in turn.

Every long job is one caller: a planar map (a task per orbit row), a 3-D map (a task per orbit),
a solve over many orbits (a task per orbit and Kz), and any sweep of the same shape (e.g. over
ephemeris epochs): the caller lists :class:`Task` objects (a module-level function and its
picklable arguments), and a ``commit(key, result)`` that stores each result (into a part store
through :class:`PartCommits`, or memory).

``scheduler``: None (this process, the tasks in order), a ``distributed.Client``, or a scheduler
address ("tcp://host:port"; a client is opened and closed here). On a cluster:

* **Checksums.** A worker returns its result with :func:`~librate.results.checksum.value_digest`
  of it; the client recomputes the digest of what arrived and commits only a match (a mismatch
  is a lost task). With a :class:`Region` (a part store the workers may share), a worker that
  sees the store's writer-lock record at the same path (the same filesystem, the same writer)
  writes its part's data into the store directly and returns only the part's digests; the client
  reads the region back, checks it against them, and commits the digests and the done flag
  (:meth:`~librate.results.PartStore.commit_written`). A worker that does not see the record
  returns the data, and the client writes them.
* **Faults.** A task lost with its worker (killed, out of memory), cancelled, or cut off by a
  restarted scheduler (the client reconnects to the same address) is submitted again, up to
  ``attempts`` times; the finished tasks were committed on arrival, so nothing finished is lost.
  Each submission has its own key (``pure=False``), a task is committed once whatever its
  arrivals, and the tasks are deterministic: the committed results equal a local run's bit for
  bit. An error raised by the task itself (e.g. ConvergenceError) is not retried: it propagates.
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..results.checksum import value_digest

__all__ = ["ArrivalError", "PartCommits", "Region", "Task", "Written", "client_of", "run_tasks"]

#: Submissions of one task before its loss is an error.
ATTEMPTS = 4
#: Seconds to wait for a client to reconnect to a restarted scheduler.
RECONNECT_S = 60.0


@dataclass(frozen=True)
class Task:
    """One independent unit of work: ``fn(*args, **kwargs)`` (``fn`` a module-level function,
    everything picklable), committed under ``key``."""

    key: Hashable
    fn: Callable
    args: tuple = ()
    kwargs: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Region:
    """Where a worker may write a task's result itself: the part store at ``path`` (variables
    ``dtypes`` by name) while its writer-lock record at ``owner`` reads ``owner_text``; the part
    index is the task's key."""

    path: str
    dtypes: dict
    owner: str
    owner_text: str

    @classmethod
    def of(cls, store, lock) -> Region | None:
        """The region of an open :class:`~librate.results.PartStore` under the writer ``lock``
        (None when the lock has no record to recognise)."""
        try:
            text = Path(lock.owner).read_text(encoding="utf-8")
        except (OSError, AttributeError):
            return None
        return cls(str(store.path), {k: v.dtype for k, v in store.schema.variables.items()}, str(lock.owner), text)

    def visible(self) -> bool:
        """Whether this process sees the writer's own record at the same path (a shared
        filesystem, and the same writer still at work)."""
        try:
            return Path(self.owner).read_text(encoding="utf-8") == self.owner_text
        except OSError:
            return False


@dataclass(frozen=True)
class Written:
    """What a worker returns after writing its part into a :class:`Region`: the part's digests."""

    digests: tuple


def _execute(fn, args, kwargs, region: Region | None, key):
    """Runs on a worker: the task, then its result and digest, or the region written and its
    part digests."""
    result = fn(*args, **kwargs)
    if region is not None and region.visible():
        from ..results.store import write_region

        return "written", Written(tuple(write_region(Path(region.path), region.dtypes, key, result))), None
    return "value", result, value_digest(result)


class ArrivalError(RuntimeError):
    """A result that does not match its checksum on arrival (retried like a lost task)."""


def client_of(scheduler):
    """``(client, owned)``: the ``distributed.Client`` of ``scheduler`` (a Client or an address),
    and whether it was opened here (and must be closed by the caller)."""
    try:
        from distributed import Client
    except ImportError:
        raise ValueError("invalid argument `scheduler`: a Dask scheduler needs dask.distributed (pip install "
                         "'dask[distributed]')") from None
    if isinstance(scheduler, Client):
        return scheduler, False
    if not isinstance(scheduler, str) or not scheduler:
        raise ValueError("invalid argument `scheduler`: None, a distributed.Client or a scheduler address "
                         f"(\"tcp://host:port\"), got {scheduler!r}")
    return Client(scheduler), True


def run_tasks(tasks: Iterable[Task], commit: Callable[[Hashable, object], None], *, scheduler=None, bar=None,
              region: Region | None = None, commit_written: Callable[[Hashable, tuple], None] | None = None,
              attempts: int = ATTEMPTS) -> None:
    """Run ``tasks`` and ``commit(key, result)`` each result (in order locally, as they arrive
    on a cluster); ``bar.update(1)`` after each commit. With ``region`` (and
    ``commit_written(key, digests)``, which checks the written part and commits it, raising
    :class:`ArrivalError` on a mismatch), workers on the client's filesystem write their parts
    directly. See the module docs for the faults handled."""
    tasks = list(tasks)
    if scheduler is None:
        for t in tasks:
            commit(t.key, t.fn(*t.args, **t.kwargs))
            if bar is not None:
                bar.update(1)
        return
    client, owned = client_of(scheduler)
    try:
        _run_on(client, tasks, commit, bar, region if commit_written is not None else None, commit_written, attempts)
    finally:
        if owned:
            client.close()


@dataclass
class PartCommits:
    """The two commits :func:`run_tasks` takes when each part of a part store
    (:class:`~librate.results.PartStore`) is one task's result: :meth:`commit` writes a result
    that arrived as data (:meth:`~librate.results.PartStore.write_part`: data, digests, then the
    done flag), :meth:`commit_written` commits a part a worker wrote into the store itself
    (:meth:`~librate.results.PartStore.commit_written`, :class:`ArrivalError` when it does not
    check out). Each sets ``done[index]`` and then moves ``bar`` (if any) by one.

    ``what`` names a part in the error ("orbit", "epoch"). ``prepare(key, result)``, if given,
    turns a task's key and result into the ``(index, data)`` of the part to write, or None while
    the part is not complete (a part gathered from several tasks); it is also where a caller
    notes what a result says besides its arrays (e.g. a failure's reason). Without it the key is
    the part's index and the result its data."""

    store: Any
    done: Any
    what: str = "part"
    bar: Any = None
    prepare: Callable[[Hashable, Any], tuple[int, dict] | None] | None = None

    def commit(self, key: Hashable, result) -> None:
        """Write the part of a result that arrived as data."""
        if self.prepare is not None:
            got = self.prepare(key, result)
            if got is None:
                return
            key, result = got
        self.store.write_part(key, result)
        self._done(key)

    def commit_written(self, index: int, digests: tuple) -> None:
        """Commit the part a worker wrote into the store itself, or raise ArrivalError."""
        if not self.store.commit_written(index, digests):
            raise ArrivalError(f"{self.what} {index}: the region written by a worker does not match its digests")
        self._done(index)

    def _done(self, index) -> None:
        self.done[index] = True
        if self.bar is not None:
            self.bar.update(1)


def _lost_errors() -> tuple[type[BaseException], ...]:
    from asyncio import CancelledError as AsyncCancelled
    from concurrent.futures import CancelledError

    from distributed import KilledWorker
    from distributed.comm import CommClosedError

    return (CancelledError, AsyncCancelled, KilledWorker, CommClosedError, OSError, TimeoutError)


def _wait_connected(client, timeout: float = RECONNECT_S) -> None:
    deadline = time.monotonic() + timeout
    while client.status != "running":
        if client.status in ("closed", "closing") or time.monotonic() > deadline:
            raise ConnectionError(f"the Dask client lost its scheduler and did not reconnect within {timeout:g} s (status "
                                  f"{client.status!r}); the finished tasks are committed: re-run the same call to resume")
        time.sleep(0.1)


def _run_on(client, tasks, commit, bar, region, commit_written, attempts) -> None:
    from distributed import as_completed

    lost = _lost_errors()
    run = uuid.uuid4().hex[:8]
    tries: dict[Hashable, int] = {}
    pending: dict = {}

    def submit(t: Task, direct: bool):
        tries[t.key] = tries.get(t.key, 0) + 1
        fut = client.submit(_execute, t.fn, t.args, t.kwargs, region if direct else None, t.key, pure=False,
                            key=f"librate-{t.fn.__name__}-{run}-{t.key}-{tries[t.key]}")
        pending[fut] = (t, direct)
        return fut

    queue = as_completed([submit(t, region is not None) for t in tasks])
    done: set = set()
    for fut in queue:
        t, direct = pending.pop(fut)
        if t.key in done:
            continue
        err: BaseException | None = None
        try:
            how, value, digest = fut.result()
        except lost as e:  # the task's own errors propagate
            err = e
        finally:
            fut.release()
        if err is None:
            try:
                if how == "written":
                    commit_written(t.key, value.digests)  # ArrivalError when the region does not check out
                elif value_digest(value) != digest:
                    raise ArrivalError(f"task {t.key}: its result does not match the checksum computed on the worker")
                else:
                    commit(t.key, value)
            except ArrivalError as e:
                err = e
        if err is not None:
            if tries[t.key] >= attempts:
                raise RuntimeError(f"task {t.key} ({t.fn.__name__}) was lost {tries[t.key]} times on the cluster (last: "
                                   f"{type(err).__name__}: {err}); the finished tasks are committed: re-run "
                                   "the same call to resume") from err
            _wait_connected(client)
            # a written region that did not check out is computed again and sent back whole
            queue.add(submit(t, direct and not isinstance(err, ArrivalError)))
            continue
        done.add(t.key)
        if bar is not None:
            bar.update(1)
