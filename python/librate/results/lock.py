"""The one writer lock of every result path (a map store, a 3-D map, a solve, a family file).

The writer holds an exclusive ``flock`` on a sibling file ``.<name>.lock`` and records who it is
(pid, host, start time) in ``.<name>.lock.owner``; both are removed when it finishes (while it
still holds the lock: a newcomer checks, after locking, that the file it locked is still the
one on disk, and retries otherwise). A second writer is refused with
:class:`StoreBusyError` naming the first. Deleting the lock file while a writer runs does not let
a second one in: a newcomer that gets a fresh lock still finds the owner record of a live
process and is refused, and the holder checks before every commit (:meth:`WriterLock.check`)
that the lock file on disk is still the one it holds, and stops with :class:`StoreBusyError`
otherwise.
"""

from __future__ import annotations

import contextlib
import os
import socket
import time
from collections.abc import Iterator
from pathlib import Path

from .atomic import atomic_write_text, pid_alive

__all__ = ["StoreBusyError", "WriterLock", "writer_lock"]


class StoreBusyError(RuntimeError):
    """Another process is writing the same result (it holds its lock), or this writer lost its
    lock (the lock file was deleted or replaced while it ran)."""


def lock_paths(out: Path) -> tuple[Path, Path]:
    return out.parent / f".{out.name}.lock", out.parent / f".{out.name}.lock.owner"


def _owner_pid(text: str) -> int | None:
    parts = text.split()
    if len(parts) >= 4 and parts[0] == "pid" and parts[1].isdigit() and parts[3] == socket.gethostname().rstrip(","):
        return int(parts[1])
    if len(parts) >= 2 and parts[0] == "pid" and parts[1].isdigit():
        return int(parts[1])
    return None


class WriterLock:
    """An exclusive writer lock on ``out`` (use :func:`writer_lock`)."""

    def __init__(self, out, wait: float = 0.0):
        self.out = Path(out)
        self.wait = float(wait)
        self.path, self.owner = lock_paths(self.out)
        self.fd: int | None = None
        self.inode: tuple[int, int] | None = None
        self.portable = None

    def _busy(self, who: str) -> StoreBusyError:
        return StoreBusyError(f"{self.out} is being written by another librate process ({who}); "
                              "wait for it to finish or stop it, or choose another folder")

    def _who(self) -> str:
        who = "a process that has not recorded its pid yet"
        for _ in range(40):  # the holder writes its pid just after taking the lock
            try:
                return self.owner.read_text(encoding="utf-8").strip() or who
            except OSError:
                time.sleep(0.05)
        return who

    def acquire(self) -> None:
        """Take the lock, retrying for up to ``wait`` seconds while another writer holds it."""
        deadline = time.monotonic() + self.wait
        while True:
            try:
                return self._acquire()
            except StoreBusyError:
                if time.monotonic() >= deadline:
                    raise
                time.sleep(0.05)

    def _acquire(self) -> None:
        self.out.parent.mkdir(parents=True, exist_ok=True)
        try:
            import fcntl
        except ImportError:  # Windows: filelock's lock, without the inode checks
            return self._acquire_portable()
        for _ in range(20):
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise self._busy(self._who()) from None
            st = os.fstat(fd)
            try:
                on_disk = os.stat(self.path)
            except FileNotFoundError:
                on_disk = None
            if on_disk is not None and (on_disk.st_dev, on_disk.st_ino) == (st.st_dev, st.st_ino):
                break
            os.close(fd)  # the file was deleted or replaced between open and lock: again
        else:
            raise self._busy("the lock file keeps changing")
        # a live owner other than us means its lock file was deleted under it: refuse
        try:
            text = self.owner.read_text(encoding="utf-8").strip()
        except OSError:
            text = ""
        pid = _owner_pid(text)
        if pid is not None and pid != os.getpid() and pid_alive(pid):
            os.close(fd)
            raise self._busy(text + "; its lock file was removed while it runs")
        self.fd, self.inode = fd, (st.st_dev, st.st_ino)
        atomic_write_text(self.owner, f"pid {os.getpid()} on {socket.gethostname()}, since {time.strftime('%Y-%m-%d %H:%M:%S')}")

    def _acquire_portable(self) -> None:
        from filelock import FileLock, Timeout

        lock = FileLock(str(self.path), timeout=0)
        try:
            lock.acquire()
        except Timeout:
            raise self._busy(self._who()) from None
        self.portable, self.fd, self.inode = lock, -1, None
        atomic_write_text(self.owner, f"pid {os.getpid()} on {socket.gethostname()}, since {time.strftime('%Y-%m-%d %H:%M:%S')}")

    def check(self) -> None:
        """Raise :class:`StoreBusyError` unless this writer still holds the lock on disk (call it
        before every commit)."""
        if self.fd is None:
            raise StoreBusyError(f"{self.out}: the writer lock is not held")
        if self.inode is None:  # the portable lock: nothing more to check
            return
        try:
            st = os.stat(self.path)
            same = (st.st_dev, st.st_ino) == self.inode
        except FileNotFoundError:
            same = False
        if not same:
            raise StoreBusyError(f"{self.out}: the writer lock file {self.path} was removed or replaced while this process wrote; "
                                 "stopped before the next commit so that two writers never mix (re-run to resume)")

    def release(self) -> None:
        if self.fd is None:
            return
        if self.inode is None:
            with contextlib.suppress(OSError):
                self.owner.unlink()
            self.portable.release()
            self.fd = None
            return
        try:
            mine = True
            try:
                st = os.stat(self.path)
                mine = (st.st_dev, st.st_ino) == self.inode
            except FileNotFoundError:
                mine = False
            if mine:  # removed while still held: a waiting writer sees the inode change and retries
                with contextlib.suppress(OSError):
                    if _owner_pid(self.owner.read_text(encoding="utf-8")) == os.getpid():
                        self.owner.unlink()
                with contextlib.suppress(OSError):
                    self.path.unlink()
        finally:
            os.close(self.fd)
            self.fd = None


@contextlib.contextmanager
def writer_lock(out, wait: float = 0.0) -> Iterator[WriterLock]:
    """Hold the exclusive writer lock of ``out`` for the ``with`` block (yields the lock; call
    its ``check()`` before each commit). ``wait``: seconds to wait for another writer."""
    lock = WriterLock(out, wait)
    lock.acquire()
    try:
        yield lock
    finally:
        lock.release()
