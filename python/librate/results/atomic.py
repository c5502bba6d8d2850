"""The one atomic writer of librate: every result, part and small file goes through here.

* A new file or folder is written under a temporary sibling ``.<name>.tmp-<pid>``, every file
  in it and every folder of it fsynced, then moved onto its name by a rename.
* A folder that already exists is replaced by an atomic exchange (Linux ``renameat2`` with
  ``RENAME_EXCHANGE``): the new tree takes the name in one step and the old one, now under the
  temporary name, is deleted only afterwards. Where the exchange is not available the old tree
  is first renamed aside to ``.<name>.old-<pid>`` (restored at the next start if a kill came
  between the two renames). A kill at any moment leaves either the old or the new result under
  the name, complete, never a half-deleted one.
* :func:`clean_orphans` removes the temporary siblings left by killed processes (only those
  whose pid is dead) and puts back an old tree whose replacement never arrived.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import shutil
from collections.abc import Callable, Iterator
from pathlib import Path

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text", "clean_orphans", "fsync_tree", "pid_alive",
           "remove_path", "replace_path",
           "temporary_sibling"]

_TMP = re.compile(r"^\.(?P<name>.+)\.(?P<what>tmp|old|creating)-(?P<pid>\d+)$")


def pid_alive(pid: int) -> bool:
    """Whether a process ``pid`` exists on this machine."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, another user's
        return True
    except OSError:
        return False
    return True


def remove_path(p) -> None:
    """Remove a file, a link or a folder tree, if there."""
    q = Path(p)
    if q.is_dir() and not q.is_symlink():
        shutil.rmtree(q, ignore_errors=True)
        if q.exists():
            shutil.rmtree(q)
    elif q.exists() or q.is_symlink():
        q.unlink()


def _fsync_dir(d: Path) -> None:
    try:
        fd = os.open(d, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def fsync_tree(p) -> None:
    """Flush a file, or every file and folder of a tree, to disk."""
    q = Path(p)
    if q.is_file():
        with open(q, "rb") as f:
            os.fsync(f.fileno())
        return
    for root, _dirs, files in os.walk(q, topdown=False):
        for name in files:
            fd = os.open(os.path.join(root, name), os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        _fsync_dir(Path(root))


def temporary_sibling(p, what: str = "tmp") -> Path:
    """``.<name>.<what>-<pid>`` beside ``p``."""
    p = Path(p)
    return p.with_name(f".{p.name}.{what}-{os.getpid()}")


def _exchange(a: Path, b: Path) -> bool:
    """Swap ``a`` and ``b`` atomically (Linux renameat2 RENAME_EXCHANGE); False when the
    system cannot."""
    if not hasattr(os, "uname") or os.uname().sysname != "Linux":
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if fn(at_fdcwd, os.fsencode(str(a)), at_fdcwd, os.fsencode(str(b)), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    import errno

    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP if hasattr(errno, "EOPNOTSUPP") else errno.EINVAL):
        return False
    raise OSError(err, f"cannot exchange {a} and {b}: {os.strerror(err)}")


#: Called with a step name at each step of :func:`replace_path` (the fault-injection tests kill
#: the process there); None in normal use.
REPLACE_HOOK: Callable[[str], None] | None = None


def _hook(step: str) -> None:
    if REPLACE_HOOK is not None:
        REPLACE_HOOK(step)


def replace_path(tmp, p) -> None:
    """Move the complete, flushed ``tmp`` onto ``p``, replacing what is there; the old result
    is deleted only once the new one holds the name (see the module docs)."""
    tmp, p = Path(tmp), Path(p)
    fsync_tree(tmp)
    _hook("before-replace")
    if tmp.is_dir() and p.is_dir() and not p.is_symlink():
        if _exchange(tmp, p):
            _fsync_dir(p.parent)
            _hook("after-exchange")
            remove_path(tmp)  # the old tree, now under the temporary name
        else:
            old = temporary_sibling(p, "old")
            remove_path(old)
            os.replace(p, old)
            _hook("old-aside")
            os.replace(tmp, p)
            _fsync_dir(p.parent)
            _hook("new-in")
            remove_path(old)
    else:
        if p.is_dir() and not p.is_symlink():  # a folder replaced by a file: aside first
            old = temporary_sibling(p, "old")
            os.replace(p, old)
            os.replace(tmp, p)
            _fsync_dir(p.parent)
            remove_path(old)
        else:
            os.replace(tmp, p)
            _fsync_dir(p.parent)
    _hook("done")


@contextlib.contextmanager
def atomic_path(p) -> Iterator[Path]:
    """``with atomic_path(p) as tmp:`` write a file or folder at ``tmp``; on a normal exit it
    replaces ``p`` (:func:`replace_path`), on an error nothing at ``p`` changes."""
    p = Path(p)
    p.parent.mkdir(parents=True, exist_ok=True)
    clean_orphans(p)
    tmp = temporary_sibling(p)
    remove_path(tmp)
    try:
        yield tmp
        replace_path(tmp, p)
    finally:
        with contextlib.suppress(OSError):
            remove_path(tmp)


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` all or nothing, flushed to disk."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` all or nothing, flushed to disk."""
    atomic_write_bytes(path, text.encode("utf-8"))


def clean_orphans(p) -> list[Path]:
    """Remove the temporary siblings of ``p`` left by dead processes; an old tree set aside by a
    replacement that was killed before the new one arrived is put back. Returns what was
    removed or restored."""
    p = Path(p)
    done: list[Path] = []
    try:
        siblings = list(p.parent.iterdir())
    except OSError:
        return done
    for q in siblings:
        m = _TMP.match(q.name)
        if not m or m["name"] != p.name or pid_alive(int(m["pid"])):
            continue
        if m["what"] == "old" and not (p.exists() or p.is_symlink()):
            os.replace(q, p)
        else:
            remove_path(q)
        done.append(q)
    return done
