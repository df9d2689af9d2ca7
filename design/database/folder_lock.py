"""One writer per output folder: an OS file lock held for the whole run.

Every database folder (:func:`~holofold.design.database.store.build_database`) and design folder
(:func:`~holofold.design.loop.design_loop.run_design`) is locked while a run writes into it: the
lock file
``.holofold.lock`` in the folder is locked with the operating system's advisory lock
(``flock`` on POSIX, ``msvcrt.locking`` on Windows), which the OS releases when the process
ends, however it ends (Ctrl-C, ``kill -9``, a crash), so a lock is never stale. The file also
says who holds it (process id, host, command, start time), for the message a second run gets:

    db/arch is in use by another holofold run (pid 4242 on host, since 05:20:11: holofold
    generate arch -n 200 -o db/arch); wait for it to end or use another folder

A second run into a locked folder refuses at once with that one line (``wait=None``), or waits
up to ``wait`` seconds, saying once that it waits. Locks are re-entrant within one process (the
design loop locks its folder, then each database inside it).
"""

from __future__ import annotations

import json
import os
import socket
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from holofold.geometry.outputs import check_output_folder

__all__ = ["FolderBusyError", "LOCK_NAME", "folder_lock", "locks_folder", "lock_holder"]

#: name of the lock file inside a locked folder
LOCK_NAME = ".holofold.lock"
_HELD: dict[Path, int] = {}  # folder -> re-entry count, this process
_GUARD = threading.Lock()


class FolderBusyError(OSError):
    """Another run holds the folder's lock (the message names it and what to do)."""


def _try_lock(fd: int) -> bool:
    if sys.platform == "win32":  # pragma: no cover - exercised on Windows only
        import msvcrt

        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
            return True
        except OSError:
            return False
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False


def _unlock(fd: int) -> None:
    if sys.platform == "win32":  # pragma: no cover
        import msvcrt

        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        return
    import fcntl

    fcntl.flock(fd, fcntl.LOCK_UN)


def lock_holder(folder) -> str:
    """Who holds (or last held) the lock of ``folder``, in words ('' if nobody recorded)."""
    try:
        info = json.loads((Path(folder) / LOCK_NAME).read_text(encoding="utf-8"))
        since = time.strftime("%H:%M:%S", time.localtime(float(info["since"])))
        return f"pid {int(info['pid'])} on {info['host']}, since {since}: {info['command']}"
    except (OSError, ValueError, KeyError, TypeError):
        return ""


def _busy(folder: Path) -> FolderBusyError:
    who = lock_holder(folder)
    return FolderBusyError(
        f"{folder} is in use by another holofold run{f' ({who})' if who else ''}; wait for it "
        "to end or use another folder"
    )


def _command() -> str:
    words = [Path(sys.argv[0]).name, *sys.argv[1:]] if sys.argv and sys.argv[0] else ["python"]
    text = " ".join(words)
    return text if len(text) <= 200 else text[:197] + "..."


@contextmanager
def folder_lock(folder, *, wait: float | None = None, say=None):
    """Hold the lock of ``folder`` (created if missing) for the block.

    Parameters
    ----------
    folder : path
        The output folder.
    wait : float, optional
        Seconds to wait for another run to release the folder; None (default) or 0 refuses
        at once.
    say : callable, optional
        Receives one line when the run starts waiting (default: a warning).

    Raises
    ------
    FolderBusyError
        Another process holds the lock (after ``wait`` seconds, if given).
    OSError
        The folder cannot be created or the lock file cannot be opened (a read-only folder:
        callers that only read do not lock).
    """
    folder = Path(folder)
    created = not folder.exists()
    check_output_folder(folder)  # one line naming the folder if it cannot be written
    folder.mkdir(parents=True, exist_ok=True)
    key = folder.resolve()
    with _GUARD:
        if key in _HELD:
            _HELD[key] += 1
            reentered = True
        else:
            reentered = False
    if reentered:
        try:
            yield folder
        finally:
            with _GUARD:
                _HELD[key] -= 1
        return
    path = folder / LOCK_NAME
    # never through a symlink: out/.holofold.lock -> ../victim would truncate the victim
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)
    except OSError as exc:
        if path.is_symlink():
            raise OSError(
                f"{path} is a symbolic link; a lock file is never opened through one: remove it"
            ) from None
        raise exc
    try:
        if not _try_lock(fd):
            if not wait:
                raise _busy(folder)
            line = f"waiting up to {wait:g} s: {_busy(folder).args[0].split('; ')[0]}"
            if say is None:
                import warnings

                warnings.warn(line, stacklevel=3)
            else:
                say(line)
            deadline = time.monotonic() + wait
            while not _try_lock(fd):
                if time.monotonic() > deadline:
                    raise _busy(folder)
                time.sleep(0.2)
        info = {"pid": os.getpid(), "host": socket.gethostname(), "since": time.time(),
                "command": _command()}  # fmt: skip
        data = (json.dumps(info) + "\n").encode()
        os.ftruncate(fd, 0)
        os.pwrite(fd, data, 0) if hasattr(os, "pwrite") else os.write(fd, data)
        with _GUARD:
            _HELD[key] = 1
        try:
            yield folder
        except BaseException:
            if created and [p.name for p in folder.iterdir()] == [LOCK_NAME]:
                path.unlink()  # a run refused before writing anything leaves no folder
                folder.rmdir()
            raise
        finally:
            with _GUARD:
                del _HELD[key]
            _unlock(fd)
    finally:
        os.close(fd)


def locks_folder(parameter: str = "folder"):
    """Decorator: the function runs holding :func:`folder_lock` of its argument ``parameter``
    (a run refused before it writes anything leaves no folder behind)."""
    import functools
    import inspect

    def wrap(fn):
        sig = inspect.signature(fn)

        @functools.wraps(fn)
        def run(*args, **kwargs):
            with folder_lock(sig.bind(*args, **kwargs).arguments[parameter]):
                return fn(*args, **kwargs)

        return run

    return wrap
